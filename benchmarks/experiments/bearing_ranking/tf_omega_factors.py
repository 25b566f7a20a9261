"""Which factor makes TF_omega(ball) - TF_omega(self-aligning) negative here and +7.3 dB in the thesis' FE?

One factor at a time on the `housingfe bearing-variants` model (test-gearbox-interior: the test gearbox housing,
shafts, gear set B mesh, bearings at the statics loads of 2000 N m, 1 N m at the wheel centre, xi = 0.04):
TF_omega = L_v - L_omega per variant; the mean and s.d. of the difference ball - variant over 320-600 Hz (tooth
frequency at 800-1500 rpm; thesis Fig. 5.18: FE +7.3, s.d. 4.5 dB) and over 20-1000 Hz, surface average and the
thesis' 8 points.  Positive = the variant transmits less.

    PYTHONPATH=. .venv/bin/python benchmarks/experiments/bearing_ranking/tf_omega_factors.py [--out DIR] [--quick]
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import common  # noqa: E402

BAND = (320.0, 600.0)


def tf_omega(model, scene, cspec):
    """(frequencies Hz, TF_omega surface dB, TF_omega 8 points dB) of the scene's harmonic analysis on cspec."""
    from housingfe import levels
    from housingfe.drivetrain.interior import build_interior
    from housingfe.response import forced as forced_response

    spec = scene.analysis.harmonic
    interior = build_interior(model, cspec, spec.modal_basis_factor * spec.f_max)
    forced = forced_response.run(interior, spec, scene.loads, scene.damping)
    r = forced.responses[next(iter(forced.responses))][0]
    omega2 = r.extras["omega_mean_square"]
    pts = levels.level(r.point_mean_square_velocity[8], levels.V0) - levels.level(omega2, levels.OMEGA0)
    return np.asarray(r.frequencies), np.asarray(r.extras["TF_omega_dB"]), np.asarray(pts)


def variants(base):
    """{context: {name: spec}}: each context holds a reference 'ball' and the variants compared against it."""
    from housingfe.studies.bearing_variants import configuration_spec

    ball, _, _ = configuration_spec(base, "ball")
    sa, _, _ = configuration_spec(base, "self_aligning")
    out = {}
    out["rbe2 bores (default)"] = {
        "ball": ball,
        "self_aligning (spherical roller model)": sa,
        "ball, moments zeroed (thesis' FE stand-in)": common.with_bearing_matrices(ball, common.scale_moments(0.0)),
        "ball moments, self_aligning translations": common.with_bearing_matrices(ball, common.translations_of(sa)),
        "self_aligning, translations x 0.4 (Palmgren spherical-roller law)":
            common.with_bearing_matrices(sa, common.scale_translations(0.4)),
        "ball, moments x 30 (Appendix C's values are of this size)":
            common.with_bearing_matrices(ball, common.scale_moments(30.0)),
    }
    for kind, k in (("rbe3", None), ("star", 1e8)):
        label = f"{kind} bores" + (f" (rods {k:.0e} N/m)" if k else "")
        b = common.with_bores(ball, kind, k)
        out[label] = {"ball": b, "self_aligning (spherical roller model)": common.with_bores(sa, kind, k),
                      "ball, moments zeroed (thesis' FE stand-in)":
                          common.with_bearing_matrices(b, common.scale_moments(0.0))}
    b30 = common.with_bearing_matrices(ball, common.scale_moments(30.0))
    out["ball with moments x 30 as the reference"] = {
        "ball": b30, "self_aligning (spherical roller model)": sa,
        "ball, moments zeroed (thesis' FE stand-in)": common.with_bearing_matrices(ball, common.scale_moments(0.0))}
    nm = common.with_mesh_stiffness(ball, 1e-6)
    out["gear mesh removed (wheel shaft alone)"] = {
        "ball": nm, "self_aligning (spherical roller model)": common.with_mesh_stiffness(sa, 1e-6),
        "ball, moments zeroed (thesis' FE stand-in)": common.with_bearing_matrices(nm, common.scale_moments(0.0))}
    return out


def main(argv=None):
    from mpi4py import MPI

    from housingfe.scene import build_model_from_scene, load_housing_scene

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", default="/tmp/bearing_ranking_tf")
    p.add_argument("--quick", action="store_true", help="only the default (rbe2) context")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override of the housing scene (e.g. geometry.bearing_plate.thickness=0.03)")
    args = p.parse_args(argv)
    t0 = time.perf_counter()
    scene, _ = load_housing_scene("test-gearbox-interior", args.set)
    model = build_model_from_scene(scene, MPI.COMM_WORLD)
    rows = []
    contexts = variants(scene.coupling)
    if args.quick:
        contexts = dict(list(contexts.items())[:1])
    for context, specs in contexts.items():
        ref = None
        for name, spec in specs.items():
            f, surf, pts = tf_omega(model, scene, spec)
            if ref is None:
                ref = (surf, pts)
                continue
            band = (f >= BAND[0]) & (f <= BAND[1])
            ds, dp = ref[0] - surf, ref[1] - pts
            rows.append({"context": context, "variant": name,
                         "mean_320_600_surface_dB": float(ds[band].mean()), "sd_320_600_surface_dB": float(ds[band].std()),
                         "mean_320_600_8pts_dB": float(dp[band].mean()), "sd_320_600_8pts_dB": float(dp[band].std()),
                         "mean_all_surface_dB": float(ds.mean()), "sd_all_surface_dB": float(ds.std())})
            print(f"{context:40s} {name:62s} {ds[band].mean():+6.2f} ({ds[band].std():4.2f})  8 pts "
                  f"{dp[band].mean():+6.2f} ({dp[band].std():4.2f})  20-1000 Hz {ds.mean():+6.2f}", flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "tf_omega_factors.json").write_text(json.dumps({"overrides": args.set, "rows": rows}, indent=1))
    print(f"{time.perf_counter() - t0:.0f} s; {out}/tf_omega_factors.json")


if __name__ == "__main__":
    main()
