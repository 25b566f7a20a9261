"""housingfe.solvers.mumps: MUMPS' LDL^T called directly (cffi) and through PETSc give the same inertia, solve
A X = B to round-off (checked against A itself), and the modal solve is the same with either back-end.  `make test`
runs them on one rank and, through the last test, on two (the distributed path)."""
import math

import numpy as np
import pytest

from housingfe.errors import SolverError
from housingfe.solvers import modal, mumps
from tests.two_ranks import rerun_on_two_ranks

BACKENDS = ["direct", "petsc"]


@pytest.fixture(scope="module")
def shifted(coarse_box_model):
    """K - sigma M of the coarse box at 1.5 kHz: indefinite, a dozen negative pivots."""
    K, M = coarse_box_model.K, coarse_box_model.M
    sigma = (2 * math.pi * 1500.0) ** 2
    A = modal._shifted_matrix(K, M, sigma, modal.axpy_structure(K, M))
    yield A
    A.destroy()


def _residual(A, B: np.ndarray, X: np.ndarray) -> float:
    """max_j ||A x_j - b_j|| / ||b_j|| over the ranks."""
    from mpi4py import MPI

    worst = 0.0
    x, y = A.createVecRight(), A.createVecLeft()
    for j in range(B.shape[1]):
        x.getArray()[:] = X[:, j]
        A.mult(x, y)
        r = A.getComm().tompi4py().allreduce(float(np.sum((y.getArray() - B[:, j]) ** 2)), op=MPI.SUM)
        b = A.getComm().tompi4py().allreduce(float(np.sum(B[:, j] ** 2)), op=MPI.SUM)
        worst = max(worst, math.sqrt(r / b))
    return worst


def test_the_direct_binding_is_available_here():
    """The stack (Debian's MUMPS 5.5, cffi) carries it: without it every modal solve would fall back silently."""
    assert mumps.available()


@pytest.mark.parametrize("backend", BACKENDS)
def test_block_solves_satisfy_the_equations(shifted, backend):
    """X = A^-1 B for an indefinite A: ||A X - B|| / ||B|| at round-off, on any number of ranks (the distributed
    solution is moved back to PETSc's rows); a wrong triangle or row map gives O(1)."""
    factor = mumps.ldlt(shifted, backend)
    try:
        factor.factorise(shifted)
        start, end = shifted.getOwnershipRange()
        B = np.random.default_rng(3).standard_normal((shifted.getSize()[0], 5))[start:end]
        X = factor.solve_block(B)
        assert X.shape == B.shape
        assert _residual(shifted, B, X) < 1e-8
        b, x = shifted.createVecRight(), shifted.createVecRight()
        b.getArray()[:] = B[:, 0]
        factor.solve(b, x)      # one right-hand side: MUMPS blocks its solve otherwise, so round-off differs
        assert _residual(shifted, B[:, :1], x.getArray()[:, None]) < 1e-8
    finally:
        factor.destroy()


@pytest.fixture(scope="module")
def saddle_point():
    """[[0, B], [B^T, 0]] of order 3000, B = I + a sparse random part (nonsingular): exactly 1500 negative and
    1500 positive eigenvalues (Sylvester), and a zero diagonal, so MUMPS' analysis (which plans for diagonal
    pivots) underestimates the workspace that the delayed 2 x 2 pivots need: INFOG(1) = -9 at the default
    ICNTL(14) = 20 % through cffi, and through PETSc at 0 %."""
    import scipy.sparse as sp
    from petsc4py import PETSc

    n = 1500
    B = sp.random(n, n, density=4 / n, random_state=1, format="csr") + sp.eye(n)
    A = sp.bmat([[None, B], [B.T, None]], format="csr")
    A.sort_indices()
    M = PETSc.Mat().createAIJ(size=A.shape, csr=(A.indptr, A.indices, A.data), comm=PETSc.COMM_SELF)
    M.assemble()
    yield M
    M.destroy()


@pytest.fixture(scope="module")
def distributed_saddle_point(comm):
    """The saddle point above with its rows split over the ranks of `comm` (PETSc's default layout)."""
    import scipy.sparse as sp
    from petsc4py import PETSc

    n = 1500
    B = sp.random(n, n, density=4 / n, random_state=1, format="csr") + sp.eye(n)
    A = sp.bmat([[None, B], [B.T, None]], format="csr")
    A.sort_indices()
    local = PETSc.Vec().createMPI(2 * n, comm=comm)
    r0, r1 = local.getOwnershipRange()
    local.destroy()
    rows = A[r0:r1]
    M = PETSc.Mat().createAIJ(size=((r1 - r0, 2 * n), (r1 - r0, 2 * n)), csr=(rows.indptr, rows.indices, rows.data),
                              comm=comm)
    M.assemble()
    yield M
    M.destroy()


