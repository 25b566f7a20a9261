"""Run-up outputs: runup.csv (totals per speed, torque, route, radiation), runup_harmonics.csv (per tooth harmonic),
spectra_<rpm>.csv / .png (like Figs. 5.2/5.5/5.8/5.9), runup.png (like Figs. 5.4/5.7/5.10 with the measured points),
slope_terms.csv / .png (the speed law split into the chain's terms, housingfe.runup.slopes), checks.csv,
summary.txt (the console summary) and runup.json (timings, provenance, the modal basis used, checks, modal
contributions per peak, the slope decomposition); when the run-up also ran the envelope bound (the face-width default
at an overlap ratio near an integer, housingfe.runup.scene), runup_envelope_bound.csv (its totals, the columns of
runup.csv), runup_envelope_bound_harmonics.csv (its lines, the columns of runup_harmonics.csv) and runup.json's
"envelope_bound" (its checks and peak contributions, housingfe.runup.checks.evaluate on the bound's curves: what
`housingfe validate` reports as the rows 28.bound.*, beside the checks, not judged); with runup.as_made = <ISO grade>,
runup_as_made.csv (the tooth band and the totals with and without the expected sidebands of gears as made,
housingfe.runup.as_made) and runup.json's "as_made"."""
from __future__ import annotations

import math
import platform
from pathlib import Path

import numpy as np

from housingfe import outputs
from housingfe.data import thesis
from housingfe.report import resolution_lines
from housingfe.runup import slopes as slope_terms

TOTAL_COLUMNS = ("route", "radiation", "torque_nm", "speed_rpm", "tooth_frequency_hz", "L_omega_dB",
                 "L_omega_coupled_dB", "Lv_tooth_dB", "Lv_dB", "Lw_dB", "LwA_dB", "harmonics")
HARMONIC_COLUMNS = ("route", "radiation", "torque_nm", "speed_rpm", "harmonic", "frequency_hz", "L_omega_dB",
                    "TF_omega_dB", "L_omega_coupled_dB", "Lv_dB", "L_sigma_dB", "Lw_dB", "LwA_dB")
CHECK_COLUMNS = ("check", "quantity", "ours", "measured", "thesis_calculated", "goal", "passed", "note")


# the run-up per micrometre of TE (runup.te_sensitivity): per torque, harmonic n, route, radiation and speed the
# levels of line n when 1 um of TE at harmonic n alone drives the chain, and the run's total L_WA of that drive
SENSITIVITY_CSV = "te_sensitivity.csv"
# the user's measured run-up beside ours (runup.measured; housingfe.runup.measured.COMPARISON_COLUMNS)
MEASURED_CSV = "measured_comparison.csv"
SENSITIVITY_COLUMNS = ("route", "radiation", "torque_nm", "speed_rpm", "harmonic", "frequency_hz", "L_omega_dB",
                       "L_omega_coupled_dB", "Lv_dB", "Lw_dB", "LwA_dB", "LwA_total_dB")
BOUND_CSV = "runup_envelope_bound.csv"
BOUND_HARMONICS_CSV = "runup_envelope_bound_harmonics.csv"


def bound_lines(results: dict, bound: dict, radiation: str) -> list[str]:
    """One summary line per torque: the maxima of L_WA (dB(A), sigma `radiation`) per route with the envelope bound
    (bound: {torque: RunupResult}) beside the default's (results: {torque: (model, RunupResult)})."""
    def maxima(res, torque):
        parts = []
        for route in res.routes:
            s, lwa = res.series(route, radiation, torque, "LwA_dB")
            i = int(np.argmax(lwa))
            parts.append(f"{lwa[i]:.1f} dB(A) @ {s[i]:g} rpm ({route})")
        return ", ".join(parts)

    return [f"  {torque:g} N m with the envelope bound: max L_WA {maxima(res, torque)}; default (face-width): "
            f"{maxima(results[torque][1], torque)}; sigma {radiation}; a bound, not a model ({BOUND_CSV})"
            for torque, res in bound.items()]


