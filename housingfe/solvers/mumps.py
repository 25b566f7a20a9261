"""MUMPS' LDL^T of a symmetric PETSc matrix, for the modal solve: one analysis, a factorisation for the
inertia count, a refactorisation at the shift, then blocks of right-hand sides.

Two interchangeable back-ends behind one interface (`ldlt(A)` picks):
- `DirectLDLT` calls the MUMPS library that PETSc itself links (Debian's libdmumps-5.5) through cffi.  Why
  not only PETSc's interface: in parallel, PETSc 3.18's MatMatSolve for MUMPS builds a new scatter of the
  distributed solution on every call (1.2 M indices for 8 right-hand sides at 309 k DOFs on 2 ranks: 23 % of
  each block solve, 268 vs 203 ms); here the map from MUMPS' solution rows to PETSc's rows is built once per
  factorisation and applied with one MPI all-to-all.
- `PetscLDLT`, PETSc's KSP/PCCholesky with MUMPS: the choice on one rank (no scatter there) and the fall-back
  where that library or cffi is missing.

Both use the same MUMPS controls as PETSc's defaults (node-block compression ICNTL(15) = -bs, PORD ordering,
which is what this MUMPS build has: it carries neither METIS nor SCOTCH) plus the inertia's (no ScaLAPACK
root, null-pivot detection for the count), so they give the same factors.
"""
from __future__ import annotations

from contextlib import contextmanager

import numpy as np
from petsc4py import PETSc

from housingfe.errors import SolverError

MUMPS_LIBRARY = "libdmumps-5.5.so"
# INFOG(1) of a workspace that the analysis' estimate left too small (MUMPS 5.5 users' guide, "Error
# diagnostics": -8 integer array IS, -9 real array S, -11/-12 S for the solve or the elimination, -14/-15 integer
# workspace); each is cured by a larger ICNTL(14).  Up to WORKSPACE_RETRIES doublings of it (20 % -> 1280 %).
_WORKSPACE_SHORT = (-8, -9, -11, -12, -14, -15)
WORKSPACE_RETRIES = 6
MUMPS_VERSION_PREFIX = "5.5."

# DMUMPS_STRUC_C of MUMPS 5.5 (dmumps_c.h, MUMPS_INT = int: Debian's 32-bit-index build)
_CDEF = """
typedef struct {
    int sym, par, job; int comm_fortran; int icntl[60]; int keep[500]; double cntl[15]; double dkeep[230];
    int64_t keep8[150]; int n; int nblk; int nz_alloc;
    int nz; int64_t nnz; int *irn; int *jcn; double *a;
    int nz_loc; int64_t nnz_loc; int *irn_loc; int *jcn_loc; double *a_loc;
    int nelt; int *eltptr; int *eltvar; double *a_elt; int *blkptr; int *blkvar;
    int *perm_in; int *sym_perm; int *uns_perm; double *colsca; double *rowsca;
    int colsca_from_mumps; int rowsca_from_mumps;
    double *rhs, *redrhs, *rhs_sparse, *sol_loc, *rhs_loc;
    int *irhs_sparse, *irhs_ptr, *isol_loc, *irhs_loc;
    int nrhs, lrhs, lredrhs, nz_rhs, lsol_loc, nloc_rhs, lrhs_loc;
    int schur_mloc, schur_nloc, schur_lld; int mblock, nblock, nprow, npcol;
    int info[80], infog[80]; double rinfo[40], rinfog[40];
    int deficiency; int *pivnul_list; int *mapping; int size_schur; int *listvar_schur; double *schur;
    int instance_number; double *wk_user;
    char version_number[32]; char ooc_tmpdir[256]; char ooc_prefix[64]; char write_problem[256];
    int lwk_user; char save_dir[256]; char save_prefix[256]; int metis_options[40];
} DMUMPS_STRUC_C;
void dmumps_c(DMUMPS_STRUC_C *);
"""
_JOB_INIT, _JOB_END, _JOB_ANALYSE, _JOB_FACTORISE, _JOB_SOLVE = -1, -2, 1, 2, 3
_binding = None


