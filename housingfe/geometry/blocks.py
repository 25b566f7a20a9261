"""Solids assembled from axis-aligned blocks on a tensor grid, meshed by gmsh (its built-in kernel for hexahedra,
OpenCASCADE for tetrahedra and wherever round bores are cut).

Why a grid of blocks: every block is a hexahedron whose faces conform with its neighbours', so the same
model meshes either as structured quadratic hexahedra (transfinite, exact through-thickness layers, the
symmetry of the part preserved) or as unstructured tetrahedra.  Plates, flanges, feet and rims of the
housings are all unions of such blocks; each block carries the name of the feature it belongs to, and
boundary faces are classified by their position so tags are exact, not found by tolerance searches.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

# A face classifier gets (centre xyz, outward unit normal xyz) of a boundary face and returns the names of
# the surface groups the face belongs to.
# gmsh 3-D algorithm for tetrahedra: 1 = Delaunay.  HXT (10) gave better slivers but is not reproducible in
# gmsh 4.8, not even on one thread with a fixed seed and address randomisation off (test-gearbox-interior: 7603 to
# 7611 tetrahedra and moved nodes from run to run, 61 584-61 659 DOFs on gearbox-model-interior, 1 vs 2 MPI
# ranks differed): Delaunay gives the same mesh every time; its slivers are refined away (_refine_slivers).
# Where halving the size around them fails (thin walls at elements several times the wall thickness), further
# Delaunay meshes are tried before HXT (_delaunay_retries, 2026-11-28): finer balls around the slivers, then the
# whole model at 0.95/0.9/0.85 of the size (a new surface triangulation across the walls).  Measured: test-gearbox
# with 11.5 mm walls at 28 mm (the run-up's size; HXT gave 64 584 / 64 659 DOFs run to run) passes at balls of
# 0.35 x size (worst 0.034 -> 0.089), box-free as tets at 30 and 45 mm at 0.85 and 0.9 x size (0.084, 0.082); all
# mesh identically twice (docs/stability.md).  HXT stays the last resort, and the mesher string says which ran;
# meshes with slivers everywhere (MAX_RETRY_SLIVERS) go to it at once.  Meshes that passed before are unchanged.
# Where the retries fail, points are embedded inside the slivers one refinement leaves (_embed_points_at_slivers):
# box-free as tets at 56.6 mm, worst 0.031 on HXT (not reproducible), 0.105 so, the same mesh twice; where that
# fails, the same after two refinements (box-free as tets at its 40 mm: 22 slivers after one refinement, 30 after
# the points; 3 after two, 1 after the first points, none after the second: worst 0.090, docs/stability.md).
# Netgen's optimiser (Mesh.OptimizeNetgen) is not compiled into this gmsh 4.8; Relocate3D does not move the
# slivers, whose four corners lie on the boundary.
TET_ALGORITHM = 1
HXT_ALGORITHM = 10
# below this minimum shape ratio after the sliver refinement, fall back to HXT (housingfe.fe.model rejects < 0.05)
DELAUNAY_MIN_QUALITY = 0.06
# where halving the size around the slivers does not lift them above DELAUNAY_MIN_QUALITY, these finer balls
# (fractions of the element size) are tried, still Delaunay, before HXT
SLIVER_RETRY_FINE = (0.35, 0.25)
# and then the whole model at these fractions of the element size
SLIVER_RETRY_SIZE_FACTORS = (0.95, 0.9, 0.85)
# no retries where more elements than this are slivers after the refinement (the cases the retries rescue had
# 2-16; NAFEMS FV12 at t/L = 1/1000 has 7360 of 7362, docs/stability.md)
MAX_RETRY_SLIVERS = 100
# where the retries fail, a point is embedded inside each sliver left by the refinement (_embed_points_at_slivers);
# not where more elements than this are slivers in the plain mesh (FV12 at t/L = 1/1000: 7360)
MAX_EMBED_SLIVERS = 1000
# and at most this many rounds of embedding
EMBED_ROUNDS = 3
# the numbers of refinements (halvings around the slivers, accumulated) tried in turn before the points are embedded
# (box-free as tets at 40 mm: 22 slivers after one, points fail; 3 after two, points pass)
EMBED_REFINEMENTS = (1, 2)

FaceClassifier = Callable[[np.ndarray, np.ndarray], Sequence[str]]


@dataclass(frozen=True)
class Bore:
    """A round hole along a coordinate axis, cut out of the blocks (all lengths in m).

    name: the surface group of the bore face; groups: further surface groups it belongs to.
    centre: a point on the axis; axis: 0, 1 or 2 (x, y, z); radius; span: (start, end) along the axis,
    overshooting the material it cuts (OCC booleans dislike coplanar faces).
    The disc of the bore must lie inside material cells wherever the axis runs through material (checked).
    """

    name: str
    centre: tuple[float, float, float]
    axis: int
    radius: float
    span: tuple[float, float]
    groups: tuple[str, ...] = ()


@dataclass
class BlockModel:
    """A solid made of grid cells.

    grid: the x, y and z plane coordinates (m), ascending.
    cells: (i, j, k) -> feature name for every material cell between planes i..i+1, j..j+1, k..k+1.
    classify_face: names of the surface groups of a boundary face (see FaceClassifier).
    thin_dimensions: lengths (m) treated as wall thicknesses: curves that short get `layers` elements.
    points: named reference points (m), e.g. bolt centres, kept as metadata.
    bores: round holes cut out of the blocks (tetrahedral meshes only).
    """

    grid: tuple[np.ndarray, np.ndarray, np.ndarray]
    cells: dict[tuple[int, int, int], str]
    classify_face: FaceClassifier
    thin_dimensions: tuple[float, ...] = ()
    points: dict[str, list[tuple[float, float, float]]] = field(default_factory=dict)
    bores: tuple[Bore, ...] = ()
    # tetrahedral meshes: build the solid from maximal boxes of same-feature cells instead of one box per
    # cell (far fewer OCC booleans; the mesh no longer follows every grid plane, which tets need not)
    merge_for_tets: bool = False
    # cells merge only with cells of the same feature and the same key here (e.g. the patches they carry,
    # so that a patch keeps its own faces); missing cells have key None
    merge_keys: dict[tuple[int, int, int], object] = field(default_factory=dict)

    def contains(self, point) -> bool:
        """True if the point (m) lies strictly inside the material (inside a cell, outside every bore)."""
        if not self.in_cells(point):
            return False
        return not any(_in_bore(b, point) for b in self.bores)

    def in_cells(self, point) -> bool:
        """True if the point (m) lies strictly inside a material cell (bores ignored)."""
        index = []
        for axis, planes in enumerate(self.grid):
            i = int(np.searchsorted(planes, point[axis])) - 1
            if i < 0 or i >= len(planes) - 1:
                return False
            index.append(i)
        return tuple(index) in self.cells

    def volume(self) -> float:
        """Exact volume (m^3) of the material: cells minus bores."""
        return self._volume_and_moment()[0]

    def centroid(self) -> np.ndarray:
        """Exact centroid (m) of the material: cells minus bores."""
        total, moment = self._volume_and_moment()
        return moment / total

    def _volume_and_moment(self) -> tuple[float, np.ndarray]:
        gx, gy, gz = self.grid
        total, moment = 0.0, np.zeros(3)
        for i, j, k in self.cells:
            v = (gx[i + 1] - gx[i]) * (gy[j + 1] - gy[j]) * (gz[k + 1] - gz[k])
            c = np.array([gx[i] + gx[i + 1], gy[j] + gy[j + 1], gz[k] + gz[k + 1]]) / 2
            total += v
            moment += v * c
        for bore in self.bores:
            for start, end in self.bore_segments(bore):
                v = math.pi * bore.radius**2 * (end - start)
                c = np.array(bore.centre, dtype=float)
                c[bore.axis] = (start + end) / 2
                total -= v
                moment -= v * c
        return total, moment

    def bore_segments(self, bore: Bore) -> list[tuple[float, float]]:
        """Intervals (m, along the bore axis) where the bore runs through material.  Raises ValueError if
        the bore's disc is not wholly inside material cells there (the exact volume would be wrong and the
        bore would break out of the part)."""
        planes = self.grid[bore.axis]
        cuts = [p for p in planes if bore.span[0] < p < bore.span[1]]
        stations = [bore.span[0], *cuts, bore.span[1]]
        segments: list[tuple[float, float]] = []
        for a, b in itertools.pairwise(stations):
            mid = np.array(bore.centre, dtype=float)
            mid[bore.axis] = (a + b) / 2
            if not self.in_cells(mid):
                continue
            if not all(self.in_cells(p) for p in _disc_rim(bore, mid)):
                raise ValueError(f"bore {bore.name}: the disc of radius {bore.radius} m breaks out of the "
                                 f"material near {np.round(mid, 4).tolist()}")
            if segments and abs(segments[-1][1] - a) < 1e-12:
                segments[-1] = (segments[-1][0], b)
            else:
                segments.append((a, b))
        return segments


def _in_bore(bore: Bore, point) -> bool:
    p = np.asarray(point, dtype=float) - np.asarray(bore.centre, dtype=float)
    if not bore.span[0] < point[bore.axis] < bore.span[1]:
        return False
    p[bore.axis] = 0.0
    return float(np.linalg.norm(p)) < bore.radius


def _disc_rim(bore: Bore, centre: np.ndarray, n: int = 36, margin: float = 1.0 + 1e-6) -> list[np.ndarray]:
    """Points just outside the rim of the bore's disc at `centre`."""
    a, b = [ax for ax in range(3) if ax != bore.axis]
    out = []
    for phi in np.linspace(0.0, 2 * math.pi, n, endpoint=False):
        p = centre.copy()
        p[a] += margin * bore.radius * math.cos(phi)
        p[b] += margin * bore.radius * math.sin(phi)
        out.append(p)
    return out


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


