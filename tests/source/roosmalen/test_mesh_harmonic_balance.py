"""The harmonic balance of the time-varying mesh on any structure's receptance (dynamics.mesh_harmonic_balance,
issue 28 item 2):

* on the rigid-bore lumped interior it is the existing harmonic balance (any reference stiffness), to 1e-9;
* on a small coupled system (the lumped interior on a flexible two-mass "housing" instead of rigid bores) it equals
  the full Hill (harmonic-balance) system assembled directly on all DOFs, per harmonic of the mesh deflection, to
  1e-8;
* with the quasi-static receptance g = 1/k_ref at every harmonic it gives the quasi-static compression
  (F - F_e)/S exactly (the zero-speed limit, analytic);
* the first-order (mean-stiffness) solve agrees with the full one within the ripple of S(t).
"""
import math

import numpy as np
import pytest
import scipy.linalg as sla

from housingfe.source.roosmalen import dynamics as dyn
from tests.source.roosmalen.test_dynamics import GEOMETRY, K_MEAN, PAIR

H = 12


def _wave(n=128, rel=0.05):
    t = np.arange(n) / n
    S = K_MEAN * (1 + rel * np.cos(2 * math.pi * t) + 0.3 * rel * np.sin(4 * math.pi * t))
    shock = 2e3 * (np.cos(2 * math.pi * t + 0.4) + 0.4 * np.cos(6 * math.pi * t))
    return S, shock


def _coupled_system():
    """The 14-DOF lumped interior with its bearings on two 5-DOF bore masses (pinion side, wheel side) that sit on
    springs to ground and are tied to each other: 24 DOFs, M, K0 (no mesh), h, modal damping of the mean system."""
    it = dyn.derive_interior(PAIR, GEOMETRY, 0.1)
    lumped = dyn.assemble(PAIR, it, K_MEAN)
    n = 24
    M = np.zeros((n, n))
    K0 = np.zeros((n, n))
    M[:14, :14] = lumped.M
    K0[:14, :14] = lumped.K0
    bores = {"pinion": (np.arange(5), np.arange(14, 19), it.pinion_bearings),
             "wheel": (np.arange(6, 11), np.arange(19, 24), it.wheel_bearings)}
    for shaft, bore, kb in bores.values():
        for i, j, k in zip(shaft, bore, kb):          # the bearing now ends on the bore mass, not on ground
            K0[i, j] -= k
            K0[j, i] -= k
            K0[j, j] += k
        M[bore, bore] = [30.0, 30.0, 30.0, 0.8, 0.8]
        K0[bore, bore] += [4e8, 6e8, 2e8, 3e6, 3e6]     # housing stiffness to ground
    tie = np.array([2e8, 2e8, 1e8, 1e6, 1e6])
    a, b = np.arange(14, 19), np.arange(19, 24)
    K0[a, a] += tie
    K0[b, b] += tie
    K0[a, b] -= tie
    K0[b, a] -= tie
    h = np.zeros(n)
    h[:14] = lumped.h
    w2, phi = sla.eigh(K0 + K_MEAN * np.outer(h, h), M)
    Mphi = M @ phi
    D = Mphi @ np.diag(2 * 0.04 * np.sqrt(w2)) @ Mphi.T
    f0 = np.zeros(n)
    f0[:14] = dyn.preload_force(lumped, 2000.0)
    return M, K0, D, h, f0


def _full_hill(M, K0, D, h, f0, S, shock, Om, H):
    """Two-sided harmonics q_n (2H+1, N) of M q'' + D q' + (K0 + S(t) h h^T) q = f0 - F_e(t) h, assembled as one
    block system on every DOF and harmonic (the direct harmonic balance of the full model)."""
    N = len(h)
    n = np.arange(-H, H + 1)
    X = dyn._fourier_coefficients(S, H)
    E = dyn._fourier_coefficients(shock, H)[H:3 * H + 1]
    hh = np.outer(h, h)
    A = np.zeros((n.size * N, n.size * N), complex)
    rhs = np.zeros(n.size * N, complex)
    for i, ni in enumerate(n):
        A[i * N:(i + 1) * N, i * N:(i + 1) * N] += K0 - (ni * Om) ** 2 * M + 1j * ni * Om * D
        for j, nj in enumerate(n):
            A[i * N:(i + 1) * N, j * N:(j + 1) * N] += X[ni - nj + 2 * H] * hh
        rhs[i * N:(i + 1) * N] = (f0 if ni == 0 else 0.0) - E[i] * h
    return np.linalg.solve(A, rhs).reshape(n.size, N)


