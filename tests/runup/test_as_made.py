"""Gears as made in the run-up (housingfe.runup.as_made, runup.as_made): the expected sidebands of ISO 1328-1
deviations as incoherent lines through the same routes, beside the periodic outputs (which stay byte-identical)."""
import csv
import importlib.util
import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from housingfe import levels
from housingfe.errors import InputError
from housingfe.runup import as_made as am
from housingfe.runup.chain import mesh_reference_stiffness, runup
from tests.runup.conftest import SPEEDS
from tests.runup.test_imported_runup import SETTINGS

ROOT = Path(__file__).parents[2]


def test_setting_is_none_or_an_iso_grade():
    assert am.check_as_made("none") == "none" and am.check_as_made(5) == 5 and am.check_as_made(0) == 0
    for bad in (13, -1, "5", 5.0, True, "five"):
        with pytest.raises(InputError, match="as_made: .* ISO 1328-1 accuracy grade"):
            am.check_as_made(bad)


def test_rigid_bore_te_receptance_is_the_budgets():
    """The batched receptance equals benchmarks/experiments/lomega_budget's frequency-by-frequency solve."""
    from housingfe.drivetrain.description import test_gearbox

    spec = importlib.util.spec_from_file_location(
        "lomega_budget", ROOT / "benchmarks/experiments/lomega_budget/lomega_budget.py")
    budget = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(budget)
    mats = test_gearbox("A").source_model()._point(2000.0).mats
    f = np.array([37.0, 180.0, 496.0, 1234.5])
    assert np.allclose(am.te_receptance_rigid_bores(mats, f), budget.lumped_te_receptance(mats, f), rtol=1e-10)


def test_one_sideband_line_through_both_routes_by_hand(coarse):
    """One expected line of power a^2 exactly at the tooth order (frequency f_tooth, where the periodic run has its
    n = 1 line): on mesh_force its L_v is the periodic line's plus 20 lg(k_ref a / sqrt 2 / |F_1|) (the same
    frequency, a linear model; the periodic line without its shuttling moment); on tf_omega its L_omega is
    20 lg(R_TE a / sqrt 2 / omega_0) and L_v - L_omega is the periodic line's TF_omega; the tooth band with the
    sideband is the energy sum of both lines."""
    gm, src, lines, res = coarse
    z2 = int(src.pair.teeth[1])
    a = 1e-6
    orders = np.arange(0, 4 * z2 + 1, dtype=float)
    power = np.where(orders == z2, a**2, 0.0)
    side = am.sideband_lines(src, gm, lines, 2000.0, am.Spectrum(orders, power, 2, 0.0), 1500.0)
    assert len(side.frequency) == len(SPEEDS)
    first = [int(np.flatnonzero(lines.point == p)[0]) for p in range(len(SPEEDS))]
    assert np.allclose(side.frequency, lines.frequency[first], rtol=1e-12)
    periodic = replace(lines, shuttle_moment=None)
    rp = runup(gm, None, SPEEDS, [2000.0], lines=periodic)
    rs = runup(gm, None, SPEEDS, [2000.0], lines=side)
    k_ref = mesh_reference_stiffness(gm)
    F1 = np.abs(periodic.mesh_excitation[first])
    expected = rp.routes["mesh_force"].L_v[first] + 20 * np.log10(k_ref * a / math.sqrt(2) / F1)
    assert np.allclose(rs.routes["mesh_force"].L_v, expected, atol=1e-9)
    mats = src._point(2000.0).mats
    R = am.te_receptance_rigid_bores(mats, side.frequency)
    assert np.allclose(side.L_omega, 20 * np.log10(R * a / math.sqrt(2) / levels.OMEGA0), atol=1e-9)
    assert np.allclose(rs.routes["tf_omega"].L_v - side.L_omega, rp.routes["tf_omega"].tf_omega[first], atol=1e-9)
    rows = am.table_rows(rp, rs, 5)
    for row, k in zip([r for r in rows if r["route"] == "mesh_force"], first):
        lp = rp.routes["mesh_force"].L_v[k]
        ls = rs.routes["mesh_force"].L_v[first.index(k)]
        assert row["Lv_tooth_band_dB"] == pytest.approx(lp, abs=1e-9)
        assert row["Lv_tooth_band_as_made_dB"] == pytest.approx(10 * math.log10(10 ** (lp / 10) + 10 ** (ls / 10)),
                                                                abs=1e-9)