def divisions(length: float, size: float, thin: Sequence[float], layers: int,
              layer_size: float | None = None) -> int:
    """Number of elements along an edge of `length` (m) for target element size `size` (m); edges no longer
    than a wall thickness get at least `layers` elements, and with `layer_size` (m) at least
    ceil(length / layer_size): elements of about that length through every wall, so a thicker wall (the box's
    15 mm flange against its 8 mm walls) gets more layers.  A length that is a whole multiple of the size up to
    round-off gets exactly that many (slack 1e-6 of a division; the built-in kernel's lengths are exact, OCC's
    bounding boxes, used before 2026-11-25, carried ~1e-7 m per side and so gave one division more there).
    The 1 um slack on the thin test: edges are compared with the thicknesses of the model they came from."""
    if length <= max(thin, default=0.0) + 1e-6:
        through = math.ceil(length / layer_size - 1e-6) if layer_size else 1
        return max(layers, through, math.ceil(length / size - 1e-6))
    return max(1, math.ceil(length / size - 1e-6))


def build_gmsh_model(model: BlockModel, element: str, size: float, layers: int,
                     grading: float = 1.0, layer_size: float | None = None) -> dict[str, dict[str, int]]:
    """Create the blocks in the current gmsh model as one conforming solid (hexahedra: grid cells sharing their
    faces in gmsh's built-in kernel; tetrahedra: OCC boxes with the bores cut, fragmented), define physical
    groups (volumes per feature, surfaces per classifier name) and mesh.

    element: "hex" (transfinite, recombined hexahedra) or "tet".  size: target element size (m).
    grading: hex only, end-to-middle element length ratio along block edges longer than a wall (1 = uniform).
    layers, layer_size: hex only, elements through every wall: at least `layers`, and at least
    ceil(thickness / layer_size) where layer_size (m) is given (`divisions`).
    Returns {"cells": {name: tag}, "facets": {name: [tags]}} of the physical groups (a surface name may
    cover several facet tag values).
    Runs on the calling rank only; the caller owns gmsh initialise/finalise.
    """
    import gmsh

    if model.bores and element != "tet":
        from housingfe.errors import InputError

        raise InputError("mesh.element: a geometry with round bores needs element = \"tet\"")
    for bore in model.bores:
        model.bore_segments(bore)  # raises if a bore breaks out of the material
    if element == "hex" and not model.bores:
        feature_volumes, atomic = _glued_cells(model)
    else:
        feature_volumes = _fragmented_blocks(model, element)
        atomic = _classify_boundary(model)

    cell_groups = {}
    for n, name in enumerate(sorted(feature_volumes), start=1):
        gmsh.model.addPhysicalGroup(3, feature_volumes[name], n)
        gmsh.model.setPhysicalName(3, n, name)
        cell_groups[name] = n
    facet_groups = _facet_groups(atomic)

    if element == "tet":
        return {"cells": cell_groups, "facets": facet_groups, "mesher": mesh_tetrahedra(size)}
    _set_mesh_options(element)
    _make_transfinite(model, size, layers, grading, layer_size)
    gmsh.model.mesh.generate(3)
    return {"cells": cell_groups, "facets": facet_groups, "mesher": "transfinite hexahedra (reproducible)"}


