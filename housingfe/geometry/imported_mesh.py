"""A housing from a volume mesh file (`[geometry] kind = "mesh"`): Abaqus .inp, Nastran .bdf/.nas, gmsh .msh and
the other formats meshio reads.

    [geometry]
    kind = "mesh"
    file = "housing.inp"          # relative to the scene file
    units = "mm"                  # "mm" or "m": the unit of the file's coordinates
    [[geometry.bores]]            # a bore: a surface the [coupling] or `housingfe reduce` ties to a master
    name = "B1"
    set = "BORE1"                 # a node set, surface-element set or physical surface group of the file
    [[geometry.surfaces]]         # any other named surface (supports, loads, radiating plates)
    name = "feet"
    set = "FEET"

Cells: linear and quadratic tetrahedra (tet4, tet10) and hexahedra (hex8, hex27) go to dolfinx as they are (the
geometry is then of degree 1 or 2; the displacement degree is the scene's mesh.degree).  20-node bricks (C3D20,
CHEXA with 20 grids) have no dolfinx coordinate element in 0.5.2: each is converted to a 27-node brick whose
face and body nodes are the serendipity map's points there (exact for straight-edged and affine-curved bricks).
One cell type per mesh; prisms, pyramids and mixed meshes are refused.  meshio gives every cell in VTK node
order (it converts Nastran's CHEXA20 and gmsh's quadratic orders); dolfinx.cpp.io.perm_vtk puts them into
dolfinx's order.

Surfaces (facet groups of the HousingMesh): "outer" = every boundary facet (the radiating skin; a surface named
"outer" in the scene replaces it), each [[geometry.bores]] / [[geometry.surfaces]] entry by its `name`: the
boundary facets whose corner nodes all lie in the node set, or the facets of the set's surface elements.
Cell groups (for [regions]): every set of volume cells by its own name (Abaqus ELSET, gmsh physical volumes,
Nastran property ids as "PID<n>").  Volume (m^3) and centroid (m) are integrated over the mesh.

MPI: rank 0 reads the file; dolfinx distributes the cells; the tags are matched by the file's node numbers
(geometry.input_global_indices), so 1 and 2 ranks give the same model.  Every problem is an InputError
naming the mesh file and the scene key, raised on all ranks.
"""
from __future__ import annotations

import contextlib
import io
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np
from pydantic import ValidationInfo, field_validator, model_validator

from housingfe.errors import InputError
from housingfe.geometry.registry import StrictSpec as _Strict
from housingfe.geometry.registry import register_geometry

UNIT_SCALE = {"mm": 1e-3, "m": 1.0}
# A housing's largest dimension (m) must lie in this range in the declared unit: outside it the unit is wrong
# (a 300 m gearbox is millimetres declared as metres).
PLAUSIBLE_EXTENT_M = (0.01, 20.0)

# meshio volume cell type -> (dolfinx cell, geometry degree); hexahedron20 is converted to hexahedron27
VOLUME_CELLS = {"tetra": ("tetrahedron", 1), "tetra10": ("tetrahedron", 2), "hexahedron": ("hexahedron", 1),
                "hexahedron27": ("hexahedron", 2), "hexahedron20": ("hexahedron", 2)}
REFUSED_CELLS = {"wedge": "prisms", "wedge15": "prisms", "wedge18": "prisms", "pyramid": "pyramids",
                 "pyramid13": "pyramids", "pyramid14": "pyramids", "tetra14": "14-node tetrahedra"}
SURFACE_CELLS = {"triangle": 3, "triangle6": 3, "triangle7": 3, "quad": 4, "quad8": 4, "quad9": 4}
# corners of the faces of the VTK tetrahedron and hexahedron (any orientation: faces are matched as node sets)
_FACES_VTK = {"tetrahedron": [(0, 1, 2), (0, 1, 3), (1, 2, 3), (0, 2, 3)],
              "hexahedron": [(0, 3, 7, 4), (1, 2, 6, 5), (0, 1, 5, 4), (3, 2, 6, 7), (0, 1, 2, 3), (4, 5, 6, 7)]}
# VTK hexahedron edges (node 8 + i is the mid-node of edge i)
_HEX_EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]


class MeshSet(_Strict):
    """A named surface of the housing: `set`, a node set, surface-element set or physical surface group of the
    mesh file."""

    name: str
    set: str


