"""Full-precision source levels over the run-up's speeds, to compare two codes beyond the run-up CSVs' 6 digits.

    PYTHONPATH=<old tree> python source_levels.py --save old.npz     (then the same with this tree: new.npz)
    python source_levels.py --compare old.npz new.npz

Gear sets A and double helical at 2000 N m, 128 stiffness positions, 30 harmonics, 50 ... 1500 rpm in 50 rpm steps
(`SourceModel.operating_point`): per speed the narrow-band L_omega of every line, the tooth-band L_omega, the mesh
force's and the bearing loads' levels 20 log10 |x| [dB]; --compare prints the largest difference per quantity.
"""
from __future__ import annotations

import argparse

import numpy as np


def save(path: str, sets=("A", "double-helical")) -> None:
    from housingfe.source.roosmalen.operating import SourceModel

    res = {}
    for name in sets:
        sm = SourceModel.from_scene(f"gearset-{name}")
        sm.stiffness_positions, sm.harmonics = 128, 30
        for rpm in np.arange(50.0, 1501.0, 50.0):
            ex = sm.operating_point(float(rpm), 2000.0)
            res[f"{name}:{rpm:g}:L_omega"] = ex.L_omega
            res[f"{name}:{rpm:g}:L_omega_band"] = np.array([ex.L_omega_tooth_band])
            res[f"{name}:{rpm:g}:L_F"] = 20 * np.log10(np.abs(ex.mesh_force))
            res[f"{name}:{rpm:g}:L_bearings"] = 20 * np.log10(np.abs(ex.bearings.loads) + 1e-300)
    np.savez(path, **res)


def compare(old: str, new: str) -> None:
    a, b = np.load(old), np.load(new)
    worst: dict[str, float] = {}
    for k in a.files:
        kind = k.split(":")[0] + " " + k.split(":")[-1]
        finite = np.isfinite(a[k]) & (a[k] > -200)          # lines that are there (not log of ~0)
        worst[kind] = max(worst.get(kind, 0.0), float(np.max(np.abs(a[k][finite] - b[k][finite]), initial=0.0)))
    for k, v in worst.items():
        print(f"{k:32s} largest |difference| {v:.3g} dB")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--save")
    ap.add_argument("--compare", nargs=2)
    args = ap.parse_args()
    if args.save:
        save(args.save)
    if args.compare:
        compare(*args.compare)