# seconds per picture on one idle core (test-gearbox-runup, 2026-11-26), to share the pictures out evenly
PICTURE_COST_S = {"spectrum": 0.28, "runup": 0.2, "slopes": 0.43}


def _import_pyplot() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot  # noqa: F401


def _fmt(v):
    if isinstance(v, float):
        # math.isfinite and a Python float: the text of np.isfinite and numpy's formatting, ~5x faster per value (the
        # 100 000+ rows of runup_harmonics.csv with gears as made in the totals)
        return "" if not math.isfinite(v) else f"{float(v):.6g}"
    return "" if v is None else v


def write(folder: Path, scene, results: dict, gm, check_rows: list, contributions: list, timings: dict,
          decompositions: list = (), notes: list = (), bound: dict | None = None,
          bound_checks: tuple | None = None, as_made=None, sensitivity: dict | None = None,
          comparison: dict | None = None) -> None:
    """Every output file of a run-up into `folder` (rank 0); decompositions: housingfe.runup.slopes
    SlopeDecomposition of every curve; notes: lines for the summary about the model's validity (e.g. the source's
    housingfe.source.roosmalen.overlap.cancellation_note); bound: {torque: RunupResult} of the envelope bound
    (engagement "envelope-bound" on the same models) -> runup_envelope_bound.csv and
    runup_envelope_bound_harmonics.csv; bound_checks: (check rows, peak contributions) of the bound's curves
    (housingfe.runup.checks.evaluate) -> runup.json "envelope_bound"; as_made: housingfe.runup.as_made.AsMadeRun
    (runup.as_made on) -> runup_as_made.csv and runup.json "as_made"; sensitivity: {torque: {n: RunupResult}} of
    1 um of TE at harmonic n (housingfe.runup.chain.te_sensitivity) -> te_sensitivity.csv and runup.json
    "te_sensitivity"; comparison: the measured run-up beside ours (housingfe.runup.scene.measured_comparison,
    runup.measured) -> measured_comparison.csv, runup.json "measured" and its points on runup.png."""
    totals = [r for _, res in results.values() for r in res.totals]
    outputs.write_csv(folder / "runup.csv", TOTAL_COLUMNS, ([_fmt(r[k]) for k in TOTAL_COLUMNS] for r in totals))
    if bound:
        outputs.write_csv(folder / BOUND_CSV, TOTAL_COLUMNS,
                          ([_fmt(r[k]) for k in TOTAL_COLUMNS] for res in bound.values() for r in res.totals))
        outputs.write_csv(folder / BOUND_HARMONICS_CSV, HARMONIC_COLUMNS,
                          ([_fmt(r[k]) for k in HARMONIC_COLUMNS] for res in bound.values() for r in res.harmonic_rows()))
    if as_made is not None:
        from housingfe.runup import as_made as am

        outputs.write_csv(folder / am.CSV, am.COLUMNS, ([_fmt(r[k]) for k in am.COLUMNS] for r in as_made.rows))
    if comparison is not None:
        from housingfe.runup import measured

        outputs.write_csv(folder / MEASURED_CSV, measured.COMPARISON_COLUMNS,
                          ([_fmt(r[k]) for k in measured.COMPARISON_COLUMNS] for r in comparison["rows"]))
    if sensitivity:
        outputs.write_csv(folder / SENSITIVITY_CSV, SENSITIVITY_COLUMNS,
                          ([_fmt(r[k]) for k in SENSITIVITY_COLUMNS] for r in sensitivity_rows(sensitivity)))
    harm = [r for _, res in results.values() for r in res.harmonic_rows()]
    # gears as made in the totals (runup.as_made_totals): a last column says which lines are the sidebands
    columns = HARMONIC_COLUMNS + (("line",) if any(res.lines.incoherent is not None for _, res in results.values())
                                  else ())
    outputs.write_csv(folder / "runup_harmonics.csv", columns, ([_fmt(r[k]) for k in columns] for r in harm))
    outputs.write_csv(folder / "checks.csv", CHECK_COLUMNS, ([_fmt(r[k]) for k in CHECK_COLUMNS] for r in check_rows))
    # the pictures (PICTURE_COST_S: matplotlib's layout, ~1.8 s together on one core) are drawn on two cores
    pictures = []
    for speed in scene.runup.spectrum_speeds_rpm:
        rows = [r for r in harm if abs(r["speed_rpm"] - speed) < 1e-9]
        if rows:
            outputs.write_csv(folder / f"spectra_{speed:g}rpm.csv", columns,
                              ([_fmt(r[k]) for k in columns] for r in rows))
            pictures.append((PICTURE_COST_S["spectrum"], lambda rows=rows, speed=speed: spectrum_plot(
                folder / f"spectra_{speed:g}rpm.png", rows, speed, scene.radiation.models[0])))
    pictures.append((PICTURE_COST_S["runup"], lambda: runup_plot(folder / "runup.png", scene, totals,
                                                                         comparison)))
    if decompositions:
        outputs.write_csv(folder / "slope_terms.csv", slope_terms.SLOPE_COLUMNS,
                          ([_fmt(r[k]) for k in slope_terms.SLOPE_COLUMNS]
                           for r in slope_terms.slope_rows(decompositions)))
        pictures.append((PICTURE_COST_S["slopes"], lambda: slope_terms.plot(folder / "slope_terms.png",
                                                                            decompositions)))
    _import_pyplot()                    # once, before the pictures are shared out (0.25 s)
    outputs.run_split(pictures, parallel=gm.structure.V.mesh.comm.size == 1)
    (folder / "summary.txt").write_text(summary_text(scene, results, gm, check_rows, timings, decompositions, notes,
                                                     sensitivity) + "\n")
    import dolfinx

    outputs.write_json(folder / "runup.json", {
        "scene": scene.scene.name, "description": scene.scene.description,
        "scene_settings": scene.model_dump(mode="json"),
        "mesh_moment": scene.runup.mesh_moment_model,     # in effect (the setting may leave it to the default)
        "mesh_friction": friction_in_effect(scene, results),
        "drive_line": scene.runup.drive_line_model,       # in effect
        "bearing_speeds": bearing_speeds_json(scene, results),
        "floating_axial": floating_axial_json(results),
        "timings_s": timings,
        "modal_basis": gm.summary(),
        "housing_resolution": _resolution(gm),
        "ritz_reanalysis": {f"{t:g}": m.reduction.frequencies_hz[:12].tolist() for t, (m, _) in results.items()},
        "checks": check_rows, "peak_contributions": contributions,
        "te_sensitivity": ({"harmonics": sorted({n for per in sensitivity.values() for n in per}),
                            "csv": SENSITIVITY_CSV,
                            "what": "the run-up driven by 1 um of quasi-static TE at one tooth harmonic alone, on the "
                                    "same models, without mesh moment and friction (housingfe.runup.chain."
                                    "te_sensitivity): a TE of a um gives the line's levels + 20 lg(a)"}
                           if sensitivity else None),
        "slope_terms": [d.to_json() for d in decompositions],
        "measured": None if comparison is None else {
            "file": comparison["measured"].source, "sha256": comparison["measured"].sha256, "csv": MEASURED_CSV,
            "outside_speeds": comparison["outside"], "statistics": comparison["statistics"],
            "what": "ours - measured at the measured speeds (ours linear in speed; housingfe.runup.measured)"},
        "envelope_bound": None if not bound_checks else {
            "engagement": "envelope-bound", "what": "a bound, not the model (docs/source.md)", "totals": BOUND_CSV,
            "harmonics": BOUND_HARMONICS_CSV, "checks": bound_checks[0], "peak_contributions": bound_checks[1]},
        "as_made": None if as_made is None else {
            "grade": as_made.grade, "pitch_model": as_made.pitch_model, "totals": "runup_as_made.csv",
            # runup.as_made_totals: runup.csv, runup_harmonics.csv, the spectra and the checks hold the sidebands too
            "in_totals": bool(scene.runup.as_made_totals),
            "bands_of_harmonics": [1, as_made.n_max],
            "sideband_lines": as_made.lines, "what": "expected sidebands of ISO 1328-1 deviations (docs/runup.md)",
            "speed_law_dBA_per_doubling": _as_made_laws(as_made, scene.radiation.models[0]),
            "speed_law_range_rpm": list(slope_terms.SPEED_LAW_RANGE_RPM)},
        "area_level_dB": next(iter(results.values()))[1].area_level_db,
        "provenance": {"python": platform.python_version(), "dolfinx": dolfinx.__version__,
                       "machine": platform.machine(), "mpi_ranks": gm.structure.V.mesh.comm.size},
    })