def _load():
    """(ffi, lib) of the MUMPS library, or None when it or cffi is missing or PETSc's scalars are complex."""
    global _binding
    if _binding is None:
        _binding = False
        if PETSc.ScalarType is np.float64:
            try:
                from cffi import FFI

                ffi = FFI()
                ffi.cdef(_CDEF)
                _binding = (ffi, ffi.dlopen(MUMPS_LIBRARY))
            except (ImportError, OSError):
                pass
    return _binding or None


# PETSc's own arrays of an AIJ matrix (no copy), as PETSc's MUMPS interface reads them: this rank's rows of a
# 309 k-DOF model are 46 M stored entries, and every fresh page costs (first touch is ~1.5 s per GB on this VM)
_PETSC_CDEF = """
typedef struct _p_Mat *Mat;
int MatMPIAIJGetSeqAIJ(Mat, Mat *, Mat *, const int **);
int MatGetSize(Mat, int *, int *);
int MatGetRowIJ(Mat, int, int, int, int *, const int **, const int **, int *);
int MatRestoreRowIJ(Mat, int, int, int, int *, const int **, const int **, int *);
int MatSeqAIJGetArrayRead(Mat, const double **);
int MatSeqAIJRestoreArrayRead(Mat, const double **);
"""
_petsc_binding = None


def _petsc():
    """(ffi, lib) of the PETSc library this process runs (32-bit PetscInt, real scalars), or None."""
    global _petsc_binding
    if _petsc_binding is None:
        _petsc_binding = False
        if PETSc.IntType is np.int32 and PETSc.ScalarType is np.float64:
            try:
                import re

                from cffi import FFI

                with open("/proc/self/maps") as maps:
                    found = re.search(r"(/\S*/libpetsc\S*\.so\S*)", maps.read())
                if found:
                    ffi = FFI()
                    ffi.cdef(_PETSC_CDEF)
                    _petsc_binding = (ffi, ffi.dlopen(found.group(1)))
            except (ImportError, OSError):
                pass
    return _petsc_binding or None


@contextmanager
def _local_blocks(A: PETSc.Mat):
    """This rank's rows of A as CSR blocks (ia, ja, values, colmap, offset): global column = colmap[ja] if
    colmap is given, else ja + offset.  Views of PETSc's arrays for seqaij / mpiaij (the diagonal and the
    off-diagonal block), valid inside the context; a copy (getValuesCSR) for other types."""
    petsc = _petsc()
    kind = A.getType()
    r0 = A.getOwnershipRange()[0]
    if petsc is None or kind not in ("seqaij", "mpiaij"):
        ia, ja, va = A.getValuesCSR()
        yield [(ia, ja, va, None, 0)]
        return
    ffi, lib = petsc
    mat = ffi.cast("Mat", A.handle)
    parts = [(mat, None, r0)]
    if kind == "mpiaij":
        Ad, Ao, colmap = ffi.new("Mat *"), ffi.new("Mat *"), ffi.new("const int **")
        _petsc_call(lib.MatMPIAIJGetSeqAIJ(mat, Ad, Ao, colmap))
        rows, columns = ffi.new("int *"), ffi.new("int *")
        _petsc_call(lib.MatGetSize(Ao[0], rows, columns))
        cmap = _view(ffi, colmap[0], columns[0], np.int32)
        parts = [(Ad[0], None, r0), (Ao[0], cmap, 0)]
    opened = []
    try:
        blocks = []
        for m, cmap, offset in parts:
            n, ia, ja = ffi.new("int *"), ffi.new("const int **"), ffi.new("const int **")
            done, va = ffi.new("int *"), ffi.new("const double **")
            _petsc_call(lib.MatGetRowIJ(m, 0, 0, 0, n, ia, ja, done))
            opened.append((m, n, ia, ja, done, va))
            if not done[0]:
                raise SolverError("MUMPS LDL^T: PETSc gave no row structure of the matrix")
            _petsc_call(lib.MatSeqAIJGetArrayRead(m, va))
            ia_view = _view(ffi, ia[0], n[0] + 1, np.int32)
            nnz = int(ia_view[-1])
            blocks.append((ia_view, _view(ffi, ja[0], nnz, np.int32), _view(ffi, va[0], nnz, np.float64), cmap,
                           offset))
        yield blocks
    finally:
        for m, n, ia, ja, done, va in opened:
            if va[0] != ffi.NULL:
                lib.MatSeqAIJRestoreArrayRead(m, va)
            lib.MatRestoreRowIJ(m, 0, 0, 0, n, ia, ja, done)


