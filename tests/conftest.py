"""Shared fixtures: small FE models built once per session."""
import os

import pytest

os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
# under pytest-xdist an mpirun test shares the cores with the other workers: idle ranks yield instead of spinning
os.environ.setdefault("OMPI_MCA_mpi_yield_when_idle", "1")


@pytest.fixture(scope="session")
def comm():
    from mpi4py import MPI

    return MPI.COMM_WORLD


def load_scene(name, *overrides):
    from housingfe.scene import load_housing_scene

    return load_housing_scene(name, list(overrides))[0]


@pytest.fixture(scope="session")
def coarse_box_model(comm):
    """The box-free scene on a coarse hex mesh (fast, still 6 rigid + a dozen elastic modes to 2.5 kHz)."""
    from housingfe.scene import build_model_from_scene

    return build_model_from_scene(load_scene("box-free", "mesh.degree=2", "mesh.grading=1",
                                                 "mesh.size=0.04", "analysis.modal.f_max=2500.0"), comm)


def mumps_solve(A, b, x=None, factor: str = "lu"):
    """x of A x = b by a MUMPS factorisation on A's communicator (`factor` "lu", or "cholesky": MUMPS LDL^T of a
    symmetric A), for the tests' static reference solves; x: the vector to fill (default a new one)."""
    from petsc4py import PETSc

    ksp = PETSc.KSP().create(A.getComm())
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.getPC().setType(factor)
    ksp.getPC().setFactorSolverType("mumps")
    if x is None:
        x = A.createVecRight()
    ksp.solve(b, x)
    return x
