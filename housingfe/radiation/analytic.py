"""Analytic radiators and quick estimates (van Roosmalen 1994, Sec. 4.7).

Conventions used throughout `housingfe.radiation` (the table in docs/radiation.md):
- SI units; frequencies in Hz; velocities in m/s.  Air: c and rho from `housingfe.levels` (344 m/s,
  1.2 kg/m^3, the thesis' symbols list); `SPEED_OF_SOUND` and `AIR_DENSITY` here are those constants.
- Amplitudes: a scalar velocity amplitude is named by its convention (`velocity_rms_m_s` or
  `velocity_peak_m_s`); velocity *fields* given to the numerical radiators are complex peak phasors unless
  `velocity_is_rms=True` (the housing's forced response passes rms phasors).  Mean squares are rms^2.
- Radiation efficiency sigma = P / (rho c S <v~^2>) (eq. 4.8), with <v~^2> the surface-averaged
  *mean-square* (rms^2) normal velocity.  A harmonic velocity of peak amplitude v_hat has
  v~^2 = |v_hat|^2 / 2.
- Radiation index L_sigma = 10 lg sigma (dB).
"""
from __future__ import annotations

import numpy as np
from scipy.special import eval_legendre, j1, spherical_jn, spherical_yn

from housingfe.errors import InputError
from housingfe.levels import AIR_DENSITY, SPEED_OF_SOUND
from housingfe.radiation.registry import Radiator, register_radiator

__all__ = ["AIR_DENSITY", "SPEED_OF_SOUND"]  # re-exported: the package's one c and rho (housingfe.levels)


def _positive(name: str, value) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0.0):
        raise InputError(f"{name}: must be positive and finite, got {value!r}")
    return arr


def _non_negative(name: str, value) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)) or np.any(arr < 0.0):
        raise InputError(f"{name}: must be non-negative and finite, got {value!r}")
    return arr


def wavenumber(frequency_hz, c: float = SPEED_OF_SOUND) -> np.ndarray:
    """Acoustic wavenumber k = 2 pi f / c in rad/m."""
    return 2.0 * np.pi * _non_negative("frequency_hz", frequency_hz) / _positive("c", c)


def sphere_transition_frequency(radius_m: float, c: float = SPEED_OF_SOUND) -> float:
    """Transitional frequency f_s = c / (2 pi R) of a pulsating sphere in Hz (eq. 4.7)."""
    return float(_positive("c", c) / (2.0 * np.pi * _positive("radius_m", radius_m)))


def sphere_sigma(ka) -> np.ndarray:
    """Radiation efficiency of a uniformly pulsating sphere, sigma = (kR)^2 / (1 + (kR)^2) (eq. 4.9;
    f/f_s = kR).  `ka` is the dimensionless Helmholtz number k*R."""
    x2 = _non_negative("ka", ka) ** 2
    return x2 / (1.0 + x2)


def sphere_power(radius_m: float, frequency_hz, *, velocity_rms_m_s=None, velocity_peak_m_s=None,
                 rho: float = AIR_DENSITY, c: float = SPEED_OF_SOUND) -> np.ndarray:
    """Time-averaged sound power of a pulsating sphere in W (eq. 4.6):
    P = 2 pi rho c R^2 v_R^2 (f/f_s)^2 / (1 + (f/f_s)^2) with v_R the radial velocity *peak* amplitude,
    i.e. P = 4 pi rho c R^2 v_rms^2 sigma.  Give exactly one of `velocity_rms_m_s` (the package's convention,
    as the scenes' loads and responses) or `velocity_peak_m_s` (as printed in eq. 4.6), in m/s; R in m,
    f in Hz.  Keyword-only, so that a value can never be read in the other convention by position."""
    if (velocity_rms_m_s is None) == (velocity_peak_m_s is None):
        raise InputError("velocity_rms_m_s: give exactly one of velocity_rms_m_s and velocity_peak_m_s")
    R = _positive("radius_m", radius_m)
    if velocity_rms_m_s is not None:
        v_rms = _non_negative("velocity_rms_m_s", velocity_rms_m_s)
    else:
        v_rms = _non_negative("velocity_peak_m_s", velocity_peak_m_s) / np.sqrt(2.0)
    ka = wavenumber(frequency_hz, c) * R
    return 4.0 * np.pi * _positive("rho", rho) * c * R**2 * v_rms**2 * sphere_sigma(ka)


def sphere_modal_resistance(n: int, ka) -> np.ndarray:
    """Normalised radiation resistance Re(z_n)/(rho c) of the n-th spherical harmonic on a sphere,
    z_n = i rho c h_n(ka) / h_n'(ka) (spherical Hankel function); n = 0 gives eq. 4.9, n = 1 gives
    (ka)^4 / (4 + (ka)^4)."""
    x = _positive("ka", ka)
    h = spherical_jn(n, x) + 1j * spherical_yn(n, x)
    dh = spherical_jn(n, x, True) + 1j * spherical_yn(n, x, True)
    return (1j * h / dh).real


