"""A housing from a CAD file (STEP, IGES, BREP): the geometry kind `cad`.

    [geometry]
    kind = "cad"
    file = "housing.step"       # relative to the scene file
    units = "mm"                # the unit of the coordinates gmsh reads (see below)
    [[geometry.bores]]          # selectors, lengths in m (housingfe.geometry.selectors)
    name = "A"; axis = [0, 1, 0]; centre = [0.1, 0, 0.2]
    [[geometry.surfaces]]
    name = "feet"; plane = {point = [0, 0, 0], normal = [0, 0, -1]}

The file is read by gmsh's OpenCASCADE kernel (importShapes), healed where it holds no solid (healShapes:
sewing, small edges and faces, closed shells made solids), scaled to metres and checked: its size must be plausible for the declared
unit (5 mm to 20 m; a 300 m gearbox is an error that says millimetres fit), it must hold at least one closed
solid (an open shell is refused), and several solids must touch: they are fragmented into one conforming
solid (a weld; each keeps its own cell group solid_<n>), pieces that do not touch are refused.
OpenCASCADE converts STEP and IGES coordinates to millimetres whatever unit the file declares, so STEP and
IGES files from CAD programs are `units = "mm"`; BREP files carry no unit, and gmsh writes a model's raw
numbers into STEP (the package's own STEP exports of its built-in housings, in metres, are `units = "m"`).

Regions, never entity numbers: every boundary face is "outer" (the radiating skin: a ray along its outward
normal leaves the part without hitting it, for most of its sample points) or "inner"; bore selectors add
bore_<name> and bores (and remove "outer": a bore does not radiate as a plate does); surface selectors add
their name.  The element size follows the scene's frequency range and the thinnest wall (`thin_walls`),
unless `thickness` is given.  Meshing: linear tetrahedra of gmsh's Delaunay (reproducible; slivers refined,
housingfe.geometry.blocks.mesh_tetrahedra), quadratic (or cubic) displacement fields on them (mesh.degree).

How the thinnest wall is estimated (`thin_walls`): the boundary is triangulated coarsely (extent / 40); from
the centroid of every triangle a ray runs along the inward normal, and the distance to where it leaves the
material is the wall thickness there.  The thinnest wall is the area-weighted 2 % quantile of those
distances (the very minimum comes from rays grazing a fillet or starting on an edge); the minimum is
reported as well.
"""
from __future__ import annotations

import os
import tempfile
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal, Optional

import numpy as np
from pydantic import PositiveFloat, model_validator

from housingfe.errors import InputError
from housingfe.geometry.registry import StrictSpec, register_geometry
from housingfe.geometry.selectors import (
    BoreSelector,
    Face,
    SurfaceSelector,
    select_bore,
    select_surface,
)

CAD_SUFFIXES = (".step", ".stp", ".iges", ".igs", ".brep", ".brp")
# the largest extent of a housing (m): below, the declared unit is too large; above, too small
PLAUSIBLE_EXTENT_M = (0.005, 20.0)
UNIT_SCALE = {"mm": 1e-3, "m": 1.0}
# the coarse triangulation for the face analysis: this fraction of the largest extent
ANALYSIS_SIZE_FRACTION = 1 / 40
THIN_WALL_QUANTILE = 0.02
MAX_THICKNESS_RAYS = 8000
# wall-thickness rays ignore crossings at less than ~17 degrees to the surface (cos 73 deg): a ray along the
# axis of a drilled hole, started beside it, grazes the facets of the hole's coarse triangulation
GRAZING_COS = 0.3
_RESERVED = {"outer", "inner", "bores"}


class CadGeometry(StrictSpec):
    """A housing imported from a CAD file (see the module docstring).  file: STEP/IGES/BREP path (relative to
    the scene file); units: "mm" or "m"; heal: OpenCASCADE's shape healing ("auto": only a file without
    solids, whose faces it may sew into one); bores, surfaces: named regions by
    geometric selectors (m); thickness (m): the thinnest wall for the element size, instead of the estimate."""

    kind: Literal["cad"]
    file: str
    units: Literal["mm", "m"]
    heal: Literal["auto", "always", "never"] = "auto"
    bores: list[BoreSelector] = []
    surfaces: list[SurfaceSelector] = []
    thickness: Optional[PositiveFloat] = None

    @model_validator(mode="after")
    def _check(self):
        path = Path(self.file)
        if path.suffix.lower() not in CAD_SUFFIXES:
            raise ValueError(f"file: {self.file}: not a CAD file by its name (expected {', '.join(CAD_SUFFIXES)})")
        if not path.is_file():
            raise ValueError(f"file: {self.file}: no such file")
        names = [b.name for b in self.bores] + [s.name for s in self.surfaces]
        for name in names:
            if name in _RESERVED or names.count(name) > 1:
                raise ValueError(f"surfaces: the name {name!r} is reserved or used twice (outer, inner and bores "
                                 f"are made by the import)")
        return self

    @property
    def min_thickness(self) -> float:
        """The thinnest wall (m): `thickness`, or the estimate from the CAD file (cached per file)."""
        return self.thickness if self.thickness is not None else cad_facts(self).thin_wall


@dataclass
class CadFacts:
    """What an imported CAD file is (lengths in m): solids (before fragmenting), volume (m^3), centroid,
    bounding box (lo, hi), the thinnest wall (m, THIN_WALL_QUANTILE of the inward ray lengths) and the
    shortest ray (m), the boundary faces (housingfe.geometry.selectors.Face, outward normals) and which of
    them are outer skin; import_s / analysis_s: times (s)."""

    path: Path
    brep: Path          # the processed solid (checked, in metres, one conforming solid), for the mesher
    solids: int
    volumes: list[int]
    volume: float
    centroid: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    thin_wall: float
    thinnest_ray: float
    faces: list[Face]
    outer: set[int]
    import_s: float = 0.0
    analysis_s: float = 0.0
    notes: list[str] = field(default_factory=list)
    triangles: Optional[np.ndarray] = None     # the coarse boundary triangulation (n, 3, 3), m
    owner: Optional[np.ndarray] = None         # the face tag of each triangle
    # the wall thickness samples (m) and the boundary area each stands for (m^2, summing to the boundary's area)
    wall_samples: Optional[np.ndarray] = None
    wall_areas: Optional[np.ndarray] = None
    wall_points: Optional[np.ndarray] = None   # where each sample's ray starts (m)


