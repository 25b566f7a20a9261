"""The torque law of any design-variant family (housingfe.studies.design_variants.torque_law, docs/design-variants.md
"Torque law"): variants that share gear set and bearings and differ only in torque form a group; per group and route
the slope of the 800-1500 rev/min energy mean of L_WA against log2 of the torque (dB(A) per doubling) and the step
between two torques, beside a measured law where the family gives one.

Synthetic runs whose L_WA is a(speed) + k lg(T / 1 N m) at every speed of 800-1500 rev/min: the step from T1 to T2 is
k lg(T2 / T1) at every speed (s.d. 0) and the slope k lg 2 per doubling (6.02 dB for k = 20, the load-proportional
line), exactly; outside 800-1500 rev/min the levels follow another law, which must not enter."""
import csv
import json
import math

import numpy as np
import pytest

from housingfe.studies import design_variants as dv

SPEEDS = np.array([300.0, 600.0, 800.0, 950.0, 1150.0, 1300.0, 1500.0])
ROUTES = ("tf_omega", "mesh_force")
INSIDE = (SPEEDS >= 800.0) & (SPEEDS <= 1500.0)
# (key, gear set, bearings, torque N m, k dB per decade of torque)
VARIANTS = (("ball@2000", "B", "ball", 2000.0, 20.0), ("ball@500", "B", "ball", 500.0, 20.0),
            ("ball@1000", "B", "ball", 1000.0, 20.0), ("ball@4000", "B", "ball", 4000.0, 20.0),
            ("sa@1000", "B", "self_aligning", 1000.0, 10.0), ("sa@3000", "B", "self_aligning", 3000.0, 10.0),
            # differ from the ball group in bearings or gear set only: not mixed in (30 dB louder, another law)
            ("ac@1500", "B", "angular_contact", 1500.0, 40.0), ("C-ball@1500", "C", "ball", 1500.0, 40.0))


def _level(speed_rpm, torque, k, route, offset=0.0):
    shape = 70.0 + 8.0 * np.sin(speed_rpm / 170.0) + (3.0 if route == "mesh_force" else 0.0) + offset
    return np.where(INSIDE, shape + k * np.log10(torque), 40.0 + 35.0 * np.log10(torque))


def _result(torque_laws=(), k_as_made=None, extra_offset=0.0):
    variants = tuple(dv.Variant(key, g, b, t) for key, g, b, t, _ in VARIANTS)
    fam = dv.Family("synthetic", "test-gearbox-runup", "synthetic torque laws", variants, "ball@2000", "analytic",
                    torque_laws=tuple(torque_laws))
    runs = {}
    for (key, g, b, t, k), v in zip(VARIANTS, variants):
        off = 30.0 if key in ("ac@1500", "C-ball@1500") else extra_offset
        curves = {r: (SPEEDS, _level(SPEEDS, t, k, r, off)) for r in ROUTES}
        made = {r: (SPEEDS, _level(SPEEDS, t, k_as_made, r, 5.0)) for r in ROUTES} if k_as_made is not None else {}
        runs[key] = dv.VariantRun(v, curves, "built", 0.0, 0.0, curves_as_made=made)
    grade = 5 if k_as_made is not None else "none"
    return dv.analyse(dv.StudyResult(fam, "face-width", "erp", ROUTES, runs, as_made_grade=grade))


def test_groups_are_the_variants_that_differ_only_in_torque():
    result = _result()
    groups = [(g, b, sorted(runs)) for g, b, runs in dv.torque_groups(result)]
    assert groups == [("B", "ball", [500.0, 1000.0, 2000.0, 4000.0]), ("B", "self_aligning", [1000.0, 3000.0])]
    assert [(t["gear_set"], t["bearings"], t["route"]) for t in result.torque_law] == \
        [("B", "ball", "tf_omega"), ("B", "ball", "mesh_force"), ("B", "self_aligning", "tf_omega"),
         ("B", "self_aligning", "mesh_force")]
    # the bearings family: one torque each, no torque law
    bearings = dv.families()["bearings"]
    runs = {v.key: dv.VariantRun(v, {r: (SPEEDS, _level(SPEEDS, v.torque, 20.0, r)) for r in ROUTES}, "built", 0, 0)
            for v in bearings.variants}
    assert dv.analyse(dv.StudyResult(bearings, "face-width", "erp", ROUTES, runs)).torque_law == []