@pytest.fixture(scope="module")
def spectra(coarse):
    _, src, _, _ = coarse
    return {g: am.deviation_spectrum(src, 2000.0, g, pitch_samples=5000) for g in (0, 5, 7, 12)}


def test_grades_order_the_sidebands_by_3_db_per_grade(spectra):
    """ISO 1328-1 tolerances grow by sqrt 2 per grade (before rounding), so the expected deviation power doubles:
    grade 7 carries 6 dB more than grade 5 (within the rounding of the tolerances, +-1 dB), grade 12 more than
    grade 0 at every order that any deviation reaches."""
    total = {g: float(np.sum(s.power)) for g, s in spectra.items()}
    assert 10 * math.log10(total[7] / total[5]) == pytest.approx(6.0, abs=1.0)
    reached = spectra[0].power > 0
    assert np.count_nonzero(reached) > 100
    assert np.all(spectra[12].power[reached] > spectra[0].power[reached])
    assert spectra[5].n_max == 8                   # 32 stiffness positions per mesh period


def test_sidebands_add_energy_in_the_tooth_band(coarse, spectra):
    """Through the routes: the tooth band and the total with the sidebands are never below the periodic ones, and
    grade 12 lies above grade 0 everywhere on both routes."""
    gm, src, lines, res = coarse
    out = {}
    for g in (0, 12):
        side = am.sideband_lines(src, gm, lines, 2000.0, spectra[g], 1500.0)
        assert np.all(side.harmonic >= 1) and np.all(side.frequency <= 1500.0)
        out[g] = am.table_rows(res, runup(gm, None, SPEEDS, [2000.0], lines=side), g)
    for r0, r12 in zip(out[0], out[12]):
        for key in ("L_omega_tooth_band", "Lv_tooth_band", "LwA_tooth_band", "LwA"):
            assert r0[f"{key}_as_made_dB"] >= r0[f"{key}_dB"] - 1e-12
            assert r12[f"{key}_as_made_dB"] > r0[f"{key}_as_made_dB"]


def test_prefetched_unit_coordinates_equal_the_direct_ones(coarse, spectra):
    """RitzReduction.prefetch_unit_coordinates (the QZ form, both loads at once) gives the unit coordinates of the
    batched direct solve at the sideband lines to 1e-8 relative."""
    from housingfe.solvers import harmonic

    gm, src, lines, _ = coarse
    f = am.sideband_lines(src, gm, lines, 2000.0, spectra[5], 1500.0).frequency
    red = gm.reduction
    red.prefetch_unit_coordinates(f, ["wheel_torque", "mesh"])
    s = red.system
    for name in ("wheel_torque", "mesh"):
        j = red.names.index(name)
        ref = harmonic.solve_reduced(s.Kr, s.Mr, s.Cr + s.D, 2 * math.pi * f, np.zeros(f.size), s.Fr[:, j:j + 1])[0]
        got = red.unit_coordinates(f, name)
        assert np.abs(got - ref).max() <= 1e-8 * np.abs(ref).max()