def _view(ffi, pointer, count: int, dtype) -> np.ndarray:
    if count == 0:
        return np.zeros(0, dtype=dtype)
    return np.frombuffer(ffi.buffer(pointer, count * np.dtype(dtype).itemsize), dtype=dtype)


def _petsc_call(code: int) -> None:
    if code:
        raise SolverError(f"MUMPS LDL^T: a PETSc call failed (error code {code})")


def _upper_triangle(blocks, r0: int):
    """(irn, jcn, masks): 1-based rows and columns of the entries on or above the diagonal (what MUMPS reads
    of a symmetric matrix), and per block the mask that picks their values."""
    irn, jcn, masks = [], [], []
    for ia, ja, va, colmap, offset in blocks:
        rows = np.repeat(np.arange(len(ia) - 1, dtype=np.int32), np.diff(ia))   # local rows
        columns = ja if colmap is None else colmap[ja]
        mask = columns >= rows + (r0 - (offset if colmap is None else 0))
        irn.append(rows[mask] + np.int32(r0 + 1))
        jcn.append(columns[mask] + np.int32((offset if colmap is None else 0) + 1))
        masks.append(mask)
    return np.concatenate(irn), np.concatenate(jcn), masks


def available() -> bool:
    """True when DirectLDLT can run here."""
    return _load() is not None


def ldlt(A: PETSc.Mat, backend: str = "auto", count_only: bool = False, workspace_percent: int | None = None):
    """An LDL^T of A, analysed, not factorised: a DirectLDLT for backend "direct", and for "auto" on more than
    one rank when it is available; else a PetscLDLT.  On one rank PETSc's interface solves in place and the
    direct one only adds its conversion of the entries (S2R box, 40 k DOFs, 3 alternating fresh runs: 0.2-0.4 s
    slower).  count_only: its factorisations only give the inertia (MUMPS discards the factors as it
    goes, ICNTL(31) = 1, a choice of the analysis): 309 k DOFs on 2 ranks, 6.2 instead of 9.2 s and 2.9 instead
    of 3.6 GB per rank.  workspace_percent: MUMPS' ICNTL(14) for the first factorisation (default MUMPS' 20);
    where the workspace proves short it is doubled and the factorisation repeated (WORKSPACE_RETRIES times)."""
    if backend not in ("auto", "direct", "petsc"):
        raise ValueError(f"unknown MUMPS back-end {backend!r}: choose from auto, direct, petsc")
    if backend == "direct" or (backend == "auto" and A.getComm().getSize() > 1 and available()):
        return DirectLDLT(A, count_only, workspace_percent)
    return PetscLDLT(A, count_only, workspace_percent)