class MeshGeometry(_Strict):
    """A housing given as a volume mesh file (see the module docstring); `file` relative to the scene file."""

    kind: Literal["mesh"]
    file: str
    units: Literal["mm", "m"]
    bores: list[MeshSet] = []
    surfaces: list[MeshSet] = []

    @field_validator("file")
    @classmethod
    def _relative_to_scene(cls, value: str, info: ValidationInfo) -> str:
        scene = (info.context or {}).get("scene_path") if info is not None else None
        path = Path(value).expanduser()
        if not path.is_absolute() and scene is not None:
            path = Path(scene).resolve().parent / path
        return str(path)

    @model_validator(mode="after")
    def _unique_names(self):
        names = [s.name for s in self.bores + self.surfaces]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ValueError(f"surfaces: names must be unique among bores and surfaces ({', '.join(dup)})")
        return self

    @property
    def min_thickness(self) -> None:
        """None: an imported mesh brings its own element size (no wall thickness to derive one from)."""
        return None


@dataclass
class MeshFile:
    """What rank 0 reads from a mesh file (SI units, dolfinx node order).

    points (N, 3) m; cells (C, n) indices into points in dolfinx order; cell_type "tetrahedron"/"hexahedron";
    degree: the geometry degree (1 or 2); facets: corner-node tuples (sorted) of the boundary facets -> cell
    index; node_sets: name -> bool mask over points; surface_sets: name -> set of sorted corner tuples;
    cell_sets: name -> cell indices; element_size: median corner-to-corner edge length (m); notes: what was
    converted."""

    path: Path
    points: np.ndarray
    cells: np.ndarray
    cell_type: str
    degree: int
    boundary: np.ndarray
    node_sets: dict = field(default_factory=dict)
    surface_sets: dict = field(default_factory=dict)
    cell_sets: dict = field(default_factory=dict)
    element_size: float = 0.0
    source_cell: str = ""
    notes: list = field(default_factory=list)


_CACHE: dict = {}


