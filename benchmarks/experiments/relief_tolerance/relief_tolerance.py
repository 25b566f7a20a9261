"""Sensitivity: the double-helical torque law L_WA(2000) - L_WA(1000 N m) with the tip-relief amounts varied by
one ISO 1328-1:1995 grade-5 profile slope tolerance f_Halpha per gear (common to all teeth; relief lengths kept).

Appendix F's reliefs (pinion 20 um over 2.2 mm, wheel 42 um over 3.3 mm) are the nominal; f_Halpha from
housingfe.source.as_made.iso1328_tolerances (m_n = 3.5 mm, d = 100.159 / 300.476 mm): 5.0 um (pinion), 6.5 um
(wheel).  Grid: pinion 20 - f, 20, 20 + f x wheel 42 - f, 42, 42 + f um.  Nothing is tuned: the default stays.

The amounts are changed where the gear set is built (housingfe.source.roosmalen.run.build, patched in the experiment
only), so the source (stiffness curve, load share, engagement shock) AND the coupled model's mean mesh stiffness
(GearSet -> Drivetrain.gear_forces) follow them: a relief off by its tolerance is the same as-made gear in the
source and in the structure.  --mean-stiffness keep patches OperatingPoint instead (the source only, as
torque_law/loaded_te_runup.py --variant unrelieved), the coupled model keeping Appendix F's mean stiffness.

    PYTHONPATH=. .venv/bin/python benchmarks/experiments/relief_tolerance/relief_tolerance.py
        [--bearings cylindrical_roller] [--variants all|p0w0,p+w-,...] [--out /tmp/relief-runs]
    (one run-up per variant, about 35-45 s each on one core, each in its own process; writes relief_tolerance.csv
    beside this script and relief_tolerance.png; --single P_UM W_UM runs one variant in this process)
"""
from __future__ import annotations

import argparse
import csv
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]
sys.path.insert(0, str(HERE.parent / "torque_law"))
from loaded_te_runup import torque_law  # noqa: E402  (the torque_law experiment's reader, reused)

NOMINAL_UM = (20.0, 42.0)                   # Appendix F, ../shared reference [gears.double_helical] tip_relief
MEASURED_DB = {"cylindrical_roller": 3.4, "fluid_film": 2.7}      # thesis Sec. 5.9
SIGNS = {"-": -1, "0": 0, "+": 1}


def profile_slope_tolerances() -> tuple[float, float]:
    """f_Halpha (um) of ISO 1328-1:1995 grade 5 for the double-helical pinion and wheel (Appendix F geometry)."""
    from housingfe.source.as_made import iso1328_tolerances

    return tuple(iso1328_tolerances(3.5e-3, d, b)["f_Halpha"] * 1e6
                 for d, b in ((100.159e-3, 25e-3), (300.476e-3, 23e-3)))


def amounts(variant: str) -> tuple[float, float]:
    """'p+w-' -> (pinion, wheel) relief amount (um)."""
    f = profile_slope_tolerances()
    return NOMINAL_UM[0] + SIGNS[variant[1]] * f[0], NOMINAL_UM[1] + SIGNS[variant[3]] * f[1]


def patch_amounts(pinion_um: float, wheel_um: float, mean_stiffness: str = "follow"):
    """Replace the tip-relief amounts (lengths kept): 'follow' where the gear set is built (source and coupled mean
    stiffness), 'keep' in every new OperatingPoint only (the source)."""
    from dataclasses import replace

    from housingfe.source.roosmalen import run as roosmalen

    def modified(corr):
        return replace(corr, tip_relief=(pinion_um * 1e-6, wheel_um * 1e-6))

    if mean_stiffness == "follow":
        original = roosmalen.build

        def build(table, scene_path="scene"):
            pair, corr, geometry, interior, model = original(table, scene_path)
            if pair.kind != "double_helical":
                return pair, corr, geometry, interior, model
            corr = modified(corr)
            return pair, corr, geometry, interior, replace(model, corrections=corr)

        build.__wrapped__ = original            # lets a caller (the test) undo the patch
        roosmalen.build = build
    else:
        original_init = roosmalen.OperatingPoint.__init__

        def init(self, pair, corr, interior, model, torque, n_positions, n_samples=256, **kw):
            c = modified(corr)
            original_init(self, pair, c, interior, replace(model, corrections=c), torque, n_positions, n_samples,
                          **kw)

        roosmalen.OperatingPoint.__init__ = init