class DirectLDLT:
    """MUMPS LDL^T (SYM = 2) of a symmetric PETSc AIJ matrix A through cffi: distributed input (the upper
    triangle of each rank's rows), distributed right-hand sides and solutions on more than one rank."""

    def __init__(self, A: PETSc.Mat, count_only: bool = False, workspace_percent: int | None = None):
        binding = _load()
        if binding is None:
            raise SolverError(f"MUMPS through cffi is not available ({MUMPS_LIBRARY})")
        self._ffi, self._lib = binding
        self.comm = A.getComm().tompi4py().Dup()   # MUMPS does not duplicate it: keep its messages apart
        self.rows = A.getSize()[0]
        self.r0, self.r1 = A.getOwnershipRange()
        ffi = self._ffi
        self.id = ffi.new("DMUMPS_STRUC_C *")
        self.id.sym, self.id.par, self.id.comm_fortran = 2, 1, self.comm.py2f()
        self._call(_JOB_INIT)
        version = ffi.string(self.id.version_number).decode().strip()
        if not version.startswith(MUMPS_VERSION_PREFIX):
            self.destroy()
            raise SolverError(f"{MUMPS_LIBRARY} reports MUMPS {version}, this binding is for "
                              f"{MUMPS_VERSION_PREFIX}x")
        for i, v in ((1, -1), (2, -1), (3, -1), (4, 0),   # silent
                     (13, 1),                             # no ScaLAPACK root: the inertia is exact in parallel
                     (18, 3),                             # distributed assembled input
                     (24, 1),                             # null-pivot detection: a singular A is reported
                     (31, 1 if count_only else 0)):
            self._icntl(i, v)
        if workspace_percent is not None:
            self._icntl(14, int(workspace_percent))       # the first factorisation's; it doubles where short
        bs = A.getBlockSize()
        if bs > 1:
            self._icntl(15, -bs)                          # the graph of nodes, as PETSc sets it
        with _local_blocks(A) as blocks:
            self._irn, self._jcn, self._masks = _upper_triangle(blocks, self.r0)
            self._values = np.empty(len(self._irn))
            self._take_values(blocks)
        self.id.n = self.rows
        self.id.nnz_loc = len(self._irn)
        self.id.irn_loc = ffi.cast("int *", self._irn.ctypes.data)
        self.id.jcn_loc = ffi.cast("int *", self._jcn.ctypes.data)
        self.id.a_loc = ffi.cast("double *", self._values.ctypes.data)
        self._call(_JOB_ANALYSE)
        self._to_petsc = None

    def factorise(self, A: PETSc.Mat) -> None:
        """Numerical factorisation of A (the pattern of the analysis)."""
        from mpi4py import MPI

        with _local_blocks(A) as blocks:
            changed = [len(b[1]) for b in blocks] != [len(m) for m in self._masks]
            if self.comm.allreduce(changed, op=MPI.LOR):     # every rank stops, none waits in MUMPS
                raise SolverError("MUMPS LDL^T: the matrix changed its sparsity pattern since the analysis")
            self._take_values(blocks)
        # MUMPS sizes its workspace from the analysis plus ICNTL(14) per cent; delayed pivots of an indefinite
        # matrix can need more (INFOG(1) = -9 and kin, seen on 2 ranks of a shifted K - sigma M): the users'
        # guide's remedy is a larger ICNTL(14) and the factorisation again.  INFOG is global: all ranks retry.
        for attempt in range(WORKSPACE_RETRIES + 1):
            self.id.job = _JOB_FACTORISE
            self._lib.dmumps_c(self.id)
            if self.id.infog[0] not in _WORKSPACE_SHORT or attempt == WORKSPACE_RETRIES:
                break
            self._icntl(14, 2 * max(int(self.id.icntl[13]), 20))
        self._check(_JOB_FACTORISE)
        self._to_petsc = None
        self._solution_rows = int(self.id.info[22])     # INFO(23)

    def _take_values(self, blocks) -> None:
        at = 0
        for (ia, ja, va, colmap, offset), mask in zip(blocks, self._masks):
            count = int(np.count_nonzero(mask))
            np.compress(mask, va, out=self._values[at:at + count])
            at += count

    def inertia(self) -> tuple[int, int]:
        """(negative pivots, null pivots) of the last factorisation (INFOG(12), INFOG(28))."""
        return int(self.id.infog[11]), int(self.id.infog[27])

    def solve_block(self, B: np.ndarray) -> np.ndarray:
        """X = A^-1 B for this rank's rows B (rows x right-hand sides)."""
        ffi = self._ffi
        n_local, nrhs = B.shape
        self.id.nrhs = nrhs
        if self.comm.size == 1:                           # centralised: solved in place
            X = np.array(B, dtype=np.float64, order="F")
            self._icntl(20, 0)
            self._icntl(21, 0)
            self.id.lrhs = self.rows
            self.id.rhs = ffi.cast("double *", X.ctypes.data)
            self._call(_JOB_SOLVE)
            return X
        B = np.asfortranarray(B, dtype=np.float64)
        if self._to_petsc is None:
            self._isol = np.zeros(self._solution_rows, dtype=np.int32)
            self._irhs = np.arange(self.r0 + 1, self.r1 + 1, dtype=np.int32)
        solution = np.empty((self._solution_rows, nrhs), order="F")
        self._icntl(20, 10)
        self._icntl(21, 1)
        self.id.nloc_rhs = self.id.lrhs_loc = n_local
        self.id.rhs_loc = ffi.cast("double *", B.ctypes.data)
        self.id.irhs_loc = ffi.cast("int *", self._irhs.ctypes.data)
        self.id.lsol_loc = self._solution_rows
        self.id.sol_loc = ffi.cast("double *", solution.ctypes.data)
        self.id.isol_loc = ffi.cast("int *", self._isol.ctypes.data)
        self._call(_JOB_SOLVE)
        if self._to_petsc is None:
            self._to_petsc = _RowExchange(self.comm, self._isol - 1, self.r0, self.r1, self.rows)
        return self._to_petsc(solution, n_local)

    def solve(self, b: PETSc.Vec, x: PETSc.Vec) -> None:
        """x = A^-1 b (PETSc vectors with A's row layout)."""
        x.getArray()[:] = self.solve_block(b.getArray(readonly=True)[:, None])[:, 0]

    def destroy(self) -> None:
        if self.id is not None:
            self.id.job = _JOB_END
            self._lib.dmumps_c(self.id)
            self.id = None
            self.comm.Free()

    def _icntl(self, i: int, value: int) -> None:
        self.id.icntl[i - 1] = value

    def _call(self, job: int) -> None:
        self.id.job = job
        self._lib.dmumps_c(self.id)
        self._check(job)

    def _check(self, job: int) -> None:
        if self.id.infog[0] < 0:
            raise SolverError(f"MUMPS failed (job {job}): INFOG(1) = {self.id.infog[0]}, "
                              f"INFOG(2) = {self.id.infog[1]} (see the MUMPS users' guide, error diagnostics)")


