"""Why tapered rollers raise the source of `housingfe study bearings` by ~8 dB over 800-1500 rev/min (gear set B).

Per bearing configuration (ball, angular contact, self-aligning, tapered roller; 2000 N m, test-gearbox-runup with
drivetrain.gear_set=B, the defaults of `housingfe study bearings`):

1. the mesh misalignment under load (runup.misalignment = "rigid-bores", the default: the static tilt of the FE
   interior on rigid bores, housingfe.drivetrain.misalignment) and, for tapered rollers, which part of their
   matrices makes it (one factor at a time on the bearing matrices; rig layout: the wheel's tapered bearing at
   the back, Sec. 5.8);
2. the rigid-bore lumped source (L_omega of the tf_omega route, L_F = |F_n - k_m d_n|) per speed, with the
   misalignment of each configuration and without any ("none"), and tapered rollers with the rig layout's tilt;
3. with the FE model (the study's: ball basis, every other configuration a Rayleigh-Ritz re-analysis): the mesh
   receptance |g(f)| k_ref over 2-3000 Hz and its peaks, and the coupled source's L_F per speed with and without
   misalignment.

    PYTHONPATH=. .venv/bin/python benchmarks/experiments/tapered_source/tapered_source.py [--out DIR] [--coarse]
        [--no-fe] [--runup]

Writes misalignment.csv, source_levels.csv (per configuration, source, misalignment, speed), source_means.csv,
source_harmonics.csv (per tooth harmonic, means over 800-1500 rev/min),
receptance.csv, receptance_peaks.csv, tapered_source.png, run.json; with --runup also runup_layouts.csv (4. the
run-ups with the FE bearings and the misalignment in the rig's layout: the wheel located at its back bearing).  Nothing in the package is changed; every
variant is a named alternative (nothing tuned).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

from housingfe.outputs import write_records

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "bearing_ranking"))
import common  # noqa: E402

TORQUE = 2000.0
CONFIGS = ("ball", "angular_contact", "self_aligning", "tapered_roller")
FRONTS = ("pinion_front", "wheel_front")
MEAN_RANGE = (800.0, 1500.0)


def speed_levels(lines) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(speeds, L_omega total, L_F total) per operating point: the energy sum over the lines (every harmonic to
    f_max), the run-up's total basis of housingfe.runup.slopes (the `excitation` term of variant_terms)."""
    pts = np.unique(lines.point)
    speeds = np.array([lines.speed[lines.point == p][0] for p in pts])
    lw = np.array([10 * np.log10(np.sum(10 ** (lines.L_omega[lines.point == p] / 10))) for p in pts])
    lf = np.array([10 * np.log10(np.sum(np.abs(lines.mesh_excitation[lines.point == p]) ** 2)) for p in pts])
    return speeds, lw, lf


def mean_in_range(speeds, values) -> float:
    keep = (speeds >= MEAN_RANGE[0]) & (speeds <= MEAN_RANGE[1])
    return float(np.mean(values[keep]))


def zero_force_tilt(K):
    K = K.copy()
    K[np.ix_(common.TRANSLATION, common.MOMENT)] = 0.0
    K[np.ix_(common.MOMENT, common.TRANSLATION)] = 0.0
    return K


def zero_axial_radial(K):
    K = K.copy()
    K[0, 2] = K[2, 0] = K[1, 2] = K[2, 1] = 0.0
    return K


def at_fronts(fn):
    """fn applied to the locating (tapered) bearings only."""
    return lambda name, K: fn(K) if name in FRONTS else K


def rig_drivetrain(session, config: str):
    """The configuration in the rig's layout (Sec. 5.8: the angular contact bearings "at the front (pinion) and at
    the back (wheel)"; the tapered ones "for the same reasons"): the scene's drivetrain with
    drivetrain.wheel_locating = "back" (the library's option, housingfe.drivetrain.description.test_gearbox): the
    configuration's locating bearing at wheel_back taking the axial force, its floating one at wheel_front, loads by
    the shaft's force and moment balance, the FE bearings and the source's misalignment from that layout."""
    from housingfe.runup.scene import drivetrain_of

    spec = session.scene.drivetrain.model_copy(update={"gear_set": "B", "bearings": config, "wheel_locating": "back"})
    return drivetrain_of(spec, TORQUE, session.scene.runup.drive_line_model)


