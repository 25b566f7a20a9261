"""Reusable building blocks of the housings: axis-aligned parts (plates, thick bearing plates, flanges, rims,
feet), named patches on their faces (bolt patches, contact faces, load points), round bores, and the
assembly of all of them into one BlockModel with exact tags.

Every housing module (box halves, gearbox model, test gearbox) lists its parts with these helpers instead of
writing its own grid and classifier.  All lengths in m; x along the housing length, y across it (the shaft
axes of the gearboxes), z up.

Tag rules of `assemble` (the same for every housing):
- cell groups: one per part name (a part listed earlier owns the cells it shares with a later one);
- a boundary face whose outside lies in a cavity box is "inner"; every other face is "outer" and
  "outer_<owner part>" unless a non-radiating patch covers it (feet contact faces);
- patches add their own name (and their groups) to the faces they cover;
- bore faces get the bore's name and groups (never "outer": an open bore does not radiate into the far
  field as a plate does, and a covered one is the cover's business).
"""
from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from housingfe.geometry.blocks import BlockModel, Bore, cells_where, unique_planes

Vec = tuple[float, float, float]
_EPS = 1e-7


@dataclass(frozen=True)
class Part:
    """A solid box of the housing between corners lo and hi (m), belonging to the feature `name`."""

    name: str
    lo: Vec
    hi: Vec

    def contains(self, p: Sequence[float]) -> bool:
        return all(self.lo[a] < p[a] < self.hi[a] for a in range(3))


@dataclass(frozen=True)
class Patch:
    """A named region on boundary faces: faces whose centre lies in the box lo..hi (m) and whose outward
    normal is `normal` (a signed unit axis vector) carry `name` and `groups`.  radiates=False removes the
    faces from "outer" (e.g. feet resting on a base)."""

    name: str
    lo: Vec
    hi: Vec
    normal: Vec
    groups: tuple[str, ...] = ()
    radiates: bool = True

    def covers(self, centre: np.ndarray, normal: np.ndarray) -> bool:
        inside = all(self.lo[a] - 1e-9 <= centre[a] <= self.hi[a] + 1e-9 for a in range(3))
        return inside and float(np.dot(normal, self.normal)) > 0.5


def box_part(name: str, x: tuple[float, float], y: tuple[float, float], z: tuple[float, float]) -> Part:
    """A part from its three coordinate intervals (m)."""
    return Part(name, (x[0], y[0], z[0]), (x[1], y[1], z[1]))


def face_patch(name: str, centre: Vec, size: tuple[float, float], normal: Vec, groups: tuple[str, ...] = (),
               radiates: bool = True) -> Patch:
    """A rectangular patch of `size` (m, the two in-plane extents in axis order) centred on `centre`, on a
    face with outward `normal`."""
    axis = int(np.argmax(np.abs(normal)))
    lo, hi = list(centre), list(centre)
    in_plane = [a for a in range(3) if a != axis]
    for a, s in zip(in_plane, size):
        lo[a] -= s / 2
        hi[a] += s / 2
    return Patch(name, tuple(lo), tuple(hi), tuple(float(v) for v in normal), groups, radiates)


def rim_parts(name: str, x: tuple[float, float], y: tuple[float, float], z: tuple[float, float],
              width: float) -> list[Part]:
    """A rectangular ring of solid section `width` (outward) x (z[1] - z[0]) around the outside of the wall
    outline x * y (m): the welded rim replacing a bolted split, or a flange."""
    (x0, x1), (y0, y1) = x, y
    return [box_part(name, (x0 - width, x1 + width), (y0 - width, y0), z),
            box_part(name, (x0 - width, x1 + width), (y1, y1 + width), z),
            box_part(name, (x0 - width, x0), (y0, y1), z),
            box_part(name, (x1, x1 + width), (y0, y1), z)]


