"""`housingfe study <family>`: design variants of the Ch. 5 test gearbox as run-ups through the chain (issue 28).

A family is a set of drivetrain variants measured by van Roosmalen (1994), each a run-up of a built-in run-up scene
with the gear set, bearing configuration and torque of the variant; every variant of the same layout re-uses the
family's modal basis (housingfe.studies.chain_session: one basis per layout, the others Rayleigh-Ritz
re-analyses).

* `profile-corrections` (Sec. 5.7): gear sets A (reference), B, C, D and uncorrected, ball bearings, 2000 N m;
* `bearings` (Sec. 5.8): gear set B with ball (reference), angular contact, self-aligning and tapered roller
  bearings, 2000 N m;
* `double-helical` (Sec. 5.9): the double helical set with cylindrical roller (reference at 2000 N m) and
  fluid-film bearings at 500, 1000, 1500 and 2000 N m, with the measured torque law (1000 -> 2000 N m, Fig. 5.21).
* run together with `profile-corrections` and/or `bearings` (`housingfe study double-helical profile-corrections
  bearings`), the double helical set against single helical set A (ball) and set B on self-aligning bearings, all
  2000 N m, as measured in Sec. 5.9 (housingfe.studies.helical_vs_single): <out>/double-helical_vs_single.csv / .md;
* a family file of the user's own (`housingfe study my_family.toml`, housingfe.studies.family_file): any variants
  of a run-up scene, with the user's measured numbers beside ours (also measured torque laws, [[torque_laws]]).

Per variant and route (housingfe.runup.chain.ROUTES) on the scene's first radiation model (sigma = 1 for the
built-in scenes): the mean and standard deviation over 800-1500 rev/min of L_WA(variant) - L_WA(reference), speed
by speed (the thesis' measure), and the largest L_WA over the run-up with its speed; beside them the measured
values and the thesis' calculated ones (housingfe/data/roosmalen1994.toml), and the ranking of the variants
(quietest first) ours against measured.  Of every group of variants that share gear set and bearings and differ
only in torque (`torque_groups`, two or more torques) the torque law (`torque_law`): the slope of the 800-1500
rev/min energy mean per doubling of torque and the step between two torques, beside a measured torque law of the
family (MeasuredTorqueLaw) where there is one; also in <family>_torque_law.csv.  The run-up scene's options pass
through `--set` as for `housingfe run` (e.g. `--set runup.engagement=thesis-2d`, the thesis' two-dimensional
engagement shock); the keys a family sets itself (gear set, bearings, torques) are refused.

With `--set runup.as_made=<ISO 1328-1 grade>` every variant's run-up also computes the expected sidebands of
tooth-to-tooth deviations of gears of that grade on the same model and source (housingfe.runup.as_made, as
`housingfe run` does), and the same comparison (differences, maxima, rankings, torque law) on that L_WA is written
BESIDE the periodic one, labelled "as made, ISO grade g": extra columns *_as_made_* in <family>.csv and
<family>_runup.csv, sections after the periodic ones in <family>.md, "as_made" in study.json, lines in the summary.
The periodic tables stay as with the option off ("none", the default: nothing changes).

With `--set drivetrain.floating_axial_ratio=X` (X != 0) every variant's floating bearings are asked to hold
X |F_r| axially, and where a directional locating bearing would lift off the ring slides and holds less
(housingfe.drivetrain.description.Drivetrain.floating_axial_held): per variant the requested and the held load of
each shaft's floating bearing and which rings slid are written as the last columns of <family>.csv
(FLOATING_COLUMNS), a section of <family>.md and lines of the summary; at X = 0 none of them (files as before).

Writes <family>.csv, <family>.md, <family>.png, <family>_runup.csv (L_WA over speed per variant and route),
<family>_torque_law.csv and <family>_torque_law.png (where there is a torque law; plot_torque_law), variant_terms.csv
(per route and variant the mean difference of each term of L_WA: excitation, T_path, T_housing, L_sigma,
A-weighting; housingfe.studies.variant_terms; also a table in <family>.md and the summary) and study.json (everything, with per-variant timings and how each model's basis was obtained) to the result folder
(default results/study-<family>-<engagement>); several families in one command share the housing model and the
bases that fit (profile-corrections and bearings are one layout) and go to <out>/<family>/.
"""
from __future__ import annotations

import argparse
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from housingfe.errors import InputError
from housingfe.studies import helical_vs_single, variant_terms
from housingfe.studies.chain_session import (
    MEAN_RANGE_RPM,
    ChainSession,
    difference_stats,
    energy_mean_db,
    lwa_curve,
    maximum,
)


@dataclass(frozen=True)
class Variant:
    """One design variant: key (its name in the tables), gear set, bearing configuration, pinion torque (N m),
    and the published numbers beside it: measured mean and s.d. of the difference to the family's reference
    (dB, 800-1500 rev/min), measured maximum L_WA (dB(A)), the thesis' calculated mean, s.d. and maximum."""

    key: str
    gear_set: str
    bearings: str
    torque: float
    measured_mean: float | None = None
    measured_sd: float | None = None
    measured_max: float | None = None
    calc_mean: float | None = None
    calc_sd: float | None = None
    calc_max: float | None = None


@dataclass(frozen=True)
class MeasuredTorqueLaw:
    """A measured torque law of the variants of one gear set and bearing configuration: the step of L_WA from
    from_nm to to_nm (pinion torques, N m; measured_step dB(A), the mean over 800-1500 rev/min as the thesis states
    it) and/or the slope (measured_slope, dB(A) per doubling of torque).  Our step of that group is taken between
    the same two torques."""

    gear_set: str
    bearings: str
    from_nm: float
    to_nm: float
    measured_step: float | None = None
    measured_slope: float | None = None


@dataclass(frozen=True)
class Family:
    """A family of variants on a run-up scene; `reference` is the key of the variant the differences are taken to;
    `source` names where in the thesis the published numbers are; `notes` what the comparison rests on."""

    name: str
    scene: str
    title: str
    variants: tuple
    reference: str
    source: str
    notes: tuple = ()
    controlled: tuple = ("drivetrain.gear_set", "drivetrain.bearings", "runup.torques_nm")
    overrides: tuple = ()        # a family file's own `set` entries, applied to the scene before any --set
    path: Path | None = None     # the family file (None: built in)
    torque_laws: tuple = ()      # MeasuredTorqueLaw per (gear set, bearings) group that has one
    torque_law_source: str = ""  # where the measured torque laws come from (heads the torque-law table)

    def variant(self, key: str) -> Variant:
        return next(v for v in self.variants if v.key == key)


