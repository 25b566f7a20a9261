"""Bearing stiffness (and fluid-film damping) matrices — standalone, no FE needed.

Public API (axis convention: z = shaft axis, DOF order x, y, z, theta_x, theta_y, theta_z; SI units):

    bearing_stiffness(bearing, load, model=None, preload_axial=0.0) -> BearingResult
        bearing: catalogue designation ("SKF 6312") or a RollingBearing; load (Fx, Fy, Fz, Mx, My) [N, N m]
        applied by the shaft to the inner ring.  result.K is the symmetric 6x6 [K]_bm of van Roosmalen (1994)
        Sec. 3.2/3.3 [N/m, N/rad, N m/rad], result.displacement the mean inner-ring displacement [m, rad],
        result.element_loads the rolling-element loads [N].
    journal_bearing_coefficients(JournalBearing(D, L, C, eta), omega, (Wx, Wy)) -> FluidFilmResult with the
        eccentricity and the non-symmetric 6x6 K and C of a plain journal bearing (finite-length Reynolds
        equation, force and tilt coefficients); short_bearing_coefficients: the Ocvirk short bearing.

    transform_stiffness(K, R) -> K in global axes (R: columns = the bearing's x, y, z in global coordinates).

`housingfe bearing DESIGNATION|--geometry FILE.toml|--balls Z --ball-diameter M ... --load FX FY FZ MX MY [--json]`
prints the same: the deflection under the load, the secant F/delta and the tangent K (see bearings.cli).
"""
from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

# The names below are loaded on first use (PEP 562) so that building the CLI parser, which imports this
# package for register_cli, does not pay for scipy.
_LAZY = {
    "designations": "catalogue", "lookup": "catalogue",
    "FluidFilmResult": "fluid_film", "JournalBearing": "fluid_film",
    "journal_bearing_coefficients": "fluid_film", "short_bearing_coefficients": "fluid_film",
    "DOF_NAMES": "rolling", "BearingResult": "rolling", "RollingBearing": "rolling",
    "finite_difference_stiffness": "rolling", "make_model": "rolling", "rolling_bearing_stiffness": "rolling",
    "stiffness_at": "rolling", "transform_stiffness": "rolling", "bearing_from_table": "rolling",
}

__all__ = ["DOF_NAMES", "BearingResult", "FluidFilmResult", "JournalBearing", "RollingBearing",
           "bearing_from_table", "bearing_stiffness", "designations", "finite_difference_stiffness", "journal_bearing_coefficients",
           "lookup", "make_model", "short_bearing_coefficients", "stiffness_at",
           "transform_stiffness"]

if TYPE_CHECKING:
    from housingfe.bearings.rolling import BearingResult, RollingBearing


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(f"housingfe.bearings.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'housingfe.bearings' has no attribute {name!r}")


def bearing_stiffness(bearing: str | RollingBearing, load, *, model: str | None = None,
                      preload_axial: float = 0.0, fixed_tilt: tuple[float, float] | None = None) -> BearingResult:
    """6x6 mean stiffness of a rolling bearing under a mean load.

    bearing: catalogue designation (str) or RollingBearing; load: (Fx, Fy, Fz, Mx, My) [N, N m] on the inner
    ring (a sixth value Mz must be 0); model: "lim-ball", "lim-roller", "sliced-roller", "self-aligning",
    "spherical-point-contact" (spherical rollers as Hertz point contacts, osculation 0.97) or
    None (the thesis' choice for the kind); preload_axial [N] is added to Fz; fixed_tilt=(bx, by) [rad]
    prescribes the tilt instead of the moments (result.load then holds the moments it takes).
    Returns BearingResult (K [N/m, N/rad, N m/rad], displacement [m, rad], element_loads [N]).
    Raises InputError for an unknown designation or a load the bearing cannot carry."""
    from housingfe.bearings.catalogue import lookup
    from housingfe.bearings.rolling import rolling_bearing_stiffness

    geometry = lookup(bearing) if isinstance(bearing, str) else bearing
    return rolling_bearing_stiffness(geometry, load, model=model, preload_axial=preload_axial,
                                     fixed_tilt=fixed_tilt)

