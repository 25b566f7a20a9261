"""The drivetrain's bearings matched to the housing's bores, and checked against the shafts (SI units).

A drivetrain description (housingfe.drivetrain.description) puts each bearing on a shaft line (a point and an
axis in the housing frame) and names the housing surface its bore master ties to (`BearingSeat.bore`, e.g.
"bore_pinion_front" on the built-in test gearbox).  An imported housing (CAD or mesh) names its bores as the user
selected them (surface groups `bore_<name>`), so the run-up scene says which bore carries which bearing:

* by name (the default): the bearing's own surface (the built-in gearbox's names), or the housing bore given for
  it in `[housing.bores]` (`pinion_front = "A_front"`);
* by position (`housing.match = "position"`): the one housing bore whose axis runs along the bearing's shaft and
  whose extent along that axis holds the bearing.

Either way every matched bore is checked against its shaft on the FE mesh: the bore's cylinder is fitted to the
mesh vertices of its surface (axis, a point on it, radius, extent along the axis), and its axis must be parallel to
the shaft's (within ANGLE_TOLERANCE_DEG), its centre within `tolerance` (m) of the shaft's axis, and the bearing's
point on the shaft within the bore's extent along the axis (+- tolerance).  A bore that does not line up is one
line naming it and the distance: "housing.bores: bore 'A_front' (centre (...) m) lies 12.3 mm off the pinion
shaft's axis (tolerance 1 mm)".
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from housingfe.errors import InputError

BORE_PREFIX = "bore_"
ANGLE_TOLERANCE_DEG = 1.0
DEFAULT_TOLERANCE_M = 1e-3
MATCH_MODES = ("name", "position")


@dataclass(frozen=True)
class BoreShape:
    """A bore surface of the housing mesh as a cylinder (m): its name (the surface group without "bore_"),
    surface, unit axis, centre (on the axis, mid-extent), radius, extent along the axis (s_lo, s_hi from the
    centre) and the rms deviation of its vertices from the cylinder (m)."""

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


def surface_triangles(model, surface: str) -> np.ndarray:
    """The facets (m; (n, 3, 3) corner points of the linear geometry) of a surface group, the same array on every
    rank (collective)."""
    mesh = model.housing.mesh
    tdim = mesh.topology.dim
    facets = np.asarray(model.housing.facets(surface), dtype=np.int32)
    mesh.topology.create_connectivity(tdim - 1, 0)
    mesh.topology.create_connectivity(tdim - 1, tdim)
    mesh.topology.create_connectivity(tdim, 0)
    f2v, f2c = mesh.topology.connectivity(tdim - 1, 0), mesh.topology.connectivity(tdim - 1, tdim)
    c2v, x = mesh.topology.connectivity(tdim, 0), mesh.geometry.x
    out = np.zeros((len(facets), 3, 3))
    for i, f in enumerate(facets):
        # a cell's vertices and its first geometry nodes are in the same order (the corners)
        c = f2c.links(f)[0]
        corner = dict(zip(c2v.links(c), mesh.geometry.dofmap.links(c)))
        out[i] = x[[corner[v] for v in f2v.links(f)]]
    return np.concatenate(mesh.comm.allgather(out))


def fit_cylinder(triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, float]:
    """(unit axis, point on the axis, radius, rms deviation of the corners) of the circular cylinder through the
    facets `triangles` (m, (n, 3, 3)): the axis is the direction the facet normals are most nearly perpendicular
    to (the smallest principal direction of the area-weighted sum of n n^T), the circle an algebraic
    least-squares fit (Kasa) of the corners projected across it; both refined by least squares on the corners'
    distances to the axis."""
    n = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])   # length: 2 x area
    area = np.linalg.norm(n, axis=1)
    n = n / np.maximum(area, 1e-300)[:, None]
    _, vectors = np.linalg.eigh((area[:, None, None] * n[:, :, None] * n[:, None, :]).sum(axis=0))
    axis, e1 = vectors[:, 0], vectors[:, 1]
    e2 = np.cross(axis, e1)
    points = np.unique(np.round(triangles.reshape(-1, 3), 12), axis=0)
    c = points.mean(axis=0)
    u, v = (points - c) @ e1, (points - c) @ e2
    # u^2 + v^2 = 2 a u + 2 b v + d, R^2 = d + a^2 + b^2
    A = np.column_stack([2 * u, 2 * v, np.ones_like(u)])
    (a, b, d), *_ = np.linalg.lstsq(A, u**2 + v**2, rcond=None)
    radius = math.sqrt(max(d + a * a + b * b, 0.0))
    # refined by least squares on the distances to the axis (the facet normals of a coarse mesh tilt a little
    # off the cylinder's; the corners lie on it): axis a0 + p e1 + q e2, point c0 + r e1 + t e2, radius
    from scipy.optimize import least_squares

    c0 = c + a * e1 + b * e2

    def residuals(z):
        ax = axis + z[0] * e1 + z[1] * e2
        ax = ax / np.linalg.norm(ax)
        d = points - (c0 + z[2] * e1 + z[3] * e2)
        return np.linalg.norm(d - np.outer(d @ ax, ax), axis=1) - z[4]

    fit = least_squares(residuals, np.array([0.0, 0.0, 0.0, 0.0, radius]), x_scale=[1.0, 1.0, radius, radius, radius])
    z = fit.x
    ax = axis + z[0] * e1 + z[1] * e2
    ax = ax / np.linalg.norm(ax)
    # the axis' sign is arbitrary (eigh of facets whose order depends on the MPI partition): its largest component
    # positive, so 1 and 2 ranks report the same axis
    ax = ax if ax[np.argmax(np.abs(ax))] > 0 else -ax
    dev = float(np.sqrt(np.mean(fit.fun ** 2)))
    return ax, c0 + z[2] * e1 + z[3] * e2, float(z[4]), dev


def bore_shape(model, name: str, surface: str) -> BoreShape:
    """The fitted cylinder of one bore surface (collective)."""
    tris = surface_triangles(model, surface)
    if len(tris) < 3:
        raise InputError(f"housing.bores: bore {name!r} (surface {surface}) has {len(tris)} mesh facets, too few "
                         f"for a cylinder")
    axis, point, radius, dev = fit_cylinder(tris)
    x = tris.reshape(-1, 3)
    s = (x - point) @ axis
    centre = point + 0.5 * (s.min() + s.max()) * axis
    half = 0.5 * float(s.max() - s.min())
    return BoreShape(name, surface, axis, centre, radius, -half, half, dev)


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
    """JSON-able rows for a report: bearing, surface, fitted centre (m), axis, radius (m), rms deviation (m)
    (collective)."""
    rows = []
    for bearing, surface in matched.items():
        b = bore_shape(model, surface, surface)
        rows.append({"bearing": bearing, "surface": surface, "centre_m": [float(x) for x in b.centre],
                     "axis": [float(x) for x in b.axis], "radius_m": b.radius, "length_m": 2 * b.s_hi,
                     "rms_deviation_m": b.deviation})
    return rows
