"""Fukuma's gear-shaft model: H. Fukuma, T. Furukawa, T. Aida, *Fundamental research on gear noise and vibration
(6th report): generation mechanism of radial and axial vibration of spur gears*, Bull. JSME 16(97), 1973
(seed /work/shared/seeds/003_bf79b85e1214a188.txt; docs/fukuma.md).

Computes the coupled circumferential / radial / axial (tilt) vibration of a spur gear on a flexible shaft between
two bearings: influence coefficients, equivalent mass and inertia, the conversion of circumferential into radial
and axial vibration over the gear's position between the bearings, and bearing load spectra.

  `model`  the shaft-bearing-gear model (the paper's Sec. 2)
  `run`    scene schema, `run_scene` for `housingfe source fukuma-*`, benchmark rows
"""
from housingfe.source.fukuma.model import (
    FukumaPair,
    GearBody,
    ShaftBearing,
    bearing_load_spectra,
    conversion_ratios,
    equivalent_inertia,
    harmonic_response,
    influence_coefficients,
)
from housingfe.source.fukuma.run import FukumaScene, run_scene

__all__ = [
    "FukumaPair",
    "FukumaScene",
    "GearBody",
    "ShaftBearing",
    "bearing_load_spectra",
    "conversion_ratios",
    "equivalent_inertia",
    "harmonic_response",
    "influence_coefficients",
    "run_scene",
]
