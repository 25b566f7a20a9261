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
    housing = build_mesh(scene.geometry, scene.mesh.element, size, scene.mesh.layers, comm)
    if housing.quality["min"] < MIN_ELEMENT_QUALITY:
        raise InputError(f"mesh: element quality {housing.quality['min']:.3f} < {MIN_ELEMENT_QUALITY} "
                         f"({housing.quality['measure']}); change mesh.size or mesh.element")
    t0 = time.perf_counter()
    V = elasticity.displacement_space(housing.mesh, scene.mesh.degree)
    bcs = boundary_conditions(scene, housing, V)
    K, M = elasticity.assemble_stiffness_mass(V, material, bcs)
    timings = {"mesh_s": housing.mesh_time_s, "assembly_s": time.perf_counter() - t0}
    return HousingModel(scene, housing, material, V, bcs, K, M, 0 if bcs else 6, timings)


def boundary_conditions(scene: HousingScene, housing: HousingMesh, V) -> list:
    """Dirichlet conditions the scene asks for (plate edges: clamped / simply supported)."""
    from housingfe.solvers.elasticity import clamp_bc

    bcs = []
    geometry = scene.geometry
    if geometry.kind == "plate":
        for edge, condition in geometry.edges.model_dump().items():
            facets = housing.facets(f"edge_{edge}")
            if condition == "clamped":
                bcs += clamp_bc(V, facets)
            elif condition == "simply_supported":
                bcs += clamp_bc(V, facets, components=(2,))
    return bcs