def distribute_gmsh_model(comm):
    """The meshed gmsh model of rank 0 as a dolfinx mesh distributed over comm's ranks: (mesh, cell_tags,
    facet_tags), with the facet-to-cell connectivity the facet tags need.  Finalizes gmsh on rank 0 (also when
    the import fails): the builders (housingfe.geometry.mesh, the CAD import) initialise it there."""
    import gmsh
    from dolfinx.io import gmshio

    try:
        mesh, cell_tags, facet_tags = gmshio.model_to_mesh(gmsh.model if comm.rank == 0 else None, comm, 0, gdim=3)
    finally:
        if comm.rank == 0:
            gmsh.finalize()
    mesh.topology.create_connectivity(2, 3)
    return mesh, cell_tags, facet_tags


def mesh_tetrahedra(size: float, hxt_fallback: bool = True) -> str:
    """Mesh the current gmsh model with linear tetrahedra of `size` (m) the project's way: every option set,
    Delaunay on one thread (reproducible), slivers refined away (Delaunay retries, then points embedded in the
    slivers left), HXT only where that fails (hxt_fallback;
    False keeps Delaunay's best mesh, slivers and all, for the caller's quality rule).  Returns the mesher's
    description for the reports.  Any OCC solid can be meshed so (block models, imported CAD)."""
    import gmsh

    _set_mesh_options("tet")
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
    _set_tet_size(size)
    gmsh.model.mesh.generate(3)
    # without the fallback (CAD parts): stop refining once an attempt makes the worst element no better (FTC-06
    # at 12 mm: 0.0002, 0.006, then 0.0001 with 135 spots, and a later attempt ran for 17 minutes in Delaunay)
    worst = _refine_slivers(size, stop_unless_better=not hxt_fallback)
    if worst < DELAUNAY_MIN_QUALITY and not hxt_fallback:
        return f"gmsh Delaunay (reproducible; slivers left, worst {worst:.3f})"
    if worst >= DELAUNAY_MIN_QUALITY:
        return "gmsh Delaunay (reproducible)"
    retried = _delaunay_retries(size)
    if retried is not None:
        return retried
    for refinements in EMBED_REFINEMENTS:
        embedded = _embed_points_at_slivers(size, refinements)
        if embedded is not None:
            return embedded
    _set_tet_size(size)
    _hxt_fallback(size)
    return "gmsh HXT (Delaunay left slivers; HXT is not reproducible run to run)"


