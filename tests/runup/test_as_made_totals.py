"""Gears as made in the run-up's totals (runup.as_made_totals; housingfe.runup.as_made.folded_result): the expected
sidebands as incoherent lines beside the periodic harmonics in runup.csv, runup_harmonics.csv, the slope terms, the
peaks and the checks."""
import csv
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from housingfe import levels
from housingfe.runup import as_made as am
from housingfe.runup.chain import Lines, RouteResult, RunupResult
from housingfe.runup.slopes import term_levels
from housingfe.verification import checks as ck
from tests.runup.test_imported_runup import SETTINGS

ROOT = Path(__file__).parents[2]


def _db(power):
    return 10.0 * math.log10(power)


def _result(lines: Lines, L_v, L_omega_coupled, L_S=0.0, sigma=0.0) -> RunupResult:
    """A RunupResult of one route ("mesh_force") and radiator ("erp") with given per-line levels, no model: L_W =
    L_v + L_S + L_sigma line by line."""
    L_v = np.asarray(L_v, float)
    rr = RouteResult("mesh_force", L_v, None, np.zeros((2, L_v.size), complex), np.asarray(L_omega_coupled, float),
                     excitation_db=L_v - 100.0, excitation_name="exc", transfer_name="tr")
    L_sigma = np.full(L_v.size, sigma)
    return RunupResult(lines, {"mesh_force": rr}, {("mesh_force", "erp"): L_sigma},
                       {("mesh_force", "erp"): L_v + L_S + L_sigma}, L_S, ["erp"], [], {})


def _lines(point, harmonic, frequency, L_omega, points) -> Lines:
    n = len(frequency)
    return Lines(torque=np.full(n, 2000.0), speed=np.array([points[p][1] for p in point], float),
                 harmonic=np.array(harmonic, int), frequency=np.array(frequency, float),
                 L_omega=np.array(L_omega, float), mesh_excitation=np.ones(n, complex), point=np.array(point, int),
                 points=points)


