"""A structure reduced once on a Ritz basis, then evaluated at any lines and load amplitudes in milliseconds.

A run-up asks for the response at every harmonic of the tooth frequency at every speed (hundreds of lines whose
load amplitudes change with speed and torque).  `harmonic_response` rebuilds the surface quantities of the modes
per call; `RitzReduction` builds them once:

    reduction = RitzReduction(basis, {"mesh": F_mesh, "torque": F_torque}, damping, nodes=("wheel:8",))
    resp = reduction.evaluate(f, {"mesh": a_mesh})    # a_mesh: complex rms amplitude per line (N)
    resp.mean_square_velocity                         # <v^2> over the surface per line (m^2/s^2)
    reduction.node_rotation(resp, "wheel:8", axis)    # complex rms rotation of an interior node (rad)

The Ritz basis is the modal basis plus, per unit load, the static residual vector of the modes left out
(housingfe.solvers.harmonic.ritz_basis, as the projected solver): exact for the loads' static response and the
kept modes' dynamics.  K, M and C are projected on it (C: bearing damping; K may be non-symmetric: fluid films) and
the small system is solved per line.  Modal damping (a ratio xi) is applied to the modes of the reduced system.

Stored once per Ritz vector: the surface Gram matrix Psi^T W Psi, the values at the kept point sets and interior
nodes.  `reanalyse(structure, loads)` projects ANOTHER structure on the same vectors (a torque with other bearing
and mesh stiffnesses, another gear set): a Rayleigh-Ritz re-analysis that reuses the basis and the surface data
(its frequency error against a fresh basis is reported by `housingfe bench runup`).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
import scipy.linalg

from housingfe.errors import InputError
from housingfe.response.harmonic import Load, StructureObserver, loss_factor
from housingfe.response.observers import node_key, responses
from housingfe.solvers import blocks, harmonic
from housingfe.solvers.blas import single_thread


@dataclass
class ReducedSystem:
    """The structure projected on the Ritz vectors: Kr, Mr, Cr (n x n; N/m, kg, N s/m in Ritz coordinates), the
    load projections Fr (n, loads), the modal damping matrix D (or None), the modes of the reduced system
    (frequencies_hz, vectors Y mass-normalised on Mr, symmetric part of Kr)."""

    Kr: np.ndarray
    Mr: np.ndarray
    Cr: np.ndarray
    Fr: np.ndarray
    D: np.ndarray | None
    frequencies_hz: np.ndarray
    Y: np.ndarray


# a re-analysis projects the change of the matrices when it touches at most this share of the rows
CHANGE_SHARE = 0.05
# unit-load solutions remembered per reduction (RitzReduction.unit_coordinates): a run-up at one torque asks for
# three frequency sets (the coupled source's receptance at every harmonic, its lines for the mesh and the wheel
# torque); each set costs (vectors x lines) complex numbers, ~1.3 MB for 91 vectors and 900 lines
UNIT_SOLUTIONS = 8


class RitzReduction:
    """The response quantities of a ModalBasis (housingfe.solvers.modal.modes) extended by the static residual
    vectors of a fixed set of unit loads (name -> PETSc Vec in the structure's DOFs, per unit amplitude).

    damping: housingfe.solvers.harmonic.Damping (modal ratio or loss factor) or a loss factor eta (-); surface: the
    observed (radiating) surface; nodes: interior nodes whose six components are kept (coupled structures);
    extra_points: named SamplePoints whose normal displacement is kept (a radiator's facet points);
    static_vectors: more force patterns whose static residual responses join the Ritz space without being loads —
    where a re-analysis will change the stiffness (e.g. self-equilibrated unit pairs across each bearing: a bearing
    stiffness change Delta K phi lies in their span, so the re-analysed modes stay accurate); residual: False
    keeps the modes only (no static vectors: the truncated modal superposition, for studies of what the modes
    above the basis contribute)."""

    def __init__(self, basis, loads: dict, damping, *, surface: str = "outer", nodes=(),
                 extra_points: dict | None = None, static_vectors=(), residual: bool = True):
        if not loads:
            raise InputError("loads: at least one load")
        t0 = time.perf_counter()
        self.basis = basis
        structure = basis.structure
        self.damping = damping if isinstance(damping, harmonic.Damping) else loss_factor(damping)
        if self.damping.D is not None:
            raise InputError("damping: per-material loss factors need the direct solver, not a Ritz reduction")
        self.names = list(loads)
        K_sym = structure.K if getattr(structure, "symmetric", True) else structure.basis_stiffness()
        statics = list(loads.values()) + list(static_vectors) if residual else []
        self.vectors = harmonic.ritz_basis(K_sym, structure.M, basis, statics)
        self.loads = dict(loads)
        t1 = time.perf_counter()
        unit = [Load(name, vec) for name, vec in loads.items()]
        self.observer = StructureObserver(structure, surface, (), unit[:1], extra_points, nodes)
        self.reduced = self.observer.reduce(self.vectors)
        t2 = time.perf_counter()
        self.structure = structure
        self.system = self._project(structure, loads)
        self.timings = {"ritz_vectors_s": t1 - t0, "surface_reduction_s": t2 - t1,
                        "projection_s": time.perf_counter() - t2}

    # ------------------------------------------------------------------------------------------- projection
    @single_thread
    def _project(self, structure, loads: dict, matrices=None) -> ReducedSystem:
        Kr, Mr, Cr = matrices or harmonic.project(self.vectors, structure.K, structure.M, structure.C)
        Fr = np.array([[b.dot(loads[name]) for name in self.names] for b in self.vectors])
        Ks = 0.5 * (Kr + Kr.T)
        Ms = 0.5 * (Mr + Mr.T)
        lam, Y = scipy.linalg.eigh(Ks, Ms)
        lam = np.clip(lam, 0.0, None)
        xi = self.damping.ratios(len(lam))
        D = None
        if xi is not None:
            # modal damping on the modes of the reduced system: D = Mr Y diag(2 xi omega) Y^T Mr
            MY = Ms @ Y
            D = (MY * (2 * xi * np.sqrt(lam))) @ MY.T
        return ReducedSystem(Kr, Mr, Cr, Fr, D, np.sqrt(lam) / (2 * math.pi), Y)

    def reanalyse(self, structure, loads: dict) -> "RitzReduction":
        """The same Ritz vectors and surface data with another structure's K, M, C and loads projected on them
        (same DOFs; e.g. the coupled model at another torque).  Loads: the same names."""
        if set(loads) != set(self.names):
            raise InputError(f"reanalyse: loads must be {', '.join(self.names)}")
        if "_changed_from" in self.__dict__:
            # a `with_change` reduction: its system is no projection of its structure, so the difference of the
            # matrices must be taken from the reduction that was one; `structure` brings its own K, M, C whole
            return self._changed_from[0].reanalyse(structure, loads)
        if structure.dofs != self.structure.dofs:
            raise InputError("reanalyse: the structure has other DOFs than the reduced one")
        t0 = time.perf_counter()
        other = object.__new__(RitzReduction)
        other.__dict__.update(self.__dict__)
        other.structure = structure
        other.loads = dict(loads)
        other.system = other._project(structure, loads, self._projected_change(structure))
        other.timings = {**self.timings, "reanalysis_s": time.perf_counter() - t0}
        return other

    def with_change(self, dK: np.ndarray, dC: np.ndarray | None = None, structure=None) -> "RitzReduction":
        """The same Ritz vectors, surface data, loads and damping with the projected stiffness and damping changed
        by dK, dC (n x n in Ritz coordinates, N/m and N s/m; may be non-symmetric): a re-analysis whose projected
        change the caller already has (e.g. a few lumped elements' change, X_e^T dA_e X_e on their nodes' rows:
        housingfe.runup.chain.follow_speeds), without any product with the coupled matrices.  No structure holds
        the returned system's K and C: `structure` is what the result reports as its own (default this
        reduction's; e.g. housingfe.runup.chain.SpeedInterior, which refuses the stale matrices).  The result
        remembers this reduction and the change: its `reanalyse` starts from this one (the new structure's
        matrices replace the change), its `with_damping` re-applies the change."""
        s = self.system
        if np.shape(dK) != s.Kr.shape or (dC is not None and np.shape(dC) != s.Cr.shape):
            raise InputError(f"with_change: dK, dC must be {s.Kr.shape[0]} x {s.Kr.shape[0]}")
        other = object.__new__(RitzReduction)
        other.__dict__.update(self.__dict__)
        other.__dict__.pop("_unit_memo", None)
        other._changed_from = (self, dK, dC)
        if structure is not None:
            other.structure = structure
        matrices = (s.Kr + dK, s.Mr.copy(), s.Cr + dC if dC is not None else s.Cr.copy())
        other.system = other._project(self.structure, self.loads, matrices)
        return other

    def _projected_change(self, structure):
        """(Kr, Mr, Cr) of `structure` as this reduction's plus the projection of the difference of the
        matrices, or None (project afresh).  Another drivetrain of the same layout changes only the rows of
        the interior (bearing matrices, mesh stiffness, gear bodies: ~300 of 65 k DOFs): X_R^T dA_RC X_C on
        those rows instead of two products with the whole matrix (1.1-1.4 s -> ~0.2 s on the 65 k-DOF
        gearbox).  One MPI rank only (the columns of the rows would have to be gathered); more than
        CHANGE_SHARE of the rows changed (another housing, another mesh) projects afresh."""
        if structure.K.getComm().getSize() > 1:
            return None
        old = self.structure
        if not hasattr(self, "_columns"):
            self._columns = blocks.columns(self.vectors)      # shared with the re-analyses (copied __dict__)
        X = self._columns
        s = self.system
        out = []
        for A_old, A_new, R in ((old.K, structure.K, s.Kr), (old.M, structure.M, s.Mr), (old.C, structure.C, s.Cr)):
            dA = blocks.csr_difference(A_old, A_new, X.shape[0])
            if dA is None:
                return None
            rows = np.flatnonzero(np.diff(dA.indptr))
            if len(rows) > CHANGE_SHARE * X.shape[0]:
                return None
            if len(rows):
                sub = dA[rows]
                cols = np.unique(sub.indices)
                R = R + X[rows].T @ (sub[:, cols] @ X[cols])
            out.append(np.array(R, dtype=float, copy=True))
        return tuple(out)

    def with_damping(self, damping) -> "RitzReduction":
        """The same reduction with another damping (Damping or loss factor): only the small system changes."""
        if "_changed_from" in self.__dict__:       # re-projecting `structure` would drop the change: re-apply it
            parent, dK, dC = self._changed_from
            return parent.with_damping(damping).with_change(dK, dC, self.structure)
        other = object.__new__(RitzReduction)
        other.__dict__.update(self.__dict__)
        other.damping = damping if isinstance(damping, harmonic.Damping) else loss_factor(damping)
        other.system = other._project(self.structure, self.loads)
        return other

    @property
    def area(self) -> float:
        """Area (m^2) of the observed surface."""
        return self.observer.area

    @property
    def frequencies_hz(self) -> np.ndarray:
        """Eigenfrequencies (Hz) of the reduced system (the basis' modes, then the residual vectors' pseudo-modes)."""
        return self.system.frequencies_hz

    # ------------------------------------------------------------------------------------------- evaluation
    def coefficients(self, frequencies, amplitudes: dict) -> np.ndarray:
        """(vectors, lines) complex Ritz coordinates of the summed response to the loads with their complex rms
        `amplitudes` (name -> number or array per line, in the load's unit; loads left out have amplitude 0)."""
        f = np.asarray(frequencies, float)
        unknown = set(amplitudes) - set(self.names)
        if unknown:
            raise InputError(f"amplitudes: unknown load(s) {', '.join(sorted(unknown))} (known: "
                             f"{', '.join(self.names)})")
        a = np.zeros((len(self.names), len(f)), complex)
        for j, name in enumerate(self.names):
            if name in amplitudes:
                a[j] = np.broadcast_to(np.asarray(amplitudes[name], complex), f.shape)
        c = np.zeros((len(self.vectors), len(f)), complex)
        for j, name in enumerate(self.names):   # one batched solve per load, weighted by its amplitudes
            if np.any(a[j]):
                c += self.unit_coordinates(f, name) * a[j][None, :]
        return c

    def unit_coordinates(self, frequencies, name: str) -> np.ndarray:
        """(vectors, lines) complex Ritz coordinates of the unit load `name` (amplitude 1 in its unit) at
        `frequencies` (Hz): one batched solve of the reduced system, remembered for the last UNIT_SOLUTIONS
        frequency sets (read-only arrays).  A run-up asks for the same lines several times (the coupled source's
        wheel rotation, the mesh_force route, a re-run with another engagement shock, housingfe.runup.chain
        .engagement_rerun), and the solve (~0.1 s per 500 lines) does not depend on the load amplitudes.  The memo
        belongs to this reduction's system and damping: a re-analysis or another damping starts afresh."""
        f = np.asarray(frequencies, float)
        j = self.names.index(name)
        solutions = self._unit_solutions()
        key = (name, f.shape, f.tobytes())
        if key not in solutions:
            s = self.system
            eta = np.zeros(len(f)) if s.D is not None else self.damping.hysteretic(f)
            C = s.Cr if s.D is None else s.Cr + s.D
            c = harmonic.solve_reduced(s.Kr, s.Mr, C, 2 * math.pi * f, eta, s.Fr[:, j:j + 1])[0]
            c.setflags(write=False)
            while len(solutions) >= UNIT_SOLUTIONS:
                solutions.pop(next(iter(solutions)))          # the oldest
            solutions[key] = c
        return solutions[key]

    def _unit_solutions(self) -> dict:
        """The memo of `unit_coordinates` for this reduction's current system and damping."""
        memo = self.__dict__.get("_unit_memo")
        if memo is None or memo[0] is not self.system or memo[1] is not self.damping:
            memo = self._unit_memo = (self.system, self.damping, {})
        return memo[2]

    def prefetch_unit_coordinates(self, frequencies, names) -> None:
        """Solve the unit loads `names` at `frequencies` (Hz) for all of them at once into the memo of
        `unit_coordinates`, which then returns them without solving: for callers that will ask for several loads at
        many new lines (e.g. housingfe.runup.as_made's thousands of sideband lines through both routes).  At most
        UNIT_SOLUTIONS names.  With modal (viscous) damping the system K + i w C - w^2 M does not depend on w
        otherwise, so its linearisation is reduced ONCE to generalised Schur form (QZ, backward stable) and each
        line costs a triangular solve, O(n^2) instead of a factorisation O(n^3) (`pencil_solve`; equal to the
        direct solve to ~1e-9 relative, tests/response/test_reduced.py); with a loss factor (eta per line) the
        batched direct solve."""
        f = np.asarray(frequencies, float)
        names = list(dict.fromkeys(names))[:UNIT_SOLUTIONS]
        solutions = self._unit_solutions()
        keys = {name: (name, f.shape, f.tobytes()) for name in names}
        missing = [name for name in names if keys[name] not in solutions]
        if not missing or not f.size:
            return
        s = self.system
        Fr = s.Fr[:, [self.names.index(name) for name in missing]]
        if s.D is not None:
            c = pencil_solve(s.Kr, s.Mr, s.Cr + s.D, 2 * math.pi * f, Fr)
        else:
            c = harmonic.solve_reduced(s.Kr, s.Mr, s.Cr, 2 * math.pi * f, self.damping.hysteretic(f), Fr)
        for i, name in enumerate(missing):
            while len(solutions) >= UNIT_SOLUTIONS:
                solutions.pop(next(iter(solutions)))          # the oldest
            ci = np.ascontiguousarray(c[i])
            ci.setflags(write=False)
            solutions[keys[name]] = ci

    def evaluate(self, frequencies, amplitudes: dict):
        """The summed response (housingfe.response.observers.LoadResponse with amplitude 1: the amplitudes are in
        it) at `frequencies` (Hz): mean_square_velocity (m^2/s^2 per line), velocity_level_db, and in
        extras["point_values"] the kept point sets and nodes (displacements m, rotations rad, complex rms)."""
        f = np.asarray(frequencies, float)
        c = self.coefficients(f, amplitudes)
        return self.response_of(f, c)

    def response_of(self, frequencies, coefficients):
        """The LoadResponse of given Ritz coordinates (vectors, lines)."""
        f = np.asarray(frequencies, float)
        result = harmonic.HarmonicResult(f, [[harmonic.Block(self.reduced, coefficients, np.arange(len(f)))]],
                                         "ritz")
        case = SimpleNamespace(name="sum", kind="", amplitude=lambda fr: np.ones(np.shape(fr)))
        return responses(result, self.observer, [case])[0]

    def node_rotation(self, response, node: str, axis) -> np.ndarray:
        """Complex rms rotation (rad) of an interior node about the unit `axis` per line of `response`."""
        values = response.extras["point_values"].get(node_key(node))
        if values is None:
            raise InputError(f"node {node!r} was not kept by this reduction (nodes=...)")
        a = np.asarray(axis, float) / np.linalg.norm(axis)
        return a @ values[3:6]

    def modal_contributions(self, frequency_hz: float, coefficients: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(frequencies_hz, share) of the reduced system's modes in the surface <v^2> at one line: share_i =
        Re(z_i^* (G z)_i) / (z^H G z) in the modes' coordinates z = Y^T Mr c (the shares sum to 1; a negative
        share is a mode cancelling others)."""
        s = self.system
        z = s.Y.T @ (0.5 * (s.Mr + s.Mr.T)) @ np.asarray(coefficients, complex)
        G = s.Y.T @ self.reduced.gram @ s.Y
        part = np.real(np.conj(z) * (G @ z))
        total = part.sum()
        return s.frequencies_hz, part / total if total > 0 else part


def modal_basis_summary(basis, reduction: RitzReduction | None = None) -> dict:
    """JSON-able facts of a modal basis (and of the Ritz reduction built on it)."""
    n = basis.rigid_count
    out = {"f_max_hz": basis.f_max, "modes": len(basis.eigenvalues), "zero_modes": n,
           "elastic_frequencies_hz": [float(x) for x in basis.frequencies_hz[n:]], "complete": bool(basis.complete),
           "dofs": int(basis.structure.dofs)}
    if reduction is not None:
        out["ritz_vectors"] = len(reduction.vectors)
        out["residual_vectors"] = len(reduction.vectors) - len(basis.eigenvalues)
    return out


__all__ = ["ReducedSystem", "RitzReduction", "modal_basis_summary"]


def pencil_solve(K, M, C, omega, F) -> np.ndarray:
    """(loads, n, lines) solutions c of (K + i omega C - omega^2 M) c = F (n x n real or complex; F (n, loads)) at
    many angular frequencies omega [rad/s]: the first-order form z = [c; s c / w0] (s = i omega; w0 =
    sqrt(max |K_ii| / max |M_ii|) balances the two halves), A z - s B z = [0; -F] with A = [[0, w0 I], [-K, -w0 C]],
    B = [[I, 0], [0, w0 M]], reduced once to complex generalised Schur form A = Q S Z^H, B = Q T Z^H
    (scipy.linalg.qz); then c = Z_top (S - s T)^-1 Q^H [0; -F], an upper-triangular solve per line."""
    K, M, C = (np.asarray(x) for x in (K, M, C))
    n = K.shape[0]
    w0 = math.sqrt(np.max(np.abs(np.diag(K))) / np.max(np.abs(np.diag(M))))
    eye, zero = np.eye(n), np.zeros((n, n))
    A = np.block([[zero, w0 * eye], [-K, -w0 * C]])
    B = np.block([[eye, zero], [zero, w0 * M]])
    S, T, Q, Z = scipy.linalg.qz(A, B, output="complex")
    rhs = Q.conj().T @ np.vstack([np.zeros_like(F), -np.asarray(F)])
    omega = np.asarray(omega, float)
    Y = np.empty((omega.size, 2 * n, rhs.shape[1]), complex)
    for k, w in enumerate(omega):
        Y[k] = scipy.linalg.solve_triangular(S - 1j * w * T, rhs, check_finite=False)
    return np.einsum("ij,kjl->lik", Z[:n], Y)