def _set_tet_size(size: float) -> None:
    """Element size (m) of the next tetrahedral mesh: the largest allowed and the size at every model point."""
    import gmsh

    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.model.mesh.setSize(gmsh.model.getEntities(0), size)


def _delaunay_retries(size: float) -> str | None:
    """Deterministic Delaunay meshes tried, in order, where the sliver refinement at `size` (m) left the worst
    shape ratio below DELAUNAY_MIN_QUALITY: first the refinement again from its best mesh with finer balls
    (SLIVER_RETRY_FINE; the size elsewhere unchanged), then the whole model meshed and refined at slightly
    smaller sizes (SLIVER_RETRY_SIZE_FACTORS; a different surface triangulation across the thin walls).  Returns
    the mesher's description of the first that passes (the mesh stays in gmsh), None if none does: at once where
    more than MAX_RETRY_SLIVERS elements are below the refinement's target (flat elements everywhere, walls far
    thinner than the elements: no retry can help, and each would cost a mesh with a ball per sliver)."""
    if int((_tet_qualities()[0] < 0.08).sum()) > MAX_RETRY_SLIVERS:
        return None
    for fine in SLIVER_RETRY_FINE:
        if _refine_slivers(size, fine=fine) >= DELAUNAY_MIN_QUALITY:
            return f"gmsh Delaunay (reproducible; slivers refined to {fine:g} x size)"
    for factor in SLIVER_RETRY_SIZE_FACTORS:
        _set_tet_size(factor * size)
        _remesh_finer_at(np.zeros((0, 3)), factor * size)
        if _refine_slivers(factor * size) >= DELAUNAY_MIN_QUALITY:
            return f"gmsh Delaunay (reproducible; at {factor:g} x size)"
    return None


def _embed_points_at_slivers(size: float, refinements: int = 1) -> str | None:
    """Last deterministic route before HXT, for slivers the refinement moves rather than removes (box-free as
    tets at 56.6 mm, 2026-11-28: the plain mesh's 244 slivers sit in the 8 x 8 mm corner columns, one element
    long; halving the size around them leaves 2-4 flat tets across the 8 mm plates, whose two faces got nearly
    the same triangulation, four corners in one plane, shape ratio 1e-4).  Re-mesh at `size` (m) with the size
    halved around the plain mesh's slivers (`refinements` times, each adding the slivers it left to the balls),
    then put a point inside each sliver still left (its centroid, embedded in its volume: the tetrahedra around
    it are rebuilt with an interior vertex) and re-mesh, up to EMBED_ROUNDS times.  Returns the mesher's
    description once the worst shape ratio reaches DELAUNAY_MIN_QUALITY, None if it does not or where more than
    MAX_EMBED_SLIVERS elements (plain mesh) or MAX_RETRY_SLIVERS (after the refinement) are slivers; the embedded
    points are then removed again."""
    import gmsh

    if int((_tet_qualities()[0] < 0.08).sum()) > MAX_EMBED_SLIVERS:
        return None
    _set_tet_size(size)
    _remesh_finer_at(np.zeros((0, 3)), size)
    q, mid = _tet_qualities()
    if int((q < 0.08).sum()) > MAX_EMBED_SLIVERS:
        return None
    spots = mid[q < 0.08]
    _remesh_finer_at(spots, size)
    embedded, slivers = [], len(spots)
    for _ in range(refinements - 1):
        q, mid = _tet_qualities()
        spots = np.vstack([spots, mid[q < 0.08]])
        _remesh_finer_at(spots, size)
    done = "gmsh Delaunay (reproducible; slivers refined{}, points embedded in the rest)".format(
        "" if refinements == 1 else f" {refinements} times")
    for _ in range(EMBED_ROUNDS):
        q, mid = _tet_qualities()
        if q.min() >= DELAUNAY_MIN_QUALITY:
            return done
        bad = np.flatnonzero(q < 0.08)
        if len(bad) > min(MAX_RETRY_SLIVERS, slivers):
            break       # no fewer slivers than before the last points (box-free at 40 mm: 22, 30, 113)
        slivers = len(bad)
        # the volume of each sliver, in _tet_qualities' order (all tetrahedra, gmsh's order)
        volume_of = {}
        for _, volume in gmsh.model.getEntities(3):
            for tags in gmsh.model.mesh.getElements(3, volume)[1]:
                volume_of.update(dict.fromkeys(tags.tolist(), volume))
        tet_tags = gmsh.model.mesh.getElements(3)[1][0]
        volumes = [volume_of[int(tet_tags[i])] for i in bad]
        points = [gmsh.model.occ.addPoint(*mid[i]) for i in bad]
        embedded += points
        gmsh.model.occ.synchronize()
        for point, volume in zip(points, volumes):
            gmsh.model.mesh.embed(0, [point], 3, volume)
        _set_tet_size(size)
        _remesh_finer_at(spots, size)
    if _tet_qualities()[0].min() >= DELAUNAY_MIN_QUALITY:
        return done
    # the points go again, so that HXT meshes the model as before (left in, box-free at 40 mm got worst 0.004;
    # removed without removeEmbedded, the volumes kept dangling points: nodes at the origin)
    gmsh.model.mesh.removeEmbedded(gmsh.model.getEntities(3), 0)
    gmsh.model.occ.remove([(0, point) for point in embedded])
    gmsh.model.occ.synchronize()
    return None


