"""Contact laws of one rolling element: Hertz point contact (balls), Palmgren line contact (Lim's
roller model) and the Weber–Banaschek line-contact law of van Roosmalen (1994) Eq. (3.17).

All functions are in SI units (N, m).  Point contact follows Harris, *Rolling Bearing Analysis*
(Ch. 6 "Contact stress and deformation"): curvature sum and difference, ellipticity from the
complete elliptic integrals, then Q = K delta^(3/2).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

from housingfe.errors import InputError


def material_compliance(E: float, nu: float) -> float:
    """Xi = 2 (1 - nu^2) / E [m^2/N] for two bodies of the same material (Harris' sum of
    (1 - xi^2)/E over both bodies)."""
    if E <= 0 or not (0.0 <= nu < 0.5):
        raise InputError(f"material: E={E} Pa, nu={nu}: need E > 0 and 0 <= nu < 0.5")
    return 2.0 * (1.0 - nu**2) / E


def _curvature_difference_of_ellipticity(kappa: float) -> float:
    """Harris' F(rho) as a function of the ellipticity kappa = a/b >= 1."""
    m = 1.0 - 1.0 / kappa**2
    K, E = ellipk(m), ellipe(m)
    return ((kappa**2 + 1.0) * E - 2.0 * K) / ((kappa**2 - 1.0) * E)


def ellipticity(curvature_difference: float) -> float:
    """Ellipticity kappa = a/b of the contact ellipse for Harris' curvature difference F(rho) in [0, 1)."""
    if not (0.0 <= curvature_difference < 1.0):
        raise InputError(f"contact: curvature difference F(rho)={curvature_difference}: need 0 <= F < 1")
    if curvature_difference < 1e-10:
        return 1.0
    return brentq(lambda k: _curvature_difference_of_ellipticity(k) - curvature_difference,
                  1.0 + 1e-9, 1e4, xtol=1e-14, rtol=1e-13)


def dimensionless_deflection(kappa: float) -> float:
    """Harris' delta* = (2 K(e) / pi) (pi / (2 kappa^2 E(e)))^(1/3) (1 for a circular contact)."""
    m = 1.0 - 1.0 / kappa**2
    return 2.0 * ellipk(m) / math.pi * (math.pi / (2.0 * kappa**2 * ellipe(m))) ** (1.0 / 3.0)


def point_contact_constant(curvature_sum: float, curvature_difference: float, E: float, nu: float) -> float:
    """Hertz load-deflection constant K [N/m^1.5] of one elliptical contact, Q = K delta^1.5.

    curvature_sum: Sigma rho [1/m]; curvature_difference: F(rho) [-]; E [Pa], nu [-] of both bodies.
    From Harris: delta = delta* (3 Q Xi / (2 Sigma rho))^(2/3) Sigma rho / 2.
    """
    if curvature_sum <= 0:
        raise InputError(f"contact: curvature sum {curvature_sum} 1/m: must be > 0")
    xi = material_compliance(E, nu)
    d_star = dimensionless_deflection(ellipticity(curvature_difference))
    return (2.0 / (d_star * curvature_sum)) ** 1.5 * 2.0 * curvature_sum / (3.0 * xi)


def ball_race_curvatures(ball_d: float, pitch_d: float, contact_angle: float,
                         groove_factor: float, inner: bool) -> tuple[float, float]:
    """Curvature sum [1/m] and difference [-] of a ball on the inner (inner=True) or outer raceway.

    groove_factor f = groove radius / ball diameter (> 0.5).  Harris Sec. 2.x: gamma = D cos(alpha)/d_m.
    """
    if groove_factor <= 0.5:
        raise InputError(f"groove curvature factor f={groove_factor}: must be > 0.5")
    gamma = ball_d * math.cos(contact_angle) / pitch_d
    rho_ball = 2.0 / ball_d
    if inner:
        rho_race_roll = rho_ball * gamma / (1.0 - gamma)
    else:
        rho_race_roll = -rho_ball * gamma / (1.0 + gamma)
    rho_groove = -1.0 / (groove_factor * ball_d)
    total = 2.0 * rho_ball + rho_race_roll + rho_groove
    difference = (rho_race_roll - rho_groove) / total
    return total, difference


def ball_effective_stiffness(ball_d: float, pitch_d: float, contact_angle: float,
                             f_inner: float, f_outer: float, E: float, nu: float) -> float:
    """Effective K_n [N/m^1.5] of inner race – ball – outer race in series (Lim's K_n, Eq. (3.6), n = 3/2).

    Both contacts carry the same load Q, so their deflections add: K_n = (K_i^(-2/3) + K_o^(-2/3))^(-3/2).
    """
    k_in = point_contact_constant(*ball_race_curvatures(ball_d, pitch_d, contact_angle, f_inner, True), E, nu)
    k_out = point_contact_constant(*ball_race_curvatures(ball_d, pitch_d, contact_angle, f_outer, False), E, nu)
    return (k_in ** (-2.0 / 3.0) + k_out ** (-2.0 / 3.0)) ** -1.5