def sphere_cap_sigma(ka, half_angle_rad: float, n_terms: int | None = None) -> np.ndarray:
    """Radiation efficiency of a rigid sphere (radius a) on which a polar cap of half-angle theta_0 vibrates
    radially with uniform velocity, the rest at rest (a 'plate' of a closed body).  Spherical-harmonic series
    (e.g. Morse & Ingard, Theoretical Acoustics, Sec. 7.2): v(theta) = sum V_n P_n(cos theta) with
    V_0 = (1 - cos theta_0)/2, V_n = (P_{n-1}(cos theta_0) - P_{n+1}(cos theta_0))/2, and
    sigma = sum Re(z_n/rho c) V_n^2 / (2n+1) / ((1 - cos theta_0)/2), normalised with the *whole* sphere's
    area and surface-averaged mean-square velocity (i.e. with the cap's own area and velocity)."""
    if not 0.0 < half_angle_rad <= np.pi:
        raise InputError(f"half_angle_rad: must lie in (0, pi], got {half_angle_rad!r}")
    x = np.atleast_1d(_positive("ka", ka))
    x0 = np.cos(half_angle_rad)
    terms = n_terms or int(40 + 3 * x.max())
    total = np.zeros_like(x)
    for n in range(terms):
        Vn = 0.5 * (1.0 - x0) if n == 0 else 0.5 * (eval_legendre(n - 1, x0) - eval_legendre(n + 1, x0))
        total += sphere_modal_resistance(n, x) * Vn**2 / (2 * n + 1)
    return total / (0.5 * (1.0 - x0))


def piston_sigma(ka) -> np.ndarray:
    """Radiation efficiency of a rigid circular piston of radius a in an infinite rigid baffle,
    sigma = 1 - J1(2ka)/(ka) (radiating into one half-space).  Tends to (ka)^2/2 for ka -> 0."""
    x = _non_negative("ka", ka)
    small = x < 1e-4
    safe = np.where(small, 1.0, x)
    return np.where(small, 0.5 * x**2, 1.0 - j1(2.0 * safe) / safe)


def piston_transition_frequency(area_m2: float, c: float = SPEED_OF_SOUND) -> float:
    """Transitional frequency of a baffled piston f_p = c sqrt(2) / (2 pi a) = c / sqrt(2 pi S) in Hz
    (eq. 4.10), S = pi a^2 in m^2."""
    return float(_positive("c", c) / np.sqrt(2.0 * np.pi * _positive("area_m2", area_m2)))


def plate_critical_frequency(thickness_m, youngs_modulus_pa: float, density_kg_m3: float,
                             poisson_ratio: float, c: float = SPEED_OF_SOUND) -> np.ndarray:
    """Critical (coincidence) frequency of a homogeneous plate in Hz,
    f_c = c^2 / (2 pi) * sqrt(m'' / B) = c^2 / (2 pi h) * sqrt(12 rho (1 - nu^2) / E),
    with m'' = rho h the mass per area and B = E h^3 / (12 (1 - nu^2)) the bending stiffness.
    For steel and aluminium this is the rule f_c ~= 12/h of Sec. 4.7 (h in m)."""
    h = _positive("thickness_m", thickness_m)
    E = _positive("youngs_modulus_pa", youngs_modulus_pa)
    rho = _positive("density_kg_m3", density_kg_m3)
    nu = float(poisson_ratio)
    if not -1.0 < nu < 0.5:
        raise InputError(f"poisson_ratio: must lie in (-1, 0.5), got {poisson_ratio!r}")
    return _positive("c", c) ** 2 / (2.0 * np.pi * h) * np.sqrt(12.0 * rho * (1.0 - nu**2) / E)


def steel_rule_critical_frequency(thickness_m) -> np.ndarray:
    """The rule of thumb f_c ~= 12 / h (Hz, h in m) for steel and aluminium plates (Sec. 4.7)."""
    return 12.0 / _positive("thickness_m", thickness_m)


def equivalent_radiated_power(mean_square_velocity_m2_s2, area_m2,
                              rho: float = AIR_DENSITY, c: float = SPEED_OF_SOUND) -> np.ndarray:
    """Equivalent radiated power (ERP) in W: the sound power with sigma = 1,
    P = rho c S <v~^2>, from the surface-averaged mean-square (rms^2) normal velocity in m^2/s^2 and
    the radiating area S in m^2.  The industry-standard upper-bound estimate above f_c."""
    v2 = _non_negative("mean_square_velocity_m2_s2", mean_square_velocity_m2_s2)
    return _positive("rho", rho) * _positive("c", c) * _positive("area_m2", area_m2) * v2


def radiation_index_db(sigma) -> np.ndarray:
    """Radiation index L_sigma = 10 lg sigma in dB."""
    s = _non_negative("sigma", sigma)
    with np.errstate(divide="ignore"):
        return 10.0 * np.log10(s)


@register_radiator("erp")
class ErpRadiator(Radiator):
    """Equivalent radiated power as a radiation model: sigma = 1, L_sigma = 0 dB at every line."""

    needs_plates = False

    @classmethod
    def from_spec(cls, spec, housing, material) -> ErpRadiator:
        return cls()

    def radiation_index_db(self, response) -> np.ndarray:
        return np.zeros(len(response.frequencies))