def read_mesh_file(path, units: str, key: str = "geometry") -> MeshFile:
    """Read a volume mesh with meshio: points scaled to m, one volume cell type in dolfinx order, the sets.

    units: "mm" or "m"; key: the scene key of the geometry section (for messages).  InputError "<file>: <key>.
    <field>: <what>" on an unreadable file, no volume cells, mixed or unsupported cells, an implausible size for
    the declared unit.  Cached per (path, mtime, units)."""
    import meshio

    path = Path(path)
    try:
        stamp = (str(path.resolve()), path.stat().st_mtime_ns, units)
    except OSError:
        raise InputError(f"{path}: {key}.file: mesh file not found") from None
    if stamp in _CACHE:
        return _CACHE[stamp]
    try:
        # meshio 5.0 prints the error of every format it tried first to stdout (a .msh is tried as ANSYS first:
        # a blank line before our output); a format that fails for good still raises -- except a ReadError of every
        # format tried (a gmsh 1.0 file), after which it prints "Error: ..." on stderr and calls sys.exit(1)
        printed = io.StringIO()
        with contextlib.redirect_stdout(printed), contextlib.redirect_stderr(printed):
            raw = meshio.read(str(path))
    except (Exception, SystemExit) as exc:    # meshio raises anything from ReadError to KeyError and IndexError
        if isinstance(exc, SystemExit):      # its "Error: ..." line, wrapped by rich at 80 columns
            text = printed.getvalue().rpartition("Error:")[2]
            what = " ".join(text.split()) or "meshio exited"
        else:
            what = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise InputError(f"{path}: {key}.file: cannot read as a mesh ({what}); meshio reads Abaqus .inp, "
                         "Nastran .bdf/.nas, gmsh .msh, ...") from None
    nastran = path.suffix.lower() in (".bdf", ".nas", ".dat", ".fem")
    if nastran and np.any(np.asarray(raw.point_data.get("nastran:ref", [])) != 0):
        # meshio reads the coordinates as given: in a local system CP they would be wrong
        raise InputError(f"{path}: {key}.file: GRID cards with a coordinate system CP other than 0; give the "
                         "grid coordinates in the basic system")
    volume_blocks = [(i, b) for i, b in enumerate(raw.cells) if b.type in VOLUME_CELLS or b.type in REFUSED_CELLS]
    if not volume_blocks:
        kinds = ", ".join(sorted({b.type for b in raw.cells})) or "no cells"
        raise InputError(f"{path}: {key}.file: no volume cells ({kinds}); a housing needs tetrahedra or "
                         "hexahedra")
    types = sorted({b.type for _, b in volume_blocks})
    refused = [REFUSED_CELLS[t] for t in types if t in REFUSED_CELLS]
    if refused:
        raise InputError(f"{path}: {key}.file: {', '.join(sorted(set(refused)))} are not supported; mesh the "
                         "housing with tetrahedra or hexahedra only")
    if len(types) > 1:
        raise InputError(f"{path}: {key}.file: mixed volume cells ({', '.join(types)}); one cell type per mesh")
    source = types[0]
    cell_type, degree = VOLUME_CELLS[source]
    cells_vtk = np.concatenate([b.data for _, b in volume_blocks]).astype(np.int64)
    points = np.asarray(raw.points, float)[:, :3] * UNIT_SCALE[units]
    if points.shape[1] < 3:
        raise InputError(f"{path}: {key}.file: the mesh is not three-dimensional")

    extent = float(np.max(np.ptp(points[np.unique(cells_vtk)], axis=0)))
    lo, hi = PLAUSIBLE_EXTENT_M
    if not lo <= extent <= hi:
        raw_extent = extent / UNIT_SCALE[units]
        fits = [u for u, s in UNIT_SCALE.items() if u != units and lo <= raw_extent * s <= hi]
        hint = (f"; read in {fits[0]} it is {raw_extent * UNIT_SCALE[fits[0]]:.3g} m: set {key}.units = "
                f"\"{fits[0]}\"" if fits else "")
        raise InputError(f"{path}: {key}.units: the mesh is {extent:.3g} m across in {units}, outside the "
                         f"plausible {lo:g}-{hi:g} m of a housing{hint}")

    notes = []
    if source == "hexahedron20":
        points, cells_vtk = _hex20_to_hex27(points, cells_vtk)
        notes.append("20-node bricks converted to 27-node bricks (serendipity face and body points)")
    # keep the nodes the volume cells use (files also carry nodes of beams, surfaces, geometry points)
    used = np.unique(cells_vtk)
    renumber = np.full(len(points), -1, np.int64)
    renumber[used] = np.arange(len(used))
    n_raw = len(raw.points)
    import dolfinx.cpp.io as cio
    from dolfinx.mesh import CellType

    perm = np.asarray(cio.perm_vtk(getattr(CellType, cell_type), cells_vtk.shape[1]))
    cells = renumber[cells_vtk][:, perm]
    corners = renumber[cells_vtk[:, :4 if cell_type == "tetrahedron" else 8]]
    out = MeshFile(path, points[used], cells, cell_type, degree, _boundary_facets(corners, cell_type),
                   source_cell=source, notes=notes)
    out.element_size = float(np.median(np.linalg.norm(out.points[corners[:, 1]] - out.points[corners[:, 0]],
                                                      axis=1)))

    for name, idx in raw.point_sets.items():
        mask = np.zeros(len(used), bool)
        idx = np.asarray(idx, np.int64)
        idx = renumber[idx[(idx >= 0) & (idx < n_raw)]]
        mask[idx[idx >= 0]] = True
        out.node_sets[name] = mask
    offsets = {}
    start = 0
    for i, b in volume_blocks:
        offsets[i] = start
        start += len(b.data)
    for name, per_block in raw.cell_sets.items():
        vol, surf = [], set()
        for i, idx in enumerate(per_block):
            if idx is None or len(idx) == 0 or i >= len(raw.cells):
                continue
            block = raw.cells[i]
            if i in offsets:
                vol.append(offsets[i] + np.asarray(idx, np.int64))
            elif block.type in SURFACE_CELLS:
                nodes = renumber[block.data[np.asarray(idx, np.int64), :SURFACE_CELLS[block.type]]]
                surf |= {tuple(sorted(f)) for f in nodes.tolist() if min(f) >= 0}
        if vol:
            out.cell_sets[name] = np.unique(np.concatenate(vol))
        if surf:
            out.surface_sets[name] = surf
    # gmsh physical groups by name (the msh 2.2 reader leaves them in field_data and cell_data)
    if "gmsh:physical" in raw.cell_data:
        for name, (tag, dim) in ((n, tuple(int(t) for t in v[:2])) for n, v in raw.field_data.items()):
            vol, surf = [], set()
            for i, block in enumerate(raw.cells):
                hit = np.flatnonzero(np.asarray(raw.cell_data["gmsh:physical"][i]) == tag)
                if not len(hit):
                    continue
                if dim == 3 and i in offsets:
                    vol.append(offsets[i] + hit)
                elif dim == 2 and block.type in SURFACE_CELLS:
                    nodes = renumber[block.data[hit, :SURFACE_CELLS[block.type]]]
                    surf |= {tuple(sorted(f)) for f in nodes.tolist() if min(f) >= 0}
            if vol:
                out.cell_sets.setdefault(name, np.unique(np.concatenate(vol)))
            if surf:
                out.surface_sets.setdefault(name, surf)
    if nastran:
        ids = getattr(raw, "points_id", None)
        index = {int(g): k for k, g in enumerate(ids)} if ids is not None else {}
        for name, grids in _nastran_node_sets(path).items():
            mask = np.zeros(len(used), bool)
            rows = renumber[[index[g] for g in grids if g in index]]
            mask[rows[rows >= 0]] = True
            out.node_sets[name] = mask
    # Nastran property ids and gmsh physical volumes without names
    for data_key, prefix in (("nastran:ref", "PID"), ("gmsh:physical", "physical_")):
        if data_key in raw.cell_data:
            values = np.concatenate([np.asarray(raw.cell_data[data_key][i]) for i, _ in volume_blocks])
            for v in np.unique(values):
                name = f"{prefix}{int(v)}"
                out.cell_sets.setdefault(name, np.flatnonzero(values == v))
    _CACHE.clear()      # one mesh at a time: a housing mesh can be large
    _CACHE[stamp] = out
    return out


