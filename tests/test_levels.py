"""Levels and bands against hand-computed values and the standards."""
import numpy as np
import pytest

from housingfe import levels


def test_third_octave_edges_and_nominal_centres():
    b = levels.third_octave_bands(100, 4000)
    assert b.nominal[0] == 100 and b.nominal[-1] == 4000 and len(b.nominal) == 17
    assert b.center[3] == pytest.approx(1000 * 10 ** (-0.7), rel=1e-12)   # 199.53 Hz, nominal 200
    assert np.allclose(b.upper[:-1], b.lower[1:])                       # contiguous bands


def test_band_sum_by_hand():
    # lines at 100, 110, 120 Hz fall in the 100 Hz band (89.1..112.2) or the 125 Hz band (112.2..141.3)
    b = levels.third_octave_bands(100, 125)
    sums = levels.band_sum([100.0, 110.0, 120.0], [1.0, 2.0, 4.0], b)
    assert sums.tolist() == [3.0, 4.0]
    assert levels.level(3.0, 1.0) == pytest.approx(10 * np.log10(3.0))


def test_a_weighting_values_of_iec_61672():
    assert levels.a_weighting_db([100, 1000, 4000]) == pytest.approx([-19.1, 0.0, 1.0], abs=0.05)


def test_references_of_the_thesis():
    assert (levels.V0, levels.OMEGA0, levels.F0, levels.P0) == (5e-8, 5e-8, 1.0, 1e-12)