def families() -> dict[str, Family]:
    """The families (registry: name -> Family), their published numbers read from housingfe/data/roosmalen1994.toml."""
    from housingfe.data import thesis
    from housingfe.verification.published import thesis_source

    tg = thesis()["test_gearbox"]
    pc, br, dh = tg["profile_corrections"], tg["bearings"], tg["double_helical"]
    corrections = [Variant("A", "A", "ball", 2000.0, measured_max=pc["meas_Lw_max_dBA"]["A"],
                           calc_max=tg["calc_Lw_max_dBA"])]
    corrections += [Variant(s, s, "ball", 2000.0, pc["meas_mean_dB"][s], pc["meas_sd_dB"][s], pc["meas_Lw_max_dBA"][s],
                            pc["calc_mean_dB"][s], pc["calc_sd_dB"][s]) for s in ("B", "C", "D")]
    corrections.append(Variant("uncorrected", "uncorrected", "ball", 2000.0, calc_mean=pc["calc_uncorrected_vs_A_dB"]))
    bearings = [Variant("ball", "B", "ball", 2000.0, measured_max=br["meas_Lw_max_dBA"]["ball"])]
    bearings += [Variant(b, "B", b, 2000.0, br["meas_mean_dB"][b], br["meas_sd_dB"][b], br["meas_Lw_max_dBA"][b])
                 for b in ("angular_contact", "self_aligning", "tapered_roller")]
    helical = []
    for b, key in (("cylindrical_roller", "roller"), ("fluid_film", "fluid_film")):
        for torque in DOUBLE_HELICAL_TORQUES_NM:
            top = torque == max(DOUBLE_HELICAL_TORQUES_NM)
            measured_mean = dh["fluid_film_vs_roller_mean_dB"] if top and b == "fluid_film" else None
            measured_sd = dh["fluid_film_vs_roller_sd_dB"] if top and b == "fluid_film" else None
            helical.append(Variant(f"{b}@{torque:g}", "double_helical", b, torque, measured_mean, measured_sd,
                                   dh["meas_Lw_max_dBA"][key] if top else None))
    return {
        "profile-corrections": Family(
            "profile-corrections", "test-gearbox-runup",
            "profile corrections: gear sets A-D and uncorrected, ball bearings, 2000 N m", tuple(corrections), "A",
            thesis_source("test_gearbox.profile_corrections", "Fig. 5.15, thesis lines 2062-2079"),
            ("measured: Fig. 5.15, mean differences of L_W over 800-1500 rev/min to set A; the uncorrected set was "
             "not measured, its +3.5 dB is the thesis' calculation",
             "thesis calculated: L_omega at the tooth frequency of each set with the same TF_omega and sigma "
             "(its Sec. 5.7: 'the vibration transmission ... is not influenced by changing the tooth profile "
             "correction'); its maximum 89.4 dB(A) is set A's (Fig. 5.10)")),
        "bearings": Family(
            "bearings", "test-gearbox-runup",
            "bearings on gear set B: ball, angular contact, self-aligning, tapered roller, 2000 N m", tuple(bearings),
            "ball", thesis_source("test_gearbox.bearings", "Figs. 5.16, 5.17, thesis lines 2109-2130"),
            ("measured: Figs. 5.16/5.17, mean differences of L_W over 800-1500 rev/min to ball bearings",
             "thesis calculated: no run-up; its FE gave TF_omega ball - self-aligning +7.3 dB (s.d. 4.5) over "
             "320-600 Hz with the ball bearings' moment terms zeroed (Fig. 5.18; `housingfe bearing-variants`)",
             "the source is the scene's (runup.source_receptance = \"coupled\": the coupled model's receptance at "
             "the mesh), so each configuration's FE bearings act on its source as well as on its transfer")),
        "double-helical": Family(
            "double-helical", "test-gearbox-runup-double-helical",
            "double helical set: cylindrical roller vs fluid-film bearings, 500-2000 N m", tuple(helical),
            f"cylindrical_roller@{max(DOUBLE_HELICAL_TORQUES_NM):g}",
            thesis_source("test_gearbox.double_helical", "Figs. 5.19, 5.21, thesis lines 2157-2183"),
            ("measured: Fig. 5.19 (2000 N m, fluid film - roller -1.9 dB mean, s.d. 3.0, over 800-1500 rev/min; "
             "maxima 91.0 / 87.7 dB(A)) and Fig. 5.21 (torque law: 1000 -> 2000 N m +3.4 / +2.7 dB(A))",
             "thesis calculated: none (its TF_omega differences of Fig. 5.20 were 'not satisfactory at all')",
             "fluid films at each run-up speed (runup.bearing_speeds = \"follow\", the default; \"fixed\": at "
             "drivetrain.bearing_speed_rpm for the whole run-up; below the film's speed limit the nearest carried "
             "speed; docs/runup.md)"),
            torque_laws=tuple(MeasuredTorqueLaw("double_helical", b, *TORQUE_LAW_NM,
                                                measured_step=dh["torque_doubling_1000_to_2000Nm_dBA"][key])
                              for b, key in TORQUE_LAW_MEASURED.items()),
            torque_law_source="Sec. 5.9, Fig. 5.21"),
    }


DOUBLE_HELICAL_TORQUES_NM = (500.0, 1000.0, 1500.0, 2000.0)
PERIODIC, AS_MADE = "periodic", "as_made"         # which L_WA is compared (VariantRun.curves_of)
TORQUE_LAW_NM = (1000.0, 2000.0)                 # the measured torque step (Sec. 5.9)
TORQUE_LAW_MEASURED = {"cylindrical_roller": "roller", "fluid_film": "fluid_film"}


# ------------------------------------------------------------------------------------------------ running
@dataclass
class VariantRun:
    """A variant's run-up: per route the speeds (rev/min) and L_WA (dB(A)) of the total; how its basis was
    obtained ("built" / "re-analysed"); wall times (s): the coupled model, the run-up (source lines + routes); with
    runup.as_made on, per route (speeds, L_WA dB(A)) with the expected sidebands of gears as made and the seconds
    they took (housingfe.runup.as_made); per route the per-speed term levels of the periodic L_WA on the total
    basis (speeds, {term: dB}; housingfe.studies.variant_terms.term_curves, None for a route without an excitation
    level; empty when not kept); with drivetrain.floating_axial_ratio != 0 (floating_ratio) what each shaft's
    floating bearing held (housingfe.drivetrain.description.Drivetrain.floating_axial_report; empty at 0)."""

    variant: Variant
    curves: dict
    basis: str
    model_s: float
    runup_s: float
    curves_as_made: dict = field(default_factory=dict)
    as_made_s: float = 0.0
    terms: dict = field(default_factory=dict)
    floating_ratio: float = 0.0
    floating: dict = field(default_factory=dict)

    def curves_of(self, kind: str) -> dict:
        """The curves per route of the periodic model (PERIODIC) or of gears as made (AS_MADE)."""
        return self.curves if kind == PERIODIC else self.curves_as_made


@dataclass
class StudyResult:
    """A family's runs and what is compared (rows per route and variant, rankings, torque law), with timings; with
    runup.as_made = <ISO grade> (as_made_grade) the same comparison on the L_WA of gears as made in `as_made`
    ({"rows", "rankings", "torque_law"}, the rows with the periodic rows' keys)."""

    family: Family
    engagement: str
    radiation: str
    routes: tuple
    runs: dict
    rows: list = field(default_factory=list)
    rankings: list = field(default_factory=list)
    torque_law: list = field(default_factory=list)
    timings: dict = field(default_factory=dict)
    basis_builds: int = 0
    as_made_grade: object = "none"
    as_made: dict = field(default_factory=dict)
    as_made_pitch: str = "independent"
    terms: list = field(default_factory=list)     # housingfe.studies.variant_terms.variant_terms (periodic)

    @property
    def as_made_label(self) -> str:
        """How the as-made comparison is labelled in every output: "as made, ISO grade g", with ", pitch <model>"
        when the pitch deviations are not the default independent ones (runup.as_made_pitch)."""
        pitch = "" if self.as_made_pitch == "independent" else f", pitch {self.as_made_pitch}"
        return f"as made, ISO grade {self.as_made_grade}{pitch}"

    @property
    def as_made_assumptions(self) -> tuple:
        """AS_MADE_ASSUMPTIONS with the pitch model's own line (runup.as_made_pitch)."""
        return AS_MADE_ASSUMPTIONS[:1] + (AS_MADE_PITCH[self.as_made_pitch],) + AS_MADE_ASSUMPTIONS[2:]


def check_overrides(family: Family, overrides) -> None:
    """InputError for a --set of a key the family sets itself."""
    for item in overrides:
        key = item.split("=", 1)[0].strip()
        for controlled in family.controlled:
            if key == controlled or key.startswith(controlled + "."):
                raise InputError(f"--set {key}: the study {family.name} sets it per variant (its variants: "
                                 f"{', '.join(v.key for v in family.variants)})")


def family_of(name: str) -> Family:
    """A built-in family by name, or a family file (a .toml path: housingfe.studies.family_file)."""
    known = families()
    if name not in known and (name.endswith(".toml") or Path(name).is_file()):
        from housingfe.studies.family_file import read_family_file

        fields = read_family_file(name, Family.controlled)
        return Family(**{**fields, "variants": tuple(Variant(**v) for v in fields["variants"]),
                         "torque_laws": tuple(MeasuredTorqueLaw(**t) for t in fields["torque_laws"])})
    if name not in known:
        raise InputError(f"study: family {name!r}: unknown (known: {', '.join(known)}) and not a "
                         "family file (give a FILE.toml: docs/design-variants.md, 'Your own family')")
    return known[name]