def _glued_cells(model: BlockModel) -> tuple[dict[str, list[int]], dict[tuple[str, ...], list[int]]]:
    """The grid cells as volumes of gmsh's built-in kernel that share their faces, edges and corners by
    construction (what OCC's fragment of the cell boxes gives, without the boolean: 0.69 s of a 1 s mesh of the
    box at 30 mm).  Returns the volumes per feature and the boundary faces per tuple of surface names."""
    import gmsh

    geo = gmsh.model.geo
    grid = model.grid
    points: dict[tuple, int] = {}
    lines: dict[tuple, int] = {}
    faces: dict[tuple, int] = {}
    owners: dict[int, list[tuple[np.ndarray, np.ndarray]]] = {}   # face -> (centre, outward normal) per cell

    def point(idx):
        if idx not in points:
            points[idx] = geo.addPoint(*(grid[a][idx[a]] for a in range(3)))
        return points[idx]

    def directed_line(a, b):   # a line from grid point a to its neighbour b (signed tag)
        lo, hi = min(a, b), max(a, b)
        if (lo, hi) not in lines:
            lines[(lo, hi)] = geo.addLine(point(lo), point(hi))
        return lines[(lo, hi)] if a == lo else -lines[(lo, hi)]

    def face(corners):
        key = tuple(sorted(corners))
        if key not in faces:
            loop = geo.addCurveLoop([directed_line(corners[m], corners[(m + 1) % 4]) for m in range(4)])
            faces[key] = geo.addPlaneSurface([loop])
        return faces[key]

    feature_volumes: dict[str, list[int]] = {}
    for cell, name in sorted(model.cells.items()):
        cell_faces = []
        for axis in range(3):
            b, c = [ax for ax in range(3) if ax != axis]
            for side in (0, 1):
                corners = []
                for db, dc in ((0, 0), (1, 0), (1, 1), (0, 1)):
                    idx = list(cell)
                    idx[axis] += side
                    idx[b] += db
                    idx[c] += dc
                    corners.append(tuple(idx))
                tag = face(corners)
                cell_faces.append(tag)
                lo = np.array([grid[a][cell[a] + (side if a == axis else 0)] for a in range(3)])
                hi = np.array([grid[a][cell[a] + (side if a == axis else 1)] for a in range(3)])
                normal = np.zeros(3)
                normal[axis] = 1.0 if side else -1.0
                owners.setdefault(tag, []).append(((lo + hi) / 2, normal))
        volume = geo.addVolume([geo.addSurfaceLoop(cell_faces)])
        feature_volumes.setdefault(name, []).append(volume)
    geo.synchronize()
    atomic: dict[tuple[str, ...], list[int]] = {}
    for tag, sides in owners.items():
        if len(sides) == 1:   # a face of one cell only: the boundary of the solid
            centre, normal = sides[0]
            atomic.setdefault(tuple(model.classify_face(centre, normal)), []).append(tag)
    return feature_volumes, atomic


