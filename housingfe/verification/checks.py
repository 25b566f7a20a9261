"""The checks of issue 28 as rows of `housingfe validate`: one row per check, with a stable `check_id`.

A check row is an ordinary validate row (housingfe.verification.published.row: scene, quantity, ours, published,
unit, source, note) with these fields added (`tag`):

* check_id — stable name, "28.<group>.<what>[.<variant>][.<route>]", e.g. "28.default.max_lwa.mesh_force"; the
  groups, in the issue's order: replica, default, excitation, speed_law, l_omega, variants (CHECK_GROUPS), and
  bound: the envelope bound's rows "28.bound.<the check's id after 28.>" (`as_bound`), reported beside the checks,
  never judged, without a band and counted apart; and as_made: the rows "28.as_made.<the check's id after 28.>" of
  the default run-up and of the design-variant studies (28.as_made.variants.*) with the expected sidebands of gears
  as made (`as_made_row`; runup.as_made, docs/runup.md), and "28.as_made.<pitch>.<the check's id after 28.>", the
  default chain's checks on a run with the sidebands in its totals (`as_made_check`; runup.as_made_totals), reported,
  never judged, without a band and counted apart as well (the count line says how many of those the checks would
  pass), and "28.as_made.reindex.<pitch>", the thesis' turned-pinion measurement (Sec. 5.6) against drawn grade-5
  gears per pitch model (AS_MADE_REINDEX; housingfe.verification.turned_pinion_rows); and in the variants group the double helical set against single helical set A and self-aligning B
  (VS_SINGLE, "28.variants.double_helical_vs_single.<roller|fluid_film>.<A|B_self_aligning>.<mean|max_reduction>.
  <route>", study_rows.double_helical_vs_single_rows) and the double helical set's speed law and smoothness
  (DH_SPEED_LAW, DH_SMOOTHNESS: "28.variants.double_helical_speed_law.<cylindrical_roller|fluid_film>.<route>",
  "28.variants.double_helical_smoothness.<cylindrical_roller|fluid_film|set_A>.<route>",
  study_rows.double_helical_speed_law_rows): the issue's checks do not name these, so they are reported beside them,
  never judged, without a band and counted apart;
* measured, thesis_calculated — the published numbers beside ours (either may be None);
* tolerance — the goal as text ("3 dB", "n <= 2", ">= 80 % of the speeds", "report");
* passed — "yes", "no" or "" (a report row: nothing to pass);
* why — what made the result, where it is known (the line, the modes, the term, ...);
* band — the model's own uncertainty (issue 28 item 5): None until someone attaches one (`attach_bands`, from the
  bands.json of `housingfe uncertainty`), rendered "—".  A band is (low, high) of ours in the check's unit (the
  5-95 % band over the Monte-Carlo samples); the table then says whether the measured value lies inside it.
  Beside it band_passes (k, n): the check passed in k of the n samples (the statement for a yes/no check), and
  band_note (e.g. "no sampled input acts on this").

Rows of other providers that already are an issue-28 check (the study rows, the default run-up's rows, the
quasi-static excitation rows) are tagged where they are made, not repeated here; the rows no provider had are made
by housingfe.verification.runup_checks_rows.  `checks_markdown` / `write_checks` give the checks alone
(validate's checks.csv / checks.md; `housingfe validate --only runup-checks`).

The pure pass/fail logic of the checks lives here too (tested on synthetic inputs with known answers in
tests/verification/test_checks.py): the measured peak windows, the harmonic that carries the L_WA at a speed,
whether the tooth-frequency 1/3-octave band is the largest, a ranking's quietest and loudest.
"""
from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

