"""Benchmark `bearings`: time per 6x6 bearing matrix (Newton + analytic Jacobian) next to the error of the
finite-difference Jacobian at several step sizes (and the time of one analytic K against one FD K); and, for the fluid-film solver, time per K/C pair next to the
eccentricity and stiffness error against a fine reference grid.

Writes bearings.csv, fluid_film.csv, bearings.png (FD error against step; fluid-film error against time) and
prints both tables.  `python -m housingfe.benchmarks.bearings --out DIR [--quick]` runs it without the CLI.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from housingfe.outputs import atomic_output_dir, format_table, write_csv

CASES = [  # (designation, model, load (Fx, Fy, Fz, Mx, My) [N, N m])
    ("SKF 6312", "lim-ball", (0.0, -10000.0, 4000.0, 0.0, 0.0)),
    ("SKF 6215", "lim-ball", (3000.0, -8000.0, 4000.0, 40.0, -25.0)),
    ("SKF 7316B", "lim-ball", (0.0, -10000.0, 4000.0, 0.0, 0.0)),
    ("SKF NJ316", "lim-roller", (0.0, -10000.0, 0.0, 0.0, 0.0)),
    ("SKF NJ316", "sliced-roller", (0.0, -10000.0, 0.0, 0.0, 0.0)),
    ("SKF 22219CC", "self-aligning", (0.0, -10000.0, 4000.0, 0.0, 0.0)),
]
FD_STEPS = (1e-2, 1e-4, 1e-6, 1e-8, 1e-10)
GRIDS = ((24, 8), (45, 12), (90, 24), (180, 48))
REFERENCE_GRID = (360, 96)


def _timed(fn, repeat: int):
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return out, best


def rolling_rows(quick: bool) -> list[list]:
    """One row per (case, FD step): Newton iterations, time per analytic matrix, time and error of FD."""
    from housingfe.bearings import (
        bearing_stiffness,
        finite_difference_stiffness,
        lookup,
        make_model,
        stiffness_at,
    )

    rows = []
    cases = CASES[:3] if quick else CASES
    repeat = 3 if quick else 20
    for designation, model, load in cases:
        res, t_solve = _timed(lambda d=designation, f=load, mo=model: bearing_stiffness(d, f, model=mo), repeat)
        m = make_model(lookup(designation), model)
        _, t_k = _timed(lambda m=m, q=res.displacement: stiffness_at(m, q), repeat)
        scale = np.max(np.abs(res.K))
        for step in FD_STEPS:
            fd, t_fd = _timed(lambda m=m, q=res.displacement, h=step: finite_difference_stiffness(m, q, rel_step=h),
                               repeat)
            rows.append([designation, model, res.iterations, round(t_solve * 1e3, 3), round(t_k * 1e3, 4), step,
                         round(t_fd * 1e3, 3), float(np.max(np.abs(fd - res.K)) / scale)])
    return rows


def fluid_film_rows(quick: bool) -> list[list]:
    """One row per grid: time per (eccentricity + K + C), eccentricity error, max relative K error."""
    from housingfe.bearings.fluid_film import JournalBearing, journal_bearing_coefficients

    bearing = JournalBearing(80.25e-3, 56e-3, 125e-6, 0.049)       # thesis Sec. 3.5 pinion bearing
    omega, load = 157.1, (0.0, -20763.0)
    grids = GRIDS[:2] if quick else GRIDS
    ref_grid = GRIDS[2] if quick else REFERENCE_GRID
    ref = journal_bearing_coefficients(bearing, omega, load, n_theta=ref_grid[0], n_z=ref_grid[1])
    idx = np.ix_([0, 1, 3, 4], [0, 1, 3, 4])
    rows = []
    for nt, nz in grids:
        res, t = _timed(lambda a=nt, b=nz: journal_bearing_coefficients(bearing, omega, load, n_theta=a, n_z=b), 1)
        k_err = np.max(np.abs(res.K[idx] - ref.K[idx]) / np.abs(np.diag(ref.K)[[0, 1, 3, 4]])[:, None])
        rows.append([f"{nt}x{nz}", round(t, 3), res.eccentricity_ratio,
                     abs(res.eccentricity_ratio - ref.eccentricity_ratio), float(k_err)])
    rows.append([f"{ref_grid[0]}x{ref_grid[1]} (reference)", float("nan"), ref.eccentricity_ratio, 0.0, 0.0])
    return rows


def _plot(path: Path, rolling: list[list], fluid: list[list]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    labels = sorted({(r[0], r[1]) for r in rolling}, key=lambda x: [(c[0], c[1]) for c in CASES].index(x))
    for name, model in labels:
        sel = [r for r in rolling if r[0] == name and r[1] == model]
        ax1.loglog([r[5] for r in sel], [max(r[7], 1e-17) for r in sel], "o-",
                   label=f"{name} {model} (Newton+K {sel[0][3]:.2g} ms; K {sel[0][4]:.2g} ms, FD {sel[0][6]:.2g} ms)")
    ax1.set_xlabel("finite-difference step (relative to the mean displacement)")
    ax1.set_ylabel("max |K_FD - K_analytic| / max |K|")
    ax1.set_title("Analytic Jacobian against finite differences")
    ax1.grid(True, which="both", alpha=0.3)
    ax1.legend(fontsize=6)
    sel = [r for r in fluid if not np.isnan(r[1])]
    ax2.loglog([r[1] for r in sel], [max(r[3], 1e-12) for r in sel], "o-", label="|eps - eps_ref|")
    ax2.loglog([r[1] for r in sel], [r[4] for r in sel], "s-", label="max rel. K error")
    for r in sel:
        ax2.annotate(r[0], (r[1], max(r[3], 1e-12)), fontsize=7)
    ax2.set_xlabel("time per eccentricity + K + C [s]")
    ax2.set_ylabel("error against the reference grid")
    ax2.set_title("Fluid film (Sec. 3.5 pinion bearing)")
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(out_dir: Path, quick: bool) -> None:
    """Run the benchmark; print the tables; write CSV + PNG into out_dir (atomically)."""
    rolling = rolling_rows(quick)
    fluid = fluid_film_rows(quick)
    head_r = ["bearing", "model", "newton_iter", "t_newton+K_ms", "t_K_analytic_ms", "fd_rel_step", "t_K_fd_ms",
              "fd_rel_error"]
    head_f = ["grid", "t_s", "eccentricity", "eps_error", "K_rel_error"]
    print(format_table(head_r, rolling, "{:.3g}"))
    print()
    print(format_table(head_f, fluid, "{:.4g}"))
    with atomic_output_dir(out_dir) as tmp:
        write_csv(tmp / "bearings.csv", head_r, rolling)
        write_csv(tmp / "fluid_film.csv", head_f, fluid)
        _plot(tmp / "bearings.png", rolling, fluid)
    print(f"results: {out_dir}/")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="results/bench-bearings")
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    main(Path(args.out), args.quick)
