"""The FE model of a housing scene: mesh, displacement space, boundary conditions, K and M.

Builds only what the scene needs: the element size follows from the highest frequency of interest.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

from housingfe.errors import InputError
from housingfe.geometry import HousingMesh, build_mesh
from housingfe.geometry.mesh import bending_wavelength
from housingfe.materials import Material
from housingfe.scene import HousingScene

# Elements that fail this quality are rejected before any solve (hex: scaled Jacobian, tet: shape ratio).
MIN_ELEMENT_QUALITY = 0.05

# Peak memory of a run ~ base + per DOF (mesh, K and M, the MUMPS LDL^T factors of the inertia count and the
# shift-invert, the Krylov basis).  Upper end of what was measured on this stack: 39 k DOFs 0.5 GB, 136 k
# 1.2-1.7 GB, 317 k 2.8-4.0 GB (STACK-NOTES); `housingfe run` peak RSS: box-free 39 k DOFs 0.83 GB, gearbox-model
# 62 k DOFs 0.84 GB (estimates 0.81 and 1.1 GB).
MEMORY_BASE_BYTES = 0.3e9
MEMORY_PER_DOF_BYTES = 13e3


@dataclass
class HousingModel:
    """Everything the solvers need.  K, M are PETSc matrices with Dirichlet rows eliminated
    (1 on K's diagonal, 0 on M's); rigid_modes_expected is 6 for a free structure, else 0 (partial
    supports may still leave mechanisms, which the modal result counts)."""

    scene: HousingScene
    housing: HousingMesh
    material: Material
    V: object
    bcs: list
    K: object
    M: object
    rigid_modes_expected: int
    timings: dict = field(default_factory=dict)
    materials: object = None

    @property
    def dofs(self) -> int:
        return self.V.dofmap.index_map.size_global * self.V.dofmap.index_map_bs


def element_size(scene: HousingScene, material: Material) -> float:
    """Element size (m): explicit, or the bending wavelength of the thinnest wall at f_max divided by
    elements_per_wavelength."""
    if scene.mesh.size is not None:
        return scene.mesh.size
    wavelength = bending_wavelength(scene.analysis.f_max, scene.geometry.min_thickness,
                                    material.youngs_modulus, material.poisson_ratio, material.density)
    return wavelength / scene.mesh.elements_per_wavelength


def build_model(scene: HousingScene, comm) -> HousingModel:
    """Mesh the scene's geometry and assemble K and M."""
    from housingfe.solvers import elasticity

    material = scene.material.resolve()
    size = element_size(scene, material)
    check_model_size(scene, size, comm)
    housing = build_mesh(scene.geometry, scene.mesh.element, size, scene.mesh.layers, comm)
    if housing.quality["min"] < MIN_ELEMENT_QUALITY:
        raise InputError(f"mesh: element quality {housing.quality['min']:.3f} < {MIN_ELEMENT_QUALITY} "
                         f"({housing.quality['measure']}); change mesh.size or mesh.element")
    t0 = time.perf_counter()
    V = elasticity.displacement_space(housing.mesh, scene.mesh.degree)
    materials = material_field(scene, housing, material)
    bcs = boundary_conditions(scene, housing, V)
    K, M = elasticity.assemble_stiffness_mass(V, materials, bcs, foundation_forms(scene, housing, V))
    timings = {"mesh_s": housing.mesh_time_s, "assembly_s": time.perf_counter() - t0}
    free = not bcs and not any(s.kind == "elastic" for s in scene.supports)
    return HousingModel(scene, housing, material, V, bcs, K, M, 6 if free else 0, timings, materials)


def available_memory_bytes() -> tuple[int, int]:
    """(MemAvailable, MemTotal) of this machine in bytes, from /proc/meminfo (0, 0 where it cannot be read)."""
    info = {}
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                key, value = line.split(":", 1)
                info[key] = int(value.split()[0]) * 1024
    except (OSError, ValueError):
        return 0, 0
    return info.get("MemAvailable", info.get("MemFree", 0)), info.get("MemTotal", 0)


