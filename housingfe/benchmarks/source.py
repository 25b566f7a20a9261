"""`housingfe bench source`: speed next to error for the gear source models.

Rows (van Roosmalen Ch. 2 model, gear set A, T1 = 2000 N m):
  - one tooth-stiffness curve (the thesis: "a few minutes" in 1994) at several discretisations, error of
    the mean stiffness and of the stiffness amplitude against a fine reference;
  - the periodic steady state at 1500 rpm by harmonic balance (H harmonics) and by explicit time
    integration (RK45, P mesh periods from the static state), error of the first five wheel
    angular-velocity harmonics against harmonic balance with H = 80;
  - a 30-speed run-up (50-1500 rpm) by harmonic balance, error against H = 80;
plus the rows the Fukuma / Trueman modules offer through their `bench_rows(quick)`.
Run with `housingfe bench source` or `python -m housingfe.benchmarks.source [--quick] [out_dir]`.
"""
from __future__ import annotations

import importlib
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

from housingfe.outputs import atomic_output_dir, format_table, write_csv
from housingfe.source.roosmalen import dynamics as dyn
from housingfe.source.roosmalen.run import OperatingPoint, build, parse

SCENE = Path(__file__).resolve().parent.parent / "scenes" / "gearset-A.toml"


def _setup(slices: int):
    scene = tomllib.loads(SCENE.read_text())
    scene["source"]["slices"] = slices
    table = parse(scene, str(SCENE))
    return table, build(table, str(SCENE))


def _harmonics(state: dyn.SteadyState, n: int = 5) -> np.ndarray:
    """First n one-sided wheel angular-velocity amplitudes; harmonics beyond H count as zero."""
    a = state.wheel_angular_velocity()[1][:n]
    return np.pad(a, (0, n - a.size))


def _rel_err(a: np.ndarray, ref: np.ndarray) -> float:
    return float(np.max(np.abs(a - ref)) / np.max(np.abs(ref)))


def _curve_error(curve, ref) -> float:
    """Relative error of the mean stiffness and of its first three Fourier harmonics (relative to the
    first harmonic of the reference): the quantities the dynamics uses.  (Max - min is not used: with
    tip relief the loaded contact edge falls between points and adds +-0.1 % wiggles.)"""
    X, R = curve.fourier(), ref.fourier()
    harm = np.max(np.abs(X[1:4] - R[1:4])) / abs(R[1])
    return float(max(abs(curve.mean / ref.mean - 1), harm))


def stiffness_rows(quick: bool) -> list[dict]:
    """Time of one stiffness curve against its discretisation error."""
    from housingfe.source.stiffness import normal_force_from_torque, stiffness_curve, weber_banaschek

    rows = []
    ref_slices, ref_positions = (24, 32) if quick else (48, 64)
    _, (pair, _, _, _, ref_model) = _setup(ref_slices)
    force = normal_force_from_torque(pair, 2000.0)
    ref = stiffness_curve(ref_model, force, ref_positions)
    for slices, positions in ((8, 16), (16, 32)) if quick else ((8, 16), (16, 32), (24, 32), (32, 64)):
        weber_banaschek.cache_clear()          # time the whole set-up, tooth profiles included
        t0 = time.perf_counter()
        _, (pair, _, _, _, model) = _setup(slices)
        curve = stiffness_curve(model, force, positions)
        wall = time.perf_counter() - t0
        rows.append({"case": f"stiffness curve, {slices} slices x {positions} positions", "wall_s": wall,
                     "error": _curve_error(curve, ref),
                     "note": f"mean, harmonics 1-3 vs {ref_slices} x {ref_positions} (incl. model set-up)"})
    return rows


