"""Timoshenko shaft elements against analytic beam solutions."""
import math

import numpy as np
import pytest
from scipy.linalg import eigh

from housingfe.drivetrain.shafts import (
    STEEL,
    CircularSection,
    Material,
    RigidDisc,
    Shaft,
    beam_element_matrices,
    dof,
    local_beam_matrices,
)
from housingfe.errors import InputError

E, NU, RHO = STEEL.youngs_modulus, STEEL.poisson_ratio, STEEL.density
G = STEEL.shear_modulus


def clamp(k, m, fixed):
    keep = np.setdiff1d(np.arange(k.shape[0]), fixed)
    return k[np.ix_(keep, keep)], m[np.ix_(keep, keep)], keep


def natural_frequencies(k, m, n):
    """Lowest n frequencies [Hz] of a supported structure (K positive definite); solved as M v = mu K v,
    mu = 1/omega^2, which stays accurate when M is nearly singular (massless shaft in the disc test)."""
    mu = eigh(m, k, eigvals_only=True)[::-1][:n]
    return 1.0 / np.sqrt(np.maximum(mu, 1e-300)) / (2 * math.pi)


@pytest.mark.parametrize("n_el", [1, 4])
@pytest.mark.parametrize("axis", [(0, 0, 1), (1, 1, 1), (1, -2, 0.5)])
def test_cantilever_tip_deflection_with_shear(n_el, axis):
    # delta = P L^3 / (3 E I) + P L / (kappa G A): exact for the interdependent Timoshenko element
    d, length, load = 0.06, 0.15, 1000.0                    # stubby: shear adds ~9 %
    shaft = Shaft.stepped([(length, d)], axis=axis, elements_per_segment=n_el)
    k, _ = shaft.matrices()
    sec = CircularSection(d)
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    transverse = np.cross(a, [0.3, 0.5, 0.7])
    transverse /= np.linalg.norm(transverse)
    f = np.zeros(shaft.n_dofs)
    tip = len(shaft.nodes) - 1
    f[6 * tip:6 * tip + 3] = load * transverse
    kr, _, keep = clamp(k, k, np.arange(6))
    u = np.zeros(shaft.n_dofs)
    u[keep] = np.linalg.solve(kr, f[keep])
    bending = load * length**3 / (3 * E * sec.second_moment)
    shear = load * length / (sec.shear_factor(NU) * G * sec.area)
    assert u[6 * tip:6 * tip + 3] @ transverse == pytest.approx(bending + shear, rel=1e-10)
    assert shear / bending > 0.05


def test_stepped_cantilever_by_unit_load_method():
    # two sections: delta = int M m / EI + int V v / (kappa G A), M = P (L - x), V = P
    (l1, d1), (l2, d2), p = (0.2, 0.08), (0.3, 0.05), 500.0
    shaft = Shaft.stepped([(l1, d1), (l2, d2)], elements_per_segment=[2, 3])
    k, _ = shaft.matrices()
    kr, _, keep = clamp(k, k, np.arange(6))
    f = np.zeros(shaft.n_dofs)
    f[dof(len(shaft.nodes) - 1, 1)] = p
    u = np.zeros(shaft.n_dofs)
    u[keep] = np.linalg.solve(kr, f[keep])
    s1, s2 = CircularSection(d1), CircularSection(d2)
    length = l1 + l2
    bend = p / (3 * E) * ((length**3 - l2**3) / s1.second_moment + l2**3 / s2.second_moment)
    shear = p * l1 / (s1.shear_factor(NU) * G * s1.area) + p * l2 / (s2.shear_factor(NU) * G * s2.area)
    assert u[dof(len(shaft.nodes) - 1, 1)] == pytest.approx(bend + shear, rel=1e-10)


def simply_supported(shaft):
    k, m = shaft.matrices()
    last = len(shaft.nodes) - 1
    # pin both ends in x, y, z; stop torsion at one end; bending rotations free
    fixed = [dof(0, 0), dof(0, 1), dof(0, 2), dof(0, 5), dof(last, 0), dof(last, 1)]
    return clamp(k, m, fixed)


def test_slender_simply_supported_matches_euler_bernoulli():
    d, length = 0.01, 1.0                      # L/d = 100: shear and rotary inertia below 0.1 %
    shaft = Shaft.stepped([(length, d)], elements_per_segment=20)
    kr, mr, _ = simply_supported(shaft)
    f = natural_frequencies(kr, mr, 6)
    sec = CircularSection(d)
    eb = [(n * math.pi / length) ** 2 * math.sqrt(E * sec.second_moment / (RHO * sec.area)) / (2 * math.pi)
          for n in (1, 2, 3)]
    # every bending frequency appears twice (two planes)
    assert f[0::2][:3] == pytest.approx(eb, rel=2e-3)
    assert f[1::2][:3] == pytest.approx(eb, rel=2e-3)


