"""Rows for `housingfe validate`: the checks of issue 28 that no other provider makes (housingfe.verification.checks).

From the default run-up's cached result (<results>/test-gearbox-runup/: runup.json, runup.csv,
runup_harmonics.csv; the computation `housingfe validate` runs anyway for its run-up rows), per route:

* 28.default.max_lwa_harmonic.<route> — the line carrying the most L_WA at the speed of the L_WA maximum: the
  tooth frequency or its 2nd harmonic (n <= 2);
* 28.default.peaks.<route> — L_WA peaks (prominence 2 dB, housingfe.runup.checks.peaks) within 100 rpm of at least
  two of 450-500 / 850-950 / 1300-1350 rpm, each traced to a coupled mode between 150 and 600 Hz (the mode with
  the largest share of the peak's <v^2>, runup.json peak_contributions);
* 28.default.no_high_harmonic_peak.<route> — no L_WA peak made (its line with the most L_WA) by the 3rd harmonic
  or higher;
* 28.default.tooth_band.<L_omega|L_v|L_W>.<route> — the tooth-frequency 1/3-octave band the largest band of the
  spectrum at >= 80 % of the speeds >= 400 rpm (L_omega: the source's on tf_omega, the wheel's on the flexible
  housing on mesh_force when the run has it);

and from the design-variant study's cached result (<results>/study-validate/, housingfe.verification.study_rows):

* 28.replica.max_lwa — the thesis replica (engagement thesis-2d, the rigid-bore source's L_omega times TF_omega,
  sigma = 1, gear set A, ball bearings, 2000 N m): max L_WA within 1.5 dB of the thesis' calculated 89.4 dB(A).
* 28.variants.double_helical_vs_single.<roller|fluid_film>.<A|B_self_aligning>.<mean|max_reduction>.<route> —
  the double helical set against single helical set A (ball) and set B on self-aligning bearings, all 2000 N m,
  from the study's run-up tables (study_rows.double_helical_vs_single_rows): reported beside the checks, not
  checks (checks.VS_SINGLE); a missing run costs these rows alone (a failure line).
* 28.variants.double_helical_speed_law.<cylindrical_roller|fluid_film>.<route> and
  28.variants.double_helical_smoothness.<cylindrical_roller|fluid_film|set_A>.<route> — the double helical set's
  L_WA slope per doubling of speed at 2000 N m (250-1500 rpm) beside the measured 6, and the s.d. of L_WA about its
  speed-law line beside set A's (Fig. 5.19: smooth against fluctuating), from the same tables
  (study_rows.double_helical_speed_law_rows): reported, not checks (checks.DH_SPEED_LAW, DH_SMOOTHNESS); a missing
  run costs these rows alone (a failure line).

and, where the default run-up also ran the envelope bound (set A's overlap ratio near an integer: runup_envelope_bound.csv,
runup_envelope_bound_harmonics.csv and runup.json "envelope_bound"), the rows of the envelope bound (`bound_chain_rows`,
checks.as_bound: reported beside the checks, never judged, no band; a bound, not the model, docs/source.md):

* 28.bound.default.max_lwa.<route>, .max_lwa_harmonic.<route>, .peaks.<route> and 28.bound.l_omega.flexible.<speed>rpm
  — the same row functions as the checks' (validate.run_check_rows, max_harmonic_row, peak_rows) on the bound's data;

and from the default run-up run once more with runup.as_made = 5 (<results>/test-gearbox-runup-5/: the same scene
with the expected sidebands of ISO 1328-1 grade-5 gears on the same models, runup_as_made.csv; one more cached
computation, ~20 s), the rows of gears as made (`as_made_rows`, checks.as_made_row: reported beside the checks, never
judged, no band; docs/runup.md "Gears as made in the run-up"), ours with the sidebands, read as the check reads it:

* 28.as_made.default.max_lwa.<route> — max L_WA over speed at the highest torque, sigma the scene's first radiation
  model (LwA_as_made_dB); why: the loudest 1/3-octave band at that maximum and its speed, the periodic maximum;
* 28.as_made.l_omega.flexible.<500,1000,1500>rpm — the mesh_force route's wheel L_omega in the tooth band on the
  flexible housing (L_omega_tooth_band_as_made_dB); why: the periodic value and what the sidebands add;

and, since that run also folds the sidebands into its totals and checks (runup.as_made_totals = true; and once more
with runup.as_made_pitch = "runout", <results>/test-gearbox-runup-5-true-runout/), every check of the default chain
on gears as made (`as_made_chain_rows`, checks.as_made_check: reported, never judged, no band; the verdict the check
would give in `why` and in "as_made_passes", which the count line sums per pitch model):

* 28.as_made.<independent,runout>.<the check's id after 28.> — 28.default.*, 28.speed_law.*, 28.l_omega.* by the
  same row functions (validate.run_check_rows tagged, `chain_rows`) on that run's runup.json, runup.csv and
  runup_harmonics.csv.

Besides the two as-made runs nothing is computed here that validate does not compute anyway: with the caches valid these rows take well under
a second; with quick and a stale cache they are left out (a note on the console).  `only_rows` collects every check
row of issue 28 (these and the ones tagged by the other providers) for `housingfe validate --only runup-checks`.
"""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from housingfe.errors import InputError, SolverError
from housingfe.verification import checks as ck

