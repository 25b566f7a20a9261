"""From a validated scene geometry to a distributed dolfinx mesh with named cell and facet tags."""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from housingfe.errors import InputError
from housingfe.geometry.blocks import build_gmsh_model, distribute_gmsh_model, tet_quality

# the registry's lookup, with the built-in kinds registered (specs imports their modules)
from housingfe.geometry.specs import GEOMETRY_KINDS, block_model_for

# Elements below this quality count as slivers in element_quality's low_count / low_volume_fraction (the
# FE model's refusal threshold, housingfe.fe.model.MIN_ELEMENT_QUALITY).
LOW_QUALITY = 0.05


@dataclass
class HousingMesh:
    """A dolfinx mesh with its tags and the exact geometric facts of the model it came from.

    cell_groups maps feature names to tag values in cell_tags; facet_groups maps surface names to the
    tuple of tag values in facet_tags that make up the surface (use `facet_tag_values` with ufl's ds).
    volume (m^3) and centroid (m) are exact (from the block model), for checks of the FE model.
    """

    mesh: object
    cell_tags: object
    facet_tags: object
    cell_groups: dict[str, int]
    facet_groups: dict[str, list[int]]
    volume: float
    centroid: np.ndarray
    element_size: float
    element: str
    points: dict = field(default_factory=dict)
    mesh_time_s: float = 0.0
    quality: dict = field(default_factory=dict)

    def facet_tag_values(self, name: str) -> tuple[int, ...]:
        """Tag values making up the named surface, for ufl: ds(housing.facet_tag_values("outer"))."""
        if name not in self.facet_groups:
            raise InputError(f"unknown surface group {name!r}; known: {', '.join(sorted(self.facet_groups))}")
        return tuple(self.facet_groups[name])

    def facets(self, name: str) -> np.ndarray:
        """Local indices of the facets of the named surface (raises InputError if unknown)."""
        values = self.facet_tag_values(name)
        return np.unique(np.concatenate([self.facet_tags.find(v) for v in values]))


def bending_wavelength(frequency: float, thickness: float, youngs_modulus: float, poisson_ratio: float,
                       density: float) -> float:
    """Bending wavelength (m) of a thin plate of `thickness` (m) at `frequency` (Hz)."""
    D = youngs_modulus * thickness**3 / (12 * (1 - poisson_ratio**2))
    omega = 2 * math.pi * frequency
    k = (omega**2 * density * thickness / D) ** 0.25
    return 2 * math.pi / k


# DOFs per cell of the estimated element grid for quadratic elements, measured (issue 12): hex27 34-38 (box-free
# at 23 and 40 mm, box-halves, NAFEMS FV12; the estimated grid is the hex mesh itself), tet10 15-63
# (gearbox-model, test-gearbox-interior, box-free as tets: HXT puts a few tetrahedra through a wall).  The
# estimate is good to a factor 3 for tets and 10 % for hexes.
DOFS_PER_GRID_CELL = {"hex": 37.0, "tet": 40.0}


def estimate_dofs(geometry, element: str, degree: int, size: float, layers: int,
                  layer_size: float | None = None) -> int:
    """Displacement DOFs (3 per node) of the mesh `build_mesh` would make, estimated from the block model
    without meshing: every grid cell gets the structured divisions of its edges (size in m, `layers` through
    wall thicknesses), times DOFS_PER_GRID_CELL scaled by degree^2 (degree + 1) / 12: the cells are mostly one
    layer through a wall, p^2 nodes per cell in the plane times p + 1 through it (Q3 box, 40 mm: 44 256 DOFs,
    estimate within 10 %)."""
    from housingfe.geometry.blocks import divisions

    kind = GEOMETRY_KINDS.get(geometry.kind)
    if kind is not None and kind.estimate_dofs is not None:     # imported CAD or a mesh file
        return kind.estimate_dofs(geometry, element, degree, size, layers, layer_size)
    model = block_model_for(geometry)
    steps = [np.diff(g) for g in model.grid]
    cells = 0
    for i, j, k in model.cells:
        cells += math.prod(divisions(float(d), size, model.thin_dimensions, layers, layer_size)
                           for d in (steps[0][i], steps[1][j], steps[2][k]))
    return int(round(DOFS_PER_GRID_CELL[element] * degree ** 2 * (degree + 1) / 12 * cells))