def _nastran_cards(path: Path, keywords: tuple[str, ...]):
    """(keyword, data fields) of the bulk-data cards named `keywords`, in free, small or large field, with their
    continuations (a line starting with "+", "*" or ",", or a blank first field)."""
    card = None

    def fields(line: str, large: bool) -> list[str]:
        if "," in line:
            parts = [f.strip() for f in line.split(",")]
            return parts[1:9]
        width = 16 if large else 8
        body = line[8:8 + (4 if large else 8) * width]
        return [body[i:i + width].strip() for i in range(0, len(body), width)]

    with open(path, errors="replace") as f:
        for raw_line in f:
            line = raw_line.rstrip("\n").expandtabs(8)
            if not line.strip() or line.startswith("$"):
                continue
            head = line.split(",")[0] if "," in line else line[:8]
            head = head.strip()
            continuation = head.startswith(("+", "*")) or head == "" or line.startswith(",")
            if continuation and card is not None:
                card[1].extend(fields(line, card[2] or head.startswith("*")))
                continue
            if card is not None:
                yield card[0], card[1]
                card = None
            if head.upper().startswith("ENDDATA"):
                return
            keyword = head.upper().rstrip("*")
            if keyword in keywords:
                card = (keyword, fields(line, head.endswith("*")), head.endswith("*"))
    if card is not None:
        yield card[0], card[1]


def _nastran_node_sets(path: Path) -> dict[str, list[int]]:
    """Node sets of a Nastran bulk-data file by GRID id: "SET1_<sid>" (SET1, THRU ranges expanded) and
    "RBE2_<eid>" (the dependent grids of an RBE2: a bore's spider, as system-tool exports define bores)."""
    sets: dict[str, list[int]] = {}
    for keyword, data in _nastran_cards(path, ("SET1", "RBE2")):
        values = [d for d in data if d]
        try:
            if keyword == "SET1":
                grids, k = [], 1
                while k < len(values):
                    if values[k].upper() == "THRU":
                        grids.extend(range(grids[-1] + 1, int(values[k + 1]) + 1))
                        k += 2
                    else:
                        grids.append(int(values[k]))
                        k += 1
                sets.setdefault(f"SET1_{int(values[0])}", []).extend(grids)
            else:           # RBE2 EID GN CM GM1 ... [ALPHA [TREF]]
                grids = [int(v) for v in values[3:] if v.lstrip("+-").isdigit()]
                sets[f"RBE2_{int(values[0])}"] = grids
        except (ValueError, IndexError):
            raise InputError(f"{path}: geometry.file: malformed {keyword} card {' '.join(values)}") from None
    return sets