# Palmgren's empirical line contact for steel rollers (Harris): delta = 3.84e-5 Q^0.9 / l^0.8 with
# delta, l in mm and Q in N, per roller-raceway contact, derived for E = 207 GPa, nu = 0.3.
_PALMGREN_MM = 3.84e-5
_PALMGREN_XI_STEEL = 2.0 * (1.0 - 0.3**2) / 207e9


def roller_effective_stiffness(roller_length: float, E: float, nu: float) -> float:
    """Effective K_n [N/m^(10/9)] of inner race – roller – outer race for Lim's roller model (n = 10/9).

    Palmgren's steel formula per contact, two contacts in series, scaled to other materials by
    (Xi / Xi_steel)^0.9 on the deflection (deflection ~ Xi for a line contact at fixed load).
    """
    if roller_length <= 0:
        raise InputError(f"roller length {roller_length} m: must be > 0")
    scale = (material_compliance(E, nu) / _PALMGREN_XI_STEEL) ** 0.9
    # delta[m] = 2 * scale * 3.84e-5 * 1e-3 * Q^0.9 / (l[mm])^0.8
    c = 2.0 * scale * _PALMGREN_MM * 1e-3 / (roller_length * 1e3) ** 0.8
    return c ** (-1.0 / 0.9)


class LineContactSlices:
    """Weber–Banaschek line contact (thesis Eq. (3.17), Eq. (2.40)) for a roller slice of length dl,
    both raceway contacts in series: delta(F) = sum_c 2F(1-nu^2)/(pi E dl) [ln(t1 t2 pi E dl / (2 rho_c (1-nu^2) F))
    - nu/(1-nu)].

    t1 = t2 = half the roller diameter as the thesis sets them; rho_c is the reduced radius of roller and
    raceway c.  (The OCR'd Eq. (3.17) prints nu/(1-nu^2) inside the logarithm; Eq. (2.40) and Weber–Banaschek
    have -nu/(1-nu) outside it, which is what is used here.)
    """

    def __init__(self, roller_d: float, inner_race_radius: float, outer_race_radius: float,
                 slice_length: float, E: float, nu: float):
        r = roller_d / 2.0
        rho_in = r * inner_race_radius / (r + inner_race_radius)
        rho_out = r * outer_race_radius / (outer_race_radius - r)
        self.c = 2.0 * (1.0 - nu**2) / (math.pi * E * slice_length)      # m/N
        self.k = nu / (1.0 - nu)
        # ln(C_c / F) for each contact: C_c = t1 t2 / (rho_c c)
        self.log_c = np.array([math.log(r * r / (rho * self.c)) for rho in (rho_in, rho_out)])
        # deflection increases with F only below F_lim = C e^(-(1 + k)); stay well below it
        self.force_limit = math.exp(self.log_c.min() - 1.0 - self.k) * 0.5

    def deflection(self, force: np.ndarray) -> np.ndarray:
        """Total approach [m] of both raceways for a slice force [N] (force > 0)."""
        f = np.asarray(force, float)
        return self.c * f * (self.log_c.sum() - 2.0 * self.k - 2.0 * np.log(f))

    def force_and_stiffness(self, approach: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Slice force F [N] and dF/d(approach) [N/m] for approaches [m]; zero where approach <= 0.

        Inverts delta(F) by Newton on ln F (vectorised), as the thesis does per slice."""
        d = np.asarray(approach, float)
        force = np.zeros_like(d)
        stiff = np.zeros_like(d)
        on = d > 0
        if not on.any():
            return force, stiff
        delta = d[on]
        s = self.log_c.sum() - 2.0 * self.k
        # start: ln(C/F) ~ 2 * 10 (a typical value); then Newton on x = ln F
        x = np.log(np.minimum(delta / (self.c * 20.0), self.force_limit))
        for _ in range(60):
            f = np.exp(x)
            g = self.c * f * (s - 2.0 * x) - delta               # deflection residual
            dg = self.c * f * (s - 2.0 * x - 2.0)                 # d(residual)/dx
            step = g / dg
            x = np.minimum(x - step, math.log(self.force_limit))
            if np.max(np.abs(step)) < 1e-13:
                break
        f = np.exp(x)
        force[on] = f
        stiff[on] = 1.0 / (self.c * (s - 2.0 * x - 2.0))
        return force, stiff

    def energy(self, approach: np.ndarray) -> np.ndarray:
        """Stored elastic energy integral F d(delta) [J] of each slice at the given approach [m]."""
        force, _ = self.force_and_stiffness(approach)
        out = np.zeros_like(force)
        on = force > 0
        f = force[on]
        s = self.log_c.sum() - 2.0 * self.k
        # int_0^F delta(f) df = c [s F^2/2 - 2 (F^2/2 ln F - F^2/4)]; energy = F delta - that
        integral = self.c * (s * f**2 / 2.0 - 2.0 * (f**2 / 2.0 * np.log(f) - f**2 / 4.0))
        out[on] = f * np.asarray(approach, float)[on] - integral
        return out


# ISO/TS 16281:2008 roller profile "when the actual profile is not known" (Lundberg's logarithmic crown), Eqs.
# (42)-(44), read from a public implementation of the standard (the standard itself was not at hand): drop of ONE
# contact at x from the roller centre, P(x) = c D_we ln(1 / (1 - (2x / L_we)^2)) with c = 0.00035 (cylindrical and
# needle rollers, L_we <= 2.5 D_we) and 0.00045 (tapered rollers); longer cylindrical rollers have a straight middle
# of L_we - 2.5 D_we and P = 0.0005 D_we ln(1 / (1 - ((2|x| - (L_we - 2.5 D_we)) / (2.5 D_we))^2)) outside it.
# The approach of lamina k is delta - x_k tan(psi) - 2 P(x_k) (both contacts).
LOGARITHMIC_PROFILE_COEFFICIENT = {"cylindrical_roller": 0.00035, "tapered_roller": 0.00045,
                                   "spherical_roller": 0.00035}


def logarithmic_profile_drop(x, roller_diameter: float, roller_length: float, kind: str) -> np.ndarray:
    """Crown drop P(x) [m] of one roller–raceway contact at x [m] from the roller centre (|x| < l/2) for the
    ISO/TS 16281 logarithmic profile (coefficients above; spherical rollers take the cylindrical one, an
    assumption: the standard's roller formula does not name them).  Infinite at the roller ends."""
    if kind not in LOGARITHMIC_PROFILE_COEFFICIENT:
        raise InputError(f"roller profile: kind={kind!r}: a logarithmic profile needs a roller bearing")
    x = np.abs(np.asarray(x, float))
    d, length = roller_diameter, roller_length
    if np.any(x >= length / 2.0):
        raise InputError(f"roller profile: |x| = {x.max()} m at or beyond the roller end ({length / 2} m)")
    if kind != "cylindrical_roller" or length <= 2.5 * d:
        u = 2.0 * x / length
        return LOGARITHMIC_PROFILE_COEFFICIENT[kind] * d * np.log(1.0 / (1.0 - u**2))
    flat = length - 2.5 * d
    u = np.clip((2.0 * x - flat) / (2.5 * d), 0.0, None)
    return 0.0005 * d * np.log(1.0 / (1.0 - u**2))


# A spherical roller as an elliptical point contact (the way a public implementation of ISO/TS 16281 treats
# spherical roller bearings, with the ball-bearing method): both raceways of radius r = d_pw / (2 cos alpha) + D_w / 2
# across the rolling direction, the roller's own profile radius 0.97 r (osculation 0.97).  Here the rolling
# direction keeps the roller diameter D_w (that implementation puts a ball of diameter 2 * 0.97 r there).
SPHERICAL_ROLLER_OSCULATION = 0.97


def spherical_roller_effective_stiffness(roller_d: float, pitch_d: float, contact_angle: float, E: float,
                                         nu: float, osculation: float = SPHERICAL_ROLLER_OSCULATION) -> float:
    """Effective K_n [N/m^1.5] of inner race – spherical roller – outer race, both Hertz point contacts in series
    (Q = K_n delta^1.5): curvatures 2/D_w (roller, rolling direction), 1/(osculation r) (roller profile),
    +-2/D_w gamma/(1 -+ gamma) (raceways, rolling direction), -1/r (raceways across), r = d_pw/(2 cos a) + D_w/2."""
    if not 0.5 < osculation < 1.0:
        raise InputError(f"spherical roller: osculation={osculation}: need 0.5 < roller profile / raceway radius < 1")
    race = pitch_d / (2.0 * math.cos(contact_angle)) + roller_d / 2.0
    gamma = roller_d * math.cos(contact_angle) / pitch_d
    roll, profile, across = 2.0 / roller_d, 1.0 / (osculation * race), -1.0 / race
    constants = []
    for race_roll in (roll * gamma / (1.0 - gamma), -roll * gamma / (1.0 + gamma)):     # inner, outer raceway
        total = roll + profile + race_roll + across
        difference = abs((roll - profile) + (race_roll - across)) / total
        constants.append(point_contact_constant(total, difference, E, nu))
    return (constants[0] ** (-2.0 / 3.0) + constants[1] ** (-2.0 / 3.0)) ** -1.5