def build_mesh(geometry, element: str, size: float, layers: int, comm, grading: float = 1.0,
               layer_size: float | None = None) -> HousingMesh:
    """Build the gmsh model on rank 0, mesh it and distribute it as a dolfinx mesh.

    element: "hex" (structured quadratic-ready hexahedra) or "tet"; size: element size (m);
    layers: elements through a wall thickness (hex meshes); layer_size (m): with it, at least
    ceil(thickness / layer_size) elements through each wall (hex meshes, `blocks.divisions`).
    """
    t0 = time.perf_counter()
    kind = GEOMETRY_KINDS.get(geometry.kind)
    if kind is not None and kind.mesh is not None:     # a kind that meshes itself (imported CAD, a mesh file)
        parts = kind.mesh(geometry, element, size, layers, comm, grading=grading, layer_size=layer_size)
        quality = {**element_quality(parts["mesh"]), **parts.pop("quality", {})}
        parts.setdefault("element_size", size)          # a mesh file gives its own element, size and timing
        parts.setdefault("element", element)
        parts.setdefault("mesh_time_s", time.perf_counter() - t0)
        return HousingMesh(**parts, quality=quality)
    import gmsh

    model = block_model_for(geometry)
    groups = error = None
    if comm.rank == 0:
        gmsh.initialize()
        try:
            gmsh.option.setNumber("General.Terminal", 0)
            gmsh.model.add("housing")
            groups = build_gmsh_model(model, element, size, layers, grading, layer_size)
        except Exception as exc:
            gmsh.finalize()
            error = exc
    # rank 0 alone meshes: its error (a bore breaking out of a wall, hexes asked for round bores) is every rank's,
    # else the others wait in the broadcast for ever (mpirun -n 2 hung on `--set mesh.element="hex"`)
    failure = None if error is None else (isinstance(error, InputError), str(error))
    groups, failure = comm.bcast((groups, failure), root=0)
    if error is not None:
        raise error
    if failure is not None:
        is_input, text = failure
        raise InputError(text) if is_input else RuntimeError(f"rank 0 failed to mesh: {text}")
    mesh, cell_tags, facet_tags = distribute_gmsh_model(comm)
    return HousingMesh(mesh=mesh, cell_tags=cell_tags, facet_tags=facet_tags, cell_groups=groups["cells"],
                       facet_groups=groups["facets"], volume=model.volume(), centroid=model.centroid(),
                       element_size=size, element=element, points=model.points,
                       mesh_time_s=time.perf_counter() - t0,
                       quality={**element_quality(mesh), "mesher": groups.get("mesher")})


def element_quality(mesh) -> dict:
    """Min/max element quality over the mesh (all ranks): for tetrahedra 6*sqrt(2)*V / l_rms^3 (1 for the
    regular tetrahedron), for hexahedra the minimum scaled Jacobian over the eight corners (1 for a cube,
    <= 0 for an inverted element); low_count: the elements below LOW_QUALITY, low_volume_fraction: their
    share of the mesh's volume (tetrahedra; hexahedra: their share of the cells), elements: the cell count."""
    x = mesh.geometry.x
    dofs = mesh.geometry.dofmap.array.reshape(mesh.topology.index_map(3).size_local
                                              + mesh.topology.index_map(3).num_ghosts, -1)
    n_local = mesh.topology.index_map(3).size_local
    xc = x[dofs[:n_local]]
    if xc.shape[1] == 4 or (xc.shape[1] == 10):
        q = tet_quality(xc[:, :4])
        measure = "tet 6*sqrt(2)*V/l_rms^3"
        v = xc[:, :4]
        volume = np.abs(np.einsum("ij,ij->i", v[:, 1] - v[:, 0], np.cross(v[:, 2] - v[:, 0], v[:, 3] - v[:, 0]))) / 6
    else:
        q = _hex_scaled_jacobian(xc[:, :8])
        measure = "hex min scaled Jacobian"
        volume = np.ones(len(q))
    comm = mesh.comm
    qmin = comm.allreduce(float(q.min()) if len(q) else np.inf, op=_mpi_min())
    qmax = comm.allreduce(float(q.max()) if len(q) else -np.inf, op=_mpi_max())
    low = q < LOW_QUALITY
    low_count = comm.allreduce(int(low.sum()))
    low_volume = comm.allreduce(float(volume[low].sum()))
    total_volume = comm.allreduce(float(volume.sum()))
    return {"min": qmin, "max": qmax, "measure": measure, "low_quality": LOW_QUALITY, "low_count": low_count,
            "low_volume_fraction": low_volume / total_volume if total_volume > 0 else 0.0,
            "elements": comm.allreduce(len(q))}


def _mpi_min():
    from mpi4py import MPI
    return MPI.MIN


def _mpi_max():
    from mpi4py import MPI
    return MPI.MAX





def _hex_scaled_jacobian(v: np.ndarray) -> np.ndarray:
    # dolfinx hexahedron vertices are in tensor-product order: vertex index = i + 2 j + 4 k
    q = np.full(len(v), np.inf)
    for corner in range(8):
        edges = []
        for bit in range(3):
            e = v[:, corner ^ (1 << bit)] - v[:, corner]
            if corner & (1 << bit):
                e = -e
            edges.append(e / np.linalg.norm(e, axis=1)[:, None])
        q = np.minimum(q, np.einsum("ij,ij->i", edges[0], np.cross(edges[1], edges[2])))
    return q
