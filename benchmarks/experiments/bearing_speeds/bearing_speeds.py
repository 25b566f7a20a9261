"""Fluid films over the run-up, fixed at 1500 rev/min against following the run-up's speed (runup.bearing_speeds).

    housingfe run test-gearbox-runup-double-helical --set 'drivetrain.bearings="fluid_film"' \
        --set 'runup.bearing_speeds="fixed"'  --out DIR/ff_fixed
    housingfe run test-gearbox-runup-double-helical --set 'drivetrain.bearings="fluid_film"' \
        --set 'runup.bearing_speeds="follow"' --out DIR/ff_follow
    python benchmarks/experiments/bearing_speeds/bearing_speeds.py DIR

Writes bearing_speeds.csv (per torque, route and speed: L_WA fixed / follow, the pinion front film's Kyy and Cxx at
the speed), bearing_speeds.png (L_WA over speed, both settings, both torques, both routes) and prints the means over
800-1500 rev/min and the timings of the two runs' runup.json."""
from __future__ import annotations

import csv
import json
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent


def lwa(folder: Path) -> dict:
    out = {}
    for r in csv.DictReader(open(folder / "runup.csv")):
        if r["radiation"] == "erp":
            out[(float(r["torque_nm"]), r["route"], float(r["speed_rpm"]))] = float(r["LwA_dB"])
    return out


def film(torque: float, speed: float) -> tuple[float, float]:
    from housingfe.drivetrain.description import test_gearbox
    from housingfe.errors import InputError

    try:
        m = replace(test_gearbox("double_helical", "fluid_film", torque), bearing_speed_rpm=speed)
        K, C = m.configuration_matrices()["pinion_front"]
        return float(K[1, 1]), float(C[0, 0])
    except InputError:
        return float("nan"), float("nan")


def main(root: Path) -> None:
    fixed, follow = lwa(root / "ff_fixed"), lwa(root / "ff_follow")
    rows = []
    films = {}
    for (t, route, s), v in sorted(fixed.items()):
        if (t, s) not in films:
            films[t, s] = film(t, s)
        rows.append({"torque_nm": t, "route": route, "speed_rpm": s, "LwA_fixed_dBA": round(v, 3),
                     "LwA_follow_dBA": round(follow[t, route, s], 3),
                     "pinion_front_Kyy_N_per_m": f"{films[t, s][0]:.4g}",
                     "pinion_front_Cxx_N_s_per_m": f"{films[t, s][1]:.4g}"})
    with open(HERE / "bearing_speeds.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    for t in sorted({r["torque_nm"] for r in rows}):
        for route in ("tf_omega", "mesh_force"):
            sel = [r for r in rows if r["torque_nm"] == t and r["route"] == route and 800 <= r["speed_rpm"] <= 1500]
            d = np.array([r["LwA_follow_dBA"] - r["LwA_fixed_dBA"] for r in sel])
            mx_f = max((r for r in rows if r["torque_nm"] == t and r["route"] == route),
                       key=lambda r: r["LwA_fixed_dBA"])
            mx_w = max((r for r in rows if r["torque_nm"] == t and r["route"] == route),
                       key=lambda r: r["LwA_follow_dBA"])
            print(f"{t:g} N m {route:10s}: follow - fixed over 800-1500 rpm {d.mean():+.2f} +- {d.std():.2f} dB "
                  f"(max |d| {np.abs(d).max():.2f}); max L_WA fixed {mx_f['LwA_fixed_dBA']:.1f} @ "
                  f"{mx_f['speed_rpm']:g}, follow {mx_w['LwA_follow_dBA']:.1f} @ {mx_w['speed_rpm']:g}")
    for name in ("ff_fixed", "ff_follow"):
        info = json.load(open(root / name / "runup.json"))
        tm = info["timings_s"]
        print(name, "total_s", round(tm["total_s"], 1),
              {k: round(v, 1) for k, v in tm.items() if k.startswith("bearing_speeds") or k.startswith("reanalysis")},
              "held", info["bearing_speeds"]["torques"])

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
    for ax, route in zip(axes, ("tf_omega", "mesh_force")):
        for t, colour in ((1000.0, "C0"), (2000.0, "C3")):
            sel = [r for r in rows if r["torque_nm"] == t and r["route"] == route]
            s = [r["speed_rpm"] for r in sel]
            ax.plot(s, [r["LwA_fixed_dBA"] for r in sel], "--", color=colour, label=f"{t:g} N m, fixed 1500 rpm")
            ax.plot(s, [r["LwA_follow_dBA"] for r in sel], "-", color=colour, label=f"{t:g} N m, follow")
        ax.axvspan(800, 1500, color="0.9", zorder=0)
        ax.set_title(f"fluid films, {route}")
        ax.set_xlabel("pinion speed (rev/min)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("L_WA (dB(A), sigma = 1)")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(HERE / "bearing_speeds.png", dpi=110)


if __name__ == "__main__":
    main(Path(sys.argv[1]))
