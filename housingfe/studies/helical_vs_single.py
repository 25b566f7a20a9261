"""Does a double helical set make this gearbox quieter?  The double helical family against the single helical ones.

The thesis (Sec. 5.9, thesis lines 2157-2185) compares its double helical set, on cylindrical roller and on
fluid-film bearings at 2000 N m, with the single helical gear set A on ball bearings (the profile corrections'
reference, Sec. 5.7) and with gear set B on double row self-aligning roller bearings (the quietest bearings of
Sec. 5.8), all at 2000 N m:

* the mean of L_WA(double helical) - L_WA(single helical) over 800-1500 rev/min, speed by speed (the thesis'
  measure of Secs. 5.7-5.9: the arithmetic mean of the dB differences at the speeds both run-ups have), with its
  population standard deviation; measured -5.3 / -7.2 dB against set A, -0.2 / -2.1 dB against self-aligning B
  (rollers / fluid films);
* the reduction of the maximum L_WA over the run-up, max L_WA(single) - max L_WA(double helical) (dB(A), > 0: the
  double helical set is quieter); measured 9.5 / 12.8 dB(A) against set A (100.5 -> 91.0 / 87.7), and from the
  measured maxima 92.3 -> 91.0 / 87.7 against self-aligning B: 1.3 / 4.6 dB(A) (the thesis states the maxima, not
  this difference).

The two layouts are different models (each family its own modal basis), so the comparison reads each family's
run-up table (<family>_runup.csv of `housingfe study`, housingfe.studies.design_variants.write): speeds and the
periodic L_WA per route and variant.  `housingfe study double-helical profile-corrections bearings` writes it
beside the families (double-helical_vs_single.csv / .md, `write`); `housingfe validate` gives its rows
(housingfe.verification.study_rows.double_helical_vs_single_rows).
"""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from housingfe.errors import InputError
from housingfe.studies.chain_session import MEAN_RANGE_RPM

# the double helical variants compared (the family's variant key, the thesis' name in roosmalen1994.toml)
DOUBLE_HELICAL = (("cylindrical_roller@2000", "roller"), ("fluid_film@2000", "fluid_film"))
# the single helical references: name in ids -> (family, variant key, what it is)
SINGLE_HELICAL = {"A": ("profile-corrections", "A", "single helical set A, ball bearings, 2000 N m"),
                  "B_self_aligning": ("bearings", "self_aligning",
                                      "single helical set B, self-aligning roller bearings, 2000 N m")}
FAMILY = "double-helical"
COLUMNS = ("double_helical", "single_helical", "route", "mean_diff_dB", "sd_diff_dB", "speeds_in_mean",
           "measured_mean_dB", "LwA_max_double_dBA", "at_rpm_double", "LwA_max_single_dBA", "at_rpm_single",
           "max_reduction_dBA", "measured_max_reduction_dBA")


def measured() -> dict:
    """{(thesis name of the double helical bearings, single helical key): (measured mean difference dB, measured
    reduction of the maximum dB(A))} from housingfe/data/roosmalen1994.toml [test_gearbox.double_helical]; against
    self-aligning B the reduction is the difference of the measured maxima (meas_Lw_max_dBA)."""
    from housingfe.data import thesis

    dh = thesis()["test_gearbox"]["double_helical"]
    top = dh["meas_Lw_max_dBA"]
    out = {}
    for _, name in DOUBLE_HELICAL:
        out[(name, "A")] = (dh["vs_single_helical_A_mean_dB"][name], dh["max_reduction_vs_single_helical_A_dBA"][name])
        out[(name, "B_self_aligning")] = (dh["vs_single_helical_B_self_aligning_mean_dB"][name],
                                          round(top["self_aligning"] - top[name], 2))
    return out