def _hex20_to_hex27(points: np.ndarray, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """20-node bricks (VTK order) -> 27-node bricks: face nodes sum(edge mids)/2 - sum(corners)/4, the body node
    sum(edge mids)/4 - sum(corners)/4 (the serendipity map at the face and body centres).  Face nodes shared
    by two bricks are created once."""
    edge_of = {frozenset(e): 8 + i for i, e in enumerate(_HEX_EDGES)}
    new_points = [points]
    n = len(points)
    faces_all = []
    for face in _FACES_VTK["hexahedron"]:
        mids = [edge_of[frozenset((face[k], face[(k + 1) % 4]))] for k in range(4)]
        centre = 0.5 * points[cells[:, mids]].sum(axis=1) - 0.25 * points[cells[:, list(face)]].sum(axis=1)
        faces_all.append((np.sort(cells[:, list(face)], axis=1), centre))
    keys = np.concatenate([k for k, _ in faces_all])
    centres = np.concatenate([c for _, c in faces_all])
    unique, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    new_points.append(centres[first])
    face_ids = (n + inverse.ravel()).reshape(6, len(cells)).T
    n += len(unique)
    body = 0.25 * points[cells[:, 8:20]].sum(axis=1) - 0.25 * points[cells[:, :8]].sum(axis=1)
    new_points.append(body)
    new_cells = np.hstack([cells, face_ids, (n + np.arange(len(cells)))[:, None]])
    return np.vstack(new_points), new_cells


def _boundary_facets(corners: np.ndarray, cell_type: str) -> np.ndarray:
    """Sorted corner tuples (F, 3 or 4) of the faces that belong to one cell only."""
    faces = np.concatenate([np.sort(corners[:, list(f)], axis=1) for f in _FACES_VTK[cell_type]])
    unique, counts = np.unique(faces, axis=0, return_counts=True)
    return unique[counts == 1]


def _groups(mf: MeshFile, geometry, key: str) -> tuple[dict, np.ndarray, dict]:
    """Facet groups of the boundary facets: (name -> tag values, tag value per boundary facet, cell groups)."""
    names = {"outer": np.ones(len(mf.boundary), bool)}
    for field_name in ("bores", "surfaces"):
        for i, entry in enumerate(getattr(geometry, field_name)):
            k = f"{key}.{field_name}.{i}.set"
            if entry.set in mf.node_sets:
                mask = mf.node_sets[entry.set][mf.boundary].all(axis=1)
            elif entry.set in mf.surface_sets:
                wanted = mf.surface_sets[entry.set]
                mask = np.array([tuple(f) in wanted for f in mf.boundary.tolist()], bool)
            elif entry.set in mf.cell_sets:
                raise InputError(f"{mf.path}: {k}: {entry.set!r} is a set of volume cells; a surface needs a node "
                                 "set or a set of surface elements")
            else:
                known = sorted(set(mf.node_sets) | set(mf.surface_sets))
                raise InputError(f"{mf.path}: {k}: no node or surface set {entry.set!r} in the file (it has: "
                                 f"{', '.join(known) or 'none'})")
            if not mask.any():
                raise InputError(f"{mf.path}: {k}: set {entry.set!r} covers no boundary facet of the volume mesh")
            names[entry.name] = mask
    order = list(names)
    membership = np.stack([names[n] for n in order], axis=1)
    combos, value_of = np.unique(membership, axis=0, return_inverse=True)
    values = value_of.ravel().astype(np.int32) + 1
    groups = {n: [int(v) + 1 for v in np.flatnonzero(combos[:, j])] for j, n in enumerate(order)}
    cell_groups = {name: i + 1 for i, name in enumerate(sorted(mf.cell_sets))}
    return groups, values, cell_groups


def _read_on_root(geometry, comm, key: str):
    """(MeshFile or None, error message or None) on rank 0, the error broadcast to every rank."""
    mf, groups, error = None, None, None
    if comm.rank == 0:
        try:
            mf = read_mesh_file(geometry.file, geometry.units, key)
            groups = _groups(mf, geometry, key)
        except InputError as exc:
            error = str(exc)
    error = comm.bcast(error, root=0)
    if error:
        raise InputError(error)
    return mf, groups


def build_imported_mesh(geometry: MeshGeometry, comm, key: str = "geometry"):
    """The fields of the distributed HousingMesh of a mesh-file geometry (collective; housingfe.geometry.mesh
    .build_mesh makes the HousingMesh and adds the element quality).  Cell tags: the volume cell sets;
    facet tags: "outer" and the named bores and surfaces (tag values = distinct combinations of groups)."""
    import ufl
    from dolfinx import fem
    from dolfinx.mesh import create_mesh, exterior_facet_indices, meshtags
    from mpi4py import MPI


    t0 = time.perf_counter()
    mf, groups = _read_on_root(geometry, comm, key)
    head = comm.bcast((mf.cell_type, mf.degree, mf.cells.shape[1], mf.element_size, mf.notes, mf.source_cell)
                      if comm.rank == 0 else None, root=0)
    cell_type, degree, n_nodes, size, notes, source = head
    family = "Q" if cell_type == "hexahedron" else "Lagrange"
    domain = ufl.Mesh(ufl.VectorElement(family, ufl.Cell(cell_type, geometric_dimension=3), degree))
    if comm.rank == 0:
        cells, x = mf.cells, mf.points
        facet_groups, facet_values, cell_groups = groups
        boundary = mf.boundary
        cell_values = np.zeros(len(cells), np.int32)
        for name, value in cell_groups.items():
            cell_values[mf.cell_sets[name]] = value
    else:
        cells, x = np.empty((0, n_nodes), np.int64), np.empty((0, 3))
        facet_groups = cell_groups = boundary = facet_values = cell_values = None
    mesh = create_mesh(comm, cells, x, domain)
    facet_groups, cell_groups = comm.bcast((facet_groups, cell_groups), root=0)
    boundary, facet_values, cell_values = comm.bcast((boundary, facet_values, cell_values), root=0)

    tdim = 3
    topology = mesh.topology
    topology.create_connectivity(tdim - 1, 0)
    topology.create_connectivity(tdim - 1, tdim)
    topology.create_connectivity(tdim, 0)
    nv = 4 if cell_type == "tetrahedron" else 8
    n_cells = topology.index_map(tdim).size_local + topology.index_map(tdim).num_ghosts
    x_dofs = mesh.geometry.dofmap.array.reshape(n_cells, -1)
    c2v = topology.connectivity(tdim, 0).array.reshape(n_cells, nv)
    vertex_node = np.empty(topology.index_map(0).size_local + topology.index_map(0).num_ghosts, np.int64)
    vertex_node[c2v.ravel()] = x_dofs[:, :nv].ravel()          # vertices are the first geometry nodes
    original = np.asarray(mesh.geometry.input_global_indices, np.int64)

    facets = np.sort(exterior_facet_indices(topology))
    f2v = topology.connectivity(tdim - 1, 0).array.reshape(-1, 3 if cell_type == "tetrahedron" else 4)
    keys = np.sort(original[vertex_node[f2v[facets]]], axis=1)
    lookup = {tuple(k): v for k, v in zip(boundary.tolist(), facet_values.tolist())}
    values = np.array([lookup.get(tuple(k), 0) for k in keys.tolist()], np.int32)
    if comm.allreduce(bool(np.any(values == 0)), op=MPI.LOR):
        raise InputError(f"{geometry.file}: {key}.file: boundary facets of the distributed mesh are not faces of "
                         "the file's cells (duplicate nodes?)")
    facet_tags = meshtags(mesh, tdim - 1, facets.astype(np.int32), values)
    n_local = topology.index_map(tdim).size_local
    cells_local = np.arange(n_local, dtype=np.int32)
    cell_tags = meshtags(mesh, tdim, cells_local,
                         cell_values[np.asarray(topology.original_cell_index, np.int64)[:n_local]])

    one = fem.form(fem.Constant(mesh, 1.0) * ufl.dx(domain=mesh))
    xs = ufl.SpatialCoordinate(mesh)
    volume = comm.allreduce(fem.assemble_scalar(one), op=MPI.SUM)
    if volume <= 0:
        raise InputError(f"{geometry.file}: {key}.file: the mesh has no volume")
    centroid = np.array([comm.allreduce(fem.assemble_scalar(fem.form(xs[i] * ufl.dx(domain=mesh))), op=MPI.SUM)
                         for i in range(3)]) / volume
    _CACHE.clear()      # the file's arrays are in the dolfinx mesh now
    return dict(mesh=mesh, cell_tags=cell_tags, facet_tags=facet_tags, cell_groups=cell_groups,
                facet_groups=facet_groups, volume=volume, centroid=centroid, element_size=size,
                element="tet" if cell_type == "tetrahedron" else "hex", mesh_time_s=time.perf_counter() - t0,
                quality={"mesher": f"imported {source} from {Path(geometry.file).name}", "notes": notes})


# edges and faces of the dolfinx reference cells by vertex (hexahedron vertices in tensor order i + 2 j + 4 k)
_DOLFINX_EDGES = {"tetrahedron": [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)],
                  "hexahedron": [(0, 1), (0, 2), (0, 4), (1, 3), (1, 5), (2, 3), (2, 6), (3, 7), (4, 5), (4, 6),
                                 (5, 7), (6, 7)]}
