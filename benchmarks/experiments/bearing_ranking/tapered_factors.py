"""Which term of the tapered-roller matrices makes them the loudest bearings on mesh_force (issue 28, item 4)?

Since 52b43f5 the mesh_force route applies the shuttling moment with the mesh excitation; `housingfe study bearings`
then gives tapered roller - ball +1.96 dB (measured -3.6) and self-aligning - ball -5.06 (measured -5.1).  The
hypothesis tested here (not assumed): the shuttling moment tilts the gear shafts, and what reaches the housing
depends on the bearings' moment stiffness and their axial-radial / force-tilt coupling.

The CURRENT default chain of `housingfe run test-gearbox-runup --set drivetrain.gear_set=B` (2000 N m, sigma = 1:
the coupled source receptance, the rigid-bore mesh misalignment, face-width engagement), as `housingfe study
bearings` runs it: a basis for ball bearings, every other configuration a Rayleigh-Ritz re-analysis on the same
Ritz vectors.  One factor at a time on the tapered-roller (and, as a control, self-aligning) bearings' 6x6 K in
their own frames (common.py): as computed; moment rows/columns zeroed; translational block from the ball bearing
(moments kept); the ball bearing's moment rows/columns swapped in; the axial-radial and/or force-tilt coupling
terms zeroed; the translations scaled to the ball bearing's radial size (K -> S K S).  A changed K acts
everywhere the FE bearings act: the coupled model (transfer and the coupled source's receptance) and the static
mesh misalignment (the rigid-bore tilt of the FE interior).  Each with the shuttling moment (default) and with
runup.mesh_moment = "none" (the TE path alone) and with the shuttling moment alone (the TE-driven mesh force of the
same lines zeroed: the moment's own path), every difference taken to ball bearings with the same setting.

Per variant and route: L_WA(variant) - L_WA(ball) per speed, mean and s.d. over 800-1500 rpm, for the total (every
harmonic to f_max) and the tooth-frequency line alone; the max L_WA.

    PYTHONPATH=. .venv/bin/python benchmarks/experiments/bearing_ranking/tapered_factors.py [--out DIR] [--coarse]
"""
from __future__ import annotations

import csv
import json
import math
import os
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import common  # noqa: E402
from runup_factors import Patched, gear_set_b_args, metrics  # noqa: E402

TORQUE = 2000.0
ROUTES = ("tf_omega", "mesh_force")
FLOATING = ("pinion_back", "wheel_back")
LOCATING = ("pinion_front", "wheel_front")
# the default (the shuttling moment with the TE-driven mesh force), the TE path alone, the moment's path alone
MESH_MOMENT_SETTINGS = ("shuttling", "none", "alone")


def moments_of(other_spec):
    """Replace each bearing's moment rows/columns (theta_x, theta_y: the tilt block and the force-tilt couplings)
    by those of the same bearing in other_spec; the translational block kept."""
    other = common.bearing_matrices(other_spec)

    def fn(name, K):
        K = K.copy()
        Ko = np.array(other[name][0], float)
        K[common.MOMENT, :] = Ko[common.MOMENT, :]
        K[:, common.MOMENT] = Ko[:, common.MOMENT]
        return K
    return fn


def zero_couplings(axial_radial: bool, force_tilt: bool):
    """K with the axial-radial terms k_xz, k_yz and/or the force-tilt terms k_(x,y,z),(theta_x,theta_y) zeroed
    (symmetrically); the diagonal blocks kept (stays positive semi-definite)."""
    def fn(name, K):
        K = K.copy()
        if axial_radial:
            for i in (0, 1):
                K[i, 2] = K[2, i] = 0.0
        if force_tilt:
            K[np.ix_(common.TRANSLATION, common.MOMENT)] = 0.0
            K[np.ix_(common.MOMENT, common.TRANSLATION)] = 0.0
        return K
    return fn