def run_family(family: Family, session: ChainSession, progress=print) -> StudyResult:
    """Run every variant of `family` on `session` (reference first, so that the basis is the reference's) and
    compare; progress(str) is told about each variant."""
    t_start = time.perf_counter()
    order = [family.variant(family.reference)] + [v for v in family.variants if v.key != family.reference]
    drivetrains = {v.key: session.drivetrain(v.gear_set, v.bearings, v.torque) for v in order}   # bad input first
    routes = tuple(session.spec.routes)
    rad = session.radiation
    runs = {}
    for v in order:
        t0 = time.perf_counter()
        model = session.model(drivetrains[v.key], v.key)
        t1 = time.perf_counter()
        res = session.runup(model, v.torque)
        t2 = time.perf_counter()
        how = session.log[-1].how
        runs[v.key] = VariantRun(v, {r: lwa_curve(res, r, rad, v.torque) for r in routes}, how, t1 - t0, t2 - t1,
                                 terms={r: variant_terms.term_curves(res, r, rad, v.torque) for r in routes},
                                 **floating_of(drivetrains[v.key]))
        made = session.runup_as_made(model, v.torque, res)      # None with runup.as_made = "none"
        if made is not None:
            from housingfe.runup.as_made import lwa_curve as as_made_curve

            runs[v.key].curves_as_made = {r: as_made_curve(made, r, rad, v.torque) for r in routes}
            runs[v.key].as_made_s = made.seconds
        progress(f"{family.name}: {v.key:22s} basis {how:11s} model {t1 - t0:5.1f} s, "
                 f"run-up {t2 - t1:5.1f} s" + (f", as made {made.seconds:5.1f} s" if made is not None else ""))
    out = analyse(StudyResult(family, session.spec.engagement, rad, routes,
                              {v.key: runs[v.key] for v in family.variants}, as_made_grade=session.spec.as_made,
                              as_made_pitch=session.spec.as_made_pitch))
    out.basis_builds = session.basis_builds
    out.timings = {**session.timings, "variants_s": time.perf_counter() - t_start,
                   "per_variant": {k: {"basis": r.basis, "model_s": r.model_s, "runup_s": r.runup_s}
                                   | ({"as_made_s": r.as_made_s} if r.curves_as_made else {})
                                   for k, r in runs.items()}}
    return out


def floating_of(drivetrain) -> dict:
    """A variant's drivetrain.floating_axial_ratio and what each floating bearing held at its torque (VariantRun's
    floating_ratio, floating: Drivetrain.floating_axial_report, the loads its model was built with)."""
    return {"floating_ratio": drivetrain.floating_axial_ratio, "floating": drivetrain.floating_axial_report()}


def analyse(result: StudyResult) -> StudyResult:
    """Fill a StudyResult's comparison from its runs: rows, rankings, torque law (of every gear set and bearing
    configuration run at two or more torques), and with as_made_grade != "none" the same on the L_WA of gears as
    made (`compare_as_made`)."""
    result.rows = compare(result)
    result.rankings = rankings(result)
    result.torque_law = torque_law(result)
    if result.runs and all(run.terms for run in result.runs.values()):
        result.terms = variant_terms.variant_terms(result)
    if result.as_made_grade != "none":
        result.as_made = compare_as_made(result)
    return result


def compare_as_made(result: StudyResult) -> dict:
    """The comparison of `compare`, `rankings` and `torque_law` on the L_WA of gears as made (runs' curves_as_made):
    {"rows", "rankings", "torque_law"}."""
    rows = compare(result, AS_MADE)
    return {"rows": rows, "rankings": rankings(result, rows), "torque_law": torque_law(result, AS_MADE)}


def compare(result: StudyResult, kind: str = "periodic") -> list[dict]:
    """One row per route and variant: ours beside measured and the thesis' calculation; kind PERIODIC (the run-up's
    L_WA) or AS_MADE (with the expected sidebands of gears as made)."""
    fam = result.family
    ref = result.runs[fam.reference]
    rows = []
    for route in result.routes:
        s_ref, l_ref = ref.curves_of(kind)[route]
        for key, run in result.runs.items():
            v = run.variant
            s, lwa = run.curves_of(kind)[route]
            mean, sd, n = difference_stats(s, lwa, l_ref)
            top, at = maximum(s, lwa)
            rows.append({"family": fam.name, "engagement": result.engagement, "route": route,
                         "radiation": result.radiation, "variant": key, "gear_set": v.gear_set,
                         "bearings": v.bearings, "torque_nm": v.torque,
                         "mean_diff_dB": round(mean, 2), "sd_diff_dB": round(sd, 2), "speeds_in_mean": n,
                         "measured_mean_dB": v.measured_mean, "measured_sd_dB": v.measured_sd,
                         "thesis_calc_mean_dB": v.calc_mean, "thesis_calc_sd_dB": v.calc_sd,
                         "LwA_max_dBA": round(top, 1), "at_rpm": at, "measured_max_dBA": v.measured_max,
                         "thesis_calc_max_dBA": v.calc_max,
                         "LwA_energy_mean_800_1500_dBA": round(energy_mean_db(s, lwa), 1),
                         "basis": run.basis, "model_s": round(run.model_s, 2), "runup_s": round(run.runup_s, 2)}
                        | floating_cells(run))
    return rows


def floating_cells(run: VariantRun) -> dict:
    """FLOATING_COLUMNS of a variant's rows (nothing where its floating bearings hold no axial load: ratio 0)."""
    if not run.floating:
        return {}
    return {"floating_axial_ratio": run.floating_ratio} | floating_report_cells(run.floating)


def floating_report_cells(report: dict) -> dict:
    """A Drivetrain.floating_axial_report as result-file cells: per shaft <shaft>_floating_requested_N and
    <shaft>_floating_held_N (N, 0.1 N), and floating_rings_slid (the shafts whose ring slid, or "none")."""
    from housingfe.drivetrain.description import slid_rings

    cells = {}
    for shaft, r in report.items():
        cells[f"{shaft}_floating_requested_N"] = round(r["requested_N"], 1)
        cells[f"{shaft}_floating_held_N"] = round(r["held_N"], 1)
    return cells | {"floating_rings_slid": " ".join(slid_rings(report)) or "none"}


def _order(values: dict) -> list[str]:
    return [k for k, _ in sorted(values.items(), key=lambda kv: kv[1])]


def rankings(result: StudyResult, rows: list | None = None) -> list[dict]:
    """Per route and measure (mean difference, maximum): the variants that were measured, quietest first, ours
    against measured; `matches` when the orders are equal, `quietest`/`loudest` when those agree.  rows: the
    comparison's rows (default result.rows; the as-made rows for gears as made)."""
    rows_all = result.rows if rows is None else rows
    fam = result.family
    measured_mean = {v.key: (0.0 if v.key == fam.reference else v.measured_mean) for v in fam.variants
                     if v.key == fam.reference or v.measured_mean is not None}
    measured_max = {v.key: v.measured_max for v in fam.variants if v.measured_max is not None}
    out = []
    for route in result.routes:
        rows = {r["variant"]: r for r in rows_all if r["route"] == route}
        for measure, measured, column in (("mean difference 800-1500 rpm", measured_mean, "mean_diff_dB"),
                                          ("maximum L_WA", measured_max, "LwA_max_dBA")):
            if len(measured) < 2:
                continue
            ours = _order({k: rows[k][column] for k in measured})
            theirs = _order(measured)
            out.append({"route": route, "measure": measure, "ours": " < ".join(ours), "measured": " < ".join(theirs),
                        "matches": ours == theirs, "quietest": ours[0] == theirs[0],
                        "loudest": ours[-1] == theirs[-1]})
    return out


def torque_groups(result: StudyResult) -> list[tuple[str, str, dict]]:
    """The variants that differ only in torque: per (gear set, bearing configuration), in the order the family
    first names them, {torque N m: VariantRun}, for the groups run at two or more torques (of two variants at one
    torque, the first)."""
    groups: dict = {}
    for run in result.runs.values():
        v = run.variant
        groups.setdefault((v.gear_set, v.bearings), {}).setdefault(v.torque, run)
    return [(g, b, runs) for (g, b), runs in groups.items() if len(runs) >= 2]


def _energy_means(runs: dict, torques: list, route: str, kind: str) -> list[float]:
    """The energy mean of L_WA over 800-1500 rev/min (dB(A)) of a torque group's run at each torque (N m)."""
    return [energy_mean_db(*runs[t].curves_of(kind)[route]) for t in torques]