_DOLFINX_FACES = {"tetrahedron": [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)],
                  "hexahedron": [(0, 1, 2, 3), (0, 1, 4, 5), (0, 2, 4, 6), (1, 3, 5, 7), (2, 3, 6, 7), (4, 5, 6, 7)]}


def estimate_imported_dofs(geometry: MeshGeometry, degree: int) -> int:
    """Displacement DOFs (3 per Lagrange node) of the mesh file at a displacement degree, counted exactly from
    its vertices V, edges E, faces F and cells C: tetrahedra V + (p-1) E + (p-1)(p-2)/2 F + (p-1)(p-2)(p-3)/6 C,
    hexahedra V + (p-1) E + (p-1)^2 F + (p-1)^3 C."""
    mf = read_mesh_file(geometry.file, geometry.units)
    nv = 4 if mf.cell_type == "tetrahedron" else 8
    corners = mf.cells[:, :nv]

    def count(groups) -> int:
        keys = np.concatenate([np.sort(corners[:, list(g)], axis=1) for g in groups])
        return len(np.unique(keys, axis=0))

    V, C = len(np.unique(corners)), len(corners)
    E, F = count(_DOLFINX_EDGES[mf.cell_type]), count(_DOLFINX_FACES[mf.cell_type])
    p = degree
    if mf.cell_type == "tetrahedron":
        nodes = V + (p - 1) * E + (p - 1) * (p - 2) // 2 * F + (p - 1) * (p - 2) * (p - 3) // 6 * C
    else:
        nodes = V + (p - 1) * E + (p - 1) ** 2 * F + (p - 1) ** 3 * C
    return int(3 * nodes)