CHECK_GROUPS = ("replica", "default", "excitation", "speed_law", "l_omega", "variants", "bound", "as_made")
# the rows of the envelope bound (engagement "envelope-bound", docs/source.md): a check's value with the bound in
# place of the default's excitation, reported beside the checks (passed "", no band), never judged nor counted
BOUND_GROUP = "bound"
BOUND_WHY = "envelope bound (engagement envelope-bound): a bound, not the model; docs/source.md"
# the rows of gears as made (runup.as_made = AS_MADE_GRADE, housingfe.runup.as_made): a check's quantity with the
# expected sidebands of ISO 1328-1 deviations beside the periodic lines, reported like the bound's, never judged
AS_MADE_GROUP = "as_made"
AS_MADE_GRADE = 5
AS_MADE_OVERRIDE = f"runup.as_made={AS_MADE_GRADE}"     # validate's runs of gears as made (run-up, studies)
AS_MADE_VARIANTS = f"28.{AS_MADE_GROUP}.variants."      # the design variants' rows as made (study_rows.as_made_rows)
# the pinion turned against the wheel (thesis Sec. 5.6, Fig. 5.12; housingfe.runup.reindex): per pitch model
AS_MADE_REINDEX = f"28.{AS_MADE_GROUP}.reindex."
AS_MADE_REINDEX_WHY = (f"gears as made (drawn ISO 1328-1 grade-{AS_MADE_GRADE} deviations standing in for the thesis' "
                       "DIN 5; the pinion turned against the wheel): reported, not a check; docs/source.md")
AS_MADE_WHY = (f"gears as made (runup.as_made = {AS_MADE_GRADE}, ISO 1328-1 grade {AS_MADE_GRADE} standing in for the "
               "thesis' DIN 5): reported, not a check; docs/runup.md")
CHECK_COLUMNS = ("check_id", "quantity", "ours", "measured", "thesis_calculated", "tolerance", "passed", "band", "why",
                 "unit", "scene", "source")
NO_BAND = "—"

# issue 28, "Default chain": the measured L_WA peaks (windows, rev/min), how close ours must be, and the band of the
# coupled modes the measured peaks sit on (the tooth frequency meeting 180 / 340-380 / 520-540 Hz modes, Sec. 5.4)
PEAK_WINDOWS_RPM = ((450.0, 500.0), (850.0, 950.0), (1300.0, 1350.0))
PEAK_TOLERANCE_RPM = 100.0
PEAK_MODE_BAND_HZ = (150.0, 600.0)
PEAKS_NEEDED = 2
HIGHEST_MAKING_HARMONIC = 2            # the maximum and every peak made by the tooth frequency or its 2nd harmonic
TOOTH_BAND_SPEED_MIN_RPM = 400.0
TOOTH_BAND_SHARE = 0.8                 # the tooth band the largest at >= 80 % of the speeds >= 400 rpm
MAX_LWA_TOLERANCE_DB = 3.0
REPLICA_MAX_TOLERANCE_DB = 1.5


# ------------------------------------------------------------------------------------------- the row format
def tag(row: dict, check_id: str, *, measured=None, thesis_calculated=None, tolerance: str = "", passed=None,
        why: str = "") -> dict:
    """Make a validate row a check row (module docstring); passed: True/False, "yes"/"no", or None/"" (report)."""
    if not check_id.startswith("28.") or check_id.split(".")[1] not in CHECK_GROUPS:
        raise ValueError(f"check_id {check_id!r}: must be 28.<group>.<...> with group in {CHECK_GROUPS}")
    if isinstance(passed, (bool, np.bool_)):
        passed = "yes" if passed else "no"
    row.update(check_id=check_id, measured=measured, thesis_calculated=thesis_calculated, tolerance=tolerance,
               passed=passed or "", why=why)
    row.setdefault("band", None)
    return row


def check_row(check_id: str, scene: str, quantity: str, ours, unit: str, source: str, *, measured=None,
              thesis_calculated=None, tolerance: str = "", passed=None, why: str = "") -> dict:
    """A new check row: `published` is the measured value, or the thesis' calculated one where nothing was
    measured; the note repeats goal, pass and why for validate.md."""
    from housingfe.verification.published import row

    published = measured if measured is not None else thesis_calculated
    p = "yes" if passed is True else "no" if passed is False else (passed or "")
    note = "; ".join(x for x in (f"goal: {tolerance}" if tolerance else "", f"passed: {p}" if p else "", why) if x)
    return tag(row(scene, quantity, ours, published, unit, source, note), check_id, measured=measured,
               thesis_calculated=thesis_calculated, tolerance=tolerance, passed=passed, why=why)


def is_check(row: dict) -> bool:
    return bool(row.get("check_id"))


