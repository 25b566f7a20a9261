"""A run-up driven by a transmission error from a file (runup.transmission_error): the run writes the TE its source
had, in the format it reads; fed back, it gives the same run-up; twice that TE gives +6.02 dB on tf_omega (the chain
is linear in the excitation); the summary says which excitation was used."""
import csv
import json
import math

import numpy as np
import pytest

from housingfe.source import transmission_error as tem
from tests.runup.test_imported_runup import SETTINGS


def _lwa(folder):
    with open(folder / "runup.csv") as fh:
        return {(r["route"], float(r["speed_rpm"])): float(r["LwA_dB"]) for r in csv.DictReader(fh)}


def test_the_runs_own_te_fed_back_gives_the_same_run_up_and_twice_it_six_decibels(tmp_path, scene_run):
    default = scene_run("test-gearbox-runup", SETTINGS)           # shared with test_as_made, test_imported_runup
    own = tem.read(default / "transmission_error.csv")
    assert own.torques.tolist() == [2000.0] and own.harmonics.tolist() == list(range(1, 31))
    assert 0.3e-6 < abs(own.amplitudes[0, 0]) < 1.0e-6            # set A's face-width TE, ~0.56 um (docs/source.md)

    fed_back = scene_run("test-gearbox-runup", SETTINGS + [f'runup.transmission_error="{default}/transmission_error.csv"'])
    ref, back = _lwa(default), _lwa(fed_back)
    assert ref.keys() == back.keys() and len(ref) == 6
    assert max(abs(ref[k] - back[k]) for k in ref) < 0.01
    summary = (fed_back / "summary.txt").read_text()
    assert "excitation: the transmission error of" in summary and "instead of the engagement model" in summary
    settings = json.loads((fed_back / "runup.json").read_text())["scene_settings"]["runup"]
    assert settings["transmission_error"].endswith("transmission_error.csv")
    assert "instead of the engagement model" not in (default / "summary.txt").read_text()

    tem.write(tmp_path / "twice.csv", own.torques, own.harmonics, 2 * own.amplitudes)
    twice = _lwa(scene_run("test-gearbox-runup", SETTINGS + [f'runup.transmission_error="{tmp_path}/twice.csv"']))
    steps = [twice[k] - ref[k] for k in ref if k[0] == "tf_omega"]
    assert len(steps) == 3 and np.allclose(steps, 20 * math.log10(2), atol=0.01), steps


def test_te_sensitivity_is_the_run_up_driven_by_one_micrometre_at_that_harmonic(tmp_path, scene_run):
    """te_sensitivity.csv (runup.te_sensitivity, default [1]) equals, line by line, the run-up driven by a TE file of
    1 um at the tooth frequency alone without the mesh moment: two code paths, one answer."""
    default = scene_run("test-gearbox-runup", SETTINGS)
    with open(default / "te_sensitivity.csv") as fh:
        sens = {(r["route"], float(r["speed_rpm"])): float(r["LwA_dB"]) for r in csv.DictReader(fh)
                if r["harmonic"] == "1"}
    (tmp_path / "unit.csv").write_text("torque_Nm,harmonic,amplitude_um\n2000,1,1.0\n")
    unit = scene_run("test-gearbox-runup", SETTINGS + [f'runup.transmission_error="{tmp_path}/unit.csv"',
                                                       'runup.mesh_moment="none"', "runup.te_sensitivity=[]"])
    assert not (unit / "te_sensitivity.csv").exists()
    with open(unit / "runup_harmonics.csv") as fh:
        line1 = {(r["route"], float(r["speed_rpm"])): float(r["LwA_dB"]) for r in csv.DictReader(fh)
                 if r["harmonic"] == "1"}
    assert sens.keys() == line1.keys() and len(sens) == 6
    assert max(abs(sens[k] - line1[k]) for k in sens) < 1e-6
    summary = (default / "summary.txt").read_text()
    assert "TE sensitivity" in summary and "harmonic 1: L_WA per 1 um of TE" in summary


def test_the_tooth_lines_transfer_at_500_rpm_is_reported_beside_the_measured_ratio(scene_run):
    """checks "te_transfer" (set A, ball, 2000 N m): the tooth line's L_WA - L_omega per um at 500 rpm from
    te_sensitivity.csv (the route's L_omega: rigid-bore source on tf_omega, flexible housing on mesh_force) beside the
    measured 80 dB(A) - 109.9 dB = -29.9 (Sec. 5.5, Fig. 5.4)."""
    default = scene_run("test-gearbox-runup", SETTINGS)
    with open(default / "te_sensitivity.csv") as fh:
        line = {r["route"]: r for r in csv.DictReader(fh)
                if r["harmonic"] == "1" and float(r["speed_rpm"]) == 500.0 and r["radiation"] == "erp"}
    rows = [c for c in json.loads((default / "runup.json").read_text())["checks"] if c["check"] == "te_transfer"]
    assert sorted(c["quantity"].split(":")[0] for c in rows) == ["mesh_force", "tf_omega"]
    for c in rows:
        r = line[c["quantity"].split(":")[0]]
        l_omega = float(r["L_omega_coupled_dB"] if c["quantity"].startswith("mesh_force") else r["L_omega_dB"])
        assert c["measured"] == -29.9 and abs(c["ours"] - (float(r["LwA_dB"]) - l_omega)) < 0.051
        assert c["passed"] == "" and "upper bound" in c["note"]


def test_the_te_for_the_measured_maximum_is_reported_and_named_in_the_max_lwa_check(scene_run):
    """checks "te_target": per route 10^((100.5 - max over speed of L_WA per um at n = 1) / 20) um; validate's
    28.default.max_lwa.<route> row says it in its why."""
    from housingfe.verification.validate import run_check_rows

    default = scene_run("test-gearbox-runup", SETTINGS)
    with open(default / "te_sensitivity.csv") as fh:
        rows = [r for r in csv.DictReader(fh) if r["harmonic"] == "1" and r["radiation"] == "erp"]
    checks = json.loads((default / "runup.json").read_text())["checks"]
    targets = {c["quantity"].split(":")[0]: c for c in checks if c["check"] == "te_target"}
    assert sorted(targets) == ["mesh_force", "tf_omega"]
    for route, c in targets.items():
        best = max(float(r["LwA_dB"]) for r in rows if r["route"] == route)
        assert c["ours"] == pytest.approx(10 ** ((100.5 - best) / 20), rel=0.01)
        assert c["measured"] is None and c["passed"] == ""
    tagged = {r["check_id"]: r for r in run_check_rows("test-gearbox-runup", checks) if r.get("check_id")}
    for route, c in targets.items():
        assert f"a tooth-frequency TE of {c['ours']} um would make the measured maximum" in \
            tagged[f"28.default.max_lwa.{route}"]["why"]