def _estimate_on_root(geometry: MeshGeometry, degree: int) -> int:
    # estimate_dofs runs on every rank; the file is read (and cached) on each, which only costs the read
    return estimate_imported_dofs(geometry, degree)


# a mesh file brings its own element, size and layers: the registry's signatures (GeometryKind) ignore them here
register_geometry(MeshGeometry, None,
                  mesh=lambda spec, element, size, layers, comm, **_: build_imported_mesh(spec, comm),
                  estimate_dofs=lambda spec, element, degree, size, layers, layer_size=None: _estimate_on_root(spec,
                                                                                                           degree))


def write_mesh_file(housing, path, units: str = "m", order: int | None = None, node_sets=()) -> Path:
    """Write a HousingMesh (one MPI rank) to a mesh file meshio writes (.inp, .bdf, .msh, ...): its cells in VTK
    order, coordinates in `units`.  order: None keeps the mesh's cells; 2 on a linear mesh adds straight-edge
    mid-nodes (tet10; hex20 for .inp/.bdf, hex27 elsewhere) so that quadratic readers can be checked on the same
    geometry.  node_sets: facet group names written as node sets (Abaqus NSET) or surface cells (gmsh)."""
    import dolfinx.cpp.io as cio
    import meshio
    from dolfinx.mesh import CellType

    mesh = housing.mesh
    if mesh.comm.size != 1:
        raise InputError("write_mesh_file: export a mesh built on one rank (MPI.COMM_SELF)")
    path = Path(path)
    tdim = 3
    n_cells = mesh.topology.index_map(tdim).size_local
    cells = mesh.geometry.dofmap.array.reshape(n_cells, -1)
    cell_type = mesh.topology.cell_type.name
    perm = np.asarray(cio.perm_vtk(getattr(CellType, cell_type), cells.shape[1]))
    cells_vtk = cells[:, np.argsort(perm)]
    x = mesh.geometry.x.copy()
    linear = cells.shape[1] in (4, 8)
    if order == 2 and linear:
        nv = cells.shape[1]
        edges = ([(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)] if nv == 4 else _HEX_EDGES)
        pairs = np.concatenate([np.sort(cells_vtk[:, list(e)], axis=1) for e in edges])
        unique, inverse = np.unique(pairs, axis=0, return_inverse=True)
        mids = len(x) + inverse.ravel().reshape(len(edges), n_cells).T
        x = np.vstack([x, 0.5 * (x[unique[:, 0]] + x[unique[:, 1]])])
        cells_vtk = np.hstack([cells_vtk, mids])
        if nv == 8 and path.suffix.lower() not in (".inp", ".bdf", ".nas", ".dat"):
            x, cells_vtk = _hex20_to_hex27(x, cells_vtk)
    meshio_type = {4: "tetra", 10: "tetra10", 8: "hexahedron", 20: "hexahedron20", 27: "hexahedron27"}[
        cells_vtk.shape[1]]
    blocks = [(meshio_type, cells_vtk)]
    point_sets, cell_sets = {}, {}
    tags = housing.facet_tags
    f2v = None
    for name in node_sets:
        facets = housing.facets(name)
        mesh.topology.create_connectivity(tdim - 1, tdim)
        mesh.topology.create_connectivity(tdim - 1, 0)
        f2c = mesh.topology.connectivity(tdim - 1, tdim)
        f2v = mesh.topology.connectivity(tdim - 1, 0)
        c2v = mesh.topology.connectivity(tdim, 0).array.reshape(n_cells, -1)
        vertex_node = np.empty(mesh.topology.index_map(0).size_local, np.int64)
        vertex_node[c2v.ravel()] = cells[:, :c2v.shape[1]].ravel()
        corners = np.array([vertex_node[f2v.links(f)] for f in facets])
        del f2c
        if path.suffix.lower() == ".msh":
            kind = "triangle" if corners.shape[1] == 3 else "quad"
            if kind == "quad":       # dolfinx quads are tensor-ordered, meshio's cyclic
                corners = corners[:, [0, 1, 3, 2]]
            cell_sets[name] = [np.array([], int)] * len(blocks) + [np.arange(len(corners))]
            blocks.append((kind, corners))
            for other in cell_sets.values():
                while len(other) < len(blocks):
                    other.append(np.array([], int))
        else:
            point_sets[name] = np.unique(corners)
    del tags, f2v
    out = meshio.Mesh(x / UNIT_SCALE[units], blocks, point_sets=point_sets)
    if path.suffix.lower() == ".msh":     # physical groups: the volume (1), then one per named surface
        out.cell_data["gmsh:physical"] = [np.full(len(b[1]), i + 1) for i, b in enumerate(blocks)]
        out.cell_data["gmsh:geometrical"] = [np.full(len(b[1]), i + 1) for i, b in enumerate(blocks)]
        out.field_data = {"housing": np.array([1, 3])}
        out.field_data.update({name: np.array([i + 2, 2]) for i, name in enumerate(cell_sets)})
        meshio.write(str(path), out, file_format="gmsh22", binary=False)
    elif path.suffix.lower() in (".bdf", ".nas"):
        _write_nastran(path, out.points, meshio_type, cells_vtk, point_sets)
    else:
        meshio.write(str(path), out)
    return path


