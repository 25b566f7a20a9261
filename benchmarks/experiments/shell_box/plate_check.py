"""Sanity check: hard simply supported square plate (Navier solution exact for Mindlin), in the xy plane
and in the xz plane (tests the frame), thin (t/a = 0.01) and thick (t/a = 0.1).

Exact Mindlin (kappa_s = 5/6, rotary inertia) for mode (m, n):
  (kGt k^2 - rho t w^2)(D k^2 + kGt - rho t^3/12 w^2) - (kGt)^2 k^2 = 0,  k^2 = (m^2 + n^2) pi^2 / a^2
Kirchhoff: f11 = (pi/2) (2/a^2) sqrt(D / (rho t)).
"""
import os
import sys

import numpy as np
from dolfinx import fem
from dolfinx import mesh as dmesh

sys.path.insert(0, os.path.dirname(__file__))
from shell import assemble, cell_data, eigensolve, make_quad_mesh, shell_forms  # noqa: E402

E, nu, rho = 210e9, 0.3, 7850.0
a = 1.0


def mindlin_exact(m, n, t):
    k2 = (m * m + n * n) * np.pi ** 2 / a ** 2
    G = E / 2 / (1 + nu)
    kGt = 5 / 6 * G * t
    D = E * t ** 3 / (12 * (1 - nu ** 2))
    I = rho * t ** 3 / 12
    # quadratic in W = w^2: (kGt k2 - rho t W)(D k2 + kGt - I W) - kGt^2 k2 = 0
    A = rho * t * I
    B = -(rho * t * (D * k2 + kGt) + I * kGt * k2)
    C = kGt * k2 * (D * k2 + kGt) - kGt ** 2 * k2
    W = (-B - np.sqrt(B * B - 4 * A * C)) / (2 * A)
    return np.sqrt(W) / (2 * np.pi)


def kirchhoff(m, n, t):
    D = E * t ** 3 / (12 * (1 - nu ** 2))
    return np.pi / 2 * (m * m + n * n) / a ** 2 * np.sqrt(D / (rho * t))


def plate(nel, t, plane, degree, shear_qdeg=None):
    s = np.linspace(0, a, nel + 1)
    I, J = np.meshgrid(np.arange(nel + 1), np.arange(nel + 1), indexing="ij")
    S1, S2 = s[I.ravel()], s[J.ravel()]
    zero = np.zeros_like(S1)
    pts = np.c_[S1, S2, zero] if plane == "xy" else np.c_[S1, zero, S2]
    idx = lambda i, j: i * (nel + 1) + j  # noqa: E731
    quads = np.array([[idx(i, j), idx(i + 1, j), idx(i, j + 1), idx(i + 1, j + 1)]
                      for i in range(nel) for j in range(nel)])
    msh = make_quad_mesh(pts, quads)
    e, th = cell_data(msh, lambda c, n: t)
    V, af, mf = shell_forms(msh, e, th, E, nu, rho, degree=degree, shear_qdeg=shear_qdeg)
    # hard SS: all translations 0, rotation about the in-plane edge normal 0
    c2 = 1 if plane == "xy" else 2  # second in-plane axis
    bcs = []
    fdim = 1
    msh.topology.create_connectivity(1, 2)
    for axis in (0, c2):
        facets = dmesh.locate_entities_boundary(
            msh, fdim, lambda x, ax=axis: np.isclose(x[ax], 0) | np.isclose(x[ax], a))
        for comp in (0, 1, 2, 3 + axis):
            Vc, _ = V.sub(comp).collapse()
            dofs = fem.locate_dofs_topological(V.sub(comp), fdim, facets)
            bcs.append(fem.dirichletbc(0.0, dofs, V.sub(comp)))
    K, M = assemble(V, af, mf, bcs)
    f, _ = eigensolve(K, M, nev=12, shift=1.0)
    f = f[f > 1e-3]
    # drop spurious unit eigenvalues from Dirichlet rows (K diag 1, M diag 0 -> infinite): not present
    return f, V.dofmap.index_map.size_global * 6


if __name__ == "__main__":
    for t in (0.01, 0.1):
        ex = sorted([(mindlin_exact(m, n, t), (m, n)) for m in range(1, 4) for n in range(1, 4)])
        print(f"t/a = {t}: Kirchhoff f11 = {kirchhoff(1, 1, t):.4f} Hz, Mindlin exact f11 = {ex[0][0]:.4f}, "
              f"f12 = {ex[1][0]:.4f}, f22 = {ex[3][0]:.4f}")
        for plane in ("xy", "xz"):
            for degree, nel in ((2, 8), (2, 16), (2, 32)):
                f, ndof = plate(nel, t, plane, degree)
                # flexural modes only: compare the first 4 (11, 12, 21, 22)
                ref = np.array([ex[0][0], ex[1][0], ex[2][0], ex[3][0]])
                err = f[:4] / ref - 1
                print(f"  {plane} Q{degree} {nel}x{nel} dofs={ndof}: f = {np.round(f[:4], 3)}  "
                      f"err = {np.round(100 * err, 4)} %")
