"""Craig–Bampton reduction of a housing to its bore masters, for system tools (KISSsys, Romax, MASTA, ...).

The housing (a HousingModel: K, M with its supports) is tied to one 6-DOF master per bore by a rigid spider
(rbe2, housingfe.drivetrain.coupling: u_s = u_m + theta_m x r_s), so the interface is the masters' DOFs b (u_x,
u_y, u_z, theta_x, theta_y, theta_z in global axes; m, rad) and every other DOF is interior i.  The
Craig–Bampton basis T = [Phi, Psi]:

* Phi: the fixed-interface modes, (K_ii - w^2 M_ii) phi = 0 with b = 0, all below the cut-off (complete by the
  inertia count), mass-normalised;
* Psi: the static constraint modes, one per master DOF: psi_j = e_j - K_ii^-1 K_ij (a unit motion of master
  DOF j, the others held, the housing relaxed statically).

K_r = T^T K T, M_r = T^T M T (dense; the DOFs in that order: modal coordinates q_1..q_n, then 6 per master).
K_r = diag(w_k^2) (+) K_bb_hat with zero coupling (to round-off), K_bb_hat = the housing's static stiffness at
the masters (Guyan); M_r has the modal-boundary coupling block.  Statics at the masters are exact; dynamics are
accurate well below the cut-off (docs/reduction.md gives the measured errors with bearings attached).

Outputs (write_npz, write_dmig): a documented npz (K, M, the DOF table, master coordinates, fixed-interface
frequencies, provenance) and Nastran DMIG bulk data (KAAX / MAAX, masters as GRIDs, modal coordinates as
SPOINTs), which read_dmig reads back.

MPI: everything is PETSc/dolfinx on any number of ranks; K_r and M_r are summed from the ranks' rows, the modes
come oriented (solvers.modal.orient_modes) and each mode's sign is then fixed by its coupling to the masters
(fix_mode_signs), so 1 and 2 ranks give the same reduced matrices (to round-off).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from petsc4py import PETSc

from housingfe.drivetrain import coupling as cp
from housingfe.errors import InputError, SolverError

# Nastran ids: master i is GRID MASTER_GRID_BASE + i, modal coordinate k is SPOINT MODAL_SPOINT_BASE + k
MASTER_GRID_BASE = 9_000_001
MODAL_SPOINT_BASE = 9_100_001
DOF_NAMES = ("ux", "uy", "uz", "rx", "ry", "rz")


@dataclass
class Master:
    """A bore master: name, the housing surface tied to it, its position (m)."""

    name: str
    surface: str
    position: np.ndarray


@dataclass
class ReducedHousing:
    """The Craig–Bampton model.  K (N/m, N, N m / rad), M (kg ...) dense (n_modes + 6 n_masters) square, SI;
    DOF order: modal coordinates (mass-normalised: q in sqrt(kg) m), then ux..rz of each master in global axes.
    frequencies_hz: the fixed-interface modes kept; masters; cutoff_hz; timings (s); provenance (dict of
    strings: scene, mesh, version, ranks, DOFs)."""

    K: np.ndarray
    M: np.ndarray
    frequencies_hz: np.ndarray
    masters: list
    cutoff_hz: float
    timings: dict = field(default_factory=dict)
    provenance: dict = field(default_factory=dict)

    @property
    def n_modes(self) -> int:
        return len(self.frequencies_hz)

    def master_dofs(self, name: str) -> np.ndarray:
        """Indices of a master's six DOFs in K and M."""
        names = [m.name for m in self.masters]
        if name not in names:
            raise InputError(f"no master {name!r} (masters: {', '.join(names)})")
        k = names.index(name)
        return self.n_modes + 6 * k + np.arange(6)

    def dof_table(self) -> list[tuple[str, int, str]]:
        """(kind, Nastran id, component) per DOF: ("mode", SPOINT id, "q<k>") or ("master", GRID id, "ux".."rz")."""
        rows = [("mode", MODAL_SPOINT_BASE + k, f"q{k + 1}") for k in range(self.n_modes)]
        rows += [("master", MASTER_GRID_BASE + i, c) for i in range(len(self.masters)) for c in DOF_NAMES]
        return rows

    def frequencies_with(self, springs: dict | None = None) -> np.ndarray:
        """Frequencies (Hz) of the reduced model with 6x6 springs to ground at masters (name -> K6, global
        axes), e.g. the bearings; rigid modes as 0."""
        from scipy.linalg import eigh

        K = self.K.copy()
        for name, K6 in (springs or {}).items():
            idx = self.master_dofs(name)
            K[np.ix_(idx, idx)] += np.asarray(K6, float)
        w2 = eigh(0.5 * (K + K.T), 0.5 * (self.M + self.M.T), eigvals_only=True)
        return np.sqrt(np.clip(w2, 0.0, None)) / (2 * math.pi)