def check_model_size(scene: HousingScene, size: float, comm) -> dict:
    """Estimate DOFs and peak memory before meshing (housingfe.geometry.mesh.estimate_dofs, MEMORY_*) and raise
    InputError in one line when the estimate exceeds the memory available on this machine (MemAvailable of
    /proc/meminfo; all ranks of a run share the machine), unless mesh.allow_large is set.  The message names
    the element size, its key, and the geometry's largest dimension.  Returns the estimate."""
    from housingfe.geometry.mesh import estimate_dofs

    mesh = scene.mesh
    dofs = estimate_dofs(scene.geometry, mesh.element, mesh.degree, size, mesh.layers)
    need = MEMORY_BASE_BYTES * comm.size + MEMORY_PER_DOF_BYTES * dofs
    available, total = comm.bcast(available_memory_bytes() if comm.rank == 0 else None, root=0)
    estimate = {"dofs": dofs, "memory_bytes": need, "available_bytes": available, "total_bytes": total}
    if available and need > available and not mesh.allow_large:
        size_key = "mesh.size" if mesh.size is not None else "mesh.elements_per_wavelength"
        lengths = {k: v for k, v in scene.geometry.model_dump().items()
                   if isinstance(v, float) and not isinstance(v, bool)}
        largest = max(lengths, key=lengths.get) if lengths else None
        dims = f" (largest dimension: geometry.{largest} = {lengths[largest]:g} m)" if largest else ""
        raise InputError(f"mesh: model too large: ~{dofs:,} DOFs at {size * 1e3:.3g} mm elements need "
                         f"~{need / 1e9:.1f} GB, this machine has {available / 1e9:.1f} GB available "
                         f"(MemAvailable, {total / 1e9:.1f} GB total); check {size_key}{dims} or set "
                         f"mesh.allow_large = true to run anyway")
    return estimate


def material_field(scene: HousingScene, housing: HousingMesh, default: Material):
    """Per-cell material properties: the scene material, overridden in the named regions."""
    from housingfe.solvers.elasticity import MaterialField

    groups = {}
    for name, spec in scene.regions.items():
        if name not in housing.cell_groups:
            raise InputError(f"regions.{name}: no such cell group (known: {', '.join(sorted(housing.cell_groups))})")
        groups[housing.cell_groups[name]] = spec.resolve()
    return MaterialField(housing.mesh, default, housing.cell_tags, groups)


def foundation_forms(scene: HousingScene, housing: HousingMesh, V) -> list:
    """Stiffness forms of the elastic supports."""
    import ufl

    from housingfe.solvers.elasticity import foundation_form

    forms = []
    ds = ufl.Measure("ds", domain=housing.mesh, subdomain_data=housing.facet_tags)
    for i, support in enumerate(scene.supports):
        if support.kind == "elastic":
            tags = _surface_tags(housing, support.surface, f"supports[{i}].surface")
            forms.append(foundation_form(V, ds(tags), support.normal_stiffness, support.tangential_stiffness or 0.0))
    return forms


def _surface_tags(housing: HousingMesh, name: str, key: str) -> tuple[int, ...]:
    if name not in housing.facet_groups:
        raise InputError(f"{key}: no surface {name!r} (known: {', '.join(sorted(housing.facet_groups))})")
    return housing.facet_tag_values(name)


def boundary_conditions(scene: HousingScene, housing: HousingMesh, V) -> list:
    """Dirichlet conditions the scene asks for: supports (fixed / normal) and plate edge conditions."""
    from housingfe.solvers.elasticity import clamp_bc

    bcs = []
    for i, support in enumerate(scene.supports):
        if support.kind == "elastic":
            continue
        _surface_tags(housing, support.surface, f"supports[{i}].surface")
        facets = housing.facets(support.surface)
        if support.kind == "fixed":
            bcs += clamp_bc(V, facets)
        else:
            bcs += clamp_bc(V, facets, components=(_normal_axis(housing, facets, f"supports[{i}]"),))
    geometry = scene.geometry
    if geometry.kind == "plate":
        for edge, condition in geometry.edges.model_dump().items():
            facets = housing.facets(f"edge_{edge}")
            if condition == "clamped":
                bcs += clamp_bc(V, facets)
            elif condition == "simply_supported":
                bcs += clamp_bc(V, facets, components=(2,))
    return bcs


def _normal_axis(housing: HousingMesh, facets, key: str) -> int:
    """The coordinate axis normal to a plane, axis-aligned set of facets (for `normal` supports)."""
    import numpy as np
    from dolfinx.mesh import compute_midpoints
    from mpi4py import MPI

    mesh = housing.mesh
    mids = compute_midpoints(mesh, mesh.topology.dim - 1, facets)
    lo = mids.min(axis=0) if len(mids) else np.full(3, np.inf)
    hi = mids.max(axis=0) if len(mids) else np.full(3, -np.inf)
    lo = np.array([mesh.comm.allreduce(v, op=MPI.MIN) for v in lo])
    hi = np.array([mesh.comm.allreduce(v, op=MPI.MAX) for v in hi])
    spread = hi - lo
    axis = int(np.argmin(spread))
    if spread[axis] > 1e-9 * max(1.0, float(spread.max())):
        raise InputError(f"{key}: a normal support needs a plane, axis-aligned surface")
    return axis