def torque_law(result: StudyResult, kind: str = "periodic") -> list[dict]:
    """The torque law of every group of variants that differ only in torque (`torque_groups`), per group and route:

    * the slope of the energy mean of L_WA over 800-1500 rev/min against log2 of the torque, least squares over
      every torque of the group (dB(A) per doubling; of two torques the energy means' step / log2(T2 / T1));
    * the step L_WA(to_nm) - L_WA(from_nm) speed by speed over 800-1500 rev/min (mean, s.d.) and at 1500 rev/min,
      between the torques of the family's measured torque law of that group (MeasuredTorqueLaw; the double helical
      family: 1000 -> 2000 N m, Fig. 5.21), else between the group's lowest and highest torque;
    * beside them the measured step and slope (None where not measured).

    kind PERIODIC or AS_MADE (the L_WA of gears as made).  Keys: bearings, route, step_mean_dB, step_sd_dB,
    step_at_1500rpm_dB, slope_dB_per_doubling, torques_nm, energy_means_dBA, measured_step_dBA, gear_set, from_nm,
    to_nm, measured_slope_dBA_per_doubling."""
    measured = {(t.gear_set, t.bearings): t for t in result.family.torque_laws}
    out = []
    for gear_set, bearings, runs in torque_groups(result):
        law = measured.get((gear_set, bearings))
        torques = sorted(runs)
        lo, hi = (law.from_nm, law.to_nm) if law is not None else (torques[0], torques[-1])
        if lo not in runs or hi not in runs:
            raise ValueError(f"study {result.family.name}: torque law {gear_set}/{bearings} {lo:g} -> {hi:g} N m: "
                             f"no run at that torque (run: {', '.join(f'{t:g}' for t in torques)} N m)")
        for route in result.routes:
            s, high = runs[hi].curves_of(kind)[route]
            _, low = runs[lo].curves_of(kind)[route]
            mean, sd, _ = difference_stats(s, high, low)
            at = float(high[np.argmin(np.abs(s - 1500.0))] - low[np.argmin(np.abs(s - 1500.0))])
            means = _energy_means(runs, torques, route, kind)
            slope = float(np.polyfit(np.log2(torques), means, 1)[0])
            out.append({"bearings": bearings, "route": route, "step_mean_dB": round(mean, 2),
                        "step_sd_dB": round(sd, 2), "step_at_1500rpm_dB": round(at, 2),
                        "slope_dB_per_doubling": round(slope, 2),
                        "torques_nm": " ".join(f"{t:g}" for t in torques),
                        "energy_means_dBA": " ".join(f"{m:.1f}" for m in means),
                        "measured_step_dBA": None if law is None else law.measured_step,
                        "gear_set": gear_set, "from_nm": lo, "to_nm": hi,
                        "measured_slope_dBA_per_doubling": None if law is None else law.measured_slope})
    return out


# ------------------------------------------------------------------------------------------------ outputs
COLUMNS = ("family", "engagement", "route", "radiation", "variant", "gear_set", "bearings", "torque_nm",
           "mean_diff_dB", "sd_diff_dB", "speeds_in_mean", "measured_mean_dB", "measured_sd_dB", "thesis_calc_mean_dB",
           "thesis_calc_sd_dB", "LwA_max_dBA", "at_rpm", "measured_max_dBA", "thesis_calc_max_dBA",
           "LwA_energy_mean_800_1500_dBA", "basis", "model_s", "runup_s")
# with drivetrain.floating_axial_ratio != 0: per variant (and so per torque) the held axial load of each shaft's
# floating bearing, requested (ratio |F_r|) and held (less where the ring slid), N, and which rings slid -- after every
# other column of <family>.csv (absent at ratio 0: the default files stay as they were)
FLOATING_COLUMNS = ("floating_axial_ratio", "pinion_floating_requested_N", "pinion_floating_held_N",
                    "wheel_floating_requested_N", "wheel_floating_held_N", "floating_rings_slid")


# <family>_torque_law.csv: one row per torque-law group and route (torque_law), ours beside the measured; with
# runup.as_made on, TORQUE_LAW_AS_MADE_COLUMNS (as made) after them
TORQUE_LAW_COLUMNS = ("gear_set", "bearings", "route", "from_nm", "to_nm", "step_mean_dB", "step_sd_dB",
                      "step_at_1500rpm_dB", "measured_step_dBA", "slope_dB_per_doubling",
                      "measured_slope_dBA_per_doubling", "torques_nm", "energy_means_dBA")
TORQUE_LAW_AS_MADE_COLUMNS = {"as_made_iso_grade": None, "step_mean_as_made_dB": "step_mean_dB",
                              "step_sd_as_made_dB": "step_sd_dB", "step_at_1500rpm_as_made_dB": "step_at_1500rpm_dB",
                              "slope_as_made_dB_per_doubling": "slope_dB_per_doubling",
                              "energy_means_as_made_dBA": "energy_means_dBA"}


# with runup.as_made on: the as-made comparison as columns beside each row's periodic ones (<family>.csv)
AS_MADE_COLUMNS = {"as_made_iso_grade": None, "mean_diff_as_made_dB": "mean_diff_dB",
                   "sd_diff_as_made_dB": "sd_diff_dB", "LwA_max_as_made_dBA": "LwA_max_dBA",
                   "at_rpm_as_made": "at_rpm", "LwA_energy_mean_800_1500_as_made_dBA": "LwA_energy_mean_800_1500_dBA"}
AS_MADE_WHAT = ("the expected power of the shaft-order sideband lines that tooth-to-tooth deviations of gears of "
                "this ISO 1328-1 grade make (housingfe.runup.as_made, docs/runup.md \"Gears as made in the run-up\"), "
                "energy-added to the periodic lines, through both routes on the same models")
AS_MADE_ASSUMPTIONS = ("ISO 1328-1:1995 grade standing in for the thesis' DIN 3962 grade (DIN 5 ~ ISO 5)",
                       "deviations uniform within the grade's tolerances (pitch, profile slope and form, helix slope, "
                       "twist), both gears the same grade",
                       "the EXPECTED power over random teeth (not one drawn gear pair); first order on the "
                       "mean-stiffness system")
# the second assumption per pitch model (runup.as_made_pitch; housingfe.source.as_made.PITCH_MODELS)
AS_MADE_PITCH = {
    "independent": AS_MADE_ASSUMPTIONS[1],
    "runout": "pitch deviations one order-1 sinusoid per gear (runout), amplitude uniform in [0, F_p / 2], random "
              "phase; profile slope and form, helix slope, twist uniform within the grade's tolerances; both gears "
              "the same grade",
    "none": "no pitch deviations; profile slope and form, helix slope, twist uniform within the grade's tolerances; "
            "both gears the same grade"}


def _as_made_row(result: StudyResult, row: dict) -> dict:
    """The as-made row of the same route and variant as a periodic row."""
    return next(r for r in result.as_made["rows"] if r["route"] == row["route"] and r["variant"] == row["variant"])


def _pm(mean, sd) -> str:
    if mean is None:
        return "-"
    return f"{mean:+.1f}" + (f" ± {sd:.1f}" if sd is not None else "")


def _num(x, fmt="{:.1f}") -> str:
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else fmt.format(x)


def _group_key(t: dict) -> tuple:
    return t["gear_set"], t["bearings"], t["route"]


def _group_label(result: StudyResult, t: dict) -> str:
    """A torque-law group as the tables name it: its bearings, with its gear set where the family's torque laws
    span several gear sets."""
    return t["bearings"] if len({x["gear_set"] for x in result.torque_law}) == 1 else f"{t['gear_set']}, {t['bearings']}"


def _group_header(result: StudyResult) -> str:
    return "bearings" if len({x["gear_set"] for x in result.torque_law}) == 1 else "gear set, bearings"


def _torque_law_heading(result: StudyResult, label: str = "") -> str:
    src = result.family.torque_law_source
    return f"## Torque law{label}" + (f" ({src})" if src else "")


def _has_measured_slope(result: StudyResult) -> bool:
    return any(t.measured_slope is not None for t in result.family.torque_laws)


def _common_step(laws: list) -> tuple | None:
    """(from_nm, to_nm) when every group's step is between the same two torques, else None."""
    steps = {(t["from_nm"], t["to_nm"]) for t in laws}
    return next(iter(steps)) if len(steps) == 1 else None


def _step_header(laws: list, label: str = "") -> str:
    common = _common_step(laws)
    which = f"L_WA({common[1]:g}) − L_WA({common[0]:g} N m)" if common else "L_WA(to) − L_WA(from)"
    return f"{which}{label}, mean ± s.d. 800–1500 rpm"


def _step_cell(laws: list, t: dict) -> str:
    prefix = "" if _common_step(laws) else f"{t['from_nm']:g} → {t['to_nm']:g} N m: "
    return prefix + _pm(t["step_mean_dB"], t["step_sd_dB"])