def test_totals_of_coherent_and_incoherent_lines_by_hand():
    """Two operating points (tooth frequencies 400 and 800 Hz).  Point 0: periodic lines n = 1, 2 with mean
    squares 4 and 10 (x 1e6, L_v 66.02 and 70 dB), sidebands of expected mean squares 1 at the tooth frequency
    itself (|D|^2 + E|X|^2), 2 and 3 elsewhere in the tooth band (370, 430 Hz), 10 in harmonic 2's band: tooth band
    4 + 1 + 2 + 3 = 10 -> 70.00 dB, total 30 -> 74.77 dB.  Point 1: periodic n = 1 alone (mean square 1), no
    sideband: its levels stay the periodic line's.  L_omega of the rigid-bore source in the tooth band: 90 dB
    periodic + sidebands 87 and 87 dB (energies) -> 10 lg(1e9 + 2 x 10^8.7)."""
    points = [(2000.0, 1000.0, 400.0, 90.0, 1e8), (2000.0, 2000.0, 800.0, 80.0, 1e8)]
    P = _lines([0, 0, 1], [1, 2, 1], [400.0, 800.0, 800.0], [90.0, 70.0, 80.0], points)
    S = _lines([0, 0, 0, 0], [1, 1, 1, 2], [430.0, 400.0, 370.0, 760.0], [87.0, 87.0, -np.inf, 60.0], points)
    lvP = [_db(4e6), _db(10e6), _db(1e6)]
    lvS = [_db(3e6), _db(1e6), _db(2e6), _db(10e6)]
    rp = _result(P, lvP, [100.0, 95.0, 90.0], L_S=-1.0, sigma=-2.0)
    rs = _result(S, lvS, [94.0, 94.0, 94.0, 50.0], L_S=-1.0, sigma=-2.0)
    folded = am.folded_result(None, rp, rs)
    ln = folded.lines
    # one set of lines, per point by frequency, the periodic line before the sideband at the same frequency
    assert ln.frequency.tolist() == [370.0, 400.0, 400.0, 430.0, 760.0, 800.0, 800.0]
    assert ln.incoherent.tolist() == [True, False, True, True, True, False, False]
    assert ln.point.tolist() == [0, 0, 0, 0, 0, 0, 1]
    rows = {r["speed_rpm"]: r for r in folded.totals}
    r0, r1 = rows[1000.0], rows[2000.0]
    assert r0["Lv_tooth_dB"] == pytest.approx(70.0, abs=1e-12)
    assert r0["Lv_dB"] == pytest.approx(_db(30e6), abs=1e-12)
    assert r0["Lw_dB"] == pytest.approx(_db(30e6) - 3.0, abs=1e-12)
    a = levels.a_weighting_db
    lwa = sum(10 ** ((lv - 3.0 + float(a(f))) / 10) for lv, f in
              zip([_db(2e6), _db(4e6), _db(1e6), _db(3e6), _db(10e6), _db(10e6)], [370, 400, 400, 430, 760, 800]))
    assert r0["LwA_dB"] == pytest.approx(_db(lwa), abs=1e-10)
    assert r0["L_omega_dB"] == pytest.approx(_db(1e9 + 2 * 10**8.7), abs=1e-10)
    # the wheel on the coupled model in the tooth band: 100 dB periodic + three sidebands of 94 dB
    assert r0["L_omega_coupled_dB"] == pytest.approx(_db(1e10 + 3 * 10**9.4), abs=1e-10)
    assert r0["harmonics"] == 2 and r1["harmonics"] == 1
    assert (r1["Lv_tooth_dB"], r1["Lv_dB"], r1["L_omega_dB"]) == pytest.approx((60.0, 60.0, 80.0), abs=1e-12)
    # the tooth band's slope terms: energy sums over its lines (excitation = L_v - 100 dB line by line)
    t = term_levels(ln.point, 2, ln.harmonic, ln.frequency, folded.routes["mesh_force"].excitation_db,
                    folded.routes["mesh_force"].L_v, folded.L_sigma["mesh_force", "erp"], -1.0, "tooth_band")
    assert t["L_v"] == pytest.approx([70.0, 60.0], abs=1e-12)
    assert t["excitation"] == pytest.approx([-30.0, -40.0], abs=1e-12)
    assert t["transfer"] == pytest.approx([100.0, 100.0], abs=1e-12)
    assert t["L_W"] == pytest.approx([67.0, 57.0], abs=1e-12)


def test_the_harmonic_that_carries_is_its_bands_energy():
    """Lines of harmonic 1 with mean squares 4, 3, 3 and one of harmonic 2 with 6: harmonic 1 carries 10 of 16
    although harmonic 2 has the largest single line; with one line per harmonic it is the largest line."""
    assert ck.carrying_harmonic([1, 1, 1, 2], [_db(4), _db(3), _db(3), _db(6)]) == (1, pytest.approx(10 / 16))
    assert ck.carrying_harmonic([1, 2, 3], [_db(4), _db(6), _db(1)]) == (2, pytest.approx(6 / 11))


