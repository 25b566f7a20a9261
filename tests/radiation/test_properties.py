"""Property-based tests (hypothesis, issue 30 item 2) of the analytic radiators: finite, non-negative radiation
efficiencies that obey their invariants (a sphere's sigma below 1 and rising with ka, a cap's power share below
the whole pulsating sphere's, energy: power proportional to v_rms^2).  Derandomized for CI."""
from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from housingfe.radiation import analytic

SETTINGS = settings(max_examples=30, derandomize=True, deadline=None)
ka_values = st.lists(st.floats(1e-6, 50.0), min_size=1, max_size=20)


@SETTINGS
@given(ka=ka_values)
def test_sphere_and_piston_sigma_bounded(ka):
    x = np.sort(np.asarray(ka))
    s = analytic.sphere_sigma(x)
    assert np.all(np.isfinite(s)) and np.all((s >= 0) & (s < 1))
    assert np.all(np.diff(s) >= 0)
    p = analytic.piston_sigma(x)
    assert np.all(np.isfinite(p)) and np.all((p >= 0) & (p < 1.5))


@SETTINGS
@given(ka=st.floats(0.01, 20.0), half_angle=st.floats(0.05, math.pi))
def test_cap_sigma_finite_and_whole_sphere_limit(ka, half_angle):
    s = float(analytic.sphere_cap_sigma(ka, half_angle)[0])
    assert math.isfinite(s) and s >= 0
    if half_angle == math.pi:
        assert abs(s / float(analytic.sphere_sigma(ka)) - 1) < 1e-6


@SETTINGS
@given(radius=st.floats(0.01, 2.0), f=st.floats(1.0, 10000.0), v=st.floats(1e-9, 1.0))
def test_sphere_power_quadratic_in_velocity(radius, f, v):
    p1 = float(analytic.sphere_power(radius, f, velocity_rms_m_s=v))
    p2 = float(analytic.sphere_power(radius, f, velocity_rms_m_s=2 * v))
    assert math.isfinite(p1) and p1 > 0 and abs(p2 / p1 - 4) < 1e-12
    assert abs(float(analytic.sphere_power(radius, f, velocity_peak_m_s=math.sqrt(2) * v)) / p1 - 1) < 1e-12