def is_bound(row: dict) -> bool:
    """A row of the envelope bound (28.bound.*): reported, not a check."""
    return is_check(row) and row["check_id"].split(".")[1] == BOUND_GROUP


def as_bound(row: dict) -> dict:
    """The envelope bound's counterpart of a check row made by the check's own row function on the bound's data:
    check_id 28.bound.<the check's id after "28.">, ours / measured / thesis calculated as made, passed "" (reported),
    no tolerance and no band, `why` saying that it is a bound (BOUND_WHY) before what made the number."""
    if not is_check(row) or is_bound(row):
        raise ValueError(f"as_bound: {row.get('check_id')!r} is not a check row")
    why = f"{BOUND_WHY}; {row['why']}" if row.get("why") else BOUND_WHY
    row.update(check_id=f"28.{BOUND_GROUP}.{row['check_id'][3:]}", passed="", tolerance="", why=why,
               note=f"reported, not judged: {why}", band=None)
    for key in ("band_passes", "band_note"):
        row.pop(key, None)
    return row


def is_as_made(row: dict) -> bool:
    """A row of gears as made (28.as_made.*): reported, not a check."""
    return is_check(row) and row["check_id"].split(".")[1] == AS_MADE_GROUP


# the double helical set against the single helical ones (housingfe.studies.helical_vs_single; issue 28's checks do
# not name this comparison): reported beside the checks, never judged, no band, counted apart
VS_SINGLE = "28.variants.double_helical_vs_single."


def is_vs_single(row: dict) -> bool:
    """A row of the double helical set against single helical (28.variants.double_helical_vs_single.*): reported."""
    return is_check(row) and row["check_id"].startswith(VS_SINGLE)


# the double helical set's speed law and smoothness over speed (Sec. 5.9, Fig. 5.19: "very smooth curves", the
# 6 dB(A) per doubling "seen clearly"; study_rows.double_helical_speed_law_rows): reported beside the checks, never
# judged, no band, counted apart (the speed-law check of issue 28 is set A's, 28.speed_law.<route>)
DH_SPEED_LAW = "28.variants.double_helical_speed_law."
DH_SMOOTHNESS = "28.variants.double_helical_smoothness."


def is_dh_speed_law(row: dict) -> bool:
    """A row of the double helical set's speed law or smoothness (DH_SPEED_LAW*, DH_SMOOTHNESS*): reported."""
    return is_check(row) and row["check_id"].startswith((DH_SPEED_LAW, DH_SMOOTHNESS))


def is_reported_beside(row: dict) -> bool:
    """A row shown beside the checks but not one of them (the envelope bound's, gears as made, the double helical
    set against single helical, its speed law and smoothness)."""
    return is_bound(row) or is_as_made(row) or is_vs_single(row) or is_dh_speed_law(row)


# the default chain's checks evaluated on gears as made (runup.as_made = AS_MADE_GRADE with runup.as_made_totals:
# the sidebands in the run's totals, spectra and checks), one set of rows per shape of the pitch deviations'
# spectrum (runup.as_made_pitch): 28.as_made.<pitch>.<the check's id after 28.>
AS_MADE_PITCHES = ("independent", "runout")


def is_as_made_check(row: dict) -> bool:
    """A default-chain check evaluated on gears as made (28.as_made.<pitch>.*, `as_made_check`)."""
    return is_as_made(row) and row["check_id"].split(".")[2] in AS_MADE_PITCHES