@pytest.mark.parametrize("backend, first", [("direct", None), ("direct", 0), ("petsc", 0)])
def test_a_workspace_too_small_for_the_delayed_pivots_is_grown_and_the_inertia_is_exact(saddle_point, backend,
                                                                                          first):
    """Seen on 2 ranks of a shifted K - sigma M in CI: MUMPS stopped with INFOG(1) = -9 (its real workspace
    short by 341 342 entries).  Both back-ends now double ICNTL(14) and factorise again; the inertia is the exact
    (1500, 0) and the factor solves; before, the direct one raised, and PETSc's kept the failed factor, whose
    inertia is that of a partial elimination (730 here)."""
    factor = mumps.ldlt(saddle_point, backend, workspace_percent=first)
    try:
        factor.factorise(saddle_point)
        assert factor.inertia() == (1500, 0)
        B = np.random.default_rng(5).standard_normal((3000, 2))
        assert _residual(saddle_point, B, factor.solve_block(B)) < 1e-8
    finally:
        factor.destroy()


def test_both_backends_count_the_same_eigenvalues(coarse_box_model):
    """The inertia of K - sigma M by either back-end equals the number of eigenvalues below sigma found by the
    eigensolver (count_eigenvalues_below's own check on one rank is against dense eigenvalues)."""
    K, M = coarse_box_model.K, coarse_box_model.M
    result = modal.solve_modes(K, M, 2500.0, method="slepc")
    for f_hz in (700.0, 1500.0, 2200.0):
        sigma = (2 * math.pi * f_hz) ** 2
        expected = int(np.sum(result.eigenvalues < sigma))
        assert [modal.count_eigenvalues_below(K, M, sigma, backend=b) for b in BACKENDS] == [expected] * 2


def test_the_modal_solve_is_the_same_with_either_backend(coarse_box_model):
    """The block eigensolver on a direct or a PETSc factorisation: the same eigenvalues to 1e-10, and the kept
    factorisation solves for the sweep's residual vectors either way (K - shift M is nearly singular, shift just
    below the rigid modes: solutions are compared through their residuals, not with each other)."""
    K, M = coarse_box_model.K, coarse_box_model.M
    runs = {b: modal.solve_modes(K, M, 2500.0, method="block", backend=b, keep_solver=True) for b in BACKENDS}
    direct, petsc = runs["direct"], runs["petsc"]
    assert isinstance(direct.shifted_solver.factor, mumps.DirectLDLT)
    assert isinstance(petsc.shifted_solver.factor, mumps.PetscLDLT)
    assert direct.complete and petsc.complete and len(direct.eigenvalues) == len(petsc.eigenvalues)
    scale = direct.eigenvalues.max()
    np.testing.assert_allclose(direct.eigenvalues, petsc.eigenvalues, rtol=0, atol=1e-10 * scale)
    for run in runs.values():     # the kept factorisation solves (K - shift M) x = b
        kept = run.shifted_solver
        A = modal._shifted_matrix(K, M, kept.shift, modal.axpy_structure(K, M))
        b, x = K.createVecRight(), K.createVecRight()
        start, end = b.getOwnershipRange()
        b.getArray()[:] = np.random.default_rng(5).standard_normal(K.getSize()[0])[start:end]
        kept.solve(b, x)
        assert _residual(A, b.getArray()[:, None], x.getArray()[:, None]) < 1e-8
        A.destroy()
        run.release_solver()


