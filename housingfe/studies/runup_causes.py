"""`housingfe runup-causes [scene]`: where the run-up prediction and the thesis' differ, measured.

The thesis names its causes for the low calculated levels of Ch. 5 (Secs. 5.4, 5.5, 5.10, 6.1): few modes per
band, modes above 4 kHz neglected, the damping estimate, how shafts and bearings meet the housing (and, for
L_omega, the rigid housing under the lumped source).  Each is a variant of the run-up that changes exactly that
and is evaluated on the same coupled model (one basis; variants re-project the small system or truncate the
basis):

* damping: modal xi 0.02 and 0.08 around the thesis' 0.04;
* modes: the basis truncated at f_max (the thesis' 4 kHz, no modes above, no static correction) and at 2 kHz,
  against ours (modes to 1.5 f_max plus static residual vectors);
* lines: the tooth frequency alone (what the thesis' tooth-band figures show) against every harmonic to f_max;
* bearings (how the shafts meet the housing, Rayleigh-Ritz re-analyses): the ball bearings' moment stiffness
  removed (their moment rows and columns zeroed, the thesis' FE stand-in for self-aligning bearings, Sec. 5.8),
  and the self-aligning configuration itself (spherical roller model: zero moment stiffness and about five times
  the ball bearings' radial stiffness; benchmarks/experiments/bearing_ranking/ separates the two);
* radiation: Föller's sigma against sigma = 1 (from the scene's radiators);
* modes per 1/3-octave band of the tooth frequencies (125-630 Hz) in the coupled model.

Per variant and route: max L_WA and its speed, the L_WA peaks, the speed-law slope, the energy mean over
800-1500 rpm and its change against the reference.  Writes causes.csv and causes.md to the result folder.
"""
from __future__ import annotations

import argparse
import dataclasses
import time
from pathlib import Path

import numpy as np

from housingfe import outputs
from housingfe.levels import third_octave_bands
from housingfe.studies.chain_session import ChainSession, energy_mean_db, lwa_curve, maximum

COLUMNS = ("variant", "route", "radiation", "LwA_max_dBA", "at_rpm", "peaks_rpm", "speed_law_dBA_per_doubling",
           "LwA_mean_800_1500_dBA", "change_vs_reference_dB")


def _truncated(basis, f_max: float):
    keep = int(np.sum(basis.frequencies_hz < f_max))
    return dataclasses.replace(basis, eigenvalues=basis.eigenvalues[:keep], vectors=basis.vectors[:keep],
                               residuals=basis.residuals[:keep], f_max=f_max, expected_count=keep)


def without_moment_stiffness(drivetrain):
    """The drivetrain with every FE bearing's 6x6 K (its own, at the statics loads) with the tilt rows and columns
    (theta_x, theta_y) zeroed: what the thesis' FE used for self-aligning bearings (Sec. 5.8)."""
    spec = drivetrain.to_coupling_spec()
    matrices = {b.name: b.matrices() for b in spec.bearings}
    seats = []
    for seat in drivetrain.bearings:
        K, C = matrices[seat.name]
        K = np.array(K, float)
        K[3:5, :] = 0.0
        K[:, 3:5] = 0.0
        seats.append(dataclasses.replace(
            seat, designation=None, model=None, stiffness=None, stiffness_matrix=tuple(map(tuple, K)),
            damping_matrix=None if C is None else tuple(map(tuple, np.asarray(C, float)))))
    return dataclasses.replace(drivetrain, bearings=tuple(seats), bearing_configuration=None)


def _rows(variant: str, res, torque: float, reference: dict | None) -> list[dict]:
    from housingfe.runup.checks import peaks, speed_law_slope

    out = []
    for route in res.routes:
        for rad in res.radiators:
            s, lwa = lwa_curve(res, route, rad, torque)
            top, at = maximum(s, lwa)
            mean = energy_mean_db(s, lwa)
            ref = reference.get((route, rad)) if reference else None
            out.append({"variant": variant, "route": route, "radiation": rad, "LwA_max_dBA": round(top, 1),
                        "at_rpm": at, "peaks_rpm": " ".join(f"{x:g}" for x in peaks(s, lwa)),
                        "speed_law_dBA_per_doubling": round(speed_law_slope(s, lwa), 2),
                        "LwA_mean_800_1500_dBA": round(mean, 1),
                        "change_vs_reference_dB": "" if ref is None else round(mean - ref, 1)})
    return out


def _tooth_only(res):
    """The run-up with the tooth frequency line alone (harmonic 1)."""
    from housingfe.levels import a_weighting_db
    from housingfe.runup.chain import RunupResult

    ln = res.lines
    keep = ln.harmonic == 1
    totals = []
    for row in res.totals:
        p = next(k for k, pt in enumerate(ln.points) if pt[0] == row["torque_nm"] and pt[1] == row["speed_rpm"])
        k = int(np.flatnonzero(keep & (ln.point == p))[0])
        Lw = res.L_W[row["route"], row["radiation"]][k]
        totals.append({**row, "Lw_dB": float(Lw), "LwA_dB": float(Lw + a_weighting_db(ln.frequency[k]))})
    return RunupResult(ln, res.routes, res.L_sigma, res.L_W, res.area_level_db, res.radiators, totals, res.timings)