def _read(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.fixture(scope="module")
def runs(scene_run):
    """The coarse run-up with runup.as_made = 5, without (the run test_as_made makes too: one run, conftest) and with
    runup.as_made_totals."""
    made = SETTINGS + ["runup.as_made=5"]
    return scene_run("test-gearbox-runup", made), scene_run("test-gearbox-runup", made + ["runup.as_made_totals=true"])


def test_totals_equal_the_as_made_columns_of_the_separate_file(runs):
    """runup.csv with the sidebands folded in equals runup_as_made.csv's *_as_made_dB columns (written by the
    separate code path, table_rows), which the option leaves byte-identical; the checks read those totals."""
    apart, totals = runs
    assert (apart / am.CSV).read_bytes() == (totals / am.CSV).read_bytes()
    made, folded, periodic = _read(totals / am.CSV), _read(totals / "runup.csv"), _read(apart / "runup.csv")
    assert len(made) == len(folded) == len(periodic) == 6
    for m, f, p in zip(made, folded, periodic):
        assert (m["route"], m["speed_rpm"]) == (f["route"], f["speed_rpm"])
        pairs = [("Lv_tooth_band_as_made_dB", "Lv_tooth_dB"), ("Lv_as_made_dB", "Lv_dB"), ("Lw_as_made_dB", "Lw_dB"),
                 ("LwA_as_made_dB", "LwA_dB")]
        pairs.append(("L_omega_tooth_band_as_made_dB",
                      "L_omega_dB" if m["route"] == "tf_omega" else "L_omega_coupled_dB"))
        for a, b in pairs:
            assert float(f[b]) == pytest.approx(float(m[a]), abs=2e-4), (m["route"], m["speed_rpm"], b)
        assert f["harmonics"] == p["harmonics"]
        assert float(f["LwA_dB"]) > float(p["LwA_dB"])
    harm = _read(totals / "runup_harmonics.csv")
    data = json.loads((totals / "runup.json").read_text())
    assert data["as_made"]["in_totals"] is True
    assert sum(r["line"] == "sideband" for r in harm) == 2 * data["as_made"]["sideband_lines"]   # two routes
    assert sum(r["line"] == "periodic" for r in harm) == len(_read(apart / "runup_harmonics.csv"))
    assert "line" not in _read(apart / "runup_harmonics.csv")[0]
    checks = {(c["check"], c["quantity"].split(":")[0]): c for c in _read(totals / "checks.csv")}
    for route in ("tf_omega", "mesh_force"):
        top = max(float(m["LwA_as_made_dB"]) for m in made if m["route"] == route)
        assert float(checks["LwA_max", route]["ours"]) == pytest.approx(round(top, 1), abs=1e-9)
    flexible = [c for c in _read(totals / "checks.csv") if c["check"] == "L_omega_flexible"]
    wheel = next(m for m in made if m["route"] == "mesh_force" and m["speed_rpm"] == "500")
    assert float(flexible[0]["ours"]) == pytest.approx(round(float(wheel["L_omega_tooth_band_as_made_dB"]), 1))
    assert "gears as made in the totals" in (totals / "summary.txt").read_text()


def test_validate_rows_of_the_chain_as_made(runs):
    """The default chain's check rows on the totals run (28.as_made.independent.*): reported, not judged, each with
    the verdict the check gives on the same run's data; none from a run without the sidebands in its totals."""
    from housingfe.verification import runup_checks_rows, validate

    apart, totals = runs
    assert runup_checks_rows.as_made_chain_rows("x", apart) == []
    rows = runup_checks_rows.as_made_chain_rows("x", totals)
    data = json.loads((totals / "runup.json").read_text())
    judged = {r["check_id"]: r for r in ck.check_rows(
        validate.run_check_rows("x", data["checks"]) + runup_checks_rows.default_chain_rows("x", totals))}
    assert [r["check_id"] for r in rows] == [f"28.as_made.independent.{c[3:]}" for c in judged]
    for r in rows:
        j = judged[r["check_id"].replace("as_made.independent.", "")]
        assert (r["passed"], r["tolerance"], r["band"]) == ("", "", None)
        assert r["as_made_passes"] == j["passed"] and r["ours"] == j["ours"]
        assert f"as made the check would pass: {j['passed']}" in r["why"]
    would = sum(r["as_made_passes"] == "yes" for r in rows)
    assert ck.checks_markdown(rows).splitlines()[-1].endswith(
        f"sidebands: 0 of the default run-up, {len(rows)} of the default chain's checks as made (28.as_made.<pitch>.*; "
        f"they would pass: independent {would} of {len(rows)})), reported: not checks")
    assert runup_checks_rows.as_made_overrides("runout") == ("runup.as_made=5", "runup.as_made_totals=true",
                                                             "runup.as_made_pitch=runout")


def test_totals_without_as_made_is_one_line_exit_2_no_folder(tmp_path):
    out = tmp_path / "bad"
    proc = subprocess.run([sys.executable, "-m", "housingfe", "run", "test-gearbox-runup", "--set",
                           "runup.as_made_totals=true", "--out", str(out)], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 2 and not out.exists()
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "runup.as_made_totals: true needs runup.as_made" in lines[0]