def timoshenko_simply_supported(n, length, sec, kappa):
    # det [[kGA k^2 - rhoA w^2, -kGA k], [-kGA k, EI k^2 + kGA - rhoI w^2]] = 0, smaller root in w^2
    k = n * math.pi / length
    kga, rho_a, rho_i, ei = kappa * G * sec.area, RHO * sec.area, RHO * sec.second_moment, E * sec.second_moment
    a = rho_a * rho_i
    b = -(rho_a * (ei * k**2 + kga) + rho_i * kga * k**2)
    c = kga * k**2 * ei * k**2
    w2 = (-b - math.sqrt(b * b - 4 * a * c)) / (2 * a)
    return math.sqrt(w2) / (2 * math.pi)


def test_stubby_simply_supported_matches_timoshenko_theory():
    d, length = 0.1, 0.4                       # L/d = 4: shear and rotary inertia lower the frequencies
    shaft = Shaft.stepped([(length, d)], elements_per_segment=40)
    kr, mr, _ = simply_supported(shaft)
    sec = CircularSection(d)
    f = natural_frequencies(kr, mr, 12)
    bending = np.unique(np.round(f, 3))
    exact = [timoshenko_simply_supported(n, length, sec, sec.shear_factor(NU)) for n in (1, 2)]
    eb = [(n * math.pi / length) ** 2 * math.sqrt(E * sec.second_moment / (RHO * sec.area)) / (2 * math.pi)
          for n in (1, 2)]
    found = [bending[np.argmin(np.abs(bending - x))] for x in exact]
    assert found == pytest.approx(exact, rel=2e-3)
    assert exact[1] < 0.85 * eb[1]            # the correction matters for this beam


def test_free_free_has_six_rigid_modes_and_exact_rigid_inertia():
    d, length = 0.015, 0.8                     # L/d = 53: Euler–Bernoulli within 0.1 %
    shaft = Shaft.stepped([(length, d)], axis=(1, 2, 2), elements_per_segment=16)
    k, m = shaft.matrices()
    w2 = eigh(k, m, eigvals_only=True)
    sec = CircularSection(d)
    first_elastic = (4.730041 / length) ** 2 * math.sqrt(E * sec.second_moment / (RHO * sec.area)) / (2 * math.pi)
    f = np.sqrt(np.abs(w2)) / (2 * math.pi)
    assert np.all(f[:6] < 1e-3 * first_elastic)
    assert f[6] == pytest.approx(first_elastic, rel=3e-3)
    # rigid body fields: u = t + omega x (x - centre), theta = omega; kinetic energies exact
    a = shaft.axis
    centre = shaft.nodes.mean(axis=0)
    total_mass = RHO * sec.area * length
    transverse_inertia = total_mass * length**2 / 12 + RHO * sec.second_moment * length

    def rigid(t, omega):
        u = np.zeros(shaft.n_dofs)
        for i, x in enumerate(shaft.nodes):
            u[6 * i:6 * i + 3] = t + np.cross(omega, x - centre)
            u[6 * i + 3:6 * i + 6] = omega
        return u

    for t in np.eye(3):
        u = rigid(t, np.zeros(3))
        assert u @ m @ u == pytest.approx(total_mass, rel=1e-12)
        assert np.max(np.abs(k @ u)) < 1e-6
    spin = rigid(np.zeros(3), a)
    assert spin @ m @ spin == pytest.approx(RHO * sec.polar_moment * length, rel=1e-12)
    tumble = rigid(np.zeros(3), np.cross(a, [1.0, 0, 0]) / np.linalg.norm(np.cross(a, [1.0, 0, 0])))
    assert tumble @ m @ tumble == pytest.approx(transverse_inertia, rel=1e-12)
    assert np.max(np.abs(k @ tumble)) < 1e-6 * np.max(np.abs(k))


