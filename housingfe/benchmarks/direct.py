"""`housingfe bench direct`: the direct harmonic solver (non-proportional damping), complex worker against the real
2x2 block form, per line; both on one core, then with every core each: the complex form with one worker per core
and the block form on as many MPI ranks (a child `mpirun` of this module with --block-child).

Model: box-free-frf on its default mesh (Q2 hexahedra, 38 997 DOFs), both load cases, eta per band.  The two forms
solve the same LINES consecutive lines (4.88 Hz apart around 1.5 kHz), interleaved block, complex, block, complex, ...
ROUNDS rounds each; wall time per line (the worker's start, the hand-over of the matrices and the ordering are
inside: they are paid once per call) with min / median / max, and the largest relative difference of the two
forms' responses (the same equations, so round-off only).
"""
from __future__ import annotations

import os
import statistics
import time
from pathlib import Path

import numpy as np

from housingfe.outputs import atomic_output_dir, format_table, write_csv

LINES, QUICK_LINES = 20, 3
ROUNDS, QUICK_ROUNDS = 2, 1
F_START = 1469.0    # Hz: the lines measured in issue 16 (1469-1562 Hz)


def main(out_dir: Path, quick: bool = False) -> None:
    """Interleave the two forms, print the per-line table, write direct_bench.csv/.txt/.png."""
    from mpi4py import MPI

    from housingfe.fe.loads import assemble_load
    from housingfe.response.forced import damping_model
    from housingfe.response.observers import SurfaceObserver, responses
    from housingfe.scene import build_model_from_scene, load_housing_scene
    from housingfe.solvers import harmonic

    scene, _ = load_housing_scene("box-free-frf")
    model = build_model_from_scene(scene, MPI.COMM_WORLD)
    spec = scene.analysis.harmonic
    loads = [assemble_load(load, model.housing, model.V, model.bcs) for load in scene.loads]
    observer = SurfaceObserver(model, spec.surface, [], loads)
    damping = damping_model(scene.damping, model)
    n_lines = QUICK_LINES if quick else LINES
    freqs = F_START + spec.df * np.arange(n_lines)
    # the two forms on one core each, then the complex form with one worker per core (the lines are independent)
    forms = {"block": ("block", 1), "complex": ("complex", 1)}
    cores = harmonic.default_direct_workers(n_lines)
    if cores > 1:
        forms[f"complex x{cores} workers"] = ("complex", cores)
    if cores > 1:
        forms[f"block, {cores} MPI ranks"] = ("block-ranks", cores)
    from housingfe.progress import Progress

    times: dict[str, list] = {name: [] for name in forms}
    answers = {}
    rounds = QUICK_ROUNDS if quick else ROUNDS
    progress = Progress("bench direct", rounds * len(forms), "runs")
    for rnd in range(rounds):
        for method, (form, workers) in forms.items():
            load = os.getloadavg()[0]
            if form == "block-ranks":
                per_line, answers[method] = _block_on_ranks(workers, n_lines)
            else:
                t0 = time.perf_counter()
                res = harmonic.direct(model.K, model.M, loads, freqs, damping, observer.reduce, method=form,
                                      workers=workers)
                per_line = (time.perf_counter() - t0) / n_lines
                answers[method] = responses(res, observer, loads)
            times[method].append((per_line, load))
            progress.update(note=method)
            progress.write(f"round {rnd + 1}  {method:18s} {per_line:.3f} s per line  load before {load:.2f}",
                           lambda text: print(text, flush=True))
    progress.close()
    difference = max(_max_relative_difference(answers["block"], a) for m, a in answers.items() if m != "block")
    header = ["form", "dofs", "lines", "per_line_min_s", "per_line_median_s", "per_line_max_s", "runs",
              "max_load_before", "speedup_median"]
    base = statistics.median(t for t, _ in times["block"])
    rows = [[m, model.dofs, n_lines, min(t for t, _ in v), statistics.median(t for t, _ in v),
             max(t for t, _ in v), len(v), max(ld for _, ld in v), base / statistics.median(t for t, _ in v)]
            for m, v in times.items()]
    note = f"largest relative difference of the responses, every form vs block on one core: {difference:.1e}"
    table = format_table(header, rows)
    with atomic_output_dir(out_dir) as tmp:
        write_csv(tmp / "direct_bench.csv", header, rows)
        (tmp / "direct_bench.txt").write_text(table + "\n" + note + "\n")
        _plot(tmp / "direct_bench.png", rows)
    print(table)
    print(note)
    print(f"results: {out_dir}/")