def _as_made_laws(as_made, radiation: str) -> dict:
    """runup.json "as_made" "speed_law_dBA_per_doubling": per torque and route the speed law of L_WA with and
    without the expected sidebands (housingfe.runup.as_made.speed_laws; NaN -> null)."""
    from housingfe.runup.as_made import speed_laws

    return {t: {route: {k: (round(v, 3) if math.isfinite(v) else None) for k, v in law.items()}
                for route, law in per.items()} for t, per in speed_laws(as_made, radiation).items()}


def spectrum_plot(path: Path, rows: list, speed: float, radiation: str) -> None:
    """Lines of L_omega, L_v (per route) and L_WA at one speed (like Figs. 5.2/5.5/5.8/5.9)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    routes = sorted({r["route"] for r in rows})
    for j, route in enumerate(routes):
        sel = [r for r in rows if r["route"] == route and r["radiation"] == radiation]
        f = np.array([r["frequency_hz"] for r in sel])
        off = (j - 0.5 * (len(routes) - 1)) * 0.02
        if j == 0:
            axes[0].vlines(f, 0, [r["L_omega_dB"] for r in sel], color="k", label="source (rigid bores)")
        if route == "mesh_force":
            axes[0].plot(f, [r["L_omega_coupled_dB"] for r in sel], "o", label="coupled model")
        axes[1].vlines(f * (1 + off), 0, [r["Lv_dB"] for r in sel], color=f"C{j}", label=route)
        axes[2].vlines(f * (1 + off), 0, [r["LwA_dB"] for r in sel], color=f"C{j}", label=route)
    for ax, label in zip(axes, ("L_omega (dB re 5e-8 rad/s)", "L_v (dB re 5e-8 m/s)", f"L_WA (dB(A) re 1 pW, {radiation})")):
        ax.set_xscale("log")
        ax.set_xlabel("frequency (Hz)")
        ax.set_ylabel(label)
        ax.set_ylim(bottom=max(0.0, ax.get_ylim()[1] - 80))
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"tooth harmonics at {speed:g} rev/min")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def runup_plot(path: Path, scene, totals: list, comparison: dict | None = None) -> None:
    """L_omega, L_v and L_WA over speed (like Figs. 5.4/5.7/5.10) with the measured points of set A, and those of
    a measured run-up the user brought (comparison: housingfe.runup.scene.measured_comparison; L_W is not drawn)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    tg = thesis()["test_gearbox"]
    rad = scene.radiation.models[0]
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2))
    torques = sorted({r["torque_nm"] for r in totals})
    routes = sorted({r["route"] for r in totals})
    for ti, torque in enumerate(torques):
        ls = "-" if ti == len(torques) - 1 else "--"
        for j, route in enumerate(routes):
            sel = [r for r in totals if r["route"] == route and r["radiation"] == rad and r["torque_nm"] == torque]
            s = [r["speed_rpm"] for r in sel]
            if j == 0:
                axes[0].plot(s, [r["L_omega_dB"] for r in sel], "k" + ls, label=f"source, {torque:g} N m")
            if route == "mesh_force":
                axes[0].plot(s, [r["L_omega_coupled_dB"] for r in sel], ls, color="C1",
                             label=f"coupled model, {torque:g} N m")
            axes[1].plot(s, [r["Lv_dB"] for r in sel], ls, color=f"C{j}", label=f"{route}, {torque:g} N m")
            axes[2].plot(s, [r["LwA_dB"] for r in sel], ls, color=f"C{j}", label=f"{route}, {torque:g} N m")
        for other in scene.radiation.models[1:]:
            for j, route in enumerate(routes):
                sel = [r for r in totals if r["route"] == route and r["radiation"] == other
                       and r["torque_nm"] == torque]
                axes[2].plot([r["speed_rpm"] for r in sel], [r["LwA_dB"] for r in sel], ":", color=f"C{j}",
                             label=f"{route}, {other}, {torque:g} N m")
    if scene.drivetrain.gear_set == "A" and scene.drivetrain.bearings == "ball":
        meas = tg["meas_L_omega_tooth_band_dB"]
        axes[0].plot([float(k) for k in meas], list(meas.values()), "rs", ms=8, label="measured (Sec. 5.3)")
        for s in tg["meas_high_Lv_speeds_rpm"]:
            axes[1].axvline(s, color="r", alpha=0.4)
        axes[1].plot([], [], "r", alpha=0.4, label="measured L_v peaks")
        axes[2].plot([250, 500, 1000, 1500], [74, 80, 86, 89], "rs", ms=7, label="measured, speed law (Fig. 5.10)")
        axes[2].axhline(tg["meas_Lw_max_dBA"], color="r", ls="--", alpha=0.6, label="measured max 100.5")
        axes[2].axhline(tg["calc_Lw_max_dBA"], color="gray", ls="--", alpha=0.6, label="thesis calc. max 89.4")
    if comparison is not None:
        axis = {"L_omega_dB": 0, "L_v_dB": 1, "L_WA_dBA": 2}
        for (quantity, torque), (speeds, values) in comparison["measured"].series.items():
            if quantity in axis:
                axes[axis[quantity]].plot(speeds, values, "D", mfc="none", color="m", ms=7,
                                          label="measured (runup.measured)" + (f", {torque:g} N m" if torque else ""))
    for ax, label in zip(axes, ("L_omega, tooth band (dB re 5e-8 rad/s)", "L_v, all harmonics (dB re 5e-8 m/s)",
                                f"L_WA (dB(A) re 1 pW), sigma: {rad}")):
        ax.set_xlabel("pinion speed (rev/min)")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"{scene.scene.name}: gear set {scene.drivetrain.gear_set}, {scene.drivetrain.bearings} bearings")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def bearing_speeds_json(scene, results: dict) -> dict:
    """runup.json "bearing_speeds": the setting (runup.bearing_speeds), whether the bearings depend on speed, and
    per torque (text) the speeds with a model of their own and the speeds held at another speed's matrices
    ({speed: held at}, housingfe.runup.chain.follow_speeds) with the reason."""
    out = {"setting": scene.runup.bearing_speeds, "fixed_speed_rpm": scene.drivetrain.bearing_speed_rpm,
           "speed_dependent": any(m.drivetrain.speed_dependent_bearings for m, _ in results.values()), "torques": {}}
    for t, (m, _) in results.items():
        if m.speed_models:
            out["torques"][f"{t:g}"] = {
                "models": len({id(v) for v in m.speed_models.values()}),
                "held": {f"{s:g}": at for s, at in sorted(m.held_speeds.items())}, "reason": m.held_reason}
    return out


