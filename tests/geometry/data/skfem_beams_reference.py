"""How the reference eigenvalues of tests/geometry/test_third_party_mesh.py were produced: scikit-fem 12.0.2
(BSD-3, PyPI; https://github.com/kinnala/scikit-fem) solves its own example ex21 (docs/examples/ex21.py) on the
file skfem_beams.msh copied from it: P2 tetrahedra, E = 200 GPa, nu = 0.3, rho = 8050 kg/m^3, the physical surface
"fixed" clamped.  Not part of the test suite (scikit-fem is not a dependency); run it in a virtual environment with
scikit-fem installed:

    /usr/bin/python3 -m venv /tmp/skfem --system-site-packages && /tmp/skfem/bin/pip install scikit-fem==12.0.2
    /tmp/skfem/bin/python tests/geometry/data/skfem_beams_reference.py

Printed on 2026-11-28: 4899 DOFs, 78 clamped; eigenvalues (rad/s)^2 50194.94437033, 251542.76238882,
301210.39794464, 598305.23144171 (scikit-fem's solver_eigen_scipy_sym; scipy's eigsh with tol=0 agrees to 5e-12).
"""
from pathlib import Path

import numpy as np
from skfem import (
    Basis,
    BilinearForm,
    ElementTetP2,
    ElementVector,
    MeshTet,
    asm,
    condense,
    solve,
    solver_eigen_scipy_sym,
)
from skfem.helpers import dot
from skfem.models.elasticity import lame_parameters, linear_elasticity

mesh = MeshTet.load(Path(__file__).parent / "skfem_beams.msh")
basis = Basis(mesh, ElementVector(ElementTetP2()))
K = asm(linear_elasticity(*lame_parameters(200.0e9, 0.3)), basis)


@BilinearForm
def mass(u, v, w):
    return dot(8050.0 * u, v)


clamped = basis.get_dofs("fixed")
eigenvalues, _ = solve(*condense(K, asm(mass, basis), D=clamped), solver=solver_eigen_scipy_sym())
print(basis.N, "DOFs,", len(clamped.flatten()), "clamped")
print("eigenvalues (rad/s)^2:", np.array2string(eigenvalues[:4], precision=8, separator=", "))
print("frequencies (Hz):", np.array2string(np.sqrt(eigenvalues[:4]) / (2 * np.pi), precision=8, separator=", "))