def as_made_check(row: dict, pitch: str, periodic: dict | None = None) -> dict:
    """The counterpart on gears as made of a check row made by the check's own row function on a run-up with the
    sidebands in its totals (runup.as_made_totals): check_id 28.as_made.<pitch>.<the check's id after "28.">, ours /
    measured / thesis calculated as made, passed "" (reported, not judged: the pitch spectrum's shape is an
    assumption), no band; the verdict the check would give kept in "as_made_passes" ("yes" / "no" / "") and said in
    `why` after AS_MADE_WHY with the tolerance, and the periodic check's ours and verdict (periodic: the check's row
    of the periodic run, or None) before the check's own why."""
    if not is_check(row) or is_reported_beside(row):
        raise ValueError(f"as_made_check: {row.get('check_id')!r} is not a check row")
    if pitch not in AS_MADE_PITCHES:
        raise ValueError(f"as_made_check: pitch {pitch!r} is not one of {AS_MADE_PITCHES}")
    verdict = row.get("passed") or ""
    parts = [f"pitch deviations {pitch} (runup.as_made_pitch), sidebands in the totals (runup.as_made_totals)"]
    if verdict:
        parts.append(f"as made the check would pass: {verdict} (tolerance {row.get('tolerance') or '-'})")
    if periodic is not None:
        parts.append(f"periodic: ours {_cell(periodic.get('ours'))}"
                     + (f", passed {periodic['passed']}" if periodic.get("passed") else ""))
    if row.get("why"):
        parts.append(row["why"])
    why = f"{AS_MADE_WHY}; " + "; ".join(parts)
    row.update(check_id=f"28.{AS_MADE_GROUP}.{pitch}.{row['check_id'][3:]}", passed="", tolerance="", why=why,
               note=f"reported, not judged: {why}", band=None, as_made_passes=verdict)
    for key in ("band_passes", "band_note"):
        row.pop(key, None)
    return row


def as_made_row(check_id: str, scene: str, quantity: str, ours, unit: str, source: str, *, measured=None,
                thesis_calculated=None, why: str = "", prefix: str = AS_MADE_WHY) -> dict:
    """A row of gears as made: check_id 28.as_made.<the check's id after "28.">, ours with the expected sidebands,
    measured / thesis calculated as the check's, passed "" (reported), no tolerance, no band, `why` starting with
    `prefix` (AS_MADE_WHY; the turned pinion's rows AS_MADE_REINDEX_WHY)."""
    if not check_id.startswith(f"28.{AS_MADE_GROUP}."):
        raise ValueError(f"as_made_row: {check_id!r} is not 28.{AS_MADE_GROUP}.<...>")
    why = f"{prefix}; {why}" if why else prefix
    r = check_row(check_id, scene, quantity, ours, unit, source, measured=measured,
                  thesis_calculated=thesis_calculated, why=why)
    r["note"] = f"reported, not judged: {why}"
    return r


def check_rows(rows) -> list[dict]:
    """The check rows of `rows`, in the issue's order of groups (stable within a group)."""
    found = [r for r in rows if is_check(r)]
    return sorted(found, key=lambda r: CHECK_GROUPS.index(r["check_id"].split(".")[1]))


BANDS_FORMAT = "housingfe-bands-2"


def attach_bands(rows, bands) -> int:
    """The uncertainty hook: bands {check_id: entry} set on the rows with that check_id; returns how many rows got
    one.  An entry is (low, high) — ours' band in the check's unit (the old bands.json) — or a dict (the format of
    `housingfe uncertainty`'s bands.json, BANDS_FORMAT): {"band": [low, high] or None, "passes": k, "samples": n,
    "note": text}: ours' 5-95 % band over the samples where the check's value is a number, in how many of the n
    samples that computed the check it passed, and a note (e.g. that no sampled input acts on the check).  Rows
    without an entry show "—"."""
    n = 0
    for r in rows:
        if not (is_check(r) and r["check_id"] in bands) or is_reported_beside(r):    # bound, as made: no band
            continue
        entry = bands[r["check_id"]]
        if isinstance(entry, dict):
            band = entry.get("band")
            r["band"] = None if band is None else (float(band[0]), float(band[1]))
            r["band_passes"] = (None if entry.get("passes") is None
                                else (int(entry["passes"]), int(entry["samples"])))
            r["band_note"] = entry.get("note") or ""
        else:
            lo, hi = entry
            r["band"] = (float(lo), float(hi))
        n += 1
    return n


def _finite_pair(value) -> bool:
    return (isinstance(value, list) and len(value) == 2
            and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in value)
            and value[0] <= value[1])