@contextmanager
def gmsh_session():
    """gmsh initialised for the block, finalised after (also on errors); the terminal output off."""
    import gmsh

    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        yield gmsh
    finally:
        gmsh.finalize()


@contextmanager
def _native_output_captured():
    """OpenCASCADE writes its statistics and parse errors straight to the process' stdout/stderr; the
    project's rule is one line per error.  Redirect both file descriptors into a temporary file for the block
    and yield a function that returns what was written."""
    import sys

    sys.stdout.flush()
    sys.stderr.flush()
    saved = os.dup(1), os.dup(2)
    with tempfile.TemporaryFile(mode="w+b") as sink:
        os.dup2(sink.fileno(), 1)
        os.dup2(sink.fileno(), 2)
        try:
            yield lambda: (sink.seek(0), sink.read().decode(errors="replace"))[1]
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])


# OpenCASCADE's STEP reader heals every shape it translates (the resource file
# /usr/share/opencascade/resources/XSTEPResource/STEP, sequence FromSTEP.FixShape).  One of those fixes, crossings
# of non-adjacent edges of one wire (FixNonAdjacentIntersectingEdgesMode), re-applies the history of the whole face
# for each of its wires (ShapeFix_IntersectionTool::FixSelfIntersectWire calls Context()->Apply(face)): quadratic
# in the holes of a face, 2.7 of 5.4 s on a 5 MB STEP file with 1250 bolt holes.  It is switched off; every other
# fix runs as OCC's defaults say.  A wire that crosses itself is an invalid CAD export; heal = "always" (gmsh's
# healShapes: it fixes self-intersecting wires too) is the remedy for such a file.  The IGES reader (its own
# resource file, the same fix) is left as it is: gmsh 4.8 writes no IGES to test it with.
_READER_FIX_OFF = "FixNonAdjacentIntersectingEdgesMode"
_OCC_RESOURCES = Path("/usr/share/opencascade/resources/XSTEPResource")   # Debian's occt-misc (gmsh depends on it)


@contextmanager
def _reader_resources(suffix: str):
    """For the block, OCC's resource file of the STEP reader with _READER_FIX_OFF set to 0 (a copy of the
    installed one in the scratch folder, through CSF_STEPDefaults).  Nothing changes for an IGES or BREP file,
    where the variable is set by the user already, or where the installed file is not found."""
    name = {".step": "STEP", ".stp": "STEP"}.get(suffix.lower())
    variable = f"CSF_{name}Defaults"
    source = _OCC_RESOURCES / str(name)
    if name is None or variable in os.environ or not source.is_file():
        yield
        return
    folder = _scratch_dir() / "occ-resources"
    if not (folder / name).is_file():
        key = f"From{name}.FixShape.{_READER_FIX_OFF}"
        lines = [f"{key} : 0" if line.split(":")[0].strip() == key else line
                 for line in source.read_text().splitlines()]
        folder.mkdir(exist_ok=True)
        (folder / name).write_text("\n".join(lines) + "\n")
    os.environ[variable] = str(folder)
    try:
        yield
    finally:
        del os.environ[variable]


def import_solid(path: Path, units: str, heal: str = "auto", key: str | None = "geometry") -> dict:
    """Import a CAD file into the current (empty) gmsh model, scaled to metres, healed, checked and fragmented
    into one conforming solid.  Returns {"solids": count in the file, "volumes": volume tags, "scale": factor}.
    InputError naming `key`.file (or only the file, key None) for an unreadable file, an implausible size for
    `units`, no closed solid, or solids that do not touch."""
    import gmsh

    occ = gmsh.model.occ
    where = f"{key}.file: {path}" if key else str(path)
    gmsh.option.setString("Geometry.OCCTargetUnit", "")   # OCC's default: STEP/IGES in mm (options persist)
    # scaled by OpenCASCADE on reading: occ.dilate would turn planes and cylinders into B-splines (volume off
    # by 1e-3, no cylinders left for the bore selectors)
    scale = UNIT_SCALE[units]
    gmsh.option.setNumber("Geometry.OCCScaling", scale)
    try:
        with _native_output_captured(), _reader_resources(path.suffix):
            try:
                occ.importShapes(str(path))
            except Exception:   # noqa: BLE001 - gmsh raises a bare Exception; OCC's own message went to the sink
                raise InputError(f"{where}: not a STEP, IGES or BREP file OpenCASCADE can read") from None
            occ.synchronize()
    finally:
        gmsh.option.setNumber("Geometry.OCCScaling", 1.0)
    if not gmsh.model.getEntities():
        raise InputError(f"{where}: the file holds no geometry")
    x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(-1, -1)
    # a scene's key is geometry.units; `housingfe inspect` (key None) takes the unit as its flag --units
    check_units(max(x1 - x0, y1 - y0, z1 - z0) / scale, units, f"{where}: units" if key else f"{where}: --units",
                flag=not key)
    solids = gmsh.model.getEntities(3)
    if heal == "always" or (heal == "auto" and not solids):
        # the solids if there are any (healing everything turns solids into loose faces in gmsh 4.8), else
        # the faces, which healing may sew into a closed shell and make a solid of; "auto" heals only a file
        # without solids (healing valid solids costs as much as reading them)
        with _native_output_captured():
            occ.healShapes(solids or gmsh.model.getEntities(2))
            occ.synchronize()
    volumes = [t for _, t in gmsh.model.getEntities(3)]
    if not volumes:
        faces = len(gmsh.model.getEntities(2))
        raise InputError(f"{where}: no closed solid ({faces} faces, no volume: an open shell or loose surfaces); "
                         f"close the housing in the CAD program and export the solid")
    solids = len(volumes)
    if solids > 1:
        # touching solids (a welded-on foot, the boxes of an export) become one conforming solid: shared
        # faces are meshed once, so the parts are joined as by a weld
        with _native_output_captured():
            occ.fragment([(3, volumes[0])], [(3, t) for t in volumes[1:]])
            occ.synchronize()
        volumes = [t for _, t in gmsh.model.getEntities(3)]
        pieces = _connected_pieces(volumes)
        if len(pieces) > 1:
            raise InputError(f"{where}: {solids} solids in {len(pieces)} pieces that do not touch (the housing "
                             f"must be one connected solid); join them in the CAD program or export one part")
    # free surfaces, curves and points not on a solid are no part of the housing
    faces = gmsh.model.getBoundary([(3, t) for t in volumes], combined=False, oriented=False)
    curves = gmsh.model.getBoundary(faces, combined=False, oriented=False)
    points = gmsh.model.getBoundary(curves, combined=False, oriented=False)
    keep = {(d, abs(t)) for d, t in faces + curves + points}
    stray = [(d, t) for d in (2, 1, 0) for _, t in gmsh.model.getEntities(d) if (d, t) not in keep]
    if stray:
        occ.remove(stray, recursive=False)
        occ.synchronize()
    return {"solids": solids, "volumes": volumes, "scale": scale}