def dynamics_rows(quick: bool) -> list[dict]:
    """Harmonic balance against explicit time integration at equal accuracy; 30-speed run-up."""
    table, (pair, corr, geometry, interior, model) = _setup(16)
    op = OperatingPoint(pair, corr, interior, model, 2000.0, 32)
    rpm = 1500.0
    ref = _harmonics(op.steady_state(pair, rpm, 80))
    rows = []
    for H in (3, 5, 10, 20, 40):
        t0 = time.perf_counter()
        st = op.steady_state(pair, rpm, H)
        wall = time.perf_counter() - t0
        rows.append({"case": f"steady state 1500 rpm, harmonic balance H = {H}", "wall_s": wall,
                     "error": _rel_err(_harmonics(st), ref), "note": "wheel omega harmonics 1-5 vs H = 80"})
    ft = pair.tooth_frequency(rpm)
    n = op.S.size
    for periods in ((25, 100) if quick else (25, 50, 100, 200, 400)):
        t0 = time.perf_counter()
        times, q = dyn.time_integration(op.mats, op.S, op.shock, op.f0, ft, periods, samples_per_period=n,
                                        rtol=1e-7, method="RK45")
        wall = time.perf_counter() - t0
        Q = np.fft.fft(q[:, dyn.WHEEL_THETA_Z]) / n
        k = np.arange(1, 6)
        omega = 2 * 1j * 2 * np.pi * ft * k * Q[k]
        rows.append({"case": f"steady state 1500 rpm, RK45 time integration {periods} periods", "wall_s": wall,
                     "error": _rel_err(omega, ref), "note": "same error measure, from the static state"})
    speeds = np.linspace(50.0, 1500.0, 30)
    t0 = time.perf_counter()
    levels = np.array([dyn.tooth_band_level(op.steady_state(pair, s, 20)) for s in speeds])
    wall = time.perf_counter() - t0
    ref_levels = np.array([dyn.tooth_band_level(op.steady_state(pair, s, 80)) for s in speeds])
    rows.append({"case": "30-speed run-up 50-1500 rpm, harmonic balance H = 20", "wall_s": wall,
                 "error": float(np.max(np.abs(levels - ref_levels))),
                 "note": "error in dB (tooth band) vs H = 80; stiffness curve excluded"})
    return rows


def other_rows(quick: bool) -> list[dict]:
    """Rows of the Fukuma / Trueman modules, if they provide `bench_rows(quick)`."""
    rows = []
    for name in ("housingfe.source.fukuma.run", "housingfe.source.trueman.run"):
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError:
            continue
        if hasattr(module, "bench_rows"):
            rows += module.bench_rows(quick)
    return rows


def main(out_dir: Path, quick: bool) -> None:
    """Run the source benchmark; print a table and write bench_source.csv and bench_source.png."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out_dir = Path(out_dir)
    rows = stiffness_rows(quick) + dynamics_rows(quick) + other_rows(quick)
    header = ["case", "wall_s", "error", "note"]
    table = [[r["case"], float(r["wall_s"]), float(r["error"]), r.get("note", "")] for r in rows]
    print(format_table(header, table, floatfmt="{:.3g}"))
    with atomic_output_dir(out_dir) as tmp:     # a result folder (docs/outputs.md)
        write_csv(tmp / "bench_source.csv", header, table)
        fig, ax = plt.subplots(figsize=(8, 5))
        for label, key in (("stiffness curve", "stiffness curve"), ("harmonic balance", "harmonic balance"),
                           ("time integration", "time integration"), ("run-up", "run-up")):
            sel = [r for r in rows if key in r["case"]]
            if sel:
                ax.loglog([r["wall_s"] for r in sel], [max(r["error"], 1e-16) for r in sel], "o-", label=label)
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("error (relative; run-up in dB)")
        ax.set_title("housingfe bench source: van Roosmalen gear set A, 2000 N m")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(tmp / "bench_source.png", dpi=120)
        plt.close(fig)
    print(f"results: {out_dir}/")


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--quick"]
    main(Path(args[0]) if args else Path("results/bench-source"), quick="--quick" in sys.argv)
