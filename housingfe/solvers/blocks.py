"""Blocks of PETSc vectors as dense arrays: one sparse matrix-times-block product and one dense product where a
loop would do a matrix-vector product and n dot products per vector (the Ritz reduction's Gram matrices and energy
shares: 91 vectors on 65 k DOFs, 8 281 dot products -> one gemm)."""
from __future__ import annotations

import numpy as np
from petsc4py import PETSc


def columns(vectors) -> np.ndarray:
    """(local rows, len(vectors)) array of the vectors' local values (a copy)."""
    if not vectors:
        raise ValueError("columns: no vectors")
    return np.column_stack([v.getArray(readonly=True) for v in vectors])


def aij_product(A: PETSc.Mat, X: np.ndarray) -> np.ndarray | None:
    """A X (C order) for a sequential AIJ matrix A (one rank) by scipy's CSR kernel on PETSc's own arrays (no copy
    of A), else None.  Each entry is the same sum in the same order as PETSc's MatMatMult (row entries in column
    order from zero, no fused multiply-add): the same bits (checked on the coupled test gearbox's M, 8 / 31 / 66
    columns), in 27 instead of 33 ms for 8 columns on 65 k DOFs (4.7 M entries)."""
    if A.getType() != "seqaij" or A.getComm().getSize() != 1:
        return None
    import scipy.sparse as sp

    from housingfe.solvers.mumps import _local_blocks

    X = np.ascontiguousarray(X, dtype=float)
    with _local_blocks(A) as parts:
        if len(parts) != 1 or parts[0][3] is not None:
            return None
        ia, ja, va, _, _ = parts[0]
        return sp.csr_matrix((va, ja, ia), shape=A.getSize(), copy=False) @ X


def mat_block(A: PETSc.Mat, X: np.ndarray) -> np.ndarray:
    """A X (local rows of the result, Fortran order) for a dense block X of A's local column rows."""
    fast = aij_product(A, X)
    if fast is not None:
        return np.asfortranarray(fast)          # PETSc's dense layout: the products downstream keep their bits
    X = np.asfortranarray(X, dtype=float)
    comm = A.getComm()
    D = PETSc.Mat().createDense([(X.shape[0], A.getSize()[1]), (X.shape[1], X.shape[1])], array=X, comm=comm)
    Y = A.matMult(D)
    out = np.array(Y.getDenseArray(), copy=True)
    Y.destroy()
    D.destroy()
    return out


def gram(X: np.ndarray, Y: np.ndarray, comm) -> np.ndarray:
    """X^T Y summed over the ranks of `comm` (a PETSc or mpi4py communicator)."""
    local = X.T @ Y
    mpi = comm.tompi4py() if hasattr(comm, "tompi4py") else comm
    return mpi.allreduce(local) if mpi.Get_size() > 1 else local


def csr_difference(A_old, A_new, rows: int):
    """A_new - A_old (scipy CSR, zeros dropped) of two PETSc AIJ matrices on one rank (None counts as zero), or
    None when either is not an AIJ matrix of `rows` rows."""
    import scipy.sparse as sp

    def csr(A):
        if A is None:
            return sp.csr_matrix((rows, rows))
        try:
            ptr, idx, val = A.getValuesCSR()
        except PETSc.Error:
            return None
        return sp.csr_matrix((val, idx, ptr), shape=A.getSize())

    a, b = csr(A_old), csr(A_new)
    if a is None or b is None or a.shape != (rows, rows) or b.shape != (rows, rows):
        return None
    if a.nnz == b.nnz and np.array_equal(a.indptr, b.indptr) and np.array_equal(a.indices, b.indices):
        d = sp.csr_matrix((b.data - a.data, a.indices, a.indptr), shape=a.shape)
    else:
        d = b - a
    d.eliminate_zeros()
    return d