def floating_axial_json(results: dict) -> dict | None:
    """runup.json "floating_axial": with drivetrain.floating_axial_ratio != 0 the ratio and per torque (text) what
    each shaft's floating bearing held ({shaft: {"requested_N", "held_N", "slid"}}, N; a ring slides where the held
    load would lift a directional locating bearing: Drivetrain.floating_axial_report); None at ratio 0."""
    reports = {f"{t:g}": m.drivetrain.floating_axial_report() for t, (m, _) in results.items()}
    if not any(reports.values()):
        return None
    ratio = next(iter(results.values()))[0].drivetrain.floating_axial_ratio
    return {"ratio": ratio, "torques": reports}


def floating_axial_lines(results: dict) -> list[str]:
    """The summary's lines on the floating bearings' held axial load, one per torque (none at ratio 0)."""
    from housingfe.drivetrain.description import FLOATING_AXIAL_KEY, floating_axial_text, slid_rings

    data = floating_axial_json(results)
    if data is None:
        return []
    lines = []
    for t, report in data["torques"].items():
        slid = slid_rings(report)
        lines.append(f"floating bearings ({FLOATING_AXIAL_KEY} = {data['ratio']:g}) at {t} N m, held axial load: "
                     f"{floating_axial_text(report)}; "
                     + (f"the {' and '.join(slid)} floating ring{'s' if len(slid) > 1 else ''} slid (the locating "
                        "bearing would lift off under the requested load)" if slid else "no ring slid"))
    return lines