def _block_on_ranks(ranks: int, n_lines: int) -> tuple[float, list]:
    """Wall time per line (s) of the block form on `ranks` MPI ranks, and its surface <v^2> per load: a child
    `mpirun -n ranks python -m housingfe.benchmarks.direct --block-child N FILE` (model built there, the direct
    call timed between barriers)."""
    import subprocess
    import sys
    import tempfile

    from housingfe.benchmarks._launch import mpi_environment, mpi_launcher

    with tempfile.TemporaryDirectory(prefix="housingfe-bench-direct-") as tmp:
        out = Path(tmp) / "block.npz"
        cmd = mpi_launcher(ranks) + [sys.executable, "-m", "housingfe.benchmarks.direct", "--block-child",
                                     str(n_lines), str(out)]
        proc = subprocess.run(cmd, env=mpi_environment(), capture_output=True, text=True)
        if proc.returncode != 0 or not out.exists():
            raise RuntimeError(f"block form on {ranks} ranks failed (exit {proc.returncode}): {proc.stderr[-500:]}")
        data = np.load(out)
        return float(data["per_line"]), [_MeanSquare(v) for v in data["msv"]]


class _MeanSquare:
    """A LoadResponse stand-in carrying only the surface <v^2> (the child run returns no receptances)."""

    def __init__(self, msv):
        self.mean_square_velocity = msv
        self.receptance = None


def _block_child(n_lines: int, out: str) -> None:
    """The block form on this process' MPI_COMM_WORLD; rank 0 writes per_line (s) and msv (loads x lines)."""
    from mpi4py import MPI

    from housingfe.fe.loads import assemble_load
    from housingfe.response.forced import damping_model
    from housingfe.response.observers import SurfaceObserver, responses
    from housingfe.scene import build_model_from_scene, load_housing_scene
    from housingfe.solvers import harmonic

    comm = MPI.COMM_WORLD
    scene, _ = load_housing_scene("box-free-frf")
    model = build_model_from_scene(scene, comm)
    spec = scene.analysis.harmonic
    loads = [assemble_load(load, model.housing, model.V, model.bcs) for load in scene.loads]
    observer = SurfaceObserver(model, spec.surface, [], loads)
    damping = damping_model(scene.damping, model)
    freqs = F_START + spec.df * np.arange(n_lines)
    comm.barrier()
    t0 = time.perf_counter()
    res = harmonic.direct(model.K, model.M, loads, freqs, damping, observer.reduce, method="block")
    answer = responses(res, observer, loads)
    comm.barrier()
    per_line = (time.perf_counter() - t0) / n_lines
    if comm.rank == 0:
        np.savez(out, per_line=per_line, msv=np.array([r.mean_square_velocity for r in answer]))


def _max_relative_difference(a: list, b: list) -> float:
    """Largest relative difference of the surface <v^2> and of the receptances of two lists of LoadResponses
    (receptances skipped where one side has none)."""
    worst = 0.0
    for ra, rb in zip(a, b):
        for xa, xb in ((ra.mean_square_velocity, rb.mean_square_velocity), (ra.receptance, rb.receptance)):
            if xa is None or xb is None:
                continue
            worst = max(worst, float(np.max(np.abs(xa - xb)) / np.max(np.abs(xa))))
    return worst


def _plot(path: Path, rows: list) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 3.5))
    med = [r[4] for r in rows]
    spread = [[m - r[3] for m, r in zip(med, rows)], [r[5] - m for m, r in zip(med, rows)]]
    ax.bar([r[0] for r in rows], med, yerr=spread, capsize=4)
    ax.set_ylabel("wall time per line (s)")
    ax.set_title(f"direct solver, {rows[0][1]} DOFs, both loads")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    import sys

    if len(sys.argv) == 4 and sys.argv[1] == "--block-child":
        _block_child(int(sys.argv[2]), sys.argv[3])
    else:
        raise SystemExit("usage: python -m housingfe.benchmarks.direct --block-child N_LINES OUT.npz "
                         "(the benchmark itself: housingfe bench direct)")