class _RowExchange:
    """Moves rows of MUMPS' distributed solution (global row indices `rows`) to the ranks that own them in
    PETSc's layout [r0, r1): built once per factorisation, one MPI all-to-all per block."""

    def __init__(self, comm, rows: np.ndarray, r0: int, r1: int, size: int):
        from mpi4py import MPI

        starts = np.array(comm.allgather(r0) + [size])
        owner = np.searchsorted(starts, rows, side="right") - 1
        self.order = np.argsort(owner, kind="stable")
        self.send = np.bincount(owner, minlength=comm.size).astype(np.int64)
        self.recv = np.array(comm.alltoall(list(self.send)), dtype=np.int64)
        self.send_at = np.concatenate([[0], np.cumsum(self.send)[:-1]])
        self.recv_at = np.concatenate([[0], np.cumsum(self.recv)[:-1]])
        arriving = np.empty(int(self.recv.sum()), dtype=np.int64)
        comm.Alltoallv([np.ascontiguousarray(rows[self.order], dtype=np.int64), (self.send, self.send_at),
                        MPI.INT64_T], [arriving, (self.recv, self.recv_at), MPI.INT64_T])
        self.local_rows = arriving - r0
        self.comm, self.mpi_double = comm, MPI.DOUBLE

    def __call__(self, solution: np.ndarray, n_local: int) -> np.ndarray:
        k = solution.shape[1]
        outgoing = np.ascontiguousarray(solution[self.order])
        incoming = np.empty((int(self.recv.sum()), k))
        self.comm.Alltoallv([outgoing, (self.send * k, self.send_at * k), self.mpi_double],
                            [incoming, (self.recv * k, self.recv_at * k), self.mpi_double])
        X = np.empty((n_local, k))
        X[self.local_rows] = incoming
        return X