SOURCE = "van Roosmalen 1994, Ch. 5 (Secs. 5.4-5.6, Figs. 5.6, 5.7, 5.10) [test_gearbox]; issue 28"
TOOTH_BAND_QUANTITIES = {"L_omega": "L_omega", "L_v": "Lv_dB", "L_W": "Lw_dB"}


def published_rows(results: Path | None = None, quick: bool = False, failures: list[str] | None = None
                   ) -> list[dict]:
    """The rows of the module docstring from the cached default run-up and study results (computed first when stale,
    not with quick).  A failed as-made run costs its rows alone (appended to failures, or printed)."""
    from housingfe.verification import study_rows, validate

    out = []
    found = validate.runup_folder(validate.DEFAULT_RUNUP, (), results, quick)
    if found is not None:
        out += default_chain_rows(*found)
        out += bound_chain_rows(*found)
    folder = study_rows.study_folder(results, quick)
    if folder is not None:
        out += replica_rows(folder)
        try:
            out += study_rows.double_helical_vs_single_rows(folder)
        except InputError as exc:
            message = f"double helical vs single helical ({ck.VS_SINGLE}* left out): {exc}"
            if failures is None:
                print(f"validate: {message}", flush=True)
            else:
                failures.append(message)
        try:
            out += study_rows.double_helical_speed_law_rows(folder)
        except InputError as exc:
            message = (f"double helical speed law and smoothness ({ck.DH_SPEED_LAW}*, {ck.DH_SMOOTHNESS}* left "
                       f"out): {exc}")
            if failures is None:
                print(f"validate: {message}", flush=True)
            else:
                failures.append(message)
    periodic = {}       # the default chain's check rows, by check_id: the periodic verdicts beside the as-made ones
    if found is not None:
        data = json.loads((found[1] / "runup.json").read_text())
        periodic = {r["check_id"]: r for r in ck.check_rows(validate.run_check_rows(found[0], data["checks"])
                                                            + default_chain_rows(*found))}
    for pitch in ck.AS_MADE_PITCHES:
        try:
            made = validate.runup_folder(validate.DEFAULT_RUNUP, as_made_overrides(pitch), results, quick)
        except (validate.ComputationFailed, SolverError) as exc:
            left = ("28.as_made.default.*, 28.as_made.l_omega.*, " if pitch == ck.AS_MADE_PITCHES[0] else "") + \
                f"28.as_made.{pitch}.*"
            message = f"gears as made, pitch {pitch} ({left} left out): {exc}"
            if failures is None:
                print(f"validate: {message}", flush=True)
            else:
                failures.append(message)
            made = None
        if made is not None:
            if pitch == ck.AS_MADE_PITCHES[0]:
                out += as_made_rows(*made)
            out += as_made_chain_rows(*made, periodic)
    return out