def _resolution(gm) -> dict | None:
    """The housing mesh's resolution of the highest line (housingfe.fe.resolution), None if not known."""
    res = getattr(getattr(gm, "housing_model", None), "resolution", None)
    return res.as_dict() if res is not None else None


def friction_in_effect(scene, results: dict) -> dict:
    """The sliding friction of a run-up (runup.json "mesh_friction"): the setting (runup.mesh_friction), whether it
    is applied (on the mesh_force route), and the mean coefficients per torque {"<torque>": [min, max]} [-]."""
    setting = scene.runup.mesh_friction
    applied = setting != "none" and "mesh_force" in scene.runup.routes
    mu = {}
    for torque, (_, res) in results.items():
        if res.lines.friction_mu is not None:
            mu[f"{torque:g}"] = [float(res.lines.friction_mu.min()), float(res.lines.friction_mu.max())]
    return {"setting": setting, "applied": applied, "mu": mu}


def friction_line(scene, results: dict) -> str | None:
    """The summary's line on the sliding friction where it is on (None where it is off)."""
    fr = friction_in_effect(scene, results)
    if not fr["applied"]:
        return None
    lo = min(v[0] for v in fr["mu"].values())
    hi = max(v[1] for v in fr["mu"].values())
    if fr["setting"] == "iso13989":
        from housingfe.source.mesh_friction import ISO13989_ROUGHNESS_RA, ISO13989_VISCOSITY

        what = (f"mu {lo:.3f}-{hi:.3f} from ISO/TR 13989-1 at each speed and torque (formula from memory, not "
                f"verified; oil {ISO13989_VISCOSITY:g} Pa s, Ra {ISO13989_ROUGHNESS_RA * 1e6:g} um assumed)")
    else:
        what = f"mu {lo:.3f} fixed"
    return (f"mesh friction: the sliding friction (runup.mesh_friction), {what}, is applied with the mesh excitation "
            "on mesh_force (docs/source.md, 'Sliding friction'); tf_omega does not contain it")