def _receptance(M, K0, D, h, f0, k_ref, Om, H):
    K = K0 + k_ref * np.outer(h, h)
    g = np.array([h @ np.linalg.solve(K - (n * Om) ** 2 * M + 1j * n * Om * D, h) for n in range(H + 1)])
    return g, float(h @ np.linalg.solve(K, f0))


@pytest.mark.parametrize("engagement", ["thesis-2d", "face-width"])
def test_on_the_rigid_bore_interior_it_is_the_harmonic_balance(engagement):
    from housingfe.drivetrain.description import test_gearbox

    src = test_gearbox("A").source_model(engagement=engagement)
    op = src._point(2000.0)
    f_t = src.pair.tooth_frequency(1000.0)
    st = op.steady_state(src.pair, 1000.0, 30)
    d_ref = st.Q @ op.mats.h
    for k_ref in (op.curve.mean, 0.7 * op.curve.mean):       # any constant part may sit in the structure
        g, b0 = dyn.lumped_receptance(op.mats, op.f0, f_t, 30, k_ref)
        ms = dyn.mesh_harmonic_balance(g, b0, op.S, op.shock, k_ref, f_t)
        scale = np.abs(d_ref[31:]).max()
        np.testing.assert_allclose(ms.compression, d_ref, rtol=0, atol=1e-9 * scale)
        np.testing.assert_allclose(ms.mesh_force, st.mesh_force, rtol=0, atol=1e-9 * np.abs(st.mesh_force[31:]).max())


@pytest.mark.parametrize("tooth_hz", [150.0, 420.0, 1300.0])
def test_equals_the_full_harmonic_balance_of_a_coupled_system(tooth_hz):
    M, K0, D, h, f0 = _coupled_system()
    S, shock = _wave()
    Om = 2 * math.pi * tooth_hz
    q = _full_hill(M, K0, D, h, f0, S, shock, Om, H)
    d_full = q @ h
    g, b0 = _receptance(M, K0, D, h, f0, K_MEAN, Om, H)
    ms = dyn.mesh_harmonic_balance(g, b0, S, shock, K_MEAN, tooth_hz)
    scale = np.abs(d_full[H + 1:]).max()
    np.testing.assert_allclose(ms.compression, d_full, rtol=0, atol=1e-8 * scale)
    assert abs(ms.compression[H] - d_full[H]) <= 1e-10 * abs(d_full[H])


def test_quasi_static_receptance_gives_the_quasi_static_compression():
    S, shock = _wave()
    F = 5e4
    g = np.full(H + 1, 1 / K_MEAN, complex)
    ms = dyn.mesh_harmonic_balance(g, F / K_MEAN, S, shock, K_MEAN)
    qs = dyn._fourier_coefficients(dyn.quasi_static_compression(S, shock, F), H)[H:3 * H + 1]
    # exact up to the harmonics beyond H that the truncated Toeplitz system drops (S's content stops at n = 2)
    np.testing.assert_allclose(ms.compression[H - 6:H + 7], qs[H - 6:H + 7], rtol=0, atol=1e-12 * abs(qs[H]))
    assert ms.mesh_force[H].real == pytest.approx(F, rel=1e-12)


@pytest.mark.parametrize("tooth_hz", [150.0, 420.0])
def test_first_order_solve_agrees_within_the_ripple(tooth_hz):
    M, K0, D, h, f0 = _coupled_system()
    S, shock = _wave(rel=0.02)
    Om = 2 * math.pi * tooth_hz
    g, b0 = _receptance(M, K0, D, h, f0, K_MEAN, Om, H)
    full = dyn.mesh_harmonic_balance(g, b0, S, shock, K_MEAN, tooth_hz)
    first = dyn.mesh_harmonic_balance(g, b0, S, shock, K_MEAN, tooth_hz, first_order=True)
    ripple = np.abs(np.fft.rfft(S)[1:]).max() * 2 / S.size / S.mean()
    for n in (1, 2, 3):
        rel = abs(first.excitation[H + n] - full.excitation[H + n]) / abs(full.excitation[H + n])
        assert rel <= ripple, (n, rel, ripple)
        assert rel > 1e-6          # it is an approximation: the parametric feedback is missing