def read_bands(path) -> dict:
    """Bands from a JSON file (`housingfe validate --bands FILE`): either {check_id: [low, high]} (the first format,
    still read) or {"format": BANDS_FORMAT, "checks": {check_id: {"band": [low, high] or null, "passes": k or null,
    "samples": n, "note": text}}} (`housingfe uncertainty`'s bands.json); InputError naming the file and key for
    anything else."""
    import json

    from housingfe.errors import InputError

    try:
        data = json.loads(Path(path).read_text())
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: cannot read a JSON object of bands: {exc}") from None
    if not isinstance(data, dict):
        raise InputError(f"{path}: must be a JSON object {{check_id: [low, high]}}")
    if "format" in data:
        if data["format"] != BANDS_FORMAT or not isinstance(data.get("checks"), dict):
            raise InputError(f"{path}: format: {data['format']!r}: expected {BANDS_FORMAT!r} with a \"checks\" object")
        out = {}
        for key, entry in data["checks"].items():
            if not isinstance(entry, dict):
                raise InputError(f"{path}: checks.{key}: must be an object {{band, passes, samples, note}}")
            band, passes, n = entry.get("band"), entry.get("passes"), entry.get("samples")
            if band is not None and not _finite_pair(band):
                raise InputError(f"{path}: checks.{key}.band: must be [low, high] with finite numbers, low <= high, "
                                 f"or null, not {band!r}")
            if passes is not None and not (isinstance(passes, int) and isinstance(n, int) and 0 <= passes <= n):
                raise InputError(f"{path}: checks.{key}.passes: must be a whole number 0..samples ({n!r}), not "
                                 f"{passes!r}")
            if not isinstance(entry.get("note", ""), str):
                raise InputError(f"{path}: checks.{key}.note: must be text")
            _check_id_of_band(path, f"checks.{key}", key)
            out[key] = {"band": band, "passes": passes, "samples": n, "note": entry.get("note", "")}
        return out
    out = {}
    for key, value in data.items():
        if not _finite_pair(value):
            raise InputError(f"{path}: {key}: must be [low, high] with finite numbers, low <= high, not {value!r}")
        _check_id_of_band(path, key, key)
        out[key] = (float(value[0]), float(value[1]))
    return out


def _check_id_of_band(path, where: str, check_id: str) -> None:
    """A band's key must be a check id (28.<group>.<what>...): a misspelt group would match no row and the band
    would silently not be shown.  (Ids of checks this validate run does not make are fine: a --quick run.)"""
    from housingfe.errors import InputError

    parts = check_id.split(".")
    if len(parts) < 3 or parts[0] != "28" or parts[1] not in CHECK_GROUPS or not all(parts[2:]):
        raise InputError(f"{path}: {where}: not a check id (28.<group>.<what>..., group one of "
                         f"{', '.join(CHECK_GROUPS)})")


def band_text(row: dict) -> str:
    """"—" without an uncertainty statement; else "low … high" and whether the measured value (and the thesis'
    calculated one, where the row has one) is inside it, in how many samples the check passed ("passes in k/n samples") and the band's note, where given."""
    band, passes, note = row.get("band"), row.get("band_passes"), row.get("band_note")
    parts = []
    if band is not None:
        lo, hi = band
        where = []
        for name in ("measured", "thesis_calculated"):      # the replica's goal is the thesis' calculation
            v = row.get(name)
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                where.append(f"{name.replace('_', ' ')} {'inside' if lo <= v <= hi else 'outside'}")
        parts.append(f"{lo:.4g} … {hi:.4g}" + (": " + ", ".join(where) if where else ""))
    if passes is not None:
        parts.append(f"passes in {passes[0]}/{passes[1]} samples")
    if note:
        parts.append(note)
    return "; ".join(parts) if parts else NO_BAND


def _cell(v) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return "nan" if math.isnan(v) else f"{v:.4g}"
    return str(v)


def _cells(r: dict) -> list[str]:
    return [r["check_id"], r["quantity"], _cell(r["ours"]), _cell(r.get("measured")),
            _cell(r.get("thesis_calculated")), r.get("tolerance", ""), r.get("passed", "") or "report", band_text(r),
            r.get("why", ""), r["unit"], r["scene"], r["source"]]