def sensitivity_rows(sensitivity: dict) -> list[dict]:
    """Rows of te_sensitivity.csv (SENSITIVITY_COLUMNS) from {torque: {n: RunupResult}} of
    housingfe.runup.chain.te_sensitivity: the levels of line n (the driven harmonic; the others hold only what the
    stiffness ripple couples into them) and the total L_WA of each drive."""
    rows = []
    for torque, per in sensitivity.items():
        for n, res in per.items():
            totals = {(r["route"], r["radiation"], r["speed_rpm"]): r["LwA_dB"] for r in res.totals}
            for r in res.harmonic_rows():
                if r["harmonic"] == n:
                    rows.append({**r, "LwA_total_dB": totals[r["route"], r["radiation"], r["speed_rpm"]]})
    return rows


def sensitivity_lines(scene, sensitivity: dict) -> list[str]:
    """Summary lines: L_WA per um of TE at each driven harmonic, the scene's first radiation model, at the spectrum
    speeds the run has."""
    rad = scene.radiation.models[0]
    rows = sensitivity_rows(sensitivity)
    lines = []
    for torque, per in sensitivity.items():
        for n in per:
            for route in scene.runup.routes:
                got = {r["speed_rpm"]: r["LwA_dB"] for r in rows if r["torque_nm"] == torque and r["harmonic"] == n
                       and r["route"] == route and r["radiation"] == rad}
                speeds = [s for s in scene.runup.spectrum_speeds_rpm if s in got]
                if speeds:
                    lines.append(f"  {torque:g} N m  {route:10s} harmonic {n}: L_WA per 1 um of TE "
                                 + " / ".join(f"{got[s]:.1f}" for s in speeds) + " dB(A) at "
                                 + " / ".join(f"{s:g}" for s in speeds) + " rpm")
    return ["TE sensitivity (runup.te_sensitivity, te_sensitivity.csv; a TE of a um adds 20 lg(a)):"] + lines