def _fragmented_blocks(model: BlockModel, element: str) -> dict[str, list[int]]:
    """The blocks (cells, or merged boxes for tetrahedra) as OCC boxes with the bores cut out, fragmented into
    one conforming solid.  Returns the volumes per feature."""
    import gmsh

    occ = gmsh.model.occ
    gx, gy, gz = model.grid
    if element == "tet" and model.merge_for_tets:
        boxes = merged_boxes(model.cells, model.merge_keys)
    else:
        boxes = [((i, j, k), (i + 1, j + 1, k + 1), model.cells[(i, j, k)]) for i, j, k in sorted(model.cells)]
    tags, owners = [], []
    for (i0, j0, k0), (i1, j1, k1), name in boxes:
        lo = (gx[i0], gy[j0], gz[k0])
        hi = (gx[i1], gy[j1], gz[k1])
        block = occ.addBox(*lo, hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2])
        # bores are cut block by block before the fragment, so the fragment's map still says which feature
        # every volume belongs to
        for piece in _cut_bores(block, lo, hi, model.bores):
            tags.append(piece)
            owners.append(name)
    if len(tags) > 1:
        _, out_map = occ.fragment([(3, t) for t in tags[:1]], [(3, t) for t in tags[1:]])
    else:
        out_map = [[(3, tags[0])]]
    occ.synchronize()
    # out_map[n] lists the volumes that input n became; blocks never overlap, so each maps to one volume.
    feature_volumes: dict[str, list[int]] = {}
    for owner, pieces in zip(owners, out_map):
        for dim, tag in pieces:
            feature_volumes.setdefault(owner, []).append(tag)
    return feature_volumes


def merged_boxes(cells: dict[tuple[int, int, int], str],
                 keys: dict | None = None) -> list[tuple[tuple, tuple, str]]:
    """Cover the cells by few boxes of one feature each: (lo index, hi index (exclusive), name).  Greedy:
    grow a run along x, then the run's rectangle along y, then along z, over unclaimed cells of the same
    feature and the same merge key."""
    keys = keys or {}
    free = {c: (name, keys.get(c)) for c, name in cells.items()}
    out = []
    for start in sorted(cells):
        if start not in free:
            continue
        name = free[start]
        i0, j0, k0 = start

        def all_free(i_range, j_range, k_range, name=name):
            return all(free.get((i, j, k)) == name for i in i_range for j in j_range for k in k_range)

        i1 = i0 + 1
        while all_free([i1], [j0], [k0]):
            i1 += 1
        j1 = j0 + 1
        while all_free(range(i0, i1), [j1], [k0]):
            j1 += 1
        k1 = k0 + 1
        while all_free(range(i0, i1), range(j0, j1), [k1]):
            k1 += 1
        for i in range(i0, i1):
            for j in range(j0, j1):
                for k in range(k0, k1):
                    del free[(i, j, k)]
        out.append(((i0, j0, k0), (i1, j1, k1), name[0]))
    return out


def _cut_bores(block: int, lo, hi, bores: Sequence[Bore]) -> list[int]:
    """Volume tags of a box block after cutting the bores that cross it (the block itself if none)."""
    import gmsh

    occ = gmsh.model.occ
    pieces = [block]
    for bore in bores:
        a, b = [ax for ax in range(3) if ax != bore.axis]
        # nearest point of the block's cross-section rectangle to the bore axis
        da = max(lo[a] - bore.centre[a], 0.0, bore.centre[a] - hi[a])
        db = max(lo[b] - bore.centre[b], 0.0, bore.centre[b] - hi[b])
        overlaps_axially = bore.span[0] < hi[bore.axis] and bore.span[1] > lo[bore.axis]
        if math.hypot(da, db) >= bore.radius - 1e-12 or not overlaps_axially:
            continue
        base = list(bore.centre)
        base[bore.axis] = bore.span[0]
        direction = [0.0, 0.0, 0.0]
        direction[bore.axis] = bore.span[1] - bore.span[0]
        cylinder = occ.addCylinder(*base, *direction, bore.radius)
        out, _ = occ.cut([(3, t) for t in pieces], [(3, cylinder)], removeObject=True, removeTool=True)
        pieces = [t for d, t in out if d == 3]
    return pieces


def _classify_boundary(model: BlockModel) -> dict[tuple[str, ...], list[int]]:
    """The boundary faces of the OCC solid per tuple of surface names (plane faces by position and outward
    normal, curved ones by the bore they lie on)."""
    import gmsh

    boundary = gmsh.model.getBoundary(gmsh.model.getEntities(3), combined=True, oriented=False)
    atomic: dict[tuple[str, ...], list[int]] = {}
    for dim, tag in boundary:
        if gmsh.model.getType(2, abs(tag)) != "Plane":
            names = _bore_of_face(abs(tag), model)
        else:
            centre = _point_on_face(abs(tag))
            names = tuple(model.classify_face(centre, _outward_normal(abs(tag), centre, model)))
        atomic.setdefault(names, []).append(abs(tag))
    return atomic