def misalignment_rows(session) -> tuple[list, dict]:
    """Per configuration and tapered variant: gamma, lead gap and the gear tilts (rigid-bores model)."""
    from housingfe.drivetrain.misalignment import rigid_bore_misalignment

    rows, gaps = [], {}
    dts = {c: session.drivetrain("B", c, TORQUE) for c in CONFIGS}
    specs = {c: dts[c].to_coupling_spec() for c in CONFIGS}
    ball_k = common.bearing_matrices(specs["ball"])

    def ball_radial(name, K):
        r = (ball_k[name][0][0][0] + ball_k[name][0][1][1]) / (K[0, 0] + K[1, 1])
        s = np.ones(6)
        s[common.TRANSLATION] = np.sqrt(r)
        return s[:, None] * K * s[None, :]

    variants = [(c, c, None) for c in CONFIGS] + [
        ("tapered_roller", "tapered: force-tilt couplings zeroed",
         common.with_bearing_matrices(specs["tapered_roller"], at_fronts(zero_force_tilt))),
        ("tapered_roller", "tapered: axial-radial couplings zeroed",
         common.with_bearing_matrices(specs["tapered_roller"], at_fronts(zero_axial_radial))),
        ("tapered_roller", "tapered: both couplings zeroed",
         common.with_bearing_matrices(specs["tapered_roller"],
                                      at_fronts(lambda K: zero_axial_radial(zero_force_tilt(K))))),
        ("tapered_roller", "tapered: moment rows/columns zeroed",
         common.with_bearing_matrices(specs["tapered_roller"], common.scale_moments(0.0))),
        ("tapered_roller", "tapered: translations scaled to the ball bearing's radial stiffness",
         common.with_bearing_matrices(specs["tapered_roller"],
                                      lambda n, K: ball_radial(n, K) if n in FRONTS else K)),
        ("tapered_roller", "tapered at the pinion only (ball at wheel_front)",
         common.with_bearing_matrices(specs["tapered_roller"],
                                      lambda n, K: np.array(ball_k[n][0]) if n == "wheel_front" else K)),
        ("tapered_roller", "tapered at the wheel only (ball at pinion_front)",
         common.with_bearing_matrices(specs["tapered_roller"],
                                      lambda n, K: np.array(ball_k[n][0]) if n == "pinion_front" else K)),
    ] + [(c, f"{c}, rig layout: wheel located at its back bearing", "rig") for c in CONFIGS]
    for config, label, spec in variants:
        if spec == "rig":
            m = rigid_bore_misalignment(rig_drivetrain(session, config))
        else:
            m = rigid_bore_misalignment(dts[config], spec=spec)
        gaps[label] = m.lead_gap
        rows.append({"configuration": config, "variant": label, "gamma_urad": m.gamma * 1e6,
                     "lead_gap": m.lead_gap, "gap_across_face_um": m.gap_across_face * 1e6,
                     **{f"tilt_{g}_{a}_urad": 1e6 * float(t[i]) for g, t in (("pinion", m.tilt_pinion),
                                                                            ("wheel", m.tilt_wheel))
                        for i, a in enumerate("xyz")}})
        print(f"  {label:70s} gamma {m.gamma * 1e6:7.1f} urad, gap across the face {m.gap_across_face * 1e6:6.2f} um",
              flush=True)
    return rows, gaps


