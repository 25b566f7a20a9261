"""Which term makes the speed law (housingfe.runup.slopes).

* Synthetic lines with known laws: an excitation growing with speed^2 (+40 lg 2 = 12.04 dB per doubling) through
  a constant transfer gives 12.04 for the excitation and 0 for the transfer, on the tooth band and on the total
  (a spectrum of constant shape); a transfer falling as 1/f gives -6.02; the A-weighting term is the IEC 61672
  curve at the tooth frequency (published values at 100 / 200 / 500 Hz); the terms add up to L_WA's slope.
* On a coupled run-up (the coarse test gearbox of test_chain.py): the terms are the chain's own quantities
  (TF_omega on the tooth line, L_v, L_WA per line and in total) and their slopes add up to the slope of the
  chain's L_WA: exactly (round-off) on the tooth band, and with the power-weighted total terms on the total.
* The CLI writes slope_terms.csv / .png, the slope lines in summary.txt and the speed-law check naming a term.
"""
import csv
import json
import math

import numpy as np
import pytest

from housingfe import levels
from housingfe.runup.slopes import (
    TERMS,
    SlopeDecomposition,
    decompose,
    decompose_all,
    slope_per_doubling,
    term_levels,
)
from tests.test_cli import housingfe

SPEEDS = np.arange(250.0, 1501.0, 250.0)
PER_DOUBLING_SQUARED = 40.0 * math.log10(2.0)       # 12.041 dB: a quantity proportional to speed^2


def _lines(excitation_of, transfer_of, harmonics=(1, 2, 3)):
    """Per-line arrays of a synthetic run-up: tooth frequency 0.4 Hz per rpm (Eq. 5.3)."""
    point, harm, freq, exc, lv = [], [], [], [], []
    for p, s in enumerate(SPEEDS):
        for n in harmonics:
            f = 0.4 * s * n
            point.append(p)
            harm.append(n)
            freq.append(f)
            exc.append(excitation_of(s, n))
            lv.append(exc[-1] + transfer_of(f))
    return np.array(point), np.array(harm), np.array(freq), np.array(exc), np.array(lv)


def _decomposition(basis, excitation_of, transfer_of, area_level=-1.2):
    point, harm, freq, exc, lv = _lines(excitation_of, transfer_of)
    lev = term_levels(point, len(SPEEDS), harm, freq, exc, lv, np.zeros(len(lv)), area_level, basis)
    return SlopeDecomposition("synthetic", "erp", 2000.0, basis, "exc", "T", SPEEDS, lev), (point, harm, freq, lv)


@pytest.mark.parametrize("basis", ["tooth_band", "total"])
def test_excitation_with_speed_squared_through_a_constant_transfer(basis):
    # the harmonics keep a fixed shape (-6 dB per harmonic number) so the total grows like each line
    d, _ = _decomposition(basis, lambda s, n: 100.0 + 40.0 * math.log10(s / 250.0) - 6.0 * (n - 1), lambda f: -20.0)
    assert d.slopes["excitation"] == pytest.approx(PER_DOUBLING_SQUARED, abs=1e-9)
    assert d.slopes["transfer"] == pytest.approx(0.0, abs=1e-9)
    assert d.slopes["L_sigma"] == pytest.approx(0.0, abs=1e-9)
    assert d.slopes["L_S"] == pytest.approx(0.0, abs=1e-12)
    assert d.slopes["L_v"] == pytest.approx(PER_DOUBLING_SQUARED, abs=1e-9)
    assert d.slopes["L_W"] == pytest.approx(PER_DOUBLING_SQUARED, abs=1e-9)
    assert d.term_sum == pytest.approx(d.slopes["L_WA"], abs=1e-9)
    assert d.made_by == "excitation"
    if basis == "tooth_band":
        # the A-weighting term is the A-curve at the tooth frequency: IEC 61672-1 table (0.1 dB, at the exact
            # mid-band frequencies), 100/200/500 Hz
        for speed, published in ((250.0, -19.1), (500.0, -10.9), (1250.0, -3.2)):
            assert d.levels["A_weighting"][list(SPEEDS).index(speed)] == pytest.approx(published, abs=0.1)
        a_slope = np.polyfit(np.log2(SPEEDS), levels.a_weighting_db(0.4 * SPEEDS), 1)[0]
        assert d.slopes["A_weighting"] == pytest.approx(a_slope, abs=1e-12)
        assert d.slopes["L_WA"] == pytest.approx(PER_DOUBLING_SQUARED + a_slope, abs=1e-9)


def test_transfer_falling_as_one_over_frequency():
    d, _ = _decomposition("tooth_band", lambda s, n: 40.0 * math.log10(s), lambda f: -20.0 * math.log10(f))
    assert d.slopes["transfer"] == pytest.approx(-20.0 * math.log10(2.0), abs=1e-9)     # -6.02
    assert d.slopes["L_v"] == pytest.approx(20.0 * math.log10(2.0), abs=1e-9)            # +6.02
    assert d.held_back_by == "transfer"
    assert d.sum_residual_db == pytest.approx(0.0, abs=1e-9)