def summary_text(scene, results: dict, gm, check_rows: list, timings: dict, decompositions: list = (),
                 notes: list = (), sensitivity: dict | None = None) -> str:
    """The console summary: the model, the run-up maxima per route, the notes (one line each), the checks, which
    term makes the speed law (one line per curve, and the table of slopes), the time split."""
    b = gm.basis
    lines = [f"{scene.scene.name}: coupled gearbox {gm.structure.dofs} DOFs, {len(b.eigenvalues)} modes to "
             f"{b.f_max:.0f} Hz ({b.rigid_count} zero), {len(gm.reduction.vectors)} Ritz vectors; radiating area "
             f"{gm.area:.3f} m2"]
    lines += resolution_lines(_resolution(gm))
    for torque, (_, res) in results.items():
        for route in res.routes:
            for rad in res.radiators:
                s, lwa = res.series(route, rad, torque, "LwA_dB")
                i = int(np.argmax(lwa))
                lines.append(f"  {torque:g} N m  {route:10s} sigma {rad:9s}: max L_WA {lwa[i]:.1f} dB(A) at "
                             f"{s[i]:g} rpm")
    if scene.runup.mesh_moment_model == "shuttling" and "mesh_force" in scene.runup.routes:
        lines.append("mesh moment: the shuttling moment (runup.mesh_moment) is applied with the mesh excitation on "
                     "mesh_force (docs/source.md, 'The shuttling moment'); tf_omega does not contain it")
    friction = friction_line(scene, results)
    if friction:
        lines.append(friction)
    lines += floating_axial_lines(results)
    if any(m.drivetrain.speed_dependent_bearings for m, _ in results.values()):
        if scene.runup.bearing_speeds == "follow":
            lines.append("bearings: the fluid films' K, C at each run-up speed (runup.bearing_speeds = \"follow\"; "
                         "docs/runup.md 'Fluid films over the run-up')")
        else:
            lines.append(f"bearings: the fluid films' K, C at {scene.drivetrain.bearing_speed_rpm:g} rev/min for the "
                         "whole run-up (runup.bearing_speeds = \"fixed\"; \"follow\" takes each run-up speed's)")
    if scene.runup.drive_line_model in ("quill-shafts", "back-to-back"):
        what = ("the quill shafts and couplings to motor and brake" if scene.runup.drive_line_model == "quill-shafts"
                else "the back-to-back loop (quill shafts, couplings, the auxiliary gearbox and motor: assumed "
                     "inertias, docs/drivetrain.md)")
        lines.append(f"drive line: {what} (runup.drive_line) are in the coupled model; its lowest elastic mode "
                     + (f"{b.frequencies_hz[b.rigid_count]:.1f} Hz" if len(b.frequencies_hz) > b.rigid_count else "-"))
    lines += list(notes)
    if sensitivity:
        lines += sensitivity_lines(scene, sensitivity)
    lines.append("checks (ours | measured | thesis calc. | pass):")
    for r in check_rows:
        lines.append(f"  {r['quantity']}: {r['ours']} | {_fmt(r['measured'])} | {_fmt(r['thesis_calculated'])} | "
                     f"{r['passed'] or '-'}")
    if decompositions:
        lines.append("speed law (slope_terms.csv):")
        lines += [f"  {d.sentence()}" for d in decompositions]
        lines.append(slope_terms.table(decompositions))
    split = ", ".join(f"{k[:-2]} {v:.1f}" for k, v in timings.items() if k.endswith("_s") and v >= 0.05)
    lines.append(f"time (s): {split}")
    return "\n".join(lines)
