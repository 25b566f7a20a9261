"""Crowned rollers: what the ISO/TS 16281 logarithmic roller profile does to the test gearbox's roller bearings.

Part 1 (default, a few seconds): our straight-roller contact law against ISO/TS 16281's lamina law on the same
roller lengths, and the bearing matrices of the roller configurations at the statics loads of gear set B, 2000 N m
(bearings.configurations.representative_loads / evaluate, tilt held), straight vs logarithmic rollers
(catalogue.estimated_internals(roller_profile=...)); ball bearings for scale.

Part 2 (--runup, minutes): the run-up experiments of this folder with every roller bearing crowned
(runup_factors.py and tapered_factors.py run unchanged inside estimated_internals(roller_profile="logarithmic");
ball bearings have no roller profile, so only the roller bearings change).

    PYTHONPATH=. .venv/bin/python benchmarks/experiments/bearing_ranking/roller_profile.py [--runup] [--coarse]
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

TORQUE = 2000.0


def law_table() -> list[str]:
    """Our per-roller law (Palmgren, both contacts, 208 GPa) over ISO/TS 16281's Q = 35948 L^(8/9) delta^(10/9)."""
    from housingfe.bearings import hertz
    from housingfe.bearings.catalogue import lookup

    rows = ["| bearing | roller length l [mm] (per row) | D_w [mm] | k_n ours / ISO/TS 16281 (same delta) |",
            "|---|---|---|---|"]
    for d in ("SKF 21316CC", "SKF 22219CC", "SKF 30316J2", "SKF 30219J2", "SKF NJ316", "SKF NU2219"):
        b = lookup(d)
        ours = hertz.roller_effective_stiffness(b.roller_length, b.youngs_modulus, b.poisson_ratio)
        iso = 35948.0 * (b.roller_length * 1e3) ** (8 / 9) * 1e3 ** (10 / 9)
        rows.append(f"| {b.designation} | {b.roller_length * 1e3:.1f} | {b.element_diameter * 1e3:.1f} | "
                    f"{ours / iso:.3f} |")
    return rows


def matrix_table() -> list[str]:
    from housingfe.bearings.catalogue import estimated_internals
    from housingfe.bearings.configurations import evaluate, representative_loads

    single = representative_loads("single_helical", pinion_torque=TORQUE)
    double = representative_loads("double_helical", pinion_torque=TORQUE)
    cases = [("self_aligning", single), ("tapered_roller", single), ("cylindrical_roller", double)]
    results, ball = {}, {}
    for profile in ("straight", "logarithmic"):
        with estimated_internals(roller_profile=profile):
            for name, loads in cases:
                results[name, profile] = evaluate(name, loads)
    for gear_set, loads in (("single", single), ("double", double)):
        ball[gear_set] = evaluate("ball", loads)          # the deep groove bearings at the same loads, for scale
    rows = ["| configuration | position | bearing | k_xx [N/m] straight → log | k_yy | k_zz | k_θxθx [N m/rad] | "
            "k_θyθy | (k_xx+k_yy) log / straight | (k_xx+k_yy) log / ball at the same load |",
            "|---|---|---|---|---|---|---|---|---|---|"]
    for name, loads in cases:
        for pos, res in results[name, "straight"].items():
            if res.detail.model == "lim-ball":
                continue            # the deep groove bearing at the floating end of the tapered configuration
            s, c = np.diag(res.K), np.diag(results[name, "logarithmic"][pos].K)
            b = np.diag(ball["single" if loads is single else "double"][pos].K)
            cells = " | ".join(f"{x:.3g} → {y:.3g}" for x, y in zip(s[:5], c[:5]))
            rows.append(f"| {name} | {pos} | {res.choice.designation} | {cells} | "
                        f"{(c[0] + c[1]) / (s[0] + s[1]):.2f} | {(c[0] + c[1]) / (b[0] + b[1]):.1f} |")
    return rows


def runup(argv) -> None:
    import runup_factors
    import tapered_factors

    from housingfe.bearings.catalogue import estimated_internals

    p = argparse.ArgumentParser()
    p.add_argument("--out", default="/tmp/bearing_ranking_crowned")
    p.add_argument("--coarse", action="store_true")
    args, _ = p.parse_known_args(argv)
    extra = ["--coarse"] if args.coarse else []
    with estimated_internals(roller_profile="logarithmic"):
        t0 = time.perf_counter()
        runup_factors.main(["--out", f"{args.out}/runup", *extra])
        print(f"runup_factors (crowned rollers): {time.perf_counter() - t0:.0f} s", flush=True)
        t0 = time.perf_counter()
        tapered_factors.main(["--out", f"{args.out}/tapered", *extra])
        print(f"tapered_factors (crowned rollers): {time.perf_counter() - t0:.0f} s", flush=True)


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if "--runup" in argv:
        runup([a for a in argv if a != "--runup"])
        return
    print("\n".join(law_table()))
    print()
    print("\n".join(matrix_table()))


if __name__ == "__main__":
    main()