def craig_bampton(model, masters: list[Master], cutoff_hz: float, tol: float = 1e-10) -> ReducedHousing:
    """Craig–Bampton reduction of a HousingModel to rbe2 bore masters (see the module docstring), fixed-interface
    modes below cutoff_hz (Hz).  Collective; the same ReducedHousing on every rank."""
    from housingfe.solvers.modal import orient_modes, solve_modes

    if not masters:
        raise InputError("reduce: no masters (give bore surfaces)")
    if not cutoff_hz > 0:
        raise InputError(f"--cutoff: {cutoff_hz} Hz must be positive")
    t0 = time.perf_counter()
    connections = [cp.BoreConnection(m.name, m.surface, tuple(map(float, m.position)), kind="rbe2")
                   for m in masters]
    system = cp.couple(model, connections)
    K, M = system.K, system.M
    n_q = system.size
    nb = 6 * len(masters)
    boundary = np.arange(n_q - nb, n_q, dtype=PETSc.IntType)       # the masters close the last rank's block
    lo, hi = K.getOwnershipRange()
    mine = boundary[(boundary >= lo) & (boundary < hi)]
    K_fixed, M_fixed = K.copy(), M.copy()
    K_fixed.zeroRowsColumns(mine, 1.0)
    M_fixed.zeroRowsColumns(mine, 0.0)
    t1 = time.perf_counter()

    fixed = solve_modes(K_fixed, M_fixed, cutoff_hz, tol=tol)
    if fixed.rigid_count:
        raise SolverError(f"reduce: {fixed.rigid_count} zero-frequency modes with the masters held: the masters "
                          "do not hold the housing (a part not connected to any bore?)")
    # the same sign of each mode on any number of ranks, so that the files are too (M_r's modal rows flipped sign
    # between 1 and 2 ranks)
    orient_modes(fixed.vectors, model.V, lambda q: system.fe_vector(q, model.V))
    phi = list(fixed.vectors)
    t2 = time.perf_counter()

    # constraint modes: K_fixed X = -K E (E: unit columns at the master DOFs, its b rows zeroed), psi = X + E;
    # one MUMPS LDL^T of K_fixed, all right-hand sides in one block
    from housingfe.solvers.mumps import ldlt

    n_local = hi - lo
    E = np.zeros((n_local, nb))
    E[mine - lo, np.searchsorted(boundary, mine)] = 1.0
    B = -_mat_dense(K, E)
    B[mine - lo, :] = 0.0
    factor = ldlt(K_fixed)
    factor.factorise(K_fixed)
    psi = factor.solve_block(B) + E
    factor.destroy()
    t3 = time.perf_counter()

    T = np.column_stack([v.getArray(readonly=True) for v in phi] + [psi]) if phi else psi
    Kr, Mr = fix_mode_signs(_project(K, T), _project(M, T), len(phi))
    for v in phi:
        v.destroy()
    for A in (K_fixed, M_fixed):
        A.destroy()
    t4 = time.perf_counter()
    comm = model.V.mesh.comm
    positions = {name: pos for name, (pos, _) in system.nodes.items()}
    out = ReducedHousing(Kr, Mr, fixed.frequencies_hz.copy(),
                         [Master(m.name, m.surface, positions[m.name]) for m in masters], cutoff_hz,
                         {"couple_s": t1 - t0, "fixed_interface_modes_s": t2 - t1, "constraint_modes_s": t3 - t2,
                          "projection_s": t4 - t3, "reduction_s": t4 - t0},
                         {"fe_dofs": int(model.dofs), "ranks": int(comm.size)})
    return out