def mean_levels(folder: Path) -> dict:
    """{route: (mean L_WA at 1000, at 2000 N m)} over 800-1500 rpm, dB(A), first radiator (as torque_law)."""
    rows = list(csv.DictReader(open(folder / "runup.csv")))
    rad = rows[0]["radiation"]
    out = {}
    for route in sorted({r["route"] for r in rows}):
        out[route] = tuple(float(np.mean([float(r["LwA_dB"]) for r in rows if r["route"] == route
                                          and r["radiation"] == rad and r["torque_nm"] == t
                                          and 800.0 <= float(r["speed_rpm"]) <= 1500.0])) for t in ("1000", "2000"))
    return out


def run_single(pinion_um: float, wheel_um: float, bearings: str, out: Path, mean_stiffness: str):
    patch_amounts(pinion_um, wheel_um, mean_stiffness)
    from housingfe.run import run_scene

    run_scene("test-gearbox-runup-double-helical", str(out),
              ["runup.torques_nm=[1000.0,2000.0]", f"drivetrain.bearings={bearings}"])


def excitation_minimum(variants, torques=tuple(range(500, 2751, 250)), harmonics=(4, 5)) -> list[dict]:
    """The chain's quasi-static excitation k_m |d_qs,n| (N; torque_law/decompose.py's exc_chain_N) at the 4th-5th
    tooth harmonics over the torque, per variant, and where it is smallest relative to a linear law (|d_qs,n| / T):
    is 1000 N m still near the reliefs' minimum?  Source only (rollers; seconds per torque)."""
    from decompose import amplitudes, source_of

    from housingfe.source.roosmalen import dynamics as dyn
    from housingfe.source.roosmalen import run as roosmalen

    rows = []
    original = roosmalen.build
    for v in variants:
        roosmalen.build = original
        patch_amounts(*amounts(v))
        src = source_of("double_helical", "cylindrical_roller", unrelieved=False)
        for t in torques:
            op = src._point(float(t))
            d_qs = dyn.quasi_static_compression(op.S, op.shock, op.normal_force)
            exc = float(op.S.mean()) * amplitudes(d_qs)
            rows.append({"variant": v, "torque_nm": t, **{f"exc_n{n}_N": round(float(exc[n]), 2) for n in harmonics}})
    roosmalen.build = original
    return rows


