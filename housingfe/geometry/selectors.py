"""Geometric selectors: named regions of an imported housing found by geometry, never by entity numbers.

An imported housing (a CAD file, a mesh from another code) has faces a user cannot see the numbers of.  The
scene names its regions by what a drawing shows instead:

- a bore by its axis direction and a point on the axis (optionally its radius): every cylindrical face on that
  axis (a bore through a front and a back bearing plate is one bore);
- a surface (a foot, a bolt face, a flange) by a plane (a point on it and its outward normal), by a box that
  holds the faces, or as the one face nearest to a point.

The functions here work on plain face descriptions (`Face`: kind, sample points, outward normal, cylinder
parameters), so that any importer that can describe its boundary faces can use them.  All lengths in m.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np
from pydantic import Field, PositiveFloat, model_validator

from housingfe.errors import InputError
from housingfe.geometry.registry import StrictSpec

Vector = list[float]
_NAME = r"^[A-Za-z0-9_]+$"
# angle tolerance of axes and normals (rad): CAD exports keep directions to ~1e-12; 1 degree forgives a
# slightly tilted user input without ever mixing up perpendicular faces
ANGLE_TOLERANCE = np.radians(1.0)


class BoreSelector(StrictSpec):
    """A bore: the cylindrical faces whose axis is parallel to `axis` and passes within `tolerance` (m) of
    `centre` (m, any point on the axis); with `radius` (m) only faces of that radius (within tolerance); with
    `span` = [s0, s1] (m, along the axis from `centre`) only faces lying wholly between s0 and s1 (within
    tolerance): one bearing seat of a shaft whose bore runs through two bearing plates.
    Every matched face gets the surface groups `bore_<name>` and `bores`."""

    name: str = Field(pattern=_NAME)
    axis: Vector = Field(min_length=3, max_length=3, json_schema_extra={"unit": "-"})
    centre: Vector = Field(min_length=3, max_length=3, json_schema_extra={"unit": "m"})
    radius: Optional[PositiveFloat] = Field(None, json_schema_extra={"unit": "m"})
    span: Optional[list[float]] = Field(None, min_length=2, max_length=2, json_schema_extra={"unit": "m"})
    tolerance: PositiveFloat = Field(1e-4, json_schema_extra={"unit": "m"})

    @model_validator(mode="after")
    def _axis(self):
        if float(np.linalg.norm(self.axis)) == 0.0:
            raise ValueError("axis: must be a non-zero vector")
        if self.span is not None and self.span[0] >= self.span[1]:
            raise ValueError("span: [s0, s1] with s0 < s1 (m along the axis from centre)")
        return self


class PlaneSelector(StrictSpec):
    """A plane by a point on it (m) and the outward normal of the faces wanted (a foot's underside: 0, 0, -1)."""

    point: Vector = Field(min_length=3, max_length=3, json_schema_extra={"unit": "m"})
    normal: Vector = Field(min_length=3, max_length=3, json_schema_extra={"unit": "-"})

    @model_validator(mode="after")
    def _normal(self):
        if float(np.linalg.norm(self.normal)) == 0.0:
            raise ValueError("normal: must be a non-zero vector")
        return self


class BoxSelector(StrictSpec):
    """An axis-aligned box (m): the faces that lie wholly inside it."""

    min: Vector = Field(min_length=3, max_length=3, json_schema_extra={"unit": "m"})
    max: Vector = Field(min_length=3, max_length=3, json_schema_extra={"unit": "m"})

    @model_validator(mode="after")
    def _ordered(self):
        if any(a >= b for a, b in zip(self.min, self.max)):
            raise ValueError("max: must exceed min in x, y and z")
        return self


class SurfaceSelector(StrictSpec):
    """A named surface group (for supports, loads, radiation plates): the faces in `plane`, inside `box`, or
    the one face `nearest` to a point (m); exactly one of the three.  tolerance (m): distance from the plane
    or the box that still counts as on it."""

    name: str = Field(pattern=_NAME)
    plane: Optional[PlaneSelector] = None
    box: Optional[BoxSelector] = None
    nearest: Optional[Vector] = Field(None, min_length=3, max_length=3, json_schema_extra={"unit": "m"})
    tolerance: PositiveFloat = 1e-4

    @model_validator(mode="after")
    def _one(self):
        if sum(x is not None for x in (self.plane, self.box, self.nearest)) != 1:
            raise ValueError("plane: give exactly one of plane, box or nearest")
        return self


@dataclass
class Face:
    """A boundary face of an imported solid (lengths in m).

    tag: the importer's face number (never shown to users as a selector); kind: "plane", "cylinder" or
    "other"; points: sample points on the face (n, 3); normal: the outward unit normal (planes);
    axis, axis_point, radius: the cylinder's unit axis, a point on it and its radius (cylinders); concave: a
    cylinder whose material lies outside it (a bore, not a boss); area (m^2)."""

    tag: int
    kind: str
    points: np.ndarray
    area: float = 0.0
    normal: Optional[np.ndarray] = None
    axis: Optional[np.ndarray] = None
    axis_point: Optional[np.ndarray] = None
    radius: Optional[float] = None
    concave: bool = True
    extra: dict = field(default_factory=dict)
    triangles: Optional[np.ndarray] = None   # (n, 3, 3): a triangulation of the face, for exact distances
    centre: Optional[np.ndarray] = None      # the centre of mass of the face (m), where the importer knows it

    def distance(self, point) -> float:
        """Distance (m) from a point to the face: to its triangles if it has any, else to its sample points."""
        p = np.asarray(point, dtype=float)
        if self.triangles is None or not len(self.triangles):
            return float(np.linalg.norm(self.points - p, axis=1).min())
        return float(point_triangle_distance(p, self.triangles).min())

    @property
    def lo(self) -> np.ndarray:
        return self.points.min(axis=0)

    @property
    def hi(self) -> np.ndarray:
        return self.points.max(axis=0)


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def _parallel(a: np.ndarray, b: np.ndarray) -> bool:
    return abs(float(np.dot(a, b))) >= np.cos(ANGLE_TOLERANCE)


def distance_to_line(point, line_point, direction) -> float:
    """Distance (m) of `point` from the line through `line_point` along the unit vector `direction`."""
    d = np.asarray(point, dtype=float) - np.asarray(line_point, dtype=float)
    return float(np.linalg.norm(d - np.dot(d, direction) * direction))


def select_bore(faces: list[Face], selector: BoreSelector, key: str) -> list[int]:
    """Tags of the cylindrical faces of a bore (see BoreSelector).  InputError naming `key` when no face
    matches, or when faces of two different radii match (two bores on one axis: give the radius)."""
    axis = _unit(selector.axis)
    tol = selector.tolerance
    hits = [f for f in faces if f.kind == "cylinder" and f.concave and _parallel(f.axis, axis)
            and distance_to_line(selector.centre, f.axis_point, f.axis) <= tol
            and (selector.radius is None or abs(f.radius - selector.radius) <= tol)
            and (selector.span is None or _within_span(f, selector, axis))]
    if not hits:
        near = [f for f in faces if f.kind == "cylinder" and f.concave and _parallel(f.axis, axis)]
        hint = ""
        if near:
            best = min(near, key=lambda f: distance_to_line(selector.centre, f.axis_point, f.axis))
            hint = (f"; the nearest bore along that axis has radius {best.radius * 1e3:.4g} mm and its axis "
                    f"{distance_to_line(selector.centre, best.axis_point, best.axis) * 1e3:.4g} mm from centre "
                    f"(housingfe inspect lists the bores)")
        raise InputError(f"{key}: no cylindrical face on the axis {_fmt(axis)} through {_fmt(selector.centre)} m"
                         + (f" with radius {selector.radius:g} m" if selector.radius else "")
                         + (f" between {selector.span[0]:g} and {selector.span[1]:g} m along it" if selector.span
                            else "") + hint)
    radii = sorted({round(f.radius / tol) for f in hits})
    if len(radii) > 1:
        shown = ", ".join(f"{r * tol * 1e3:.4g}" for r in radii)
        raise InputError(f"{key}: matches {len(radii)} bores of different radius ({shown} mm) on that axis; "
                         f"give radius to pick one")
    return sorted(f.tag for f in hits)


def _within_span(face: Face, selector: BoreSelector, axis: np.ndarray) -> bool:
    """Whether every sample point of `face` lies between span[0] and span[1] (m, +- tolerance) along `axis`
    from the selector's centre."""
    s = (face.points - np.asarray(selector.centre, dtype=float)) @ axis
    return bool(s.min() >= selector.span[0] - selector.tolerance and s.max() <= selector.span[1] + selector.tolerance)


def select_surface(faces: list[Face], selector: SurfaceSelector, key: str) -> list[int]:
    """Tags of the faces of a surface selector; InputError naming `key` when none matches."""
    tol = selector.tolerance
    if selector.plane is not None:
        n = _unit(selector.plane.normal)
        p0 = np.asarray(selector.plane.point, dtype=float)
        hits = [f.tag for f in faces if f.kind == "plane" and np.dot(f.normal, n) >= np.cos(ANGLE_TOLERANCE)
                and np.abs((f.points - p0) @ n).max() <= tol]
        what = f"in the plane through {_fmt(p0)} m with outward normal {_fmt(n)}"
    elif selector.box is not None:
        lo = np.asarray(selector.box.min, dtype=float) - tol
        hi = np.asarray(selector.box.max, dtype=float) + tol
        hits = [f.tag for f in faces if np.all(f.lo >= lo) and np.all(f.hi <= hi)]
        what = f"inside the box {_fmt(selector.box.min)} .. {_fmt(selector.box.max)} m"
    else:
        p = np.asarray(selector.nearest, dtype=float)
        best = min(faces, key=lambda f: f.distance(p))
        return [best.tag]
    if not hits:
        raise InputError(f"{key}: no face {what} (tolerance {tol:g} m; housingfe inspect lists the flat faces)")
    return sorted(hits)


def bore_candidates(faces: list[Face], tol: float) -> list[dict]:
    """Concave cylindrical faces grouped by axis line and radius: one entry per candidate bore with its axis,
    a centre (the middle of its extent along the axis), radius, length along the axis (m) and face tags."""
    # key: the canonical axis, the axis line's point nearest the origin and the radius, on a grid of tol
    # (a dictionary, not a pairwise search: castings have hundreds of bolt holes)
    groups: dict[tuple, dict] = {}
    for f in sorted((f for f in faces if f.kind == "cylinder" and f.concave), key=lambda f: f.tag):
        axis = _canonical(f.axis)
        foot = f.axis_point - np.dot(f.axis_point, axis) * axis
        key = (tuple(np.round(axis / np.sin(ANGLE_TOLERANCE)).astype(int)), tuple(np.round(foot / tol).astype(int)),
               int(round(f.radius / tol)))
        g = groups.setdefault(key, {"axis": axis, "axis_point": f.axis_point, "radius": f.radius, "faces": []})
        g["faces"].append(f)
    groups = list(groups.values())
    out = []
    for g in groups:
        s = np.concatenate([(f.points - g["axis_point"]) @ g["axis"] for f in g["faces"]])
        centre = g["axis_point"] + 0.5 * (s.min() + s.max()) * g["axis"]
        out.append({"axis": g["axis"], "centre": centre, "radius": g["radius"],
                    "length": float(s.max() - s.min()), "area": sum(f.area for f in g["faces"]),
                    "tags": sorted(f.tag for f in g["faces"])})
    return sorted(out, key=lambda b: (-b["radius"], tuple(np.round(b["centre"], 6))))


def flat_candidates(faces: list[Face], tol: float) -> list[dict]:
    """Plane faces grouped by plane (outward normal and offset): each with its normal, a point (the area
    centre), total area (m^2), bounding box and face tags; largest first."""
    groups: dict[tuple, dict] = {}
    for f in sorted((f for f in faces if f.kind == "plane"), key=lambda f: f.tag):
        offset = float(np.mean(f.points @ f.normal))
        key = (tuple(np.round(f.normal / np.sin(ANGLE_TOLERANCE)).astype(int)), int(round(offset / tol)))
        groups.setdefault(key, {"normal": f.normal, "offset": offset, "faces": []})["faces"].append(f)
    groups = list(groups.values())
    out = []
    for g in groups:
        area = sum(f.area for f in g["faces"])
        pts = np.vstack([f.points for f in g["faces"]])
        point = (sum(f.area * (f.centre if f.centre is not None else f.points.mean(axis=0)) for f in g["faces"])
                 / area if area else pts.mean(axis=0))
        point = point - (point @ g["normal"] - g["offset"]) * g["normal"]
        out.append({"normal": g["normal"], "point": point, "area": area, "min": pts.min(axis=0),
                    "max": pts.max(axis=0), "tags": sorted(f.tag for f in g["faces"])})
    return sorted(out, key=lambda p: -p["area"])


def point_triangle_distance(p: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Distance (m) from point p to each triangle (n, 3, 3): to its plane where the foot lies inside it, else
    to the nearest of its three edges."""
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    n = np.cross(b - a, c - a)
    nn = np.einsum("ij,ij->i", n, n)
    nn = np.where(nn > 0, nn, 1.0)
    foot = p - (np.einsum("ij,ij->i", p - a, n) / nn)[:, None] * n
    inside = np.ones(len(triangles), dtype=bool)
    for u, v in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("ij,ij->i", np.cross(v - u, foot - u), n) >= 0
    best = np.where(inside, np.linalg.norm(p - foot, axis=1), np.inf)
    for u, v in ((a, b), (b, c), (c, a)):
        e = v - u
        ee = np.einsum("ij,ij->i", e, e)
        t = np.clip(np.einsum("ij,ij->i", p - u, e) / np.where(ee > 0, ee, 1.0), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(p - (u + t[:, None] * e), axis=1))
    return best


def _canonical(axis: np.ndarray) -> np.ndarray:
    """The axis direction with its largest component positive (so that +y and -y bores group together)."""
    axis = _unit(axis)
    return axis if axis[np.argmax(np.abs(axis))] > 0 else -axis


def _fmt(v) -> str:
    return "(" + ", ".join(f"{float(c):.6g}" for c in v) + ")"