class PetscLDLT:
    """The same interface on PETSc's KSP/PCCholesky with MUMPS (one rank, and the fall-back of DirectLDLT)."""

    def __init__(self, A: PETSc.Mat, count_only: bool = False, workspace_percent: int | None = None):
        self.count_only = count_only
        self.rows = A.getSize()[0]
        self.ksp = self._new_factor(A, workspace_percent)
        self.factor = self.ksp.getPC().getFactorMatrix()

    def _new_factor(self, A: PETSc.Mat, workspace_percent: int | None) -> PETSc.KSP:
        ksp = mumps_cholesky(A, "ldlt_", inertia=True)
        ksp.getPC().setFactorSetUpSolverType()
        # on this factor, not in the options database: other solvers under the prefix keep their factors
        ksp.getPC().getFactorMatrix().setMumpsIcntl(31, 1 if self.count_only else 0)
        set_workspace(ksp, workspace_percent)
        return ksp

    def factorise(self, A: PETSc.Mat) -> None:
        """Numerical factorisation of A (the pattern of the analysis)."""
        self.ksp.setOperators(A)
        # a failed factor would report the inertia of its partial elimination: set_up_factor raises instead
        self.ksp = set_up_factor(lambda percent: self._new_factor(A, percent), self.ksp, what="MUMPS LDL^T")
        self.factor = self.ksp.getPC().getFactorMatrix()

    def inertia(self) -> tuple[int, int]:
        negative, null, _ = self.factor.getInertia()
        return int(negative), int(null)

    def solve_block(self, B: np.ndarray) -> np.ndarray:
        D = PETSc.Mat().createDense([(B.shape[0], self.rows), (B.shape[1], B.shape[1])],
                                    array=np.asfortranarray(B), comm=self.factor.getComm())
        X = D.duplicate()
        self.factor.matSolve(D, X)
        out = np.array(X.getDenseArray())
        X.destroy()
        D.destroy()
        return out

    def solve(self, b: PETSc.Vec, x: PETSc.Vec) -> None:
        self.ksp.solve(b, x)

    def destroy(self) -> None:
        self.ksp.destroy()


def mumps_cholesky(A: PETSc.Mat, prefix: str, inertia: bool = False) -> PETSc.KSP:
    """A direct solver for a symmetric A: MUMPS LDL^T (Cholesky when A is positive definite) through PETSc's
    KSP.  With `inertia`, the factor can report its inertia (no ScaLAPACK root, null-pivot detection on)."""
    ksp = PETSc.KSP().create(A.getComm())
    ksp.setOptionsPrefix(prefix)
    ksp.setOperators(A)
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType("cholesky")
    pc.setFactorSolverType("mumps")
    if inertia:
        opts = PETSc.Options()
        opts[f"{prefix}mat_mumps_icntl_13"] = 1   # no ScaLAPACK root: required for the inertia in parallel
        opts[f"{prefix}mat_mumps_icntl_24"] = 1   # null-pivot detection: MatGetInertia requires it
    ksp.setFromOptions()
    return ksp


# INFOG(1) = -10: MUMPS found the matrix numerically singular
_SINGULAR = -10


class SingularMatrix(SolverError):
    """MUMPS found the matrix numerically singular (INFOG(1) = -10): callers may say why (a resonance, no
    supports)."""


def set_workspace(ksp: PETSc.KSP, workspace_percent: int | None) -> None:
    """ICNTL(14) (per cent of extra workspace over the analysis' estimate) on the MUMPS factor of ksp's PC; None
    leaves MUMPS' default (20) or the options database's value.  PETSc applies -<prefix>mat_mumps_icntl_14 at the
    analysis, over the factor's own ICNTL(14): a smaller value there is raised to workspace_percent (it proved
    short)."""
    if workspace_percent is not None:
        key = f"{ksp.getOptionsPrefix() or ''}mat_mumps_icntl_14"
        options = PETSc.Options()
        if options.hasName(key) and options.getInt(key) < workspace_percent:
            options[key] = int(workspace_percent)
        pc = ksp.getPC()
        pc.setFactorSetUpSolverType()
        pc.getFactorMatrix().setMumpsIcntl(14, int(workspace_percent))


