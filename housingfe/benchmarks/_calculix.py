"""CalculiX (`ccx`) as the peer of `housingfe bench modal` and `housingfe bench imported`: one *FREQUENCY run on a
deck and its eigenfrequencies."""
from __future__ import annotations

import os
import subprocess
import time
from pathlib import Path

import numpy as np

THREADS = 2     # OpenMP and SPOOLES threads of ccx: the machine's 2 cores


def run_calculix(workdir: Path, job: str) -> tuple[np.ndarray, float]:
    """`ccx -i job` in workdir (job.inp there) on THREADS threads.  Returns the elastic eigenfrequencies (Hz,
    those above 1 Hz: the rigid modes of a free part dropped) from job.dat and the wall time of ccx (s);
    RuntimeError with the tail of ccx's output when it fails."""
    env = {**os.environ, "OMP_NUM_THREADS": str(THREADS), "CCX_NPROC_EQUATION_SOLVER": str(THREADS)}
    t0 = time.perf_counter()
    proc = subprocess.run(["ccx", "-i", job], cwd=workdir, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - t0
    if proc.returncode != 0 or not (workdir / f"{job}.dat").exists():
        raise RuntimeError(f"ccx failed: {proc.stdout[-2000:]}")
    freqs = parse_calculix_frequencies(workdir / f"{job}.dat")
    return freqs[freqs > 1.0], wall


def parse_calculix_frequencies(dat: Path) -> np.ndarray:
    """Eigenfrequencies (Hz, column CYCLES/TIME) from a ccx .dat file."""
    freqs, reading = [], False
    for line in dat.read_text().splitlines():
        if "E I G E N V A L U E   O U T P U T" in line:
            reading, freqs = True, []
            continue
        if reading:
            parts = line.split()
            if len(parts) >= 4 and parts[0].isdigit():
                freqs.append(float(parts[3]))
            elif freqs and not parts:
                reading = False
    return np.array(freqs)