def test_total_terms_are_power_weighted_and_add_up():
    # two harmonics whose share changes with speed: the total terms still add up to the total L_WA
    d, (point, harm, freq, lv) = _decomposition(
        "total", lambda s, n: 90.0 + (30.0 if n == 1 else 10.0) * math.log10(s), lambda f: -0.01 * f)
    power = np.zeros(len(SPEEDS))
    np.add.at(power, point, 10 ** ((lv - 1.2 + levels.a_weighting_db(freq)) / 10))
    np.testing.assert_allclose(d.levels["L_WA"], 10 * np.log10(power), atol=1e-9)
    parts = sum(d.levels[t] for t in TERMS)
    np.testing.assert_allclose(parts, d.levels["L_WA"], atol=1e-9)
    assert abs(d.sum_residual_db) < 1e-9


def test_slope_needs_a_doubling_of_speed():
    assert math.isnan(slope_per_doubling([1000.0, 1250.0, 1500.0], [1.0, 2.0, 3.0]))
    assert slope_per_doubling([250.0, 500.0, 1000.0], [70.0, 76.0, 82.0]) == pytest.approx(6.0)


@pytest.mark.slow
def test_the_terms_of_a_coupled_runup_add_up(coarse):
    gm, src, lines, res = coarse
    rows = res.harmonic_rows()
    for d in decompose_all(res):
        assert abs(d.sum_residual_db) < 1e-9, d.sentence()
        curve = [r for r in rows if r["route"] == d.route and r["radiation"] == d.radiation]
        if d.basis == "tooth_band":
            tooth = [r for r in curve if r["harmonic"] == 1]
            # the terms are the chain's own per-line quantities
            np.testing.assert_allclose(d.levels["L_WA"], [r["LwA_dB"] for r in tooth], atol=1e-9)
            np.testing.assert_allclose(d.levels["L_v"], [r["Lv_dB"] for r in tooth], atol=1e-9)
            if d.route == "tf_omega":
                np.testing.assert_allclose(d.levels["transfer"], [r["TF_omega_dB"] for r in tooth], atol=1e-9)
                np.testing.assert_allclose(d.levels["excitation"], [r["L_omega_dB"] for r in tooth], atol=1e-9)
            lwa = [r["LwA_dB"] for r in tooth]
        else:
            s, lwa = res.series(d.route, d.radiation, d.torque_nm, "LwA_dB")
            np.testing.assert_array_equal(s, d.speeds_rpm)
        assert d.term_sum == pytest.approx(slope_per_doubling(d.speeds_rpm, lwa), abs=1e-9)
    mf = decompose(res, "mesh_force", "erp", 2000.0, "tooth_band")
    first = [k for k in range(len(lines.point)) if lines.harmonic[k] == 1]
    np.testing.assert_allclose(mf.levels["excitation"], 20 * np.log10(np.abs(lines.mesh_excitation[first])),
                               atol=1e-9)