def _torque_law_text(t: dict, periodic: str | None = None) -> str:
    """One torque-law line of the summary: the step, ours (with the periodic one and) the measured beside it, then
    the slope over the group's torques with the measured one."""
    beside = [periodic] if periodic else []
    if t["measured_step_dBA"] is not None:
        beside.append(f"measured {t['measured_step_dBA']:+.1f}")
    text = (f"{t['from_nm']:g} -> {t['to_nm']:g} N m {t['step_mean_dB']:+.1f} ± {t['step_sd_dB']:.1f} dB(A)"
            + (f" ({', '.join(beside)})" if beside else "")
            + f"; slope {t['slope_dB_per_doubling']:+.1f} dB(A) per doubling over {t['torques_nm']} N m")
    if t["measured_slope_dBA_per_doubling"] is not None:
        text += f" (measured {t['measured_slope_dBA_per_doubling']:+.1f})"
    return text


def markdown(result: StudyResult, wall_s: float | None = None) -> str:
    """The family's comparison table, rankings and (double helical) torque law as Markdown."""
    fam = result.family
    lo, hi = MEAN_RANGE_RPM
    lines = [f"# `housingfe study {fam.name}`: {fam.title}", "",
             f"Engagement shock `runup.engagement = \"{result.engagement}\"`; radiation `{result.radiation}`; "
             f"differences L_WA(variant) − L_WA({fam.reference}) speed by speed, mean ± s.d. over {lo:g}–{hi:g} "
             f"rev/min; maxima over the whole run-up. Published numbers: {fam.source}.", ""]
    for route in result.routes:
        lines += [f"## Route `{route}`", "",
                  "| variant | Δ mean ± s.d., ours, dB | measured | thesis calc. | max L_WA ours, dB(A) (rpm) "
                  "| measured | thesis calc. | basis |",
                  "|---|---|---|---|---|---|---|---|"]
        for r in (r for r in result.rows if r["route"] == route):
            ref = r["variant"] == fam.reference
            lines.append(f"| {r['variant']}{' (reference)' if ref else ''} | "
                         f"{'0' if ref else _pm(r['mean_diff_dB'], r['sd_diff_dB'])} | "
                         f"{'0' if ref else _pm(r['measured_mean_dB'], r['measured_sd_dB'])} | "
                         f"{'0' if ref and r['thesis_calc_mean_dB'] is None and fam.name == 'profile-corrections' else _pm(r['thesis_calc_mean_dB'], r['thesis_calc_sd_dB'])} | "
                         f"{r['LwA_max_dBA']:.1f} ({r['at_rpm']:g}) | {_num(r['measured_max_dBA'])} | "
                         f"{_num(r['thesis_calc_max_dBA'])} | {r['basis']} |")
        lines.append("")
    if result.rankings:
        lines += ["## Ranking (quietest first, the measured variants)", "",
                  "| route | by | ours | measured | same order | quietest | loudest |", "|---|---|---|---|---|---|---|"]
        for k in result.rankings:
            yn = {True: "yes", False: "no"}
            lines.append(f"| {k['route']} | {k['measure']} | {k['ours']} | {k['measured']} | {yn[k['matches']]} | "
                         f"{yn[k['quietest']]} | {yn[k['loudest']]} |")
        lines.append("")
    if result.torque_law:
        laws = result.torque_law
        slopes = _has_measured_slope(result)
        lines += [_torque_law_heading(result), "",
                  f"| {_group_header(result)} | route | {_step_header(laws)} | at 1500 rpm | measured "
                  "| slope over torques, dB(A) per doubling |" + (" measured slope |" if slopes else "")
                  + " energy means 800–1500 rpm, dB(A) |",
                  "|---|---|---|---|---|---|---|" + ("---|" if slopes else "")]
        for t in laws:
            lines.append(f"| {_group_label(result, t)} | {t['route']} | {_step_cell(laws, t)} | "
                         f"{t['step_at_1500rpm_dB']:+.1f} | {_num(t['measured_step_dBA'], '{:+.1f}')} | "
                         f"{_num(t['slope_dB_per_doubling'], '{:+.1f}')} | "
                         + (f"{_num(t['measured_slope_dBA_per_doubling'], '{:+.1f}')} | " if slopes else "")
                         + f"{t['energy_means_dBA']} (at {t['torques_nm']} N m) |")
        lines.append("")
    if result.terms:
        lines += variant_terms.markdown(result.terms)
    if result.as_made:
        lines += markdown_as_made(result)
    lines += markdown_floating(result)
    per = result.timings.get("per_variant", {})
    lines += ["## Cost", "",
              f"{result.basis_builds} modal basis computed for {len(result.runs)} variants; per variant (s): "
              + ", ".join(f"{k} {p['basis']} {p['model_s']:.1f} + run-up {p['runup_s']:.1f}"
                          + (f" + as made {p['as_made_s']:.1f}" if "as_made_s" in p else "") for k, p in per.items())
              + f"; housing mesh {result.timings.get('mesh_s', 0.0):.1f} s"
              + (f"; wall time {wall_s:.0f} s (this family; a command of one family: end to end)." if wall_s is not None else "."), "",
              "## Notes", ""] + [f"* {n}" for n in result.family.notes] + [""]
    return "\n".join(lines)


def _floating_runs(result: StudyResult) -> dict:
    return {k: run for k, run in result.runs.items() if run.floating}


def floating_slid_text(result: StudyResult) -> str:
    """The line naming the variants whose floating rings slid, and the others ("" at ratio 0)."""
    runs = _floating_runs(result)
    if not runs:
        return ""
    from housingfe.drivetrain.description import FLOATING_AXIAL_KEY, slid_rings

    ratios = sorted({run.floating_ratio for run in runs.values()})
    slid = [f"{k} ({', '.join(slid_rings(run.floating))})" for k, run in runs.items() if slid_rings(run.floating)]
    kept = [k for k, run in runs.items() if not slid_rings(run.floating)]
    return (f"floating rings ({FLOATING_AXIAL_KEY} = {', '.join(f'{r:g}' for r in ratios)}): slid: "
            f"{'; '.join(slid) or 'none'}; held as requested: {', '.join(kept) or 'none'}")


def markdown_floating(result: StudyResult) -> list[str]:
    """The Markdown section on the floating bearings' held axial load (none at drivetrain.floating_axial_ratio 0)."""
    runs = _floating_runs(result)
    if not runs:
        return []
    from housingfe.drivetrain.description import FLOATING_AXIAL_KEY, slid_rings

    lines = ["## Floating bearings' held axial load", "",
             f"`{FLOATING_AXIAL_KEY}`: each floating bearing is asked to hold ratio·|F_r|; where a directional "
             "locating bearing (angular contact, tapered roller) would lift off under that, the floating ring "
             "slides and holds the most the locating bearing carries (`Drivetrain.floating_axial_held`; N, > 0 "
             "away from the locating bearing; columns `*_floating_*` in the CSV).", "",
             floating_slid_text(result) + ".", "",
             "| variant | torque, N m | ratio | pinion requested → held, N | wheel requested → held, N | slid |",
             "|---|---|---|---|---|---|"]
    for k, run in runs.items():
        f = run.floating
        lines.append(f"| {k} | {run.variant.torque:g} | {run.floating_ratio:g} | "
                     + " | ".join(f"{f[s]['requested_N']:.0f} → {f[s]['held_N']:.0f}" for s in ("pinion", "wheel"))
                     + f" | {', '.join(slid_rings(f)) or 'no'} |")
    return lines + [""]


