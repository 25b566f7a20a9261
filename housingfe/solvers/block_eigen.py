"""Block Krylov–Schur for the lowest eigenpairs of K x = lambda M x, shift-and-invert with a MUMPS factor.

Why a block method next to SLEPc's Krylov–Schur: the eigensolve of a housing model is dominated by MUMPS'
triangular solves, which are memory-bound: one right-hand side costs 45 ms at 71 k Q3 DOFs, a block of 8 costs
10 ms per right-hand side and a block of 32 costs 6 ms (bench modal).  SLEPc 3.18's Krylov–Schur applies the
operator one vector at a time and its block method (LOBPCG) breaks down on the free box (LAPACK sygvd fails on
the projected problem).  A block Krylov space needs about twice as many operator applications as a
single-vector one, so the gain per solve more than pays, and the mass products (one per block) run on the
scalar mass matrix when M = m ⊗ I (the elastic mass: 3x fewer stored entries).

Method (a block form of Stewart's Krylov–Schur): with S = (K - sigma M)^-1 M, keep an M-orthonormal basis V
and the relation S V[:, :p] = V[:, :p+b] H.  Expand block by block (full M-orthogonalisation, two passes, then
CholQR2); after every block (once p >= nev + b), Rayleigh–Ritz on H[:p, :p] (S is M-self-adjoint, so H is
symmetric up to round-off); stop when the nev largest Ritz values theta have residual norms ||H[p:, :p] u|| / |theta|
below tol (SLEPc's relative criterion on the transformed problem); with a full basis, restart with the `keep` best Ritz
vectors and the last block, whose relation H = [diag(theta); H[p:, :p] U] keeps the expansion going.
lambda = sigma + 1 / theta.  With side="below" (sigma above the wanted eigenvalues, e.g. sigma_max of the inertia
count) the most negative theta are wanted instead, and the estimates are scaled to residuals of K x = lambda M x
(BELOW_RIGID_FLOOR).  A known invariant subspace (`deflate`: a free body's rigid-body motions) is projected out
of every new block, so the basis holds only the other eigenpairs.  The same answer on any number of MPI ranks:
vectors are distributed by rows,
the small projected matrices are reduced over the ranks and solved redundantly.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from petsc4py import PETSc

from housingfe.errors import SolverError


@dataclass
class BlockEigenResult:
    """eigenvalues (rad^2/s^2, ascending), vectors (local rows x nev, M-orthonormal), residual estimates
    (relative, transformed problem), and the work done."""

    eigenvalues: np.ndarray
    vectors: np.ndarray
    residual_estimates: np.ndarray
    restarts: int
    block_solves: int
    block: int
    timings: dict = field(default_factory=dict)


class MassProducts:
    """Products M X for dense blocks X (local rows).  When M = m ⊗ I_bs (the consistent mass of a vector
    field with bs components: the off-diagonal component blocks are zero and the diagonal ones equal), the
    product runs on the scalar matrix m with X's rows regrouped per node: bs^2 fewer stored entries read."""

    def __init__(self, M: PETSc.Mat):
        self.M = M
        self.comm = M.getComm()
        self.rows_local, self.rows = M.getLocalSize()[0], M.getSize()[0]
        self.bs = M.getBlockSize()
        self.scalar = _scalar_factor(M) if self.bs > 1 else None

    def __call__(self, X: np.ndarray) -> np.ndarray:
        k = X.shape[1]
        if self.scalar is not None:
            bs = self.bs
            D = _dense(np.ascontiguousarray(X).reshape(self.rows_local // bs, bs * k), self.rows // bs,
                       self.comm)
            Y = self.scalar.matMult(D)
            out = np.array(Y.getDenseArray()).reshape(self.rows_local, k)
        else:
            D = _dense(X, self.rows, self.comm)
            Y = self.M.matMult(D)
            out = np.array(Y.getDenseArray())
        Y.destroy()
        D.destroy()
        return out

    def destroy(self) -> None:
        if self.scalar is not None:
            self.scalar.destroy()


def _scalar_factor(M: PETSc.Mat) -> PETSc.Mat | None:
    """m with M = m ⊗ I_bs, or None.  m is the first component's block of M; M = m ⊗ I_bs is then checked on the
    products with two random vectors (M X against (m ⊗ I) X to 1e-14, which a differing entry fails with
    probability one): one submatrix and two products instead of bs^2 submatrices (0.01 vs 0.11 s at 40 k DOFs)."""
    bs = M.getBlockSize()
    r0, r1 = M.getOwnershipRange()
    comm = M.getComm()
    if comm.tompi4py().allreduce(int(r0 % bs or r1 % bs)):
        return None
    first = PETSc.IS().createStride((r1 - r0) // bs, r0, bs, comm=comm)
    m = M.createSubMatrix(first, first)
    first.destroy()
    X = np.random.default_rng(r0).standard_normal((r1 - r0, 2))
    D = _dense(X, M.getSize()[0], comm)
    Y = M.matMult(D)
    full = np.array(Y.getDenseArray())
    for A in (D, Y):
        A.destroy()
    Ds = _dense(X.reshape((r1 - r0) // bs, bs * 2), M.getSize()[0] // bs, comm)
    Ys = m.matMult(Ds)
    scalar = np.array(Ys.getDenseArray()).reshape(r1 - r0, 2)
    for A in (Ds, Ys):
        A.destroy()
    mpi = comm.tompi4py()
    error, scale = mpi.allreduce(np.array([np.sum((full - scalar) ** 2), np.sum(full ** 2)]))
    if not scale > 0 or np.sqrt(error) > 1e-14 * np.sqrt(scale):
        m.destroy()
        return None
    return m


# The random start block goes through S twice before the iteration: a random vector carries every mesh
# frequency, and what of it survives in the Ritz vectors shows in ||K x - lambda M x|| amplified by
# lambda_mesh / lambda (thin plate, FV12: residuals 2e-4 without, 1e-6 with one pass, 3e-7 with two, SLEPc
# 4e-6); 16 extra right-hand sides.
START_FILTER = 2


def _dense(a: np.ndarray, rows: int, comm) -> PETSc.Mat:
    """A dense PETSc matrix on the local rows of `a` (copied to column-major order)."""
    a = np.asfortranarray(a)
    return PETSc.Mat().createDense([(a.shape[0], rows), (a.shape[1], a.shape[1])], array=a, comm=comm)


class _Operators:
    """S X = (K - sigma M)^-1 M X through a factor (solve_block or matSolve), M-products, reductions, and their timers."""

    def __init__(self, factor, M: PETSc.Mat):
        self.factor = factor
        self.mass_products = MassProducts(M)
        self.comm = M.getComm()
        self.mpi = self.comm.tompi4py()
        self.rows_local, self.rows = M.getLocalSize()[0], M.getSize()[0]
        self.timings = {"solve_s": 0.0, "mass_s": 0.0, "orthogonalise_s": 0.0, "restart_s": 0.0}

    def solve(self, B: np.ndarray) -> np.ndarray:
        t = time.perf_counter()
        if hasattr(self.factor, "solve_block"):
            out = self.factor.solve_block(B)
        else:
            D = _dense(B, self.rows, self.comm)
            X = D.duplicate()
            self.factor.matSolve(D, X)
            out = np.array(X.getDenseArray())
            X.destroy()
            D.destroy()
        self.timings["solve_s"] += time.perf_counter() - t
        return out

    def mass(self, X: np.ndarray) -> np.ndarray:
        t = time.perf_counter()
        out = self.mass_products(X)
        self.timings["mass_s"] += time.perf_counter() - t
        return out

    def gram(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """A^T B summed over the ranks."""
        return self.mpi.allreduce(A.T @ B)


def _cholqr2(ops: _Operators, W: np.ndarray, MW: np.ndarray):
    """W, M W made M-orthonormal by two Cholesky-QR passes; returns W, MW, R with W_in = W R."""
    R = np.eye(W.shape[1])
    for _ in range(2):
        G = ops.gram(W, MW)
        try:
            L = np.linalg.cholesky((G + G.T) / 2)
        except np.linalg.LinAlgError as err:
            raise SolverError("block Krylov–Schur: the new block is linearly dependent on the basis") from err
        Rinv = np.linalg.inv(L.T)
        W, MW, R = W @ Rinv, MW @ Rinv, L.T @ R
    return W, MW, R


def default_block(nev: int) -> int:
    """Right-hand sides per solve: 8 (bench modal: 8 to 16 are equally fast at 44 eigenpairs, larger blocks
    need more operator applications than their cheaper solves save)."""
    return 8


def default_max_basis(nev: int, block: int) -> int:
    """Basis size before a restart: room for nev plus 12 blocks, at least 3 nev (rounded to whole blocks).  A
    restart keeps nev + block Ritz vectors and throws the rest of the Krylov space away: on the S2R box (38 elastic
    eigenpairs) 24 block solves with 2 restarts at max(nev + 8 blocks, 2 nev), 20 without; at 85 eigenpairs 53 -> 37.
    Memory: two bases (V and M V) of max_basis + block vectors."""
    size = max(nev + 12 * block, 3 * nev)
    return block * -(-size // block)


SIDES = ("above", "below")


def block_krylov_schur(factor, M: PETSc.Mat, shift: float, nev: int, *, side: str = "above",
                       block: int | None = None, max_basis: int | None = None, tol: float = 1e-10,
                       max_restarts: int = 200, seed: int = 0,
                       deflate: np.ndarray | None = None) -> BlockEigenResult:
    """The nev eigenpairs of K x = lambda M x closest to `shift` (rad^2/s^2) on one side of it, given `factor`,
    a factorisation of K - shift M: an LDL^T of housingfe.solvers.mumps (solve_block) or a PETSc factored Mat.

    side="above": the nev closest above the shift (a shift below the spectrum: the lowest nev).
    side="below": the nev closest below the shift, i.e. the most negative theta = 1 / (lambda - shift); with nev
    the inertia count of K - shift M, every eigenpair below the shift, so the count's own factorisation serves
    the eigensolve.  Eigenvalues ascending, eigenvectors M-orthonormal.  SolverError if it does not converge
    within max_restarts or the basis degenerates (then use SLEPc's Krylov–Schur).

    deflate: local rows x r, M-orthonormal, an exact invariant subspace of S (e.g. a free body's rigid-body
    motions, K x = 0): the basis is kept M-orthogonal to it and the nev eigenpairs are sought in its complement
    (S is M-self-adjoint, so S maps that complement to itself; the projection only removes round-off)."""
    if side not in SIDES:
        raise ValueError(f"side must be one of {SIDES}, not {side!r}")
    ops = _Operators(factor, M)
    try:
        result = _iterate(ops, shift, nev, block or default_block(nev), max_basis, tol, max_restarts, seed,
                          side == "below", deflate)
    finally:
        ops.mass_products.destroy()
    order = np.argsort(result.eigenvalues, kind="stable")
    result.eigenvalues, result.vectors = result.eigenvalues[order], result.vectors[:, order]
    result.residual_estimates = result.residual_estimates[order]
    return result


def _iterate(ops: _Operators, shift: float, nev: int, b: int, max_basis: int | None, tol: float,
             max_restarts: int, seed: int, below: bool, deflate: np.ndarray | None = None) -> BlockEigenResult:
    pmax = max_basis or default_max_basis(nev, b)
    if pmax + b > ops.rows:
        raise SolverError(f"block Krylov–Schur: basis of {pmax + b} vectors for {ops.rows} DOFs")
    keep = min(pmax - b, nev + b)
    n = ops.rows_local
    V, MV = np.empty((n, pmax + b)), np.empty((n, pmax + b))
    H = np.zeros((pmax + b, pmax))
    # the same random start on any number of ranks: each rank draws the global rows it owns
    start, _ = _global_row_range(ops)
    W = np.random.default_rng(seed).standard_normal((ops.rows, b))[start:start + n]
    if deflate is not None:
        mdeflate = ops.mass(deflate)
    for _ in range(START_FILTER):
        if deflate is not None:
            W = _project_out(ops, W, deflate, mdeflate)
        W, MW, _ = _cholqr2(ops, W, ops.mass(W))
        W = ops.solve(MW)
    if deflate is not None:
        W = _project_out(ops, W, deflate, mdeflate)
    V[:, :b], MV[:, :b], _ = _cholqr2(ops, W, ops.mass(W))
    p, solves = 0, 0
    for restart in range(max_restarts + 1):
        while p + b <= pmax:
            q = p + b
            W = ops.solve(MV[:, p:q])
            solves += 1
            t = time.perf_counter()
            C = np.zeros((q, b))
            for _ in range(2):          # classical Gram–Schmidt twice: orthogonal to round-off
                if deflate is not None:
                    W = _project_out(ops, W, deflate, mdeflate)
                c = ops.gram(MV[:, :q], W)
                W -= V[:, :q] @ c
                C += c
            ops.timings["orthogonalise_s"] += time.perf_counter() - t
            MW = ops.mass(W)
            t = time.perf_counter()
            W, MW, R = _cholqr2(ops, W, MW)
            H[:q, p:q], H[q:q + b, p:q] = C, R
            V[:, q:q + b], MV[:, q:q + b] = W, MW
            ops.timings["orthogonalise_s"] += time.perf_counter() - t
            p = q
            if nev + b <= p < pmax:
                # the Krylov–Schur relation holds after every block, so convergence is checked after every
                # block (a p x p eigenproblem, ~1 ms), not only with a full basis: a run no longer pays a whole
                # restart cycle (7 block solves at 63 eigenpairs) when its last Ritz values pass tol mid-cycle
                theta, U, coupling, estimates = _ritz(H, p, b, below, shift)
                if np.all(estimates[:nev] < tol):
                    return BlockEigenResult(shift + 1.0 / theta[:nev], V[:, :p] @ U[:, :nev], estimates[:nev],
                                            restart, solves, b, dict(ops.timings))
        theta, U, coupling, estimates = _ritz(H, p, b, below, shift)
        if np.all(estimates[:nev] < tol):
            X = V[:, :p] @ U[:, :nev]
            return BlockEigenResult(shift + 1.0 / theta[:nev], X, estimates[:nev], restart, solves, b,
                                    dict(ops.timings))
        t = time.perf_counter()
        Uk = np.ascontiguousarray(U[:, :keep])
        last, mlast = V[:, p:p + b].copy(), MV[:, p:p + b].copy()
        V[:, :keep], MV[:, :keep] = V[:, :p] @ Uk, MV[:, :p] @ Uk
        V[:, keep:keep + b], MV[:, keep:keep + b] = last, mlast
        H[:] = 0.0
        H[:keep, :keep] = np.diag(theta[:keep])
        H[keep:keep + b, :keep] = coupling[:, :keep]
        p = keep
        ops.timings["restart_s"] += time.perf_counter() - t
    raise SolverError(f"block Krylov–Schur: {int(np.sum(estimates[:nev] < tol))} of {nev} eigenpairs converged "
                      f"after {max_restarts} restarts")


# With the shift above the wanted eigenvalues (side="below"), a residual of the transformed problem maps to one of
# K x = lambda M x enlarged by |lambda - shift| / lambda: sigma_max / lambda_1 = 46 on the box's lowest elastic mode.
# The estimates are scaled by it, so the modes meet the same residual as with a shift below zero; the rigid modes
# (lambda ~ 0) are held to 1 / BELOW_RIGID_FLOOR of the tolerance instead.
BELOW_RIGID_FLOOR = 1e-2


def _ritz(H: np.ndarray, p: int, b: int, below: bool = False, shift: float = 0.0):
    """Ritz values theta, wanted first (largest: eigenvalues closest above the shift; with `below`, most negative:
    closest below it), vectors U of the projected H[:p, :p], the last block row's coupling H[p:p+b, :p] U and
    the relative residual estimates |coupling| / |theta| (with `below`, scaled as said at BELOW_RIGID_FLOOR)."""
    T = H[:p, :p]
    theta, U = np.linalg.eigh((T + T.T) / 2)
    if not below:
        theta, U = theta[::-1], U[:, ::-1]
    coupling = H[p:p + b, :p] @ U
    estimates = np.linalg.norm(coupling, axis=0) / np.abs(theta)
    if below:
        lam = shift + 1.0 / theta
        estimates = estimates / (np.abs(theta) * np.maximum(lam, BELOW_RIGID_FLOOR * abs(shift)))
    return theta, U, coupling, estimates


def _project_out(ops: _Operators, W: np.ndarray, Q: np.ndarray, MQ: np.ndarray) -> np.ndarray:
    """W minus its M-orthogonal projection on the M-orthonormal Q."""
    return W - Q @ ops.gram(MQ, W)


def _global_row_range(ops: _Operators) -> tuple[int, int]:
    start = ops.mpi.exscan(ops.rows_local) or 0
    return start, start + ops.rows_local
