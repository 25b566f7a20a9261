"""Complex-valued direct harmonic solve in its own process (complex PETSc build, one rank).

Started by `housingfe.solvers.harmonic.direct` as `python -m housingfe.solvers._complex_worker job.npz` with
PETSC_DIR / SLEPC_DIR selecting the complex build (one process cannot hold both builds, see
docs/forced-response.md).  Per line it factorises A = K_r + i K_i (n x n complex, MUMPS LDL^T when symmetric,
LU otherwise) instead of the real 2n x 2n block form, and the sparsity pattern is the same on every line, so the
ordering and symbolic analysis are done once and only the numerical factorisation is repeated.

job.npz: K, M (and D, C when given) as CSR arrays <name>_indptr/_indices/_data (real), loads (n_loads, n) real,
omega (rad/s) and eta per line, use_D (D replaces eta K), symmetric.
stdout, per line: one float64 (numerical factorisation seconds), then the solutions (n_loads, n) complex128.
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


def run(job_path: str, out) -> int:
    from petsc4py import PETSc

    if not np.issubdtype(PETSc.ScalarType, np.complexfloating):
        print("the complex PETSc build was not selected (PETSC_DIR/SLEPC_DIR)", file=sys.stderr)
        return 2
    job = dict(np.load(job_path))
    names = ["K", "M"] + [m for m in ("D", "C") if f"{m}_data" in job]
    indptr, indices, datas = _on_union([_csr(job, m) for m in names])
    data = dict(zip(names, datas))
    loads = job["loads"]
    n = loads.shape[1]
    use_D, symmetric = bool(job["use_D"]), bool(job["symmetric"])
    A = PETSc.Mat().createAIJ((n, n), csr=(indptr, indices, np.zeros(len(indices), complex)), comm=PETSc.COMM_SELF)
    A.setOption(PETSc.Mat.Option.SYMMETRIC, symmetric)
    ksp = PETSc.KSP().create(PETSc.COMM_SELF)
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.setErrorIfNotConverged(True)   # a failed factorisation raises instead of returning inf/nan
    pc = ksp.getPC()
    pc.setType("cholesky" if symmetric else "lu")   # complex symmetric (not Hermitian): MUMPS LDL^T, sym = 2
    pc.setFactorSolverType("mumps")
    b, x = A.createVecs()
    for k, (w, eta) in enumerate(zip(job["omega"], job["eta"])):
        values = data["K"] + 1j * (data["D"] if use_D else eta * data["K"]) - w * w * data["M"]
        if "C" in data:
            values = values + 1j * w * data["C"]
        A.setValuesCSR(indptr, indices, values)   # same pattern: the symbolic factorisation is kept
        A.assemble()
        t0 = time.perf_counter()
        try:
            ksp.setUp()
        except PETSc.Error:
            print(f"SINGULAR {k}", file=sys.stderr)
            return SINGULAR_EXIT
        t_factor = time.perf_counter() - t0
        sol = np.empty((len(loads), n), complex)
        try:
            for j, f in enumerate(loads):
                b.setArray(f.astype(complex))
                ksp.solve(b, x)
                sol[j] = x.getArray()
        except PETSc.Error:
            print(f"SINGULAR {k}", file=sys.stderr)
            return SINGULAR_EXIT
        if not np.all(np.isfinite(sol)):
            print(f"SINGULAR {k}", file=sys.stderr)
            return SINGULAR_EXIT
        out.write(np.float64(t_factor).tobytes())
        out.write(sol.tobytes())
        out.flush()
    return 0


if __name__ == "__main__":
    raise SystemExit(run(sys.argv[1], sys.stdout.buffer))
