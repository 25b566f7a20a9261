"""Complex-valued direct harmonic solve in its own process (complex PETSc build, one rank).

Started by `housingfe.solvers.harmonic.direct` as `python -m housingfe.solvers._complex_worker -` (the job's path
then comes on stdin, once the worker's imports are done, optionally followed by `first step`: this worker solves
lines first, first + step, ... of the job, so that several workers share the lines) or `... job.npz`, with
PETSC_DIR / SLEPC_DIR selecting the complex build (one process cannot hold both builds, see
docs/forced-response.md).  Per line it factorises A = K_r + i K_i (n x n complex, MUMPS LDL^T when symmetric,
LU otherwise) instead of the real 2n x 2n block form, and the sparsity pattern is the same on every line, so the
ordering and symbolic analysis are done once and only the numerical factorisation is repeated.

job.npz: K, M (and D, C when given) as CSR arrays <name>_indptr/_indices/_data (real; a matrix without
_indptr/_indices has K's pattern), loads (n_loads, n) real,
omega (rad/s) and eta per line, use_D (D replaces eta K), symmetric, block_size (K's: 3 for FE displacements).
stdout, per line: three float64 (seconds for the factorisation, the solve and its check; factorisations, 1 or 2;
the normwise backward error max_j ||A x_j - f_j||_inf / (||A||_inf ||x_j||_inf + ||f_j||_inf), ||A|| bounded by its
parts' norms), then the solutions (n_loads, n) complex128.  All loads are solved at once (MatMatSolve: one pass
over the factor, 0.030 s per line against 2 x 0.029 s at 39 k DOFs).  (Tried and dropped: GMRES preconditioned
by a nearby line's factor.  At 39 k DOFs, lines 4.9 Hz apart, eta 0.02, it needed ~6 iterations per load of ~0.1 s
each plus failed attempts: 1.66 s per line against 1.46 s for a new factorisation per line.)
A singular line: "SINGULAR <line index>" on stderr and exit code 3.
"""
from __future__ import annotations

import os
import sys
import time

import numpy as np

COMPLEX_PETSC_DIR = "/usr/lib/petscdir/petsc3.18/x86_64-linux-gnu-complex"
COMPLEX_SLEPC_DIR = "/usr/lib/slepcdir/slepc3.18/x86_64-linux-gnu-complex"
SINGULAR_EXIT = 3
HEAD_BYTES = 24   # per line: seconds, factorisations, backward error (float64 each)
BACKWARD_ERROR_TOL = 1e-12   # normwise; MUMPS LDL^T gives 1e-16 on the box models


def available() -> bool:
    """Is the complex PETSc build installed (python3-petsc4py-complex / python3-dolfinx-complex)?"""
    return os.path.isdir(COMPLEX_PETSC_DIR) and os.path.isdir(COMPLEX_SLEPC_DIR)