def bore_through(name: str, x: float, z: float, diameter: float, y: tuple[float, float],
                 groups: tuple[str, ...] = (), overshoot: tuple[float, float] = (1e-3, 1e-3)) -> Bore:
    """A bore along y (the shaft direction) with its axis at (x, z), through the material between y[0] and
    y[1] (m); the cutting cylinder overshoots the faces by `overshoot` (m; 0 where a cover closes it)."""
    return Bore(name, (x, 0.5 * (y[0] + y[1]), z), 1, diameter / 2, (y[0] - overshoot[0], y[1] + overshoot[1]),
                groups)


def face_grid_points(lo: Vec, hi: Vec, n: int = 3) -> list[Vec]:
    """n x n sample points at the centres of an n x n division of a flat rectangle lo..hi (m), e.g. the
    response points of one plate."""
    axis = int(np.argmin(np.subtract(hi, lo)))
    a, b = [ax for ax in range(3) if ax != axis]
    out = []
    for i in range(n):
        for j in range(n):
            p = list(lo)
            p[a] = lo[a] + (i + 0.5) * (hi[a] - lo[a]) / n
            p[b] = lo[b] + (j + 0.5) * (hi[b] - lo[b]) / n
            out.append(tuple(float(v) for v in p))
    return out


def assemble(parts: Sequence[Part], cavities: Sequence[Part] = (), patches: Sequence[Patch] = (),
             bores: Sequence[Bore] = (), thin: Iterable[float] = (), points: dict | None = None) -> BlockModel:
    """The BlockModel of a housing made of parts (earlier parts own shared cells), with the tag rules of
    this module.  cavities: boxes of air inside the housing (faces looking into them are "inner").
    thin: wall thicknesses (m) for the through-thickness layers of hex meshes."""
    coords: list[list[float]] = [[], [], []]
    for box in (*parts, *patches):
        for a in range(3):
            coords[a] += [box.lo[a], box.hi[a]]
    grid = tuple(unique_planes(c) for c in coords)

    def feature(x: float, y: float, z: float) -> str | None:
        for part in parts:
            if part.contains((x, y, z)):
                return part.name
        return None

    cells = cells_where(grid, feature)

    def owner(centre: np.ndarray, normal: np.ndarray) -> str:
        name = feature(*(centre - _EPS * normal))
        if name is None:
            raise ValueError(f"boundary face at {np.round(centre, 4).tolist()} has no material behind it")
        return name

    def classify(centre: np.ndarray, normal: np.ndarray) -> list[str]:
        outside = centre + _EPS * normal
        if any(c.contains(outside) for c in cavities):
            names = ["inner"]
        else:
            names = ["outer", f"outer_{owner(centre, normal)}"]
        for patch in patches:
            if patch.covers(centre, normal):
                if not patch.radiates:
                    names = [n for n in names if not n.startswith("outer")]
                names += [patch.name, *patch.groups]
        return list(dict.fromkeys(names))

    return BlockModel(grid=grid, cells=cells, classify_face=classify, thin_dimensions=tuple(sorted(set(thin))),
                      points=dict(points or {}), bores=tuple(bores), merge_for_tets=True,
                      merge_keys=_patch_keys(grid, cells, patches))


def _patch_keys(grid, cells: dict, patches: Sequence[Patch]) -> dict:
    """For merged tet blocks: the patches each cell touches, so that a cell under a patch never merges with
    one outside it (the patch would vanish inside a larger face).  Only the cells at a patch are split:
    a patch edge does not cut the rest of the housing into slivers."""
    keys: dict = {}
    for n, patch in enumerate(patches):
        axis = int(np.argmax(np.abs(patch.normal)))
        for key in cells:
            lo = [grid[a][key[a]] for a in range(3)]
            hi = [grid[a][key[a] + 1] for a in range(3)]
            touches = all(lo[a] < patch.hi[a] - 1e-12 and hi[a] > patch.lo[a] + 1e-12
                          for a in range(3) if a != axis)
            side = hi[axis] if patch.normal[axis] > 0 else lo[axis]
            if touches and abs(side - patch.lo[axis]) < 1e-12:
                keys[key] = keys.get(key, ()) + (n,)
    return keys