def difference(speeds, levels_db, ref_speeds, ref_db, speed_range=MEAN_RANGE_RPM) -> dict:
    """One run-up (speeds rev/min, L_WA dB(A)) against a reference run-up of another layout, at the speeds both
    have (to 1e-6 rev/min): mean_dB / sd_dB (population) / n of levels - reference over speed_range (inclusive),
    and each curve's maximum over the common speeds with its speed, reduction_dB = max(reference) - max(levels).
    InputError when no common speed lies inside speed_range."""
    s, v = np.asarray(speeds, float), np.asarray(levels_db, float)
    rs, rv = np.asarray(ref_speeds, float), np.asarray(ref_db, float)
    key, rkey = np.round(s, 6), np.round(rs, 6)
    common = np.intersect1d(key, rkey)
    a = np.array([v[np.flatnonzero(key == c)[0]] for c in common])
    b = np.array([rv[np.flatnonzero(rkey == c)[0]] for c in common])
    keep = (common >= speed_range[0]) & (common <= speed_range[1])
    if not keep.any():
        raise InputError(f"no common speed of the two run-ups inside {speed_range[0]:g}-{speed_range[1]:g} rev/min, "
                         "where the thesis states its mean differences")
    d = a[keep] - b[keep]
    i, j = int(np.argmax(a)), int(np.argmax(b))
    return {"mean_dB": float(d.mean()), "sd_dB": float(d.std()), "n": int(keep.sum()),
            "max_dB": float(a[i]), "at_rpm": float(common[i]), "ref_max_dB": float(b[j]),
            "ref_at_rpm": float(common[j]), "reduction_dB": float(b[j] - a[i])}


def speed_law(speeds, levels_db, speed_range=None) -> dict:
    """The speed law of one run-up curve (speeds rev/min, L_WA dB(A)) over speed_range (inclusive; default the
    set-A check's 250-1500 rev/min, housingfe.runup.slopes.SPEED_LAW_RANGE_RPM): slope_dB (least squares against
    log2 of the speed: dB(A) per doubling), residual_sd_dB (population s.d. of L_WA about that line, dB: how
    smooth the curve is), n and the lowest / highest speed used.  InputError when fewer than three speeds or less
    than a doubling of speed lie in the range."""
    from housingfe.runup.slopes import SPEED_LAW_RANGE_RPM

    lo, hi = SPEED_LAW_RANGE_RPM if speed_range is None else speed_range
    s, v = np.asarray(speeds, float), np.asarray(levels_db, float)
    keep = (s >= lo) & (s <= hi) & np.isfinite(v)
    if keep.sum() < 3 or s[keep].max() < 2 * s[keep].min():
        raise InputError(f"speed law: less than a doubling of speed (or fewer than three speeds) inside "
                         f"{lo:g}-{hi:g} rev/min")
    x, y = np.log2(s[keep]), v[keep]
    slope, intercept = np.polyfit(x, y, 1)
    return {"slope_dB": float(slope), "residual_sd_dB": float(np.std(y - (intercept + slope * x))),
            "n": int(keep.sum()), "from_rpm": float(s[keep].min()), "to_rpm": float(s[keep].max())}


def read_runup_table(path: Path) -> dict:
    """{column: values} of a family's run-up table (<family>_runup.csv: speed_rpm, LwA_<route>_<variant>_dBA, ...);
    InputError naming the file when it is missing or unreadable."""
    path = Path(path)
    try:
        with open(path, newline="") as fh:
            rows = list(csv.DictReader(fh))
    except OSError as exc:
        raise InputError(f"{path}: cannot read the run-up table: {exc.strerror or exc}") from None
    if not rows:
        raise InputError(f"{path}: empty run-up table")
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def curves(table: dict, variant: str, path) -> dict:
    """{route: (speeds, L_WA)} of one variant's periodic L_WA (LwA_<route>_<variant>_dBA; not the *_as_made_*
    columns); InputError naming the file and variant when it has none."""
    tail = f"_{variant}_dBA"
    out = {c[4:-len(tail)]: (table["speed_rpm"], v) for c, v in table.items()
           if c.startswith("LwA_") and c.endswith(tail) and not c.startswith("LwA_as_made_")}
    if "speed_rpm" not in table or not out:
        raise InputError(f"{path}: no column LwA_<route>{tail} (the run of variant {variant!r} is missing)")
    return out