def _facet_groups(atomic: dict[tuple[str, ...], list[int]]) -> dict[str, list[int]]:
    """Physical surface groups.  A dolfinx facet tag holds one value per facet, so each face gets one
    atomic group named by all its names ("outer/outer_top"); every name maps to the union of the
    atomic groups that carry it."""
    import gmsh

    facet_groups: dict[str, list[int]] = {}
    for n, names in enumerate(sorted(atomic), start=1):
        gmsh.model.addPhysicalGroup(2, sorted(set(atomic[names])), n)
        gmsh.model.setPhysicalName(2, n, "/".join(names))
        for name in names:
            facet_groups.setdefault(name, []).append(n)
    return facet_groups


def _point_on_face(face: int, samples: int = 24) -> np.ndarray:
    """A point on a plane face (m): its centre of mass if that lies on the face (always for the rectangles
    of a plain block model), else the sample of a parametric grid nearest to it that does (a face with a
    hole, or an L-shaped one, can have its centre of mass off the face, where tests of the material on
    either side would look at the wrong place)."""
    import gmsh

    centre = np.array(gmsh.model.occ.getCenterOfMass(2, face))
    uv = gmsh.model.getParametrization(2, face, list(centre))
    if gmsh.model.isInside(2, face, list(uv)):
        return centre
    (u0, v0), (u1, v1) = gmsh.model.getParametrizationBounds(2, face)
    best, best_d = centre, np.inf
    for i in range(samples):
        for j in range(samples):
            p_uv = [u0 + (i + 0.5) * (u1 - u0) / samples, v0 + (j + 0.5) * (v1 - v0) / samples]
            if gmsh.model.isInside(2, face, p_uv):
                p = np.array(gmsh.model.getValue(2, face, p_uv))
                d = float(np.linalg.norm(p - centre))
                if d < best_d:
                    best, best_d = p, d
    return best


def _bore_of_face(face: int, model: BlockModel) -> tuple[str, ...]:
    """Surface names of a curved boundary face: the bore whose cylinder it lies on."""
    import gmsh

    umin, umax = gmsh.model.getParametrizationBounds(2, face)
    point = np.array(gmsh.model.getValue(2, face, [(umin[0] + umax[0]) / 2, (umin[1] + umax[1]) / 2]))
    for bore in model.bores:
        r = point - np.asarray(bore.centre)
        r[bore.axis] = 0.0
        along = bore.span[0] <= point[bore.axis] <= bore.span[1]
        if along and abs(np.linalg.norm(r) - bore.radius) < 1e-6 * max(1.0, bore.radius):
            return (bore.name, *bore.groups)
    raise ValueError(f"curved face {face} near {np.round(point, 4).tolist()} lies on no bore")


def _outward_normal(face: int, centre: np.ndarray, model: BlockModel) -> np.ndarray:
    """Outward normal of an axis-aligned boundary face: the axis direction pointing out of the solid.
    Material is tested with the bores first (a cover closing a bore has material on one side only); if the
    centre lies in a bore on both sides (the centre of mass of a face with a hole in it), with the cells."""
    import gmsh

    xmin, ymin, zmin, xmax, ymax, zmax = gmsh.model.getBoundingBox(2, face)
    axis = int(np.argmin([xmax - xmin, ymax - ymin, zmax - zmin]))
    normal = np.zeros(3)
    normal[axis] = 1.0
    ahead, behind = centre + 1e-7 * normal, centre - 1e-7 * normal
    if model.contains(ahead) != model.contains(behind):
        return -normal if model.contains(ahead) else normal
    return -normal if model.in_cells(ahead) else normal


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
    gmsh.option.setNumber("Mesh.Smoothing", 1)      # gmsh's default; the CAD face analysis turns it off
    gmsh.option.setNumber("Mesh.OptimizeThreshold", 0.3)
    gmsh.option.setNumber("General.NumThreads", 1)   # parallel meshing is not reproducible
    for dim in (1, 2, 3):
        gmsh.option.setNumber(f"Mesh.MaxNumThreads{dim}D", 1)
    gmsh.option.setNumber("Mesh.RandomSeed", 1)
    gmsh.option.setNumber("Mesh.RandomFactor", 1e-9)