def test_slope_per_doubling_and_step_of_analytic_curves():
    """k = 20: 20 lg 2 = 6.02 dB per doubling (least squares over four torques) and 20 lg 8 = 18.06 dB from the
    lowest to the highest torque; k = 10 with two torques: slope = step / log2(3000 / 1000) = 10 lg 2."""
    result = _result()
    law = {(t["bearings"], t["route"]): t for t in result.torque_law}
    for route in ROUTES:
        ball, sa = law["ball", route], law["self_aligning", route]
        assert ball["slope_dB_per_doubling"] == pytest.approx(20 * math.log10(2), abs=0.005)
        assert (ball["from_nm"], ball["to_nm"]) == (500.0, 4000.0)
        assert ball["step_mean_dB"] == pytest.approx(20 * math.log10(8), abs=0.005) and ball["step_sd_dB"] == 0.0
        assert ball["step_at_1500rpm_dB"] == pytest.approx(20 * math.log10(8), abs=0.005)
        assert ball["torques_nm"] == "500 1000 2000 4000"
        assert sa["step_mean_dB"] == pytest.approx(10 * math.log10(3), abs=0.005)
        assert sa["slope_dB_per_doubling"] == pytest.approx(10 * math.log10(2), abs=0.005)
        assert sa["slope_dB_per_doubling"] == pytest.approx(sa["step_mean_dB"] / math.log2(3), abs=0.005)
        assert ball["measured_step_dBA"] is None and ball["measured_slope_dBA_per_doubling"] is None


def test_a_measured_law_sets_the_step_torques_and_stands_beside_ours(tmp_path):
    """A measured 1000 -> 2000 N m law on the ball group: our step between those torques (20 lg 2), the measured
    step and slope beside it in study.json, <family>_torque_law.csv, <family>.md and the summary, and in the
    comparison of gears as made (k = 6 there: 6 lg 2 = 1.81 dB)."""
    measured = dv.MeasuredTorqueLaw("B", "ball", 1000.0, 2000.0, measured_step=3.4, measured_slope=3.0)
    result = _result([measured], k_as_made=6.0)
    ball = [t for t in result.torque_law if t["bearings"] == "ball"]
    for t in ball:
        assert (t["from_nm"], t["to_nm"]) == (1000.0, 2000.0)
        assert t["step_mean_dB"] == pytest.approx(20 * math.log10(2), abs=0.005)
        assert (t["measured_step_dBA"], t["measured_slope_dBA_per_doubling"]) == (3.4, 3.0)
    made = [t for t in result.as_made["torque_law"] if t["bearings"] == "ball"]
    assert [t["step_mean_dB"] for t in made] == pytest.approx([6 * math.log10(2)] * 2, abs=0.005)
    assert [t["slope_dB_per_doubling"] for t in made] == pytest.approx([6 * math.log10(2)] * 2, abs=0.005)
    assert all((t["measured_step_dBA"], t["measured_slope_dBA_per_doubling"]) == (3.4, 3.0) for t in made)

    dv.write(tmp_path, result, 1.0)
    data = json.loads((tmp_path / "study.json").read_text())
    assert data["torque_law"] == result.torque_law and data["as_made"]["torque_law"] == result.as_made["torque_law"]
    rows = list(csv.DictReader(open(tmp_path / "synthetic_torque_law.csv")))
    assert [(r["bearings"], r["route"]) for r in rows] == [(t["bearings"], t["route"]) for t in result.torque_law]
    assert (rows[0]["from_nm"], rows[0]["to_nm"], rows[0]["measured_step_dBA"]) == ("1000.0", "2000.0", "3.4")
    assert float(rows[0]["step_mean_as_made_dB"]) == pytest.approx(6 * math.log10(2), abs=0.005)
    assert rows[2]["measured_step_dBA"] == "" and rows[2]["from_nm"] == "1000.0" and rows[2]["to_nm"] == "3000.0"
    md = (tmp_path / "synthetic.md").read_text()
    # two step pairs (1000 -> 2000, 1000 -> 3000): the torques stand in the cells
    assert "| ball | tf_omega | 1000 → 2000 N m: +6.0 ± 0.0 | +6.0 | +3.4 | +6.0 | +3.0 |" in md
    assert "| self_aligning | mesh_force | 1000 → 3000 N m: +4.8 ± 0.0 | +4.8 | - | +3.0 | - |" in md
    assert "## Torque law, as made, ISO grade 5" in md
    summary = dv.summary_text(result)
    assert ("torque law ball, tf_omega: 1000 -> 2000 N m +6.0 ± 0.0 dB(A) (measured +3.4); slope +6.0 dB(A) per "
            "doubling over 500 1000 2000 4000 N m (measured +3.0)") in summary
    assert ("torque law self_aligning, tf_omega: 1000 -> 3000 N m +4.8 ± 0.0 dB(A); slope +3.0 dB(A) per doubling "
            "over 1000 3000 N m") in summary
    assert "torque law as made, ISO grade 5, ball, mesh_force: 1000 -> 2000 N m +1.8 ± 0.0 dB(A) (periodic +6.0, " \
           "measured +3.4)" in summary


