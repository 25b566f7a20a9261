"""Run a test file's other tests again under `mpirun -n 2` from a one-rank session (the distributed paths run in
`make test` too)."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest


def rerun_on_two_ranks(test_file: str, comm, timeout: float = 600.0) -> None:
    """Run the tests of `test_file` not named *two_ranks* on 2 MPI ranks and assert they pass (one pytest summary
    line per rank).  Skips inside a multi-rank session or without mpirun."""
    if comm.size > 1 or not shutil.which("mpirun"):
        pytest.skip("runs from a one-rank session with mpirun installed")
    root = Path(__file__).resolve().parents[1]
    env = {**os.environ, "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OPENBLAS_NUM_THREADS": "1"}
    proc = subprocess.run([shutil.which("mpirun"), "-n", "2", sys.executable, "-m", "pytest", "-q", "-p",
                           "no:cacheprovider", "-k", "not two_ranks", str(Path(test_file))],
                          capture_output=True, text=True, env=env, timeout=timeout, cwd=root)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-2000:]
    assert proc.stdout.count(" passed") == 2      # one summary line per rank
