"""The named surfaces of a geometry without meshing: the boundary faces of its block model (housingfe.geometry.blocks),
classified by the kind's own face classifier, as gmsh's tagging classifies them.  For `housingfe describe`, the
scene reference (docs/scene-reference.md) and its pictures."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from housingfe.geometry.blocks import BlockModel


@dataclass
class Surface:
    """A named surface group: its area (m^2, bores not cut out), the outward normals of its faces ("+x", ...),
    the features (cell groups) it bounds, its bounding box (m) and the faces (centre, normal, half sizes)."""

    name: str
    area: float = 0.0
    normals: set = field(default_factory=set)
    features: set = field(default_factory=set)
    lower: np.ndarray = field(default_factory=lambda: np.full(3, np.inf))
    upper: np.ndarray = field(default_factory=lambda: np.full(3, -np.inf))
    faces: list = field(default_factory=list)


def boundary_faces(model: BlockModel):
    """Yield (centre, outward normal, lower corner, upper corner, feature) of every boundary face of the blocks
    (a face of a material cell whose neighbour across it is not material)."""
    grid = model.grid
    for (i, j, k), feature in model.cells.items():
        idx = (i, j, k)
        lo = np.array([grid[a][idx[a]] for a in range(3)])
        hi = np.array([grid[a][idx[a] + 1] for a in range(3)])
        for axis in range(3):
            for side in (-1, 1):
                neighbour = list(idx)
                neighbour[axis] += side
                if tuple(neighbour) in model.cells:
                    continue
                normal = np.zeros(3)
                normal[axis] = side
                f_lo, f_hi = lo.copy(), hi.copy()
                plane = hi[axis] if side > 0 else lo[axis]
                f_lo[axis] = f_hi[axis] = plane
                yield (f_lo + f_hi) / 2, normal, f_lo, f_hi, feature


def named_surfaces(model: BlockModel) -> dict[str, Surface]:
    """Surface name -> Surface of a block model, in the order the classifier first names them; the bores'
    surfaces (cut by gmsh's OpenCASCADE kernel, not faces of the blocks) are added with their cylinder areas."""
    out: dict[str, Surface] = {}
    for centre, normal, lo, hi, feature in boundary_faces(model):
        extent = hi - lo
        area = float(np.prod([e for e in extent if e > 0]))
        axis = int(np.argmax(np.abs(normal)))
        label = ("+" if normal[axis] > 0 else "-") + "xyz"[axis]
        for name in model.classify_face(centre, normal):
            s = out.setdefault(name, Surface(name))
            s.area += area
            s.normals.add(label)
            s.features.add(feature)
            s.lower, s.upper = np.minimum(s.lower, lo), np.maximum(s.upper, hi)
            s.faces.append((centre, normal, lo, hi))
    for bore in model.bores:
        length = sum(b - a for a, b in model.bore_segments(bore))
        for name in (bore.name, *bore.groups):
            s = out.setdefault(name, Surface(name))
            s.area += 2 * np.pi * bore.radius * length
            s.normals.add(f"radial about {'xyz'[bore.axis]}")
            s.features.add("bore")
            centre = np.asarray(bore.centre, dtype=float)
            s.lower = np.minimum(s.lower, centre - bore.radius)
            s.upper = np.maximum(s.upper, centre + bore.radius)
    return out


def bounding_box(model: BlockModel) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corner (m) of the material cells."""
    idx = np.array(list(model.cells))
    lower = np.array([model.grid[a][idx[:, a].min()] for a in range(3)])
    upper = np.array([model.grid[a][idx[:, a].max() + 1] for a in range(3)])
    return lower, upper