def main(argv=None):
    from housingfe.drivetrain.misalignment import lead_gap_law
    from housingfe.runup.chain import mesh_receptance, mesh_reference_stiffness, run_source, source_lines
    from housingfe.studies.chain_session import ChainSession

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", default="/tmp/tapered_source")
    p.add_argument("--coarse", action="store_true", help="60 mm housing mesh, lines to 1.5 kHz (a quick look)")
    p.add_argument("--no-fe", action="store_true", help="parts 1 and 2 only (no FE model)")
    p.add_argument("--runup", action="store_true",
                   help="also part 4: the run-ups (L_WA and its terms) with the FE bearings AND the source's "
                        "misalignment in the rig's layout, against the model's layout")
    args = p.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    # "model layout" = the wheel located at its front bearing for every configuration (the scene's default until
    # 2026-11-28, when it became the thesis' side, "configuration"); the rig layout is `rig_drivetrain`
    overrides = ["drivetrain.gear_set=B", "drivetrain.wheel_locating=front", 'radiation.models=["erp"]']
    if args.coarse:
        overrides += ['housing.set=["mesh.size=0.06"]', "runup.f_max_hz=1500.0"]
    t0, load0 = time.perf_counter(), os.getloadavg()
    timings = {}
    session = ChainSession.from_scene("test-gearbox-runup", overrides)
    spec = session.spec
    print(f"chain: source_receptance={spec.source_receptance}, misalignment={spec.misalignment_model}, "
          f"engagement={spec.engagement}, mesh_moment={spec.mesh_moment_model}, f_max {spec.f_max_hz:g} Hz", flush=True)
    dts = {c: session.drivetrain("B", c, TORQUE) for c in CONFIGS}
    f_t = [dts["ball"].gears.pair.tooth_frequency(v) for v in MEAN_RANGE]
    print(f"tooth frequency over {MEAN_RANGE[0]:g}-{MEAN_RANGE[1]:g} rpm: {f_t[0]:.0f}-{f_t[1]:.0f} Hz", flush=True)

    # 1. misalignment
    t = time.perf_counter()
    print("1. misalignment under load (rigid-bores):", flush=True)
    mis_rows, gaps = misalignment_rows(session)
    timings["misalignment_s"] = time.perf_counter() - t
    write_records(out / "misalignment.csv", mis_rows)

    # 2. the rigid-bore lumped source per configuration and misalignment
    t = time.perf_counter()
    level_rows, harmonic_rows, sources = [], [], {}

    def record(config, source_kind, mis, lines):
        s, lw, lf = speed_levels(lines)
        keep = (lines.speed >= MEAN_RANGE[0]) & (lines.speed <= MEAN_RANGE[1])
        for n in np.unique(lines.harmonic[keep]):
            at = keep & (lines.harmonic == n)
            harmonic_rows.append({"configuration": config, "source": source_kind, "misalignment": mis,
                                  "harmonic": int(n), "L_omega_mean_dB": float(np.mean(lines.L_omega[at])),
                                  "L_F_mean_dB": float(np.mean(20 * np.log10(np.abs(lines.mesh_excitation[at]))))})
        for i in range(len(s)):
            level_rows.append({"configuration": config, "source": source_kind, "misalignment": mis,
                               "speed_rpm": s[i], "L_omega_dB": lw[i], "L_F_dB": lf[i]})

    laws = {c: lead_gap_law(dts[c], "rigid-bores") for c in CONFIGS}
    # the rig layout's tilt as a constant lead gap (one torque here): misalignment "rig layout"
    rig_gaps = {c: gaps[f"{c}, rig layout: wheel located at its back bearing"] for c in CONFIGS}
    for config in CONFIGS:
        dt = dts[config]
        cases = {"rigid-bores": laws[config], "rig layout": lambda _t, g=rig_gaps[config]: g}
        cases["none"] = "none"
        for mis, law in cases.items():
            src = dt.source_model(harmonics=spec.harmonics, engagement=spec.engagement, misalignment=law)
            sources[config, mis] = src
            lines, _ = source_lines(src, spec.speeds, [TORQUE], spec.f_max_hz, "none")
            record(config, "rigid-bores", mis, lines)
    timings["lumped_source_s"] = time.perf_counter() - t

    # 3. the FE model: mesh receptance and the coupled source
    rec_rows, peak_rows = [], []
    if not args.no_fe:
        freqs = np.arange(2.0, min(3000.0, spec.f_max_hz) + 1e-9, 2.0)
        for config in CONFIGS:
            t = time.perf_counter()
            model = session.model(dts[config], label=config)
            timings[f"model_{config}_s"] = time.perf_counter() - t
            t = time.perf_counter()
            k_ref = mesh_reference_stiffness(model)
            g = mesh_receptance(model, freqs) * k_ref
            mag = np.abs(g)
            for f, v in zip(freqs, g):
                rec_rows.append({"configuration": config, "frequency_Hz": f, "abs_g_kref": abs(v),
                                 "re_g_kref": v.real, "im_g_kref": v.imag})
            peaks = [i for i in range(1, len(mag) - 1) if mag[i] > mag[i - 1] and mag[i] >= mag[i + 1]]
            for i in peaks:
                peak_rows.append({"configuration": config, "frequency_Hz": freqs[i], "abs_g_kref": mag[i],
                                  "in_tooth_band": f_t[0] <= freqs[i] <= f_t[1],
                                  "in_2nd_harmonic_band": 2 * f_t[0] <= freqs[i] <= 2 * f_t[1]})
            print(f"  {config:16s} k_ref {k_ref:.3e} N/m; |g| k_ref peaks > 1.5: " + ", ".join(
                f"{freqs[i]:.0f} Hz ({mag[i]:.2f})" for i in peaks if mag[i] > 1.5), flush=True)
            timings[f"receptance_{config}_s"] = time.perf_counter() - t
            t = time.perf_counter()
            for mis in ("rigid-bores", "rig layout", "none"):
                lines, _ = run_source(model, sources[config, mis], spec.speeds, [TORQUE], spec.f_max_hz,
                                      "coupled", spec.mesh_moment_model, spec.mesh_friction)
                record(config, "coupled", mis, lines)
            timings[f"coupled_source_{config}_s"] = time.perf_counter() - t
        write_records(out / "receptance.csv", rec_rows)
        write_records(out / "receptance_peaks.csv", peak_rows)
    write_records(out / "source_levels.csv", level_rows)
    if args.runup and not args.no_fe:
        t = time.perf_counter()
        write_records(out / "runup_layouts.csv", runup_layouts(session, dts, rig_gaps))
        timings["runup_layouts_s"] = time.perf_counter() - t
    write_records(out / "source_harmonics.csv", harmonic_rows)

    # means over 800-1500 rpm, differences to ball with the same source and misalignment
    means = []
    keys = sorted({(r["configuration"], r["source"], r["misalignment"]) for r in level_rows},
                  key=lambda k: (k[1], k[2], k[0]))
    curves = {}
    for key in keys:
        rows = [r for r in level_rows if (r["configuration"], r["source"], r["misalignment"]) == key]
        s = np.array([r["speed_rpm"] for r in rows])
        curves[key] = (s, np.array([r["L_omega_dB"] for r in rows]), np.array([r["L_F_dB"] for r in rows]))
    for key, (s, lw, lf) in curves.items():
        ref = curves.get(("ball", key[1], key[2]))
        d = {}
        if ref is not None:
            keep = (s >= MEAN_RANGE[0]) & (s <= MEAN_RANGE[1])
            d = {"dL_omega_to_ball_dB": float(np.mean((lw - ref[1])[keep])),
                 "dL_omega_sd_dB": float(np.std((lw - ref[1])[keep])),
                 "dL_F_to_ball_dB": float(np.mean((lf - ref[2])[keep])),
                 "dL_F_sd_dB": float(np.std((lf - ref[2])[keep]))}
        means.append({"configuration": key[0], "source": key[1], "misalignment": key[2],
                      "L_omega_mean_dB": mean_in_range(s, lw), "L_F_mean_dB": mean_in_range(s, lf), **d})
    write_records(out / "source_means.csv", means)
    print("3. source over 800-1500 rpm (mean of the per-speed totals; difference to ball, mean +- s.d.):")
    for m in means:
        extra = (f"  dL_omega {m['dL_omega_to_ball_dB']:+6.2f} +- {m['dL_omega_sd_dB']:.2f}, dL_F "
                 f"{m['dL_F_to_ball_dB']:+6.2f} +- {m['dL_F_sd_dB']:.2f}" if "dL_F_to_ball_dB" in m else "")
        print(f"  {m['configuration']:28s} {m['source']:11s} mis={m['misalignment']:11s} L_omega "
              f"{m['L_omega_mean_dB']:6.2f} L_F {m['L_F_mean_dB']:6.2f}{extra}")

    _plot(out / "tapered_source.png", curves, rec_rows, f_t, args.no_fe)
    wall = time.perf_counter() - t0
    json.dump({"coarse": args.coarse, "no_fe": args.no_fe, "overrides": overrides, "wall_s": wall,
               "timings_s": timings, "loadavg_start": load0, "loadavg_end": os.getloadavg()},
              open(out / "run.json", "w"), indent=1)
    print(f"wall {wall:.0f} s (load {load0[0]:.1f} -> {os.getloadavg()[0]:.1f}); wrote {out}")
    return 0