def markdown_as_made(result: StudyResult) -> list[str]:
    """The Markdown sections of gears as made (runup.as_made on): per route the differences and maxima as made
    beside the periodic ones and the measured, the rankings and (double helical) the torque law."""
    fam, label = result.family, result.as_made_label
    lo, hi = MEAN_RANGE_RPM
    made = result.as_made
    lines = [f"# Gears {label} (`runup.as_made = {result.as_made_grade}`)", "",
             f"The same comparison on L_WA with {AS_MADE_WHAT}. Assumptions: " + "; ".join(result.as_made_assumptions)
             + f". Differences to {fam.reference}, mean ± s.d. over {lo:g}–{hi:g} rev/min. The tables above are the "
               "periodic model's (identical teeth), unchanged.", ""]
    for route in result.routes:
        lines += [f"## Route `{route}`, {label}", "",
                  f"| variant | Δ mean ± s.d., {label}, dB | periodic | measured | max L_WA {label}, dB(A) (rpm) "
                  "| periodic | measured |",
                  "|---|---|---|---|---|---|---|"]
        for p in (r for r in result.rows if r["route"] == route):
            r = _as_made_row(result, p)
            ref = r["variant"] == fam.reference
            lines.append(f"| {r['variant']}{' (reference)' if ref else ''} | "
                         f"{'0' if ref else _pm(r['mean_diff_dB'], r['sd_diff_dB'])} | "
                         f"{'0' if ref else _pm(p['mean_diff_dB'], p['sd_diff_dB'])} | "
                         f"{'0' if ref else _pm(r['measured_mean_dB'], r['measured_sd_dB'])} | "
                         f"{r['LwA_max_dBA']:.1f} ({r['at_rpm']:g}) | {p['LwA_max_dBA']:.1f} ({p['at_rpm']:g}) | "
                         f"{_num(r['measured_max_dBA'])} |")
        lines.append("")
    if made["rankings"]:
        yn = {True: "yes", False: "no"}
        lines += [f"## Ranking, {label} (quietest first, the measured variants)", "",
                  "| route | by | ours | measured | same order | quietest | loudest |", "|---|---|---|---|---|---|---|"]
        for k in made["rankings"]:
            lines.append(f"| {k['route']} | {k['measure']} | {k['ours']} | {k['measured']} | {yn[k['matches']]} | "
                         f"{yn[k['quietest']]} | {yn[k['loudest']]} |")
        lines.append("")
    if made["torque_law"]:
        laws = made["torque_law"]
        periodic = {_group_key(t): t for t in result.torque_law}
        slopes = _has_measured_slope(result)
        lines += [_torque_law_heading(result, f", {label}"), "",
                  f"| {_group_header(result)} | route | {_step_header(laws, f', {label}')} | periodic "
                  "| measured | at 1500 rpm | slope over torques, dB(A) per doubling |"
                  + (" periodic slope | measured slope |" if slopes else "") + " energy means 800–1500 rpm, dB(A) |",
                  "|---|---|---|---|---|---|---|---|" + ("---|---|" if slopes else "")]
        for t in laws:
            p = periodic.get(_group_key(t))
            lines.append(f"| {_group_label(result, t)} | {t['route']} | {_step_cell(laws, t)} | "
                         f"{_pm(p['step_mean_dB'], p['step_sd_dB']) if p else '-'} | "
                         f"{_num(t['measured_step_dBA'], '{:+.1f}')} | {t['step_at_1500rpm_dB']:+.1f} | "
                         f"{_num(t['slope_dB_per_doubling'], '{:+.1f}')} | "
                         + (f"{_num(p['slope_dB_per_doubling'] if p else None, '{:+.1f}')} | "
                            f"{_num(t['measured_slope_dBA_per_doubling'], '{:+.1f}')} | " if slopes else "")
                         + f"{t['energy_means_dBA']} (at {t['torques_nm']} N m) |")
        lines.append("")
    return lines


def write(folder: Path, result: StudyResult, wall_s: float | None = None) -> None:
    """<family>.csv, <family>.md, <family>.png, <family>_runup.csv and study.json in `folder`; where the study has
    a torque law also <family>_torque_law.csv and <family>_torque_law.png; with the runs' terms variant_terms.csv."""
    from housingfe.outputs import write_csv, write_json

    name = result.family.name
    made = bool(result.as_made)
    # gears as made: their columns after the periodic ones, which stay as without runup.as_made
    extra = list(AS_MADE_COLUMNS) if made else []
    # the floating bearings' held axial loads last, only where a variant's ratio is not 0 (floating_cells)
    floating = [c for c in FLOATING_COLUMNS if any(c in r for r in result.rows)]

    def as_made_cells(row):
        m = _as_made_row(result, row)
        return [result.as_made_grade] + [m[c] for c in list(AS_MADE_COLUMNS.values())[1:]]

    write_csv(folder / f"{name}.csv", list(COLUMNS) + extra + floating,
              ([r[c] for c in COLUMNS] + (as_made_cells(r) if made else []) + [r.get(c) for c in floating]
               for r in result.rows))
    keys = list(result.runs)
    first = result.runs[keys[0]].curves[result.routes[0]][0]
    kinds = (PERIODIC, AS_MADE) if made else (PERIODIC,)
    if made:
        for k in keys:
            for route in result.routes:
                if not np.array_equal(result.runs[k].curves_as_made[route][0], first):
                    raise ValueError(f"study {name}: {k} {route}: the as-made speeds are not the run-up's")
    header = ["speed_rpm"] + [f"LwA_{'as_made_' if kind == AS_MADE else ''}{route}_{k}_dBA"
                              for kind in kinds for route in result.routes for k in keys]
    write_csv(folder / f"{name}_runup.csv", header,
              ([s] + [round(float(result.runs[k].curves_of(kind)[route][1][i]), 3)
                      for kind in kinds for route in result.routes for k in keys]
               for i, s in enumerate(first)))
    if result.torque_law:
        made_laws = {_group_key(t): t for t in result.as_made.get("torque_law", [])}
        write_csv(folder / f"{name}_torque_law.csv",
                  list(TORQUE_LAW_COLUMNS) + (list(TORQUE_LAW_AS_MADE_COLUMNS) if made else []),
                  ([t[c] for c in TORQUE_LAW_COLUMNS]
                   + ([result.as_made_grade] + [made_laws[_group_key(t)][c]
                                                for c in list(TORQUE_LAW_AS_MADE_COLUMNS.values())[1:]]
                      if made else [])
                   for t in result.torque_law))
    if result.terms:
        write_csv(folder / "variant_terms.csv", list(variant_terms.COLUMNS),
                  (variant_terms.csv_cells(r) for r in result.terms))
    (folder / f"{name}.md").write_text(markdown(result, wall_s))
    data = {
        "family": name, "scene": result.family.scene, "engagement": result.engagement,
        "radiation": result.radiation, "reference": result.family.reference, "source": result.family.source,
        "notes": list(result.family.notes), "rows": result.rows, "rankings": result.rankings,
        "torque_law": result.torque_law, "basis_builds": result.basis_builds, "timings_s": result.timings,
        "wall_s": wall_s}
    if made:
        data["as_made"] = {"grade": result.as_made_grade, "label": result.as_made_label, "what": AS_MADE_WHAT,
                           "pitch_model": result.as_made_pitch,
                           "assumptions": list(result.as_made_assumptions), **result.as_made}
    write_json(folder / "study.json", data)
    plot(folder / f"{name}.png", result)
    if result.torque_law:
        plot_torque_law(folder / f"{name}_torque_law.png", result)