def compare(tables: dict) -> list[dict]:
    """The comparison rows (COLUMNS) from the run-up tables {family: (table, path)} of the double helical family and
    of the single helical families present (profile-corrections -> A, bearings -> B_self_aligning), per double
    helical variant, single helical reference and route of the double helical table.  InputError when the double
    helical table, or a variant or route of a table given, is missing."""
    if FAMILY not in tables:
        raise InputError("double helical vs single helical: no run-up table of the double-helical family")
    known = measured()
    table, path = tables[FAMILY]
    rows = []
    for variant, name in DOUBLE_HELICAL:
        mine = curves(table, variant, path)
        for ref, (family, ref_variant, _) in SINGLE_HELICAL.items():
            if family not in tables:
                continue
            theirs = curves(*tables[family][:1], ref_variant, tables[family][1])
            mean_meas, red_meas = known[(name, ref)]
            for route, (s, lv) in mine.items():
                if route not in theirs:
                    raise InputError(f"{tables[family][1]}: no column LwA_{route}_{ref_variant}_dBA (route {route} "
                                     f"of {ref_variant!r} is missing)")
                d = difference(s, lv, *theirs[route])
                rows.append({"double_helical": name, "single_helical": ref, "route": route,
                             "mean_diff_dB": round(d["mean_dB"], 2), "sd_diff_dB": round(d["sd_dB"], 2),
                             "speeds_in_mean": d["n"], "measured_mean_dB": mean_meas,
                             "LwA_max_double_dBA": round(d["max_dB"], 1), "at_rpm_double": d["at_rpm"],
                             "LwA_max_single_dBA": round(d["ref_max_dB"], 1), "at_rpm_single": d["ref_at_rpm"],
                             "max_reduction_dBA": round(d["reduction_dB"], 2), "measured_max_reduction_dBA": red_meas})
    return rows


def tables_of(folders: dict) -> dict:
    """{family: (run-up table, path)} read from {family: the folder `housingfe study` wrote it into}."""
    return {f: (read_runup_table(Path(d) / f"{f}_runup.csv"), Path(d) / f"{f}_runup.csv") for f, d in folders.items()}


def markdown(rows: list[dict]) -> str:
    """The comparison as a Markdown table, ours beside measured."""
    out = ["# Double helical vs single helical (2000 N m)", "",
           "Mean of L_WA(double helical) - L_WA(single helical) over 800-1500 rev/min at the common speeds (s.d. "
           "over speed), and the reduction of the maximum L_WA, max(single) - max(double helical); measured: "
           "van Roosmalen 1994, Sec. 5.9 (thesis lines 2157-2185; against self-aligning B the reduction is the "
           "difference of the measured maxima 92.3 -> 91.0 / 87.7 dB(A)).  A: set A, ball bearings; "
           "B_self_aligning: set B, self-aligning roller bearings.", "",
           "| double helical | vs | route | mean diff dB (s.d.) | measured | max reduction dB(A) (max double / "
           "single) | measured |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        out.append(f"| {r['double_helical']} | {r['single_helical']} | {r['route']} | {r['mean_diff_dB']:+.1f} "
                   f"({r['sd_diff_dB']:.1f}) | {r['measured_mean_dB']:+g} | {r['max_reduction_dBA']:+.1f} "
                   f"({r['LwA_max_double_dBA']:.1f} / {r['LwA_max_single_dBA']:.1f}) | "
                   f"{r['measured_max_reduction_dBA']:+g} |")
    return "\n".join(out) + "\n"


def write(folder: Path, rows: list[dict]) -> None:
    """double-helical_vs_single.csv and .md into folder."""
    with open(Path(folder) / "double-helical_vs_single.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, COLUMNS)
        w.writeheader()
        w.writerows(rows)
    (Path(folder) / "double-helical_vs_single.md").write_text(markdown(rows))


def from_studies(written) -> list[dict]:
    """The comparison of families run together (`housingfe study double-helical profile-corrections bearings`):
    written = [(family name, engagement, the folder its tables were written into)]; the double helical family
    against the single helical families run with the same engagement shock (the first of each).  [] when the double
    helical family, or every single helical one, is not among them."""
    dh = next(((e, d) for f, e, d in written if f == FAMILY), None)
    if dh is None:
        return []
    folders = {FAMILY: dh[1]}
    for family, engagement, folder in written:
        if family in {f for f, _, _ in SINGLE_HELICAL.values()} and engagement == dh[0]:
            folders.setdefault(family, folder)
    return compare(tables_of(folders)) if len(folders) > 1 else []
