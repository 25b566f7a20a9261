"""Design variants through the chain (`housingfe study`, issue 28 item 4) against the thesis' Secs. 5.7-5.9.

Rows, per route (tf_omega, mesh_force; sigma = 1), with the default engagement shock (face width):
* every measured variant's mean L_WA difference to its family's reference over 800-1500 rev/min (goal: within 3 dB
  of the measured mean, read against the measured s.d. given in the note) and its maximum L_WA;
* the ranking of the measured variants by mean difference and by maximum, ours against measured;
* profile correction D: whether ours reproduces the measured near-zero difference (-0.3 dB) better than the
  thesis' calculation (-5.1 dB);
* the double helical set's torque law (L_WA(2000 N m) - L_WA(1000 N m), mean over 800-1500 rev/min; goal within
  1.5 dB of the measured +3.4 / +2.7 dB(A));
and the thesis replica's check on the profile corrections (engagement `thesis-2d`, tf_omega): the thesis'
calculated differences -0.4/+2.9/-5.1 dB within 1.5 dB.  With the envelope bound (engagement `envelope-bound`, set
A's overlap ratio 1.026 sits at the face-width engagement's cancellation; docs/source.md) the profile corrections and
the bearings run once more, and their check rows come out as the envelope bound's rows 28.bound.variants.* (the same
row functions, checks.as_bound: reported beside the checks, never judged, no band; a bound, not the model).  The
double helical set (overlap ratio 1.139) has no such note and no bound rows.  The bearings and the double helical
set run with runup.as_made = 5 (the expected sidebands of ISO grade-5 gears; docs/design-variants.md "Gears as made
in the variants"): the same run gives the periodic comparison, unchanged, and beside it the same comparison on the
L_WA as made, whose rows come out as 28.as_made.variants.* (`as_made_rows`, checks.as_made_row: reported, never
judged, no band) for the bearings' mean differences and rankings and the double helical set's torque law.

The six studies run as one cached computation (`housingfe.studies.design_variants.run_studies`: one process, so
the single helical families and both engagements share one modal basis and the double helical family has its
own) in <results>/study-validate/, reused while its key holds (housingfe.verification.validate: the resolved scenes
and the content of every file the run imported).  From an empty cache it takes a few minutes (two bases, 17
re-analyses, the bound's two families about 20 s of it, the sidebands of the twelve variants as made about 100 s),
so `housingfe validate --quick` computes nothing here: it takes the rows from a valid cached result or leaves them
out with a note.
"""
from __future__ import annotations

import json
from pathlib import Path

from housingfe.verification.checks import AS_MADE_OVERRIDE

FOLDER = "study-validate"
# (family, --set overrides, subfolder): the default engagement for every family, the thesis replica's shock for
# the profile corrections (its calculated differences are the replica check), and the envelope bound for the single
# helical families (set A's overlap note; reported rows 28.bound.*, not checks); the bearings and the double helical
# set also with gears as made (runup.as_made = 5: the same run gives the periodic comparison, unchanged, and the
# as-made one beside it, study.json "as_made"; reported rows 28.as_made.variants.*, not checks)
BOUND_ENGAGEMENT = "envelope-bound"
JOBS = (("profile-corrections", (), "profile-corrections-face-width"),
        ("bearings", (AS_MADE_OVERRIDE,), "bearings-face-width"),
        ("double-helical", (AS_MADE_OVERRIDE,), "double-helical-face-width"),
        ("profile-corrections", ("runup.engagement=thesis-2d",), "profile-corrections-thesis-2d"),
        ("profile-corrections", (f"runup.engagement={BOUND_ENGAGEMENT}",), f"profile-corrections-{BOUND_ENGAGEMENT}"),
        ("bearings", (f"runup.engagement={BOUND_ENGAGEMENT}",), f"bearings-{BOUND_ENGAGEMENT}"))
