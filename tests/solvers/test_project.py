"""housingfe.solvers.harmonic.project: the Galerkin projection B^T A B of PETSc matrices on a list of vectors,
against the dense product of the same numbers, on one and two ranks (the matrix-matrix form gathers the rows of
the small result that each rank holds)."""
import numpy as np
import pytest
from petsc4py import PETSc

from housingfe.solvers import harmonic
from tests.two_ranks import rerun_on_two_ranks

N, VECTORS = 600, 9


def _matrix(comm, seed):
    """A non-symmetric tridiagonal N x N (AIJ, distributed) and its dense copy."""
    rng = np.random.default_rng(seed)
    dense = np.diag(2.0 + rng.random(N)) + np.diag(-rng.random(N - 1), 1) + np.diag(-rng.random(N - 1), -1)
    A = PETSc.Mat().createAIJ((N, N), nnz=3, comm=comm)
    A.setUp()
    r0, r1 = A.getOwnershipRange()
    for i in range(r0, r1):
        for j in range(max(0, i - 1), min(N, i + 2)):
            A.setValue(i, j, dense[i, j])
    A.assemble()
    return A, dense


def test_projection_equals_the_dense_product(comm):
    K, Kd = _matrix(comm, 1)
    M, Md = _matrix(comm, 2)
    C, Cd = _matrix(comm, 3)
    B = np.random.default_rng(4).normal(size=(N, VECTORS))
    r0, r1 = K.getOwnershipRange()
    vectors = []
    for j in range(VECTORS):
        v = K.createVecRight()
        v.setArray(B[r0:r1, j])
        vectors.append(v)
    Kr, Mr, Cr = harmonic.project(vectors, K, M, C)
    for reduced, dense in ((Kr, Kd), (Mr, Md), (Cr, Cd)):
        assert reduced.shape == (VECTORS, VECTORS)
        np.testing.assert_allclose(reduced, B.T @ dense @ B, rtol=1e-12, atol=1e-12 * np.abs(B.T @ dense @ B).max())
    assert not np.any(harmonic.project(vectors, K, M)[2])          # no C: a zero Cr


@pytest.mark.mpi
def test_the_projection_passes_on_two_ranks(comm):
    rerun_on_two_ranks(__file__, comm, timeout=300)
