"""Linear elasticity on a dolfinx mesh: function space, stiffness and mass matrices, Dirichlet conditions.

Quadratic Lagrange elements (P2 tetrahedra / Q2 hexahedra) are the default: they do not lock in bending of
thin walls with one or two elements through the thickness.
"""
from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem.petsc import assemble_matrix
from dolfinx.mesh import CellType
from petsc4py import PETSc

from housingfe.materials import Material

FAMILIES = {"lagrange": "Lagrange", "serendipity": "S"}


def displacement_space(mesh, degree: int = 2, family: str = "lagrange"):
    """Vector space of the given polynomial degree and family (lagrange, serendipity) for the displacement (m)."""
    return fem.VectorFunctionSpace(mesh, (FAMILIES[family], degree))


class MaterialField:
    """Piecewise-constant material properties over the mesh (one value per cell, DG0): Lamé constants
    (Pa), density (kg/m^3) and loss factor (-).  Cells of a named group take that group's material, the
    rest the default material."""

    def __init__(self, mesh, default: Material, cell_tags=None, groups: dict[int, Material] | None = None):
        Q = fem.FunctionSpace(mesh, ("DG", 0))
        self.lam, self.mu = fem.Function(Q, name="lambda"), fem.Function(Q, name="mu")
        self.rho, self.eta = fem.Function(Q, name="rho"), fem.Function(Q, name="eta")
        self._fill(default, None)
        for tag, material in (groups or {}).items():
            self._fill(material, cell_tags.find(tag))
        for f in (self.lam, self.mu, self.rho, self.eta):
            f.x.scatter_forward()

    def _fill(self, m: Material, cells) -> None:
        lam, mu = m.lame
        for f, value in ((self.lam, lam), (self.mu, mu), (self.rho, m.density), (self.eta, m.loss_factor)):
            if cells is None:
                f.x.array[:] = value
            else:
                f.x.array[cells] = value


def _stress(u, lam, mu):
    eps = ufl.sym(ufl.grad(u))
    return 2.0 * mu * eps + lam * ufl.tr(eps) * ufl.Identity(len(u))


def volume_measure(V, reduced: bool = False):
    """dx with full Gauss integration on hexahedra: (p+1)^3 points for Q_p, exact for K and M on brick
    (parallelepiped) cells.  UFL's estimate adds degrees for the trilinear geometry map and picks (p+2)^3:
    the same matrices to 3e-15 on the box meshes at 2.2x the assembly time (Q3, 40 mm: 1.58 -> 0.72 s for K).
    Simplices keep UFL's estimate, which is exact there (affine cells).  reduced: p^3 points (2x2x2 for the
    20-node brick, C3D20R's rule)."""
    if reduced:
        return ufl.dx(metadata={"quadrature_degree": 2 * V.ufl_element().degree() - 2})
    if V.mesh.topology.cell_type == CellType.hexahedron:
        return ufl.dx(metadata={"quadrature_degree": 2 * V.ufl_element().degree()})
    return ufl.dx


# Above this Poisson ratio (lambda > 49 mu) a material counts as nearly incompressible (rubber gaskets, nu = 0.499):
# fully integrated bricks lock volumetrically there.  Bench stability, a 10 mm nu = 0.499 layer (E = 10 MPa) bonded
# between two 40 mm steel blocks, one Q2 layer through it: the rocking and bounce modes came out 2.3x too stiff
# (2016 Hz against 860 Hz converged, Q3); with the volumetric term of those cells integrated at p^3 points
# (selective reduced integration) 854 Hz (-0.7 %).  Other materials keep full integration (unchanged results).
NEARLY_INCOMPRESSIBLE_NU = 0.49
_LAMBDA_OVER_MU = 2 * NEARLY_INCOMPRESSIBLE_NU / (1 - 2 * NEARLY_INCOMPRESSIBLE_NU)


def nearly_incompressible(materials: MaterialField) -> bool:
    """Whether any cell (on any rank) has a Poisson ratio above NEARLY_INCOMPRESSIBLE_NU."""
    local = bool(np.any(materials.lam.x.array > _LAMBDA_OVER_MU * materials.mu.x.array * (1 + 1e-12)))
    return bool(materials.lam.function_space.mesh.comm.allreduce(local, op=_mpi_lor()))


def _mpi_lor():
    from mpi4py import MPI
    return MPI.LOR


