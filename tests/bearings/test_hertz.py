"""Contact laws against textbook formulas (Johnson, Hamrock–Brewe, Harris) and against their own inverse."""
import math

import numpy as np
import pytest

from housingfe.bearings import hertz

E, NU = 208e9, 0.3
E_STAR = E / (2 * (1 - NU**2))          # Johnson's contact modulus of two equal bodies


def test_sphere_on_flat_matches_johnson():
    # Johnson (Contact Mechanics, Eq. 4.23): P = 4/3 E* R^1/2 delta^3/2
    radius = 0.011
    k = hertz.point_contact_constant(2.0 / radius, 0.0, E, NU)
    assert k == pytest.approx(4.0 / 3.0 * E_STAR * math.sqrt(radius), rel=1e-12)


def test_two_equal_spheres_match_johnson():
    # two spheres of radius R: effective radius R/2
    radius = 0.02
    k = hertz.point_contact_constant(4.0 / radius, 0.0, E, NU)
    assert k == pytest.approx(4.0 / 3.0 * E_STAR * math.sqrt(radius / 2), rel=1e-12)


@pytest.mark.parametrize("inner", [True, False])
def test_ball_groove_contact_matches_hamrock_brewe(inner):
    # Hamrock & Brewe (1983) curve fits: kappa = 1.0339 (Ry/Rx)^0.636, E(e) = 1.0003 + 0.5968 Rx/Ry,
    # K(e) = 1.5277 + 0.6023 ln(Ry/Rx), delta = K [9/(2 E R) (Q/(pi kappa E'))^2]^(1/3), E' = 2 E*.
    # They claim a few per cent accuracy; a 6312-like ball (22.22 mm, d_m 95 mm, f = 0.52/0.53).
    dw, dm, f = 22.22e-3, 95e-3, 0.52 if inner else 0.53
    gamma = dw / dm
    inv_rx = 2 / dw + (2 / dw * gamma / (1 - gamma) if inner else -2 / dw * gamma / (1 + gamma))
    inv_ry = 2 / dw - 1 / (f * dw)
    rx, ry = 1 / inv_rx, 1 / inv_ry
    r_eff = 1 / (inv_rx + inv_ry)
    kappa = 1.0339 * (ry / rx) ** 0.636
    ell_e = 1.0003 + 0.5968 * rx / ry
    ell_k = 1.5277 + 0.6023 * math.log(ry / rx)
    load = 3000.0
    delta_hb = ell_k * (9 / (2 * ell_e * r_eff) * (load / (math.pi * kappa * 2 * E_STAR)) ** 2) ** (1 / 3)
    total, diff = hertz.ball_race_curvatures(dw, dm, 0.0, f, inner)
    assert total == pytest.approx(inv_rx + inv_ry, rel=1e-12)
    assert hertz.ellipticity(diff) == pytest.approx(kappa, rel=0.03)
    k = hertz.point_contact_constant(total, diff, E, NU)
    assert (load / k) ** (2 / 3) == pytest.approx(delta_hb, rel=0.02)


def test_harris_steel_constant():
    # Harris: K = 2.15e5 (Sigma rho)^(-1/2) (delta*)^(-3/2) N/mm^1.5 for steel (E = 207.5 GPa, nu = 0.3)
    total, diff = hertz.ball_race_curvatures(17.46e-3, 102.5e-3, 0.0, 0.52, True)
    k = hertz.point_contact_constant(total, diff, 207.5e9, 0.3)
    d_star = hertz.dimensionless_deflection(hertz.ellipticity(diff))
    harris_n_per_mm15 = 2.15e5 * (total * 1e-3) ** -0.5 * d_star**-1.5
    assert k * 1e-3**1.5 == pytest.approx(harris_n_per_mm15, rel=2e-3)


def test_series_contacts_add_deflections():
    args = (22.22e-3, 95e-3, 0.0)
    k_i = hertz.point_contact_constant(*hertz.ball_race_curvatures(*args, 0.52, True), E, NU)
    k_o = hertz.point_contact_constant(*hertz.ball_race_curvatures(*args, 0.53, False), E, NU)
    k_n = hertz.ball_effective_stiffness(*args, 0.52, 0.53, E, NU)
    load = 5000.0
    assert (load / k_n) ** (2 / 3) == pytest.approx((load / k_i) ** (2 / 3) + (load / k_o) ** (2 / 3), rel=1e-12)


def test_palmgren_roller_constant():
    # Harris: delta = 3.84e-5 Q^0.9 / l^0.8 [mm, N] per contact; two contacts in series.
    length, load = 0.020, 4000.0
    k_n = hertz.roller_effective_stiffness(length, 207e9, 0.3)
    delta_mm = 2 * 3.84e-5 * load**0.9 / (length * 1e3) ** 0.8
    assert (load / k_n) ** 0.9 * 1e3 == pytest.approx(delta_mm, rel=1e-10)


def test_weber_banaschek_slice_law_inverts_and_differentiates():
    law = hertz.LineContactSlices(20e-3, 40e-3, 60e-3, 1e-3, E, NU)
    approach = np.array([-1e-6, 0.0, 1e-7, 1e-6, 5e-6, 2e-5])
    force, stiff = law.force_and_stiffness(approach)
    assert np.all(force[:2] == 0) and np.all(stiff[:2] == 0)
    assert law.deflection(force[2:]) == pytest.approx(approach[2:], rel=1e-10)
    h = 1e-10
    fd = (law.force_and_stiffness(approach[2:] + h)[0] - law.force_and_stiffness(approach[2:] - h)[0]) / (2 * h)
    assert stiff[2:] == pytest.approx(fd, rel=1e-5)
    # the energy is the integral of the force
    e = law.energy(np.array([1e-6, 1e-6 + h]))
    assert (e[1] - e[0]) / h == pytest.approx(law.force_and_stiffness(np.array([1e-6 + h / 2]))[0][0], rel=1e-4)
    # uniform line load p [N/m]: deflection independent of the slice length (ln(dl/F) constant)
    p = 2e5
    wide = hertz.LineContactSlices(20e-3, 40e-3, 60e-3, 4e-3, E, NU)
    assert law.deflection(np.array(p * 1e-3)) == pytest.approx(wide.deflection(np.array(p * 4e-3)), rel=1e-12)
