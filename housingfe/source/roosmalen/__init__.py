"""van Roosmalen's source model: A.N.J. van Roosmalen, *Design tools for low noise gear transmissions*, PhD thesis,
TU Eindhoven, 1994, Ch. 2 (seed /work/shared/seeds/004_44ded8f5ffaac66c.txt; published values in
housingfe/data/roosmalen1994.toml).

Computes, on rigid bores, the periodic steady state of the 15-DOF lumped gearbox interior under the time-varying
mesh stiffness and the engagement shock (harmonic balance): mesh force, transmission error, bearing force spectra
and the wheel's angular velocity level L_omega (dB) per tooth harmonic, over speed and torque.

  `dynamics`   the lumped interior (Sec. 2.5-2.7, Appendix C), engagement shock, harmonic balance, levels
  `operating`  the source as a stage of the chain: `SourceModel.operating_point(speed_rpm, torque_nm)`
  `run`        scene schema and `run_scene` for `housingfe source gearset-*`, `correction_study`
  `studies`    overlap-ratio and correction studies, excitation spectrum (`housingfe source-spectrum`); not
               imported here, so that `python -m housingfe.source.roosmalen.studies` runs it without a warning
"""
from housingfe.source.roosmalen.dynamics import (
    ENGAGEMENT_MODELS,
    BearingSpectra,
    LumpedInterior,
    SteadyState,
    assemble,
    bearing_spectra,
    derive_interior,
    engagement_shock,
    harmonic_balance,
    mesh_harmonic_balance,
    tooth_band_level,
)
from housingfe.source.roosmalen.operating import Excitation, SourceModel
from housingfe.source.roosmalen.run import OperatingPoint, build, correction_study, parse, run_scene

__all__ = [
    "ENGAGEMENT_MODELS",
    "BearingSpectra",
    "Excitation",
    "LumpedInterior",
    "OperatingPoint",
    "SourceModel",
    "SteadyState",
    "assemble",
    "bearing_spectra",
    "build",
    "correction_study",
    "derive_interior",
    "engagement_shock",
    "harmonic_balance",
    "mesh_harmonic_balance",
    "parse",
    "run_scene",
    "tooth_band_level",
]