def radial_size_of(other_spec):
    """K -> S K S with S = sqrt(r) on x, y, z, r = (k_xx + k_yy) of the same bearing in other_spec / this one's:
    the translations at the other bearing's radial size, the couplings by sqrt(r), the tilt block kept (the
    matrix keeps its shape and stays positive semi-definite)."""
    other = common.bearing_matrices(other_spec)

    def fn(name, K):
        Ko = np.array(other[name][0], float)
        r = (Ko[0, 0] + Ko[1, 1]) / (K[0, 0] + K[1, 1])
        s = np.ones(6)
        s[common.TRANSLATION] = math.sqrt(r)
        return s[:, None] * K * s[None, :]
    return fn


def positions_of(other_spec, names):
    """Each bearing in `names` replaced whole by the same position of other_spec (another bearing there)."""
    other = common.bearing_matrices(other_spec)

    def fn(name, K):
        return np.array(other[name][0], float) if name in names else K
    return fn


def min_eigenvalue_ratio(spec) -> float:
    """The most negative eigenvalue of the bearings' symmetric K over the largest, across the bearings (>= 0 up to
    round-off: positive semi-definite; < 0: the variant is not a physical stiffness)."""
    worst = 0.0
    for name, (K, _) in common.bearing_matrices(spec).items():
        K = np.array(K, float)
        w = np.linalg.eigvalsh(0.5 * (K + K.T))
        worst = min(worst, w[0] / w[-1])
    return worst


def shaft_bending(drivetrain) -> dict:
    """{shaft: (4 E I / L [N m/rad], L [m], d [m])}: the moment at one end of the shaft span L between its two
    bearings that turns that end by 1 rad with the other end clamped."""
    from housingfe.drivetrain.shafts import STEEL, CircularSection

    out = {}
    for shaft in ("pinion", "wheel"):
        line = drivetrain.shaft(shaft)
        pos = sorted(b.position for b in drivetrain.bearings if b.shaft == shaft)
        L = pos[-1] - pos[0]
        EI = STEEL.youngs_modulus * CircularSection(line.diameter).second_moment
        out[shaft] = (4.0 * EI / L, L, line.diameter)
    return out


def variant_lines(session, model, drivetrain, mesh_moment: str):
    """The scene's source lines (as ChainSession.scene_lines / `housingfe run`) for a possibly patched drivetrain:
    its rigid-bore mesh misalignment from ITS FE bearings (the patched K), the coupled source on `model`.
    mesh_moment: "shuttling", "none" (housingfe.runup.chain.MESH_MOMENTS) or "alone" (the shuttling moment without
    the TE-driven mesh force: its own path on mesh_force)."""
    from housingfe.drivetrain.misalignment import rigid_bore_misalignment
    from housingfe.runup.chain import run_source

    spec = session.spec
    if spec.misalignment_model != "rigid-bores":
        raise SystemExit(f"this experiment expects the default misalignment 'rigid-bores', got "
                         f"{spec.misalignment_model!r}")
    gap = rigid_bore_misalignment(drivetrain).lead_gap
    alone = mesh_moment == "alone"
    mesh_moment = "shuttling" if alone else mesh_moment

    def law(_torque: float) -> float:
        return gap
    law.model = "rigid-bores"
    source = drivetrain.source_model(harmonics=spec.harmonics, engagement=spec.engagement, misalignment=law)
    lines, _ = run_source(model, source, spec.speeds, [TORQUE], spec.f_max_hz, spec.source_receptance, mesh_moment)
    if alone:        # the shuttling moment's path by itself: the TE-driven mesh force of the same lines removed
        lines = replace(lines, mesh_excitation=np.zeros_like(lines.mesh_excitation))
    return lines, gap


def mean_level(res, route: str) -> float:
    """Arithmetic mean of L_WA (dB(A)) over 800-1500 rpm (the absolute level the differences are taken of)."""
    s, a = res.series(route, "erp", TORQUE, "LwA_dB")
    return float(a[s >= 800.0].mean())