def fe_results(results: Path | None = None, quick: bool = False) -> list:
    """The FE results these rows read besides the default run-up and the study (validate and study_rows declare
    those), for `housingfe validate --workers` (validate.fe_results): the default run-up as made, per pitch model,
    as [(rough seconds, callable computing it when stale)]."""
    from functools import partial

    from housingfe.verification import validate

    return [(60.0, partial(validate.runup_folder, validate.DEFAULT_RUNUP, as_made_overrides(pitch), results, quick))
            for pitch in ck.AS_MADE_PITCHES]


def only_rows(results: Path, quick: bool = False, failures: list[str] | None = None) -> list[dict]:
    """The check rows of issue 28 alone (`housingfe validate --only runup-checks`): the default run-up's tagged rows,
    the design-variant study's (study_rows), the quasi-static excitation's (source_rows.excitation_rows) and the
    checks no other provider makes (runup_checks_rows), each from the same cached computation the full validate
    uses, and after them the reported rows 28.bound.* and 28.as_made.* (not checks: checks.as_bound, as_made_row; the
    turned pinion's 28.as_made.reindex.* computed as in the full validate, turned_pinion_rows, ~10 s).  A failed
    computation is appended to failures (its rows are missing)."""
    from housingfe.verification import source_rows, study_rows, turned_pinion_rows, validate
    from housingfe.verification.checks import check_rows

    failures = [] if failures is None else failures
    rows: list[dict] = []
    # in the order of the full validate (its run-up rows, then the providers by name), so both give one table
    for what, make in ((validate.DEFAULT_RUNUP, lambda: validate.runup_rows(validate.DEFAULT_RUNUP, (), results, quick)),
                       ("runup_checks_rows", lambda: published_rows(results, quick, failures)),
                       ("quasi-static excitation", source_rows.excitation_rows),
                       ("study rows", lambda: study_rows.published_rows(results, quick)),
                       ("turned pinion (28.as_made.reindex.*)", turned_pinion_rows.published_rows)):
        try:
            rows += make()
        except validate.ComputationFailed as exc:
            failures.append(str(exc))
        except SolverError as exc:
            failures.append(f"{what}: {exc}")
    return check_rows(rows)


def _read_csv(path: Path) -> list[dict]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def _num(x: str) -> float:
    return float(x) if x not in ("", None) else float("nan")


def default_chain_rows(label: str, folder: Path) -> list[dict]:
    """The default chain's rows (module docstring) from a run-up result folder."""
    data = json.loads((folder / "runup.json").read_text())
    rad = data["scene_settings"]["radiation"]["models"][0]
    return chain_rows(label, rad, _read_csv(folder / "runup.csv"), _read_csv(folder / "runup_harmonics.csv"),
                      data["peak_contributions"])


# the checks whose counterpart with the envelope bound is reported (28.bound.<id after 28.>)
BOUND_CHECKS = ("default.max_lwa.", "default.max_lwa_harmonic.", "default.peaks.", "l_omega.flexible.")


def bound_chain_rows(label: str, folder: Path) -> list[dict]:
    """The envelope bound's rows (module docstring) from a run-up result folder; none when the run did not run the
    bound (no runup_envelope_bound.csv, or a result written before its lines and checks were kept)."""
    from housingfe.runup.report import BOUND_CSV, BOUND_HARMONICS_CSV
    from housingfe.verification import validate

    data = json.loads((folder / "runup.json").read_text())
    bound = data.get("envelope_bound")
    if not bound or not (folder / BOUND_CSV).is_file() or not (folder / BOUND_HARMONICS_CSV).is_file():
        return []
    rad = data["scene_settings"]["radiation"]["models"][0]
    scene = f"{label} (envelope bound)"
    rows = validate.run_check_rows(scene, bound["checks"])
    rows += chain_rows(scene, rad, _read_csv(folder / BOUND_CSV), _read_csv(folder / BOUND_HARMONICS_CSV),
                       bound["peak_contributions"])
    kept = [r for r in ck.check_rows(rows) if r["check_id"][3:].startswith(BOUND_CHECKS)]
    kept.sort(key=lambda r: next(i for i, p in enumerate(BOUND_CHECKS) if r["check_id"][3:].startswith(p)))
    return [ck.as_bound(r) for r in kept]


