"""`housingfe study <family> --set runup.as_made=<grade>`: the variants' comparison on the L_WA of gears as made,
beside the periodic one (housingfe.studies.design_variants, housingfe.runup.as_made).  Synthetic runs with levels
whose differences, torque laws and speed laws are known in closed form; the study's own run-ups are measured in
docs/design-variants.md ("Gears as made in the variants")."""
import csv
import json
import math
from types import SimpleNamespace

import numpy as np
import pytest

from housingfe.runup import as_made as am
from housingfe.studies import design_variants as dv
from tests.studies.runup_cli import cli_lwa_curves

SPEEDS = np.array([500.0, 800.0, 1150.0, 1500.0])
ROUTES = ("tf_omega", "mesh_force")


def _energy_sum(*levels_db):
    return 10 * np.log10(sum(10 ** (np.asarray(x, float) / 10) for x in levels_db))


def _bearings(grade=5):
    """Gear set B's bearings: periodic L_WA ball 90, angular contact 88, self-aligning 95, tapered roller 91 dB(A)
    at every speed; with gears as made the same expected sideband power of 100 dB(A) added to each (deviations
    that do not depend on the bearings)."""
    fam = dv.families()["bearings"]
    periodic = {"ball": 90.0, "angular_contact": 88.0, "self_aligning": 95.0, "tapered_roller": 91.0}
    runs = {}
    for v in fam.variants:
        flat = np.full(SPEEDS.size, periodic[v.key])
        made = _energy_sum(flat, 100.0)
        runs[v.key] = dv.VariantRun(v, {r: (SPEEDS, flat) for r in ROUTES}, "built", 0.0, 0.0,
                                    curves_as_made={r: (SPEEDS, made) for r in ROUTES} if grade != "none" else {})
    return dv.analyse(dv.StudyResult(fam, "face-width", "erp", ROUTES, runs, as_made_grade=grade)), periodic


def test_as_made_differences_are_the_energy_sums_differences():
    """Variant - reference with a common sideband power S: 10 lg(p_v + S) - 10 lg(p_ref + S), analytically; the
    periodic rows keep p_v / p_ref; the ranking follows the as-made means."""
    result, periodic = _bearings()
    made = {(r["route"], r["variant"]): r for r in result.as_made["rows"]}
    for r in result.rows:
        m = made[r["route"], r["variant"]]
        assert r["mean_diff_dB"] == pytest.approx(periodic[r["variant"]] - 90.0)
        expected = 10 * math.log10((10 ** (periodic[r["variant"]] / 10) + 1e10) / (1e9 + 1e10))
        assert m["mean_diff_dB"] == pytest.approx(expected, abs=0.005) and m["sd_diff_dB"] == 0.0
        assert m["speeds_in_mean"] == 3 and m["measured_mean_dB"] == r["measured_mean_dB"]
        assert m["LwA_max_dBA"] == pytest.approx(_energy_sum(periodic[r["variant"]], 100.0), abs=0.05)
    # the sidebands compress the spread (+5 dB periodic -> +0.78 dB) but keep the order
    sa = made["mesh_force", "self_aligning"]["mean_diff_dB"]
    assert sa == pytest.approx(0.78, abs=0.01)
    by_mean = [k for k in result.as_made["rankings"] if k["measure"].startswith("mean")]
    assert by_mean[0]["ours"] == "angular_contact < ball < tapered_roller < self_aligning"
    assert by_mean[0]["measured"] == "self_aligning < angular_contact < tapered_roller < ball"


def _double_helical(periodic_law, as_made_law):
    """Double helical runs whose L_WA at every speed is 80 dB(A) + law(torque / 1000 N m) (dB)."""
    fam = dv.families()["double-helical"]
    runs = {}
    for v in fam.variants:
        p = np.full(SPEEDS.size, 80.0 + periodic_law(v.torque / 1000.0))
        m = np.full(SPEEDS.size, 80.0 + as_made_law(v.torque / 1000.0))
        runs[v.key] = dv.VariantRun(v, {r: (SPEEDS, p) for r in ROUTES}, "built", 0.0, 0.0,
                                    curves_as_made={r: (SPEEDS, m) for r in ROUTES})
    return dv.analyse(dv.StudyResult(fam, "face-width", "erp", ROUTES, runs, as_made_grade=5))


