"""Sound radiation (van Roosmalen 1994, Sec. 4.7, Appendix E).

Public API (SI units; velocities are complex peak phasors, mean squares are rms^2; see analytic.py):
- analytic radiators: `sphere_sigma`, `sphere_power`, `sphere_cap_sigma`, `piston_sigma`, `plate_critical_frequency`,
  `equivalent_radiated_power` (ERP, sigma = 1);
- Föller's box model: `Plate`, `plate_from_triangles`, `foller_radiation_index` -> `FollerResult`,
  `load_plate_table`;
- numerical radiation efficiency from surface data: `rayleigh_radiated_power` (plane baffled radiator),
  `baffled_plates_radiated_power` (housing, plate by plate), `helmholtz_fem_radiation` (closed bodies,
  exterior Helmholtz FE in a complex-PETSc subprocess);
- sound power (eq. 4.16): `sound_power_level`, `radiation_index_from_levels`, `sound_power_spectrum`;
- the radiation models of a housing by name (`RADIATORS`: "erp", "foller", "numerical"; `register_radiator` adds
  one) and `sound_power(response, radiator) -> SoundPower` (housingfe.radiation.radiators).
Sub-command: `housingfe radiation foller <table.toml|builtin:scale-model|builtin:test-gearbox>`.
"""
from housingfe.radiation.analytic import (
    AIR_DENSITY,
    SPEED_OF_SOUND,
    equivalent_radiated_power,
    piston_sigma,
    plate_critical_frequency,
    radiation_index_db,
    sphere_cap_sigma,
    sphere_modal_resistance,
    sphere_power,
    sphere_sigma,
    steel_rule_critical_frequency,
)
from housingfe.radiation.fem import (
    FemGeometry,
    FemSweep,
    baffled_piston_geometry,
    box_geometry,
    helmholtz_fem_radiation,
    sphere_geometry,
)
from housingfe.radiation.foller import (
    FollerResult,
    Plate,
    foller_radiation_index,
    load_plate_table,
    plate_from_triangles,
)
from housingfe.radiation.numerical import (
    RadiationResult,
    baffled_plates_radiated_power,
    rayleigh_radiated_power,
)
from housingfe.radiation.power import (
    SoundPowerSpectrum,
    area_level_db,
    power_level_db,
    radiation_index_from_levels,
    sound_power_level,
    sound_power_spectrum,
)
from housingfe.radiation.radiators import (
    RADIATORS,
    Radiator,
    SoundPower,
    radiator_from_spec,
    register_radiator,
    sound_power,
)

__all__ = [
    "AIR_DENSITY",
    "SPEED_OF_SOUND",
    "FemGeometry",
    "FemSweep",
    "FollerResult",
    "Plate",
    "RADIATORS",
    "Radiator",
    "RadiationResult",
    "SoundPower",
    "SoundPowerSpectrum",
    "area_level_db",
    "baffled_piston_geometry",
    "baffled_plates_radiated_power",
    "box_geometry",
    "equivalent_radiated_power",
    "foller_radiation_index",
    "helmholtz_fem_radiation",
    "load_plate_table",
    "piston_sigma",
    "plate_critical_frequency",
    "plate_from_triangles",
    "power_level_db",
    "radiation_index_db",
    "radiation_index_from_levels",
    "radiator_from_spec",
    "rayleigh_radiated_power",
    "register_cli",
    "register_radiator",
    "sound_power",
    "sound_power_level",
    "sound_power_spectrum",
    "sphere_cap_sigma",
    "sphere_geometry",
    "sphere_modal_resistance",
    "sphere_power",
    "sphere_sigma",
    "steel_rule_critical_frequency",
]


def register_cli(subparsers) -> None:
    """Add `housingfe radiation ...` to the top-level CLI."""
    from housingfe.radiation.cli import register

    register(subparsers)