@pytest.mark.slow
def test_cli_writes_the_slope_terms(tmp_path):
    out = tmp_path / "run"
    proc = housingfe("run", "test-gearbox-runup", "--set", 'housing.set=["mesh.size=0.06"]', "--set",
                     "runup.f_max_hz=1500.0", "--set", "runup.speed_min_rpm=500.0", "--set",
                     "runup.speed_step_rpm=500.0", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    with open(out / "slope_terms.csv") as fh:
        rows = list(csv.DictReader(fh))
    # 2 routes x 2 radiators (the scene's erp and foller) x 2 bases x (5 terms + sum + 3 levels + the transfer's
    # split: path, housing, their sum, L_bore, L_bore_moment)
    assert len(rows) == 2 * 2 * 2 * 14
    for route in ("tf_omega", "mesh_force"):
        for basis in ("tooth_band", "total"):
            sel = {r["term"]: float(r["slope_dB_per_doubling"]) for r in rows
                   if r["route"] == route and r["basis"] == basis and r["radiation"] == "erp"}
            assert sel["sum of terms"] == pytest.approx(sel["L_WA"], abs=1e-6)
            # the CSV keeps 6 significant digits: five rounded terms sum to L_WA within their rounding
            assert sum(sel[t] for t in TERMS) == pytest.approx(sel["L_WA"], abs=5e-4)
            assert sel["path + housing"] == pytest.approx(sel["transfer"], abs=5e-4)
            assert sel["transfer_path"] + sel["transfer_housing"] == pytest.approx(sel["transfer"], abs=5e-4)
    split = json.loads((out / "runup.json").read_text())["slope_terms"]
    assert all(abs(s["split_residual_dB"]) < 1e-9 for s in split)
    assert (out / "slope_terms.png").stat().st_size > 10_000
    summary = (out / "summary.txt").read_text()
    assert "made by" in summary and "tf_omega (erp, 2000 N m, total): L_WA" in summary
    assert "= path" in summary and "T housing" in summary
    with open(out / "checks.csv") as fh:
        law = [r for r in csv.DictReader(fh) if r["check"] == "speed_law"]
    assert len(law) == 2 and all("made by" in r["note"] for r in law)
    # a speed law made by the transfer says whether its path or the housing makes it, with the split's slopes
    for r in law:
        route = r["quantity"].split(":")[0]
        sel = {t["term"]: float(t["slope_dB_per_doubling"]) for t in rows
               if t["route"] == route and t["basis"] == "total" and t["radiation"] == "erp"}
        if r["note"].startswith("made by transfer"):
            assert (f"= path {sel['transfer_path']:+.2f} + housing {sel['transfer_housing']:+.2f}, "
                    in r["note"].split(";")[0])
        else:
            assert "= path" not in r["note"].split(";")[0]
    assert "made by" in proc.stdout
    # set A (eps_beta 1.026) with the default face-width engagement: the overlap note, once (issue 28)
    notes = [ln for ln in summary.splitlines() if ln.startswith("NOTE: overlap ratio 1.026")]
    assert len(notes) == 1 and notes[0] in proc.stdout and "Lachenmaier" in notes[0]
    # ... and the run-up with the envelope bound on the same models: one line, its curves in runup_envelope_bound.csv
    # (the columns of runup.csv), its maxima above the default's (the bound's excitation lies 14-17 dB higher)
    bound = [ln for ln in summary.splitlines() if "with the envelope bound: max L_WA" in ln]
    assert len(bound) == 1 and bound[0] in proc.stdout
    with open(out / "runup.csv") as fh:
        default = list(csv.DictReader(fh))
    with open(out / "runup_envelope_bound.csv") as fh:
        enveloped = list(csv.DictReader(fh))
    assert list(enveloped[0]) == list(default[0]) and len(enveloped) == len(default)
    for route in ("tf_omega", "mesh_force"):
        top = max((float(r["LwA_dB"]), float(r["speed_rpm"])) for r in enveloped
                  if r["route"] == route and r["radiation"] == "erp")
        assert f"{top[0]:.1f} dB(A) @ {top[1]:g} rpm ({route})" in bound[0].split("default")[0]
        assert top[0] > max(float(r["LwA_dB"]) for r in default if r["route"] == route and r["radiation"] == "erp")
    # the bound's lines and its checks on the same curves (validate's rows 28.bound.*): the lines sum to its totals
    with open(out / "runup_envelope_bound_harmonics.csv") as fh:
        lines = list(csv.DictReader(fh))
    with open(out / "runup_harmonics.csv") as fh:
        assert list(lines[0]) == list(next(csv.DictReader(fh)))
    for r in enveloped:
        mine = [float(x["LwA_dB"]) for x in lines if (x["route"], x["radiation"], x["speed_rpm"])
                == (r["route"], r["radiation"], r["speed_rpm"])]
        assert 10 * np.log10(np.sum(10 ** (np.array(mine) / 10))) == pytest.approx(float(r["LwA_dB"]), abs=2e-4)
    bound_checks = json.loads((out / "runup.json").read_text())["envelope_bound"]["checks"]
    for route in ("tf_omega", "mesh_force"):
        top = max(float(r["LwA_dB"]) for r in enveloped if r["route"] == route and r["radiation"] == "erp")
        assert next(c["ours"] for c in bound_checks if c["check"] == "LwA_max" and c["quantity"].startswith(route)) \
            == round(top, 1)


def test_less_than_a_doubling_of_speed_reports_no_law(tmp_path):
    # a run-up of 1000-1500 rpm (as the MPI test's): no slope to fit, and every output says so instead of failing
    from housingfe.runup.slopes import plot, slope_rows, table

    point = np.repeat(np.arange(3), 2)
    speeds = np.array([1000.0, 1250.0, 1500.0])
    harm = np.tile([1, 2], 3)
    freq = 0.4 * speeds[point] * harm
    lev = term_levels(point, 3, harm, freq, np.full(6, 100.0), np.full(6, 90.0), np.zeros(6), -1.2, "total")
    d = SlopeDecomposition("r", "erp", 2000.0, "total", "exc", "T", speeds, lev)
    assert math.isnan(d.slopes["L_WA"]) and d.made_by == "" and d.held_back_by == ""
    assert "no speed law" in d.sentence()
    assert "r" in table([d]) and len(slope_rows([d])) == 9
    assert d.to_json()["slopes_dB_per_doubling"]["L_WA"] is None
    plot(tmp_path / "p.png", [d])               # nothing to draw: no file, no error
    assert not (tmp_path / "p.png").exists()