def test_torque_law_of_load_independent_lines_is_0_db_and_of_load_proportional_lines_20lg2():
    """A line set whose amplitude grows in proportion to the load steps 20 lg 2 = 6.02 dB(A) from 1000 to 2000 N m
    (and 6.02 dB per doubling over 500-2000 N m); a load-independent one (the first-order TE of deviations is
    geometric) 0 dB.  Here the periodic lines are the proportional ones, the as-made the independent ones; the
    measured steps (+3.4 rollers, +2.7 fluid films) stand beside both."""
    result = _double_helical(lambda t: 20 * math.log10(t), lambda t: 0.0)
    assert len(result.torque_law) == len(result.as_made["torque_law"]) == 4
    for t in result.torque_law:
        assert t["step_mean_dB"] == pytest.approx(20 * math.log10(2), abs=0.005) and t["step_sd_dB"] == 0.0
        assert t["slope_dB_per_doubling"] == pytest.approx(20 * math.log10(2), abs=0.005)
    for t in result.as_made["torque_law"]:
        assert t["step_mean_dB"] == 0.0 and t["step_at_1500rpm_dB"] == 0.0 and t["slope_dB_per_doubling"] == 0.0
    assert {t["bearings"]: t["measured_step_dBA"] for t in result.as_made["torque_law"]} == \
        {"cylindrical_roller": 3.4, "fluid_film": 2.7}
    # the energy sum of both: between 0 and 6.02, nearer 0 the more the load-independent lines dominate
    mixed = _double_helical(lambda t: 20 * math.log10(t),
                            lambda t: float(_energy_sum(20 * math.log10(t), 10.0)))
    step = mixed.as_made["torque_law"][0]["step_mean_dB"]
    assert step == pytest.approx(_energy_sum(20 * math.log10(2), 10.0) - _energy_sum(0.0, 10.0), abs=0.005)
    assert step == pytest.approx(10 * math.log10(14 / 11), abs=0.01)      # 10 lg((4 + 10) / (1 + 10))


def _read_csv(path):
    with open(path, newline="") as fh:
        return list(csv.reader(fh))


def test_periodic_tables_unchanged_and_as_made_labelled(tmp_path):
    """With runup.as_made on, the periodic columns of <family>.csv and <family>_runup.csv, the periodic sections
    of <family>.md, study.json's periodic entries and the summary's periodic lines are those of the option off;
    the as-made part is labelled "as made, ISO grade 5" in every output; off writes no as-made part at all."""
    on, _ = _bearings(5)
    off, _ = _bearings("none")
    assert off.as_made == {}
    for name, result in (("on", on), ("off", off)):
        (tmp_path / name).mkdir()
        dv.write(tmp_path / name, result, 1.0)
    csv_on, csv_off = _read_csv(tmp_path / "on/bearings.csv"), _read_csv(tmp_path / "off/bearings.csv")
    n = len(dv.COLUMNS)
    assert len(csv_off[0]) == n and [r[:n] for r in csv_on] == csv_off
    assert csv_on[0][n:] == list(dv.AS_MADE_COLUMNS) and {r[n] for r in csv_on[1:]} == {"5"}
    curves_on, curves_off = _read_csv(tmp_path / "on/bearings_runup.csv"), _read_csv(tmp_path / "off/bearings_runup.csv")
    k = len(curves_off[0])
    assert [r[:k] for r in curves_on] == curves_off
    assert curves_on[0][k] == "LwA_as_made_tf_omega_ball_dBA"
    md_on, md_off = (tmp_path / "on/bearings.md").read_text(), (tmp_path / "off/bearings.md").read_text()
    periodic = md_off.split("## Cost")[0]
    assert md_on.startswith(periodic) and "as made, ISO grade" not in md_off
    assert "# Gears as made, ISO grade 5 (`runup.as_made = 5`)" in md_on
    assert "## Route `mesh_force`, as made, ISO grade 5" in md_on and "## Ranking, as made, ISO grade 5" in md_on
    j_on = json.loads((tmp_path / "on/study.json").read_text())
    j_off = json.loads((tmp_path / "off/study.json").read_text())
    assert "as_made" not in j_off and j_on.pop("as_made")["label"] == "as made, ISO grade 5"
    assert j_on == j_off
    s_on, s_off = dv.summary_text(on), dv.summary_text(off)
    assert s_on.startswith(s_off.rsplit("\n", 1)[0]) and "ranking as made, ISO grade 5, mesh_force" in s_on


