"""Sound power from surface velocity and radiation index (van Roosmalen 1994, eq. 4.16).

    L_W(f) = L_v(f) + L_S + L_sigma(f),   L_S = 10 lg(S / S0)
    L_sigma(f) = L_W(f) - L_v(f) - L_S    (the radiation index from a pair of L_W and L_v)

with L_v = 10 lg(<v~^2> / v0^2), v0 = 5e-8 m/s, L_W = 10 lg(P / P0), P0 = 1 pW, S0 = 1 m^2 (all from
`housingfe.levels`).  Band sums, band edges and the A-weighting are those of `housingfe.levels`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from housingfe import levels
from housingfe.errors import InputError


def _finite(name: str, value) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{name}: must be finite numbers (dB)")
    return arr


def area_level_db(area_m2: float) -> float:
    """Area level L_S = 10 lg(S / S0) in dB, S in m^2 (S0 = 1 m^2)."""
    if not np.isfinite(area_m2) or area_m2 <= 0:
        raise InputError(f"area_m2: must be positive, got {area_m2!r}")
    return float(10.0 * np.log10(area_m2 / levels.S0))


def power_level_db(power_w) -> np.ndarray:
    """Sound power level L_W = 10 lg(P / P0) in dB re 1 pW, P in W."""
    p = np.asarray(power_w, dtype=float)
    if np.any(p < 0):
        raise InputError("power_w: must be non-negative")
    with np.errstate(divide="ignore"):
        return 10.0 * np.log10(p / levels.P0)


def power_from_level(power_level) -> np.ndarray:
    """Sound power in W from L_W in dB re 1 pW."""
    return levels.P0 * 10.0 ** (np.asarray(power_level, dtype=float) / 10.0)


def sound_power_level(velocity_level_db, area_m2: float, radiation_index_db) -> np.ndarray:
    """L_W = L_v + 10 lg(S/S0) + L_sigma in dB re 1 pW (eq. 4.16); L_v in dB re 5e-8 m/s, S in m^2,
    L_sigma in dB.  Works per narrow-band line or per band (arrays broadcast)."""
    return (_finite("velocity_level_db", velocity_level_db) + area_level_db(area_m2)
            + _finite("radiation_index_db", radiation_index_db))


def radiation_index_from_levels(power_level_db, velocity_level_db, area_m2: float) -> np.ndarray:
    """L_sigma = L_W - L_v - L_S in dB (eq. 4.16) from computed or measured L_W (dB re 1 pW) and
    L_v (dB re 5e-8 m/s) and the radiating area S in m^2."""
    return (_finite("power_level_db", power_level_db) - _finite("velocity_level_db", velocity_level_db)
            - area_level_db(area_m2))


def band_power_levels(frequencies_hz, line_levels_db, bands: levels.Bands) -> np.ndarray:
    """Energy sum of narrow-band L_W lines (dB re 1 pW) into `bands` (IEC 61260, from
    `housingfe.levels`); an empty band gives -inf."""
    power = power_from_level(_finite("line_levels_db", line_levels_db))
    return power_level_db(levels.band_sum(frequencies_hz, power, bands))


def a_weighted(frequencies_hz, level_db) -> np.ndarray:
    """Levels with the IEC 61672 A-weighting (from `housingfe.levels`) added, dB(A)."""
    return _finite("level_db", level_db) + levels.a_weighting_db(frequencies_hz)


def energy_total_db(level_db) -> float:
    """Energy sum 10 lg(sum 10^(L/10)) of levels in dB over the last axis (-inf entries add nothing)."""
    L = np.asarray(level_db, dtype=float)
    with np.errstate(divide="ignore"):
        return 10.0 * np.log10(np.sum(10.0 ** (L / 10.0), axis=-1))


@dataclass(frozen=True)
class SoundPowerSpectrum:
    """Narrow-band and one-third-octave sound power levels (dB re 1 pW) with totals.

    Band levels are energy sums of the narrow-band lines; the A-weighted total applies the A-weighting
    at each narrow-band line before summing (identical to weighting bands at their exact centres only in
    the limit of narrow bands)."""

    frequencies_hz: np.ndarray
    L_W_db: np.ndarray
    bands: levels.Bands
    band_L_W_db: np.ndarray
    band_L_WA_db: np.ndarray
    total_L_W_db: float
    total_L_WA_db: float


def sound_power_spectrum(frequencies_hz, velocity_level_db, area_m2: float, radiation_index_db,
                         f_min: float | None = None, f_max: float | None = None) -> SoundPowerSpectrum:
    """Sound power per narrow-band line (eq. 4.16), summed into one-third-octave bands (IEC 61260 via
    `housingfe.levels`), with linear and A-weighted (IEC 61672) totals.  Frequencies in Hz, L_v in dB re
    5e-8 m/s, S in m^2, L_sigma in dB (per line, or a scalar)."""
    f = np.asarray(frequencies_hz, dtype=float)
    if f.ndim != 1 or f.size == 0 or np.any(f <= 0):
        raise InputError("frequencies_hz: need a 1-D array of positive frequencies")
    L_W = np.broadcast_to(sound_power_level(velocity_level_db, area_m2, radiation_index_db), f.shape)
    # Default: every band that receives a line (a line lies within a factor 2^(1/6) of its band centre).
    half_band = 2.0 ** (1.0 / 6.0)
    bands = levels.third_octave_bands(f_min or f.min() / half_band, f_max or f.max() * half_band)
    band_L = band_power_levels(f, L_W, bands)
    band_LA = band_power_levels(f, a_weighted(f, L_W), bands)
    return SoundPowerSpectrum(f, np.array(L_W), bands, band_L, band_LA,
                              energy_total_db(L_W), energy_total_db(a_weighted(f, L_W)))
