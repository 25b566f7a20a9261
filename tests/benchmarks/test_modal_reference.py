"""The extrapolated reference of `housingfe bench modal`: Richardson extrapolation recovers a known limit, and the
stored reference file says how it was produced and agrees with its own discrete solutions."""
import json

import numpy as np
import pytest

from housingfe.benchmarks.modal import REFERENCE_FILE, extrapolate


@pytest.mark.parametrize("rate", [0.7, 1.0, 1.5, 2.0, 4.0])
def test_extrapolation_recovers_the_limit_and_the_rate(rate):
    sizes = (0.030, 0.015, 0.010)
    limits = np.array([634.5, 1251.9, 3941.0])
    coeffs = np.array([2.0e3, -5.0e4, 8.0e4])            # converging from above and from below
    f = np.array([limits + coeffs * h ** rate for h in sizes])
    f_inf, p = extrapolate(sizes, f)
    assert np.allclose(f_inf, limits, rtol=1e-9)
    assert np.allclose(p, rate, rtol=1e-6)


def test_non_monotone_sequences_give_nan_not_a_number_that_looks_right():
    f_inf, p = extrapolate((0.03, 0.015, 0.01), np.array([[100.0], [99.0], [99.5]]))
    assert np.isnan(f_inf[0]) and np.isnan(p[0])


def test_stored_reference_is_the_extrapolation_of_its_discrete_solutions():
    data = json.loads(REFERENCE_FILE.read_text())
    assert "how_produced" in data and "extrapolation" in data["how_produced"].lower()
    sizes = data["case"]["sizes_m"]
    discrete = np.array([data["discrete_hz"][f"{h:.3f}"] for h in sizes])
    f_inf, _ = extrapolate(sizes, discrete)
    ref = np.asarray(data["frequencies_hz"])
    assert len(ref) == 36                                 # converged count of elastic modes below 4 kHz
    assert np.allclose(f_inf[:len(ref)], ref, atol=1e-3)
    # the finest mesh lies above the limit (stiff discretisation), by less than half a percent
    fine = discrete[-1][:len(ref)]
    assert np.all(fine > ref) and np.max(fine / ref - 1) < 5e-3
