"""Distributed runs from a one-rank test session (the distributed paths run in `make test` too): a test file's other
tests again under `mpirun -n 2` (rerun_on_two_ranks), or a test module's `__main__` half on N ranks, whose JSON the
test compares with its own one-rank answer (module_result)."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest


def _mpi_env() -> dict:
    return {**os.environ, "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
            "OPENBLAS_NUM_THREADS": "1"}


def module_result(module: str, *args: str, ranks: int = 2, timeout: float = 300.0) -> dict:
    """Run `python -m module args` from the repository root under `mpirun -n ranks` (a plain process for one rank),
    assert it exits 0 and return the JSON object of its last stdout line (what its rank 0 printed)."""
    cmd = [sys.executable, "-m", module, *args]
    if ranks > 1:
        cmd = [shutil.which("mpirun"), "-n", str(ranks), *cmd]
    proc = subprocess.run(cmd, capture_output=True, text=True, env=_mpi_env(), timeout=timeout,
                          cwd=Path(__file__).resolve().parents[1])
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


def rerun_on_two_ranks(test_file: str, comm, timeout: float = 600.0) -> None:
    """Run the tests of `test_file` not named *two_ranks* on 2 MPI ranks and assert they pass (one pytest summary
    line per rank).  Skips inside a multi-rank session or without mpirun."""
    if comm.size > 1 or not shutil.which("mpirun"):
        pytest.skip("runs from a one-rank session with mpirun installed")
    root = Path(__file__).resolve().parents[1]
    proc = subprocess.run([shutil.which("mpirun"), "-n", "2", sys.executable, "-m", "pytest", "-q", "-p",
                           "no:cacheprovider", "-k", "not two_ranks", str(Path(test_file))],
                          capture_output=True, text=True, env=_mpi_env(), timeout=timeout, cwd=root)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-2000:]
    assert proc.stdout.count(" passed") == 2      # one summary line per rank
