"""Launching a benchmark case on several MPI ranks."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path


def mpi_launcher(ranks: int) -> list[str]:
    """The command prefix that starts `ranks` MPI processes (empty for one rank: a plain process)."""
    if ranks <= 1:
        return []
    return ["mpirun", "-n", str(ranks), "--oversubscribe"]


def mpi_environment(env: dict | None = None) -> dict:
    """The environment for the launched ranks: one BLAS thread per rank (the ranks would otherwise fight over
    the cores), Open MPI's shared-memory transport layer ob1 (the ranks run on this one host; UCX's probing costs
    0.2 s per rank at start-up: S2R box on 2 ranks 3.33-3.57 -> 3.16-3.17 s, the solve unchanged) unless the user
    chose one, and, when run as root (containers, CI), Open MPI's explicit consent to that."""
    out = dict(os.environ if env is None else env)
    out.setdefault("OPENBLAS_NUM_THREADS", "1")
    out.setdefault("OMPI_MCA_pml", "ob1")
    if os.geteuid() == 0:
        out.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
        out.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    return out


def write_worker_result(out: dict, workdir: Path) -> None:
    """The end of a case's worker process: add its peak resident memory (GB, summed over the ranks, each rank's
    own peak or its child processes' if larger) to `out` and write it to workdir/result.json on rank 0."""
    import resource

    from mpi4py import MPI

    self_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    child_kb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    out["peak_memory_gb"] = MPI.COMM_WORLD.allreduce(max(self_kb, child_kb)) / 1024**2
    if MPI.COMM_WORLD.rank == 0:
        (Path(workdir) / "result.json").write_text(json.dumps(out))


def run_worker(module: str, job: dict, workdir: Path, ranks: int = 1) -> tuple[dict | None, float, str]:
    """Write `job` (with "workdir") to workdir/job.json and run `python -m module job.json` on `ranks` MPI processes
    (mpi_launcher, mpi_environment); the worker ends with write_worker_result.  Returns (its result dict with
    process_wall_s added, None if it failed; the process wall time (s); the last line of its stderr, "failed" if
    it wrote none)."""
    path = Path(workdir) / "job.json"
    path.write_text(json.dumps({**job, "workdir": str(workdir)}))
    t0 = time.perf_counter()
    proc = subprocess.run(mpi_launcher(ranks) + [sys.executable, "-m", module, str(path)], capture_output=True,
                          text=True, env=mpi_environment())
    wall = time.perf_counter() - t0
    last = proc.stderr.strip().splitlines()[-1] if proc.stderr.strip() else "failed"
    if proc.returncode != 0:
        return None, wall, last
    out = json.loads((Path(workdir) / "result.json").read_text())
    out["process_wall_s"] = wall
    return out, wall, last