def plot(path: Path, result: StudyResult) -> None:
    """L_WA over speed per variant and route (top), mean differences and maxima ours / measured / thesis (bottom)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fam = result.family
    routes = result.routes
    fig, axes = plt.subplots(2, max(2, len(routes)), figsize=(6 * max(2, len(routes)), 8.5), squeeze=False)
    for j, route in enumerate(routes):
        ax = axes[0, j]
        for k, run in result.runs.items():
            s, lwa = run.curves[route]
            ax.plot(s, lwa, lw=1.8 if k == fam.reference else 1.0, label=k)
            if run.curves_as_made:
                ax.plot(*run.curves_as_made[route], lw=1.8 if k == fam.reference else 1.0, ls="--",
                        color=ax.lines[-1].get_color())
            if run.variant.measured_max is not None:
                ax.plot([s[-1] + 25], [run.variant.measured_max], marker="<", color=ax.lines[-1].get_color(), ms=7)
        ax.axvspan(*MEAN_RANGE_RPM, color="0.93", zorder=0)
        ax.set_title(f"{route}: L_WA over speed (◁ measured maxima)"
                     + (f"\ndashed: {result.as_made_label}" if result.as_made else ""), fontsize=10)
        ax.set_xlabel("pinion speed [rev/min]")
        ax.set_ylabel("L_WA [dB(A)]")
        ax.legend(fontsize=7, ncol=2)
    others = [k for k in result.runs if k != fam.reference]
    x = np.arange(len(others))
    width = 0.8 / (len(routes) + 2)
    ax = axes[1, 0]
    for j, route in enumerate(routes):
        rows = {r["variant"]: r for r in result.rows if r["route"] == route}
        ax.bar(x + j * width, [rows[k]["mean_diff_dB"] for k in others], width,
               yerr=[rows[k]["sd_diff_dB"] for k in others], capsize=2, label=f"ours, {route}")
    for j, (label, attr, sd) in enumerate((("measured", "measured_mean", "measured_sd"),
                                           ("thesis calculated", "calc_mean", "calc_sd"))):
        vals = [getattr(result.runs[k].variant, attr) for k in others]
        sds = [getattr(result.runs[k].variant, sd) for k in others]
        ax.bar(x + (len(routes) + j) * width, [np.nan if v is None else v for v in vals], width,
               yerr=[0.0 if v is None else v for v in sds], capsize=2, label=label,
               color="k" if label == "measured" else "0.6")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xticks(x + width * (len(routes) + 1) / 2, others, rotation=20, fontsize=8)
    ax.set_ylabel(f"L_WA − L_WA({fam.reference}), mean ± s.d. 800–1500 rpm [dB]")
    ax.legend(fontsize=7)
    ax = axes[1, 1]
    keys = list(result.runs)
    x = np.arange(len(keys))
    for j, route in enumerate(routes):
        rows = {r["variant"]: r for r in result.rows if r["route"] == route}
        ax.bar(x + j * width, [rows[k]["LwA_max_dBA"] for k in keys], width, label=f"ours, {route}")
    for j, (label, attr) in enumerate((("measured", "measured_max"), ("thesis calculated", "calc_max"))):
        vals = [getattr(result.runs[k].variant, attr) for k in keys]
        ax.bar(x + (len(routes) + j) * width, [np.nan if v is None else v for v in vals], width, label=label,
               color="k" if label == "measured" else "0.6")
    lo = min(r["LwA_max_dBA"] for r in result.rows) - 10
    ax.set_ylim(bottom=max(0.0, lo))
    ax.set_xticks(x + width * (len(routes) + 1) / 2, keys, rotation=20, fontsize=8)
    ax.set_ylabel("max L_WA [dB(A)]")
    ax.legend(fontsize=7)
    for extra in axes.flat[len(routes) + 2:] if len(routes) > 2 else []:
        extra.axis("off")
    fig.suptitle(f"housingfe study {fam.name} (engagement {result.engagement}, radiation {result.radiation})")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_torque_law(path: Path, result: StudyResult) -> list[dict]:
    """The torque law as a figure (<family>_torque_law.png), one panel per torque-law group: per route the energy
    mean of L_WA over 800-1500 rev/min (dB(A)) against the pinion torque (N m, log2 axis), markers, and the least
    squares line with its slope per doubling in the legend (`torque_law`); where a measured law is known, the
    measured step (and/or slope) as a segment from our energy mean at its lower torque; with runup.as_made the
    same of gears as made, dashed.  Returns what was plotted, read back from the lines: per line {"gear_set",
    "bearings", "route", "kind" (PERIODIC / AS_MADE / "measured_step" / "measured_slope"), "what" ("means",
    "fit", "measured"), "torques_nm", "LwA_dBA" (arrays), "linestyle"}."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    groups = {(g, b): runs for g, b, runs in torque_groups(result)}
    laws: dict = {}
    for t in result.torque_law:
        laws.setdefault((t["gear_set"], t["bearings"]), []).append(t)
    made_laws = {_group_key(t): t for t in result.as_made.get("torque_law", [])}
    kinds = (PERIODIC, AS_MADE) if result.as_made else (PERIODIC,)
    fig, axes = plt.subplots(1, len(laws), figsize=(6.0 * len(laws), 5.2), squeeze=False)
    plotted: list[dict] = []

    def line(ax, meta, x, y, **style):
        drawn = ax.plot(x, y, **style)[0]
        plotted.append({**meta, "torques_nm": np.asarray(drawn.get_xdata(), float),
                        "LwA_dBA": np.asarray(drawn.get_ydata(), float), "linestyle": drawn.get_linestyle()})

    for ax, ((gear_set, bearings), group_laws) in zip(axes[0], laws.items()):
        runs = groups[gear_set, bearings]
        torques = sorted(runs)
        ends = np.array([torques[0], torques[-1]], float)
        for j, t in enumerate(group_laws):
            route, colour = t["route"], f"C{j}"
            for kind in kinds:
                law = t if kind == PERIODIC else made_laws[_group_key(t)]
                meta = {"gear_set": gear_set, "bearings": bearings, "route": route, "kind": kind}
                means = _energy_means(runs, torques, route, kind)
                slope, intercept = np.polyfit(np.log2(torques), means, 1)
                dashed = kind == AS_MADE
                line(ax, {**meta, "what": "means"}, torques, means, ls="none", color=colour,
                     marker="s" if dashed else "o", mfc="none" if dashed else colour, ms=6)
                line(ax, {**meta, "what": "fit"}, ends, intercept + slope * np.log2(ends), color=colour,
                     ls="--" if dashed else "-", lw=1.4,
                     label=f"{route}{', as made' if dashed else ''}: "
                           f"{law['slope_dB_per_doubling']:+.1f} dB(A) per doubling")
                if kind != PERIODIC:
                    continue
                lo, hi = t["from_nm"], t["to_nm"]
                at_lo = means[torques.index(lo)]
                # the measured law drawn from OUR level at its lower torque: the measured step or slope is then
                # read against our line directly
                if t["measured_step_dBA"] is not None:
                    line(ax, {**meta, "kind": "measured_step", "what": "measured"}, [lo, hi],
                         [at_lo, at_lo + t["measured_step_dBA"]], color=colour, ls=":", lw=1.6, marker="*",
                         markevery=[1], ms=11, mec="k",
                         label=f"{route}: measured step {t['measured_step_dBA']:+.1f} dB(A), "
                               f"{lo:g} → {hi:g} N m")
                if t["measured_slope_dBA_per_doubling"] is not None:
                    line(ax, {**meta, "kind": "measured_slope", "what": "measured"}, [lo, hi],
                         [at_lo, at_lo + t["measured_slope_dBA_per_doubling"] * math.log2(hi / lo)],
                         color=colour, ls="-.", lw=1.2, marker="D", markevery=[1], ms=6, mec="k",
                         label=f"{route}: measured slope {t['measured_slope_dBA_per_doubling']:+.1f} dB(A) "
                               "per doubling")
        ax.set_xscale("log", base=2)
        ax.set_xticks(torques, [f"{x:g}" for x in torques])
        ax.minorticks_off()
        ax.set_xlim(torques[0] / 1.2, torques[-1] * 1.2)
        ax.set_xlabel("pinion torque [N m] (log2 axis)")
        ax.set_ylabel("L_WA energy mean 800–1500 rpm [dB(A)]")
        ax.set_title(f"{_group_label(result, group_laws[0])}", fontsize=10)
        ax.grid(True, color="0.9")
        # below the panel: inside, it would hide the measured segments, which end where the lines are
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14))
    entries = max(len(ax.get_legend_handles_labels()[1]) for ax in axes[0])
    fig.set_size_inches(6.0 * len(laws), 4.6 + 0.17 * entries)
    fam = result.family
    notes = [f"measured: {fam.torque_law_source}, drawn from ours at the lower torque"
             if fam.torque_law_source else "measured: drawn from ours at the lower torque"] \
        if fam.torque_laws else []
    if result.as_made:
        notes.append(f"dashed, open markers: {result.as_made_label}")
    fig.suptitle(f"housingfe study {fam.name}: torque law (engagement {result.engagement}, radiation "
                 f"{result.radiation})" + ("\n" + "; ".join(notes) if notes else ""), fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return plotted


def summary_text(result: StudyResult, wall_s: float | None = None) -> str:
    """The console summary: per route the table ours | measured | thesis, and the rankings."""
    from housingfe.outputs import format_table

    fam = result.family
    out = [f"study {fam.name} (engagement {result.engagement}, radiation {result.radiation}); differences to "
           f"{fam.reference}, mean ± s.d. over {MEAN_RANGE_RPM[0]:g}-{MEAN_RANGE_RPM[1]:g} rpm"]
    out.append(format_table(["route", "variant", "diff ours", "measured", "thesis", "max ours (rpm)", "measured max",
                             "basis"],
                            [[r["route"], r["variant"], _pm(r["mean_diff_dB"], r["sd_diff_dB"]),
                              _pm(r["measured_mean_dB"], r["measured_sd_dB"]),
                              _pm(r["thesis_calc_mean_dB"], r["thesis_calc_sd_dB"]),
                              f"{r['LwA_max_dBA']:.1f} ({r['at_rpm']:g})", _num(r["measured_max_dBA"]), r["basis"]]
                             for r in result.rows]))
    if _floating_runs(result):
        from housingfe.drivetrain.description import floating_axial_text

        out.append(floating_slid_text(result))
        out += [f"  {k} at {run.variant.torque:g} N m, held axial load: {floating_axial_text(run.floating)}"
                for k, run in _floating_runs(result).items()]
    for k in result.rankings:
        out.append(f"ranking {k['route']}, {k['measure']}: ours {k['ours']}; measured {k['measured']}; "
                   f"{'same order' if k['matches'] else 'different order'}")
    for t in result.torque_law:
        out.append(f"torque law {_group_label(result, t)}, {t['route']}: {_torque_law_text(t)}")
    out += variant_terms.summary_lines(result.terms)
    if result.as_made:
        label = result.as_made_label
        out.append(f"{label} (runup.as_made = {result.as_made_grade}: expected sidebands of tooth-to-tooth "
                   "deviations added to the periodic lines)")
        out.append(format_table(["route", "variant", f"diff {label}", "diff periodic", "measured",
                                 f"max {label} (rpm)", "max periodic", "measured max"],
                                [[r["route"], r["variant"], _pm(m["mean_diff_dB"], m["sd_diff_dB"]),
                                  _pm(r["mean_diff_dB"], r["sd_diff_dB"]),
                                  _pm(r["measured_mean_dB"], r["measured_sd_dB"]),
                                  f"{m['LwA_max_dBA']:.1f} ({m['at_rpm']:g})", f"{r['LwA_max_dBA']:.1f}",
                                  _num(r["measured_max_dBA"])]
                                 for r, m in ((r, _as_made_row(result, r)) for r in result.rows)]))
        for k in result.as_made["rankings"]:
            out.append(f"ranking {label}, {k['route']}, {k['measure']}: ours {k['ours']}; measured {k['measured']}; "
                       f"{'same order' if k['matches'] else 'different order'}")
        periodic = {_group_key(t): t for t in result.torque_law}
        for t in result.as_made["torque_law"]:
            p = periodic.get(_group_key(t))
            out.append(f"torque law {label}, {_group_label(result, t)}, {t['route']}: "
                       + _torque_law_text(t, f"periodic {_pm(p['step_mean_dB'], None) if p else '-'}"))
    out.append(f"{result.basis_builds} basis for {len(result.runs)} variants"
               + (f"; wall time {wall_s:.1f} s" if wall_s is not None else ""))
    return "\n".join(out)


def run_studies(jobs, out_dir: str | None = None, fresh_basis: bool = False) -> Path:
    """Run families through the chain and write their comparisons (module docstring) atomically; returns the result
    folder.  jobs: [(family, overrides, subfolder)]: the family's run-up scene with --set overrides, written into
    out_dir/subfolder (None: into out_dir itself; default out_dir results/study-<family>-<engagement> for one job).
    The jobs share the housing model and every modal basis that fits (one ModelPool): families on the same layout,
    or one family with another engagement shock, re-analyse the first one's basis.  Bad input (unknown family, a
    bad or family-controlled --set, speeds that miss 800-1500 rev/min, a bearing that cannot carry its load) stops
    with InputError before any folder is made."""
    from housingfe import outputs
    from housingfe.studies.chain_session import ModelPool

    t_start = time.perf_counter()
    pool = ModelPool()
    planned = []
    for family, overrides, sub in jobs:
        fam = family_of(family)
        check_overrides(fam, overrides)
        session = ChainSession.from_scene(fam.scene, [*fam.overrides, *overrides], fresh_basis=fresh_basis,
                                          pool=pool)
        speeds = session.spec.speeds
        if not np.any((speeds >= MEAN_RANGE_RPM[0]) & (speeds <= MEAN_RANGE_RPM[1])):
            raise InputError(f"{session.scene_path}: runup.speed_min_rpm/speed_max_rpm: no speed inside "
                             f"{MEAN_RANGE_RPM[0]:g}-{MEAN_RANGE_RPM[1]:g} rev/min, where the thesis states its "
                             "mean differences")
        planned.append((fam, session, sub))
    if len({sub for *_, sub in planned}) < len(planned):
        raise InputError("study: two jobs write into the same folder (a family named twice?)")
    fam0, session0, _ = planned[0]
    comm = session0.comm
    out = Path(out_dir or f"results/study-{fam0.name}-{session0.spec.engagement}")
    outputs.reserve_output(out, comm, inputs=[s.scene_path for _, s, _ in planned]        # before any model is built
                           + [f.path for f, _, _ in planned if f.path is not None])
    for fam, session, _ in planned:          # a bearing that cannot carry its load stops here, before any FE
        for v in fam.variants:
            session.drivetrain(v.gear_set, v.bearings, v.torque)
    say = (lambda text: print(text, flush=True)) if comm.rank == 0 else (lambda text: None)
    results = []
    for fam, session, sub in planned:
        t0 = time.perf_counter()
        results.append((run_family(fam, session, progress=say), sub, time.perf_counter() - t0))
    wall = time.perf_counter() - t_start
    vs_single = []
    with outputs.atomic_output_dir(out, comm) as tmp:
        if comm.rank == 0:
            written = []
            for result, sub, seconds in results:
                folder = tmp / sub if sub else tmp
                folder.mkdir(exist_ok=True)
                write(folder, result, seconds if len(results) > 1 else wall)
                written.append((result.family.name, result.engagement, folder))
            # the double helical set run together with single helical families: the thesis' Sec. 5.9 comparison
            vs_single = helical_vs_single.from_studies(written) if len(results) > 1 else []
            if vs_single:
                helical_vs_single.write(tmp, vs_single)
    if comm.rank == 0:
        for result, _, seconds in results:
            print(summary_text(result, seconds if len(results) > 1 else wall))
        for r in vs_single:
            print(f"double helical {r['double_helical']} - single helical {r['single_helical']}, {r['route']}: mean "
                  f"{_pm(r['mean_diff_dB'], r['sd_diff_dB'])} dB (measured {r['measured_mean_dB']:+g}), max reduced "
                  f"by {r['max_reduction_dBA']:+.1f} dB(A) (measured {r['measured_max_reduction_dBA']:+g})")
        print(f"total wall time {wall:.1f} s; results: {out}/")
    return out


def run_study(family: str, out_dir: str | None = None, overrides=(), fresh_basis: bool = False) -> Path:
    """`housingfe study <family>`: one family (run_studies with one job)."""
    return run_studies([(family, list(overrides), None)], out_dir, fresh_basis)


# --------------------------------------------------------------------------------------------------- CLI
def register_cli(subparsers) -> None:
    """Add `housingfe study <family> [<family> ...] [--out DIR] [--set KEY=VALUE] [--fresh-basis]`."""
    p = subparsers.add_parser("study", help="design variants through the chain beside the thesis' measurements "
                                            "(profile-corrections, bearings, double-helical) or your own family file")
    p.add_argument("families", nargs="+", metavar="family",
                   help="profile-corrections | bearings | double-helical | a family file FILE.toml "
                        "(docs/design-variants.md, 'Your own family'; several: they share the housing model and "
                        "the bases that fit, each written to <out>/<family name>/; double-helical together with "
                        "profile-corrections and/or bearings also writes double-helical_vs_single.csv/.md, the "
                        "double helical set against single helical A and self-aligning B)")
    p.add_argument("--out", default=None, help="result folder (default results/study-<family>-<engagement>, for "
                                               "several families results/study-<engagement>)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="override a value of the families' run-up scenes, e.g. runup.engagement=thesis-2d, or "
                        "runup.as_made=5 (the comparison also with the expected sidebands of ISO grade-5 gears, "
                        "beside the periodic one) (repeatable; not the gear set, bearings or torques, which the "
                        "family sets)")
    p.add_argument("--fresh-basis", action="store_true",
                   help="compute a modal basis for every variant instead of re-analysing the layout's (slower; "
                        "measures what the reuse costs)")
    p.set_defaults(func=_cmd)


def _cmd(args: argparse.Namespace) -> int:
    overrides = args.set or []
    if len(args.families) == 1:
        run_study(args.families[0], args.out, overrides, args.fresh_basis)
        return 0
    fams = [family_of(f) for f in args.families]
    out = args.out
    if out is None:
        engagement = ChainSession.from_scene(fams[0].scene, [*fams[0].overrides, *overrides]).spec.engagement
        out = f"results/study-{engagement}"
    run_studies([(f, overrides, fam.name) for f, fam in zip(args.families, fams)], out, args.fresh_basis)
    return 0
