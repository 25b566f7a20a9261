"""Solids assembled from axis-aligned blocks on a tensor grid, meshed by gmsh (OpenCASCADE kernel).

Why a grid of blocks: every block is a hexahedron whose faces conform with its neighbours', so the same
model meshes either as structured quadratic hexahedra (transfinite, exact through-thickness layers, the
symmetry of the part preserved) or as unstructured tetrahedra.  Plates, flanges, feet and rims of the
housings are all unions of such blocks; each block carries the name of the feature it belongs to, and
boundary faces are classified by their position so tags are exact, not found by tolerance searches.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

# A face classifier gets (centre xyz, outward unit normal xyz) of a boundary face and returns the names of
# the surface groups the face belongs to.
# gmsh 3-D algorithm for tetrahedra: 10 = HXT (robust, best minimum quality measured here)
TET_ALGORITHM = 10

FaceClassifier = Callable[[np.ndarray, np.ndarray], Sequence[str]]


@dataclass
class BlockModel:
    """A solid made of grid cells.

    grid: the x, y and z plane coordinates (m), ascending.
    cells: (i, j, k) -> feature name for every material cell between planes i..i+1, j..j+1, k..k+1.
    classify_face: names of the surface groups of a boundary face (see FaceClassifier).
    thin_dimensions: lengths (m) treated as wall thicknesses: curves that short get `layers` elements.
    points: named reference points (m), e.g. bolt centres, kept as metadata.
    """

    grid: tuple[np.ndarray, np.ndarray, np.ndarray]
    cells: dict[tuple[int, int, int], str]
    classify_face: FaceClassifier
    thin_dimensions: tuple[float, ...] = ()
    points: dict[str, list[tuple[float, float, float]]] = field(default_factory=dict)

    def contains(self, point) -> bool:
        """True if the point (m) lies strictly inside a material cell."""
        index = []
        for axis, planes in enumerate(self.grid):
            i = int(np.searchsorted(planes, point[axis])) - 1
            if i < 0 or i >= len(planes) - 1:
                return False
            index.append(i)
        return tuple(index) in self.cells

    def volume(self) -> float:
        """Exact volume (m^3) of the material cells."""
        gx, gy, gz = self.grid
        return float(sum((gx[i + 1] - gx[i]) * (gy[j + 1] - gy[j]) * (gz[k + 1] - gz[k])
                         for i, j, k in self.cells))

    def centroid(self) -> np.ndarray:
        """Exact centroid (m) of the material cells."""
        gx, gy, gz = self.grid
        total, moment = 0.0, np.zeros(3)
        for i, j, k in self.cells:
            v = (gx[i + 1] - gx[i]) * (gy[j + 1] - gy[j]) * (gz[k + 1] - gz[k])
            c = np.array([gx[i] + gx[i + 1], gy[j] + gy[j + 1], gz[k] + gz[k + 1]]) / 2
            total += v
            moment += v * c
        return moment / total


def unique_planes(values: Sequence[float], tol: float = 1e-9) -> np.ndarray:
    """Sorted plane coordinates with near-duplicates (closer than tol, m) merged."""
    out: list[float] = []
    for v in sorted(values):
        if not out or v - out[-1] > tol:
            out.append(float(v))
    return np.array(out)


def cells_where(grid, predicate: Callable[[float, float, float], str | None]) -> dict:
    """Material cells of a grid: predicate(xc, yc, zc) at the cell centre returns a feature name or None."""
    gx, gy, gz = grid
    cells = {}
    for i in range(len(gx) - 1):
        for j in range(len(gy) - 1):
            for k in range(len(gz) - 1):
                name = predicate((gx[i] + gx[i + 1]) / 2, (gy[j] + gy[j + 1]) / 2, (gz[k] + gz[k + 1]) / 2)
                if name:
                    cells[(i, j, k)] = name
    return cells


def divisions(length: float, size: float, thin: Sequence[float], layers: int) -> int:
    """Number of elements along an edge of `length` (m) for target element size `size` (m); edges as
    short as a wall thickness get `layers` elements."""
    if any(abs(length - t) < 1e-9 for t in thin) or length < 0.999 * min(thin, default=0.0):
        return max(layers, math.ceil(length / size - 1e-9))
    return max(1, math.ceil(length / size - 1e-9))


def build_gmsh_model(model: BlockModel, element: str, size: float, layers: int) -> dict[str, dict[str, int]]:
    """Create the blocks in the current gmsh model, fragment them into one conforming solid, define physical
    groups (volumes per feature, surfaces per classifier name) and mesh.

    element: "hex" (transfinite, recombined hexahedra) or "tet".  size: target element size (m).
    Returns {"cells": {name: tag}, "facets": {name: [tags]}} of the physical groups (a surface name may
    cover several facet tag values).
    Runs on the calling rank only; the caller owns gmsh initialise/finalise.
    """
    import gmsh

    occ = gmsh.model.occ
    gx, gy, gz = model.grid
    keys = sorted(model.cells)
    tags = []
    for i, j, k in keys:
        tags.append(occ.addBox(gx[i], gy[j], gz[k], gx[i + 1] - gx[i], gy[j + 1] - gy[j], gz[k + 1] - gz[k]))
    if len(tags) > 1:
        _, out_map = occ.fragment([(3, t) for t in tags[:1]], [(3, t) for t in tags[1:]])
    else:
        out_map = [[(3, tags[0])]]
    occ.synchronize()
    # out_map[n] lists the volumes that input n became; blocks never overlap, so each maps to one volume.
    feature_volumes: dict[str, list[int]] = {}
    for key, pieces in zip(keys, out_map):
        for dim, tag in pieces:
            feature_volumes.setdefault(model.cells[key], []).append(tag)

    cell_groups = {}
    for n, name in enumerate(sorted(feature_volumes), start=1):
        gmsh.model.addPhysicalGroup(3, feature_volumes[name], n)
        gmsh.model.setPhysicalName(3, n, name)
        cell_groups[name] = n

    facet_groups = _classify_boundary(model)

    _set_mesh_options(element)
    if element == "hex":
        _make_transfinite(model, size, layers)
    else:
        gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        gmsh.model.mesh.setSize(gmsh.model.getEntities(0), size)
    gmsh.model.mesh.generate(3)
    if element == "tet":
        _retry_slivers()
    return {"cells": cell_groups, "facets": facet_groups}


def _classify_boundary(model: BlockModel) -> dict[str, list[int]]:
    """Physical surface groups.  A dolfinx facet tag holds one value per facet, so each face gets one
    atomic group named by all its names ("outer/outer_top"); every name maps to the union of the
    atomic groups that carry it."""
    import gmsh

    boundary = gmsh.model.getBoundary(gmsh.model.getEntities(3), combined=True, oriented=False)
    atomic: dict[tuple[str, ...], list[int]] = {}
    for dim, tag in boundary:
        centre = np.array(gmsh.model.occ.getCenterOfMass(2, abs(tag)))
        names = tuple(model.classify_face(centre, _outward_normal(abs(tag), centre, model)))
        atomic.setdefault(names, []).append(abs(tag))
    facet_groups: dict[str, list[int]] = {}
    for n, names in enumerate(sorted(atomic), start=1):
        gmsh.model.addPhysicalGroup(2, sorted(set(atomic[names])), n)
        gmsh.model.setPhysicalName(2, n, "/".join(names))
        for name in names:
            facet_groups.setdefault(name, []).append(n)
    return facet_groups


def _outward_normal(face: int, centre: np.ndarray, model: BlockModel) -> np.ndarray:
    """Outward normal of an axis-aligned boundary face: the axis direction pointing out of the solid."""
    import gmsh

    xmin, ymin, zmin, xmax, ymax, zmax = gmsh.model.getBoundingBox(2, face)
    axis = int(np.argmin([xmax - xmin, ymax - ymin, zmax - zmin]))
    normal = np.zeros(3)
    normal[axis] = 1.0
    return -normal if model.contains(centre + 1e-7 * normal) else normal


def _set_mesh_options(element: str) -> None:
    """Set every gmsh option the builders rely on (gmsh 4.8 options survive gmsh.clear())."""
    import gmsh

    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("Mesh.RecombineAll", 0)
    gmsh.option.setNumber("Mesh.Recombine3DAll", 0)
    gmsh.option.setNumber("Mesh.ElementOrder", 1)
    gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 1 if element == "tet" else 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 1)
    gmsh.option.setNumber("Mesh.Algorithm", 6)
    gmsh.option.setNumber("Mesh.Algorithm3D", TET_ALGORITHM)
    gmsh.option.setNumber("Mesh.Optimize", 1)
    gmsh.option.setNumber("Mesh.OptimizeThreshold", 0.3)
    gmsh.option.setNumber("General.NumThreads", 1)   # HXT is not reproducible with several threads
    gmsh.option.setNumber("Mesh.RandomSeed", 1)
    gmsh.option.setNumber("Mesh.RandomFactor", 1e-9)


def _make_transfinite(model: BlockModel, size: float, layers: int) -> None:
    import gmsh

    mesh = gmsh.model.mesh
    for _, curve in gmsh.model.getEntities(1):
        xmin, ymin, zmin, xmax, ymax, zmax = gmsh.model.getBoundingBox(1, curve)
        length = max(xmax - xmin, ymax - ymin, zmax - zmin)
        mesh.setTransfiniteCurve(curve, divisions(length, size, model.thin_dimensions, layers) + 1)
    for _, surface in gmsh.model.getEntities(2):
        mesh.setTransfiniteSurface(surface)
        mesh.setRecombine(2, surface)
    for _, volume in gmsh.model.getEntities(3):
        mesh.setTransfiniteVolume(volume)


def _retry_slivers(min_quality: float = 0.08, attempts: int = 3) -> None:
    """HXT occasionally leaves a sliver tetrahedron (it is not deterministic): re-mesh with a perturbed
    random factor until the minimum shape ratio passes, instead of handing a sliver to the solver."""
    import gmsh

    from housingfe.geometry.mesh import _tet_quality

    for attempt in range(attempts):
        _, _, conn = gmsh.model.mesh.getElements(3)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        xyz = np.zeros((int(tags.max()) + 1, 3))
        xyz[tags.astype(int)] = coords.reshape(-1, 3)
        if _tet_quality(xyz[conn[0].reshape(-1, 4).astype(int)]).min() >= min_quality:
            return
        gmsh.option.setNumber("Mesh.RandomFactor", 1e-9 * (attempt + 2))
        gmsh.model.mesh.clear()
        gmsh.model.mesh.generate(3)
