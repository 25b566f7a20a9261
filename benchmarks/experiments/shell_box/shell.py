"""Linear Reissner-Mindlin (Naghdi) shell on flat quadrilateral facets, dolfinx 0.5.2.

6 DOFs per node: u (3 global translations) and theta (3 global rotations), both vector Q_p Lagrange.
Per-cell orthonormal frame (e1, e2, e3) from the cell edges (flat rectangular facets: exact).
Kinematics (through-thickness displacement U(z) = u + z * d, director increment d = theta x e3):
  membrane   eps   = sym(P^T grad(u) P)                      P = [e1 e2]  (3x2)
  bending    kappa = sym(P^T grad(d) P)
  shear      gamma = P^T grad(u)^T e3 + P^T d
  drilling   drill = (G[1,0] - G[0,1]) / 2 - theta . e3,     G = P^T grad(u) P  (Hughes-Brezzi type penalty)
Energy: N:eps + M:kappa + kappa_s G t gamma.gamma + k_drill drill^2,  kappa_s = 5/6,
        k_drill = drill_factor * E * t^3   [value in SI, per unit area; used as a small penalty]
Mass:   rho t u.u + rho t^3/12 d.d   (rotary inertia of the director, no drilling inertia)
"""
from __future__ import annotations

import time

import numpy as np
import ufl
from dolfinx import fem
from dolfinx import mesh as dmesh
from dolfinx.fem.petsc import assemble_matrix
from mpi4py import MPI
from petsc4py import PETSc
from slepc4py import SLEPc


def make_quad_mesh(points: np.ndarray, quads: np.ndarray):
    """Manifold quadrilateral mesh (gdim 3). quads in DOLFINx/tensor order (v00, v10, v01, v11)."""
    cell = ufl.Cell("quadrilateral", geometric_dimension=3)
    domain = ufl.Mesh(ufl.VectorElement("Lagrange", cell, 1))
    return dmesh.create_mesh(MPI.COMM_WORLD, quads.astype(np.int64), points.astype(np.float64), domain)


def cell_data(msh, thickness_of_cell):
    """DG0 frame vectors e1, e2, e3 and thickness from the mesh's own geometry (flat facets).

    thickness_of_cell(centroid, normal) -> float."""
    V0 = fem.VectorFunctionSpace(msh, ("DG", 0), dim=3)
    S0 = fem.FunctionSpace(msh, ("DG", 0))
    e = [fem.Function(V0) for _ in range(3)]
    th = fem.Function(S0)
    x = msh.geometry.x
    gdm = msh.geometry.dofmap
    ncell = msh.topology.index_map(2).size_local + msh.topology.index_map(2).num_ghosts
    for c in range(ncell):
        nodes = gdm.links(c)
        p00, p10, p01 = x[nodes[0]], x[nodes[1]], x[nodes[2]]
        a1 = p10 - p00
        a2 = p01 - p00
        e1 = a1 / np.linalg.norm(a1)
        a2 = a2 - np.dot(a2, e1) * e1
        e2 = a2 / np.linalg.norm(a2)
        e3 = np.cross(e1, e2)
        d = V0.dofmap.cell_dofs(c)[0]
        for k, v in enumerate((e1, e2, e3)):
            e[k].x.array[3 * d:3 * d + 3] = v
        th.x.array[S0.dofmap.cell_dofs(c)[0]] = thickness_of_cell(x[nodes[:4]].mean(axis=0), e3)
    return e, th


def shell_forms(msh, e, th, E, nu, rho, degree=2, drill_factor=1.0, shear_qdeg=None, kappa_s=5.0 / 6.0):
    """Bilinear forms (K, M) and the function space."""
    el = ufl.VectorElement("Lagrange", msh.ufl_cell(), degree, dim=6)
    V = fem.FunctionSpace(msh, el)
    w, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    e1, e2, e3 = e
    P = ufl.as_matrix([[e1[i], e2[i]] for i in range(3)])  # 3x2
    G_ = E / 2 / (1 + nu)
    t = th
    Dm = E * t / (1 - nu ** 2)
    Db = E * t ** 3 / (12 * (1 - nu ** 2))
    kd = drill_factor * E * t ** 3

    def parts(z):
        u = ufl.as_vector([z[0], z[1], z[2]])
        th_ = ufl.as_vector([z[3], z[4], z[5]])
        d = ufl.cross(th_, e3)
        Gu = ufl.dot(P.T, ufl.dot(ufl.grad(u), P))
        eps = ufl.sym(Gu)
        kap = ufl.sym(ufl.dot(P.T, ufl.dot(ufl.grad(d), P)))
        gam = ufl.dot(P.T, ufl.dot(ufl.grad(u).T, e3)) + ufl.dot(P.T, d)
        drill = (Gu[1, 0] - Gu[0, 1]) / 2 - ufl.dot(th_, e3)
        return u, d, eps, kap, gam, drill

    I2 = ufl.Identity(2)

    def plane_stress(C, x):
        return C * ((1 - nu) * x + nu * ufl.tr(x) * I2)

    uw, dw, epw, kaw, gaw, drw = parts(w)
    uv, dv, epv, kav, gav, drv = parts(v)
    dx = ufl.Measure("dx", domain=msh)
    dxs = dx if shear_qdeg is None else ufl.Measure("dx", domain=msh, metadata={"quadrature_degree": shear_qdeg})
    a = (ufl.inner(plane_stress(Dm, epw), epv) + ufl.inner(plane_stress(Db, kaw), kav)) * dx \
        + kd * drw * drv * dx \
        + kappa_s * G_ * t * ufl.dot(gaw, gav) * dxs
    m = rho * t * ufl.dot(uw, uv) * dx + rho * t ** 3 / 12 * ufl.dot(dw, dv) * dx
    return V, a, m


def assemble(V, a, m, bcs=()):
    K = assemble_matrix(fem.form(a), bcs=list(bcs))
    K.assemble()
    M = assemble_matrix(fem.form(m), bcs=list(bcs), diagonal=0.0)
    M.assemble()
    return K, M


def eigensolve(K, M, nev=42, shift=-(2 * np.pi * 40) ** 2, factor="cholesky"):
    K.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    M.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    eps = SLEPc.EPS().create(MPI.COMM_WORLD)
    eps.setOperators(K, M)
    eps.setProblemType(SLEPc.EPS.ProblemType.GHEP)
    eps.setType(SLEPc.EPS.Type.KRYLOVSCHUR)
    st = eps.getST()
    st.setType(SLEPc.ST.Type.SINVERT)
    st.setShift(shift)
    ksp = st.getKSP()
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType(factor)
    pc.setFactorSolverType("mumps")
    eps.setTarget(shift)
    eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_MAGNITUDE)
    eps.setDimensions(nev=nev)
    eps.setTolerances(tol=1e-10, max_it=500)
    eps.solve()
    nconv = eps.getConverged()
    lam = np.array([eps.getEigenvalue(i).real for i in range(nconv)])
    lam.sort()
    f = np.sign(lam) * np.sqrt(np.abs(lam)) / (2 * np.pi)
    return f, eps


class Timer:
    def __init__(self):
        self.t = {}
        self._t0 = None

    def __call__(self, name):
        now = time.perf_counter()
        self._last = getattr(self, "_last", now)
        self.t[name] = now - self._last
        self._last = now