def _make_transfinite(model: BlockModel, size: float, layers: int, grading: float = 1.0,
                      layer_size: float | None = None) -> None:
    """Structured divisions on every curve; with grading < 1, a symmetric "Bump" distribution (finer at both
    ends, where the block meets its neighbours) on curves longer than a wall with at least two divisions.  The
    bump is symmetric, so opposite edges of a block agree whatever their orientation."""
    import gmsh

    mesh = gmsh.model.mesh
    thickest = max(model.thin_dimensions, default=0.0)
    for _, curve in gmsh.model.getEntities(1):
        xmin, ymin, zmin, xmax, ymax, zmax = gmsh.model.getBoundingBox(1, curve)
        length = max(xmax - xmin, ymax - ymin, zmax - zmin)
        n = divisions(length, size, model.thin_dimensions, layers, layer_size)
        if grading < 1.0 and n >= 2 and length > thickest + 1e-6:
            mesh.setTransfiniteCurve(curve, n + 1, "Bump", grading)
        else:
            mesh.setTransfiniteCurve(curve, n + 1)
    for _, surface in gmsh.model.getEntities(2):
        mesh.setTransfiniteSurface(surface)
        mesh.setRecombine(2, surface)
    for _, volume in gmsh.model.getEntities(3):
        mesh.setTransfiniteVolume(volume)


def _tet_qualities() -> tuple[np.ndarray, np.ndarray]:
    """Shape ratio and centroid (m) of every tetrahedron of the current gmsh mesh."""
    import gmsh


    _, _, conn = gmsh.model.mesh.getElements(3)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    xyz = np.zeros((int(tags.max()) + 1, 3))
    xyz[tags.astype(int)] = coords.reshape(-1, 3)
    corners = xyz[conn[0].reshape(-1, 4).astype(int)]
    return tet_quality(corners), corners.mean(axis=1)


def _remesh_finer_at(centres: np.ndarray, size: float, fine: float = 0.5) -> None:
    """Re-mesh with the element size `fine` x size (halved by default) within one element size of each centre
    (m); no centres: re-mesh with no size field acting (a ball of the plain size)."""
    import gmsh

    field = gmsh.model.mesh.field
    balls = []
    for x, y, z in centres if len(centres) else [(0.0, 0.0, 0.0)]:
        ball = field.add("Ball")
        inside = fine * size if len(centres) else 1e3 * size
        for key, value in (("Radius", size), ("Thickness", size), ("VIn", inside), ("VOut", 1e3 * size),
                           ("XCenter", x), ("YCenter", y), ("ZCenter", z)):
            field.setNumber(ball, key, float(value))
        balls.append(ball)
    smallest = field.add("Min")
    field.setNumbers(smallest, "FieldsList", balls)
    field.setAsBackgroundMesh(smallest)     # replaces the previous one (gmsh 4.8 cannot list fields to remove)
    gmsh.model.mesh.clear()
    gmsh.model.mesh.generate(3)


def _refine_slivers(size: float, min_quality: float = 0.08, attempts: int = 3,
                    stop_unless_better: bool = False, fine: float = 0.5) -> float:
    """Delaunay leaves a few slivers whose four corners all lie on the boundary (across a thin wall, where the
    two faces' triangulations meet badly); no interior optimisation removes them.  Re-mesh with the element
    size halved around them (the surface meshes change there), accumulating the spots, up to `attempts` times,
    and keep the attempt with the best minimum shape ratio, which is returned.  Every step is deterministic,
    so the same scene still gives the same mesh.  stop_unless_better: no further attempt after one that did
    not raise the minimum.  fine: the element size inside the balls as a fraction of size."""
    centres = np.zeros((0, 3))
    history = []
    for attempt in range(attempts + 1):
        q, mid = _tet_qualities()
        history.append((float(q.min()), centres))
        if q.min() >= min_quality:
            return float(q.min())
        if attempt == attempts or (stop_unless_better and attempt and history[-1][0] <= history[-2][0]):
            break
        centres = np.vstack([centres, mid[q < min_quality]])
        _remesh_finer_at(centres, size, fine)
    best = max(range(len(history)), key=lambda i: history[i][0])
    if best != len(history) - 1:
        _remesh_finer_at(history[best][1], size, fine)
    return history[best][0]


def _hxt_fallback(size: float, min_quality: float = 0.08, attempts: int = 3) -> None:
    """HXT (not reproducible in gmsh 4.8) where Delaunay's slivers could not be refined away: re-mesh with a
    perturbed random factor until the minimum shape ratio passes, instead of handing a sliver to the solver."""
    import gmsh

    gmsh.option.setNumber("Mesh.Algorithm3D", HXT_ALGORITHM)
    _remesh_finer_at(np.zeros((0, 3)), size)
    for attempt in range(attempts):
        if _tet_qualities()[0].min() >= min_quality:
            return
        gmsh.option.setNumber("Mesh.RandomFactor", 1e-9 * (attempt + 2))
        gmsh.model.mesh.clear()
        gmsh.model.mesh.generate(3)


def tet_quality(v: np.ndarray) -> np.ndarray:
    e = [v[:, j] - v[:, i] for i, j in ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))]
    vol = np.abs(np.einsum("ij,ij->i", e[0], np.cross(e[1], e[2]))) / 6
    l_rms = np.sqrt(sum((ek**2).sum(axis=1) for ek in e) / 6)
    return 6 * np.sqrt(2) * vol / l_rms**3