def complex_env() -> dict:
    """The environment selecting the complex PETSc/SLEPc build (both variables, see STACK-NOTES), without the
    Open MPI launcher variables of a parent started by mpirun (the worker is a singleton MPI process)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_"))}
    env["PETSC_DIR"] = COMPLEX_PETSC_DIR
    env["SLEPC_DIR"] = COMPLEX_SLEPC_DIR
    env.setdefault("OPENBLAS_NUM_THREADS", "1")
    return env


def _csr(job, name):
    import scipy.sparse as sp

    n = job["loads"].shape[1]
    return sp.csr_matrix((job[f"{name}_data"], job[f"{name}_indices"], job[f"{name}_indptr"]), shape=(n, n))


def _on_union(mats):
    """(indptr, indices, [data of each matrix on the union pattern]): the values of every matrix on one common
    sorted pattern, so each line only recombines data arrays."""
    import scipy.sparse as sp

    first = mats[0]
    if all(np.array_equal(A.indptr, first.indptr) and np.array_equal(A.indices, first.indices) for A in mats[1:]):
        # one pattern already (K and M of one form space, usually D too): nothing to align
        return first.indptr.astype(np.int32), first.indices.astype(np.int32), [A.data for A in mats]
    union = None
    for A in mats:
        ones = sp.csr_matrix((np.ones(len(A.data)), A.indices, A.indptr), shape=A.shape)
        union = ones if union is None else union + ones   # positive sums: no cancellation drops an entry
    union.sort_indices()
    datas = []
    for A in mats:
        # A + i * union: never zero on the union pattern, so scipy keeps every entry; the real part is A there
        B = (A.astype(complex) + 1j * union).tocsr()
        B.sort_indices()
        if not (np.array_equal(B.indptr, union.indptr) and np.array_equal(B.indices, union.indices)):
            raise RuntimeError("pattern alignment failed")
        datas.append(B.data.real.copy())
    return union.indptr.astype(np.int32), union.indices.astype(np.int32), datas


def _upper_triangle(indptr, indices, datas):
    """The entries with column >= row of a CSR pattern and of its data arrays (sorted rows stay sorted)."""
    rows = np.repeat(np.arange(len(indptr) - 1, dtype=np.int32), np.diff(indptr))
    keep = indices >= rows
    counts = np.bincount(rows[keep], minlength=len(indptr) - 1)
    upper_ptr = np.concatenate([[0], np.cumsum(counts)]).astype(np.int32)
    return upper_ptr, indices[keep].astype(np.int32), [np.ascontiguousarray(d[keep]) for d in datas]



def _factor_solver(A, symmetric: bool, block_size: int, workspace_percent: int | None = None):
    """preonly + MUMPS (LDL^T when symmetric, LU otherwise) on A; user options under the prefix direct_ win.
    A symmetric matrix of one kind of unknown in node blocks (FE displacements, block_size 3) gets its ordering on
    the compressed node graph (ICNTL(15)) and no row/column scaling (ICNTL(8) = 0: the rows share one unit; a line
    whose backward error then exceeds BACKWARD_ERROR_TOL is refactorised with MUMPS' scaling): 0.79 -> 0.70 s per
    factorisation at 39 k DOFs, backward errors ~1e-16 either way.  workspace_percent: MUMPS' ICNTL(14) (None:
    its default or the options'); set up by housingfe.solvers.mumps.set_up_factor, which grows it where short."""
    from petsc4py import PETSc

    from housingfe.solvers.mumps import set_workspace

    n = A.getSize()[0]
    opts = PETSc.Options()
    if symmetric and block_size > 1 and n % block_size == 0:
        for key, value in (("direct_mat_mumps_icntl_15", -block_size), ("direct_mat_mumps_icntl_8", 0)):
            if not opts.hasName(key):
                opts[key] = value
    ksp = PETSc.KSP().create(PETSc.COMM_SELF)
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.setErrorIfNotConverged(True)   # a failed factorisation raises instead of returning inf/nan
    pc = ksp.getPC()
    pc.setType("cholesky" if symmetric else "lu")   # complex symmetric (not Hermitian): MUMPS LDL^T, sym = 2
    pc.setFactorSolverType("mumps")
    ksp.setOptionsPrefix("direct_")   # -direct_mat_mumps_icntl_* through PETSC_OPTIONS reach the worker
    ksp.setFromOptions()
    set_workspace(ksp, workspace_percent)
    return ksp


def _scaling_off(ksp) -> bool:
    return ksp.getPC().getFactorMatrix().getMumpsIcntl(8) == 0


def _inf_norm(rows, indices, data, n: int, symmetric: bool) -> float:
    """max row sum of |entries| of a matrix in coordinates (rows, indices) (symmetric: stored as its upper
    triangle)."""
    sums = np.bincount(rows, weights=np.abs(data), minlength=n)
    if symmetric:   # the lower triangle: the upper one's columns, without the diagonal twice
        off = indices != rows
        sums += np.bincount(indices[off], weights=np.abs(data[off]), minlength=n)
    return float(sums.max())


def _backward_error(A, sol, loads, residual, a_norm: float, load_norms) -> float:
    """Largest normwise backward error ||A x - f||_inf / (||A||_inf ||x||_inf + ||f||_inf) over the loads."""
    from petsc4py import PETSc

    worst = 0.0
    x, f = A.createVecRight(), A.createVecRight()
    for j in range(len(loads)):
        x.setArray(sol[j])
        f.setArray(loads[j])
        A.mult(x, residual)
        residual.axpy(-1.0, f)
        denominator = a_norm * np.abs(sol[j]).max() + load_norms[j]
        worst = max(worst, residual.norm(PETSc.NormType.INFINITY) / denominator if denominator else 0.0)
    return worst


def run(job_path: str | None, out, first: int = 0, step: int = 1) -> int:
    """Solve lines first, first + step, ... of the job (job_path; None: read `path [first step]` from stdin once the
    imports are done, so the parent can start the worker first and write the job meanwhile), streaming the
    solutions to the binary stream `out`."""
    import scipy.sparse  # noqa: F401  (imported while the parent writes the job)
    from petsc4py import PETSc

    from housingfe.solvers.mumps import SingularMatrix, set_up_factor

    if not np.issubdtype(PETSc.ScalarType, np.complexfloating):
        print("the complex PETSc build was not selected (PETSC_DIR/SLEPC_DIR)", file=sys.stderr)
        return 2
    if job_path is None:
        words = sys.stdin.readline().split()
        job_path = words[0]
        if len(words) == 3:
            first, step = int(words[1]), int(words[2])
    job = dict(np.load(job_path))
    for name in ("M", "D", "C"):   # a matrix sent without its pattern shares K's
        if f"{name}_data" in job and f"{name}_indptr" not in job:
            job[f"{name}_indptr"], job[f"{name}_indices"] = job["K_indptr"], job["K_indices"]
    names = ["K", "M"] + [m for m in ("D", "C") if f"{m}_data" in job]
    indptr, indices, datas = _on_union([_csr(job, m) for m in names])
    loads = job["loads"]
    n = loads.shape[1]
    use_D, symmetric = bool(job["use_D"]), bool(job["symmetric"])
    if symmetric:
        # the upper triangle only, as SBAIJ: half the entries to recombine per line and to hand to MUMPS' LDL^T
        # (which reads only the upper triangle anyway): 1.47 -> 1.3 s per line at 39 k DOFs
        indptr, indices, datas = _upper_triangle(indptr, indices, datas)
        A = PETSc.Mat().createSBAIJ((n, n), 1, csr=(indptr, indices, np.zeros(len(indices), complex)),
                                    comm=PETSc.COMM_SELF)
    else:
        A = PETSc.Mat().createAIJ((n, n), csr=(indptr, indices, np.zeros(len(indices), complex)),
                                  comm=PETSc.COMM_SELF)
    A.setOption(PETSc.Mat.Option.SYMMETRIC, symmetric)
    data = dict(zip(names, datas))
    block_size = int(job.get("block_size", 1))
    ksp = _factor_solver(A, symmetric, block_size)
    rhs = PETSc.Mat().createDense((n, len(loads)), array=np.asfortranarray(loads.T.astype(complex)),
                                  comm=PETSc.COMM_SELF)
    sol_mat = PETSc.Mat().createDense((n, len(loads)), array=np.zeros((n, len(loads)), complex, order="F"),
                                      comm=PETSc.COMM_SELF)
    residual = A.createVecLeft()
    load_norms = np.abs(loads).max(axis=1)
    values = np.empty(len(indices), complex)
    work = np.empty(len(indices))
    rows = np.repeat(np.arange(n, dtype=np.int32), np.diff(indptr))
    norms = {name: _inf_norm(rows, indices, d, n, symmetric) for name, d in data.items()}
    del rows
    for k in range(first, len(job["omega"]), step):
        w, eta = job["omega"][k], job["eta"][k]
        # values = K + i (D or eta K) + i omega C - omega^2 M, in place (5 M entries at 39 k DOFs: temporaries cost)
        np.multiply(data["M"], -w * w, out=work)
        work += data["K"]
        values.real = work
        if use_D:
            values.imag = data["D"]
        else:
            np.multiply(data["K"], eta, out=work)
            values.imag = work
        if "C" in data:
            np.multiply(data["C"], w, out=work)
            values.imag += work
        A.setValuesCSR(indptr, indices, values)   # same pattern: the symbolic factorisation is kept
        A.assemble()
        # ||A||_inf bounded by the parts' norms: the backward error below is then a lower bound's safe side
        a_norm = (norms["K"] * (1.0 if use_D else abs(complex(1.0, eta))) + w * w * norms["M"]
                  + (norms["D"] if use_D else 0.0) + (w * norms["C"] if "C" in norms else 0.0))
        t0 = time.perf_counter()
        factorisations = 0
        try:
            while True:
                ksp.setOperators(A)   # marks the operator changed: setUp redoes the numerical factorisation only
                # a failed factor raises (a short workspace is grown on a new factor, kept for later lines)
                ksp = set_up_factor(lambda percent: _factor_solver(A, symmetric, block_size, percent), ksp,
                                    what=f"direct solver, line {k}")
                factorisations += 1
                ksp.getPC().getFactorMatrix().matSolve(rhs, sol_mat)
                sol = sol_mat.getDenseArray().T.copy()
                error = _backward_error(A, sol, loads, residual, a_norm, load_norms)
                if error <= BACKWARD_ERROR_TOL or not _scaling_off(ksp):
                    break
                # unscaled pivoting was not accurate enough on this line: MUMPS' scaling from here on (decided in
                # the analysis, so a new factor: setMumpsIcntl on the old one changes nothing, measured)
                ksp.destroy()
                PETSc.Options()["direct_mat_mumps_icntl_8"] = 77
                ksp = _factor_solver(A, symmetric, block_size)
        except (SingularMatrix, PETSc.Error):
            print(f"SINGULAR {k}", file=sys.stderr)
            return SINGULAR_EXIT
        t_factor = time.perf_counter() - t0
        if not np.all(np.isfinite(sol)):
            print(f"SINGULAR {k}", file=sys.stderr)
            return SINGULAR_EXIT
        out.write(np.array([t_factor, float(factorisations), error], np.float64).tobytes())
        out.write(sol.tobytes())
        out.flush()
    return 0


if __name__ == "__main__":
    raise SystemExit(run(sys.argv[1] if len(sys.argv) > 1 and sys.argv[1] != "-" else None, sys.stdout.buffer))
