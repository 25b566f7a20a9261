"""Levels in dB, frequency bands and weighting, shared by every stage of the chain.

References as in van Roosmalen (1994): v0 = 5e-8 m/s (eq. 4.1, 5.4), omega0 = 5e-8 rad/s (eq. 2.61),
F0 = 1 N, P0 = 1 pW (eq. 4.16), S0 = 1 m^2, l0 = 1 m (eq. 4.5).  Levels are of rms quantities
(`level(mean_square, ref)` takes the mean square, i.e. rms^2).  Air: c = 344 m/s, rho = 1.2 kg/m^3.

Bands follow IEC 61260-1 (base-10: G = 10^(3/10), exact mid-band f_m = 1000 * G^(x/b)).
A-weighting follows IEC 61672-1 (analytic pole form, normalised to 0 dB at 1 kHz).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

V0 = 5e-8        # m/s, velocity level reference
OMEGA0 = 5e-8    # rad/s, angular velocity level reference
F0 = 1.0         # N, force level reference
P0 = 1e-12       # W, sound power reference
S0 = 1.0         # m^2, area level reference
L0 = 1.0         # m, moment-to-force reference length

# Air: the one place for c and rho; every default in the package is taken from here (a test greps for others).
# Source: the thesis' list of symbols (housingfe/data/roosmalen1994.toml [references] c_air_m_per_s,
# rho_air_kg_per_m3); c = 344 m/s is also the value behind Appendix E's printed 1.13*U*fc/c.
SPEED_OF_SOUND = 344.0  # m/s
AIR_DENSITY = 1.2       # kg/m^3

# Amplitude convention (docs/radiation.md, "Conventions"): loads, responses and velocities are rms unless a
# parameter name says peak; a harmonic quantity of peak amplitude x_hat has rms x_hat / sqrt(2).
RMS_PER_PEAK = 2.0 ** -0.5

_G = 10.0 ** 0.3  # octave frequency ratio, base 10

NOMINAL_THIRD_OCTAVES = (
    10, 12.5, 16, 20, 25, 31.5, 40, 50, 63, 80, 100, 125, 160, 200, 250, 315, 400, 500, 630, 800,
    1000, 1250, 1600, 2000, 2500, 3150, 4000, 5000, 6300, 8000, 10000, 12500, 16000, 20000,
)


def level(mean_square, reference: float) -> np.ndarray:
    """10*log10(mean_square / reference^2) in dB; mean_square in (unit)^2, reference in unit."""
    ms = np.asarray(mean_square, dtype=float)
    with np.errstate(divide="ignore"):
        return 10.0 * np.log10(ms / reference**2)


def from_level(level_db, reference: float) -> np.ndarray:
    """Inverse of `level`: mean square (unit^2) from a level in dB re `reference`."""
    return reference**2 * 10.0 ** (np.asarray(level_db, dtype=float) / 10.0)


@dataclass(frozen=True)
class Bands:
    """Fractional-octave bands: nominal and exact centres, lower and upper edges (Hz)."""

    nominal: np.ndarray
    center: np.ndarray
    lower: np.ndarray
    upper: np.ndarray


def fractional_octave_bands(f_min: float, f_max: float, fraction: int = 3) -> Bands:
    """IEC 61260-1 base-10 bands (1/fraction octave, fraction 1 or 3) whose nominal centre frequency lies
    in [f_min, f_max] (Hz)."""
    if fraction not in (1, 3):
        raise ValueError("fraction must be 1 (octaves) or 3 (one-third octaves)")
    x = np.arange(-20, 14) if fraction == 3 else np.arange(-6, 5)   # 10 (16) Hz .. 20 (16) kHz
    center = 1000.0 * _G ** (x / fraction)
    nominal_table = np.array(NOMINAL_THIRD_OCTAVES, dtype=float)
    nominal = np.array([nominal_table[np.argmin(abs(np.log(nominal_table / c)))] for c in center])
    keep = (nominal >= f_min * (1 - 1e-9)) & (nominal <= f_max * (1 + 1e-9))
    half = _G ** (1.0 / (2 * fraction))
    center, nominal = center[keep], nominal[keep]
    return Bands(nominal=nominal, center=center, lower=center / half, upper=center * half)


def third_octave_bands(f_min: float, f_max: float) -> Bands:
    """One-third-octave bands with exact centre frequencies in [f_min, f_max] (Hz)."""
    return fractional_octave_bands(f_min, f_max, 3)


def band_sum(frequencies, mean_square, bands: Bands) -> np.ndarray:
    """Energy sum of narrow-band lines into bands: a line at f counts in the band with
    lower <= f < upper.  `mean_square` has the frequency axis last; returns (..., n_bands)."""
    f = np.asarray(frequencies, dtype=float)
    ms = np.asarray(mean_square, dtype=float)
    out = np.zeros(ms.shape[:-1] + (len(bands.center),))
    for i, (lo, hi) in enumerate(zip(bands.lower, bands.upper)):
        sel = (f >= lo) & (f < hi)
        out[..., i] = ms[..., sel].sum(axis=-1)
    return out


def a_weighting_db(frequency) -> np.ndarray:
    """A-weighting in dB (IEC 61672-1 analytic form, 0.00 dB at 1 kHz) at frequency (Hz)."""
    f2 = np.asarray(frequency, dtype=float) ** 2
    f1, f2p, f3, f4 = 20.598997, 107.65265, 737.86223, 12194.217
    ra = (f4**2 * f2**2) / ((f2 + f1**2) * np.sqrt((f2 + f2p**2) * (f2 + f3**2)) * (f2 + f4**2))
    with np.errstate(divide="ignore"):
        return 20.0 * np.log10(ra) + 2.000
