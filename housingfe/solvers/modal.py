"""All eigenmodes below f_max of K x = lambda M x, with a completeness proof.

Completeness: Sylvester's law of inertia — the number of negative pivots of the LDL^T factorisation of
K - sigma_max M equals the number of eigenvalues below sigma_max = (2 pi f_max)^2.  If the eigensolver returns
fewer, the result is marked incomplete and `require_complete` raises.

Method: shift-and-invert with MUMPS.  From BLOCK_MIN_DOFS DOFs on, the block Krylov–Schur of
housingfe.solvers.block_eigen runs on that same LDL^T of K - sigma_max M: the wanted eigenvalues are exactly its
negative theta = 1 / (lambda - sigma_max), so one factorisation serves the count and the eigensolve, and the
eigenvalues are the Rayleigh quotients of the vectors.  Otherwise (a caller's shift or nev, a kept solver for
residual vectors, small models, SLEPc's Krylov–Schur) the operator is factorised again at a shift just below zero,
positive definite even for free-free structures.  A free structure's rigid-body motions are known exactly
(null_space, known_null_space): the block method returns them as the zero modes and seeks only the others.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from petsc4py import PETSc
from slepc4py import SLEPc

from housingfe.errors import SolverError
from housingfe.solvers import mumps

# Rigid-body (mechanism) modes are classified against the scale of the matrices, not against f_max: the
# computed zero eigenvalues are round-off, |lambda| ~ 1e-18..1e-16 of lambda_scale = max_i K_ii / M_ii (an
# estimate of the highest eigenvalue of the mesh), on the plate, box, cube and coupled models measured, whatever
# f_max, units or size.  The lowest elastic eigenvalue falls with the walls' slenderness, about as (t/L)^4: a
# free plate of t/L = 1/1000 has it at 2e-13..1e-12 of lambda_scale (Q3..S2R, one layer), one of t/L = 1/2000 at
# 8e-14 (bench stability), so the line between zero and elastic sits at 1e-15 (it was 1e-13, which counted that
# plate's first elastic mode as a rigid one).
RIGID_EIGENVALUE_RATIO = 1e-15
# A null-space candidate (a free structure's exact rigid motions, null_space_basis) is accepted when
# ||K r|| <= NULL_VECTOR_RATIO lambda_scale ||M r||: the box's are at ~1e-17.
NULL_VECTOR_RATIO = 1e-13
# The inertia count and the eigensolve both work on K - sigma M in double precision.  When (2 pi f_max)^2 lies below
# PRECISION_FLOOR of lambda_scale the eigenvalues of interest are round-off against the mesh's highest one (free
# plates, one element layer, elements 625 thicknesses wide, t/L = 1/10 000: sigma_max at 2.5e-15..4.4e-15 of it,
# with the floor switched off the solve finds 11 near-zero modes instead of 6) and solve_modes refuses.  Above the
# floor a free structure's known rigid motions must still all be counted (solve_modes checks it).  (S2R at t/L =
# 1/3333, 3.5e-13, once counted 0 of 16: that was a MUMPS factor short of workspace, INFOG(1) = -9, kept silently by
# PETSc; grown since 2026-11-26, housingfe.solvers.mumps, it solves within 1 % of Kirchhoff.)  A cantilever's
# static-range FRF asks for f_max at 1.5e-13 (no mode below it) and gets its exact count of 0; Q2 at t/L = 1/5000
# (4e-14) counts and solves right.
PRECISION_FLOOR = 1e-14
# Kept for small dense models that have no matrix scale at hand (housingfe.drivetrain.interior): a frequency ratio.
RIGID_FREQUENCY_RATIO = 1e-4
# From this many DOFs on, method="auto" uses the block Krylov–Schur (housingfe.solvers.block_eigen): below,
# MUMPS' single solves are cheap and SLEPc's Krylov–Schur needs fewer of them (bench modal).
BLOCK_MIN_DOFS = 5000


@dataclass
class ModalResult:
    """Eigenpairs below f_max.

    eigenvalues: lambda = omega^2 (rad^2/s^2), ascending, rigid-body modes included.
    vectors: mass-normalised eigenvectors (PETSc Vecs, x^T M x = 1).
    expected_count: eigenvalues below (2 pi f_max)^2 by the inertia count.
    residuals: ||K x - lambda M x|| / ||K x|| (for rigid modes: / (sigma_max ||M x||)).
    eigenvalue_scale: max_i K_ii / M_ii (rad^2/s^2), the scale against which rigid modes are classified.
    eigensolver: the method that produced the pairs ("block" or "slepc", see solve_modes).
    shifted_solver: with solve_modes(keep_solver=True), the eigensolve's factorisation of K - shift M (else
    None), for the residual vectors of a modal sweep; release_solver() frees it.
    """

    eigenvalues: np.ndarray
    vectors: list
    expected_count: int
    residuals: np.ndarray
    f_max: float
    timings: dict = field(default_factory=dict)
    eigenvalue_scale: float | None = None
    eigensolver: str = "slepc"
    shifted_solver: ShiftedSolver | None = None

    @property
    def frequencies_hz(self) -> np.ndarray:
        """Eigenfrequencies (Hz); tiny negative round-off of rigid modes is shown as 0."""
        return np.sqrt(np.clip(self.eigenvalues, 0.0, None)) / (2 * math.pi)

    @property
    def rigid_count(self) -> int:
        """Number of rigid-body (mechanism) modes: |lambda| < RIGID_EIGENVALUE_RATIO * eigenvalue_scale, a
        criterion independent of f_max (without a scale, the older frequency ratio to f_max)."""
        if self.eigenvalue_scale is None:
            return int(np.sum(self.frequencies_hz < RIGID_FREQUENCY_RATIO * self.f_max))
        return int(np.sum(np.abs(self.eigenvalues) < RIGID_EIGENVALUE_RATIO * self.eigenvalue_scale))

    @property
    def complete(self) -> bool:
        """True if every eigenvalue below f_max (by the inertia count) was returned."""
        return len(self.eigenvalues) == self.expected_count

    def release_solver(self) -> None:
        """Free the kept factorisation (a no-op without one)."""
        if self.shifted_solver is not None:
            self.shifted_solver.destroy()
            self.shifted_solver = None


@dataclass
class ShiftedSolver:
    """The eigensolve's MUMPS factorisation of K - shift M (shift in rad^2/s^2), kept for later solves with the
    same matrices: the residual vectors of a modal sweep need exactly that factorisation, and a second one costs
    as much as the first (10 s of a 13 s sweep at 309 k DOFs).  It serves only the K and M it was built from
    (matches())."""

    factor: object          # housingfe.solvers.mumps.DirectLDLT or PetscLDLT, factorised at the shift
    matrix: PETSc.Mat
    shift: float
    k_handle: int
    m_handle: int

    def matches(self, K: PETSc.Mat, M: PETSc.Mat) -> bool:
        """True for the very matrices (PETSc objects) of the eigensolve."""
        return K.handle == self.k_handle and M.handle == self.m_handle

    def solve(self, b: PETSc.Vec, x: PETSc.Vec) -> None:
        """x = (K - shift M)^-1 b."""
        self.factor.solve(b, x)

    def destroy(self) -> None:
        self.factor.destroy()
        self.matrix.destroy()


def axpy_structure(Y: PETSc.Mat, X: PETSc.Mat):
    """PETSc's fast SAME_NONZERO_PATTERN when Y and X share their sparsity pattern on every rank (FE K and M,
    a coupled K_c and M_c), DIFFERENT_NONZERO_PATTERN otherwise (e.g. a stand-in stiffness built separately):
    SAME on different patterns would silently give a wrong matrix."""
    same = int(_same_pattern(Y, X))
    same = Y.getComm().tompi4py().allreduce(same, op=_mpi_min())
    return PETSc.Mat.Structure.SAME_NONZERO_PATTERN if same else PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN


def _same_pattern(Y: PETSc.Mat, X: PETSc.Mat) -> bool:
    """Equal local sparsity patterns, by the row/column indices alone (MatGetRowIJ: no copy of the values;
    0.015 vs 0.77 s at 13 M nonzeros on one rank).  Parallel AIJ answers it too (local rows, global columns),
    cheaper than the CSR arrays with their values; types without it compare their CSR arrays."""
    if Y.getType() == X.getType():
        try:
            ia, ja = Y.getRowIJ()
            ib, jb = X.getRowIJ()
        except PETSc.Error:
            ia = None
        if ia is not None and ib is not None:
            return bool(np.array_equal(ia, ib) and np.array_equal(ja, jb))
    ia, ja, _ = Y.getValuesCSR()
    ib, jb, _ = X.getValuesCSR()
    return bool(np.array_equal(ia, ib) and np.array_equal(ja, jb))


def _mpi_min():
    from mpi4py import MPI

    return MPI.MIN


def count_eigenvalues_below(K: PETSc.Mat, M: PETSc.Mat, sigma: float, backend: str = "auto") -> int:
    """Number of eigenvalues of K x = lambda M x below sigma (rad^2/s^2), by the inertia of K - sigma M."""
    A = _shifted_matrix(K, M, sigma, axpy_structure(K, M))
    factor = mumps.ldlt(A, backend, count_only=True)
    try:
        return _count_below(factor, A)
    finally:
        factor.destroy()
        A.destroy()


def _shifted_matrix(K: PETSc.Mat, M: PETSc.Mat, sigma: float, structure) -> PETSc.Mat:
    """A new K - sigma M, marked symmetric.  structure: axpy_structure(K, M)."""
    A = K.copy()
    A.axpy(-sigma, M, structure=structure)
    A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    return A


def _count_below(factor, A: PETSc.Mat) -> int:
    """Negative pivots of the LDL^T of A = K - sigma M (factor: housingfe.solvers.mumps, analysed on A)."""
    factor.factorise(A)
    negative, null = factor.inertia()
    if null:
        raise SolverError("K - sigma M is singular at f_max (an eigenvalue sits exactly at f_max); "
                          "move f_max slightly")
    return negative


def solve_modes(K: PETSc.Mat, M: PETSc.Mat, f_max: float, *, nev: int | None = None,
                tol: float = 1e-10, require_complete: bool = True, shift_hz: float | None = None,
                ncv: int | None = None, purify: bool = False, method: str = "auto",
                keep_solver: bool = False, backend: str = "auto",
                null_space: list | None = None) -> ModalResult:
    """All eigenpairs with frequency below f_max (Hz).

    nev: number of eigenpairs to ask for (default: the inertia count); asking for fewer makes the
    result incomplete, which raises SolverError when require_complete is True.
    shift_hz: shift of the spectral transformation (default: -1 % of f_max, i.e. below the rigid modes).
    method: "block" (housingfe.solvers.block_eigen: block Krylov–Schur, several right-hand sides per MUMPS
    solve), "slepc" (SLEPc's Krylov–Schur) or "auto": block from BLOCK_MIN_DOFS DOFs on (where a block of
    solves is cheaper than single ones), SLEPc below and whenever the block method fails.
    ncv, purify: SLEPc only.  purify: SLEPc's eigenvector purification costs one extra solve per mode (2.4 s
    of a 10 s box run); constrained rows are decoupled (1 on K's, 0 on M's diagonal), so it is off and
    residuals are reported.
    keep_solver: keep the block method's factorisation of K - shift M in result.shifted_solver (the SLEPc path
    keeps none); the caller frees it with result.release_solver().
    backend: how the inertia count and the block method call MUMPS (housingfe.solvers.mumps.ldlt): "auto",
    "direct" or "petsc".
    null_space: PETSc Vecs known to lie in K's null space, e.g. a free structure's six rigid-body motions
    (Structure.rigid_body_vectors()).  The block method returns them (M-orthonormalised) as the zero modes and
    seeks only the other eigenpairs, in their M-orthogonal complement (S2R box: 27 -> 20 block solves, with
    default_max_basis); vectors that are not null to round-off (null_space_basis) are not used.
    """
    if method not in EIGENSOLVERS and method != "auto":
        raise ValueError(f"unknown eigensolver {method!r}: choose from auto, {', '.join(EIGENSOLVERS)}")
    sigma_max = (2 * math.pi * f_max) ** 2
    scale = eigenvalue_scale(K, M)
    if sigma_max < PRECISION_FLOOR * scale:
        raise SolverError(f"f_max = {f_max:g} Hz is at {sigma_max / scale:.1e} of the model's highest eigenvalue: "
                          "below what double precision resolves (the inertia count and the zero-mode test become "
                          "round-off); walls far thinner than the elements are wide cause this: use elements "
                          "closer to the wall thickness in size, or a higher f_max")
    chosen = method if method != "auto" else ("block" if K.getSize()[0] >= BLOCK_MIN_DOFS else "slepc")
    first_choice = chosen
    t0 = time.perf_counter()
    # one pattern comparison for every K - s M below (each one copied the CSR arrays on 2 ranks: 0.2-1.4 s
    # at 309 k DOFs)
    structure = axpy_structure(K, M)
    A = _shifted_matrix(K, M, sigma_max, structure)
    # the block method: one analysis for the count and the factorisation at the shift (0.2-0.3 s at 40 k DOFs
    # on one rank; on two at 309 k DOFs, count and shift factorisation 14-16 s either way, but the factorisation
    # at the shift 5.0-5.3 s instead of 7.4-8.1 s); a count alone discards its factors as it goes
    reuse_analysis = chosen == "block"
    factor = mumps.ldlt(A, backend, count_only=not reuse_analysis)
    null = null_space_basis(K, M, null_space) if null_space else None
    try:
        expected = _count_below(factor, A)
        if null is not None and expected < null.shape[1]:
            # the known zero eigenvalues all lie below sigma_max > 0: a count below their number is round-off
            raise SolverError(f"the inertia count at f_max = {f_max:g} Hz found {expected} eigenvalues below it, fewer "
                              f"than the {null.shape[1]} rigid-body modes the model has: K - sigma M is beyond what "
                              "double precision resolves (walls far thinner than the elements are wide): use "
                              "elements closer to the wall thickness in size, or a higher f_max")
    except BaseException:
        factor.destroy()
        A.destroy()
        raise
    if not reuse_analysis:
        factor.destroy()
        factor = None
    t_inertia = time.perf_counter() - t0

    shift = -((2 * math.pi * (shift_hz if shift_hz is not None else 0.01 * f_max)) ** 2)
    requested = expected if nev is None else nev
    # every eigenpair below f_max from the count's own factorisation of K - sigma_max M: the wanted are exactly
    # its negative theta = 1 / (lambda - sigma_max), the unwanted all positive (S2R box, 40 k DOFs: 23 block
    # solves against 24 at a shift below zero, and no second factorisation).  A kept solver is wanted at the
    # shift below zero (the static residual vectors of the sweeps), and a shift or nev of the caller's is honoured.
    one_factor = reuse_analysis and nev is None and shift_hz is None and not keep_solver
    t0 = time.perf_counter()
    pairs = [] if requested == 0 else None
    phases, kept = {}, []
    if chosen == "block" and pairs is None:
        try:
            if one_factor:
                shift, phases["factor_s"] = sigma_max, 0.0
            else:
                factor, A = _factorise_at(K, M, shift, factor, A, structure, backend, phases)
            known = [] if null is None else _zero_pairs(M, null, requested)
            phases["deflated"] = len(known)
            pairs = known + (_block_krylov_schur(factor, M, shift, requested - len(known), tol, sigma_max, phases,
                                                 side="below" if one_factor else "above", deflate=null)
                             if requested > len(known) else [])
        except SolverError:
            if method == "block":
                _destroy(factor, A)
                raise
        if method == "auto" and pairs is not None and len(pairs) < requested:
            pairs = None   # an eigenvalue missed: SLEPc below, with its retry for close pairs at f_max
    if keep_solver and pairs is not None and chosen == "block" and requested:
        kept.append(ShiftedSolver(factor, A, shift, K.handle, M.handle))
    else:
        _destroy(factor, A)
    if pairs is None:
        chosen = "slepc"
        phases.pop("deflated", None)   # SLEPc finds the rigid modes itself
        pairs = _krylov_schur(K, M, shift, requested, ncv, tol, purify, sigma_max, structure=structure)
    if nev is None and len(pairs) < requested:
        # SLEPc's nev closest to the shift can miss one of a close pair near f_max (seen on the coupled test
        # gearbox: 62 of 63): ask again for a few more; the extras above f_max are dropped
        pairs = _krylov_schur(K, M, shift, requested + max(2, requested // 20), ncv, tol, purify, sigma_max,
                              keep=requested, structure=structure)
    if nev is None and len(pairs) < requested and method == "auto" and first_choice == "slepc":
        # a single-vector Krylov method finds the members of a multiplet one after another and can miss one even
        # with more vectors asked for (free cube, 1 029 DOFs: a triple eigenvalue at 0.99 f_max, 57 of 58 after the
        # retry); a block of vectors spans a multiplet at once (58 of 58): the block method decides
        return solve_modes(K, M, f_max, tol=tol, require_complete=require_complete, method="block",
                           keep_solver=keep_solver, backend=backend, null_space=null_space)
    t_solve = time.perf_counter() - t0
    values = np.array([p[0] for p in pairs])
    vectors = [p[1] for p in pairs]
    # lambda = sigma_max + 1/theta loses relative accuracy by sigma_max / lambda on the lowest modes (1.5e-8 on the
    # thin FV12 plate): there the Rayleigh quotients x^T K x / x^T M x, exact to second order, replace them
    values, residuals = _normalise_and_residuals(K, M, values, vectors, sigma_max,
                                                 rayleigh=chosen == "block" and one_factor)
    result = ModalResult(values, vectors, expected, residuals, f_max,
                         {"inertia_s": t_inertia, "eigensolve_s": t_solve,
                          **{f"eigensolve_{k}": v for k, v in phases.items()}}, scale,
                         eigensolver=chosen, shifted_solver=kept[0] if kept else None)
    if require_complete and not result.complete:
        result.release_solver()
        raise SolverError(f"incomplete eigen-solution: {len(values)} eigenvalues returned, "
                          f"{expected} lie below f_max = {f_max:g} Hz (inertia count)")
    return result


def _factorise_at(K, M, shift: float, factor, A: PETSc.Mat, structure, backend: str, timings: dict):
    """(factor, A) with A = K - shift M factorised.  When K and M share their pattern, A (K - sigma M) is
    overwritten in place (its memory is already touched) and the count's analysis, if given as `factor`, is
    reused; K - shift M is written bitwise as K.copy() - shift M (moving A by (sigma - shift) M instead perturbs
    K by round-off, which on a thin plate moves eigenvalues by 3e-8).  Otherwise A's pattern is K's and M's
    union: a new matrix and analysis."""
    t0 = time.perf_counter()
    if structure == PETSc.Mat.Structure.SAME_NONZERO_PATTERN:
        K.copy(A, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        A.axpy(-shift, M, structure=structure)
    else:
        _destroy(factor, A)
        A = _shifted_matrix(K, M, shift, structure)
        factor = None
    if factor is None:
        factor = mumps.ldlt(A, backend)
    factor.factorise(A)
    timings["factor_s"] = time.perf_counter() - t0
    return factor, A


def _destroy(factor, A: PETSc.Mat) -> None:
    if factor is not None:
        factor.destroy()
    A.destroy()


def null_space_basis(K: PETSc.Mat, M: PETSc.Mat, vectors: list) -> np.ndarray | None:
    """The vectors (PETSc Vecs in K's layout) as an M-orthonormal basis (local rows x r), or None when one of
    them is not null to round-off: ||K r|| > NULL_VECTOR_RATIO eigenvalue_scale ||M r|| (the box's rigid motions:
    ~1e-17) or they are linearly dependent."""
    X = _dense_columns(K, vectors)
    KX, MX = K.matMult(X), M.matMult(X)
    x, kx, mx = X.getDenseArray().copy(), KX.getDenseArray(), MX.getDenseArray()
    comm = K.getComm().tompi4py()
    norms = comm.allreduce(np.stack([np.einsum("ij,ij->j", kx, kx), np.einsum("ij,ij->j", mx, mx)]))
    gram = comm.allreduce(x.T @ mx)
    for A in (X, KX, MX):
        A.destroy()
    if np.any(np.sqrt(norms[0]) > NULL_VECTOR_RATIO * eigenvalue_scale(K, M) * np.sqrt(norms[1])):
        return None
    try:
        L = np.linalg.cholesky((gram + gram.T) / 2)
    except np.linalg.LinAlgError:
        return None
    return x @ np.linalg.inv(L.T)


def _zero_pairs(M: PETSc.Mat, basis: np.ndarray, nev: int) -> list:
    """(0, vector) pairs of the first min(nev, r) columns of an M-orthonormal null-space basis."""
    pairs = []
    for j in range(min(nev, basis.shape[1])):
        x = M.createVecRight()
        x.getArray()[:] = basis[:, j]
        pairs.append((0.0, x))
    return pairs


def _block_krylov_schur(factor, M, shift: float, nev: int, tol: float, sigma_max: float,
                        timings: dict | None = None, side: str = "above", deflate: np.ndarray | None = None) -> list:
    """(eigenvalue, vector) pairs below sigma_max, ascending, by housingfe.solvers.block_eigen with `factor`, an
    LDL^T of K - shift M (housingfe.solvers.mumps), the nev closest to the shift on `side` of it.  Fewer than nev
    pairs when an eigenvalue was missed (the caller falls back).  `timings` (if given) receives the phases:
    solve_s, mass_s, orthogonalise_s, restart_s, block_solves, restarts."""
    from housingfe.solvers.block_eigen import block_krylov_schur

    result = block_krylov_schur(factor, M, shift, nev, side=side, tol=tol, deflate=deflate)
    if timings is not None:
        timings.update(**result.timings, block_solves=result.block_solves, restarts=result.restarts)
    pairs = []
    for j, lam in enumerate(result.eigenvalues):
        if lam < sigma_max:
            x = M.createVecRight()
            x.getArray()[:] = result.vectors[:, j]
            pairs.append((float(lam), x))
    return pairs


def _krylov_schur(K, M, shift: float, nev: int, ncv, tol: float, purify: bool, sigma_max: float,
                  keep: int | None = None, structure=None) -> list:
    """(eigenvalue, vector) pairs below sigma_max (at most `keep`, default nev), ascending: Krylov-Schur with
    shift-and-invert (MUMPS Cholesky of K - shift M) about `shift` (rad^2/s^2).

    Every Krylov step multiplies by M three times (the operator (K - shift M)^-1 M and the M-inner products of
    the orthogonalisation): M goes in as a symmetric block matrix (SBAIJ, half the memory traffic of AIJ: 5.7
    vs 12.5 ms per product at 44 k DOFs), and K - shift M, assembled here in AIJ, is the matrix MUMPS factors
    (the spectral transformation's shell operator is never applied: the factorisation is exact)."""
    keep = nev if keep is None else keep
    M_fast = _symmetric_block_copy(M)
    P = K.copy()
    P.axpy(-shift, M, structure=axpy_structure(K, M) if structure is None else structure)
    P.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    eps = SLEPc.EPS().create(K.getComm())
    eps.setOperators(K, M_fast)
    eps.setProblemType(SLEPc.EPS.ProblemType.GHEP)
    eps.setType(SLEPc.EPS.Type.KRYLOVSCHUR)
    eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_MAGNITUDE)
    eps.setTarget(shift)
    # subspace nev + max(20, nev/2): SLEPc's 2 nev spends more on orthogonalisation than it saves in restarts
    # (box, Q3 40 mm, nev 44: ncv 48 / 56 / 64 / 72 / 88 -> 9.3 / 5.7 / 5.5-5.9 / 5.5 / 6.2-7.8 s)
    eps.setDimensions(nev=max(nev, 1), ncv=ncv or nev + max(20, nev // 2))
    eps.setPurify(purify)
    eps.setTolerances(tol=tol, max_it=500)
    st = eps.getST()
    st.setType(SLEPc.ST.Type.SINVERT)
    st.setShift(shift)
    st.setMatMode(SLEPc.ST.MatMode.SHELL)
    st.setPreconditionerMat(P)
    ksp = st.getKSP()
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType("cholesky")
    pc.setFactorSolverType("mumps")
    eps.setFromOptions()
    try:                              # factorises K - shift M, checked (and its workspace grown) before the solve
        eps.setUp()
    except PETSc.Error:               # SLEPc's KSP raises on a failed factor: set_up_factor reads why
        pass
    operators = ksp.getOperators()

    def regrown_ksp(workspace_percent):
        new = PETSc.KSP().create(K.getComm())
        new.setOptionsPrefix(ksp.getOptionsPrefix())
        new.setOperators(*operators)
        new.setType("preonly")
        new.getPC().setType("cholesky")
        new.getPC().setFactorSolverType("mumps")
        new.setFromOptions()
        mumps.set_workspace(new, workspace_percent)
        st.setKSP(new)
        return new

    mumps.set_up_factor(regrown_ksp, st.getKSP(), what="modal solve (SLEPc's shift-and-invert)")
    eps.solve()
    pairs = []
    for i in range(eps.getConverged()):
        lam = eps.getEigenvalue(i).real
        if lam < sigma_max:
            x = K.createVecRight()
            eps.getEigenvector(i, x)
            pairs.append((lam, x))
    eps.destroy()
    P.destroy()
    if M_fast is not M:
        M_fast.destroy()
    pairs.sort(key=lambda p: p[0])
    return pairs[:keep]


EIGENSOLVERS = {"block": _block_krylov_schur, "slepc": _krylov_schur}


def _symmetric_block_copy(M: PETSc.Mat) -> PETSc.Mat:
    """M as (MPI)SBAIJ with its block size, for fast products; M itself when it has no block structure or its
    type does not convert."""
    if M.getBlockSize() == 1 or not M.getType().endswith("aij"):
        return M
    M.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    out = PETSc.Mat()
    try:
        M.convert("sbaij", out)
    except PETSc.Error:
        return M
    return out


def eigenvalue_scale(K: PETSc.Mat, M: PETSc.Mat) -> float:
    """max_i K_ii / M_ii over the rows with mass (rad^2/s^2): the Rayleigh quotient of a unit vector, a lower
    estimate of the highest eigenvalue of K x = lambda M x, used as the scale of round-off in the eigenvalues."""
    k, m = K.getDiagonal().getArray(), M.getDiagonal().getArray().real
    mass = m > 0
    local = float(np.max(k.real[mass] / m[mass])) if np.any(mass) else 0.0
    return K.getComm().tompi4py().allreduce(local, op=_mpi_max())


def _mpi_max():
    from mpi4py import MPI

    return MPI.MAX


def _normalise_and_residuals(K: PETSc.Mat, M: PETSc.Mat, values: np.ndarray, vectors: list,
                             sigma_max: float, rayleigh: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Mass-normalise the vectors in place; return the eigenvalues (with `rayleigh`, the Rayleigh quotients
    x^T K x / x^T M x instead of `values`) and ||K x - lambda M x|| / ||K x|| (rigid modes: / (sigma_max ||M x||)).
    K X and M X as two sparse-times-dense products (one pass over each matrix for all vectors: 0.35 s instead
    of 1.7 s for 44 vectors at 44 k DOFs)."""
    if not vectors:
        return values, np.zeros(0)
    X = _dense_columns(K, vectors)
    KX, MX = K.matMult(X), M.matMult(X)
    x, kx, mx = X.getDenseArray(), KX.getDenseArray(), MX.getDenseArray()
    comm = K.getComm().tompi4py()
    columns = lambda a, b: np.einsum("ij,ij->j", a, b)  # noqa: E731 - column-wise dot products
    if rayleigh:
        xkx, xmx = comm.allreduce(np.stack([columns(x, kx), columns(x, mx)]))
        values = xkx / xmx
    r = kx - mx * values
    xmx, kx2, mx2, r2 = comm.allreduce(np.stack([columns(x, mx), columns(kx, kx), columns(mx, mx),
                                                 columns(r, r)]))
    scale = 1.0 / np.sqrt(xmx)
    for vec, a in zip(vectors, scale):
        vec.scale(a)
    # residuals are homogeneous of degree one in x: the normalisation cancels in the ratio
    rigid = np.abs(values) <= 1e-6 * sigma_max
    norm_ref = np.where(rigid, sigma_max * np.sqrt(mx2), np.sqrt(kx2))
    for A in (X, KX, MX):
        A.destroy()
    return values, np.sqrt(r2) / norm_ref


def _dense_columns(K: PETSc.Mat, vectors: list) -> PETSc.Mat:
    """The vectors as the columns of a dense PETSc matrix with K's row layout."""
    X = PETSc.Mat().createDense([K.getSizes()[1], [PETSc.DECIDE, len(vectors)]], comm=K.getComm())
    X.setUp()
    a = X.getDenseArray()
    for j, vec in enumerate(vectors):
        a[:, j] = vec.getArray(readonly=True)
    X.assemble()
    return X


def rigid_body_mass_properties(M: PETSc.Mat, rigid_modes: list, rigid_fields: list) -> dict:
    """Mass (kg) and centre of gravity (m) seen by the computed rigid-body modes.

    The six exact rigid fields R (translations, rotations about the origin) are projected onto the span of
    the computed rigid modes Phi; the rigid-body mass matrix R^T M P R (P the M-orthogonal projector on
    span Phi) gives m = its translational diagonal and c from its translation-rotation coupling.  If the
    computed modes do not span the rigid motions, this mass is too small: a real check of the modes.
    """
    n = len(rigid_modes)
    M_modes = [_mult(M, x) for x in rigid_modes]      # one product per vector (12), not per pair (108)
    M_fields = [_mult(M, r) for r in rigid_fields]
    G = np.array([[rigid_modes[i].dot(M_modes[j]) for j in range(n)] for i in range(n)])
    C = np.array([[rigid_modes[i].dot(mr) for mr in M_fields] for i in range(n)])
    B = C.T @ np.linalg.solve(G, C)
    exact = np.array([[ri.dot(mr) for mr in M_fields] for ri in rigid_fields])
    mass = float(np.mean(np.diag(B)[:3]))
    centre = np.array([B[1, 5], B[2, 3], B[0, 4]]) / mass
    return {"mass_kg": mass, "centre_of_gravity_m": centre,
            "projection_defect": float(np.linalg.norm(B - exact) / np.linalg.norm(exact))}


def _mult(M: PETSc.Mat, x: PETSc.Vec) -> PETSc.Vec:
    y = M.createVecLeft()
    M.mult(x, y)
    return y


# ------------------------------------------------------------------------------------ the stage API
@dataclass
class ModalBasis(ModalResult):
    """A ModalResult plus the structure (housingfe.fe.structure.Structure) it belongs to: the input of
    housingfe.response.harmonic.harmonic_response and of the modal reports."""

    structure: object = None

    @property
    def expected_zero_modes(self) -> int | None:
        return self.structure.expected_zero_modes

    def check_zero_modes(self) -> None:
        """SolverError unless the rigid-body / mechanism count equals the structure's expected_zero_modes
        (no check when the structure does not know it, e.g. partial supports)."""
        expected = self.expected_zero_modes
        if expected is not None and self.rigid_count != expected:
            raise SolverError(f"the model must have {expected} rigid-body / mechanism modes, found "
                              f"{self.rigid_count}: lowest frequencies "
                              f"{np.round(self.frequencies_hz[:expected + 1], 4).tolist()} Hz"
                              + self._rigid_motion_clause())

    def _rigid_motion_clause(self) -> str:
        """Why a zero mode may be missing: the Rayleigh quotients of the structure's six exact rigid motions, when
        it has them.  Each one the model does not hold must be round-off (below RIGID_EIGENVALUE_RATIO of the
        scale); one above it means the model itself resists a rigid motion (e.g. a spring between two points
        that are not one), a modelling fault that no threshold should hide (docs/stability.md, "Hard case")."""
        if self.eigenvalue_scale is None or not hasattr(self.structure, "rigid_body_vectors"):
            return ""
        K, M = self.structure.K, self.structure.M
        quotients = []
        for r in self.structure.rigid_body_vectors():
            kr, mr = K.createVecLeft(), M.createVecLeft()
            K.mult(r, kr)
            M.mult(r, mr)
            quotients.append(r.dot(kr) / r.dot(mr))
        limit = RIGID_EIGENVALUE_RATIO * self.eigenvalue_scale
        strained = [f"{name} {q:.3g}" for name, q in zip(("tx", "ty", "tz", "rx", "ry", "rz"), quotients)
                    if abs(q) >= limit]
        if not strained or len(strained) == len(quotients):      # none, or a held structure: nothing to say
            return ""
        return (f"; the model resists these exact rigid motions (Rayleigh quotients, rad^2/s^2, zero-mode limit "
                f"{limit:.3g}): {', '.join(strained)} (held on purpose, e.g. by a grounded spring, or a fault of "
                "the model such as a spring between two points that are not one)")

    def to_housing(self) -> ModalResult:
        """The same modes as housing FE fields (structure.to_housing of every vector), for the housing reports."""
        import dataclasses

        return ModalResult(**{f.name: getattr(self, f.name) for f in dataclasses.fields(ModalResult)
                              if f.name not in ("vectors", "shifted_solver")},
                           vectors=[self.structure.to_housing(x) for x in self.vectors])


def known_null_space(structure) -> list | None:
    """A free structure's six rigid-body motions (PETSc Vecs), known exactly: the null_space of solve_modes, so
    the eigensolve seeks only the other modes (solve_modes checks that they are null vectors of the K it gets).
    None when the structure is not free (expected_zero_modes < 6 or unknown) or cannot give them."""
    free = (structure.expected_zero_modes or 0) >= 6 and hasattr(structure, "rigid_body_vectors")
    return structure.rigid_body_vectors() if free else None


# a fixed field of the coordinates normalised to the mesh's bounding box (no symmetry of a box or plate) that
# orient_modes measures each mode's sign against: wave vectors and phases (rad) of its x, y and z component
_ORIENT_WAVES = ((2.9, 4.1, 3.3, 0.3), (3.7, -2.3, 4.4, 1.1), (-4.3, 3.1, 2.6, 2.0))
# a product below this share of |field| |mode| leaves the sign as the solver gave it (round-off decides there)
_ORIENT_MIN_SHARE = 1e-9


def orient_modes(vectors: list, V, to_housing=lambda vec: vec) -> None:
    """Give each eigenvector (PETSc Vecs, flipped in place) the sign that makes its housing field's product with a
    fixed smooth field of the coordinates positive.  An eigenvector's sign is arbitrary and the eigensolver's start
    vectors depend on the partition: 1 and 2 MPI ranks gave the same modes with opposite signs (exported UFF mode
    shapes, the reduced housing's mass coupling).  The product is a sum over the global DOFs, so every number of
    ranks picks the same sign.  Modes of a repeated eigenvalue get a sign, not a unique basis of their subspace.
    V: the housing's displacement space; to_housing: structure DOFs -> housing field (Structure.to_housing)."""
    if not vectors:
        return
    from dolfinx import fem
    from mpi4py import MPI

    comm = V.mesh.comm
    x = V.mesh.geometry.x
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    if len(x):
        lo, hi = x.min(axis=0), x.max(axis=0)
    comm.Allreduce(MPI.IN_PLACE, lo, op=MPI.MIN)
    comm.Allreduce(MPI.IN_PLACE, hi, op=MPI.MAX)
    span = np.where(hi > lo, hi - lo, 1.0)

    def field(points):
        u = (points - lo[:, None]) / span[:, None]
        return np.vstack([np.cos(a * u[0] + b * u[1] + c * u[2] + phase) for a, b, c, phase in _ORIENT_WAVES])

    g = fem.Function(V)
    g.interpolate(field)
    g.x.scatter_forward()
    g_norm = g.vector.norm()
    for vec in vectors:
        h = to_housing(vec)
        product = g.vector.dot(h)
        if product < -_ORIENT_MIN_SHARE * g_norm * h.norm():
            vec.scale(-1.0)


def modes(structure, f_max: float, *, tol: float = 1e-10, check: bool = True) -> ModalBasis:
    """All modes of a structure (housingfe.fe.structure.Structure: K, M, expected_zero_modes) below f_max (Hz),
    complete by the inertia count (solve_modes; SolverError if not).  Eigenvalues in rad^2/s^2, vectors
    mass-normalised in the structure's DOFs.  check: also raise SolverError when the number of zero modes is
    not the structure's expected_zero_modes (ModalBasis.check_zero_modes).  A structure with a non-symmetric
    stiffness (fluid-film bearings: structure.symmetric False) gets the modes of its symmetric positive
    semi-definite stand-in structure.basis_stiffness(), the basis of the projected solver."""
    K = structure.K if getattr(structure, "symmetric", True) else structure.basis_stiffness()
    result = solve_modes(K, structure.M, f_max, tol=tol, null_space=known_null_space(structure))
    if getattr(structure, "V", None) is not None:     # a bare K, M stand-in has no coordinates to orient by
        orient_modes(result.vectors, structure.V, getattr(structure, "to_housing", lambda vec: vec))
    return structure_basis(result, structure, check=check)


def structure_basis(result: ModalResult, structure, *, check: bool = True) -> ModalBasis:
    """The ModalBasis of a solve_modes result on `structure`'s matrices (the same eigenpairs, a kept factorisation
    included).  check: SolverError when the number of zero modes is not the structure's expected_zero_modes
    (ModalBasis.check_zero_modes; no check where that is None); a kept factorisation is freed before raising.
    The one zero-mode check of the modal path (modes) and of the forced response's modal bases."""
    import dataclasses

    basis = ModalBasis(**{f.name: getattr(result, f.name) for f in dataclasses.fields(ModalResult)},
                       structure=structure)
    if check:
        try:
            basis.check_zero_modes()
        except SolverError:
            basis.release_solver()
            raise
    return basis
