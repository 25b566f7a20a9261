"""Property-based tests (hypothesis, issue 30 item 2) of the cheap bearing and stability stages: over the valid
ranges no traceback, every output finite, and the invariants each owes.  Derandomized (fixed examples in CI)."""
from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from housingfe.bearings.fluid_film import (
    JournalBearing,
    lund_critical_mass,
    rotor_eigenvalues,
    short_bearing_coefficients,
)
from housingfe.solvers.harmonic import reduced_stability

SETTINGS = settings(max_examples=25, derandomize=True, deadline=None)

bearings = st.builds(JournalBearing, diameter=st.floats(0.02, 0.5), length=st.floats(0.005, 0.2),
                     clearance=st.floats(10e-6, 400e-6), viscosity=st.floats(0.002, 0.2))


@SETTINGS
@given(bearing=bearings, rpm=st.floats(100.0, 20000.0), load=st.floats(10.0, 50000.0),
       angle=st.floats(0.0, 2 * math.pi))
def test_short_bearing_coefficients_finite_and_damping_symmetric_psd(bearing, rpm, load, angle):
    """Ocvirk film: eccentricity in (0, 1), K and C finite, C symmetric positive semi-definite (a squeeze film
    only dissipates), the film force balancing the load (K's direct terms positive)."""
    w = (load * math.cos(angle), load * math.sin(angle))
    r = short_bearing_coefficients(bearing, rpm * 2 * math.pi / 60, w)
    assert 0 < r.eccentricity_ratio < 1
    k, c = r.K[:2, :2], r.C[:2, :2]
    assert np.all(np.isfinite(r.K)) and np.all(np.isfinite(r.C))
    # to the central differences' noise: ~1e-6 of the diagonal at eccentricity ~0 (a 14 N load on a 500 mm bearing)
    assert np.allclose(c, c.T, rtol=1e-4, atol=1e-5 * np.abs(c).max())
    assert np.linalg.eigvalsh(0.5 * (c + c.T)).min() > -1e-6 * np.abs(c).max()
    assert np.trace(k) > 0


@SETTINGS
@given(bearing=bearings, rpm=st.floats(100.0, 20000.0), load=st.floats(10.0, 50000.0),
       mass=st.floats(1.0, 2000.0))
def test_lund_threshold_agrees_with_the_eigenvalues(bearing, rpm, load, mass):
    """Routh-Hurwitz in Lund's form and the eigenvalues agree on stability wherever the margin is not marginal."""
    r = short_bearing_coefficients(bearing, rpm * 2 * math.pi / 60, (0.0, -load))
    m_crit, _ = lund_critical_mass(r.K, r.C)
    s = rotor_eigenvalues(mass, r.K, r.C)
    assert np.all(np.isfinite(s))
    if abs(mass / m_crit - 1) > 1e-3:
        assert (s.real.max() > 0) == (mass > m_crit)


@SETTINGS
@given(n=st.integers(2, 8), seed=st.integers(0, 10_000), damping=st.floats(0.0, 10.0))
def test_symmetric_systems_are_never_flagged_unstable(n, seed, damping):
    """Symmetric positive definite K and M with positive semi-definite C: no energy source, reduced_stability must
    stay silent (no false oil-whirl alarms on ordinary housings)."""
    rng = np.random.default_rng(seed)
    a, b = rng.normal(size=(n, n)), rng.normal(size=(n, n))
    K = a @ a.T + n * np.eye(n)
    M = b @ b.T + n * np.eye(n)
    c = rng.normal(size=(n, n))
    C = damping * c @ c.T
    lam = np.linalg.eigvals(np.linalg.solve(M, K)).real
    assert reduced_stability(K, M, C, lam) == []
