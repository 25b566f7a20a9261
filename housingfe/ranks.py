"""One command on several MPI ranks (mpirun / srun): serial work done once, on rank 0, and errors that stop every
rank together (docs/cluster.md).

* `on_rank_zero(fn)`: a serial step (a gear source model, `housingfe describe`) runs on rank 0 alone; the other
  ranks wait without spinning and return its value or raise its InputError / SolverError, so the output is
  written and printed once and every rank exits the same way.  A serial step must not communicate on
  MPI.COMM_WORLD; PETSc, if not started yet, is started on rank 0's MPI.COMM_SELF (its start is collective).
* `stop_together(line, code)`: after an error on this rank.  Errors found collectively (rank 0 decides and
  broadcasts, or every rank checks the same input) stop every rank at the same moment: the line is printed once
  (rank 0) and every rank exits with `code`.  An error found on one rank alone would leave that rank in
  MPI_Finalize and the others waiting for it in a collective, for ever (measured: `mpirun -n 2` with one rank
  raising before a barrier hangs); such a rank prints its line and aborts the job (MPI_Abort) after
  STOP_GRACE_S.

Base layer: mpi4py is imported only when a launcher started this process (an MPI singleton is one rank).
"""
from __future__ import annotations

import os
import sys
import time

from housingfe.errors import InputError, SolverError

# environment variables a launcher sets in every process it starts (the same list as housingfe/__init__.py)
LAUNCHER_VARIABLES = ("OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "SLURM_PROCID")
# how long a rank that stopped waits for the others to report that they stopped too (s): ranks that raise the
# same collectively decided error do so within milliseconds of each other
STOP_GRACE_S = 10.0
_TAG_SERIAL, _TAG_STOP = 7301, 7302     # point-to-point tags; the package's own communication is collective
_POLL_S = 0.02


def world():
    """MPI.COMM_WORLD when this process is one of several MPI ranks, else None (no MPI import without a
    launcher)."""
    if not any(v in os.environ for v in LAUNCHER_VARIABLES):
        return None
    from mpi4py import MPI

    return MPI.COMM_WORLD if MPI.COMM_WORLD.size > 1 else None


def _wait(request):
    """The message of a receive request, polled (a blocking receive spins a core at 100 % meanwhile)."""
    while True:
        done, message = request.test()
        if done:
            return message
        time.sleep(_POLL_S)


def _petsc_on_this_rank() -> None:
    """Initialise PETSc on MPI.COMM_SELF unless it is initialised already.  PetscInitialize is collective on its
    world (it broadcasts the options): a serial step that imports a module importing petsc4py waited there for
    the other ranks for ever (`mpirun -n 2 housingfe describe test-gearbox-runup`)."""
    if "petsc4py.PETSc" in sys.modules:
        return
    import petsc4py
    from mpi4py import MPI

    petsc4py.init(comm=MPI.COMM_SELF)


def on_rank_zero(fn, comm=None):
    """fn() on rank 0 of `comm` alone (default: world(); without several ranks fn() is simply called).  The
    other ranks wait and return rank 0's return value (it must pickle), or raise the InputError / SolverError it
    raised (another exception: RuntimeError naming it)."""
    comm = world() if comm is None else comm
    if comm is None or comm.size == 1:
        return fn()
    if comm.rank == 0:
        outcome = ("crash", "stopped")
        try:
            _petsc_on_this_rank()
            value = fn()
            outcome = ("ok", value)
            return value
        except (InputError, SolverError) as exc:
            outcome = (type(exc).__name__, str(exc))
            raise
        except BaseException as exc:
            outcome = ("crash", f"{type(exc).__name__}: {exc}")
            raise
        finally:
            for rank in range(1, comm.size):
                comm.send(outcome, dest=rank, tag=_TAG_SERIAL)
    kind, payload = _wait(comm.irecv(source=0, tag=_TAG_SERIAL))
    if kind == "ok":
        return payload
    if kind == "InputError":
        raise InputError(payload)
    if kind == "SolverError":
        raise SolverError(payload)
    raise RuntimeError(f"rank 0 stopped: {payload}")


def stop_together(line: str | None, code: int, comm=None, grace_s: float = STOP_GRACE_S) -> int:
    """Print `line` (None: already reported, e.g. a traceback) to stderr once per distinct message and return
    `code`, after the other ranks of `comm` (default: world()) reported that they stopped too: rank 0 prints a
    line every rank has, each rank its own otherwise.  A rank whose partners do not stop within grace_s seconds
    prints its line and aborts the job with `code` (MPI_Abort: mpirun then ends every rank)."""
    comm = world() if comm is None else comm
    if comm is None:
        if line is not None:
            print(line, file=sys.stderr, flush=True)
        return code
    others = [r for r in range(comm.size) if r != comm.rank]
    sends = [comm.isend((code, line), dest=r, tag=_TAG_STOP) for r in others]
    heard = {}
    deadline = time.monotonic() + grace_s
    while len(heard) < len(others) and time.monotonic() < deadline:
        for rank in others:
            if rank not in heard and comm.iprobe(source=rank, tag=_TAG_STOP):
                heard[rank] = comm.recv(source=rank, tag=_TAG_STOP)
        if len(heard) < len(others):
            time.sleep(_POLL_S)
    if len(heard) < len(others):
        if line is not None:
            print(line, file=sys.stderr, flush=True)
        sys.stdout.flush()
        comm.Abort(code)
    for request in sends:
        request.wait()
    same = all(message == (code, line) for message in heard.values())
    if line is not None and (comm.rank == 0 or not same):
        print(line, file=sys.stderr, flush=True)
    return code