def checks_markdown(rows) -> str:
    """The check rows of `rows` as a Markdown table (the columns of CHECK_COLUMNS) and a count line; the envelope
    bound's rows (28.bound.*), those of gears as made (28.as_made.*; those of the design variants,
    28.as_made.variants.*, named apart), those of the double helical set against single helical (VS_SINGLE) and
    those of its speed law and smoothness (DH_SPEED_LAW, DH_SMOOTHNESS) are counted apart: they are not checks."""
    found = check_rows(rows)
    lines = ["| " + " | ".join(CHECK_COLUMNS) + " |", "|" + "---|" * len(CHECK_COLUMNS)]
    lines += ["| " + " | ".join(c.replace("|", "\\|").replace("\n", " ") for c in _cells(r)) + " |" for r in found]
    bound = sum(is_bound(r) for r in found)
    made = sum(is_as_made(r) for r in found)
    variants = sum(is_as_made(r) and r["check_id"].startswith(AS_MADE_VARIANTS) for r in found)
    reindex = sum(is_as_made(r) and r["check_id"].startswith(AS_MADE_REINDEX) for r in found)
    chain = {p: [r for r in found if is_as_made_check(r) and r["check_id"].split(".")[2] == p]
             for p in AS_MADE_PITCHES}
    n_chain = sum(len(v) for v in chain.values())
    vs_single = sum(is_vs_single(r) for r in found)
    dh_law = sum(is_dh_speed_law(r) for r in found)
    checks = len(found) - bound - made - vs_single - dh_law
    passed = sum(r.get("passed") == "yes" for r in found)
    failed = sum(r.get("passed") == "no" for r in found)
    parts = [f"{made - variants - n_chain - reindex} of the default run-up"]
    if n_chain:
        would = ", ".join(f"{p} {sum(r.get('as_made_passes') == 'yes' for r in v)} of "
                          f"{sum(bool(r.get('as_made_passes')) for r in v)}" for p, v in chain.items() if v)
        parts.append(f"{n_chain} of the default chain's checks as made (28.{AS_MADE_GROUP}.<pitch>.*; they would "
                     f"pass: {would})")
    if variants:
        parts.append(f"{variants} of the design variants {AS_MADE_VARIANTS}*")
    if reindex:
        parts.append(f"{reindex} of the pinion turned against the wheel {AS_MADE_REINDEX}* (Sec. 5.6)")
    detail = f": {', '.join(parts)}" if (variants or n_chain or reindex) else ""
    lines += ["", f"{checks} checks: {passed} passed, {failed} failed, {checks - passed - failed} reported"
              + (f"; and {bound} rows of the envelope bound (28.bound.*), reported: a bound, not the model" if bound
                 else "")
              + (f"; and {made} rows of gears as made (28.as_made.*, ISO grade {AS_MADE_GRADE} sidebands{detail}), "
                 "reported: not checks" if made else "")
              + (f"; and {vs_single} rows of the double helical set against single helical ({VS_SINGLE}*), "
                 "reported: not checks" if vs_single else "")
              + (f"; and {dh_law} rows of the double helical set's speed law and smoothness ({DH_SPEED_LAW}*, "
                 f"{DH_SMOOTHNESS}*), reported: not checks" if dh_law else "")]
    return "\n".join(lines) + "\n"