def fix_mode_signs(Kr: np.ndarray, Mr: np.ndarray, n_modes: int) -> tuple[np.ndarray, np.ndarray]:
    """The reduced K, M with each fixed-interface mode's sign fixed.  An eigenvector's sign is arbitrary: the
    eigensolver's start vector and the MPI layout pick it, and it flips the sign of that mode's row and column of
    the modal-master mass coupling.  Each mode is turned so that its coupling to the master DOFs, weighted by
    1/sqrt(j) (generic weights: a symmetric pair of masters does not cancel), is positive; a mode without
    coupling leaves both matrices unchanged either way.  So the same housing gives the same K_r, M_r (and DMIG)
    on any number of ranks.  (Modes of one repeated frequency may still come out as another basis of their
    eigenspace.)"""
    if n_modes == 0:
        return Kr, Mr
    weights = 1.0 / np.sqrt(np.arange(1, Mr.shape[0] - n_modes + 1))
    signs = np.ones(Mr.shape[0])
    signs[:n_modes] = np.where(Mr[:n_modes, n_modes:] @ weights < 0.0, -1.0, 1.0)
    flip = np.outer(signs, signs)
    return Kr * flip, Mr * flip


def _mat_dense(A: PETSc.Mat, X: np.ndarray) -> np.ndarray:
    """A X for this rank's rows X (rows x columns) of a distributed basis: this rank's rows of the product."""
    n_local, m = X.shape
    comm = A.getComm()
    D = PETSc.Mat().createDense(((n_local, PETSc.DETERMINE), (PETSc.DECIDE, m)),
                                array=np.asfortranarray(X, dtype=PETSc.ScalarType), comm=comm)
    D.assemble()
    AD = A.matMult(D)
    out = np.array(AD.getDenseArray(), copy=True)
    AD.destroy()
    D.destroy()
    return out


def _project(A: PETSc.Mat, T: np.ndarray) -> np.ndarray:
    """T^T A T (dense, the same on every rank) from this rank's rows of T: local rows of A T against local rows
    of T, summed over ranks."""
    from mpi4py import MPI

    local = T.T @ _mat_dense(A, T)
    total = np.empty_like(local)
    A.getComm().tompi4py().Allreduce(local, total, op=MPI.SUM)
    return 0.5 * (total + total.T)


# ------------------------------------------------------------------------------------------------ output
def write_npz(reduced: ReducedHousing, path) -> Path:
    """The reduced housing as an npz (numpy.load): K, M (SI), dof_kind ("mode"/"master"), dof_id (Nastran
    SPOINT/GRID ids), dof_component ("q<k>" or "ux".."rz"), dof_direction (unit vector per DOF, zero for modal
    coordinates), master_names, master_surfaces, master_xyz (m), fixed_interface_hz, cutoff_hz, provenance
    (JSON text).  Format described in docs/reduction.md."""
    import json

    rows = reduced.dof_table()
    direction = np.zeros((len(rows), 3))
    for k, (kind, _, comp) in enumerate(rows):
        if kind == "master":
            direction[k, DOF_NAMES.index(comp) % 3] = 1.0
    path = Path(path)
    np.savez(path, K=reduced.K, M=reduced.M, dof_kind=np.array([r[0] for r in rows]),
             dof_id=np.array([r[1] for r in rows]), dof_component=np.array([r[2] for r in rows]),
             dof_direction=direction, master_names=np.array([m.name for m in reduced.masters]),
             master_surfaces=np.array([m.surface for m in reduced.masters]),
             master_xyz=np.array([m.position for m in reduced.masters]).reshape(-1, 3),
             fixed_interface_hz=reduced.frequencies_hz, cutoff_hz=reduced.cutoff_hz,
             provenance=json.dumps(reduced.provenance, sort_keys=True), units="SI: m, kg, s, N, rad")
    return path


def _nastran_real(value: float) -> str:
    """A real in 16 characters with 10 significant digits, Nastran's D exponent for double precision."""
    text = f"{value:.9E}".replace("E", "D")
    if len(text) > 16:
        raise ValueError(f"{value} does not fit a 16-character field")
    return text


def _field16(text) -> str:
    return f"{text!s:<16s}"


