"""How the tip relief's loaded contact edge quantises the mesh stiffness harmonics with the points per contact line.

|S_n| / k_m (one-sided amplitude 2 |X_n| of the stiffness curve over its mean, n = 1..30) of gear sets A, B, C, D and
uncorrected at 2000 N m (the run-up's operating point: the scene's MeshModel as `housingfe.source.roosmalen.run.build`
makes it, aligned gears), at 128 positions per base pitch (dyn.DEFAULT_STIFFNESS_POSITIONS) and 24 / 48 / 96 / 192
(/ 384) points per contact line (MeshModel.n_slices), with the time per position.

    PYTHONPATH=. OPENBLAS_NUM_THREADS=1 /work/main/.venv/bin/python \
        benchmarks/experiments/contact_edge/contact_edge.py --label after [--sets A,B] [--slices 24,48] [--out DIR]
        [--refinement R]

Runs on whatever `housingfe` PYTHONPATH imports (the "before" rows: the same script on a checkout of the code before the
fix) and appends rows (label, set, n_slices, n, amp_rel, k_m, ms_per_position) to contact_edge_<label>.csv.
"""
import argparse
import csv
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from housingfe.source.cli import load_scene
from housingfe.source.roosmalen import dynamics as dyn
from housingfe.source.roosmalen import run as rs
from housingfe.source.stiffness import normal_force_from_torque, stiffness_curve

HERE = Path(__file__).parent
TORQUE = 2000.0
HARMONICS = 30
SETS = {"A": "gearset-A", "B": "gearset-B", "C": "gearset-C", "D": "gearset-D", "unc": "gearset-uncorrected"}


def model_of(name: str):
    scene, path = load_scene(SETS[name])
    table = rs.parse(scene, str(path))
    pair, _, _, _, model = rs.build(table, str(path))
    return pair, model


def measure(name: str, n_slices: int, positions: int = dyn.DEFAULT_STIFFNESS_POSITIONS, refinement: int | None = None):
    pair, model = model_of(name)
    model = replace(model, n_slices=n_slices)
    if refinement is not None:             # MeshModel.edge_refinement (the code after the fix only)
        model = replace(model, edge_refinement=refinement)
    force = normal_force_from_torque(pair, TORQUE)
    t0 = time.perf_counter()
    curve = stiffness_curve(model, force, positions)
    ms = (time.perf_counter() - t0) / positions * 1e3
    amp = 2 * np.abs(np.fft.rfft(curve.stiffness)[1:HARMONICS + 1]) / curve.stiffness.size / curve.mean
    return curve.mean, amp, ms


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--label", required=True)
    ap.add_argument("--sets", default="A,B,C,D,unc")
    ap.add_argument("--slices", default="24,48,96,192")
    ap.add_argument("--out", default=str(HERE))
    ap.add_argument("--refinement", type=int, default=None, help="MeshModel.edge_refinement (default: the model's)")
    args = ap.parse_args()
    out = Path(args.out) / f"contact_edge_{args.label}.csv"
    new = not out.exists()
    with out.open("a", newline="") as fh:
        wr = csv.writer(fh)
        if new:
            wr.writerow(["label", "set", "n_slices", "n", "amp_rel", "k_m", "ms_per_position"])
        for n_slices in (int(x) for x in args.slices.split(",")):
            for name in args.sets.split(","):
                k_m, amp, ms = measure(name, n_slices, refinement=args.refinement)
                for n, a in enumerate(amp, start=1):
                    wr.writerow([args.label, name, n_slices, n, f"{a:.6e}", f"{k_m:.6e}", f"{ms:.2f}"])
                fh.flush()
                print(f"{args.label} {name} {n_slices}: k_m {k_m:.4e} N/m, {ms:.1f} ms/position, "
                      f"S_6,9,17 = {amp[5]:.2e} {amp[8]:.2e} {amp[16]:.2e}", flush=True)


if __name__ == "__main__":
    main()