def runup_layouts(session, dts, rig_gaps) -> list:
    """Part 4: per configuration the run-up (the study's routes, erp) in the model's layout (the scene's source, as
    `housingfe study bearings`) and in the rig's (`rig_drivetrain`: drivetrain.wheel_locating = "back", a
    Rayleigh-Ritz re-analysis on the same basis with that layout's FE bearings and source misalignment, as
    `housingfe study bearings --set drivetrain.wheel_locating=back`), and per layout the mean difference of L_WA
    and of its terms to ball bearings over 800-1500 rev/min (housingfe.studies.variant_terms).  rig_gaps: unused
    since the library computes the rig layout's lead gap itself (kept for the call's shape)."""
    from housingfe.studies.variant_terms import decompose_difference, term_curves

    spec = session.spec
    radiation = session.radiation
    curves = {}
    for config in CONFIGS:
        model = session.model(dts[config], label=config)
        curves["model layout", config] = session.runup(model, TORQUE)
        model = session.model(rig_drivetrain(session, config), label=f"{config} (rig layout)")
        curves["rig layout", config] = session.runup(model, TORQUE)
    rows = []
    for (layout, config), res in curves.items():
        for route in spec.routes:
            tc = term_curves(res, route, radiation, TORQUE)
            ref = term_curves(curves[layout, "ball"], route, radiation, TORQUE)
            d = decompose_difference(tc[0], tc[1], ref[0], ref[1])
            rows.append({"layout": layout, "configuration": config, "route": route,
                         **{k: v for k, v in d.items() if k != "largest_term"}, "largest_term": d["largest_term"]})
            print(f"  {layout:13s} {config:16s} {route:10s} dL_WA {d['mean_diff_dB']:+6.2f}: excitation "
                  f"{d['d_excitation_dB']:+6.2f} T_path {d['d_transfer_path_dB']:+6.2f} T_housing "
                  f"{d['d_transfer_housing_dB']:+6.2f}", flush=True)
    return rows




