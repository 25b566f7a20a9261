"""housingfe: gearbox noise from the gear mesh to radiated sound power.

The chain, one module per concern (data flows one way):
scene -> geometry -> model (solvers.elasticity) -> solver (solvers.modal, solvers.harmonic)
-> response -> radiation -> report.  Standalone analytic models: source (gears), bearings.

Units are SI throughout; dB references follow van Roosmalen (1994): v0 = omega0 = 5e-8,
F0 = 1 N, P0 = 1 pW (see housingfe.levels).
"""

import os as _os

__version__ = "0.1.0"


def _single_host_mpi_default() -> None:
    """Open MPI 4.1 probes its UCX transport in MPI_Init: 0.34 s of every process's start, 0.14 s with the ob1
    transport layer (shared memory on one host), measured on this stack.  A process started without a launcher
    (Open MPI's singleton) talks to no other rank, so there ob1 is the default, unless the user chose a layer
    (OMPI_MCA_pml).  Processes under mpirun / srun keep what their launcher gives them (docs/cluster.md)."""
    launched = any(k in _os.environ for k in ("OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "SLURM_PROCID"))
    if not launched:
        _os.environ.setdefault("OMPI_MCA_pml", "ob1")


_single_host_mpi_default()