# the default run-up once more with the expected sidebands of gears as made (runup.as_made, docs/runup.md), in its
# totals and checks too (runup.as_made_totals): its runup_as_made.csv gives the rows 28.as_made.default.* and
# 28.as_made.l_omega.*, its checks the rows 28.as_made.independent.*; the same with runup.as_made_pitch = "runout"
# the rows 28.as_made.runout.* (`as_made_overrides`)
AS_MADE_OVERRIDES = (ck.AS_MADE_OVERRIDE, "runup.as_made_totals=true")


def as_made_overrides(pitch: str) -> tuple[str, ...]:
    """validate's overrides of the default run-up as made with the pitch deviations' spectrum `pitch`
    (checks.AS_MADE_PITCHES; the first is runup.as_made_pitch's default)."""
    if pitch not in ck.AS_MADE_PITCHES:
        raise ValueError(f"as_made_overrides: pitch {pitch!r} is not one of {ck.AS_MADE_PITCHES}")
    return AS_MADE_OVERRIDES + (() if pitch == ck.AS_MADE_PITCHES[0] else (f"runup.as_made_pitch={pitch}",))


def as_made_chain_rows(label: str, folder: Path, periodic: dict | None = None) -> list[dict]:
    """The default chain's checks on gears as made (28.as_made.<pitch>.*, checks.as_made_check) from a run-up result
    folder run with runup.as_made and runup.as_made_totals: the same row functions as the checks'
    (validate.run_check_rows tagged, `chain_rows`) on its runup.json checks, runup.csv, runup_harmonics.csv and peak
    contributions, which hold the sidebands; periodic: {check_id: the periodic check's row} for `why`.  None when
    the run did not fold the sidebands into its totals (runup.json "as_made" without "in_totals")."""
    from housingfe.verification import validate

    data = json.loads((folder / "runup.json").read_text())
    made = data.get("as_made")
    if not made or not made.get("in_totals") or made.get("pitch_model") not in ck.AS_MADE_PITCHES:
        return []
    rad = data["scene_settings"]["radiation"]["models"][0]
    scene = (f"{label} (gears as made, ISO grade {made['grade']}, pitch {made['pitch_model']}, sidebands in the "
             "totals)")
    rows = validate.run_check_rows(scene, data["checks"])
    rows += chain_rows(scene, rad, _read_csv(folder / "runup.csv"), _read_csv(folder / "runup_harmonics.csv"),
                       data["peak_contributions"])
    periodic = periodic or {}
    return [ck.as_made_check(r, made["pitch_model"], periodic.get(r["check_id"])) for r in ck.check_rows(rows)]
AS_MADE_SPEEDS_RPM = (500, 1000, 1500)          # the measured L_omega's speeds (28.l_omega.flexible.<speed>rpm)


def as_made_rows(label: str, folder: Path) -> list[dict]:
    """The rows of gears as made (module docstring) from a run-up result folder run with runup.as_made; none when it
    was not (no runup_as_made.csv or runup.json "as_made").  measured / thesis calculated are the corresponding
    check's (runup.json "checks": LwA_max, L_omega_flexible)."""
    from housingfe.runup.as_made import CSV

    data = json.loads((folder / "runup.json").read_text())
    made = data.get("as_made")
    if not made or not (folder / CSV).is_file():
        return []
    return as_made_rows_of(label, data["scene_settings"]["radiation"]["models"][0], made["grade"],
                           _read_csv(folder / CSV), data["checks"])


def _check_of(run_checks: list[dict], kind: str, quantity_test) -> dict:
    return next((c for c in run_checks if c["check"] == kind and quantity_test(c["quantity"])), {})