MEAN_GOAL_DB = 3.0          # issue 28: mean differences within 3 dB where the measured s.d. allows
REPLICA_GOAL_DB = 1.5       # issue 28: the replica's correction differences within 1.5 dB of the thesis' calculation
TORQUE_LAW_GOAL_DB = 1.5
# what the failing checks were traced to, measured one factor at a time (benchmarks/experiments/replica_d)
_CAUSES = "docs/design-variants.md, 'Why correction D and the torque law fail'"
REPLICA_D_CAUSE = ("; cause measured: D's data read right; in the 2-D shock D sits on the steep flank of its optimum "
                   "(1750 N m), sensitive to the load and the ramp shape; the 2-D shock cannot represent D's 3-D "
                   f"triangle ({_CAUSES})")
TORQUE_LAW_CAUSE = ("; cause measured: the L_WA step is carried by the 4th-5th tooth harmonics, whose excitation "
                    "grows +12 dB because 1000 N m sits near the reliefs' minimum for them (unrelieved: +5.7 to "
                    "+6.8 dB(A)); not the bearings' stiffness, the max-picking, misalignment or the shuttling moment "
                    "(docs/design-variants.md, 'The torque law per harmonic')")


def published_rows(results: Path | None = None, quick: bool = False) -> list[dict]:
    """The rows (module docstring) from the cached study result in <results>/study-validate/, computed first when
    stale (not with quick: then no rows, and a note on the console)."""
    folder = study_folder(results, quick)
    if folder is None:
        return []
    rows = []
    for family, overrides, sub in JOBS:
        data = json.loads((folder / sub / "study.json").read_text())
        rows += bound_rows(data) if data["engagement"] == BOUND_ENGAGEMENT else study_rows(data) + as_made_rows(data)
    return rows


# the check rows of a family whose counterparts with gears as made are reported (28.as_made.<the check's id after
# 28.>): the bearings' mean differences and rankings, the double helical set's torque law
AS_MADE_CHECKS = {"bearings": ("variants.mean.bearings.", "variants.ranking.bearings."),
                  "double-helical": ("variants.torque_law.",)}


def as_made_rows(data: dict) -> list[dict]:
    """The rows of gears as made of one study result run with runup.as_made (study.json "as_made": the comparison on
    the L_WA with the expected sidebands of gears of that ISO grade): the check rows of `study_rows` on the as-made
    comparison that AS_MADE_CHECKS names for the family, as 28.as_made.<the check's id after 28.>
    (checks.as_made_row: reported, never judged, no tolerance, no band), ours as made beside the check's measured
    and thesis calculated, the periodic value (the check's ours) first in `why`.  None for a study without
    "as_made" (run without runup.as_made) or of another family: not an error."""
    from housingfe.verification.checks import AS_MADE_GROUP, as_made_row, is_check

    made, keep = data.get("as_made"), AS_MADE_CHECKS.get(data["family"], ())
    if not made or not keep:
        return []
    periodic = {r["check_id"]: r for r in study_rows(data) if is_check(r)}
    scene = f"study {data['family']} ({data['engagement']}, gears {made['label']})"
    out = []
    for r in study_rows({**data, **{k: made[k] for k in ("rows", "rankings", "torque_law")}}, causes=False):
        if not (is_check(r) and r["check_id"][3:].startswith(keep)):
            continue
        p = periodic[r["check_id"]]["ours"]
        p = p if isinstance(p, str) else f"{p:+g} {r['unit']}"
        out.append(as_made_row(f"28.{AS_MADE_GROUP}.{r['check_id'][3:]}", scene,
                               f"{made['label']}: {r['quantity']}",
                               r["ours"], r["unit"], r["source"], measured=r["measured"],
                               thesis_calculated=r["thesis_calculated"], why=f"periodic {p}; as made: {r['why']}"))
    return out


