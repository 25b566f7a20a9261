"""`housingfe bench frf`: forced response of the free box (scene box-free-frf), speed against band error.

Accuracy: every modal variant (basis up to 1.0 / 1.5 / 2.0 x f_max, with and without residual flexibility)
against the direct solution on every line, 1/3-octave bands 100 Hz .. f_max.  The direct sweep over all
820 lines costs one 2N x 2N factorisation per line, so the accuracy study uses the 40 mm hex mesh
(same physics, fewer DOFs); the speed study uses the scene's default mesh.
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from housingfe.outputs import atomic_output_dir, format_table, write_csv

VARIANTS = [(1.0, False), (1.0, True), (1.5, False), (1.5, True), (2.0, False), (2.0, True)]


def _model(overrides):
    from mpi4py import MPI

    from housingfe.scene import build_model_from_scene, load_housing_scene

    scene, _ = load_housing_scene("box-free-frf", overrides)
    return scene, build_model_from_scene(scene, MPI.COMM_WORLD)


def _bands(resp, f_lo, f_hi):
    from housingfe.response.observers import transfer_band_levels

    bands, _, tf = transfer_band_levels(resp, f_lo, f_hi)
    return bands, tf


def accuracy_study(quick: bool) -> tuple[list, dict]:
    """Band TF of every modal variant minus direct (dB), per load case and band."""
    from housingfe.fe.loads import assemble_load
    from housingfe.response.forced import damping_model
    from housingfe.response.observers import SurfaceObserver, responses
    from housingfe.solvers import harmonic, modal

    df = 19.52 if quick else 4.88
    scene, model = _model(["mesh.size=0.04", f"analysis.harmonic.df={df}", f"analysis.harmonic.f_min={df}"])
    spec = scene.analysis.harmonic
    loads = [assemble_load(load, model.housing, model.V, model.bcs) for load in scene.loads]
    observer = SurfaceObserver(model, spec.surface, [], loads)
    damping = damping_model(scene.damping, model)
    freqs = spec.frequencies
    t0 = time.perf_counter()
    direct = responses(harmonic.direct(model.K, model.M, loads, freqs, damping, observer.reduce), observer, loads)
    t_direct = time.perf_counter() - t0
    rows, curves = [], {}
    for factor, residual in VARIANTS:
        t0 = time.perf_counter()
        # as the product runs it: the residual vectors reuse the eigensolve's factorisation
        modes = modal.solve_modes(model.K, model.M, factor * spec.f_max, keep_solver=residual)
        t_modes = time.perf_counter() - t0
        t0 = time.perf_counter()
        res = harmonic.modal_superposition(model.K, model.M, modes, loads, freqs, damping, observer.reduce,
                                           residual=residual)
        modes.release_solver()
        resp = responses(res, observer, loads)
        t_sup = time.perf_counter() - t0
        diffs = []
        for j in range(len(loads)):
            bands, tf_m = _bands(resp[j], 100.0, spec.f_max)
            _, tf_d = _bands(direct[j], 100.0, spec.f_max)
            diffs.append(tf_m - tf_d)
            curves[(factor, residual, loads[j].name)] = (bands.nominal, tf_m - tf_d)
        d = np.concatenate(diffs)
        rows.append([f"modal {factor:g}x f_max" + (" + residual" if residual else ""), model.dofs, len(freqs),
                     len(modes.eigenvalues) - modes.rigid_count, t_modes, t_sup,
                     float(np.max(np.abs(d))), float(np.min(d))])
    rows.append(["direct (auto: complex workers, one per core, MUMPS)", model.dofs, len(freqs), 0, 0.0, t_direct, 0.0, 0.0])
    return rows, curves


def speed_study(quick: bool) -> list:
    """Wall times on the default mesh: eigensolve, 820-line modal + residual sweep, direct per line."""
    from housingfe.fe.loads import assemble_load
    from housingfe.response.forced import damping_model
    from housingfe.response.observers import SurfaceObserver, responses
    from housingfe.solvers import harmonic, modal

    scene, model = _model([])
    spec = scene.analysis.harmonic
    loads = [assemble_load(load, model.housing, model.V, model.bcs) for load in scene.loads]
    t0 = time.perf_counter()
    observer = SurfaceObserver(model, spec.surface, spec.sample_points, loads)
    t_obs = time.perf_counter() - t0
    damping = damping_model(scene.damping, model)
    freqs = spec.frequencies
    t0 = time.perf_counter()
    modes = modal.solve_modes(model.K, model.M, spec.modal_basis_factor * spec.f_max, keep_solver=True)
    t_modes = time.perf_counter() - t0
    t0 = time.perf_counter()
    responses(harmonic.modal_superposition(model.K, model.M, modes, loads, freqs, damping, observer.reduce),
              observer, loads)
    t_sup = time.perf_counter() - t0
    modes.release_solver()
    n_direct = 2 if quick else 5
    sub = freqs[:: max(1, len(freqs) // n_direct)][:n_direct]
    t0 = time.perf_counter()
    harmonic.direct(model.K, model.M, loads, sub, damping, observer.reduce)
    per_line = (time.perf_counter() - t0) / len(sub)
    return [
        ["default mesh DOFs", model.dofs, ""],
        ["lines x load cases", f"{len(freqs)} x {len(loads)}", ""],
        ["surface operator + sample points", t_obs, "s"],
        [f"eigensolve to {spec.modal_basis_factor:g} x f_max ({len(modes.eigenvalues)} modes)", t_modes, "s"],
        ["modal + residual sweep, all lines and loads (after the modes)", t_sup, "s"],
        [f"direct, per line (both loads; {len(sub)} lines, the workers' start included)", per_line, "s"],
        ["direct, full sweep (extrapolated)", per_line * len(freqs), "s"],
    ]


def main(out_dir: Path, quick: bool = False) -> None:
    """Run both studies; print the tables; write frf_bench.csv, frf_speed.csv and frf_bench.png."""
    acc_rows, curves = accuracy_study(quick)
    acc_header = ["solver", "dofs", "lines", "modes_in_basis", "eigensolve_s", "sweep_s", "max_abs_band_error_dB",
                  "min_band_error_dB"]
    print(format_table(acc_header, acc_rows))
    speed_rows = speed_study(quick)
    print(format_table(["quantity", "value", "unit"], speed_rows))
    with atomic_output_dir(out_dir) as tmp:
        write_csv(tmp / "frf_bench.csv", acc_header, acc_rows)
        write_csv(tmp / "frf_speed.csv", ["quantity", "value", "unit"], speed_rows)
        (tmp / "frf_bench.txt").write_text(format_table(acc_header, acc_rows) + "\n\n"
                                           + format_table(["quantity", "value", "unit"], speed_rows) + "\n")
        _plot(tmp / "frf_bench.png", curves)
    print(f"results: {out_dir}/")


def _plot(path: Path, curves: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = sorted({k[2] for k in curves})
    fig, axes = plt.subplots(1, len(names), figsize=(6 * len(names), 4), squeeze=False)
    for ax, name in zip(axes[0], names):
        for (factor, residual, load), (nominal, d) in sorted(curves.items()):
            if load == name:
                ax.semilogx(nominal, d, "o-" if residual else "x--", ms=3,
                            label=f"{factor:g}x f_max" + (" + residual" if residual else ""))
        ax.axhline(0.5, color="grey", lw=0.6, ls=":")
        ax.axhline(-0.5, color="grey", lw=0.6, ls=":")
        ax.set_xlabel("1/3-octave band (Hz)")
        ax.set_ylabel("TF modal - TF direct (dB)")
        ax.set_title(f"free box, force {name}")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