def test_the_pitch_model_names_itself_in_the_label_and_the_assumptions(tmp_path):
    """runup.as_made_pitch other than the default "independent" is named in the label and in the assumptions the
    outputs state (a runout study must not claim independent per-tooth pitch deviations); the default keeps the
    label "as made, ISO grade g"."""
    on, _ = _bearings(5)
    assert on.as_made_label == "as made, ISO grade 5" and on.as_made_assumptions == dv.AS_MADE_ASSUMPTIONS
    on.as_made_pitch = "runout"
    assert on.as_made_label == "as made, ISO grade 5, pitch runout"
    assert "order-1 sinusoid" in on.as_made_assumptions[1] and "uniform within" not in on.as_made_assumptions[0]
    dv.write(tmp_path, on, 1.0)
    made = json.loads((tmp_path / "study.json").read_text())["as_made"]
    assert made["pitch_model"] == "runout" and made["label"].endswith("pitch runout")
    assert "order-1 sinusoid" in (tmp_path / "bearings.md").read_text()


def test_as_made_speed_law_is_the_speed_law_fit():
    """runup.json "as_made" speed law: the least-squares slope of L_WA against log2(speed) over 250-1500 rev/min
    of the rows' as-made and periodic totals: 6 and 3 dB(A) per doubling for levels built with those laws (the
    speed below 250 rev/min left out of the fit)."""
    speeds = [100.0, 250.0, 500.0, 1000.0, 1500.0]
    rows = [{"route": route, "radiation": "erp", "torque_nm": 2000.0, "speed_rpm": s,
             "LwA_dB": 70 + 3 * math.log2(s / 250), "LwA_as_made_dB": 75 + 6 * math.log2(s / 250)
             + (30.0 if s < 250 else 0.0)} for route in ROUTES for s in speeds]
    run = am.AsMadeRun(5, rows, {2000.0: SimpleNamespace(routes=dict.fromkeys(ROUTES))}, 8, 0, 0.0)
    laws = am.speed_laws(run, "erp")
    for route in ROUTES:
        assert laws["2000"][route]["as_made"] == pytest.approx(6.0)
        assert laws["2000"][route]["periodic"] == pytest.approx(3.0)
    assert math.isnan(am.speed_laws(run, "sigma1")["2000"]["tf_omega"]["as_made"])     # no rows: no law


@pytest.mark.slow
def test_a_study_as_made_run_up_is_that_of_housingfe_run(tmp_path):
    """A variant's as-made L_WA in a study (ChainSession.runup_as_made) is `housingfe run --set runup.as_made=5`'s
    (runup_as_made.csv, LwA_as_made_dB) on the same scene, to 2e-3 dB at every speed and route: the same source,
    mesh model and coupled model, not a simplified chain."""
    from housingfe.studies.chain_session import ChainSession
    from tests.studies.test_design_variants import COARSE

    settings = COARSE + ["runup.as_made=5"]
    session = ChainSession.from_scene("test-gearbox-runup", settings)
    model = session.model(session.drivetrain("A", "ball", 2000.0))
    made = session.runup_as_made(model, 2000.0, session.runup(model, 2000.0))
    assert made.grade == 5 and made.lines > 100
    cli_lwa_curves("test-gearbox-runup", settings, tmp_path / "run")
    rows = _read_dicts(tmp_path / "run" / am.CSV)
    for route in ROUTES:
        s, lwa = am.lwa_curve(made, route, "erp", 2000.0)
        cli = [r for r in rows if r["route"] == route and r["radiation"] == "erp"]
        np.testing.assert_array_equal(s, [float(r["speed_rpm"]) for r in cli])
        np.testing.assert_allclose(lwa, [float(r["LwA_as_made_dB"]) for r in cli], rtol=0, atol=2e-3, err_msg=route)
    off = ChainSession.from_scene("test-gearbox-runup", COARSE)
    assert off.runup_as_made(model, 2000.0, None) is None         # "none": nothing computed


def _read_dicts(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))