def plot(rows: list[dict], path: Path, f: tuple[float, float]):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
    for ax, route in zip(axes, ("tf_omega", "mesh_force")):
        for bearings, marker in (("cylindrical_roller", "o"), ("fluid_film", "s")):
            sel = [r for r in rows if r["bearings"] == bearings]
            for w in sorted({r["wheel_um"] for r in sel}):
                colour = {-1: "C0", 0: "C1", 1: "C2"}[int(np.sign(round(w - NOMINAL_UM[1], 6)))]
                pts = sorted((r["pinion_um"], r[f"torque_law_{route}_dB"]) for r in sel if r["wheel_um"] == w)
                ax.plot(*zip(*pts), marker=marker, ls="-" if bearings == "cylindrical_roller" else ":",
                        color=colour, label=f"{bearings}, wheel {w:g} um")
            if sel:
                ax.axhline(MEASURED_DB[bearings], color="k", ls="-" if bearings == "cylindrical_roller" else ":",
                           lw=0.8, label=f"measured ({bearings})")
        ax.set_title(f"{route}")
        ax.set_xlabel(f"pinion tip relief (um), +-f_Halpha = {f[0]:g} um")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("L_WA(2000) - L_WA(1000 N m) (dB(A))\nmean 800-1500 rpm")
    axes[1].legend(fontsize=7)
    fig.suptitle(f"Double helical torque law vs tip-relief amounts (wheel +-f_Halpha = {f[1]:g} um)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bearings", default="cylindrical_roller")
    ap.add_argument("--variants", default="all", help="all or comma-separated of p[-0+]w[-0+]")
    ap.add_argument("--out", default="/tmp/relief-runs")
    ap.add_argument("--mean-stiffness", choices=("follow", "keep"), default="follow")
    ap.add_argument("--csv", default=str(HERE / "relief_tolerance.csv"))
    ap.add_argument("--single", nargs=2, type=float, metavar=("PINION_UM", "WHEEL_UM"))
    ap.add_argument("--minimum", action="store_true",
                    help="only the source's n = 4-5 excitation over 500-2750 N m for p0w0, p-w+, p+w- "
                         "(relief_minimum.csv): where is its minimum relative to a linear law?")
    ap.add_argument("--plot-only", action="store_true", help="redraw the PNG from the CSV")
    args = ap.parse_args(argv)
    f = profile_slope_tolerances()
    if args.single:
        run_single(*args.single, args.bearings, Path(args.out), args.mean_stiffness)
        return 0
    if args.minimum:
        rows = excitation_minimum(["p0w0", "p-w+", "p+w-"])
        with open(HERE / "relief_minimum.csv", "w", newline="") as fh:
            wr = csv.DictWriter(fh, fieldnames=list(rows[0]))
            wr.writeheader()
            wr.writerows(rows)
        for v in dict.fromkeys(r["variant"] for r in rows):
            sel = [r for r in rows if r["variant"] == v]
            for key in ("exc_n4_N", "exc_n5_N"):
                rel = [r[key] / r["torque_nm"] for r in sel]
                t_min = sel[int(np.argmin(rel))]["torque_nm"]
                law = 20 * np.log10(next(r[key] for r in sel if r["torque_nm"] == 2000)
                                    / next(r[key] for r in sel if r["torque_nm"] == 1000))
                print(f"{v:5s} {key}: " + " ".join(f"{r[key]:.0f}" for r in sel)
                      + f" N at {sel[0]['torque_nm']}..{sel[-1]['torque_nm']} N m; smallest relative to linear at "
                      f"{t_min} N m; 1000 -> 2000 N m {law:+.1f} dB")
        return 0
    csv_path = Path(args.csv)
    old = list(csv.DictReader(open(csv_path))) if csv_path.exists() else []
    if not args.plot_only:
        variants = ([f"p{a}w{b}" for a in "-0+" for b in "-0+"] if args.variants == "all"
                    else args.variants.split(","))
        for v in variants:
            p, w = amounts(v)
            tag = "" if args.mean_stiffness == "follow" else "-keep"
            out = Path(args.out) / args.bearings / (v + tag)
            t0 = time.perf_counter()
            env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
            subprocess.run([sys.executable, __file__, "--single", str(p), str(w), "--bearings", args.bearings,
                            "--out", str(out), "--mean-stiffness", args.mean_stiffness], check=True, env=env,
                           stdout=subprocess.DEVNULL)
            seconds = time.perf_counter() - t0
            law = {r["route"]: r["step_mean_dB"] for r in torque_law(out)}
            lw = mean_levels(out)
            row = {"variant": v + tag, "bearings": args.bearings, "pinion_um": p, "wheel_um": w}
            for route in ("tf_omega", "mesh_force"):
                row[f"torque_law_{route}_dB"] = round(law[route], 3)
            for route in ("tf_omega", "mesh_force"):
                row[f"LwA_1000_{route}_dB"] = round(lw[route][0], 2)
                row[f"LwA_2000_{route}_dB"] = round(lw[route][1], 2)
            row["seconds"] = round(seconds, 1)
            old = [r for r in old if not (r["variant"] == row["variant"] and r["bearings"] == row["bearings"])]
            old.append(row)
            print(f"{row['variant']:9s} {args.bearings:18s} pinion {p:5.1f} wheel {w:5.1f} um: torque law "
                  f"tf_omega {law['tf_omega']:+.2f}, mesh_force {law['mesh_force']:+.2f} dB(A)  ({seconds:.0f} s)",
                  flush=True)
            with open(csv_path, "w", newline="") as fh:
                wr = csv.DictWriter(fh, fieldnames=list(row))
                wr.writeheader()
                wr.writerows(old)
    rows = [{k: (v if k in ("variant", "bearings") else float(v)) for k, v in r.items()}
            for r in csv.DictReader(open(csv_path))]
    plot([r for r in rows if not r["variant"].endswith("-keep")], csv_path.with_suffix(".png"), f)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