def write_dmig(reduced: ReducedHousing, path, names: tuple[str, str] = ("KAAX", "MAAX")) -> Path:
    """Nastran bulk data of the reduced housing: GRID cards of the masters (basic system, m), SPOINTs of the
    modal coordinates, and two DMIG matrices (large field, symmetric IFO = 6, real double TIN = TOUT = 2, the
    upper triangle by columns: each column's rows up to the diagonal), SI units.  Include it and select the
    matrices with K2GG = KAAX, M2GG = MAAX (docs/reduction.md)."""
    rows = reduced.dof_table()
    ids = [(r[1], 0 if r[0] == "mode" else DOF_NAMES.index(r[2]) + 1) for r in rows]
    path = Path(path)
    with open(path, "w") as f:
        f.write("$ housingfe Craig-Bampton reduced housing: SI units (m, kg, s, N)\n")
        for key, value in sorted(reduced.provenance.items()):
            f.write(f"$ {key}: {value}\n")
        f.write(f"$ {reduced.n_modes} fixed-interface modes below {reduced.cutoff_hz:g} Hz, "
                f"{len(reduced.masters)} masters\n")
        for i, m in enumerate(reduced.masters):
            f.write(f"$ master {MASTER_GRID_BASE + i}: {m.name} (surface {m.surface})\n")
        for i, m in enumerate(reduced.masters):
            x, y, z = m.position
            f.write("GRID*   " + _field16(MASTER_GRID_BASE + i) + _field16("") + _field16(_nastran_real(x))
                    + _field16(_nastran_real(y)) + "\n*       " + _field16(_nastran_real(z)) + "\n")
        for k in range(reduced.n_modes):
            f.write(f"SPOINT  {MODAL_SPOINT_BASE + k:<8d}\n")
        for name, A in zip(names, (reduced.K, reduced.M)):
            # header: NAME, "0", IFO, TIN, TOUT, POLAR, (blank), NCOL
            f.write("DMIG*   " + _field16(name) + _field16(0) + _field16(6) + _field16(2) + "\n*       "
                    + _field16(2) + _field16(0) + _field16("") + _field16(len(rows)) + "\n")
            for j, (gj, cj) in enumerate(ids):
                f.write("DMIG*   " + _field16(name) + _field16(gj) + _field16(cj) + _field16("") + "\n")
                for i in range(j + 1):
                    if A[i, j] != 0.0:
                        gi, ci = ids[i]
                        f.write("*       " + _field16(gi) + _field16(ci) + _field16(_nastran_real(A[i, j]))
                                + _field16("") + "\n")
        f.write("ENDDATA\n")
    return path


def read_dmig(path) -> dict:
    """Read the DMIG matrices of a bulk-data file written in large field (as write_dmig does): name ->
    (list of (grid, component) DOFs in order of first appearance as columns, dense symmetric matrix).  A small
    reader for checking exports, not a general Nastran parser."""
    matrices: dict = {}
    current = None
    with open(path) as f:
        lines = f.readlines()
    k = 0
    while k < len(lines):
        line = lines[k].rstrip("\n")
        k += 1
        if not line.startswith("DMIG*"):
            if not line.startswith("*"):
                current = None
            elif current is not None:
                g, c, a = (line[8 + 16 * n:8 + 16 * (n + 1)].strip() for n in range(3))
                current[2].append(((int(g), int(c)), current[1], float(a.replace("D", "E"))))
            continue
        fields = [line[8 + 16 * n:8 + 16 * (n + 1)].strip() for n in range(4)]
        name = fields[0]
        if fields[1] == "0":                    # header card: skip its continuation
            matrices[name] = {"cols": [], "entries": []}
            k += 1
            current = None
            continue
        col = (int(fields[1]), int(fields[2]))
        matrices[name]["cols"].append(col)
        current = (name, col, matrices[name]["entries"])
    out = {}
    for name, data in matrices.items():
        dofs = data["cols"]
        index = {d: n for n, d in enumerate(dofs)}
        A = np.zeros((len(dofs), len(dofs)))
        for row, col, value in data["entries"]:
            A[index[row], index[col]] = value
            A[index[col], index[row]] = value
        out[name] = (dofs, A)
    return out