def _read(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def test_run_scene_with_as_made_keeps_the_periodic_outputs_byte_identical(scene_run):
    """A coarse run-up with runup.as_made = 5 and without: runup.csv, runup_harmonics.csv, checks.csv and the
    spectra are byte-identical; runup_as_made.csv has a row per route, radiator and speed whose periodic columns
    are runup.csv's (tooth band = the n = 1 line, total = all lines) and whose as-made columns are not below them."""
    off = scene_run("test-gearbox-runup", SETTINGS)           # shared with test_imported_runup (conftest)
    on = scene_run("test-gearbox-runup", SETTINGS + ["runup.as_made=5"])     # and with test_as_made_totals
    for name in ("runup.csv", "runup_harmonics.csv", "checks.csv", "spectra_500rpm.csv"):
        assert (off / name).read_bytes() == (on / name).read_bytes(), name
    assert not (off / am.CSV).exists()
    rows, totals = _read(on / am.CSV), _read(on / "runup.csv")
    assert len(rows) == len(totals) == 2 * 3
    for r, t in zip(rows, totals):
        assert (r["route"], r["speed_rpm"]) == (t["route"], t["speed_rpm"])
        assert float(r["Lv_dB"]) == pytest.approx(float(t["Lv_dB"]), abs=1e-4)
        assert float(r["Lv_tooth_band_dB"]) == pytest.approx(float(t["Lv_tooth_dB"]), abs=1e-4)
        assert float(r["LwA_as_made_dB"]) >= float(r["LwA_dB"]) and int(r["sideband_lines"]) > 50
        # the loudest 1/3-octave band holds part of the total and at least its share among the bands it spans
        for sfx in ("", "_as_made"):
            peak, total = float(r[f"LwA_peak_band{sfx}_dB"]), float(r[f"LwA{sfx}_dB"])
            assert total - 10 * math.log10(12) <= peak <= total + 1e-9
            assert float(r[f"LwA_peak_band{sfx}_hz"]) in levels.NOMINAL_THIRD_OCTAVES
    assert "as made (ISO 1328-1 grade 5" in (on / "summary.txt").read_text()
    # the speed law of each route's L_WA with and without the sidebands: the fit of L_WA over log2(speed), 250-1500 rpm
    assert json.loads((on / "runup.json").read_text())["as_made"]["pitch_model"] == "independent"     # the default
    assert {r["pitch_model"] for r in rows} == {"independent"}
    laws = json.loads((on / "runup.json").read_text())["as_made"]["speed_law_dBA_per_doubling"]["2000"]
    for route in ("tf_omega", "mesh_force"):
        sel = [r for r in rows if r["route"] == route]
        x = np.log2([float(r["speed_rpm"]) for r in sel])
        for kind, col in (("as_made", "LwA_as_made_dB"), ("periodic", "LwA_dB")):
            fit = np.polyfit(x, [float(r[col]) for r in sel], 1)[0]
            assert laws[route][kind] == pytest.approx(fit, abs=2e-3), (route, kind)
    assert "speed law" in (on / "summary.txt").read_text()


def test_pitch_models_through_the_run_up_spectrum(coarse):
    """runup.as_made_pitch: "runout" differs from "none" (the flanks alone) only at wheel orders 72 n +- 1 (the
    wheel's order-1 sinusoid) and 72 n +- 3 (the pinion's), and there it adds power; "independent" puts more power
    than "runout" into the bands of harmonics 4-5 (wheel orders 256-403), where the helix averages the tooth-periodic
    terms."""
    _, src, _, _ = coarse
    spec = {m: am.deviation_spectrum(src, 2000.0, 5, pitch_samples=2000, pitch_model=m)
            for m in ("independent", "runout", "none")}
    z2 = int(src.pair.teeth[1])
    q = np.rint(spec["none"].orders).astype(int)
    assert np.allclose(spec["none"].orders, q)
    near = np.isin(np.minimum(q % z2, (-q) % z2), (1, 3))
    extra = spec["runout"].power - spec["none"].power
    assert np.all(np.abs(extra[~near]) <= 1e-12 * spec["none"].power.max())
    assert np.all(extra[near & (q < 9 * z2)] > 0)
    high = (q >= 256) & (q <= 403)
    assert np.sum(spec["independent"].power[high]) > 2 * np.sum(spec["runout"].power[high])


def test_bad_pitch_model_is_one_line_exit_2_no_folder(tmp_path):
    import subprocess
    import sys

    out = tmp_path / "bad"
    proc = subprocess.run([sys.executable, "-m", "housingfe", "run", "test-gearbox-runup", "--set",
                           "runup.as_made_pitch=eccentric", "--out", str(out)], capture_output=True, text=True,
                          cwd=ROOT)
    assert proc.returncode == 2 and not out.exists()
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("housingfe: error: ")
    assert "runup.as_made_pitch: 'eccentric' is not a pitch-deviation model" in lines[0]