def as_made_rows_of(label: str, rad: str, grade: int, table: list[dict], run_checks: list[dict]) -> list[dict]:
    """28.as_made.default.max_lwa.<route> and 28.as_made.l_omega.flexible.<speed>rpm from runup_as_made.csv's rows
    (`table`) of the radiation model `rad` at the highest torque; run_checks: the run's checks (runup.json)."""
    table = [r for r in table if r["radiation"] == rad]
    if not table:
        return []
    top = max(_num(r["torque_nm"]) for r in table)
    scene = f"{label} (gears as made, ISO grade {grade})"
    out = []
    for route in dict.fromkeys(r["route"] for r in table):
        sel = [r for r in table if r["route"] == route and _num(r["torque_nm"]) == top]
        made = np.array([_num(r["LwA_as_made_dB"]) for r in sel])
        periodic = np.array([_num(r["LwA_dB"]) for r in sel])
        i, j = int(np.nanargmax(made)), int(np.nanargmax(periodic))
        at, p_at = sel[i], sel[j]
        c = _check_of(run_checks, "LwA_max", lambda q: q.startswith(f"{route}:"))
        out.append(ck.as_made_row(
            f"28.as_made.default.max_lwa.{route}", scene,
            f"{route}: max L_WA dB(A) with the expected sidebands of ISO grade-{grade} gears "
            f"({_num(at['speed_rpm']):g} rpm, {top:g} N m, sigma {rad})", round(float(made[i]), 1), "dB(A)", SOURCE,
            measured=c.get("measured"), thesis_calculated=c.get("thesis_calculated"),
            why=f"the loudest 1/3-octave band at the maximum ({_num(at['speed_rpm']):g} rpm) is "
                f"{_num(at['LwA_peak_band_as_made_hz']):g} Hz ({_num(at['LwA_peak_band_as_made_dB']):.1f} dB(A)); "
                f"periodic alone {periodic[j]:.1f} dB(A) at {_num(p_at['speed_rpm']):g} rpm, loudest band "
                f"{_num(p_at['LwA_peak_band_hz']):g} Hz: the sidebands add {made[i] - periodic[j]:+.1f} dB(A)"))
    wheel = {_num(r["speed_rpm"]): r for r in table if r["route"] == "mesh_force" and _num(r["torque_nm"]) == top}
    for speed in AS_MADE_SPEEDS_RPM:
        r = wheel.get(float(speed))
        if r is None:
            continue
        ours, periodic = _num(r["L_omega_tooth_band_as_made_dB"]), _num(r["L_omega_tooth_band_dB"])
        c = _check_of(run_checks, "L_omega_flexible", lambda q: q.endswith(f" at {speed} rpm"))
        out.append(ck.as_made_row(
            f"28.as_made.l_omega.flexible.{speed}rpm", scene,
            f"mesh_force wheel on the flexible housing: L_omega tooth band dB at {speed} rpm with the expected "
            f"sidebands of ISO grade-{grade} gears ({top:g} N m)", round(ours, 1), "dB", SOURCE,
            measured=c.get("measured"), thesis_calculated=c.get("thesis_calculated"),
            why=f"periodic {periodic:.1f} dB; the sidebands add {ours - periodic:+.1f} dB"))
    return out


def chain_rows(label: str, rad: str, totals: list[dict], harm: list[dict], peak_contributions: list[dict]
               ) -> list[dict]:
    """The default chain's rows of one run-up: totals (runup.csv rows, or RunupResult.totals), harm
    (runup_harmonics.csv rows, or RunupResult.harmonic_rows()) and the peak contributions (runup.json, or
    housingfe.runup.checks.evaluate), read for the radiation model `rad` at the highest torque.  The Monte-Carlo
    of `housingfe uncertainty` calls this on each sample's run, so its bands are of the very same quantities."""
    totals = [r for r in totals if r["radiation"] == rad]
    harm = [r for r in harm if r["radiation"] == rad]
    top = max(_num(r["torque_nm"]) for r in totals)
    out = []
    for route in dict.fromkeys(r["route"] for r in totals):
        tot = [r for r in totals if r["route"] == route and _num(r["torque_nm"]) == top]
        lines = [r for r in harm if r["route"] == route and _num(r["torque_nm"]) == top]
        where = f"{route}, {top:g} N m, sigma {rad}"
        out.append(max_harmonic_row(label, route, where, tot, lines))
        contributions = [c for c in peak_contributions if c["route"] == route and c["torque_nm"] == top]
        out += peak_rows(label, route, where, contributions)
        out += tooth_band_rows(label, route, where, lines)
    return out