def bound_rows(data: dict) -> list[dict]:
    """The envelope bound's rows of one study result with engagement envelope-bound: its check rows of
    `study_rows` (the mean differences, the rankings of the bearings, correction D) as 28.bound.variants.*
    (checks.as_bound: reported, not judged, no band), and the mean difference of a variant that has no check for
    want of a measured mean but a calculated one of the thesis (the uncorrected set: +3.5 dB), beside that; the
    other rows are left out.  Per route: the mean differences first, then the rankings and correction D."""
    from housingfe.verification.checks import as_bound, check_row, is_check

    if data["engagement"] != BOUND_ENGAGEMENT:
        raise ValueError(f"bound_rows: engagement {data['engagement']!r}, not {BOUND_ENGAGEMENT!r}")
    out = [as_bound(r) for r in study_rows(data) if is_check(r)]
    family, ref = data["family"], data["reference"]
    for r in data["rows"]:
        if r["measured_mean_dB"] is None and r["thesis_calc_mean_dB"] is not None:
            out.append(as_bound(check_row(
                f"28.variants.mean.{family}.{_id(r['variant'])}.{r['route']}", f"study {family} ({data['engagement']})",
                f"{r['route']}: {r['variant']} - {ref}, mean L_WA difference 800-1500 rpm", r["mean_diff_dB"], "dB",
                data["source"], thesis_calculated=r["thesis_calc_mean_dB"],
                why=f"s.d. over speed: ours {r['sd_diff_dB']} dB; no measured mean (so no check), the thesis "
                    f"calculated {r['thesis_calc_mean_dB']:+g}" + ("" if r["thesis_calc_sd_dB"] is None else
                                                                   f" (s.d. {r['thesis_calc_sd_dB']})"))))
    routes = list(dict.fromkeys(r["route"] for r in data["rows"]))
    return sorted(out, key=lambda r: (routes.index(r["check_id"].rsplit(".", 1)[1]) if r["check_id"].rsplit(".", 1)[1]
                                      in routes else len(routes), ".mean." not in r["check_id"]))


def fe_results(results: Path | None = None, quick: bool = False) -> list:
    """The FE result these rows read, for `housingfe validate --workers` (validate.fe_results): [(rough seconds,
    callable computing it when stale)]."""
    from functools import partial

    return [(240.0, partial(study_folder, results, quick))]


def study_folder(results: Path | None = None, quick: bool = False) -> Path | None:
    """<results>/study-validate/ with every job's study.json, computed first when its key does not match (a few
    minutes); with quick a stale result is not computed: None, and a note on the console."""
    from housingfe.verification import validate

    results = validate.RESULTS if results is None else Path(results)
    folder = results / FOLDER
    scene, extra = cache_identity()
    last = f"{JOBS[-1][2]}/study.json"
    reason = validate.stale_reason(folder, scene, last, extra)
    if reason:
        if quick:
            print(f"validate: study rows left out with --quick (no valid cached {folder}/: {reason}; "
                  "`housingfe validate` computes it)", flush=True)
            return None
        validate.compute({"kind": "study", "jobs": [[f, list(o), sub] for f, o, sub in JOBS]}, scene, folder, results,
                         "housingfe study (profile-corrections, bearings, double-helical, the last two also as "
                         "made; thesis-2d profile corrections; envelope-bound profile corrections and bearings)", extra, reason)
    return folder


def cache_identity():
    """(the first job's resolved run-up scene, the others' and the jobs as JSON-able extra): what the cached result
    depends on besides the code."""
    from housingfe.runup.scene import load_runup_scene
    from housingfe.scene import load_housing_scene
    from housingfe.studies.design_variants import family_of

    scenes = []
    for family, overrides, sub in JOBS:
        scene, _ = load_runup_scene(family_of(family).scene, list(overrides))
        housing, _ = load_housing_scene(scene.housing.scene, list(scene.housing.set))
        scenes.append((scene, {"family": family, "overrides": list(overrides), "folder": sub,
                               "scene": scene.model_dump(mode="json"), "housing": housing.model_dump(mode="json")}))
    return scenes[0][0], {"jobs": [e for _, e in scenes]}


def _yes(flag: bool) -> str:
    return "yes" if flag else "no"


def _id(variant: str) -> str:
    return variant.replace("@", "_at_")


# the rankings that are checks of issue 28 ("the measured ranking of the bearing configurations (self-aligning
# quietest, ball loudest) and of rollers vs fluid films"): family -> the name in the check_id
RANKING_CHECKS = {"bearings": "bearings", "double-helical": "rollers_vs_fluid_films"}