def test_double_helical_keeps_its_measured_1000_to_2000_law():
    """The built-in double helical family: its two groups' steps are 1000 -> 2000 N m beside the measured +3.4
    (rollers) / +2.7 (fluid films) dB(A) of Fig. 5.21, the slope over all four torques."""
    fam = dv.families()["double-helical"]
    assert [(t.gear_set, t.bearings, t.from_nm, t.to_nm, t.measured_step) for t in fam.torque_laws] == \
        [("double_helical", "cylindrical_roller", 1000.0, 2000.0, 3.4), ("double_helical", "fluid_film", 1000.0,
                                                                          2000.0, 2.7)]
    runs = {v.key: dv.VariantRun(v, {r: (SPEEDS, _level(SPEEDS, v.torque, 20.0, r)) for r in ROUTES}, "built", 0, 0)
            for v in fam.variants}
    law = dv.analyse(dv.StudyResult(fam, "face-width", "erp", ROUTES, runs)).torque_law
    assert [(t["bearings"], t["from_nm"], t["to_nm"], t["measured_step_dBA"], t["torques_nm"]) for t in law] == \
        [(b, 1000.0, 2000.0, m, "500 1000 1500 2000") for b, m in (("cylindrical_roller", 3.4), ("fluid_film", 2.7))
         for _ in ROUTES]
    assert all(t["slope_dB_per_doubling"] == pytest.approx(6.02, abs=0.005) for t in law)


def test_groups_of_several_gear_sets_are_named_by_gear_set_and_bearings():
    """Ball bearings on gear sets B and C, each at 1000 and 2000 N m: two groups, never mixed (C is 30 dB louder
    and steps by 40 lg 2), labelled "B, ball" / "C, ball" in the table and the summary."""
    variants = tuple(dv.Variant(f"{g}@{t:g}", g, "ball", t) for g in ("B", "C") for t in (1000.0, 2000.0))
    fam = dv.Family("two-sets", "test-gearbox-runup", "two gear sets", variants, "B@2000", "analytic")
    runs = {v.key: dv.VariantRun(v, {r: (SPEEDS, _level(SPEEDS, v.torque, 20.0 if v.gear_set == "B" else 40.0, r,
                                                         0.0 if v.gear_set == "B" else 30.0)) for r in ROUTES},
                                 "built", 0.0, 0.0) for v in variants}
    result = dv.analyse(dv.StudyResult(fam, "face-width", "erp", ROUTES, runs))
    steps = {(t["gear_set"], t["route"]): t["step_mean_dB"] for t in result.torque_law}
    assert steps == pytest.approx({("B", r): 20 * math.log10(2) for r in ROUTES}
                                  | {("C", r): 40 * math.log10(2) for r in ROUTES}, abs=0.005)
    md = dv.markdown(result)
    assert "| gear set, bearings | route | L_WA(2000) − L_WA(1000 N m), mean ± s.d. 800–1500 rpm |" in md
    assert "| C, ball | mesh_force | +12.0 ± 0.0 |" in md
    assert "torque law C, ball, tf_omega: 1000 -> 2000 N m +12.0 ± 0.0 dB(A); slope +12.0" in dv.summary_text(result)