def max_harmonic_row(label: str, route: str, where: str, totals: list[dict], lines: list[dict]) -> dict:
    """28.default.max_lwa_harmonic: which line carries the L_WA at the speed of the maximum."""
    speeds = np.array([_num(r["speed_rpm"]) for r in totals])
    lwa = np.array([_num(r["LwA_dB"]) for r in totals])
    s = float(speeds[int(np.nanargmax(lwa))])
    at = [r for r in lines if _num(r["speed_rpm"]) == s]
    n, share = ck.carrying_harmonic([int(r["harmonic"]) for r in at], [_num(r["LwA_dB"]) for r in at])
    # its strongest line (one line per harmonic, but with gears as made in the totals the band's sidebands too)
    band = [r for r in at if int(r["harmonic"]) == n]
    f = _num(max(band, key=lambda r: _num(r["LwA_dB"]))["frequency_hz"])
    what = (f"harmonic {n}'s 1/3-octave band ({len(band)} lines, the strongest at {f:.0f} Hz)" if len(band) > 1
            else f"harmonic {n} at {f:.0f} Hz")
    return ck.check_row(f"28.default.max_lwa_harmonic.{route}", label,
                        f"{where}: harmonic carrying the L_WA maximum ({s:g} rpm, {lwa.max():.1f} dB(A))", n, "-",
                        SOURCE, measured="1 or 2", tolerance=f"n <= {ck.HIGHEST_MAKING_HARMONIC}",
                        passed=n <= ck.HIGHEST_MAKING_HARMONIC,
                        why=f"{what} carries {share:.0%} of the L_WA; measured: the tooth "
                            "frequency and its 2nd harmonic only (Fig. 5.6)")


def _dominant_mode(contribution: dict) -> float | None:
    modes = contribution.get("modes") or []
    return max(modes, key=lambda m: m["share"])["frequency_hz"] if modes else None


def peak_rows(label: str, route: str, where: str, contributions: list[dict]) -> list[dict]:
    """28.default.peaks (the measured windows, traced to 150-600 Hz modes) and 28.default.no_high_harmonic_peak."""
    peaks = [(c["speed_rpm"], _dominant_mode(c)) for c in contributions]
    result = ck.peak_windows(peaks)
    listed = ", ".join(f"{c['speed_rpm']:g} (n = {c['harmonic']}, mode {_dominant_mode(c) or 0:.0f} Hz)"
                       for c in contributions) or "none"
    per_window = "; ".join(
        f"{w['window'][0]:g}-{w['window'][1]:g}: " + ("no peak" if w["peak_rpm"] is None else
                                                     f"{w['peak_rpm']:g} rpm ({w['distance_rpm']:g} rpm off, mode "
                                                     f"{w['mode_hz'] or 0:.0f} Hz) {'yes' if w['matched'] else 'no'}")
        for w in result["windows"])
    lo, hi = ck.PEAK_MODE_BAND_HZ
    windows = " / ".join(f"{a:g}-{b:g}" for a, b in ck.PEAK_WINDOWS_RPM)
    rows = [ck.check_row(f"28.default.peaks.{route}", label,
                         f"{where}: L_WA peaks (rpm; line, dominant mode) near the measured ones, on {lo:g}-{hi:g} Hz "
                         "modes", listed, "rpm", SOURCE, measured=windows,
                         tolerance=f"{ck.PEAKS_NEEDED} of 3 windows: a peak within {ck.PEAK_TOLERANCE_RPM:g} rpm whose "
                                   f"dominant mode is {lo:g}-{hi:g} Hz",
                         passed=result["passed"], why=f"{result['hits']} of 3 matched; {per_window}")]
    high = [c for c in contributions if c["harmonic"] > ck.HIGHEST_MAKING_HARMONIC]
    rows.append(ck.check_row(
        f"28.default.no_high_harmonic_peak.{route}", label,
        f"{where}: L_WA peaks made by the 3rd harmonic or higher", len(high), "-", SOURCE, measured=0,
        tolerance="none", passed=not high,
        why=("; ".join(f"{c['speed_rpm']:g} rpm: n = {c['harmonic']} at {c['line_hz']:.0f} Hz "
                       f"({c['line_share_of_LwA']:.0%} of the L_WA)" for c in high)
             or f"{len(contributions)} peaks, all made by n <= {ck.HIGHEST_MAKING_HARMONIC}")))
    return rows