def test_cantilever_with_disc_matches_spring_mass():
    # a (nearly) massless cantilever with a tip disc: f = sqrt(k/m)/2pi with k = 1/(L^3/3EI + L/kGA),
    # and the tip-rotation mode sees the disc's diametral inertia
    d, length = 0.03, 0.3
    light = Material("light", E, NU, 1e-6)
    shaft = Shaft.stepped([(length, d)], material=light, elements_per_segment=4)
    disc = RigidDisc.cylinder(0.2, 0.04)
    shaft.add_disc(len(shaft.nodes) - 1, disc)
    k, m = shaft.matrices()
    kr, mr, _ = clamp(k, m, np.arange(6))
    sec = CircularSection(d)
    k_tip = 1.0 / (length**3 / (3 * E * sec.second_moment) + length / (sec.shear_factor(NU) * G * sec.area))
    axial = E * sec.area / length
    torsion = G * sec.polar_moment / length
    f = natural_frequencies(kr, mr, kr.shape[0])
    assert math.sqrt(torsion / disc.polar_inertia) / (2 * math.pi) == pytest.approx(
        f[np.argmin(np.abs(f - math.sqrt(torsion / disc.polar_inertia) / (2 * math.pi)))], rel=1e-6)
    assert math.sqrt(axial / disc.mass) / (2 * math.pi) == pytest.approx(
        f[np.argmin(np.abs(f - math.sqrt(axial / disc.mass) / (2 * math.pi)))], rel=1e-6)
    # the lowest pair couples translation and tilt: with I_d = 0 it would be sqrt(k_tip/m)
    assert f[0] < math.sqrt(k_tip / disc.mass) / (2 * math.pi)
    disc_point = RigidDisc(disc.mass, disc.polar_inertia, 0.0)
    point = Shaft.stepped([(length, d)], material=light, elements_per_segment=4)
    point.add_disc(len(point.nodes) - 1, disc_point)
    kp, mp = point.matrices()
    kr, mr, _ = clamp(kp, mp, np.arange(6))
    assert natural_frequencies(kr, mr, 1)[0] == pytest.approx(math.sqrt(k_tip / disc.mass) / (2 * math.pi),
                                                              rel=1e-6)


def test_disc_of_cylinder_inertia():
    disc = RigidDisc.cylinder(0.2, 0.05, 0.06, rho=7850.0)
    m = 7850 * math.pi * (0.1**2 - 0.03**2) * 0.05
    assert disc.mass == pytest.approx(m)
    assert disc.polar_inertia == pytest.approx(m * (0.1**2 + 0.03**2) / 2)
    assert disc.diametral_inertia == pytest.approx(m * (3 * (0.1**2 + 0.03**2) + 0.05**2) / 12)


def test_local_matrices_symmetric_and_euler_bernoulli_limit():
    sec = CircularSection(0.01)
    k, m = local_beam_matrices(1.0, sec, STEEL)          # Phi ~ 2e-4: Euler–Bernoulli limit
    assert np.allclose(k, k.T) and np.allclose(m, m.T)
    ei = E * sec.second_moment
    assert k[1, 1] == pytest.approx(12 * ei, rel=1e-3)
    assert k[5, 5] == pytest.approx(4 * ei, rel=1e-3)
    assert k[4, 10] == pytest.approx(2 * ei, rel=1e-3)
    assert m[1, 1] == pytest.approx(RHO * sec.area * 13 / 35 + RHO * sec.second_moment * 6 / 5, rel=1e-3)
    ke, me = beam_element_matrices((0, 0, 0), (0.3, 0.1, -0.2), sec)
    assert np.all(np.linalg.eigvalsh(ke) > -1e-6 * np.max(ke)) and np.all(np.linalg.eigvalsh(me) > 0)


def test_bad_input():
    with pytest.raises(InputError):
        CircularSection(0.02, 0.03)
    with pytest.raises(InputError):
        Shaft.stepped([(-0.1, 0.02)])
    with pytest.raises(InputError):
        Material("negative", -1.0, NU, RHO)


def test_stiff_shaft_on_two_bearings_rigid_body_frequencies():
    # a short, very stiff shaft (E x 1e4) on two identical supports at its ends behaves as a rigid body:
    # bounce sqrt(2 k / m), rocking sqrt((2 k (L/2)^2 + 2 k_t) / I_d), with I_d of the rod about its centre
    d, length = 0.05, 0.4
    stiff = Material("stiff", E * 1e4, NU, RHO)
    shaft = Shaft.stepped([(length, d)], material=stiff, elements_per_segment=8)
    k_r, k_a, k_t = 4e8, 1e8, 2e5
    support = np.diag([k_r, k_r, k_a, k_t, k_t, 0.0])
    shaft.add_support(0, support)
    shaft.add_support(len(shaft.nodes) - 1, support)
    k, m = shaft.matrices()
    sec = CircularSection(d)
    mass = RHO * sec.area * length
    i_d = mass * length**2 / 12 + RHO * sec.second_moment * length
    # torsion is free (bearings): drop it by holding theta_z at node 0
    kr, mr, _ = clamp(k, m, [dof(0, 5)])
    f = natural_frequencies(kr, mr, 6)
    bounce = math.sqrt(2 * k_r / mass) / (2 * math.pi)
    axial = math.sqrt(2 * k_a / mass) / (2 * math.pi)
    rock = math.sqrt((2 * k_r * (length / 2) ** 2 + 2 * k_t) / i_d) / (2 * math.pi)
    for expected in (bounce, axial, rock):
        assert f[np.argmin(np.abs(f - expected))] == pytest.approx(expected, rel=1e-3)
    with pytest.raises(InputError):
        shaft.add_support(0, np.eye(5))