def stiffness_form(V, materials: MaterialField, weight=None, reduced: bool = False, selective: bool = True):
    """Bilinear form of the elastic strain energy, K (N/m); `weight` (e.g. the loss factor field)
    multiplies the integrand, giving the hysteretic damping matrix for weight = eta.  reduced: reduced
    Gauss integration (volume_measure).  Nearly incompressible cells (nu > NEARLY_INCOMPRESSIBLE_NU) get their
    volumetric term lambda div(u) div(v) integrated at reduced order (against volumetric locking) unless
    selective=False (the fully integrated form, for references)."""
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    if reduced or not selective or not nearly_incompressible(materials):
        integrand = ufl.inner(_stress(u, materials.lam, materials.mu), ufl.sym(ufl.grad(v)))
        return fem.form((integrand if weight is None else weight * integrand) * volume_measure(V, reduced))
    lam, mu = materials.lam, materials.mu
    soft = ufl.conditional(ufl.gt(lam, _LAMBDA_OVER_MU * mu), 1.0, 0.0)
    w = 1.0 if weight is None else weight
    eps_u, eps_v = ufl.sym(ufl.grad(u)), ufl.sym(ufl.grad(v))
    full = w * (2.0 * mu * ufl.inner(eps_u, eps_v) + (1.0 - soft) * lam * ufl.div(u) * ufl.div(v))
    volumetric = w * soft * lam * ufl.div(u) * ufl.div(v)
    return fem.form(full * volume_measure(V) + volumetric * _volumetric_measure(V))


def _volumetric_measure(V):
    """Reduced quadrature of the volumetric term: p^3 Gauss points on Q_p bricks, one point on tetrahedra."""
    p = V.ufl_element().degree()
    if V.mesh.topology.cell_type == CellType.hexahedron:
        return ufl.dx(metadata={"quadrature_degree": max(2 * p - 2, 0)})
    return ufl.dx(metadata={"quadrature_degree": 1})


def mass_form(V, materials: MaterialField):
    """Bilinear form of the kinetic energy, M (kg)."""
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    return fem.form(materials.rho * ufl.inner(u, v) * volume_measure(V))


def foundation_form(V, ds, normal_stiffness: float, tangential_stiffness: float):
    """Distributed springs on a surface (elastic foundation): k_n (u.n)(v.n) + k_t (u_t . v_t),
    stiffness per unit area in N/m^3."""
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    n = ufl.FacetNormal(V.mesh)
    un, vn = ufl.dot(u, n), ufl.dot(v, n)
    ut, vt = u - un * n, v - vn * n
    # constants, not floats: a float is compiled into the form, so every other stiffness (a sampled frame,
    # housingfe uncertainty) was a C compile of its own
    kn = fem.Constant(V.mesh, PETSc.ScalarType(normal_stiffness))
    kt = fem.Constant(V.mesh, PETSc.ScalarType(tangential_stiffness))
    return fem.form((kn * un * vn + kt * ufl.inner(ut, vt)) * ds)


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


def assemble_stiffness_mass(V, materials: MaterialField, bcs: list, extra_stiffness: list = (),
                            reduced: bool = False, selective: bool = True) -> tuple[PETSc.Mat, PETSc.Mat]:
    """Assemble K (plus any extra stiffness forms, e.g. foundations) and M.  Constrained rows/columns get 1
    on K's diagonal and 0 on M's, so their eigenvalues go to infinity and never enter the spectrum of
    interest.  reduced: reduced integration of K (M stays fully integrated).  selective: the reduced volumetric
    integration of nearly incompressible cells (stiffness_form)."""
    K = assemble_matrix(stiffness_form(V, materials, reduced=reduced, selective=selective), bcs=bcs, diagonal=1.0)
    K.assemble()
    for form in extra_stiffness:
        Ke = assemble_matrix(form, bcs=bcs, diagonal=0.0)
        Ke.assemble()
        K.axpy(1.0, Ke, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
    M = assemble_matrix(mass_form(V, materials), bcs=bcs, diagonal=0.0)
    M.assemble()
    for A in (K, M):
        A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    return K, M


def rigid_body_vectors(V) -> list[PETSc.Vec]:
    """The six rigid-body fields: translations x, y, z and rotations about the x, y, z axes through the
    origin (m per unit translation / rad), interpolated into V (exact: they are linear; any element family)."""
    vectors = []
    for i in range(6):
        u = fem.Function(V)
        if i < 3:
            u.interpolate(lambda x, i=i: np.vstack([np.full(x.shape[1], 1.0 if c == i else 0.0) for c in range(3)]))
        else:
            axis = np.zeros(3)
            axis[i - 3] = 1.0
            u.interpolate(lambda x, axis=axis: np.cross(axis, x.T).T)
        vectors.append(u.vector.copy())
    return vectors