def check_units(extent: float, units: str, key: str, flag: bool = False) -> None:
    """InputError (naming `key`) when a largest extent of `extent` (in `units`) is implausible for a housing,
    saying which unit would fit (as the scene value `units = "mm"`, or with flag as the option `--units mm`)."""
    metres = extent * UNIT_SCALE[units]
    lo, hi = PLAUSIBLE_EXTENT_M
    if lo <= metres <= hi:
        return
    fits = [u for u, s in UNIT_SCALE.items() if lo <= extent * s <= hi and u != units]
    fix = f"give --units {fits[0]}" if flag and fits else f"set units = \"{fits[0]}\"" if fits else ""
    hint = f"; this looks like {'millimetres' if fits == ['mm'] else 'metres'}: {fix}" if fits else ""
    # 3 digits: OpenCASCADE's bounding box carries the shape tolerance (0.2002 mm for a 0.2 mm part)
    raise InputError(f"{key}: the part is {extent:.3g} {units} across ({metres:.3g} m), implausible for a housing "
                     f"({lo * 1e3:g} mm to {hi:g} m){hint}")


def _connected_pieces(volumes: list[int]) -> list[set[int]]:
    """Volumes grouped into pieces that share faces (union-find)."""
    import gmsh

    parent = {v: v for v in volumes}

    def root(v):
        while parent[v] != v:
            parent[v] = parent[parent[v]]
            v = parent[v]
        return v

    owner: dict[int, int] = {}
    for v in volumes:
        for _, f in gmsh.model.getBoundary([(3, v)], combined=False, oriented=False):
            f = abs(f)
            if f in owner:
                parent[root(v)] = root(owner[f])
            else:
                owner[f] = v
    pieces: dict[int, set[int]] = {}
    for v in volumes:
        pieces.setdefault(root(v), set()).add(v)
    return list(pieces.values())