def tooth_band_rows(label: str, route: str, where: str, lines: list[dict]) -> list[dict]:
    """28.default.tooth_band.<quantity>: the share of the speeds >= 400 rpm at which the tooth band is largest."""
    rows = []
    speeds = [_num(r["speed_rpm"]) for r in lines]
    freq = [_num(r["frequency_hz"]) for r in lines]
    harmonic = [int(r["harmonic"]) for r in lines]
    for name, column in TOOTH_BAND_QUANTITIES.items():
        what = name
        if name == "L_omega":
            flexible = [_num(r["L_omega_coupled_dB"]) for r in lines]
            if route == "mesh_force" and np.all(np.isfinite(flexible)):
                values, what = flexible, "L_omega of the wheel on the flexible housing"
            else:
                values, what = [_num(r["L_omega_dB"]) for r in lines], "L_omega of the source (rigid bores)"
        else:
            values = [_num(r[column]) for r in lines]
        share, count, missed = ck.tooth_band_share(speeds, freq, harmonic, values)
        rows.append(ck.check_row(
            f"28.default.tooth_band.{name}.{route}", label,
            f"{where}: share of the speeds >= {ck.TOOTH_BAND_SPEED_MIN_RPM:g} rpm at which the tooth band is the "
            f"largest 1/3-octave band of {name}", round(share, 2), "-", SOURCE, measured="tooth band dominant",
            tolerance=f">= {ck.TOOTH_BAND_SHARE:g}", passed=share >= ck.TOOTH_BAND_SHARE,
            why=f"{what}; {count} speeds; not the largest at "
                + (", ".join(f"{s:g}" for s in missed) + " rpm" if missed else "none")))
    return rows


def replica_rows(folder: Path) -> list[dict]:
    """28.replica.max_lwa from the study's thesis-2d profile-corrections run (set A, tf_omega)."""
    from housingfe.verification.study_rows import JOBS

    sub = next(s for f, o, s in JOBS if f == "profile-corrections" and any("thesis-2d" in x for x in o))
    return replica_rows_of(json.loads((folder / sub / "study.json").read_text()))


def replica_rows_of(data: dict) -> list[dict]:
    """28.replica.max_lwa from a thesis-2d profile-corrections study's data (study.json's content)."""
    from housingfe.verification.study_rows import REPLICA_GOAL_DB

    r = next((r for r in data["rows"] if r["variant"] == "A" and r["route"] == "tf_omega"), None)
    if r is None:
        return []
    ok = ck.within(r["LwA_max_dBA"], r["thesis_calc_max_dBA"], REPLICA_GOAL_DB)
    return [ck.check_row("28.replica.max_lwa", f"study profile-corrections ({data['engagement']})",
                         f"thesis replica (engagement {data['engagement']}, rigid-bore L_omega x TF_omega, sigma "
                         f"{data['radiation']}, set A, ball, 2000 N m): max L_WA dB(A) ({r['at_rpm']:g} rpm)",
                         r["LwA_max_dBA"], "dB(A)", data["source"], measured=r["measured_max_dBA"],
                         thesis_calculated=r["thesis_calc_max_dBA"], tolerance=f"{REPLICA_GOAL_DB:g} dB of the "
                         "thesis' calculation", passed=ok,
                         why=f"the thesis' own chain gave {r['thesis_calc_max_dBA']} dB(A) against "
                             f"{r['measured_max_dBA']} measured")]
