"""The registry of radiation models ("radiators"): name -> class.

A radiator turns a computed response into the radiation index L_sigma = 10 lg sigma (dB per line) of eq. 4.16.
Each model lives in its own module and registers itself with `@register_radiator("<name>")`; the built-in ones
(erp in analytic.py, foller in foller.py, numerical in numerical.py) are imported by
housingfe.radiation.radiators, which is where a new model's module is added (one line).  The scene schema
(housingfe.scene.RadiationSpec.model) accepts exactly the registered names.

This module imports nothing of the models, so that the model modules can import it.
"""
from __future__ import annotations

import numpy as np

RADIATORS: dict[str, type] = {}


def register_radiator(name: str):
    """Class decorator: register a Radiator subclass under `name` (sets cls.name)."""
    def add(cls):
        if name in RADIATORS:
            raise ValueError(f"radiator {name!r} is registered twice ({RADIATORS[name].__qualname__}, "
                             f"{cls.__qualname__})")
        cls.name = name
        RADIATORS[name] = cls
        return cls

    return add


def check_radiator(name: str) -> str:
    """`name` if it is a registered radiator, else ValueError "'<name>' is not a radiation model; known: ..."."""
    if name not in RADIATORS:
        raise ValueError(f"{name!r} is not a radiation model; known: {', '.join(sorted(RADIATORS))}")
    return name


class Radiator:
    """A radiation model.  Subclasses set `needs_plates` (does the scene have to list radiating plates?) and
    implement `radiation_index_db`; `from_spec` builds one from a scene's radiation section (duck-typed: `.plates`
    with `.surface`, `.thickness`, `.count`), the housing mesh and its material.

    A radiator that needs the response at its own surface points (e.g. the Rayleigh integral) returns them from
    `extra_points(structure)` as {name: SamplePoints}; the forced response adds them to its observer, and the
    response then carries their values in `response.extras["point_values"][name]`."""

    name = ""
    needs_plates = True

    @classmethod
    def from_spec(cls, spec, housing, material) -> Radiator:
        """The radiator of a scene's radiation section on `housing` (HousingMesh) made of `material`."""
        raise NotImplementedError

    def extra_points(self, structure) -> dict:
        """Surface points (name -> SamplePoints) the response must be evaluated at; none by default."""
        return {}

    def radiation_index_db(self, response) -> np.ndarray:
        """L_sigma (dB) per frequency line of `response` (its `.frequencies`, Hz)."""
        raise NotImplementedError

    def facts(self) -> dict | None:
        """Model quantities worth reporting (JSON-able), or None."""
        return None