def main(argv=None):
    from housingfe.studies.chain_session import ChainSession

    args, overrides = gear_set_b_args(__doc__, "/tmp/bearing_ranking_tapered", argv, ['radiation.models=["erp"]'])
    t0 = time.perf_counter()
    load0 = os.getloadavg()
    session = ChainSession.from_scene("test-gearbox-runup", overrides)
    spec = session.spec
    print(f"default chain: source_receptance={spec.source_receptance}, misalignment={spec.misalignment_model}, "
          f"engagement={spec.engagement}, mesh_moment={spec.mesh_moment_model}", flush=True)
    ball = session.drivetrain("B", "ball", TORQUE)
    tap = session.drivetrain("B", "tapered_roller", TORQUE)
    sa = session.drivetrain("B", "self_aligning", TORQUE)
    ball_spec, tap_spec, sa_spec = ball.to_coupling_spec(), tap.to_coupling_spec(), sa.to_coupling_spec()

    # the catalogue-derived contact angle: e x 0.85 / 1.15 (the uncertainty run's range of tapered_e_scale)
    from housingfe.bearings.catalogue import estimated_internals

    e_specs = {}
    for scale in (0.85, 1.15):
        with estimated_internals(tapered_e_scale=scale):
            e_specs[scale] = tap.to_coupling_spec()

    # the matrices at the statics loads beside the shafts' bending
    bend = shaft_bending(ball)
    diag_rows = []
    for cfg, s in (("ball", ball_spec), ("tapered_roller", tap_spec), ("self_aligning", sa_spec)):
        for name, (K, _) in common.bearing_matrices(s).items():
            K = np.array(K, float)
            shaft = name.split("_")[0]
            diag_rows.append({"configuration": cfg, "bearing": name, "k_xx": K[0, 0], "k_yy": K[1, 1],
                              "k_zz": K[2, 2], "k_txtx": K[3, 3], "k_tyty": K[4, 4],
                              "max_force_tilt_N_per_rad": float(np.abs(K[np.ix_([0, 1, 2], [3, 4])]).max()),
                              "max_axial_radial_N_per_m": float(max(abs(K[0, 2]), abs(K[1, 2]))),
                              "shaft_4EI_over_L": bend[shaft][0]})
            r = diag_rows[-1]
            print(f"{cfg:15s} {name:13s} k_xx {r['k_xx']:.2e} k_yy {r['k_yy']:.2e} k_zz {r['k_zz']:.2e} "
                  f"k_txtx {r['k_txtx']:.2e} k_tyty {r['k_tyty']:.2e} | max k_F,theta "
                  f"{r['max_force_tilt_N_per_rad']:.2e} max k_xz,yz {r['max_axial_radial_N_per_m']:.2e} | "
                  f"4EI/L {bend[shaft][0]:.2e} (L {bend[shaft][1]:.3f} m, d {bend[shaft][2]:.3f} m)", flush=True)

    def patched(dt, fn):
        return Patched(dt, lambda s: common.with_bearing_matrices(s, fn))

    variants = [
        ("tapered_roller", "as computed", tap),
        ("tapered_roller", "moment rows/columns zeroed", patched(tap, common.scale_moments(0.0))),
        ("tapered_roller", "translational block from ball (moments kept)", patched(tap, common.translations_of(ball_spec))),
        ("tapered_roller", "translations scaled to ball's radial size (S K S)", patched(tap, radial_size_of(ball_spec))),
        ("tapered_roller", "ball's moment rows/columns swapped in", patched(tap, moments_of(ball_spec))),
        ("tapered_roller", "axial-radial k_xz, k_yz zeroed", patched(tap, zero_couplings(True, False))),
        ("tapered_roller", "force-tilt couplings zeroed", patched(tap, zero_couplings(False, True))),
        ("tapered_roller", "axial-radial and force-tilt couplings zeroed", patched(tap, zero_couplings(True, True))),
        *[("tapered_roller", f"catalogue e x {scale:g} (contact angle {math.degrees(math.atan(e * scale / 1.5)):.1f} / "
           f"{math.degrees(math.atan(e2 * scale / 1.5)):.1f} deg)", patched(tap, positions_of(e_specs[scale], LOCATING)))
          for scale, e, e2 in ((0.85, 0.35, 0.43), (1.15, 0.35, 0.43))],
        ("tapered_roller", "self-aligning at the floating positions (both shaft ends stiff)",
         patched(tap, positions_of(sa_spec, FLOATING))),
        ("self_aligning", "as computed (moment rows/columns zero by construction)", sa),
        ("self_aligning", "translational block from ball (= ball, moments zeroed)", patched(sa, common.translations_of(ball_spec))),
        ("self_aligning", "translations scaled to ball's radial size (S K S)", patched(sa, radial_size_of(ball_spec))),
        ("self_aligning", "ball's moment rows/columns swapped in", patched(sa, moments_of(ball_spec))),
        ("self_aligning", "axial-radial k_xz, k_yz zeroed", patched(sa, zero_couplings(True, False))),
        ("self_aligning", "ball at the floating positions (the tapered configuration's layout)",
         patched(sa, positions_of(ball_spec, FLOATING))),
    ]

    t1 = time.perf_counter()
    ball_model = session.model(ball, "ball")
    print(f"housing + ball basis {time.perf_counter() - t0:.0f} s", flush=True)
    refs = {}
    for mm in MESH_MOMENT_SETTINGS:
        lines, gap = variant_lines(session, ball_model, ball, mm)
        refs[mm] = session.runup(ball_model, TORQUE, lines=lines)
    rows = []
    for mm, ref in refs.items():
        for route in ROUTES:
            s, a = ref.series(route, session.radiation, TORQUE, "LwA_dB")
            rows.append({"configuration": "ball", "variant": "reference", "mesh_moment": mm, "route": route,
                         "mean_LwA_dBA": mean_level(ref, route), "max_LwA_dBA": float(a.max()), "max_at_rpm": float(s[np.argmax(a)])})
    print("ball: " + "; ".join(f"{r['mesh_moment']}/{r['route']} mean L_WA {r['mean_LwA_dBA']:.1f}, max "
                               f"{r['max_LwA_dBA']:.1f} at {r['max_at_rpm']:g}" for r in rows), flush=True)
    print(f"ball reference run-ups {time.perf_counter() - t1:.0f} s", flush=True)
    for cfg, name, dt in variants:
        t2 = time.perf_counter()
        spec_v = dt.to_coupling_spec()
        psd = min_eigenvalue_ratio(spec_v)
        model = session.model(dt, f"{cfg}: {name}")
        for mm in MESH_MOMENT_SETTINGS:
            lines, gap = variant_lines(session, model, dt, mm)
            res = session.runup(model, TORQUE, lines=lines)
            for route in ROUTES:
                rows.append({"configuration": cfg, "variant": name, "mesh_moment": mm, "route": route,
                             "min_eig_ratio": psd, "lead_gap": gap, "mean_LwA_dBA": mean_level(res, route),
                             **metrics(res, refs[mm], route)})
        sel = [r for r in rows[-2 * len(MESH_MOMENT_SETTINGS):] if r["route"] == "mesh_force"]
        print(f"{cfg}: {name} (min eig/max {psd:.1e}) " + "; ".join(
            f"{r['mesh_moment']}/{r['route']} {r['mean_total_dB']:+.2f}±{r['sd_total_dB']:.2f} "
            f"tooth {r['mean_tooth_dB']:+.2f}±{r['sd_tooth_dB']:.2f} (L_WA {r['mean_LwA_dBA']:.1f})" for r in sel)
            + f"  {time.perf_counter() - t2:.1f} s", flush=True)
    wall = time.perf_counter() - t0
    load1 = os.getloadavg()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    keys = ["configuration", "variant", "mesh_moment", "route", "mean_total_dB", "sd_total_dB", "mean_tooth_dB",
            "sd_tooth_dB", "mean_LwA_dBA", "max_LwA_dBA", "max_at_rpm", "min_eig_ratio", "lead_gap"]
    with open(out / "tapered_factors.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    with open(out / "tapered_diagonals.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, list(diag_rows[0]))
        w.writeheader()
        w.writerows(diag_rows)
    (out / "tapered_factors.json").write_text(json.dumps(
        {"coarse": args.coarse, "overrides": overrides, "wall_s": wall, "loadavg_start": load0, "loadavg_end": load1,
         "models": [vars(e) for e in session.log], "rows": rows, "diagonals": diag_rows}, indent=1, default=float))
    print(f"{wall:.0f} s wall, load average {load0[0]:.1f} -> {load1[0]:.1f}; {out}/tapered_factors.csv")


if __name__ == "__main__":
    main()