# VTK -> Nastran order of the 20-node brick: Nastran lists the vertical edges (G13-G16) before the top ones
_NASTRAN_HEX20 = list(range(12)) + [16, 17, 18, 19, 12, 13, 14, 15]


def _write_nastran(path: Path, points: np.ndarray, meshio_type: str, cells_vtk: np.ndarray,
                   node_sets: dict | None = None) -> None:
    """Nastran bulk data: GRID* in large field (16-character reals, 10 significant digits: meshio 5.0's writer
    overflows the field on negative coordinates), CTETRA / CHEXA in free field with continuations, and each node
    set as SET1 <k> (k = 1, 2, ... in the order given; read back as "SET1_<k>")."""
    name = {"tetra": "CTETRA", "tetra10": "CTETRA", "hexahedron": "CHEXA", "hexahedron20": "CHEXA"}[meshio_type]
    cells = cells_vtk[:, _NASTRAN_HEX20] if meshio_type == "hexahedron20" else cells_vtk
    with open(path, "w") as f:
        f.write("$ written by housingfe\nBEGIN BULK\n")
        for i, (x, y, z) in enumerate(points, start=1):
            f.write(f"GRID*   {i:<16d}{'':16s}{x:16.9E}{y:16.9E}*\n*       {z:16.9E}\n")
        for e, cell in enumerate(cells + 1, start=1):
            fields = [name, str(e), "1"] + [str(n) for n in cell]
            f.write(",".join(fields[:9]) + "\n")
            for k in range(9, len(fields), 8):
                f.write("+," + ",".join(fields[k:k + 8]) + "\n")
        for sid, (name, nodes) in enumerate((node_sets or {}).items(), start=1):
            f.write(f"$ SET1 {sid}: {name}\n")
            fields = ["SET1", str(sid)] + [str(n + 1) for n in nodes]
            f.write(",".join(fields[:9]) + "\n")
            for k in range(9, len(fields), 8):
                f.write("+," + ",".join(fields[k:k + 8]) + "\n")
        f.write("ENDDATA\n")