def study_rows(data: dict, causes: bool = True) -> list[dict]:
    """Validate rows of one study result (study.json of housingfe.studies.design_variants); the rows that are checks
    of issue 28 carry their check_id (housingfe.verification.checks).  causes: the measured causes of the failing
    checks in their `why` (they were measured on the periodic comparison: `as_made_rows` leaves them out)."""
    from housingfe.verification.checks import ranking_ends, tag
    from housingfe.verification.published import row

    family, engagement, src = data["family"], data["engagement"], data["source"]
    label = f"study {family} ({engagement})"
    ref = data["reference"]
    replica = engagement == "thesis-2d"
    out = []
    for r in data["rows"]:
        route, v = r["route"], r["variant"]
        if replica:       # the thesis' calculation: L_omega differences on one TF_omega (tf_omega route)
            if route == "tf_omega" and r["thesis_calc_mean_dB"] is not None:
                ok = abs(r["mean_diff_dB"] - r["thesis_calc_mean_dB"]) <= REPLICA_GOAL_DB
                out.append(tag(row(label, f"{route}: {v} - {ref}, mean L_WA difference 800-1500 rpm (thesis "
                                   "replica)", r["mean_diff_dB"], r["thesis_calc_mean_dB"], "dB", src,
                                   f"published = the thesis' CALCULATED mean (s.d. {r['thesis_calc_sd_dB']}); ours "
                                   f"s.d. {r['sd_diff_dB']}; goal: within {REPLICA_GOAL_DB:g} dB; passed: {_yes(ok)}"),
                               f"28.replica.correction.{_id(v)}", measured=r["measured_mean_dB"],
                               thesis_calculated=r["thesis_calc_mean_dB"], tolerance=f"{REPLICA_GOAL_DB:g} dB of the "
                               "thesis' calculation", passed=ok, why=f"ours s.d. {r['sd_diff_dB']} dB over speed"
                               + (REPLICA_D_CAUSE if v == "D" and causes else "")))
            continue
        if r["measured_mean_dB"] is not None:
            ok = abs(r["mean_diff_dB"] - r["measured_mean_dB"]) <= MEAN_GOAL_DB
            calc = ("" if r["thesis_calc_mean_dB"] is None else
                    f"; thesis calculated {r['thesis_calc_mean_dB']:+g} (s.d. {r['thesis_calc_sd_dB']})")
            inside_sd = (r["measured_sd_dB"] is not None
                         and abs(r["mean_diff_dB"] - r["measured_mean_dB"]) <= r["measured_sd_dB"])
            out.append(tag(row(label, f"{route}: {v} - {ref}, mean L_WA difference 800-1500 rpm", r["mean_diff_dB"],
                               r["measured_mean_dB"], "dB", src,
                               f"s.d. ours {r['sd_diff_dB']}, measured {r['measured_sd_dB']}{calc}; goal: within "
                               f"{MEAN_GOAL_DB:g} dB; passed: {_yes(ok)}"),
                           f"28.variants.mean.{family}.{_id(v)}.{route}", measured=r["measured_mean_dB"],
                           thesis_calculated=r["thesis_calc_mean_dB"], tolerance=f"{MEAN_GOAL_DB:g} dB", passed=ok,
                           why=f"s.d. over speed: ours {r['sd_diff_dB']}, measured {r['measured_sd_dB']} dB; ours "
                               f"{'inside' if inside_sd else 'outside'} the measured s.d."))
        if r["measured_max_dBA"] is not None:
            out.append(row(label, f"{route}: {v}: max L_WA ({r['at_rpm']:g} rpm)", r["LwA_max_dBA"],
                           r["measured_max_dBA"], "dB(A)", src,
                           "" if r["thesis_calc_max_dBA"] is None else
                           f"thesis calculated {r['thesis_calc_max_dBA']}"))
    if replica:
        return out
    for k in data["rankings"]:
        r = row(label, f"{k['route']}: ranking by {k['measure']}, quietest first", k["ours"], k["measured"],
                "-", src, f"same order: {_yes(k['matches'])}; quietest: {_yes(k['quietest'])}; loudest: "
                          f"{_yes(k['loudest'])}")
        if family in RANKING_CHECKS:
            ends = ranking_ends(k["ours"], k["measured"])
            measure = "mean" if k["measure"].startswith("mean") else "max"
            tag(r, f"28.variants.ranking.{RANKING_CHECKS[family]}.{measure}.{k['route']}", measured=k["measured"],
                tolerance="the measured quietest and loudest", passed=ends["passed"],
                why=f"quietest {_yes(ends['quietest'])}, loudest {_yes(ends['loudest'])}, whole order "
                    f"{_yes(ends['order'])}")
        out.append(r)
    if family == "profile-corrections":
        for r in (r for r in data["rows"] if r["variant"] == "D"):
            ours = abs(r["mean_diff_dB"] - r["measured_mean_dB"])
            thesis_miss = abs(r["thesis_calc_mean_dB"] - r["measured_mean_dB"])
            out.append(tag(row(label, f"{r['route']}: correction D, |ours - measured| of the mean difference vs "
                                      "the thesis' |calculated - measured|", round(ours, 2), round(thesis_miss, 2), "dB",
                               src, f"ours {r['mean_diff_dB']:+.2f}, measured {r['measured_mean_dB']:+g}, thesis "
                                    f"calculated {r['thesis_calc_mean_dB']:+g}; goal: ours below the thesis'; passed: "
                                    f"{_yes(ours < thesis_miss)}"),
                           f"28.variants.correction_d.{r['route']}", thesis_calculated=round(thesis_miss, 2),
                           tolerance="|ours - measured| below the thesis' |calculated - measured|",
                           passed=ours < thesis_miss,
                           why=f"D - A mean: ours {r['mean_diff_dB']:+.2f}, measured {r['measured_mean_dB']:+g}, "
                               f"thesis calculated {r['thesis_calc_mean_dB']:+g} dB"))
    for t in data.get("torque_law", []):
        if t["measured_step_dBA"] is None:       # a group without a measured step: nothing to check against
            continue
        ok = abs(t["step_mean_dB"] - t["measured_step_dBA"]) <= TORQUE_LAW_GOAL_DB
        out.append(tag(row(label, f"{t['route']}: {t['bearings']}: L_WA(2000 N m) - L_WA(1000 N m), mean 800-1500 "
                                  "rpm", t["step_mean_dB"], t["measured_step_dBA"], "dB(A)", src,
                           f"s.d. {t['step_sd_dB']}, at 1500 rpm {t['step_at_1500rpm_dB']:+.2f}; slope over "
                           f"{t['torques_nm']} N m {t['slope_dB_per_doubling']:+.2f} dB(A) per doubling; goal: within "
                           f"{TORQUE_LAW_GOAL_DB:g} dB; passed: {_yes(ok)}"),
                       f"28.variants.torque_law.{t['bearings']}.{t['route']}", measured=t["measured_step_dBA"],
                       tolerance=f"{TORQUE_LAW_GOAL_DB:g} dB", passed=ok,
                       why=f"slope over {t['torques_nm']} N m {t['slope_dB_per_doubling']:+.2f} dB(A) per doubling "
                           f"(measured law: +3 per doubling){TORQUE_LAW_CAUSE if causes else ''}"))
    return out