def write_checks(rows, folder: Path) -> None:
    """checks.csv and checks.md (the check rows of `rows`) into folder."""
    found = check_rows(rows)
    with open(Path(folder) / "checks.csv", "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(CHECK_COLUMNS)
        for r in found:
            cells = _cells(r)
            cells[7] = "" if cells[7] == NO_BAND else cells[7]
            writer.writerow(cells)
    (Path(folder) / "checks.md").write_text(checks_markdown(rows))


# ------------------------------------------------------------------------------------------ pass/fail logic
def window_distance(speed: float, window) -> float:
    """Distance (rev/min) of a speed from a window (lo, hi); 0 inside."""
    lo, hi = window
    return max(lo - speed, speed - hi, 0.0)


def peak_windows(peaks, windows=PEAK_WINDOWS_RPM, tolerance=PEAK_TOLERANCE_RPM, mode_band=PEAK_MODE_BAND_HZ,
                 needed=PEAKS_NEEDED) -> dict:
    """The "L_WA peaks within 100 rpm of at least two of the measured windows, each traced to coupled modes between
    150 and 600 Hz" check.  peaks: [(speed rpm, dominant mode Hz or None)] — the dominant mode is the one with the
    largest share of the peak's <v^2>.  Per window the nearest peak that qualifies (within `tolerance` and its mode
    inside mode_band) or, if none, the nearest peak at all; passed when `needed` windows have a qualifying peak."""
    per_window = []
    for w in windows:
        qualifying = [(window_distance(s, w), s, f) for s, f in peaks if window_distance(s, w) <= tolerance
                      and f is not None and mode_band[0] <= f <= mode_band[1]]
        near = [(window_distance(s, w), s, f) for s, f in peaks]
        best = min(qualifying or near, default=None)
        per_window.append({"window": tuple(w), "matched": bool(qualifying),
                           "peak_rpm": None if best is None else best[1], "distance_rpm": None if best is None else
                           best[0], "mode_hz": None if best is None else best[2]})
    hits = sum(p["matched"] for p in per_window)
    return {"windows": per_window, "hits": hits, "passed": hits >= needed}


def carrying_harmonic(harmonics, lwa_db) -> tuple[int, float]:
    """(harmonic, its share of the total power) of the line with the largest L_WA at one speed.  Where a harmonic
    has several lines (gears as made in the totals: the periodic line and the incoherent sidebands in its 1/3-octave
    band, runup.as_made_totals) they are energy-summed first: the harmonic whose band carries the most."""
    lw = np.asarray(lwa_db, float)
    power = 10.0 ** (lw / 10.0)
    h = np.asarray(harmonics).astype(int)
    if np.unique(h).size < h.size:
        uniq, group = np.unique(h, return_inverse=True)
        band = np.bincount(group, weights=np.nan_to_num(power))
        g = int(np.argmax(band))
        return int(uniq[g]), float(band[g] / np.nansum(power))
    i = int(np.nanargmax(lw))
    return int(h[i]), float(power[i] / np.nansum(power))


def third_octave_index(frequency_hz) -> np.ndarray:
    """The base-10 one-third-octave band number of each frequency (IEC 61260-1: band b has the exact centre
    1000 * 10^((b - 30) / 10) Hz, its edges at +-1/20 decade): round(10 lg f)."""
    return np.rint(10.0 * np.log10(np.asarray(frequency_hz, float))).astype(int)


def tooth_band_largest(frequency_hz, harmonic, level_db) -> bool:
    """At one speed: is the 1/3-octave band of the tooth frequency (harmonic 1) the largest band of this quantity's
    spectrum?  Lines energy-summed per band (at high harmonics two lines can share a band); ties count as largest."""
    band = third_octave_index(frequency_hz)
    power = 10.0 ** (np.asarray(level_db, float) / 10.0)
    h = np.asarray(harmonic)
    if not np.any(h == 1):
        raise ValueError("tooth_band_largest: no tooth-frequency line")
    tooth = band[h == 1][0]
    sums = {b: float(np.nansum(power[band == b])) for b in np.unique(band)}
    return sums[tooth] >= max(sums.values()) * (1.0 - 1e-12)


def tooth_band_share(speeds, frequency_hz, harmonic, level_db, speed_min=TOOTH_BAND_SPEED_MIN_RPM
                     ) -> tuple[float, int, list[float]]:
    """(share of the speeds >= speed_min at which the tooth band is the largest, number of such speeds, the speeds
    where it is not); all arguments per line (one row per speed and harmonic)."""
    s = np.asarray(speeds, float)
    f, h, lv = (np.asarray(x) for x in (frequency_hz, harmonic, level_db))
    keep = np.unique(s[s >= speed_min])
    if not keep.size:
        return float("nan"), 0, []
    missed = [float(v) for v in keep if not tooth_band_largest(f[s == v], h[s == v], lv[s == v])]
    return 1.0 - len(missed) / keep.size, int(keep.size), missed


def ranking_ends(ours: str, measured: str) -> dict:
    """Quietest-first rankings "a < b < c": do the quietest and the loudest agree, and the whole order?"""
    o, m = [x.strip() for x in ours.split("<")], [x.strip() for x in measured.split("<")]
    return {"quietest": o[0] == m[0], "loudest": o[-1] == m[-1], "order": o == m,
            "passed": o[0] == m[0] and o[-1] == m[-1]}


def within(ours: float, target: float, tolerance: float) -> bool:
    """|ours - target| <= tolerance (False for NaN)."""
    return bool(abs(float(ours) - float(target)) <= tolerance)
