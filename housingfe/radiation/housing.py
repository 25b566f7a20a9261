"""Sound power of a housing from its computed forced response (eq. 4.16):
L_W(f) = L_v(f) + 10 lg(S/S0) + L_sigma(f), with L_sigma from the radiator the scene names (the registry
housingfe.radiation.radiators.RADIATORS: ERP, Föller's box model on the housing's own plates, the Rayleigh
integral plate by plate)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from housingfe.radiation.foller import Plate
from housingfe.radiation.numerical import RADIATION_POINTS, NumericalRadiator, housing_plate_points
from housingfe.radiation.power import SoundPowerSpectrum
from housingfe.radiation.radiators import Radiator, radiator_from_spec
from housingfe.radiation.radiators import sound_power as response_sound_power

__all__ = ["RADIATION_POINTS", "HousingSoundPower", "housing_plates", "radiation_points", "sound_power"]


@dataclass
class HousingSoundPower:
    """Per load case: the radiation index per line (dB) and the sound power spectrum."""

    load_case: str
    model: str
    radiation_index_db: np.ndarray
    spectrum: SoundPowerSpectrum
    plates: tuple = ()
    foller: dict | None = None   # Appendix E quantities of the housing's own plates


def housing_plates(model, spec) -> list[Plate]:
    """Föller plates from the mesh: area and perimeter of each listed surface, fc from the material."""
    from housingfe.radiation.foller import FollerRadiator

    return list(FollerRadiator.from_spec(spec, model.housing, model.material).plates)


def radiation_points(model, spec):
    """Facet points (and one id per plate) of the listed plates, for the numerical model."""
    return housing_plate_points(model.housing, [p.surface for p in spec.plates])


def sound_power(forced, model, spec, plate_ids=None, *, radiator: Radiator | None = None
                ) -> list[HousingSoundPower]:
    """Sound power of every load case of a ForcedResult (the first solver's responses).

    model: the HousingModel (its housing and material); spec: the scene's radiation section; radiator: the one
    whose extra_points the forced response evaluated (default: made from spec; for the numerical model the points
    already in forced.observer with their `plate_ids`)."""
    if radiator is None:
        radiator = radiator_from_spec(spec, model.housing, model.material)
        if isinstance(radiator, NumericalRadiator) and plate_ids is not None:
            radiator.points, radiator.plate_ids = forced.observer.extra_samples[RADIATION_POINTS], plate_ids
        else:
            radiator.extra_points(model)
    solver = next(iter(forced.responses))
    out = []
    for resp in forced.responses[solver]:
        p = response_sound_power(resp, radiator, area=forced.observer.area)
        out.append(HousingSoundPower(resp.name, p.radiator, p.radiation_index_db, p.spectrum,
                                     getattr(radiator, "plates", ()), p.facts))
    return out
