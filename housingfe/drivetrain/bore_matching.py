"""The drivetrain's bearings matched to the housing's bores, and checked against the shafts (SI units).

A drivetrain description (housingfe.drivetrain.description) puts each bearing on a shaft line (a point and an
axis in the housing frame) and names the housing surface its bore master ties to (`BearingSeat.bore`, e.g.
"bore_pinion_front" on the built-in test gearbox).  An imported housing (CAD or mesh) names its bores as the user
selected them (surface groups `bore_<name>`), so the run-up scene says which bore carries which bearing:

* by name (the default): the bearing's own surface (the built-in gearbox's names), or the housing bore given for
  it in `[housing.bores]` (`pinion_front = "A_front"`);
* by position (`housing.match = "position"`): the one housing bore whose axis runs along the bearing's shaft and
  whose extent along that axis holds the bearing.

Either way every matched bore is checked against its shaft on the FE mesh: the bore's cylinder (axis, centre on it
mid-extent, radius, extent along the axis) is the one the coupling puts its bore master on, fitted by area-weighted
least squares to the mesh vertices of its surface (`bore_shape`: housingfe.drivetrain.bore_axis.fit_points, the one
cylinder fit of the package; a flat seat is its plane, a curved surface that is no cylinder is refused), and its
axis must be parallel to the shaft's (within ANGLE_TOLERANCE_DEG), its centre within `tolerance` (m) of the shaft's
axis, and the bearing's point on the shaft within the bore's extent along the axis (+- tolerance).  A bore that
does not line up is one line naming it and the distance: "housing.bores: bore 'A_front' (centre (...) m) lies
12.3 mm off the pinion shaft's axis (tolerance 1 mm)".
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from housingfe.drivetrain.bore_axis import MAX_TILT_DEG, fit_points, surface_geometry
from housingfe.errors import InputError

BORE_PREFIX = "bore_"
ANGLE_TOLERANCE_DEG = MAX_TILT_DEG      # a bore's axis vs its shaft's: the coupling's bound on the same tilt
DEFAULT_TOLERANCE_M = 1e-3
MATCH_MODES = ("name", "position")


@dataclass(frozen=True)
class BoreShape:
    """A bore surface of the housing mesh as a cylinder (m): its name (the surface group without "bore_"),
    surface, unit axis (largest component positive), centre (on the axis, mid-extent), radius, extent along the
    axis (s_lo, s_hi from the centre) and the area-weighted rms deviation of its vertices from the cylinder (m).
    A flat surface: axis its normal, centre its centroid, radius nan, s_lo = s_hi = 0 (bore_axis.BoreFit)."""

    name: str
    surface: str
    axis: np.ndarray
    centre: np.ndarray
    radius: float
    s_lo: float
    s_hi: float
    deviation: float


def bore_surfaces(model) -> dict[str, str]:
    """{bore name: surface group} of a housing model: every `bore_<name>` group (built-in housings, the `cad`
    kind's selectors; the group "bores" is the union of all, not a bore), and the `[[geometry.bores]]` of its scene
    that are groups by their own name (the `mesh` kind's sets)."""
    groups = model.housing.facet_groups
    out = {g[len(BORE_PREFIX):]: g for g in sorted(groups) if g.startswith(BORE_PREFIX)}
    geometry = getattr(getattr(model, "scene", None), "geometry", None)
    for entry in getattr(geometry, "bores", None) or []:
        name = getattr(entry, "name", None)
        if isinstance(name, str) and name in groups and name not in out:
            out[name] = name
    return dict(sorted(out.items()))


def bore_shape(model, name: str, surface: str) -> BoreShape:
    """The fitted cylinder of one bore surface (collective; the same on every rank): the coupling's bore fit
    (housingfe.drivetrain.bore_axis: `surface_geometry` + `fit_points`, area-weighted on the surface's mesh
    vertices).  A flat surface (a flat bearing seat) is its plane: axis the face normal, centre the centroid,
    radius nan, no extent.  InputError "housing.bores: bore <name>: ..." for fewer than three vertices and for a
    curved surface that is no cylinder (rms deviation above bore_axis.MAX_RELATIVE_RMS of the radius)."""
    try:
        fit = fit_points(*surface_geometry(model, surface), surface)
    except InputError as err:
        raise InputError(f"housing.bores: bore {name!r}: {err}") from None
    half = fit.length / 2
    return BoreShape(name, surface, fit.axis, fit.centre, fit.radius, -half, half, fit.rms)


def _fmt(v) -> str:
    return "(" + ", ".join(f"{float(x) + 0.0:.4g}" for x in v) + ")"


def misfit(bore: BoreShape, shaft, bearing_point: np.ndarray, tolerance: float) -> str | None:
    """Why `bore` does not carry a bearing at `bearing_point` (m) on shaft line `shaft` (a
    description.ShaftLine), or None when it lines up: axis parallel within ANGLE_TOLERANCE_DEG, centre within
    `tolerance` (m) of the shaft's axis, the bearing within the bore's extent along the axis (+- tolerance)."""
    a = np.asarray(shaft.axis, float) / np.linalg.norm(shaft.axis)
    angle = math.degrees(math.acos(min(1.0, abs(float(bore.axis @ a)))))
    if angle > ANGLE_TOLERANCE_DEG:
        return (f"bore {bore.name!r} (axis {_fmt(bore.axis)}) is tilted {angle:.3g} deg from the {shaft.name} "
                f"shaft's axis {_fmt(a)} (tolerance {ANGLE_TOLERANCE_DEG:g} deg)")
    d = bore.centre - np.asarray(shaft.centre, float)
    off = float(np.linalg.norm(d - (d @ a) * a))
    if off > tolerance:
        return (f"bore {bore.name!r} (centre {_fmt(bore.centre)} m) lies {off * 1e3:.4g} mm off the {shaft.name} "
                f"shaft's axis (tolerance {tolerance * 1e3:g} mm)")
    s = float((bearing_point - bore.centre) @ bore.axis)
    outside = max(bore.s_lo - s, s - bore.s_hi)
    if outside > tolerance:
        return (f"bore {bore.name!r} (centre {_fmt(bore.centre)} m, {2 * bore.s_hi * 1e3:.4g} mm long) does not "
                f"hold the bearing at {_fmt(bearing_point)} m: it lies {outside * 1e3:.4g} mm beyond the bore's "
                f"end along the {shaft.name} shaft's axis (tolerance {tolerance * 1e3:g} mm)")
    return None


def match_bores(model, drivetrain, mapping: dict | None = None, match: str = "name",
                tolerance: float = DEFAULT_TOLERANCE_M, key: str = "housing.bores") -> dict[str, str]:
    """{bearing name: housing surface group} for every bearing seat of `drivetrain` on the housing `model`
    (collective; see the module docstring).  mapping: {bearing name: housing bore name (with or without
    "bore_")}, overriding `match` for those bearings; match: "name" or "position"; tolerance (m).  InputError
    (one line naming `key`) for a bearing not in the drivetrain, a bore the housing does not have, no bore or two
    on a bearing's shaft (by position), a bore used twice, and a bore that does not line up with its shaft."""
    mapping = dict(mapping or {})
    if match not in MATCH_MODES:
        raise InputError(f"{key}: match {match!r} is not one of {', '.join(MATCH_MODES)}")
    seats = {b.name: b for b in drivetrain.bearings}
    for name in mapping:
        if name not in seats:
            raise InputError(f"{key}.{name}: the drivetrain has no bearing {name!r} (its bearings: "
                             f"{', '.join(seats)})")
    surfaces = bore_surfaces(model)
    known = ", ".join(surfaces) or "none"
    shapes: dict[str, BoreShape] = {}

    def shape(name: str) -> BoreShape:
        if name not in shapes:
            shapes[name] = bore_shape(model, name, surfaces[name])
        return shapes[name]

    out = {}
    for seat in drivetrain.bearings:
        shaft = drivetrain.shaft(seat.shaft)
        point = shaft.point(seat.position)
        if seat.name in mapping:
            name = str(mapping[seat.name])
            if name not in surfaces and name.startswith(BORE_PREFIX):
                name = name[len(BORE_PREFIX):]
            if name not in surfaces:
                raise InputError(f"{key}.{seat.name}: the housing has no bore {name!r} (its bores: {known})")
        elif match == "name":
            name = seat.bore[len(BORE_PREFIX):] if seat.bore.startswith(BORE_PREFIX) else seat.bore
            if name not in surfaces:
                raise InputError(f"{key}: the bearing {seat.name!r} needs the housing bore {name!r} (surface "
                                 f"{seat.bore}), which the housing does not have (its bores: {known}); name it so "
                                 f"in the housing scene, map it ({key}.{seat.name} = \"<bore>\") or set "
                                 f"housing.match = \"position\"")
        else:
            fits = [n for n in surfaces if misfit(shape(n), shaft, point, tolerance) is None]
            if len(fits) > 1:
                raise InputError(f"{key}: {len(fits)} bores ({', '.join(fits)}) hold the bearing {seat.name!r} at "
                                 f"{_fmt(point)} m; map it ({key}.{seat.name} = \"<bore>\")")
            if not fits:
                if not surfaces:
                    raise InputError(f"{key}: the housing has no bores (surface groups bore_<name>) for the "
                                     f"bearing {seat.name!r}")
                nearest = min(surfaces, key=lambda n: float(np.linalg.norm(shape(n).centre - point)))
                raise InputError(f"{key}: no bore holds the bearing {seat.name!r} at {_fmt(point)} m; the nearest: "
                                 + misfit(shape(nearest), shaft, point, tolerance))
            name = fits[0]
        why = misfit(shape(name), shaft, point, tolerance)
        if why is not None:
            raise InputError(f"{key}: {why} (bearing {seat.name!r})")
        if surfaces[name] in out.values():
            other = next(k for k, v in out.items() if v == surfaces[name])
            raise InputError(f"{key}: bore {name!r} would carry both bearings {other!r} and {seat.name!r}")
        out[seat.name] = surfaces[name]
    return out


def matched_bores_summary(model, matched: dict[str, str]) -> list[dict]:
    """JSON-able rows for a report: bearing, surface, fitted centre (m), axis, radius (m; None for a flat seat),
    length (m), rms deviation (m) (collective)."""
    rows = []
    for bearing, surface in matched.items():
        b = bore_shape(model, surface, surface)
        rows.append({"bearing": bearing, "surface": surface, "centre_m": [float(x) for x in b.centre],
                     "axis": [float(x) for x in b.axis],
                     "radius_m": None if math.isnan(b.radius) else b.radius, "length_m": 2 * b.s_hi,
                     "rms_deviation_m": b.deviation})
    return rows
