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


def mat_block(A: PETSc.Mat, X: np.ndarray) -> np.ndarray:
    """A X (local rows of the result) for a dense block X of A's local column rows."""
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
