"""`housingfe bench mpi`: strong scaling of the modal solve and of the harmonic sweep, 1 against 2 MPI ranks.

The model: the box-free-frf scene (two forces, 819 lines of 4.88 Hz to 4 kHz, modal superposition with residual
vectors on a basis to 6 kHz) on a Q3 hexahedral mesh graded towards the wall junctions, h = 12.5 mm: 309 k DOFs
(--quick: 30 mm, ~60 k).  Each run is `mpirun -n R python -m housingfe run box-free-frf ...` in a fresh process;
the 1- and 2-rank runs alternate, ROUNDS rounds, and the table gives min / median / max of every phase with the
1-minute load average before each run.  Phases (from harmonic.json): modal solve = inertia count + Krylov-Schur
to 6 kHz; harmonic sweep = the superposition of all lines for both loads after the modes (residual vectors
included); the rest is start-up, meshing, assembly, observers and result files.  Memory: peak resident set of
every rank, summed, per DOF.  Same answer: the band levels of the two runs are compared (max |dB| difference).
"""
from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from housingfe.benchmarks._launch import mpi_environment, mpi_launcher
from housingfe.outputs import atomic_output_dir, dumps_json, format_table, write_csv

SCENE = "box-free-frf"
MESH = ["mesh.degree=3", "mesh.grading=0.25", "output.pictures=false"]
SIZE, QUICK_SIZE = 0.0125, 0.030       # m: 309 108 and 59 952 DOFs
RANKS = (1, 2)
ROUNDS, QUICK_ROUNDS = 3, 1

_CHILD = """
import resource, sys
from mpi4py import MPI
from housingfe.run import run_scene
run_scene(sys.argv[1], sys.argv[2], sys.argv[3:])
peak = MPI.COMM_WORLD.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
if MPI.COMM_WORLD.rank == 0:
    print("PEAK_KB", peak)
"""


def run_case(ranks: int, size: float) -> dict:
    """One run of the scene on `ranks` ranks: phase timings (s), DOFs, summed peak memory (GB), band levels."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "run"
        t0 = time.perf_counter()
        proc = subprocess.run(mpi_launcher(ranks) + [sys.executable, "-c", _CHILD, SCENE, str(out), *MESH,
                                          f"mesh.size={size}"], capture_output=True, text=True,
                              env=mpi_environment())
        wall = time.perf_counter() - t0
        if proc.returncode != 0:
            raise RuntimeError(f"{ranks} rank(s): {proc.stderr.strip()[-800:]}")
        peak_kb = int(next(line.split()[1] for line in proc.stdout.splitlines() if line.startswith("PEAK_KB")))
        info = json.loads((out / "harmonic.json").read_text())
        bands = (out / "octave_bands.csv").read_text()
    t = info["timings_s"]
    modal = t["modal_eigensolve_s"]
    # the superposition's own key is its solver name: modal_s or modal+residual_s (it includes the eigensolve)
    total = next(v for k, v in t.items() if k.startswith("modal") and k != "modal_eigensolve_s")
    sweep = total - modal
    return {"wall_s": wall, "modal_solve_s": modal, "sweep_s": sweep, "dofs": info.get("dofs"),
            "peak_memory_gb": peak_kb / 1024**2, "bands": bands, "timings": t}


def band_difference_db(a: str, b: str) -> float:
    """Max |difference| of the numeric columns (dB) of two octave_bands.csv texts."""
    rows_a = [line.split(",") for line in a.strip().splitlines()[1:]]
    rows_b = [line.split(",") for line in b.strip().splitlines()[1:]]
    worst = 0.0
    for ra, rb in zip(rows_a, rows_b):
        for x, y in zip(ra, rb):
            try:
                worst = max(worst, abs(float(x) - float(y)))
            except ValueError:
                continue
    return worst


def main(out_dir: Path, quick: bool = False, resume: bool = False) -> None:
    """Alternate 1- and 2-rank runs, print the scaling table, write mpi_bench.csv/.txt/.png.  Every finished run is
    kept in <out>.partial/ until the result folder is written; resume: re-use them."""
    from housingfe.benchmarks._runs import FinishedRuns

    size = QUICK_SIZE if quick else SIZE
    rounds = QUICK_ROUNDS if quick else ROUNDS
    runs: dict[int, list] = {r: [] for r in RANKS}
    finished = FinishedRuns("mpi", out_dir, {"scene": SCENE, "mesh": MESH, "size": size, "rounds": rounds,
                                             "ranks": RANKS}, rounds * len(RANKS), resume=resume)

    def one_run(ranks: int) -> dict:
        load = os.getloadavg()[0]
        return {**run_case(ranks, size), "load_before": load}

    try:
        for rnd in range(rounds):
            for ranks in RANKS:
                res = finished.run(f"round {rnd + 1} {ranks} rank(s)", lambda: one_run(ranks),
                                   note=f"{ranks} rank(s)")
                runs[ranks].append(res)
                finished.write(f"round {rnd + 1}/{rounds}  {ranks} rank(s)  dofs {res['dofs']}  wall "
                               f"{res['wall_s']:.1f} s  modal solve {res['modal_solve_s']:.1f} s  sweep "
                               f"{res['sweep_s']:.2f} s  load before {res['load_before']:.2f}")
    except BaseException as exc:
        finished.interrupted(exc)
        raise
    finished.close()
    header = ["ranks", "dofs", "phase", "min_s", "median_s", "max_s", "speedup_median", "peak_memory_gb",
              "bytes_per_dof", "max_load_before"]
    rows = []
    base = {}
    for ranks in RANKS:
        rs = runs[ranks]
        for phase in ("modal_solve_s", "sweep_s", "wall_s"):
            values = [r[phase] for r in rs]
            med = statistics.median(values)
            base.setdefault(phase, med)
            mem = max(r["peak_memory_gb"] for r in rs)
            rows.append([ranks, rs[0]["dofs"], phase[:-2], min(values), med, max(values), base[phase] / med, mem,
                         mem * 1024**3 / rs[0]["dofs"], max(r["load_before"] for r in rs)])
    same = band_difference_db(runs[1][0]["bands"], runs[2][0]["bands"])
    note = (f"{rounds} alternating round(s); highest 1-min load average before a run "
            f"{max(r[-1] for r in rows):.2f} on 2 cores; octave-band levels 1 vs 2 ranks differ by at most "
            f"{same:.2e} dB")
    table = format_table(header, rows)
    with atomic_output_dir(out_dir) as tmp:
        write_csv(tmp / "mpi_bench.csv", header, rows)
        (tmp / "mpi_bench.txt").write_text(table + "\n" + note + "\n")
        (tmp / "timings.json").write_text(dumps_json({str(k): [r["timings"] for r in v] for k, v in runs.items()},
                                                     indent=1))
        _plot(tmp / "mpi_bench.png", rows)
    finished.finish()
    print(table)
    print(note)
    print(f"results: {out_dir}/")


def _plot(path: Path, rows: list) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 4))
    phases = ["modal_solve", "sweep", "wall"]
    x = np.arange(len(phases))
    for k, ranks in enumerate(RANKS):
        med = [next(r[4] for r in rows if r[0] == ranks and r[2] == p) for p in phases]
        ax.bar(x + 0.38 * k, med, 0.38, label=f"{ranks} rank(s)")
    ax.set_xticks(x + 0.19, phases)
    ax.set_ylabel("median wall time (s)")
    ax.set_title(f"strong scaling, {rows[0][1]} DOFs")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
