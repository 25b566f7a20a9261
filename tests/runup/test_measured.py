"""A measured run-up beside the chain's (runup.measured, housingfe.runup.measured): the file is read strictly (one
line naming the file and the line for anything it cannot take); ours at a measured speed is the run's own curve
interpolated linearly in speed; mean, s.d., maxima and slopes of ours - measured are those of the compared points;
points outside the run's speeds are counted, not compared; a torque the run does not have is refused before any
work."""
import csv
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from housingfe.errors import InputError
from housingfe.runup import measured
from tests.runup.test_imported_runup import SETTINGS


def _write(tmp_path, text, name="m.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_read_takes_comments_a_bom_empty_cells_and_sorts_by_speed(tmp_path):
    path = tmp_path / "m.csv"
    path.write_bytes("\ufeff# rig B\ntorque_Nm,speed_rpm,L_WA_dBA,L_omega_dB\n2000,1000,86,111.2\n"
                     "2000,250,74,\n2000,500,80,109.9\n".encode())
    m = measured.read(path)
    assert m.torques == [2000.0] and len(m.sha256) == 64
    speeds, levels = m.series["L_WA_dBA", 2000.0]
    assert speeds.tolist() == [250.0, 500.0, 1000.0] and levels.tolist() == [74.0, 80.0, 86.0]
    speeds, levels = m.series["L_omega_dB", 2000.0]
    assert speeds.tolist() == [500.0, 1000.0] and levels.tolist() == [109.9, 111.2]
    without = measured.read(_write(tmp_path, "speed_rpm,L_v_dB\n500,90\n", "n.csv"))
    assert without.torques == [None]
    assert without.torque_problem([2000.0]) is None
    assert "has no torque_Nm column" in without.torque_problem([1000.0, 2000.0])
    assert m.torque_problem([1000.0, 2000.0]) is None
    assert "its 2000 N m is not a torque of the run-up" in m.torque_problem([1500.0])


@pytest.mark.parametrize("text,match", [
    ("", "no rows"),
    ("speed_rpm,L_WA_dB\n500,80\n", "line 1: unknown column 'L_WA_dB'"),
    ("torque_Nm,L_WA_dBA\n2000,80\n", "line 1: no column 'speed_rpm'"),
    ("torque_Nm,speed_rpm\n2000,500\n", "line 1: no level column"),
    ("speed_rpm,L_WA_dBA,L_WA_dBA\n500,80,80\n", "a column is named twice"),
    ("speed_rpm,L_WA_dBA\n500,eighty\n", "line 2: L_WA_dBA: 'eighty' is not a number"),
    ("speed_rpm,L_WA_dBA\n500,nan\n", "line 2: L_WA_dBA: nan is not a finite number"),
    ("speed_rpm,L_WA_dBA\n-500,80\n", "line 2: speed_rpm: -500 is not a positive speed"),
    ("speed_rpm,L_WA_dBA\n,80\n", "line 2: speed_rpm: '' is not a number"),
    ("torque_Nm,speed_rpm,L_WA_dBA\n0,500,80\n", "line 2: torque_Nm: 0 is not a positive torque"),
    ("speed_rpm,L_WA_dBA\n500,80\n500,81\n", "line 3: L_WA_dBA at 500 rev/min is given twice"),
    ("speed_rpm,L_v_dB\n500,0.003\n500,0.004\n", "given twice"),
    ("speed_rpm,L_v_dB\n500,3e5\n", "line 2: L_v_dB: 300000 dB is not a level in dB re 5e-8 m/s"),
    ("speed_rpm,L_WA_dBA\n500,80,1\n", "line 2: 3 values for 2 columns"),
    ("speed_rpm,L_WA_dBA\n500,\n", "no measured level after the header"),
])
def test_bad_files_name_the_file_and_the_line(tmp_path, text, match):
    path = _write(tmp_path, text)
    with pytest.raises(InputError) as info:
        measured.read(path)
    assert str(info.value).startswith(str(path)) and match in str(info.value), str(info.value)


def test_unreadable_file(tmp_path):
    with pytest.raises(InputError, match="cannot read the measured run-up file"):
        measured.read(tmp_path)                 # a folder


def _totals(route, speeds, lwa, torque=2000.0, radiation="erp"):
    return [{"route": route, "radiation": radiation, "torque_nm": torque, "speed_rpm": s, "LwA_dB": v,
             "Lw_dB": v + 3.0, "Lv_dB": v - 10.0, "L_omega_dB": 100.0, "L_omega_coupled_dB": 90.0}
            for s, v in zip(speeds, lwa)]


def test_compare_and_statistics_on_a_known_curve(tmp_path):
    """Ours a straight line in log2(speed) (+6 dB per doubling: 60 dB at 250 rpm) against measured points with known
    offsets: the interpolation between the run's speeds, the mean and s.d. of the offsets, the maxima, both slopes,
    the point outside the run's speeds, and L_omega taken per route."""
    speeds = np.array([250.0, 500.0, 1000.0, 2000.0])
    ours = 60.0 + 6.0 * np.log2(speeds / 250.0)
    totals = _totals("tf_omega", speeds, ours) + _totals("mesh_force", speeds, ours - 1.0)
    m = measured.read(_write(tmp_path, "speed_rpm,L_WA_dBA,L_omega_dB\n250,62,\n750,71,95\n2000,80,\n4000,90,\n"))
    rows, outside = measured.compare(m, totals, [2000.0])
    assert outside == 1                                            # 4000 rpm: beyond the run
    by = {(r["quantity"], r["route"], r["speed_rpm"]): r for r in rows}
    assert len(rows) == 2 * 3 + 2 * 1
    # 750 rpm lies between the run's 500 and 1000: linear in speed, (66 + 72) / 2 = 69
    assert by["L_WA_dBA", "tf_omega", 750.0]["ours_dB"] == pytest.approx(69.0, abs=1e-12)
    assert by["L_WA_dBA", "tf_omega", 750.0]["difference_dB"] == pytest.approx(-2.0, abs=1e-12)
    assert by["L_omega_dB", "tf_omega", 750.0]["ours_dB"] == 100.0           # the source's L_omega drives tf_omega
    assert by["L_omega_dB", "mesh_force", 750.0]["ours_dB"] == 90.0          # the wheel's in the coupled gearbox
    stats = {(s["quantity"], s["route"]): s for s in measured.statistics(rows)}
    s = stats["L_WA_dBA", "tf_omega"]
    diffs = np.array([60.0 - 62.0, 69.0 - 71.0, 78.0 - 80.0])
    assert s["points"] == 3 and s["mean_difference_dB"] == pytest.approx(diffs.mean())
    assert s["sd_difference_dB"] == pytest.approx(diffs.std(ddof=1), abs=1e-12)
    assert (s["measured_max_dB"], s["measured_max_speed_rpm"]) == (80.0, 2000.0)
    assert s["ours_max_dB"] == pytest.approx(78.0) and s["ours_max_speed_rpm"] == 2000.0
    assert s["measured_slope_dB_per_doubling"] == pytest.approx(np.polyfit(np.log2([250, 750, 2000]), [62, 71, 80],
                                                                           1)[0])
    assert stats["L_WA_dBA", "mesh_force"]["mean_difference_dB"] == pytest.approx(diffs.mean() - 1.0)
    assert math.isnan(stats["L_omega_dB", "tf_omega"]["sd_difference_dB"])   # one point: no s.d.
    lines = measured.summary_lines(m, measured.statistics(rows), outside, "erp")
    assert "1 measured point(s) outside the run's speeds were not compared" in lines[-1]


def test_run_up_lays_the_measured_points_over_its_own_curve(tmp_path, scene_run):
    """The coarse run (500, 800, 1100 rpm): measured_comparison.csv holds ours = runup.csv's curve at the measured
    speeds (linear in speed between the run's), the summary and runup.json say the statistics, 1300 rpm is outside."""
    path = _write(tmp_path, "# published points of set A (van Roosmalen 1994, Figs. 5.4 and 5.10)\n"
                            "torque_Nm,speed_rpm,L_WA_dBA,L_omega_dB\n2000,500,80,109.9\n2000,650,83,\n"
                            "2000,1000,86,111.2\n2000,1300,88,\n")
    out = scene_run("test-gearbox-runup", SETTINGS + [f'runup.measured="{path}"'])
    with open(out / "runup.csv") as fh:
        curve = {}
        for r in csv.DictReader(fh):
            curve.setdefault(r["route"], []).append((float(r["speed_rpm"]), float(r["LwA_dB"]),
                                                     r["L_omega_dB"], r["L_omega_coupled_dB"]))
    with open(out / "measured_comparison.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert {r["route"] for r in rows} == {"tf_omega", "mesh_force"}
    for r in rows:
        points = sorted(curve[r["route"]])
        s = [p[0] for p in points]
        if r["quantity"] == "L_WA_dBA":
            expected = np.interp(float(r["speed_rpm"]), s, [p[1] for p in points])
        else:
            column = 3 if r["route"] == "mesh_force" else 2
            expected = np.interp(float(r["speed_rpm"]), s, [float(p[column]) for p in points])
        assert float(r["ours_dB"]) == pytest.approx(expected, abs=2e-3)     # the CSVs carry 6 digits
        assert float(r["difference_dB"]) == pytest.approx(float(r["ours_dB"]) - float(r["measured_dB"]), abs=2e-3)
    assert sorted({float(r["speed_rpm"]) for r in rows if r["quantity"] == "L_WA_dBA"}) == [500.0, 650.0, 1000.0]
    facts = json.loads((out / "runup.json").read_text())["measured"]
    assert facts["outside_speeds"] == 1 and facts["file"] == str(path) and facts["csv"] == "measured_comparison.csv"
    lwa = [s for s in facts["statistics"] if s["quantity"] == "L_WA_dBA" and s["route"] == "tf_omega"][0]
    diffs = [float(r["difference_dB"]) for r in rows if r["quantity"] == "L_WA_dBA" and r["route"] == "tf_omega"]
    assert lwa["points"] == 3 and lwa["mean_difference_dB"] == pytest.approx(np.mean(diffs), abs=2e-3)
    summary = (out / "summary.txt").read_text()
    assert "measured run-up (runup.measured)" in summary and "outside the run's speeds" in summary
    assert (out / "runup.png").stat().st_size > 10_000


@pytest.mark.parametrize("setting,match", [
    ("runup.measured=other.csv", "runup.measured: {tmp}/other.csv: its 1500 N m is not a torque of the run-up"),
    ("runup.measured=none.csv", "has no torque_Nm column, and the run-up has 2 torques"),
    ("runup.measured=missing.csv", "missing.csv: cannot read the measured run-up file"),
])
def test_a_file_that_cannot_serve_the_run_stops_it_before_any_work(tmp_path, setting, match):
    _write(tmp_path, "torque_Nm,speed_rpm,L_WA_dBA\n1500,500,80\n", "other.csv")
    _write(tmp_path, "speed_rpm,L_WA_dBA\n500,80\n", "none.csv")
    extra = ["--set", "runup.torques_nm=[1000.0,2000.0]"] if "none" in setting else []
    run = subprocess.run([sys.executable, "-m", "housingfe", "run", "test-gearbox-runup", "--set", setting, *extra,
                          "--out", str(tmp_path / "out")], capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert run.returncode == 2, run.stderr
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("housingfe: error: "), run.stderr
    assert match.format(tmp=tmp_path) in lines[0], lines[0]
    assert not (tmp_path / "out").exists()