# ------------------------------------------------------------------------------------------- face analysis
def _boundary_triangles(faces: list[int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Triangles (n, 3, 3) of the current 2-D mesh on the given faces, their node tags (n, 3) and the face
    tag of each."""
    import gmsh

    tags, coords, _ = gmsh.model.mesh.getNodes()
    xyz = np.zeros((int(tags.max()) + 1, 3))
    xyz[tags.astype(int)] = coords.reshape(-1, 3)
    conns, owner = [], []
    for f in faces:
        types, _, nodes = gmsh.model.mesh.getElements(2, f)
        for etype, conn in zip(types, nodes):
            if etype == 2:   # 3-node triangle
                c = conn.astype(int).reshape(-1, 3)
                conns.append(c)
                owner.append(np.full(len(c), f))
    conn = np.concatenate(conns)
    return xyz[conn], conn, np.concatenate(owner)


def _relative_face_signs(conn: np.ndarray, owner: np.ndarray, faces: list[int]) -> tuple[dict, list[list[int]]]:
    """Orient the faces consistently: two faces sharing a mesh edge must run along it in opposite directions
    (gmsh orients the triangles within a face alike).  Breadth-first over the faces; returns each face's sign
    (+1 keeps its triangles' orientation) relative to the first face of its connected shell, and the shells."""
    edges = np.concatenate([conn[:, [0, 1]], conn[:, [1, 2]], conn[:, [2, 0]]])
    faces_of = np.tile(owner, 3)
    forward = edges[:, 0] < edges[:, 1]
    key = np.sort(edges, axis=1)
    _, group, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    group = group.ravel()
    pairs = np.flatnonzero(counts[group] == 2)
    order = pairs[np.argsort(group[pairs], kind="stable")]
    a, b = order[0::2], order[1::2]
    neighbours: dict[int, dict[int, int]] = {f: {} for f in faces}
    for i, j in zip(a, b):
        fa, fb = int(faces_of[i]), int(faces_of[j])
        if fa != fb:    # a seam of a cylinder joins a face to itself
            # same direction along the shared edge: one of the two faces is reversed
            neighbours[fa][fb] = -1 if forward[i] == forward[j] else 1
            neighbours[fb][fa] = neighbours[fa][fb]
    sign: dict[int, int] = {}
    shells = []
    for start in faces:
        if start in sign:
            continue
        sign[start] = 1
        shell, queue = [start], [start]
        while queue:
            f = queue.pop()
            for g, relation in neighbours[f].items():
                if g not in sign:
                    sign[g] = sign[f] * relation
                    shell.append(g)
                    queue.append(g)
        shells.append(shell)
    return sign, shells


class RayCaster:
    """Rays against a triangulated surface (m): the triangles binned on a uniform grid (about 4 cells per
    triangle), all rays walked through it together cell by cell (Amanatides & Woo 1987), each ray tested
    against the triangles of its cell (Moller & Trumbore 1997), in numpy.  0.3 s for the 18 000 rays of the
    5 MB bolted housing's face analysis, where VTK's cell locator, one ray per call, took 1 s."""

    CELLS_PER_TRIANGLE = 4.0
    BARYCENTRIC_TOL = 1e-12    # a ray through an edge or a vertex hits the triangles there (then counted once)

    def __init__(self, triangles: np.ndarray):
        t = np.asarray(triangles, dtype=float)
        self.v0, self.e1, self.e2 = t[:, 0], t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
        normal = np.cross(self.e1, self.e2)
        self.normals = normal / np.maximum(np.linalg.norm(normal, axis=1), 1e-300)[:, None]
        pts = t.reshape(-1, 3)
        pad = 1e-6 * float(np.linalg.norm(np.ptp(pts, axis=0)))
        self.lo = pts.min(axis=0) - pad
        extent = pts.max(axis=0) + pad - self.lo
        h = (np.prod(extent) / (self.CELLS_PER_TRIANGLE * len(t))) ** (1 / 3)
        self.shape = np.maximum(1, np.ceil(extent / h).astype(int))
        self.h = extent / self.shape
        # every cell that a triangle's bounding box touches (widened by rounding's reach) lists the triangle
        slack = 1e-9 * self.h
        first = np.clip(np.floor((t.min(axis=1) - slack - self.lo) / self.h).astype(int), 0, self.shape - 1)
        last = np.clip(np.floor((t.max(axis=1) + slack - self.lo) / self.h).astype(int), 0, self.shape - 1)
        span = last - first + 1
        count = span.prod(axis=1)
        tri = np.repeat(np.arange(len(t)), count)
        local = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
        a, rest = np.divmod(local, span[tri, 1] * span[tri, 2])
        b, c = np.divmod(rest, span[tri, 2])
        cell = self._cell_number(first[tri] + np.stack([a, b, c], axis=1))
        order = np.argsort(cell, kind="stable")
        self.members = tri[order]
        self.start = np.searchsorted(cell[order], np.arange(int(self.shape.prod()) + 1))

    def _cell_number(self, index: np.ndarray) -> np.ndarray:
        return (index[:, 0] * self.shape[1] + index[:, 1]) * self.shape[2] + index[:, 2]

    def _distances(self, origins, directions, tri):
        """Distance along each ray (unit direction) to the plane of its triangle where the ray crosses the
        triangle, else inf (Moller-Trumbore)."""
        e1, e2 = self.e1[tri], self.e2[tri]
        p = np.cross(directions, e2)
        det = np.einsum("ij,ij->i", e1, p)
        crossing = np.abs(det) > 1e-300       # a ray in the triangle's plane does not cross it
        inv = 1.0 / np.where(crossing, det, 1.0)
        s = origins - self.v0[tri]
        u = np.einsum("ij,ij->i", s, p) * inv
        q = np.cross(s, e1)
        v = np.einsum("ij,ij->i", directions, q) * inv
        tol = self.BARYCENTRIC_TOL
        crossing &= (u >= -tol) & (v >= -tol) & (u + v <= 1.0 + tol)
        return np.where(crossing, np.einsum("ij,ij->i", e2, q) * inv, np.inf)

    def _walk(self, origins, directions, eps, min_incidence, mode):
        """mode "nearest": the distance to the nearest crossing farther than eps (inf if none); "any": the
        distance to some such crossing (inf if none: the ray escapes); "all": (ray, triangle, distance) of
        every such crossing."""
        o = np.ascontiguousarray(origins, dtype=float)
        d = np.ascontiguousarray(directions, dtype=float)
        best = np.full(len(o), np.inf)
        index = np.clip(np.floor((o - self.lo) / self.h).astype(int), 0, self.shape - 1)
        step = np.where(d > 0, 1, -1)
        # ray parameter of the next cell boundary along each axis, and of one cell's width (inf: parallel)
        inv = 1.0 / np.where(d != 0, d, 1.0)
        t_next = np.where(d != 0, (self.lo + (index + (step > 0)) * self.h - o) * inv, np.inf)
        t_cell = np.where(d != 0, self.h * np.abs(inv), np.inf)
        slack = 1e-9 * float(self.h.min())
        active = np.arange(len(o))
        found = []
        while len(active):
            cell = self._cell_number(index[active])
            first, n = self.start[cell], self.start[cell + 1] - self.start[cell]
            ray = np.repeat(active, n)
            tri = self.members[np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n) + np.repeat(first, n)]
            t = self._distances(o[ray], d[ray], tri)
            valid = np.isfinite(t) & (t > eps)
            if min_incidence > 0.0:
                valid &= np.abs(np.einsum("ij,ij->i", self.normals[tri], d[ray])) >= min_incidence
            exit_t = t_next[active].min(axis=1)
            if mode == "nearest":
                # a crossing beyond this cell is met again, in order, in the cell that holds it
                valid &= t <= np.repeat(exit_t, n) + slack
            if mode == "all":
                found.append((ray[valid], tri[valid], t[valid]))
            else:
                np.minimum.at(best, ray[valid], t[valid])
            axis = np.argmin(t_next[active], axis=1)
            index[active, axis] += step[active, axis]
            t_next[active, axis] += t_cell[active, axis]
            going = np.all((index[active] >= 0) & (index[active] < self.shape), axis=1)
            active = active[going & (np.isinf(best[active]) | (mode == "all"))]
        if mode == "all":
            return tuple(np.concatenate(x) for x in zip(*found)) if found else (np.zeros(0, int),) * 2 + (
                np.zeros(0),)
        return best

    RAYS_PER_WALK = 4096     # the candidate pairs of a walk's steps stay within tens of MB

    def _chunked(self, origins, directions, eps, min_incidence, mode):
        n = len(origins)
        return np.concatenate([self._walk(origins[k:k + self.RAYS_PER_WALK], directions[k:k + self.RAYS_PER_WALK],
                                          eps, min_incidence, mode)
                               for k in range(0, n, self.RAYS_PER_WALK)]) if n else np.zeros(0)

    def nearest(self, origins: np.ndarray, directions: np.ndarray, eps: float,
                min_incidence: float = 0.0) -> np.ndarray:
        """For every ray (origin, unit direction, m): the distance to the nearest crossing of the surface
        farther than eps (inf if none).  min_incidence: ignore crossings where |cos| of the angle between ray
        and triangle normal is smaller (grazing hits on the facets of a coarsely triangulated hole, next to
        which a ray parallel to the hole's axis starts)."""
        return self._chunked(origins, directions, eps, min_incidence, "nearest")

    def escapes(self, origins: np.ndarray, directions: np.ndarray, eps: float) -> np.ndarray:
        """For every ray: True where it crosses the surface nowhere farther than eps."""
        return np.isinf(self._chunked(origins, directions, eps, 0.0, "any"))

    def crossings(self, origins: np.ndarray, directions: np.ndarray, eps: float) -> np.ndarray:
        """For every ray: the number of crossings of the surface farther than eps (a ray through a mesh edge
        or vertex crosses every triangle there at one distance: counted once)."""
        ray, tri, t = self._walk(origins, directions, eps, 0.0, "all")
        counts = np.zeros(len(origins), dtype=int)
        pairs = np.unique(np.stack([ray, tri], axis=1), axis=0, return_index=True)[1]   # a triangle in two cells
        ray, t = ray[pairs], t[pairs]
        for k in np.unique(ray):
            dist = np.sort(t[ray == k])
            counts[k] = 1 + int(np.sum(np.diff(dist) > eps))
        return counts


def analyse_faces(volumes: list[int], size: float) -> dict:
    """Describe the boundary faces of the current gmsh model's solid (a coarse 2-D mesh of `size` m is made
    and cleared again): outward-oriented triangles, selectors' Face records, the outer skin and the wall
    thickness samples."""
    import gmsh

    from housingfe.geometry.blocks import _set_mesh_options

    _set_mesh_options("tet")
    gmsh.option.setNumber("Mesh.Algorithm", 5)   # 2-D Delaunay: 25 % less time than Frontal-Delaunay here
    # small holes keep their small triangles to themselves: 85 000 instead of 208 000 triangles (4.5 instead of
    # 6.7 s) on a 5 MB STEP with 1250 holes; mesh_tetrahedra sets it back for the volume mesh
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    # no Laplacian smoothing of the triangles: the same 1-D mesh and triangle count, 2.4x less time (17.1 -> 7.2 s
    # on the loaded host, 5 MB STEP, 83 000 triangles); the analysis needs the faces' extents (on the curves, so
    # unchanged) and ray origins, not well-shaped triangles
    gmsh.option.setNumber("Mesh.Smoothing", 0)
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.model.mesh.setSize(gmsh.model.getEntities(0), size)
    boundary = sorted({abs(t) for _, t in gmsh.model.getBoundary([(3, v) for v in volumes], combined=True,
                                                                     oriented=False)})
    gmsh.model.mesh.generate(2)
    tris, conn, owner = _boundary_triangles(boundary)
    gmsh.model.mesh.clear()
    normal = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    area = 0.5 * np.linalg.norm(normal, axis=1)
    normal /= np.maximum(2 * area, 1e-300)[:, None]
    centroid = tris.mean(axis=1)
    lo, hi = tris.reshape(-1, 3).min(axis=0), tris.reshape(-1, 3).max(axis=0)
    diag = float(np.linalg.norm(hi - lo))
    eps = 1e-7 * diag
    caster = RayCaster(tris)

    # orientation: consistent over each closed shell by the shared edges; then per shell, a point just off
    # its largest triangles along the normal is inside the solid when a ray from it crosses the boundary an
    # odd number of times (up to 9 probes, three fixed skew directions, majority vote)
    relative, shells = _relative_face_signs(conn, owner, boundary)
    normal *= np.array([relative[f] for f in owner])[:, None]
    directions = np.random.default_rng(20261125).normal(size=(3, 3))   # fixed: the same answer every run
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    flip = {}
    for n, shell in enumerate(shells):
        idx = np.flatnonzero(np.isin(owner, shell))
        top = idx[np.argsort(-area[idx], kind="stable")[:9]]
        probes = centroid[top] + 1e-4 * diag * normal[top]
        votes = sum(caster.crossings(probes, np.broadcast_to(d, probes.shape), eps) % 2 for d in directions)
        flip[n] = np.mean(votes >= 2) > 0.5
    shell_of = {f: n for n, shell in enumerate(shells) for f in shell}
    normal *= np.array([-1.0 if flip[shell_of[f]] else 1.0 for f in owner])[:, None]

    # wall thickness: along the inward normal to where the ray leaves the material (at most MAX_THICKNESS_RAYS
    # triangles, every k-th: the estimate needs the area distribution, not every triangle)
    sample = np.arange(0, len(tris), max(1, len(tris) // MAX_THICKNESS_RAYS))
    thickness = caster.nearest(centroid[sample], -normal[sample], 1e-5 * diag, min_incidence=GRAZING_COS)
    # outer skin: along the outward normal nothing is hit (up to 8 of a face's largest triangles, majority)
    # each face's triangles in ascending order, and its 8 largest (ties in order): two sorts of all triangles,
    # not two per face (1261 faces)
    by_owner = np.argsort(owner, kind="stable")
    by_area = np.lexsort((-area, owner))
    first = np.searchsorted(owner[by_owner], boundary)
    last = np.searchsorted(owner[by_owner], boundary, side="right")
    by_face = {f: by_owner[i:j] for f, i, j in zip(boundary, first, last)}
    top = {f: by_area[i:min(j, i + 8)] for f, i, j in zip(boundary, first, last)}
    rays = np.concatenate(list(top.values()))
    escapes = dict(zip(rays, caster.escapes(centroid[rays], normal[rays], 1e-5 * diag)))
    faces, outer = [], set()
    for f in boundary:
        idx = by_face[f]
        if np.mean([escapes[i] for i in top[f]]) > 0.5:
            outer.add(f)
        # the face's mesh nodes, each once (by node tag: np.unique of rounded coordinates along axis 0 took
        # most of the per-face time on 1261 faces)
        _, first = np.unique(conn[idx].ravel(), return_index=True)
        faces.append(_face_record(f, tris[idx], area[idx], centroid[idx], normal[idx],
                                  tris[idx].reshape(-1, 3)[first]))
    finite = np.isfinite(thickness)
    return {"faces": faces, "outer": outer, "thickness": thickness[finite], "weights": area[sample][finite],
            "points": centroid[sample][finite],
            "lo": lo, "hi": hi, "triangles": tris, "owner": owner}


def _face_record(tag: int, triangles: np.ndarray, areas: np.ndarray, centroids: np.ndarray,
                 normals: np.ndarray, points: np.ndarray) -> Face:
    """A selectors.Face from a gmsh face (its triangles (n, 3, 3), their areas, centroids and outward normals,
    and its mesh nodes (m, 3), each once): kind from gmsh.model.getType, cylinder axis/radius from three points
    on a circle of its parametrisation (OCC cylinders: u the angle, v along the axis)."""
    import gmsh

    kind = gmsh.model.getType(2, tag)
    # area and centre of mass exact from OpenCASCADE (the triangles only approximate curved edges)
    area = float(gmsh.model.occ.getMass(2, tag))
    # a cylinder's centre is a point on its axis (below): no centre of mass (0.3 s for 1250 bolt holes)
    centre = None if kind == "Cylinder" else np.asarray(gmsh.model.occ.getCenterOfMass(2, tag))
    normal_sum = (areas[:, None] * normals).sum(axis=0)
    mean_normal = normal_sum / max(np.linalg.norm(normal_sum), 1e-300)
    if kind == "Plane":
        return Face(tag, "plane", points, area, normal=mean_normal, triangles=triangles, centre=centre)
    if kind == "Cylinder":
        (u0, v0), (u1, v1) = gmsh.model.getParametrizationBounds(2, tag)
        vm = 0.5 * (v0 + v1)
        us = [u0 + (u1 - u0) * s for s in (0.1, 0.5, 0.9)]
        # the three points in one call (the API's overhead per call is most of the cost)
        a, b, c = np.array(gmsh.model.getValue(2, tag, [us[0], vm, us[1], vm, us[2], vm])).reshape(3, 3)
        axis = _cross3(b - a, c - a)
        axis /= np.linalg.norm(axis)
        centre, radius = _circumcircle(a, b, c)
        # a bore: the outward normal of the face points towards the axis (area-weighted over its triangles)
        radial = (centroids - centre) - np.outer((centroids - centre) @ axis, axis)
        concave = bool(np.sum(areas * np.einsum("ij,ij->i", normals, radial)) < 0)
        return Face(tag, "cylinder", points, area, normal=mean_normal, axis=axis, axis_point=centre,
                    radius=radius, concave=concave, triangles=triangles, centre=centre)
    return Face(tag, "other", points, area, normal=mean_normal, extra={"gmsh_type": kind}, triangles=triangles,
                centre=centre)


def _cross3(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """np.cross of two 3-vectors with numpy's arithmetic (the same numbers), without its overhead per call."""
    return np.array([u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]])


def _circumcircle(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, float]:
    ab, ac = b - a, c - a
    n = _cross3(ab, ac)
    centre = a + (np.dot(ac, ac) * _cross3(n, ab) + np.dot(ab, ab) * _cross3(ac, n)) / (2 * np.dot(n, n))
    return centre, float(np.linalg.norm(a - centre))


def _weighted_quantile(values: np.ndarray, weights: np.ndarray, q: float) -> float:
    order = np.argsort(values)
    cum = np.cumsum(weights[order])
    return float(values[order][np.searchsorted(cum, q * cum[-1])])


_SCRATCH: list[Path] = []


def _scratch_dir() -> Path:
    """A folder of this process for the processed solids, removed at exit."""
    if not _SCRATCH:
        import atexit
        import shutil

        _SCRATCH.append(Path(tempfile.mkdtemp(prefix="housingfe-cad-")))
        atexit.register(shutil.rmtree, _SCRATCH[0], ignore_errors=True)
    return _SCRATCH[0]


def load_processed(brep: Path) -> list[int]:
    """Read a processed solid (BREP in metres, written by read_cad) into the current gmsh model; returns the
    volume tags (the same on every reading)."""
    import gmsh

    gmsh.option.setNumber("Geometry.OCCScaling", 1.0)
    with _native_output_captured():
        gmsh.model.occ.importShapes(str(brep))
        gmsh.model.occ.synchronize()
    return [t for _, t in gmsh.model.getEntities(3)]


def read_cad(path: Path, units: str, heal: str = "auto", key: str | None = "geometry") -> CadFacts:
    """Import, check and analyse a CAD file in the current gmsh session (see CadFacts); the processed solid is
    kept as BREP (CadFacts.brep) and stays loaded (fragmented, in metres, no mesh)."""
    import gmsh

    t0 = time.perf_counter()
    imported = import_solid(path, units, heal, key)
    # the checked, scaled, joined solid as BREP (0.04 s to write, 0.1 s to read for the box's 153 solids, which
    # took 6 s from STEP with the fragment): the mesher reads it back with the same face numbers
    brep = _scratch_dir() / f"solid-{len(list(_scratch_dir().iterdir()))}.brep"
    with _native_output_captured():
        gmsh.write(str(brep))
    gmsh.clear()
    volumes = load_processed(brep)
    t1 = time.perf_counter()
    volume, moment = 0.0, np.zeros(3)
    for v in volumes:
        m = gmsh.model.occ.getMass(3, v)
        volume += m
        moment += m * np.asarray(gmsh.model.occ.getCenterOfMass(3, v))
    x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(-1, -1)
    extent = max(x1 - x0, y1 - y0, z1 - z0)
    analysis = analyse_faces(volumes, extent * ANALYSIS_SIZE_FRACTION)
    if len(analysis["thickness"]) == 0:
        where = f"{key}.file: {path}" if key else str(path)
        raise InputError(f"{where}: no wall thickness found (no ray from the surface crosses material)")
    thin = _weighted_quantile(analysis["thickness"], analysis["weights"], THIN_WALL_QUANTILE)
    boundary_area = sum(f.area for f in analysis["faces"])
    notes = []
    if imported["solids"] > 1:
        notes.append(f"{imported['solids']} solids fragmented into one conforming solid of {len(volumes)} volumes")
    return CadFacts(path=path, brep=brep, solids=imported["solids"], volumes=volumes, volume=volume,
                    centroid=moment / volume, lo=analysis["lo"], hi=analysis["hi"], thin_wall=thin,
                    thinnest_ray=float(analysis["thickness"].min()), faces=analysis["faces"],
                    outer=analysis["outer"], import_s=t1 - t0, analysis_s=time.perf_counter() - t1, notes=notes,
                    triangles=analysis["triangles"], owner=analysis["owner"], wall_samples=analysis["thickness"],
                    wall_areas=analysis["weights"] * (boundary_area / analysis["weights"].sum()),
                    wall_points=analysis["points"])



_FACTS_CACHE: dict[tuple, CadFacts] = {}


def cad_facts(spec: CadGeometry) -> CadFacts:
    """CadFacts of a scene's CAD geometry, read once per file version (path, size, mtime, units, heal)."""
    path = Path(spec.file).resolve()
    stat = path.stat()
    key = (str(path), stat.st_size, stat.st_mtime_ns, spec.units, spec.heal)
    if key not in _FACTS_CACHE:
        with gmsh_session():
            _FACTS_CACHE[key] = read_cad(path, spec.units, spec.heal)
    return _FACTS_CACHE[key]


# ------------------------------------------------------------------------------------------------ regions
def face_groups(spec: CadGeometry, facts: CadFacts) -> dict[int, tuple[str, ...]]:
    """Surface names of every boundary face: outer/inner, bore_<name> + bores (never outer), the surface
    selectors' names.  InputError naming geometry.bores[i] / geometry.surfaces[i] for a selector that
    matches nothing (or two bores)."""
    names: dict[int, list[str]] = {f.tag: [] for f in facts.faces}
    bore_faces: set[int] = set()
    for i, selector in enumerate(spec.bores):
        for tag in select_bore(facts.faces, selector, f"geometry.bores[{i}]"):
            names[tag] += [f"bore_{selector.name}", "bores"]
            bore_faces.add(tag)
    for i, selector in enumerate(spec.surfaces):
        for tag in select_surface(facts.faces, selector, f"geometry.surfaces[{i}]"):
            names[tag].append(selector.name)
    out = {}
    for tag, extra in names.items():
        skin = [] if tag in bore_faces else ["outer" if tag in facts.outer else "inner"]
        out[tag] = tuple(dict.fromkeys(skin + extra))
    return out


def bore_points(spec: CadGeometry, facts: CadFacts) -> dict[str, list[tuple[float, float, float]]]:
    """Named reference points: the centre of each selected bore (middle of its faces along the axis, m)."""
    from housingfe.geometry.selectors import bore_candidates

    points = {}
    for selector in spec.bores:
        tags = set(select_bore(facts.faces, selector, "geometry.bores"))
        (bore,) = bore_candidates([f for f in facts.faces if f.tag in tags], selector.tolerance) or [None]
        if bore is not None:
            points[f"bore_{selector.name}"] = [tuple(float(c) for c in bore["centre"])]
    return points


# ------------------------------------------------------------------------------------------------ meshing
# How gmsh's Delaunay (mesh_tetrahedra) fills a solid, measured on plates of 40 x 40 h and thickness 0.25-8 h
# (docs/cad.md "Model size"): the surface triangulation first (the estimate makes it: it is exact), then interior
# nodes at INTERIOR_NODES_PER_H3 per h^3 (gmsh's interior edges run ~1.5 h) farther than BOUNDARY_LAYER h from
# the surface (a wall thinner than ~1.5 h gets no interior node: one element through it); the edges and cells
# per node of the surface and interior nodes (P2 needs the edges, P3 the faces and cells too).
SURFACE_NODES_PER_H2 = 1.3        # surface nodes per h^2 of boundary area, for the local size of a triangle
INTERIOR_NODES_PER_H3 = 0.44
BOUNDARY_LAYER = 0.75
# above this many surface nodes (SURFACE_NODES_PER_H2 x area / h^2, ~5 M P2 DOFs and more) the surface is not
# triangulated (that alone would take minutes): its nodes are counted from its area, which misses the refinement
# around small features (an under-count) but decides the guard's question (no machine here holds such a model)
SURFACE_MESH_MAX_NODES = 300_000
EDGES_PER_NODE = {"surface": 4.95, "interior": 7.5}
CELLS_PER_NODE = {"surface": 3.0, "interior": 6.56}
_SURFACE_CACHE: dict[tuple, dict] = {}


def surface_mesh_facts(facts: CadFacts, size: float) -> dict:
    """gmsh's triangulation of the solid's boundary at element size `size` (m), made as mesh_tetrahedra makes
    it before it fills the volume (same options; seconds where the volume mesh takes minutes): its node count,
    and per triangle the area (m^2) and centroid (m).  Cached per processed solid and size."""
    import gmsh

    from housingfe.geometry.blocks import _set_mesh_options

    key = (str(facts.brep), size)
    if key not in _SURFACE_CACHE:
        with gmsh_session():
            gmsh.model.add("surface")
            load_processed(facts.brep)
            _set_mesh_options("tet")
            # no Laplacian smoothing: it moves the nodes, never adds any (as in analyse_faces)
            gmsh.option.setNumber("Mesh.Smoothing", 0)
            gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
            gmsh.option.setNumber("Mesh.MeshSizeMax", size)
            gmsh.model.mesh.setSize(gmsh.model.getEntities(0), size)
            gmsh.model.mesh.generate(2)
            tags, coords, _ = gmsh.model.mesh.getNodes()
            xyz = np.zeros((int(tags.max()) + 1, 3))
            xyz[tags.astype(int)] = coords.reshape(-1, 3)
            _, _, conn = gmsh.model.mesh.getElements(2)
            tris = xyz[np.concatenate([c.astype(int) for c in conn]).reshape(-1, 3)]
        area = 0.5 * np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1)
        _SURFACE_CACHE[key] = {"nodes": len(tags), "areas": area, "centroids": tris.mean(axis=1)}
    return _SURFACE_CACHE[key]


def estimate_mesh_entities(facts: CadFacts, size: float) -> dict:
    """Nodes, edges, faces and cells of the linear tetrahedral mesh mesh_tetrahedra makes of the solid at
    element size `size` (m), without the volume mesh (docs/cad.md "Model size").  The surface nodes are counted
    on gmsh's own surface triangulation (surface_mesh_facts: it holds the refinement gmsh makes around features
    smaller than the element, e.g. 8 mm bolt holes, which no count from area and volume sees).  Under every
    surface triangle a column reaches half the local wall thickness tau (the nearest ray sample of the face
    analysis) into the solid and holds INTERIOR_NODES_PER_H3 / h^3 interior nodes beyond BOUNDARY_LAYER h, h
    the geometric mean of the element size and the triangle's own size (sqrt(2.6 x area): SURFACE_NODES_PER_H2
    nodes per h^2, two triangles per node).  The columns are scaled down to the solid's volume where they
    overlap (a cube's columns hold it three times).  Edges and cells per node EDGES_PER_NODE, CELLS_PER_NODE;
    faces by Euler's formula (nodes - edges + faces - cells = 1).  Beyond SURFACE_MESH_MAX_NODES surface nodes
    the surface is not triangulated: its nodes are SURFACE_NODES_PER_H2 x area / size^2 (an under-count where
    small features refine the mesh)."""
    from scipy.spatial import cKDTree

    boundary_area = float(facts.wall_areas.sum())
    if SURFACE_NODES_PER_H2 * boundary_area / size**2 > SURFACE_MESH_MAX_NODES:
        # from the geometry alone: the thickness samples' triangles at the element size
        area, tau = facts.wall_areas, facts.wall_samples
        surface_nodes = SURFACE_NODES_PER_H2 * boundary_area / size**2
        h = np.full(len(area), size)
    else:
        surface = surface_mesh_facts(facts, size)
        area, surface_nodes = surface["areas"], float(surface["nodes"])
        # the interior element size under a triangle: between the triangle's own (sqrt(2.6 x area)) and the
        # element size, to which gmsh's interpolated size grows away from a refined surface (geometric mean)
        h = np.sqrt(np.sqrt(2.0 * SURFACE_NODES_PER_H2 * area) * size)
        _, nearest = cKDTree(facts.wall_points).query(surface["centroids"])
        tau = facts.wall_samples[nearest]
    columns = float(np.sum(area * tau / 2))
    depth = np.maximum(0.0, tau / 2 - BOUNDARY_LAYER * h)
    interior = INTERIOR_NODES_PER_H3 * float(np.sum(area * depth / h**3)) * min(1.0, facts.volume / columns)
    nodes = {"surface": surface_nodes, "interior": interior}
    edges = sum(EDGES_PER_NODE[k] * n for k, n in nodes.items())
    cells = sum(CELLS_PER_NODE[k] * n for k, n in nodes.items())
    vertices = nodes["surface"] + nodes["interior"]
    return {"nodes": vertices, "edges": edges, "faces": 1.0 - vertices + edges + cells, "cells": cells,
            "surface_nodes": nodes["surface"], "interior_nodes": interior}


def estimate_cad_dofs(spec: CadGeometry, element: str, degree: int, size: float, layers: int,
                      layer_size: float | None = None) -> int:
    """Displacement DOFs of the tetrahedral mesh of element size `size` (m) at Lagrange degree 1-3: three per
    node of the degree-`degree` field on the counts of estimate_mesh_entities (a node per vertex, degree - 1
    per edge, (degree - 1)(degree - 2)/2 per face).  0.82-1.21 of the meshes measured in docs/cad.md ("Model
    size": element sizes from a tenth of the thinnest wall to ten walls), but 0.65 where the volume mesher's
    sliver refinement adds nodes (NIST FTC-06 at 30 mm)."""
    counts = estimate_mesh_entities(cad_facts(spec), size)
    p = degree
    nodes = counts["nodes"] + (p - 1) * counts["edges"] + (p - 1) * (p - 2) / 2 * counts["faces"]
    return int(round(3 * nodes))


def build_cad_mesh(spec: CadGeometry, element: str, size: float, layers: int, comm, grading: float = 1.0,
                   layer_size: float | None = None):
    """Import the CAD file on rank 0, tag it, mesh it with tetrahedra of `size` (m) and distribute it: the
    parts of a housingfe.geometry.mesh.HousingMesh (registry.GeometryKind.mesh; volume and centroid from
    OpenCASCADE, quality: the 1 % quantile and median of the shape ratio and the mesher)."""
    import gmsh

    from housingfe.geometry.blocks import _tet_qualities, distribute_gmsh_model, mesh_tetrahedra

    if element != "tet":
        raise InputError("mesh.element: an imported CAD housing is meshed with tetrahedra: set element = \"tet\"")
    facts = cad_facts(spec)      # on every rank: the checks raise everywhere, and the facts are cached
    payload = None
    if comm.rank == 0:
        gmsh.initialize()
        try:
            gmsh.option.setNumber("General.Terminal", 0)
            gmsh.model.add("cad")
            if load_processed(facts.brep) != facts.volumes:
                raise RuntimeError("the processed CAD solid read back with other volumes")
            groups = face_groups(spec, facts)
            payload = {"cells": _volume_groups(facts.volumes), "facets": _surface_groups(groups),
                       "points": bore_points(spec, facts)}
            # no HXT fallback: it is not reproducible, and the slivers a real part's small chamfers leave are
            # judged by their share of the volume (housingfe.fe.model.check_element_quality, docs/cad.md)
            payload["mesher"] = mesh_tetrahedra(size, hxt_fallback=False)
            q = _tet_qualities()[0]
            payload["quantiles"] = {"q01": float(np.quantile(q, 0.01)), "median": float(np.median(q))}
        except InputError as exc:
            gmsh.finalize()
            payload = {"error": str(exc)}
        except Exception:
            gmsh.finalize()
            comm.bcast({"error": "the CAD mesh failed on rank 0"}, root=0)
            raise
    payload = comm.bcast(payload, root=0)
    if "error" in payload:
        raise InputError(payload["error"])
    mesh, cell_tags, facet_tags = distribute_gmsh_model(comm)
    return {"mesh": mesh, "cell_tags": cell_tags, "facet_tags": facet_tags, "cell_groups": payload["cells"],
            "facet_groups": payload["facets"], "volume": facts.volume, "centroid": facts.centroid,
            "points": payload["points"], "quality": {**payload["quantiles"], "mesher": payload["mesher"]}}


def _volume_groups(volumes: list[int]) -> dict[str, int]:
    import gmsh

    groups = {}
    for n, v in enumerate(sorted(volumes), start=1):
        name = "solid" if len(volumes) == 1 else f"solid_{n}"
        gmsh.model.addPhysicalGroup(3, [v], n)
        gmsh.model.setPhysicalName(3, n, name)
        groups[name] = n
    return groups


def _surface_groups(groups: dict[int, tuple[str, ...]]) -> dict[str, list[int]]:
    """Physical surface groups, one per distinct tuple of names (a facet tag holds one value); every name maps
    to the tags of the tuples that carry it (as housingfe.geometry.blocks does for the built-in housings)."""
    import gmsh

    atomic: dict[tuple[str, ...], list[int]] = {}
    for tag, names in groups.items():
        atomic.setdefault(names, []).append(tag)
    out: dict[str, list[int]] = {}
    for n, names in enumerate(sorted(atomic), start=1):
        gmsh.model.addPhysicalGroup(2, sorted(atomic[names]), n)
        gmsh.model.setPhysicalName(2, n, "/".join(names))
        for name in names:
            out.setdefault(name, []).append(n)
    return out


def _no_block_model(spec: CadGeometry):
    raise InputError("geometry.kind: an imported CAD housing has no block model (it meshes itself)")


register_geometry(CadGeometry, _no_block_model, mesh=build_cad_mesh, estimate_dofs=estimate_cad_dofs)


def write_step(geometry, path: Path) -> Path:
    """Write a built-in (block-model) housing's OpenCASCADE solid, as its tetrahedral mesh is built from
    (boxes with the bores cut, fragmented), to a STEP (or BREP, by the suffix) file in metres: gmsh writes the
    model's raw numbers, so it reads back with units = "m".  For the round trips of tests and docs."""
    from housingfe.geometry.blocks import _fragmented_blocks
    from housingfe.geometry.registry import block_model_for

    model = block_model_for(geometry)
    with gmsh_session() as gmsh:
        gmsh.model.add("export")
        _fragmented_blocks(model, "tet")
        with _native_output_captured():
            gmsh.write(str(path))
    return Path(path)
