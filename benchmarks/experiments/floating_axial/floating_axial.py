"""Does the floating bearing's outer ring stick in its bore or slide at the run-up's vibration amplitudes?

A floating bearing's outer ring can slide axially in its bore only when the axial force on it exceeds the friction
of the fit, mu F_r (F_r its radial load).  The model gives every floating bearing its full linearised axial
stiffness (the ring stuck).  This script measures, for the default run-up (test-gearbox-runup: gear set A, ball,
2000 N m) and the four configurations of `housingfe study bearings` (gear set B, 2000 N m), on both routes:

1. the dynamic axial force the floating bearings put on their bores, per speed: the bore loads of the run-up
   (RouteResult.bore_loads, complex rms per line; tf_omega's scaled to the source's L_omega as its L_v is) projected
   on the shaft axis; the peak of the time signal bounded by the sum over the speed's harmonic lines of sqrt(2) |F_n|
   (phases ignored: an upper bound), and its rms sqrt(sum |F_n|^2);
2. the friction limit mu (F_r - F_r_dyn) with F_r the static radial load of the bearing (Drivetrain.bearing_loads,
   the statics the bearing matrices are linearised at) and F_r_dyn the same bound of the dynamic radial force's peak
   (the radial load can dip while the axial one peaks), mu = 0.1 and 0.2 (a lubricated steel ring in a cast iron /
   steel bore, README);
3. the static axial force on each bearing: in the statics (exactly 0 at a floating bearing by construction) and in
   the linear FE interior on rigid bores under the mean tooth force (as the misalignment model loads it), where the
   floating bearing's axial stiffness takes its share of the helical mesh's axial force.

    PYTHONPATH=. /work/main/.venv/bin/python benchmarks/experiments/floating_axial/floating_axial.py [--out DIR] [--coarse] [--only-default]

Writes floating_axial.csv (per case, route, bearing, speed), margins.csv (per case, route, floating bearing: the
smallest margin over the speeds), static.csv (part 3), floating_axial.png, run.json.  Nothing in the package is
changed.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import time
from pathlib import Path

import numpy as np

from housingfe.outputs import write_records

TORQUE = 2000.0
MUS = (0.1, 0.2)
ROUTES = ("tf_omega", "mesh_force")
# (case, scene overrides, gear set, bearing configuration); B ball first: the study's reference and basis
CASES = (("A_ball", (), "A", "ball"),
         ("B_ball", ("drivetrain.gear_set=B",), "B", "ball"),
         ("B_angular_contact", ("drivetrain.gear_set=B",), "B", "angular_contact"),
         ("B_self_aligning", ("drivetrain.gear_set=B",), "B", "self_aligning"),
         ("B_tapered_roller", ("drivetrain.gear_set=B",), "B", "tapered_roller"))


def peak_and_rms(amplitudes, groups):
    """Per group (e.g. per speed) of complex rms line amplitudes (lines,) or (lines, 3): (peak bound, rms) of the
    time signal, peak bound = sum over the group's lines of sqrt(2) |a| (|a| the vector norm for (lines, 3): a
    harmonic's rotating force reaches at most sqrt(2) times its rms norm), rms = sqrt(sum |a|^2).  Returns
    (unique groups, peak, rms)."""
    a = np.asarray(amplitudes)
    mag = np.abs(a) if a.ndim == 1 else np.sqrt(np.sum(np.abs(a) ** 2, axis=-1))
    g = np.asarray(groups)
    keys = np.unique(g)
    peak = np.array([math.sqrt(2.0) * mag[g == k].sum() for k in keys])
    rms = np.array([math.sqrt(np.sum(mag[g == k] ** 2)) for k in keys])
    return keys, peak, rms


def synthesised_peak(amplitudes, harmonics, groups, samples: int = 512):
    """Per group (speed) the largest |f(t)| of f(t) = sum_n sqrt(2) Re(a_n exp(i 2 pi n t / T)) over one tooth period
    T (complex rms line amplitudes a_n of harmonic n, N): the time peak where the lines' phases are coherent (route
    mesh_force: one periodic mesh excitation per speed), against the bound of `peak_and_rms`."""
    a, n, g = np.asarray(amplitudes), np.asarray(harmonics, float), np.asarray(groups)
    phase = np.exp(2j * np.pi * np.arange(samples) / samples)
    return np.array([np.max(np.abs(np.sqrt(2.0) * np.real(a[g == k] @ phase[None, :] ** n[g == k][:, None])))
                     for k in np.unique(g)])


def stick_margin(axial_peak, radial_static, radial_peak, mu):
    """The friction fit's margin against sliding: mu (F_r - F_r_dyn) / F_a_dyn (N / N; > 1: the ring sticks), with
    F_a_dyn the axial force's peak, F_r the static radial load, F_r_dyn the dynamic radial force's peak (all N).
    A radial load that the vibration can lift off (F_r_dyn >= F_r) gives 0."""
    limit = mu * np.maximum(np.asarray(radial_static, float) - np.asarray(radial_peak, float), 0.0)
    return limit / np.asarray(axial_peak, float)


def static_bearing_forces(drivetrain) -> dict:
    """{bearing: (axial N, radial N)} the bearings put on RIGID bores in the linear FE interior under the mean tooth
    force (Drivetrain.mesh_node_loads at the mean normal force, the spin held, no mesh spring or drive line: as
    housingfe.drivetrain.misalignment.static_gear_tilts), axial along the shaft axis."""
    from housingfe.drivetrain.interior import interior_matrices, parts
    from housingfe.drivetrain.misalignment import _gear_loads

    forces = drivetrain.gear_forces()
    spec = drivetrain.to_coupling_spec(forces).model_copy(update={"gear_meshes": [], "drive_lines": [],
                                                                   "aux_gearbox": None})
    centres = {s.name: drivetrain.shaft(s.shaft).point(s.position) for s in drivetrain.bearings}
    K, _, _, names = interior_matrices(spec, centres)
    index = {n: 6 * i for i, n in enumerate(names)}
    f = np.zeros(K.shape[0])
    scale = float(np.max(np.abs(np.diag(K))))
    loads, axes = _gear_loads(drivetrain, forces)       # the mean tooth force without its moment about the axis
    for node, load in loads.items():
        i = index[node]
        f[i:i + 6] += load
        K[i + 3:i + 6, i + 3:i + 6] += scale * np.outer(axes[node], axes[node])     # hold the spin
    u = np.linalg.solve(K, f)
    seat = {s.name: s for s in drivetrain.bearings}
    out = {}
    for e in parts(spec, centres).bearings:
        shaft_node, bore = e.nodes
        F = -(np.asarray(e.K, float)[6:9, 0:6] @ u[index[shaft_node]:index[shaft_node] + 6])
        a = np.asarray(drivetrain.shaft(seat[bore].shaft).axis, float)
        a /= np.linalg.norm(a)
        out[bore] = (float(F @ a), float(np.linalg.norm(F - (F @ a) * a)))
    return out


def case_rows(case, drivetrain, model, res) -> tuple[list, list, list]:
    """Per route and bearing and speed: the axial and radial dynamic bore forces (peak bound, rms) against the
    friction limits; the smallest margin over speeds per floating bearing; the static axial forces."""
    from housingfe.drivetrain.bore_loads import structure_bearing_elements

    els = structure_bearing_elements(model.structure, model.reduction.vectors)
    seats = {s.name: s for s in drivetrain.bearings}
    statics = drivetrain.bearing_loads()
    linear = static_bearing_forces(drivetrain)
    ln = res.lines
    rows, margins, static = [], [], []
    for b, e in enumerate(els):
        s = seats[e.bore]
        Fx, Fy, Fz = statics[e.bore][:3]
        static.append({"case": case, "bearing": e.bore, "role": "locating" if s.locating else "floating",
                       "F_r_statics_N": math.hypot(Fx, Fy), "F_a_statics_N": Fz,
                       "F_r_linear_rigid_bores_N": linear[e.bore][1], "F_a_linear_rigid_bores_N": linear[e.bore][0],
                       "mu01_F_r_N": 0.1 * math.hypot(Fx, Fy)})
    for route in ROUTES:
        rr = res.routes[route]
        scale = 10 ** ((rr.L_v - rr.response.velocity_level_db) / 20)     # tf_omega: to the source's L_omega
        for b, e in enumerate(els):
            s = seats[e.bore]
            a = np.asarray(drivetrain.shaft(s.shaft).axis, float)
            a /= np.linalg.norm(a)
            F = rr.bore_loads[:, b, :3] * scale[:, None]
            axial = F @ a
            radial = F - axial[:, None] * a[None, :]
            speeds, ax_peak, ax_rms = peak_and_rms(axial, ln.speed)
            _, rad_peak, _ = peak_and_rms(radial, ln.speed)
            # tf_omega scales each line by a magnitude (to the source's L_omega): no phases across its harmonics
            synth = synthesised_peak(axial, ln.harmonic, ln.speed) if route == "mesh_force" \
                else np.full(len(speeds), np.nan)
            F_r = math.hypot(*statics[e.bore][:2])
            m = {mu: stick_margin(ax_peak, F_r, rad_peak, mu) for mu in MUS}
            for k, sp in enumerate(speeds):
                rows.append({"case": case, "route": route, "bearing": e.bore,
                             "role": "locating" if s.locating else "floating", "speed_rpm": float(sp),
                             "F_a_dyn_peak_N": float(ax_peak[k]), "F_a_dyn_rms_N": float(ax_rms[k]),
                             "F_a_dyn_peak_synthesised_N": float(synth[k]),
                             "F_r_dyn_peak_N": float(rad_peak[k]), "F_r_static_N": F_r,
                             **{f"margin_mu{mu:g}_dB": float(20 * np.log10(m[mu][k])) for mu in MUS}})
            if not s.locating:
                k = int(np.argmin(m[MUS[0]]))
                margins.append({"case": case, "route": route, "bearing": e.bore, "F_r_static_N": F_r,
                                "F_a_dyn_peak_max_N": float(ax_peak.max()),
                                "F_a_dyn_peak_synthesised_max_N": float(np.max(synth)),
                                "at_speed_rpm": float(speeds[int(np.argmax(ax_peak))]),
                                "F_r_dyn_peak_max_N": float(rad_peak.max()),
                                **{f"min_margin_mu{mu:g}_dB": float(20 * np.log10(m[mu].min())) for mu in MUS},
                                "min_margin_at_rpm": float(speeds[k]),
                                # the friction coefficient below which the ring would slide at some speed
                                "mu_slides_below": float(MUS[0] / m[MUS[0]].min())})
    return rows, margins, static


def main(argv=None):
    from housingfe.studies.chain_session import ChainSession, ModelPool

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", default="/tmp/floataxial-exp")
    p.add_argument("--coarse", action="store_true", help="60 mm housing mesh, lines to 1.5 kHz (a quick look)")
    p.add_argument("--only-default", action="store_true", help="the default run-up (gear set A, ball) alone")
    args = p.parse_args(argv)
    extra = ['housing.set=["mesh.size=0.06"]', "runup.f_max_hz=1500.0"] if args.coarse else []
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0, load0 = time.perf_counter(), os.getloadavg()
    housings = {}
    sessions, timings = {}, {}
    rows, margins, static = [], [], []
    for case, overrides, gear_set, bearings in CASES[:1] if args.only_default else CASES:
        t = time.perf_counter()
        if overrides not in sessions:     # one session per scene (the study's for set B); the housing mesh shared
            sessions[overrides] = ChainSession.from_scene("test-gearbox-runup", [*overrides, *extra],
                                                          pool=ModelPool(housings=housings))
        session = sessions[overrides]
        dt = session.drivetrain(gear_set, bearings, TORQUE)
        model = session.model(dt, case)
        res = session.runup(model, TORQUE)
        a, b, c = case_rows(case, dt, model, res)
        rows += a
        margins += b
        static += c
        timings[f"{case}_s"] = time.perf_counter() - t
        print(f"{case}: {timings[f'{case}_s']:.1f} s ({session.log[-1].how})", flush=True)
    write_records(out / "floating_axial.csv", rows)
    write_records(out / "margins.csv", margins)
    write_records(out / "static.csv", static)
    for r in static:
        print("static", {k: (round(v, 1) if isinstance(v, float) else v) for k, v in r.items()})
    for r in margins:
        print("margin", {k: (round(v, 1) if isinstance(v, float) else v) for k, v in r.items()})
    _plot(out / "floating_axial.png", rows)
    wall = time.perf_counter() - t0
    json.dump({"coarse": args.coarse, "wall_s": wall, "timings_s": timings, "mu": MUS,
               "loadavg_start": load0, "loadavg_end": os.getloadavg()}, open(out / "run.json", "w"), indent=1)
    print(f"wall {wall:.0f} s; wrote {out}")
    return 0




def _plot(path, rows):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    floating = sorted({r["bearing"] for r in rows if r["role"] == "floating"})
    fig, axes = plt.subplots(1, len(floating), figsize=(7 * len(floating), 4.8), squeeze=False)
    cases = list(dict.fromkeys(r["case"] for r in rows))
    colours = dict(zip(cases, plt.rcParams["axes.prop_cycle"].by_key()["color"]))
    for ax, bearing in zip(axes[0], floating):
        for case in cases:
            for route, style in (("tf_omega", "o-"), ("mesh_force", "x--")):
                sel = [r for r in rows if r["case"] == case and r["route"] == route and r["bearing"] == bearing]
                if sel:
                    ax.plot([r["speed_rpm"] for r in sel], [r["F_a_dyn_peak_N"] for r in sel], style, ms=3,
                            color=colours[case], label=f"{case}, {route}")
        F_r = {r["F_r_static_N"] for r in rows if r["bearing"] == bearing}
        for mu, ls in zip(MUS, (":", "-.")):
            ax.axhline(mu * min(F_r), color="k", ls=ls, label=f"mu F_r, mu = {mu:g} (smallest F_r)")
        ax.set_yscale("log")
        ax.set_xlabel("pinion speed (rev/min)")
        ax.set_ylabel("axial bore force, peak bound sum sqrt(2)|F_n| (N)")
        ax.set_title(f"floating bearing {bearing}: dynamic axial force vs fit friction")
        ax.set_ylim(0.1, 1e5)
        ax.legend(fontsize=6, ncol=3, loc="upper left")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    raise SystemExit(main())