def factor_status(ksp: PETSc.KSP) -> tuple[int, int] | None:
    """(INFOG(1), INFOG(2)) of the MUMPS factor of ksp's PC after its set-up, or None when the PC is no MUMPS
    factorisation (user options chose another) or has none yet."""
    pc = ksp.getPC()
    if pc.getType() not in ("lu", "cholesky") or pc.getFactorSolverType() != "mumps":
        return None
    try:
        factor = pc.getFactorMatrix()
        return int(factor.getMumpsInfog(1)), int(factor.getMumpsInfog(2))
    except PETSc.Error:
        return None


def set_up_factor(make_ksp, ksp: PETSc.KSP | None = None, what: str = "MUMPS") -> PETSc.KSP:
    """The KSP of a MUMPS factorisation through PETSc, set up and checked: the one way the package factorises with
    MUMPS through PETSc.  make_ksp(workspace_percent) builds the KSP with its operators (workspace_percent: None,
    or ICNTL(14) to set with set_workspace); `ksp`: one already built (its operators changed: set-up refactorises
    it), else make_ksp(None) is called.

    Through PETSc 3.18 a failed MUMPS factorisation does not raise (unless the KSP errors if not converged): the
    factor keeps INFOG(1) < 0 and a solve then diverges or returns garbage.  Here a workspace too small
    (INFOG(1) in _WORKSPACE_SHORT, e.g. -9 from the delayed pivots of an indefinite matrix) gets a new KSP with
    twice the ICNTL(14) (PETSc never refactorises a factor whose MUMPS call failed), up to WORKSPACE_RETRIES times;
    any other failure raises SolverError ("singular matrix" for INFOG(1) = -10).  Collective; INFOG is global, so
    every rank takes the same branch.  The returned KSP may differ from `ksp` (which is then destroyed)."""
    ksp = make_ksp(None) if ksp is None else ksp
    for attempt in range(WORKSPACE_RETRIES + 1):
        try:
            ksp.setUp()
            raised = None
        except PETSc.Error as exc:     # a KSP that errors if not converged raises on a failed factorisation
            raised = exc
        status = factor_status(ksp)
        if status is None:
            if raised is not None:
                ksp.destroy()
                raise SolverError(f"{what}: the factorisation failed ({raised})") from raised
            return ksp
        info1, info2 = status
        if info1 >= 0:
            if raised is None:
                return ksp
            ksp.destroy()
            raise SolverError(f"{what}: the set-up failed ({raised})") from raised
        if info1 not in _WORKSPACE_SHORT or attempt == WORKSPACE_RETRIES:
            break
        percent = 2 * max(int(ksp.getPC().getFactorMatrix().getMumpsIcntl(14)), 20)
        ksp.destroy()
        ksp = make_ksp(percent)
    ksp.destroy()
    raise _failure(what, info1, info2)


def _failure(what: str, info1: int, info2: int) -> SolverError:
    if info1 == _SINGULAR:
        return SingularMatrix(f"{what}: singular matrix (MUMPS INFOG(1) = {info1}, INFOG(2) = {info2})")
    if info1 in _WORKSPACE_SHORT:
        return SolverError(f"{what}: MUMPS' workspace too small (after up to {WORKSPACE_RETRIES} doublings of "
                           f"ICNTL(14)): INFOG(1) = {info1}, INFOG(2) = {info2}")
    return SolverError(f"{what}: MUMPS failed: INFOG(1) = {info1}, INFOG(2) = {info2} (see the MUMPS users' "
                       "guide, error diagnostics)")


def check_solved(ksp: PETSc.KSP, what: str = "MUMPS") -> None:
    """After ksp.solve on a MUMPS factor that set_up_factor did not set up (dolfinx's LinearProblem sets up its
    own in its solve): SolverError when the factorisation failed (PETSc 3.18 does not raise then; the solution is
    garbage) or the solve diverged."""
    status = factor_status(ksp)
    if status is not None and status[0] < 0:
        raise _failure(what, *status)
    reason = ksp.getConvergedReason()
    if reason < 0:
        raise SolverError(f"{what}: the direct solve failed (PETSc KSP converged reason {reason})")