def _plot(path, curves, rec_rows, f_t, no_fe):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = 2 if no_fe else 3
    fig, axes = plt.subplots(1, n, figsize=(6 * n, 4.5))
    colours = {"ball": "k", "angular_contact": "tab:blue", "self_aligning": "tab:green",
               "tapered_roller": "tab:red"}
    for ax, idx, what in ((axes[0], 1, "L_omega (dB re 5e-8 rad/s), rigid-bore source"),
                          (axes[1], 2, "L_F (dB re 1 N), coupled source")):
        for (config, src, mis), c in curves.items():
            if idx == 1 and src != "rigid-bores":
                continue
            if mis == "none" and config != "ball":
                continue             # identical to ball's (the lumped source does not see the FE bearings)
            style = {"rigid-bores": "-", "rig layout": "--", "none": ":"}[mis]
            if idx == 2 and src == "rigid-bores":
                continue
            ax.plot(c[0], c[idx], linestyle=style, color=colours[config], label=f"{config}, {src}, mis. {mis}")
        ax.axvspan(*MEAN_RANGE, color="0.93")
        ax.set_xlabel("speed (rev/min)")
        ax.set_ylabel(what)
        ax.legend(fontsize=6)
    if not no_fe:
        ax = axes[2]
        for config in CONFIGS:
            f = np.array([r["frequency_Hz"] for r in rec_rows if r["configuration"] == config])
            g = np.array([r["abs_g_kref"] for r in rec_rows if r["configuration"] == config])
            ax.semilogy(f, g, color=colours[config], label=config)
        ax.axvspan(*f_t, color="0.9", label="tooth frequency 800-1500 rpm")
        ax.axvspan(2 * f_t[0], 2 * f_t[1], color="0.96", label="2nd harmonic")
        ax.set_xlabel("frequency (Hz)")
        ax.set_ylabel("|g(f)| k_ref")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


if __name__ == "__main__":
    raise SystemExit(main())
