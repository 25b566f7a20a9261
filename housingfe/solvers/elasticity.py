"""Linear elasticity on a dolfinx mesh: function space, stiffness and mass matrices, Dirichlet conditions.

Quadratic Lagrange elements (P2 tetrahedra / Q2 hexahedra) are the default: they do not lock in bending of
thin walls with one or two elements through the thickness.
"""
from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem.petsc import assemble_matrix
from petsc4py import PETSc

from housingfe.materials import Material


def displacement_space(mesh, degree: int = 2):
    """Vector Lagrange space of the given polynomial degree for the displacement (m)."""
    return fem.VectorFunctionSpace(mesh, ("Lagrange", degree))


def _stress(u, material: Material):
    lam, mu = material.lame
    eps = ufl.sym(ufl.grad(u))
    return 2.0 * mu * eps + lam * ufl.tr(eps) * ufl.Identity(len(u))


def stiffness_form(V, material: Material):
    """Bilinear form of the elastic strain energy, K (N/m)."""
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    return fem.form(ufl.inner(_stress(u, material), ufl.sym(ufl.grad(v))) * ufl.dx)


def mass_form(V, material: Material):
    """Bilinear form of the kinetic energy, M (kg)."""
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    return fem.form(material.density * ufl.inner(u, v) * ufl.dx)


def clamp_bc(V, facets: np.ndarray, components: tuple[int, ...] | None = None) -> list:
    """Zero-displacement conditions on the given facets: all components, or only the listed ones
    (e.g. (2,) = zero transverse displacement of a z-normal plate = simple support)."""
    fdim = V.mesh.topology.dim - 1
    if components is None:
        dofs = fem.locate_dofs_topological(V, fdim, facets)
        return [fem.dirichletbc(np.zeros(3, dtype=PETSc.ScalarType), dofs, V)]
    bcs = []
    for c in components:
        Vc = V.sub(c)
        dofs = fem.locate_dofs_topological(Vc, fdim, facets)
        bcs.append(fem.dirichletbc(PETSc.ScalarType(0), dofs, Vc))
    return bcs


def assemble_stiffness_mass(V, material: Material, bcs: list) -> tuple[PETSc.Mat, PETSc.Mat]:
    """Assemble K and M.  Constrained rows/columns get 1 on K's diagonal and 0 on M's, so their
    eigenvalues go to infinity and never enter the spectrum of interest."""
    K = assemble_matrix(stiffness_form(V, material), bcs=bcs, diagonal=1.0)
    K.assemble()
    M = assemble_matrix(mass_form(V, material), bcs=bcs, diagonal=0.0)
    M.assemble()
    for A in (K, M):
        A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    return K, M


def rigid_body_vectors(V) -> list[PETSc.Vec]:
    """The six rigid-body fields: translations x, y, z and rotations about the x, y, z axes through the
    origin (m per unit translation / rad)."""
    from dolfinx import la

    index_map, bs = V.dofmap.index_map, V.dofmap.index_map_bs
    vectors = [la.create_petsc_vector(index_map, bs) for _ in range(6)]
    x = V.tabulate_dof_coordinates()
    n = index_map.size_local + index_map.num_ghosts
    x = x[:n]
    for i, vec in enumerate(vectors):
        with vec.localForm() as local:
            a = np.zeros((n, 3))
            if i < 3:
                a[:, i] = 1.0
            else:
                axis = np.zeros(3)
                axis[i - 3] = 1.0
                a[:] = np.cross(axis, x)
            local.array[:] = a.reshape(-1)
    return vectors
