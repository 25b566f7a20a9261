"""Which factor makes the chain rank self-aligning bearings louder than ball bearings on gear set B (run-up)?

The run-up of `housingfe run test-gearbox-runup --set drivetrain.gear_set=B` (2000 N m, 50-1500 rpm, sigma = 1),
ball bearings with a fresh modal basis; every variant a Rayleigh-Ritz re-analysis on the same Ritz vectors
(housingfe.runup.chain.with_drivetrain; the vectors hold the static responses to unit pairs across every bearing,
so a bearing change lies in them).  Per variant and route: L_WA(variant) - L_WA(ball) per speed, mean and s.d.
over 800-1500 rpm (measured, thesis Sec. 5.8: self-aligning -5.1, s.d. 6.0 dB; maxima 92.3 vs 98.3 dB(A)), for
the total (every harmonic to 4 kHz) and for the tooth-frequency line alone; and the max L_WA.

    PYTHONPATH=. .venv/bin/python benchmarks/experiments/bearing_ranking/runup_factors.py [--out DIR] [--coarse]
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import common  # noqa: E402

TORQUE = 2000.0


class Patched:
    """A Drivetrain whose FE reduction (to_coupling_spec) is changed by `patch(spec) -> spec`; all else delegated."""

    def __init__(self, drivetrain, patch):
        self._dt, self._patch = drivetrain, patch

    def __getattr__(self, key):
        return getattr(self._dt, key)

    def to_coupling_spec(self, forces=None):
        return self._patch(self._dt.to_coupling_spec(forces))


def lumped_like(dt, other_spec, ball_spec):
    """The drivetrain whose lumped source (rigid bores) has Appendix C's bearing diagonal scaled per shaft by the
    FE bearings' stiffness ratio other / ball: radial (x, y) and the shaft tilt (two bearings' radial stiffness x
    span^2, so the same ratio) by the mean radial ratio, axial (z) by the axial ratio."""
    from housingfe.source.roosmalen.dynamics import APPENDIX_C_BEARINGS

    a, b = common.diagonals(other_spec), common.diagonals(ball_spec)
    out = {}
    for shaft in ("pinion", "wheel"):
        names = [n for n in a if n.startswith(shaft)]
        radial = sum(a[n][0] + a[n][1] for n in names) / sum(b[n][0] + b[n][1] for n in names)
        axial = sum(a[n][2] for n in names) / sum(b[n][2] for n in names)
        x, y, z, tx, ty = APPENDIX_C_BEARINGS[shaft]
        out[shaft] = (x * radial, y * radial, z * axial, tx * radial, ty * radial)
    return replace(dt, lumped_bearing_stiffness=out), out


def metrics(res, ref, route):
    """(mean, s.d.) of L_WA(res) - L_WA(ref) over 800-1500 rpm for the total and the tooth line; max L_WA."""
    s, a = res.series(route, "erp", TORQUE, "LwA_dB")
    _, b = ref.series(route, "erp", TORQUE, "LwA_dB")
    sel = s >= 800.0
    d = a - b
    out = {"mean_total_dB": float(d[sel].mean()), "sd_total_dB": float(d[sel].std()), "max_LwA_dBA": float(a.max()),
           "max_at_rpm": float(s[np.argmax(a)])}
    from housingfe import levels

    ln = res.lines
    tooth = ln.harmonic == 1
    aw = levels.a_weighting_db(ln.frequency[tooth])
    ta = res.L_W[route, "erp"][tooth] + aw
    tb = ref.L_W[route, "erp"][tooth] + aw
    dt = (ta - tb)[ln.speed[tooth] >= 800.0]
    out.update(mean_tooth_dB=float(dt.mean()), sd_tooth_dB=float(dt.std()))
    return out


def gear_set_b_args(doc: str, default_out: str, argv=None, extra=()) -> tuple[argparse.Namespace, list[str]]:
    """The command line of the run-up experiments (--out, --coarse) and the scene overrides of test-gearbox-runup for
    gear set B (`extra` added; --coarse: a 60 mm housing mesh and lines to 1.5 kHz, a quick look)."""
    p = argparse.ArgumentParser(description=doc.splitlines()[0])
    p.add_argument("--out", default=default_out)
    p.add_argument("--coarse", action="store_true", help="60 mm housing mesh, lines to 1.5 kHz (a quick look)")
    args = p.parse_args(argv)
    # the layout these experiments were measured in: the wheel located at its front bearing for every configuration
    # (the scene's default became the thesis' side, "configuration", on 2026-11-28: docs/design-variants.md)
    overrides = ["drivetrain.gear_set=B", "drivetrain.wheel_locating=front", *extra]
    if args.coarse:
        overrides += ['housing.set=["mesh.size=0.06"]', "runup.f_max_hz=1500.0"]
    return args, overrides


def ball_reference(overrides, others=()):
    """The experiments' reference: test-gearbox-runup with `overrides`, ball bearings at TORQUE, a fresh basis (erp
    radiation), the rigid-bore source lines and the ball run-up.  Returns (spec, ball drivetrain, {name: drivetrain of
    bearing configuration name for name in others}, gearbox model, lines, reference run-up)."""
    from mpi4py import MPI

    from housingfe.radiation.radiators import RADIATORS
    from housingfe.runup.chain import build_gearbox_model, runup, source_lines
    from housingfe.runup.scene import drivetrain_of, housing_model_for, load_runup_scene
    from housingfe.scene import load_housing_scene

    t0 = time.perf_counter()
    scene, _ = load_runup_scene("test-gearbox-runup", overrides)
    spec = scene.runup
    hs, _ = load_housing_scene(scene.housing.scene, list(scene.housing.set))
    hm = housing_model_for(hs, spec.f_max_hz, MPI.COMM_WORLD)
    ball = drivetrain_of(scene.drivetrain, TORQUE)
    config = {name: drivetrain_of(scene.drivetrain.model_copy(update={"bearings": name}), TORQUE) for name in others}
    gm = build_gearbox_model(hm, ball, spec.f_max_hz, damping_ratio=spec.damping_ratio,
                             basis_factor=spec.basis_factor, radiators={"erp": RADIATORS["erp"]()})
    print(f"model {time.perf_counter() - t0:.0f} s", flush=True)
    lines, _ = source_lines(ball.source_model(harmonics=spec.harmonics), spec.speeds, [TORQUE], spec.f_max_hz)
    ref = runup(gm, None, spec.speeds, [TORQUE], lines=lines)
    return spec, ball, config, gm, lines, ref


def main(argv=None):
    from housingfe.runup.chain import runup, source_lines, with_drivetrain

    args, overrides = gear_set_b_args(__doc__, "/tmp/bearing_ranking_runup", argv)
    t0 = time.perf_counter()
    spec, ball, config, gm, lines, ref = ball_reference(overrides, ("self_aligning",))
    sa = config["self_aligning"]
    ball_spec, sa_spec = ball.to_coupling_spec(), sa.to_coupling_spec()
    structural = {
        "self_aligning (spherical roller model)": sa,
        "ball, moments zeroed (thesis' FE stand-in)":
            Patched(ball, lambda s: common.with_bearing_matrices(s, common.scale_moments(0.0))),
        "ball moments, self_aligning translations":
            Patched(ball, lambda s: common.with_bearing_matrices(s, common.translations_of(sa_spec))),
        "self_aligning, translations x 0.4 (Palmgren spherical-roller law)":
            Patched(sa, lambda s: common.with_bearing_matrices(s, common.scale_translations(0.4))),
    }
    rows = []
    results = {}
    for name, dt in structural.items():
        t1 = time.perf_counter()
        m = with_drivetrain(gm, dt)
        results[name] = runup(m, None, spec.speeds, [TORQUE], lines=lines)
        for route in results[name].routes:
            rows.append({"variant": name, "source": "Appendix C bearings (unchanged)", "route": route,
                         **metrics(results[name], ref, route)})
            print(rows[-1], f"{time.perf_counter() - t1:.1f} s", flush=True)
    # the excitation: the lumped source on rigid bores sees the self-aligning bearings' stiffness too
    dt_src, diag = lumped_like(sa, sa_spec, ball_spec)
    lines_sa, _ = source_lines(dt_src.source_model(harmonics=spec.harmonics), spec.speeds, [TORQUE], spec.f_max_hz)
    m = with_drivetrain(gm, sa)
    res = runup(m, None, spec.speeds, [TORQUE], lines=lines_sa)
    for route in res.routes:
        rows.append({"variant": "self_aligning (spherical roller model)",
                     "source": "lumped bearings scaled like the FE ones: " + ", ".join(
                         f"{k} " + " ".join(f"{v:.2g}" for v in vals) for k, vals in diag.items()),
                     "route": route, **metrics(res, ref, route)})
        print(rows[-1], flush=True)
    for route in ref.routes:
        s, a = ref.series(route, "erp", TORQUE, "LwA_dB")
        rows.append({"variant": "ball (reference)", "source": "Appendix C bearings", "route": route,
                     "max_LwA_dBA": float(a.max()), "max_at_rpm": float(s[np.argmax(a)])})
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "runup_factors.json").write_text(json.dumps(rows, indent=1))
    print(f"{time.perf_counter() - t0:.0f} s; {out}/runup_factors.json")


if __name__ == "__main__":
    main()