def test_a_matrix_of_another_pattern_is_refused(shifted):
    from petsc4py import PETSc

    factor = mumps.ldlt(shifted, "direct")
    other = shifted.duplicate(copy=True)
    other.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
    start, end = other.getOwnershipRange()
    n = other.getSize()[0]
    far = (start + n // 2) % n
    other.setValue(start, far, 0.0, addv=True)
    other.setValue(far, start, 0.0, addv=True)
    other.assemble()
    try:
        assert other.getInfo()["nz_used"] > shifted.getInfo()["nz_used"]
        with pytest.raises(SolverError, match="sparsity pattern"):
            factor.factorise(other)
    finally:
        factor.destroy()
        other.destroy()


def test_unknown_backend_is_named(shifted):
    with pytest.raises(ValueError, match="unknown MUMPS back-end 'umfpack'"):
        mumps.ldlt(shifted, "umfpack")


def test_auto_calls_mumps_directly_only_in_parallel(shifted):
    """The direct binding pays where PETSc's multi-right-hand-side solve scatters (several ranks); on one rank
    PETSc's interface solves in place."""
    factor = mumps.ldlt(shifted)
    try:
        assert isinstance(factor, mumps.DirectLDLT) == (shifted.getComm().getSize() > 1)
    finally:
        factor.destroy()


def _singular(n: int = 40):
    """diag(1, ..., 1, 0): MUMPS reports INFOG(1) = -10 (null-pivot detection is off by default)."""
    from petsc4py import PETSc

    S = PETSc.Mat().createAIJ(size=(n, n), nnz=1, comm=PETSc.COMM_SELF)
    for i in range(n):
        S.setValue(i, i, 0.0 if i == n - 1 else 1.0)
    S.assemble()
    return S


def _solves(ksp, A, seed: int) -> float:
    """||A x - b|| / ||b|| of ksp's solution x for a random b (A's row layout, any number of ranks)."""
    b, x = A.createVecs()
    r0, r1 = A.getOwnershipRange()
    b.getArray()[:] = np.random.default_rng(seed).standard_normal(A.getSize()[0])[r0:r1]
    ksp.solve(b, x)
    return _residual(A, b.getArray()[:, None], x.getArray()[:, None])


def test_set_up_factor_grows_a_short_workspace_and_raises_on_a_singular_matrix(distributed_saddle_point, comm):
    """The one way the package factorises with MUMPS through PETSc: at ICNTL(14) = 0 the saddle point's factor
    fails with INFOG(1) = -9 on one rank (which PETSc 3.18 does not raise); the helper builds a new factor with
    40 % and it solves to round-off (on two ranks too, whether or not they run short); a singular matrix raises
    SingularMatrix (a SolverError) instead of leaving a failed factor whose solve is garbage."""
    A = distributed_saddle_point
    asked = []

    def make_ksp(percent):
        asked.append(percent)
        ksp = mumps.mumps_cholesky(A, "test_grow_")
        mumps.set_workspace(ksp, 0 if percent is None else percent)
        return ksp

    ksp = mumps.set_up_factor(make_ksp)
    try:
        if comm.size == 1:
            assert asked == [None, 40]
        assert mumps.factor_status(ksp)[0] == 0
        assert _solves(ksp, A, 7) < 1e-8
    finally:
        ksp.destroy()
    S = _singular()
    with pytest.raises(mumps.SingularMatrix, match=r"singular matrix \(MUMPS INFOG\(1\) = -10"):
        mumps.set_up_factor(lambda percent: mumps.mumps_cholesky(S, "test_singular_"))
    S.destroy()


def test_the_harmonic_solvers_factor_is_checked_and_grown(distributed_saddle_point, comm):
    """harmonic._factor (the residual vectors' K - shift M and the 2x2 real block system per line, symmetric
    indefinite): a short workspace is grown (LDL^T and LU) and solves to round-off; a singular system raises."""
    from housingfe.solvers import harmonic

    A = distributed_saddle_point
    for lu in (False, True):
        ksp = harmonic._factor(A, "test_harmonic_", lu=lu, workspace_percent=0)
        try:
            assert ksp.getPC().getFactorSolverType() == "mumps"
            assert ksp.getPC().getFactorMatrix().getMumpsIcntl(14) >= (40 if comm.size == 1 else 0)
            assert _solves(ksp, A, 8) < 1e-8
        finally:
            ksp.destroy()
    S = _singular()
    with pytest.raises(SolverError, match="singular"):
        harmonic._factor(S, "direct_")
    S.destroy()


def test_slepc_shift_invert_regrows_a_short_workspace(saddle_point):
    """The modal "slepc" method's shift-and-invert factor of K - 0 M with K the saddle point (M = I): with
    -st_mat_mumps_icntl_14 0 it fails with INFOG(1) = -9 (SLEPc then raised PETSc's error); now a new factor with
    more workspace is made and the eigenvalues nearest 0 are +-(the smallest singular values of B), exactly."""
    import scipy.sparse as sp
    from petsc4py import PETSc

    identity = sp.eye(3000, format="csr")
    M = PETSc.Mat().createAIJ(size=(3000, 3000), csr=(identity.indptr, identity.indices, identity.data),
                              comm=PETSc.COMM_SELF)
    M.assemble()
    ia, ja, va = saddle_point.getValuesCSR()
    B = sp.csr_matrix((va, ja, ia), shape=(3000, 3000))[:1500, 1500:].toarray()
    sv = np.sort(np.linalg.svd(B, compute_uv=False))[:2]
    options = PETSc.Options()
    options["st_mat_mumps_icntl_14"] = 0
    try:
        pairs = modal._krylov_schur(saddle_point, M, 0.0, 4, None, 1e-10, False, np.inf,
                                    structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
    finally:
        options.delValue("st_mat_mumps_icntl_14")
        M.destroy()
    np.testing.assert_allclose([p[0] for p in pairs], [-sv[1], -sv[0], sv[0], sv[1]], rtol=1e-8)


@pytest.mark.mpi
def test_the_tests_above_pass_on_two_ranks(comm):
    """The distributed path (MUMPS' solution rows moved back to PETSc's, the collective pattern check) runs in
    `make test` too: this file's other tests under `mpirun -n 2`."""
    rerun_on_two_ranks(__file__, comm, timeout=600)

