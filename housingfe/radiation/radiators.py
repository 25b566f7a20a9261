"""Radiation models and the sound power of a response (van Roosmalen 1994, eq. 4.16).

    L_W(f) = L_v(f) + 10 lg(S / S0) + L_sigma(f)

`RADIATORS` maps a model name to its class (housingfe.radiation.registry.Radiator):
- "erp": sigma = 1 (equivalent radiated power; housingfe.radiation.analytic.ErpRadiator);
- "foller": Föller's box model on the housing's plates (housingfe.radiation.foller.FollerRadiator);
- "numerical": the Rayleigh integral plate by plate (housingfe.radiation.numerical.NumericalRadiator).
Each model registers itself in its own module; the import below is the one line that adds a model's module.
The scene schema (housingfe.scene.RadiationSpec.model) accepts exactly these names.

    radiator = radiator_from_spec(scene.radiation, model.housing, model.material)
    extra = radiator.extra_points(structure)       # points the forced response must evaluate (maybe none)
    ...forced response with `extra` added to its observer...
    power = sound_power(response, radiator, area=surface_area_m2)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# the built-in radiation models: importing a model's module registers it (one line per model)
from housingfe.radiation.analytic import ErpRadiator  # noqa: F401
from housingfe.radiation.foller import FollerRadiator  # noqa: F401
from housingfe.radiation.numerical import NumericalRadiator  # noqa: F401
from housingfe.radiation.power import SoundPowerSpectrum, sound_power_spectrum
from housingfe.radiation.registry import RADIATORS, Radiator, check_radiator, register_radiator

__all__ = ["RADIATORS", "Radiator", "SoundPower", "check_radiator", "radiator_from_spec", "register_radiator",
           "sound_power"]


def radiator_from_spec(spec, housing, material) -> Radiator:
    """The radiator a scene's radiation section names (spec.model, spec.plates) on `housing` (HousingMesh) made
    of `material` (E, density, Poisson ratio)."""
    return RADIATORS[check_radiator(spec.model)].from_spec(spec, housing, material)


@dataclass(frozen=True)
class SoundPower:
    """Sound power of one response: the radiator's name and facts, L_sigma per line (dB) and the spectrum
    (L_W per line and per 1/3-octave band, dB re 1 pW, with linear and A-weighted totals)."""

    radiator: str
    radiation_index_db: np.ndarray
    spectrum: SoundPowerSpectrum
    facts: dict | None = None

    @property
    def frequencies_hz(self) -> np.ndarray:
        return self.spectrum.frequencies_hz

    @property
    def L_W_db(self) -> np.ndarray:
        """L_W per line, dB re 1 pW."""
        return self.spectrum.L_W_db

    @property
    def band_L_W_db(self) -> np.ndarray:
        return self.spectrum.band_L_W_db

    @property
    def total_L_WA_db(self) -> float:
        """A-weighted total, dB(A) re 1 pW."""
        return self.spectrum.total_L_WA_db


def _velocity_level_db(response) -> np.ndarray:
    """L_v (dB re 5e-8 m/s) of a response: LoadResponse.velocity_level_db (scaled by its load amplitude) or the
    stage API's mean_square_velocity() (m^2/s^2)."""
    level = getattr(response, "velocity_level_db", None)
    if level is not None:
        return level
    from housingfe import levels

    return levels.level(response.mean_square_velocity(), levels.V0)


def sound_power(response, radiator: Radiator, *, area: float | None = None) -> SoundPower:
    """Sound power (eq. 4.16) of `response` (frequencies in Hz, surface-averaged velocity) radiated as
    `radiator` says, from `area` (m^2, the radiating surface; default response.area).  Bands from 10 Hz (or the
    lowest line) to the highest line."""
    f = response.frequencies
    S = area if area is not None else response.area
    L_sigma = radiator.radiation_index_db(response)
    spectrum = sound_power_spectrum(f, _velocity_level_db(response), S, L_sigma, f_min=max(f.min(), 10.0),
                                    f_max=f.max())
    return SoundPower(radiator.name, L_sigma, spectrum, radiator.facts())