# the jobs whose run-up tables the double helical set is compared with single helical from: each family's run with
# the default engagement (the first job of the family in JOBS)
VS_SINGLE_FAMILIES = ("double-helical", "profile-corrections", "bearings")
VS_SINGLE_WHAT = {"mean": ("mean L_WA difference 800-1500 rpm", "dB"),
                  "max_reduction": ("reduction of the maximum L_WA, max(single) - max(double helical)", "dB(A)")}


def default_engagement_folders(folder: Path, families) -> dict:
    """{family: the folder of its default-engagement job in the study folder} (the first job of each of `families`
    in JOBS without an engagement override), where `housingfe study` wrote its <family>_runup.csv."""
    subs = {}
    for family, overrides, sub in JOBS:
        if family in families and family not in subs and not any("engagement" in o for o in overrides):
            subs[family] = Path(folder) / sub
    return subs


def double_helical_vs_single_rows(folder: Path) -> list[dict]:
    """The double helical set (rollers, fluid films; 2000 N m) against single helical set A (ball bearings) and set B
    on self-aligning roller bearings (2000 N m), per route, from the run-up tables of the study's default-engagement
    jobs in folder (<results>/study-validate/<family>-face-width/<family>_runup.csv; housingfe.studies.
    helical_vs_single): the mean ± s.d. of the L_WA difference over 800-1500 rpm and the reduction of the maximum,
    ours beside measured, as 28.variants.double_helical_vs_single.<roller|fluid_film>.<A|B_self_aligning>.
    <mean|max_reduction>.<route> (checks.VS_SINGLE: reported, never judged, no band: the issue's checks do not name
    this comparison).  InputError naming the file when a needed run is missing."""
    from housingfe.studies import helical_vs_single as hvs
    from housingfe.verification.checks import VS_SINGLE, check_row
    from housingfe.verification.published import thesis_source

    rows = hvs.compare(hvs.tables_of(default_engagement_folders(folder, VS_SINGLE_FAMILIES)))
    src = thesis_source("test_gearbox.double_helical", "Sec. 5.9, thesis lines 2157-2185")
    out = []
    for r in rows:
        ref = hvs.SINGLE_HELICAL[r["single_helical"]][2]
        scene = "study double-helical vs " + ", ".join(f for f in VS_SINGLE_FAMILIES[1:])
        for what, (text, unit) in VS_SINGLE_WHAT.items():
            mean = what == "mean"
            why = (f"s.d. over speed: ours {r['sd_diff_dB']} dB, {r['speeds_in_mean']} common speeds"
                   if mean else f"max L_WA ours: double helical {r['LwA_max_double_dBA']} dB(A) at "
                                f"{r['at_rpm_double']:g} rpm, single {r['LwA_max_single_dBA']} dB(A) at "
                                f"{r['at_rpm_single']:g} rpm" + ("" if r["single_helical"] == "A" else
                                                                 "; measured: the difference of the measured maxima"))
            row = check_row(f"{VS_SINGLE}{r['double_helical']}.{r['single_helical']}.{what}.{r['route']}", scene,
                            f"{r['route']}: double helical {r['double_helical']} - {ref}: {text}",
                            r["mean_diff_dB"] if mean else r["max_reduction_dBA"], unit, src,
                            measured=r["measured_mean_dB"] if mean else r["measured_max_reduction_dBA"], why=why)
            row["note"] = f"reported, not judged (the issue's checks do not name this comparison): {why}"
            out.append(row)
    return out


