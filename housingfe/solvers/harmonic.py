"""Forced harmonic response: (K (1 + i eta) + i omega C - omega^2 M) u = f.

Two solvers, one result type (`HarmonicResult`): for every load case, blocks of vectors Psi with
coefficients c(omega), u(omega) = Psi c(omega).  The vectors go through a `reduce` function (surface
Gram matrix, point values, load projections: see housingfe.response.observers) as soon as they exist, so a long
direct sweep never keeps its solution vectors.

* direct: one sparse factorisation per frequency of (K_r + i K_i), K_r = K - omega^2 M, K_i = eta K + omega C.
  On one rank (default) the n x n complex system is factorised by MUMPS (LDL^T) in a worker process running
  the complex PETSc build (housingfe.solvers._complex_worker), the ordering and symbolic analysis done once for
  all lines.  Otherwise (method="block", several ranks) the real 2x2 block form
  [[K_r, K_i], [K_i, -K_r]] [u_r; -u_i] = [f_r; f_i], a symmetric indefinite 2n x 2n system, in this process.
* modal: superposition of the modes up to `basis_factor * f_max`, the rigid-body modes, and the
  residual flexibility of all modes left out.  For a free-free structure K is singular, so the residual
  uses the inertia-relief form: r = (K - s M)^-1 P f - sum_basis phi_n phi_n^T f / (omega_n^2 - s), with
  P = I - M Phi_r Phi_r^T removing the rigid-body part of the load and a small negative shift s (the
  residual of the truncated modes, exact up to s / omega_n^2 ~ 1e-4 relative).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from petsc4py import PETSc

from housingfe.errors import SolverError
from housingfe.solvers.blas import single_thread

EtaFunction = Callable[[np.ndarray], np.ndarray]


@dataclass
class Damping:
    """eta(f): hysteretic loss factor at the excitation frequency (Hz -> -); modal_ratio: viscous xi per
    mode (modal solver; the direct solver applies eta = 2 xi); D: optional structural damping matrix
    (per-material loss factors, K_eta = int eta sigma:eps) replacing eta(f) K."""

    eta: EtaFunction
    modal_ratio: float | None = None
    D: PETSc.Mat | None = None
    modal_ratios: tuple | None = None   # per elastic mode (ascending); the last value repeats

    def ratios(self, n_modes: int) -> np.ndarray | None:
        """Viscous xi of each of n_modes elastic modes, or None for hysteretic damping."""
        if self.modal_ratios:
            r = np.asarray(self.modal_ratios, float)
            return np.concatenate([r[:n_modes], np.full(max(0, n_modes - len(r)), r[-1])])
        if self.modal_ratio is not None:
            return np.full(n_modes, self.modal_ratio)
        return None

    def hysteretic(self, f: np.ndarray) -> np.ndarray:
        if self.modal_ratios:   # direct solver: eta = 2 xi of the first mode (documented approximation)
            return np.full(np.shape(f), 2.0 * self.modal_ratios[0])
        if self.modal_ratio is not None:
            return np.full(np.shape(f), 2.0 * self.modal_ratio)
        return self.eta(np.asarray(f, dtype=float))


@dataclass
class Block:
    """Reduced vectors and their coefficients on the frequency indices `index`."""

    reduced: object
    coeffs: np.ndarray
    index: np.ndarray


@dataclass
class HarmonicResult:
    """blocks[j]: the blocks of load case j; together they cover every frequency once."""

    frequencies: np.ndarray
    blocks: list
    solver: str
    timings: dict = field(default_factory=dict)
    modal_vectors: list | None = None   # Psi of each load case (modal solver), for deflection shapes
    # self-excited modes of the reduced system (projected solver, non-symmetric K): reduced_stability's report
    unstable: list = field(default_factory=list)


# ------------------------------------------------------------------------------------------ modal
def modal_superposition(K, M, modal_result, loads, frequencies, damping: Damping, reduce, *,
                        residual: bool = True, shift: float | None = None) -> HarmonicResult:
    """Modal superposition (+ residual flexibility) for every load case on `frequencies` (Hz)."""
    t0 = time.perf_counter()
    omega = 2 * math.pi * np.asarray(frequencies, dtype=float)
    lam = modal_result.eigenvalues
    n_rigid = modal_result.rigid_count
    phis = modal_result.vectors
    rigid, elastic = phis[:n_rigid], phis[n_rigid:]
    lam_e = lam[n_rigid:]
    eta = damping.hysteretic(frequencies)
    xi = damping.ratios(len(lam_e))
    eta_modal = None
    if damping.D is not None and xi is None:
        eta_modal = np.array([phi.dot(_mult(damping.D, phi)) / l for phi, l in zip(elastic, lam_e)])
    denominators = modal_denominators(lam_e, omega, eta, xi, eta_modal)
    _check_not_singular(denominators, lam_e, frequencies)

    ksp, shift, own = _residual_solver(K, M, modal_result, lam_e, shift, "residual_") if residual else (None, 0, False)
    every = np.arange(len(omega))
    shared = list(rigid) + list(elastic)
    residuals = [_residual_vector(ksp, M, load.vector, rigid, elastic, lam_e, shift) for load in loads] if residual else []
    reduced = reduce(shared + residuals)   # one reduction for all load cases: modes are shared
    damp = (1.0 / (1 + 1j * eta) if xi is None else np.ones_like(omega))[None, :]
    blocks, kept = [], []
    for j, load in enumerate(loads):
        f = load.vector
        p_rigid = np.array([phi.dot(f) for phi in rigid])
        p_el = np.array([phi.dot(f) for phi in elastic])
        c = np.zeros((len(shared) + len(residuals), len(omega)), dtype=complex)
        c[:len(rigid)] = p_rigid[:, None] / (-omega[None, :] ** 2)
        c[len(rigid):len(shared)] = p_el[:, None] / denominators
        if residual:
            c[len(shared) + j] = damp[0]
        blocks.append([Block(reduced, c, every)])
        kept.append(shared + residuals)
    if own:
        ksp.destroy()
    return HarmonicResult(np.asarray(frequencies, float), blocks, "modal+residual" if residual else "modal",
                          {"modal_superposition_s": time.perf_counter() - t0}, modal_vectors=kept)


def modal_denominators(lam_e: np.ndarray, omega: np.ndarray, eta: np.ndarray, xi: np.ndarray | None,
                       eta_modal: np.ndarray | None = None) -> np.ndarray:
    """(modes, lines) denominators of the elastic modal coordinates, lambda_i (1 + i eta) - omega^2 (hysteretic,
    eta per line or eta_modal per mode) or lambda_i - omega^2 + 2 i xi_i omega_i omega (viscous xi per mode);
    lambda in rad^2/s^2, omega in rad/s."""
    if eta_modal is not None:
        return lam_e[:, None] * (1 + 1j * eta_modal[:, None]) - omega[None, :] ** 2
    if xi is not None:
        w_n = np.sqrt(lam_e)
        return lam_e[:, None] - omega[None, :] ** 2 + 2j * xi[:, None] * w_n[:, None] * omega[None, :]
    return lam_e[:, None] * (1 + 1j * np.asarray(eta)[None, :]) - omega[None, :] ** 2


def _residual_solver(K, M, modal_result, lam_e: np.ndarray, shift: float | None, prefix: str):
    """(solver of K - shift M, shift, whether the caller destroys it): the eigensolve's own factorisation when
    modal_result kept it for these K and M (solve_modes(keep_solver=True)) and no other shift is asked for, else
    a new one at `shift` (default: -(1 % of the highest basis frequency)^2, rad^2/s^2)."""
    kept = getattr(modal_result, "shifted_solver", None)
    if shift is None and kept is not None and kept.matches(K, M):
        return kept, kept.shift, False
    shift = shift if shift is not None else -(0.01 * math.sqrt(max(lam_e.max(initial=1.0), 1.0))) ** 2
    return _factor(_shifted(K, M, shift), prefix), shift, True


def _residual_vector(ksp, M, f, rigid, elastic, lam_e, shift) -> PETSc.Vec:
    """Static response of the modes outside the basis to the rigid-body-free part of f."""
    pf = f.copy()
    for phi in rigid:                       # P f = f - M phi_r (phi_r^T f)
        pf.axpy(-phi.dot(f), _mult(M, phi))
    r = f.duplicate()
    ksp.solve(pf, r)
    for phi, lam in zip(elastic, lam_e):
        r.axpy(-phi.dot(f) / (lam - shift), phi)
    for phi in rigid:                       # keep r M-orthogonal to the rigid modes (round-off)
        r.axpy(-phi.dot(_mult(M, r)), phi)
    return r


def _check_not_singular(denominators: np.ndarray, lam_e: np.ndarray, frequencies) -> None:
    tiny = 1e-12 * np.abs(lam_e)[:, None]
    hit = np.argwhere(np.abs(denominators) <= tiny)
    if len(hit):
        n, k = hit[0]
        raise SolverError(f"undamped system driven exactly at an eigenfrequency ({frequencies[k]:.6g} Hz, "
                          f"mode {n + 1}): the response is infinite; add damping or move the line")


# -------------------------------------------------------------------------------------- projected
def projected(K, M, modal_result, loads, frequencies, damping: Damping, reduce, C: PETSc.Mat | None = None, *,
              K_sym: PETSc.Mat | None = None, shift: float | None = None) -> HarmonicResult:
    """Non-proportional damping and non-symmetric stiffness (fluid films) on a reduced basis.

    Basis: the undamped modes of (K_sym, M) (modal_result; K_sym a symmetric PSD stand-in for K) plus, per load, the
    static residual vector of the modes left out (as in modal superposition), M-orthonormalised.  The full K,
    C and M are projected on it (Galerkin, dense, non-symmetric) and the small system
    (Kr (1 + i eta) + i omega (Cr + D_xi) - omega^2 Mr) c = Fr is solved per line; D_xi = 2 xi omega_n on the
    modes for modal damping ratios.  Exact for the loads' static response and the kept modes' dynamics; the
    error is what the rest of the spectrum does beyond its static part (check: tests against `direct`)."""
    t0 = time.perf_counter()
    K_sym = K_sym if K_sym is not None else K
    omega = 2 * math.pi * np.asarray(frequencies, dtype=float)
    lam = modal_result.eigenvalues
    n_rigid = modal_result.rigid_count
    lam_e = lam[n_rigid:]
    basis = ritz_basis(K_sym, M, modal_result, [load.vector for load in loads], shift=shift)
    t1 = time.perf_counter()
    Kr, Mr, Cr = project(basis, K, M, C)
    Fr = np.array([[b.dot(load.vector) for load in loads] for b in basis])
    D = modal_damping_matrix(len(basis), n_rigid, lam_e, damping.ratios(len(lam_e)))
    eta = np.zeros(len(omega)) if D is not None else damping.hysteretic(frequencies)
    coeffs = solve_reduced(Kr, Mr, Cr if D is None else Cr + D, omega, eta, Fr)
    unstable = reduced_stability(Kr, Mr, Cr if D is None else Cr + D, lam_e)
    t2 = time.perf_counter()
    reduced = reduce(basis)
    every = np.arange(len(omega))
    blocks = [[Block(reduced, coeffs[j], every)] for j in range(len(loads))]
    return HarmonicResult(np.asarray(frequencies, float), blocks, "projected",
                          {"projected_s": time.perf_counter() - t0, "projected_basis_s": t1 - t0,
                           "projected_lines_s": t2 - t1, "projected_basis_size": len(basis)},
                          modal_vectors=[basis] * len(loads), unstable=unstable)


def reduced_stability(Kr: np.ndarray, Mr: np.ndarray, Cr: np.ndarray, lam_e: np.ndarray) -> list[dict]:
    """Self-excited modes of the reduced system Mr c'' + Cr c' + Kr c = 0 (a non-symmetric Kr, as from fluid films,
    can feed energy in: oil whirl): [{"frequency_hz", "growth_rate_per_s"}] of the eigenvalues s with Re s > 0,
    empty when stable.  Viscous damping only (Cr, modal ratios): a hysteretic loss factor has no time-domain meaning
    here.  Re s counts as positive above 1e-9 of the basis' highest omega (round-off of the rigid modes' s ~ 0)."""
    n = len(Kr)
    if n == 0:
        return []
    try:
        Minv = np.linalg.inv(Mr)
    except np.linalg.LinAlgError:
        return []
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ Kr, -Minv @ Cr]])
    s = np.linalg.eigvals(A)
    scale = math.sqrt(max(float(np.max(lam_e, initial=0.0)), 1.0))
    growing = s[(s.real > 1e-9 * scale) & (s.imag >= 0)]
    return [{"frequency_hz": float(abs(x.imag) / (2 * math.pi)), "growth_rate_per_s": float(x.real)}
            for x in sorted(growing, key=lambda x: -x.real)]


def ritz_basis(K_sym, M, modal_result, load_vectors, *, shift: float | None = None) -> list:
    """The modes of modal_result plus, per load vector, the static residual vector of the modes left out,
    M-orthonormalised against the basis (Ritz vectors: exact for the loads' static response).  K_sym: a symmetric
    positive semi-definite stiffness (the modes' own).

    All residual vectors come from one block solve (MUMPS with every load as a right-hand side: 26 loads on the
    65 k-DOF gearbox 0.1 s instead of 1.7 s one by one) and are M-orthogonalised as a block (dense products
    instead of one dot product per pair); a load whose residual is dependent on the others (the Cholesky
    factor's pivot below the drop threshold) sends the block back to the one-by-one Gram-Schmidt, which drops it."""
    lam = modal_result.eigenvalues
    n_rigid = modal_result.rigid_count
    phis = list(modal_result.vectors)
    lam_e = lam[n_rigid:]
    ksp, shift, own = _residual_solver(K_sym, M, modal_result, lam_e, shift, "projected_")
    try:
        if not load_vectors:
            return list(phis)
        block = _residual_block(ksp, M, load_vectors, phis, n_rigid, lam_e, shift)
    finally:
        if own:
            ksp.destroy()
    return phis + block


def _residual_block(solver, M, load_vectors, phis, n_rigid: int, lam_e, shift: float) -> list:
    """The M-orthonormal residual vectors of `load_vectors` (see ritz_basis), as PETSc Vecs."""
    from housingfe.solvers.block_eigen import _Operators

    if hasattr(solver, "getPC"):                     # a KSP of our own: its MUMPS factor solves the block
        solver.setUp()
        factor = solver.getPC().getFactorMatrix()
    else:                                            # the eigensolve's kept ShiftedSolver
        factor = solver.factor
    ops = _Operators(factor, M)
    try:
        Phi = np.column_stack([p.getArray(readonly=True) for p in phis]) if phis else None
        F = np.column_stack([f.getArray(readonly=True) for f in load_vectors])
        P = F
        if n_rigid:                                  # P f = f - M phi_r (phi_r^T f)
            Pr = Phi[:, :n_rigid]
            P = F - ops.mass(Pr) @ ops.gram(Pr, F)
        R = ops.solve(P)
        if len(lam_e):                               # minus the kept elastic modes' static part
            Pe = Phi[:, n_rigid:]
            R -= Pe @ (ops.gram(Pe, F) / (np.asarray(lam_e) - shift)[:, None])
        if n_rigid:                                  # M-orthogonal to the rigid modes (round-off)
            R -= Pr @ ops.gram(Pr, ops.mass(R))
        norms_f = np.sqrt(np.maximum(ops.mpi.allreduce(np.sum(F * F, axis=0)), 1e-300))
        for _ in range(2):                           # against the modes: classical Gram-Schmidt, twice (CGS2)
            if Phi is not None:
                R -= Phi @ ops.gram(Phi, ops.mass(R))
        MR = ops.mass(R)
        G = ops.gram(R, MR)
        try:
            L = np.linalg.cholesky(0.5 * (G + G.T))
            ok = bool(np.all(np.diag(L) > 1e-12 * np.sqrt(norms_f)))
        except np.linalg.LinAlgError:
            ok = False
        if not ok:
            return _residual_one_by_one(R, M, phis, norms_f)
        R = np.linalg.solve(L, R.T).T                # sequential Gram-Schmidt among the loads, as one solve
        for _ in range(2):                           # round-off: once more against the modes, then CholQR
            if Phi is not None:
                R -= Phi @ ops.gram(Phi, ops.mass(R))
            G = ops.gram(R, ops.mass(R))
            R = np.linalg.solve(np.linalg.cholesky(0.5 * (G + G.T)), R.T).T
        out = []
        for j in range(R.shape[1]):
            v = M.createVecRight()
            v.getArray()[:] = R[:, j]
            out.append(v)
        return out
    finally:
        ops.mass_products.destroy()


def _residual_one_by_one(R: np.ndarray, M, phis: list, norms_f: np.ndarray) -> list:
    """Gram-Schmidt (CGS2) of the residual columns R one by one against the growing basis, dropping a vector
    whose M-norm falls below 1e-12 sqrt(|f|) (a load dependent on the others)."""
    basis = list(phis)
    out = []
    for j in range(R.shape[1]):
        r = M.createVecRight()
        r.getArray()[:] = R[:, j]
        for _ in range(2):
            Mr = _mult(M, r)
            for b, c in [(b, b.dot(Mr)) for b in basis]:
                r.axpy(-c, b)
        norm = math.sqrt(max(r.dot(_mult(M, r)), 0.0))
        if norm > 1e-12 * math.sqrt(norms_f[j]):
            r.scale(1.0 / norm)
            basis.append(r)
            out.append(r)
    return out


def project(basis, K, M, C=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Galerkin projections (Kr, Mr, Cr) = B^T (K, M, C) B of PETSc matrices on a list of vectors B (Cr = 0 without
    C), on every rank.  The vectors are gathered into one dense matrix and projected with two matrix-matrix products
    per matrix (PETSc MatMatMult, MatTransposeMatMult): a re-analysis of 91 Ritz vectors on 65 k DOFs takes about a
    quarter of the time of one matrix-vector product and n^2 dot products per matrix."""
    n = len(basis)
    if n == 0:
        return np.zeros((0, 0)), np.zeros((0, 0)), np.zeros((0, 0))
    comm = basis[0].comm
    B = PETSc.Mat().createDense((basis[0].getSizes(), (None, n)), comm=comm)
    B.setUp()
    columns = B.getDenseArray()
    for j, b in enumerate(basis):
        columns[:, j] = b.getArray(readonly=True)
    B.assemble()

    def one(A):
        AB = A.matMult(B)
        R = B.transposeMatMult(AB)
        local = np.array(R.getDenseArray(), dtype=float, copy=True)
        AB.destroy()
        R.destroy()
        if comm.size == 1:
            return local
        return np.vstack(comm.tompi4py().allgather(local))      # R's rows are spread over the ranks

    Kr, Mr = one(K), one(M)
    Cr = one(C) if C is not None else np.zeros_like(Kr)
    B.destroy()
    return Kr, Mr, Cr


def modal_damping_matrix(size: int, n_rigid: int, lam_e: np.ndarray, xi: np.ndarray | None) -> np.ndarray | None:
    """(size, size) viscous damping 2 xi_i omega_i on the elastic modes (the first n_rigid + len(lam_e) vectors of a
    Ritz basis; zero on the rigid modes and the residual vectors), or None for hysteretic damping (xi None)."""
    if xi is None:
        return None
    D = np.zeros((size, size))
    idx = np.arange(n_rigid, n_rigid + len(lam_e))
    D[idx, idx] = 2 * xi * np.sqrt(np.clip(lam_e, 0.0, None))
    return D


@single_thread
def solve_reduced(Kr, Mr, Cr, omega, eta, Fr) -> np.ndarray:
    """(loads, n, lines) solutions c of (Kr (1 + i eta) + i omega Cr - omega^2 Mr) c = Fr per line (omega rad/s, eta
    per line; Fr (n, loads)), batched."""
    omega = np.asarray(omega, float)
    A = (Kr[None] * (1 + 1j * np.asarray(eta, float))[:, None, None] + 1j * omega[:, None, None] * Cr[None]
         - omega[:, None, None] ** 2 * Mr[None])
    try:
        c = np.linalg.solve(A, np.broadcast_to(Fr.astype(complex), (len(omega),) + Fr.shape))
    except np.linalg.LinAlgError as exc:
        raise SolverError("projected solver: singular reduced system (an undamped line at a rigid-body or "
                          "eigenfrequency)") from exc
    return np.transpose(c, (2, 1, 0))

# ----------------------------------------------------------------------------------------- direct
def direct(K, M, loads, frequencies, damping: Damping, reduce, C: PETSc.Mat | None = None, *,
           method: str = "auto", workers: int | None = None) -> HarmonicResult:
    """Direct solution per frequency (Hz) of (K_r + i K_i) u = f, K_r = K - omega^2 M, K_i = eta K (or the damping
    matrix D) + omega C; all load cases per factor.

    method: "complex" solves the n x n complex system in a worker process running the complex PETSc build
    (housingfe.solvers._complex_worker: MUMPS LDL^T, ordering and symbolic factorisation done once for all lines);
    "block" the real 2n x 2n block form in this process; "auto" (default): complex on one MPI rank when the complex
    build is installed, block otherwise (the worker is a single process; the block form runs on every rank).
    workers: complex worker processes sharing the lines (line k goes to worker k mod workers); default: one per
    core this process may use (os.sched_getaffinity), at most one per line and at most 8.  The lines are
    independent, so on a one-rank run the otherwise idle cores factorise other lines."""
    from housingfe.solvers import _complex_worker

    if method not in ("auto", "complex", "block"):
        raise ValueError(f"direct: unknown method {method!r}")
    if method == "auto":
        method = "complex" if K.getComm().getSize() == 1 and _complex_worker.available() else "block"
    if method == "complex":
        return _direct_complex(K, M, loads, frequencies, damping, reduce, C, workers)
    return _direct_block(K, M, loads, frequencies, damping, reduce, C)


def default_direct_workers(n_lines: int) -> int:
    """Complex workers for n_lines lines: one per usable core, at most one per line, at most 8."""
    import os

    return max(1, min(len(os.sched_getaffinity(0)), n_lines, 8))


def _direct_complex(K, M, loads, frequencies, damping: Damping, reduce, C=None, workers: int | None = None
                    ) -> HarmonicResult:
    """`direct` through complex workers (one rank): line k is solved by worker k mod workers; the solutions stream
    back line by line, in order, and are reduced at once."""
    import os
    import subprocess
    import sys
    import tempfile

    from housingfe.solvers import _complex_worker

    HEAD = _complex_worker.HEAD_BYTES
    if K.getComm().getSize() != 1:
        raise SolverError("direct solver: the complex worker runs on one MPI rank; use method='block' in parallel")
    t0 = time.perf_counter()
    frequencies = np.asarray(frequencies, dtype=float)
    eta = np.asarray(damping.hysteretic(frequencies), dtype=float)
    undamped = C is None and (damping.D is None or damping.modal_ratio is not None) and not np.any(eta)
    use_D = damping.D is not None and damping.modal_ratio is None
    symmetric = all(_is_symmetric(A) for A in (K, M, damping.D, C) if A is not None)
    omega = 2 * math.pi * frequencies
    if undamped:
        for w, f_hz in zip(omega, frequencies):
            _check_undamped_line(K, M, w * w, f_hz)
    n = K.getSize()[0]
    n_workers = default_direct_workers(len(frequencies)) if workers is None else int(workers)
    if n_workers < 1:
        raise ValueError(f"direct: workers must be >= 1, got {workers}")
    n_workers = min(n_workers, max(len(frequencies), 1))
    tmp = tempfile.TemporaryDirectory(prefix="housingfe-direct-")
    errs = [open(os.path.join(tmp.name, f"stderr{w}.txt"), "w+") for w in range(n_workers)]
    # started first: their imports (~0.5 s) overlap with writing the job
    procs = [subprocess.Popen([sys.executable, "-m", "housingfe.solvers._complex_worker", "-"], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, stderr=err, env=_complex_worker.complex_env()) for err in errs]
    job = {"loads": np.array([load.vector.getArray() for load in loads], dtype=float).reshape(len(loads), n),
           "omega": omega, "eta": np.broadcast_to(eta, omega.shape).copy(), "use_D": use_D, "symmetric": symmetric,
           "block_size": K.getBlockSize()}
    blocks = [[] for _ in loads]
    pair = np.array([[1.0], [1j]])
    t_factor = 0.0
    line_bytes = HEAD + 16 * len(loads) * n
    factorisations = 0
    backward_error = 0.0
    try:
        K_pattern = None
        for name, A in (("K", K), ("M", M), ("D", damping.D if use_D else None), ("C", C)):
            if A is not None:
                indptr, indices, data = A.getValuesCSR()
                job[f"{name}_data"] = np.real(data)
                if K_pattern is None:
                    K_pattern = (indptr, indices)
                if name == "K" or not (np.array_equal(indptr, K_pattern[0]) and np.array_equal(indices, K_pattern[1])):
                    job.update({f"{name}_indptr": indptr, f"{name}_indices": indices})
        np.savez(os.path.join(tmp.name, "job.npz"), **job)
        del job
        for w, proc in enumerate(procs):
            try:
                proc.stdin.write(f"{os.path.join(tmp.name, 'job.npz')} {w} {n_workers}\n".encode())
                proc.stdin.close()
            except BrokenPipeError:   # the worker died at start: its stderr is reported below
                pass
        for k in range(len(frequencies)):
            # in line order, round robin: each worker is at most one line ahead of the reading
            raw = procs[k % n_workers].stdout.read(line_bytes)
            if len(raw) < line_bytes:
                break
            head = np.frombuffer(raw[:HEAD], np.float64)
            t_factor += float(head[0])
            factorisations += int(head[1])
            backward_error = max(backward_error, float(head[2]))
            sol = np.frombuffer(raw[HEAD:], np.complex128).reshape(len(loads), n)
            for j in range(len(loads)):
                ur, ui = K.createVecRight(), K.createVecRight()
                ur.setArray(sol[j].real)
                ui.setArray(sol[j].imag)
                blocks[j].append(Block(reduce([ur, ui]), pair, np.array([k])))
    finally:
        incomplete = any(len(b) != len(frequencies) for b in blocks)
        codes, messages = [], []
        for proc, err in zip(procs, errs):
            if proc.poll() is None and incomplete:
                proc.kill()   # an exception here (in reduce, say) or a failed worker: leave none running
            proc.stdout.close()
            codes.append(proc.wait())
            err.seek(0)
            messages.append(err.read().strip())
            err.close()
        tmp.cleanup()
    for code, message in zip(codes, messages):
        if code == _complex_worker.SINGULAR_EXIT and message.startswith("SINGULAR"):
            f_hz = frequencies[int(message.split()[1])]
            raise SolverError(f"direct solver: singular system at {f_hz:.6g} Hz (undamped resonance?)")
    # the worker that failed first, not the ones killed because of it (exit -9)
    failed = sorted(((c, m) for c, m in zip(codes, messages) if c), key=lambda cm: cm[0] == -9)
    if failed or any(len(b) != len(frequencies) for b in blocks):
        code, message = failed[0] if failed else (0, "fewer lines than asked")
        tail = " | ".join(message.splitlines()[-5:])
        raise SolverError(f"direct solver: the complex worker failed (exit {code}): {tail}")
    return HarmonicResult(frequencies, blocks, "direct",
                          {"direct_s": time.perf_counter() - t0, "direct_factor_s": t_factor,
                           "direct_factorisations": factorisations, "direct_workers": n_workers,
                           "direct_backward_error": backward_error,
                           "direct_s_per_frequency": (time.perf_counter() - t0) / max(len(frequencies), 1)})


def _direct_block(K, M, loads, frequencies, damping: Damping, reduce, C: PETSc.Mat | None = None) -> HarmonicResult:
    """Direct solution per frequency in the real 2x2 block form (MUMPS LDL^T), all load cases per factor."""
    t0 = time.perf_counter()
    eta = damping.hysteretic(frequencies)
    undamped = C is None and (damping.D is None or damping.modal_ratio is not None) and not np.any(eta)
    blocks = [[] for _ in loads]
    t_factor = 0.0
    pair = np.array([[1.0], [1j]])
    # the 2x2 block matrix is symmetric iff K, M and the damping matrices are: LDL^T then, LU otherwise
    symmetric = all(_is_symmetric(A) for A in (K, M, damping.D, C) if A is not None)
    from housingfe.solvers.modal import axpy_structure

    structure = axpy_structure(K, M)
    for k, (f_hz, eta_f) in enumerate(zip(frequencies, eta)):
        w = 2 * math.pi * f_hz
        if undamped:
            _check_undamped_line(K, M, w * w, f_hz)
        Kr = K.copy()
        Kr.axpy(-w * w, M, structure=structure)
        if damping.D is not None and damping.modal_ratio is None:
            Ki = damping.D.copy()
        else:
            Ki = K.copy()
            Ki.scale(eta_f)
        if C is not None:
            Ki.axpy(w, C, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        mKr = Kr.copy()
        mKr.scale(-1.0)
        nest = PETSc.Mat().createNest([[Kr, Ki], [Ki, mKr]], comm=K.getComm())
        row_is, _ = nest.getNestISs()
        A = nest.convert("aij", PETSc.Mat())   # petsc4py converts in place unless given an output
        A.setOption(PETSc.Mat.Option.SYMMETRIC, symmetric)
        t1 = time.perf_counter()
        from housingfe.solvers.mumps import SingularMatrix

        try:
            ksp = _factor(A, "direct_", lu=not symmetric)
        except SingularMatrix as exc:
            raise SolverError(f"direct solver: singular system at {f_hz:.6g} Hz (undamped resonance?)") from exc
        t_factor += time.perf_counter() - t1
        for j, load in enumerate(loads):
            b, x = A.createVecRight(), A.createVecRight()
            b.set(0.0)
            sub = b.getSubVector(row_is[0])
            load.vector.copy(sub)
            b.restoreSubVector(row_is[0], sub)
            ksp.solve(b, x)
            ur = x.getSubVector(row_is[0]).copy()
            ui = x.getSubVector(row_is[1]).copy()
            ui.scale(-1.0)
            blocks[j].append(Block(reduce([ur, ui]), pair, np.array([k])))
        for m in (Kr, Ki, mKr, nest, A, ksp):
            m.destroy()
    n = len(frequencies)
    return HarmonicResult(np.asarray(frequencies, float), blocks, "direct",
                          {"direct_s": time.perf_counter() - t0, "direct_factor_s": t_factor,
                           "direct_s_per_frequency": (time.perf_counter() - t0) / max(n, 1)})


def _check_undamped_line(K, M, w2: float, f_hz: float, tol: float = 1e-9) -> None:
    """Without damping, K - w^2 M is singular at an eigenfrequency: detect an eigenvalue within a relative
    `tol` of w^2 by two inertia counts (Sylvester) instead of returning a silent inf/nan."""
    from housingfe.solvers.modal import count_eigenvalues_below

    try:
        below = count_eigenvalues_below(K, M, w2 * (1 - tol))
        above = count_eigenvalues_below(K, M, w2 * (1 + tol))
    except SolverError:
        below, above = 0, 1
    if above != below:
        raise SolverError(f"undamped system driven exactly at an eigenfrequency ({f_hz:.6g} Hz): the response "
                          "is infinite; add damping or move the line")


# ---------------------------------------------------------------------------------------- helpers
def _shifted(K, M, shift: float) -> PETSc.Mat:
    A = K.copy()
    from housingfe.solvers.modal import axpy_structure

    A.axpy(-shift, M, structure=axpy_structure(A, M))
    A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    return A


def _factor(A: PETSc.Mat, prefix: str, lu: bool = False, workspace_percent: int | None = None) -> PETSc.KSP:
    """A set-up MUMPS factorisation of A (LDL^T, LU with `lu`) through housingfe.solvers.mumps.set_up_factor: a
    workspace too small is grown, any other failure raises SolverError (SingularMatrix when singular).
    workspace_percent: ICNTL(14) of the first attempt (default MUMPS' 20)."""
    from housingfe.solvers.mumps import mumps_cholesky, set_up_factor, set_workspace

    def make_ksp(percent):
        ksp = mumps_cholesky(A, prefix)
        if lu:   # non-symmetric bearing stiffness or fluid-film damping
            # a new PC type forgets the solver type: without this it was PETSc's own LU, not MUMPS
            ksp.getPC().setType("lu")
            ksp.getPC().setFactorSolverType("mumps")
            ksp.setFromOptions()
        set_workspace(ksp, workspace_percent if percent is None else percent)
        return ksp

    return set_up_factor(make_ksp, what="direct solver" if prefix == "direct_" else "MUMPS")


def _is_symmetric(A: PETSc.Mat) -> bool:
    """Numerically symmetric (relative 1e-12 of the matrix norm)?"""
    return bool(A.isSymmetric(1e-12 * max(A.norm(), 1e-300)))


def _mult(A: PETSc.Mat, x: PETSc.Vec) -> PETSc.Vec:
    y = A.createVecLeft()
    A.mult(x, y)
    return y