def run_study(scene_name: str = "test-gearbox-runup", out_dir: str | None = None, overrides=()) -> Path:
    """Run the variants (module docstring) of a run-up scene at its highest torque; returns the result folder."""
    from housingfe.progress import Progress
    from housingfe.response.reduced import RitzReduction
    from housingfe.runup.chain import unit_loads, with_reduction

    t0 = time.perf_counter()
    session = ChainSession.from_scene(scene_name, overrides)
    scene, spec, comm = session.scene, session.spec, session.comm
    torque = max(spec.torques_nm)
    out = Path(out_dir or f"results/runup-causes-{scene.scene.name}")
    outputs.reserve_output(out, comm, inputs=[session.scene_path])     # before the model is built
    # steps: the coupled model, then the run-up of every variant (reference, 2 damping ratios, 2 truncations, and
    # with ball bearings the re-analyses without moment stiffness and with self-aligning bearings)
    progress = Progress(f"runup-causes {scene.scene.name}", 6 + 2 * (scene.drivetrain.bearings == "ball"), "steps",
                        comm=comm)
    dt = session.drivetrain(scene.drivetrain.gear_set, scene.drivetrain.bearings, torque)
    gm = session.model(dt, "reference")
    lines = session.lines(dt, torque)
    progress.update(note="coupled model and modal basis")

    def run(m, note: str):
        out = session.runup(m, torque, lines)
        progress.update(note=note)
        return out

    base = run(gm, "reference")
    rows = _rows(f"reference: xi {spec.damping_ratio:g}, modes to {gm.basis.f_max:g} Hz + static vectors, "
                 f"harmonics to {spec.f_max_hz:g} Hz", base, torque, None)
    ref = {(r["route"], r["radiation"]): r["LwA_mean_800_1500_dBA"] for r in rows}
    from housingfe.solvers.harmonic import Damping

    for xi in (0.02, 0.08):
        damping = Damping(lambda f: np.zeros(np.shape(f)), modal_ratio=xi)
        rows += _rows(f"damping xi {xi:g}", run(with_reduction(gm, gm.reduction.with_damping(damping)),
                                                f"damping xi {xi:g}"), torque, ref)
    loads, _, _ = unit_loads(gm.structure, gm.drivetrain)
    extra = {}
    for radiator in gm.radiators.values():
        extra.update(radiator.extra_points(gm.structure))
    for f_cut in (spec.f_max_hz, 0.5 * spec.f_max_hz):
        red = RitzReduction(_truncated(gm.basis, f_cut), loads, gm.reduction.damping, surface=spec.surface,
                            nodes=(gm.wheel_node,), extra_points=extra,
                            residual=False)
        rows += _rows(f"modes to {f_cut:g} Hz only, no static vectors",
                      run(with_reduction(gm, red), f"modes to {f_cut:g} Hz"), torque, ref)
    rows += _rows("tooth frequency line only (harmonic 1)", _tooth_only(base), torque, ref)
    if scene.drivetrain.bearings == "ball":
        rows += _rows("ball bearings without moment stiffness (moment rows and columns zeroed, re-analysed)",
                      run(session.model(without_moment_stiffness(dt), "no moments"), "no moment stiffness"), torque,
                      ref)
        other = dataclasses.replace(dt, bearing_configuration="self_aligning")
        rows += _rows("self-aligning bearings (spherical roller model: no moment stiffness AND ~5x the radial "
                      "stiffness, re-analysed)", run(session.model(other, "self-aligning"), "self-aligning"), torque, ref)
    progress.close()
    n = gm.basis.rigid_count
    freqs = gm.basis.frequencies_hz[n:]
    bands = third_octave_bands(125.0, 630.0)
    counts = {int(c): int(np.sum((freqs >= lo) & (freqs < hi)))
              for c, lo, hi in zip(bands.nominal, bands.lower, bands.upper)}
    with outputs.atomic_output_dir(out, comm) as tmp:
        if comm.rank == 0:
            outputs.write_csv(tmp / "causes.csv", COLUMNS, ([r[c] for c in COLUMNS] for r in rows))
            cells = [[r[c] for c in COLUMNS] for r in rows]
            tail = ("\n\nElastic modes of the coupled model per 1/3-octave band of the tooth frequencies: "
                    + ", ".join(f"{k} Hz: {v}" for k, v in counts.items())
                    + f"\n\n(wall time {time.perf_counter() - t0:.0f} s)\n")
            head = f"# Run-up causes: {scene.scene.name} at {torque:g} N m\n\n"
            # the file keeps every column whole; the terminal's blocks each repeat variant, route and radiation
            (tmp / "causes.md").write_text(head + outputs.format_table(list(COLUMNS), cells, width=None) + tail)
            text = head + outputs.format_table(list(COLUMNS), cells, keys=3) + tail
    if comm.rank == 0:
        print(text)
        print(f"results: {out}/")
    return out


def register_cli(subparsers) -> None:
    """Add `housingfe runup-causes [scene] [--out DIR] [--set KEY=VALUE]`."""
    p = subparsers.add_parser("runup-causes", help="the run-up's sensitivity to the thesis' named causes "
                                                   "(damping, modes above 4 kHz, harmonics, bearings, sigma)")
    p.add_argument("scene", nargs="?", default="test-gearbox-runup", help="a run-up scene (default test-gearbox-runup)")
    p.add_argument("--out", default=None, help="result folder (default results/runup-causes-<scene>)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scene value (repeatable)")
    p.set_defaults(func=_cmd)


def _cmd(args: argparse.Namespace) -> int:
    run_study(args.scene, args.out, args.set or [])
    return 0