# the double helical set's speed law and smoothness (Sec. 5.9, Fig. 5.19, thesis lines 2157-2167): the curves at
# 2000 N m, and set A's (ball, 2000 N m: the profile corrections' reference, the same scene and settings as the
# default run-up whose slope is the check 28.speed_law.<route>) for the smoothness's order
DH_SPEED_LAW_VARIANTS = (("cylindrical_roller", "cylindrical_roller@2000"), ("fluid_film", "fluid_film@2000"))
SPEED_LAW_MEASURED = 6.0          # dB(A) per doubling, "seen clearly" in Fig. 5.19
SPEED_LAW_TOLERANCE = 2.0         # the set-A check's tolerance (28.speed_law.<route>): stated here, not judged


def double_helical_speed_law_rows(folder: Path) -> list[dict]:
    """The double helical set's speed law and smoothness over speed at 2000 N m, per route, from the run-up tables
    of the study's default-engagement jobs in folder (<results>/study-validate/<family>-face-width/
    <family>_runup.csv: double-helical, and profile-corrections for set A), no further computation
    (helical_vs_single.speed_law, over 250-1500 rev/min):

    * 28.variants.double_helical_speed_law.<cylindrical_roller|fluid_film>.<route> — the L_WA slope, dB(A) per
      doubling (least squares against log2 of the speed), beside the measured 6 ("seen clearly", Fig. 5.19);
      `why` states whether |ours - 6| <= 2 (the set-A check's tolerance, not judged here);
    * 28.variants.double_helical_smoothness.<cylindrical_roller|fluid_film|set_A>.<route> — the population s.d.
      of L_WA about its own speed-law line (dB); measured: the double helical curves "very smooth", set A's with
      "large sound power level fluctuations" (Fig. 5.19 is not digitised: only the order is compared, in `why`).

    Reported, never judged, no band (checks.DH_SPEED_LAW, DH_SMOOTHNESS).  InputError naming the file when a
    needed run is missing."""
    from housingfe.errors import InputError
    from housingfe.studies import helical_vs_single as hvs
    from housingfe.verification.checks import DH_SMOOTHNESS, DH_SPEED_LAW, check_row
    from housingfe.verification.published import thesis_source

    tables = hvs.tables_of(default_engagement_folders(folder, ("double-helical", "profile-corrections")))
    dh_table, dh_path = tables["double-helical"]
    laws = {name: {route: hvs.speed_law(s, lv) for route, (s, lv) in hvs.curves(dh_table, key, dh_path).items()}
            for name, key in DH_SPEED_LAW_VARIANTS}
    a_table, a_path = tables["profile-corrections"]
    set_a = hvs.curves(a_table, "A", a_path)
    routes = list(laws[DH_SPEED_LAW_VARIANTS[0][0]])
    for route in routes:
        if route not in set_a:
            raise InputError(f"{a_path}: no column LwA_{route}_A_dBA (route {route} of set A is missing)")
    laws["set_A"] = {route: hvs.speed_law(*set_a[route]) for route in routes}
    src = thesis_source("test_gearbox.double_helical", "Sec. 5.9, Fig. 5.19, thesis lines 2157-2167")
    scene = "study double-helical (2000 N m), set A from profile-corrections"
    what = {"cylindrical_roller": "double helical, cylindrical rollers", "fluid_film": "double helical, fluid films",
            "set_A": "single helical set A, ball bearings"}

    def reported(check_id, quantity, ours, unit, measured, why):
        r = check_row(check_id, scene, quantity, ours, unit, src, measured=measured, why=why)
        r["note"] = f"reported, not judged (the issue's checks do not name this): {why}"
        return r

    out = []
    for route in routes:
        for name, _ in DH_SPEED_LAW_VARIANTS:
            law = laws[name][route]
            miss = abs(law["slope_dB"] - SPEED_LAW_MEASURED)
            inside = "within" if miss <= SPEED_LAW_TOLERANCE else "outside"
            why = (f"|ours - {SPEED_LAW_MEASURED:g}| = {miss:.2f} dB(A), {inside} "
                   f"{SPEED_LAW_TOLERANCE:g} (the set-A check's tolerance, 28.speed_law.{route}; stated, not judged); "
                   f"least squares against log2(speed) over {law['from_rpm']:g}-{law['to_rpm']:g} rpm ({law['n']} "
                   "speeds); no slope terms: the study keeps the L_WA curves alone, not the run's decomposition "
                   f"(set A's terms: 28.speed_law.{route}); set A here {laws['set_A'][route]['slope_dB']:+.2f}")
            out.append(reported(f"{DH_SPEED_LAW}{name}.{route}",
                                f"{route}: {what[name]}, 2000 N m: L_WA slope 250-1500 rpm, per doubling of speed",
                                round(law["slope_dB"], 2), "dB(A) per doubling", SPEED_LAW_MEASURED, why))
        sd = {name: laws[name][route]["residual_sd_dB"] for name in laws}
        ordered = all(sd[name] < sd["set_A"] for name, _ in DH_SPEED_LAW_VARIANTS)
        why = ("measured (Fig. 5.19, not digitised: only the order is compared): the double helical curves very "
               "smooth, set A's with large fluctuations, i.e. smaller residual s.d. for the double helical sets; ours "
               + ", ".join(f"{n} {sd[n]:.2f}" for n in laws) + f" dB: ordered as measured: {_yes(ordered)}")
        for name in laws:
            out.append(reported(f"{DH_SMOOTHNESS}{name}.{route}",
                                f"{route}: {what[name]}, 2000 N m: s.d. of L_WA about its speed-law line, "
                                "250-1500 rpm", round(sd[name], 2), "dB", None, why))
    return out
