"""Run-up of gear set B with crowned roller bearings: straight vs crowned rollers, one basis.

The setting of runup_factors.py (`test-gearbox-runup --set drivetrain.gear_set=B`, 2000 N m, sigma = 1, a basis for
ball bearings, every variant a Rayleigh-Ritz re-analysis on the same Ritz vectors): per variant and route
L_WA(variant) - L_WA(ball), mean and s.d. over 800-1500 rpm (total and tooth line) and the max L_WA.  Variants:
the self-aligning and tapered-roller configurations with the rollers as the catalogue has them (straight, line
contact), with the ISO/TS 16281 logarithmic crown (roller_profile = "logarithmic"), and the spherical rollers as
Hertz point contacts (model "spherical-point-contact", osculation 0.97).  Each roller bearing's K is recomputed at
the same load, model and held tilt as the configuration's; ball bearings are unchanged.

    PYTHONPATH=. .venv/bin/python benchmarks/experiments/bearing_ranking/crowned_runup.py [--out DIR] [--coarse]
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from runup_factors import Patched, gear_set_b_args, metrics  # noqa: E402

TORQUE = 2000.0


def rollers_as(profile: str = "straight", spherical_model: str | None = None):
    """Patch of a coupling spec: every roller bearing's K recomputed with `profile` (and the spherical rollers with
    `spherical_model` if given) at the spec's load, model and tilt; ball bearings kept."""
    from housingfe.bearings import bearing_stiffness, lookup
    from housingfe.bearings.catalogue import estimated_internals

    def patch(spec):
        new = []
        with estimated_internals(roller_profile=profile):
            for b in spec.bearings:
                kind = lookup(b.designation).kind if b.designation else "ball"
                if kind == "ball":
                    new.append(b)
                    continue
                model = spherical_model if (spherical_model and kind == "spherical_roller") else b.model
                k = bearing_stiffness(b.designation, b.load, model=model, fixed_tilt=b.fixed_tilt).K
                new.append(b.model_copy(update={"designation": None, "load": None, "model": None, "fixed_tilt": None,
                                                "stiffness_matrix": k.tolist()}))
        return spec.model_copy(update={"bearings": new})
    return patch


def main(argv=None):
    import numpy as np
    from mpi4py import MPI

    from housingfe.radiation.radiators import RADIATORS
    from housingfe.runup.chain import build_gearbox_model, runup, source_lines, with_drivetrain
    from housingfe.runup.scene import drivetrain_of, housing_model_for, load_runup_scene
    from housingfe.scene import load_housing_scene

    args, overrides = gear_set_b_args(__doc__, "/tmp/bearing_ranking_crowned_runup", argv)
    t0 = time.perf_counter()
    scene, _ = load_runup_scene("test-gearbox-runup", overrides)
    spec = scene.runup
    hs, _ = load_housing_scene(scene.housing.scene, list(scene.housing.set))
    hm = housing_model_for(hs, spec.f_max_hz, MPI.COMM_WORLD)
    ball = drivetrain_of(scene.drivetrain, TORQUE)
    config = {name: drivetrain_of(scene.drivetrain.model_copy(update={"bearings": name}), TORQUE)
              for name in ("self_aligning", "tapered_roller")}
    gm = build_gearbox_model(hm, ball, spec.f_max_hz, damping_ratio=spec.damping_ratio,
                             basis_factor=spec.basis_factor, radiators={"erp": RADIATORS["erp"]()})
    lines, _ = source_lines(ball.source_model(harmonics=spec.harmonics), spec.speeds, [TORQUE], spec.f_max_hz)
    ref = runup(gm, None, spec.speeds, [TORQUE], lines=lines)
    variants = {
        "self_aligning, straight rollers (catalogue)": config["self_aligning"],
        "self_aligning, logarithmic crown (ISO/TS 16281)": Patched(config["self_aligning"],
                                                                   rollers_as("logarithmic")),
        "self_aligning, Hertz point contacts (spherical-point-contact)": Patched(
            config["self_aligning"], rollers_as("straight", "spherical-point-contact")),
        "tapered_roller, straight rollers (catalogue)": config["tapered_roller"],
        "tapered_roller, logarithmic crown (ISO/TS 16281)": Patched(config["tapered_roller"],
                                                                    rollers_as("logarithmic")),
    }
    rows = []
    for name, dt in variants.items():
        res = runup(with_drivetrain(gm, dt), None, spec.speeds, [TORQUE], lines=lines)
        diag = {b.label: np.diag(np.array(b.matrices()[0]))[:5].tolist() for b in dt.to_coupling_spec().bearings}
        for route in res.routes:
            rows.append({"variant": name, "route": route, **metrics(res, ref, route), "diagonals": diag})
            r = rows[-1]
            print(f"{name:62s} {route:10s} total {r['mean_total_dB']:+.1f} ({r['sd_total_dB']:.1f})  tooth "
                  f"{r['mean_tooth_dB']:+.1f} ({r['sd_tooth_dB']:.1f})  max {r['max_LwA_dBA']:.1f}", flush=True)
    for route in ref.routes:
        s, a = ref.series(route, "erp", TORQUE, "LwA_dB")
        rows.append({"variant": "ball (reference)", "route": route, "max_LwA_dBA": float(a.max()),
                     "max_at_rpm": float(s[np.argmax(a)])})
        print(f"{'ball (reference)':62s} {route:10s} max {a.max():.1f} at {s[np.argmax(a)]:.0f} rpm")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "crowned_runup.json").write_text(json.dumps(rows, indent=1))
    print(f"{time.perf_counter() - t0:.0f} s; {out}/crowned_runup.json")


if __name__ == "__main__":
    main()
