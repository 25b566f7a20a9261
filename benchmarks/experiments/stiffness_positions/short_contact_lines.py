"""Stiffness curves of the run-up's gear sets with and without spikes from short contact lines at the path's ends.

For sets A and uncorrected (2000 N m, ball bearings) and the double helical set (cylindrical rollers, 1000 and
2000 N m) of `test-gearbox-runup`: the curve at 128 and 512 positions (mean, |S_n|/k_m n = 1..30, seconds), the
largest departure of a 512-position point from its neighbours' mean, and for the double helical set a scan of S at
u/p_bt = 0.280 ... 0.300 and 0.810 ... 0.830 (step 0.0005).  Writes short_contact_lines_<label>.json into --out.
Run it on two trees (PYTHONPATH) to compare; README.md "Short contact lines" has the numbers.

    PYTHONPATH=. OPENBLAS_NUM_THREADS=1 /work/main/.venv/bin/python \\
        benchmarks/experiments/stiffness_positions/short_contact_lines.py --label new --out /tmp/scl
"""
import argparse
import json
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from housingfe.drivetrain.misalignment import lead_gap_law
from housingfe.source.stiffness import normal_force_from_torque, stiffness_curve
from housingfe.studies.chain_session import ChainSession

CASES = (("A", "A", "ball", 2000.0), ("uncorrected", "uncorrected", "ball", 2000.0),
         ("dh1000", "double_helical", "cylindrical_roller", 1000.0),
         ("dh2000", "double_helical", "cylindrical_roller", 2000.0))
SCAN = np.round(np.concatenate([np.arange(0.280, 0.3001, 0.0005), np.arange(0.810, 0.8301, 0.0005)]), 5)


def run() -> dict:
    session = ChainSession.from_scene("test-gearbox-runup")
    spec = session.spec
    res = {}
    for name, gears, bearings, torque in CASES:
        dt = session.drivetrain(gears, bearings, torque)
        law = lead_gap_law(dt, spec.misalignment_model)
        src = dt.source_model(harmonics=spec.harmonics, engagement=spec.engagement, misalignment=law,
                              stiffness_positions=128)
        model = replace(src.mesh_model, lead_gap=src.lead_gap(torque))
        force = normal_force_from_torque(src.pair, torque)
        r = {}
        for P in (128, 512):
            t0 = time.perf_counter()
            S = stiffness_curve(model, force, P).stiffness
            r[f"t{P}"] = time.perf_counter() - t0
            X = np.fft.rfft(S) / P
            r[f"S{P}"], r[f"mean{P}"] = S.tolist(), float(X[0].real)
            r[f"harm{P}"] = (2 * np.abs(X[1:31]) / X[0].real).tolist()
        S = np.array(r["S512"])
        r["max_outlier_rel"] = float(np.max(np.abs(S - (np.roll(S, 1) + np.roll(S, -1)) / 2)) / S.mean())
        if name.startswith("dh"):
            pbt = src.pair.transverse_base_pitch
            r["scan_u"] = SCAN.tolist()
            r["scan_S"] = [model.stiffness_at(u * pbt, force)["stiffness"] for u in SCAN]
        res[name] = r
        print(f"{name}: mean {r['mean128']:.6e} N/m, largest outlier {r['max_outlier_rel']:.2e} k_m, "
              f"curve 128 {r['t128']:.2f} s, 512 {r['t512']:.2f} s", flush=True)
    return res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--label", default="new")
    ap.add_argument("--out", type=Path, default=Path("."))
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / f"short_contact_lines_{args.label}.json").write_text(json.dumps(run()))


if __name__ == "__main__":
    main()
