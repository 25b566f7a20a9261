"""Which term makes a design variant's difference (housingfe.studies.variant_terms), on a synthetic family of two
variants whose term differences are known by construction: per-line levels through the run-up's own term split
(housingfe.runup.slopes.term_levels, total basis), the variant's excitation, bore loads, surface velocity and
radiation index shifted by known dB per speed.  A uniform shift of every line of a speed shifts its power-weighted
total by the same dB and leaves the power-weighted A-weighting alone, so each term's mean difference over
800-1500 rev/min is the mean of its shifts there (the 500 rev/min speed, outside, shifted wildly, must not count)."""
import csv

import numpy as np
import pytest

from housingfe.runup.slopes import term_levels
from housingfe.studies import design_variants as dv
from housingfe.studies import variant_terms as vt

SPEEDS = np.array([500.0, 800.0, 1150.0, 1500.0])
HARMONICS = (1, 2, 3)
AREA_DB = 3.0
# shifts of the variant per speed (dB): excitation, T_path (bore loads - excitation), T_housing (L_v - bore), sigma
D_EXC = np.array([30.0, 2.0, 1.0, 3.0])
D_PATH = np.array([-40.0, 3.0, 4.0, 5.0])
D_HOUSING = np.array([20.0, -1.0, -2.0, -6.0])
D_SIGMA = np.array([10.0, 0.5, 0.0, 1.0])


def _curves(shift: bool):
    """(speeds, {term: levels}) and the L_WA curve of one synthetic variant: three harmonics per speed with
    different levels (the lines' powers differ, so the totals are true power-weighted means)."""
    point = np.repeat(np.arange(len(SPEEDS)), len(HARMONICS))
    harmonic = np.tile(HARMONICS, len(SPEEDS))
    frequency = harmonic * SPEEDS[point] / 60.0 * 26            # 26 teeth: 220 Hz - 2 kHz, A-weighting varies
    exc = 60.0 - 8.0 * (harmonic - 1) + 0.01 * SPEEDS[point]
    bore = exc + 10.0 + 2.0 * harmonic
    L_v = bore - 30.0 + 5.0 * np.sin(harmonic + point)
    sigma = -3.0 + 0.5 * harmonic
    if shift:
        exc = exc + D_EXC[point]
        bore = bore + (D_EXC + D_PATH)[point]
        L_v = L_v + (D_EXC + D_PATH + D_HOUSING)[point]
        sigma = sigma + D_SIGMA[point]
    lv = term_levels(point, len(SPEEDS), harmonic, frequency, exc, L_v, sigma, AREA_DB, "total", bore)
    terms = {k: v for k, v in lv.items() if k in vt.KEPT}
    return SPEEDS.copy(), terms


def test_two_variants_term_differences_are_the_known_shifts():
    (s, ref), (_, var) = _curves(False), _curves(True)
    d = vt.decompose_difference(s, var, s, ref)
    inside = slice(1, 4)                                 # 800, 1150, 1500 rev/min
    assert d["speeds_in_mean"] == 3
    assert d["d_excitation_dB"] == pytest.approx(D_EXC[inside].mean(), abs=1e-9)         # 2.0
    assert d["d_transfer_path_dB"] == pytest.approx(D_PATH[inside].mean(), abs=1e-9)     # 4.0
    assert d["d_transfer_housing_dB"] == pytest.approx(D_HOUSING[inside].mean(), abs=1e-9)   # -3.0
    assert d["d_L_sigma_dB"] == pytest.approx(D_SIGMA[inside].mean(), abs=1e-9)         # 0.5
    assert d["d_A_weighting_dB"] == pytest.approx(0.0, abs=1e-9)
    assert d["d_L_S_dB"] == 0.0
    assert d["d_transfer_dB"] == pytest.approx((D_PATH + D_HOUSING)[inside].mean(), abs=1e-9)
    assert d["mean_diff_dB"] == pytest.approx(3.5, abs=1e-9)          # 2 + 4 - 3 + 0.5
    assert abs(d["residual_dB"]) < 1e-9
    assert d["largest_term"] == "transfer_path"


def test_a_study_result_writes_the_terms_beside_unchanged_tables(tmp_path):
    fam = dv.families()["bearings"]
    (s, ref), (_, var) = _curves(False), _curves(True)
    runs = {}
    for key, terms in (("ball", ref), ("angular_contact", ref), ("self_aligning", var), ("tapered_roller", ref)):
        runs[key] = dv.VariantRun(fam.variant(key), {"r": (s, terms["L_WA"])}, "built", 0.0, 0.0,
                                  terms={"r": (s, terms)})
    result = dv.analyse(dv.StudyResult(fam, "face-width", "erp", ("r",), runs))
    plain = dv.analyse(dv.StudyResult(fam, "face-width", "erp", ("r",),
                                      {k: dv.VariantRun(r.variant, r.curves, "built", 0.0, 0.0)
                                       for k, r in runs.items()}))
    assert result.rows == plain.rows and plain.terms == []             # the comparison itself is unchanged
    sa = next(r for r in result.terms if r["variant"] == "self_aligning")
    assert sa["mean_diff_dB"] == pytest.approx(3.5) and sa["measured_mean_dB"] == -5.1
    assert next(r for r in result.terms if r["variant"] == "ball")["largest_term"] == ""
    dv.write(tmp_path, result)
    with open(tmp_path / "variant_terms.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["variant"] for r in rows] == ["ball", "angular_contact", "self_aligning", "tapered_roller"]
    r = rows[2]
    assert float(r["d_transfer_path_dB"]) == pytest.approx(4.0, abs=1e-3)
    assert sum(float(r[f"d_{t}_dB"]) for t in vt.DELTA_TERMS) == pytest.approx(float(r["mean_diff_dB"]), abs=5e-3)
    md = (tmp_path / "bearings.md").read_text()
    assert "| r | self_aligning | +3.50 | +2.00 | +4.00 | -3.00 | +0.50 | +0.00 |" in md
    assert "largest transfer_path" in dv.summary_text(result)


def test_speeds_that_do_not_line_up_are_refused():
    (s, ref), (_, var) = _curves(False), _curves(True)
    with pytest.raises(ValueError, match="speeds"):
        vt.decompose_difference(s + 1.0, var, s, ref)
    with pytest.raises(ValueError, match="speeds"):
        vt.decompose_difference(s, var, s, ref, (s[:3], var["L_WA"][:3]), (s, ref["L_WA"]))
