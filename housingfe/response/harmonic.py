"""The harmonic-response stage: loads with complex spectra on a Structure -> a Response.

    basis = modes(structure, f_max)                                   # housingfe.solvers.modal
    load = Load("mesh force", structure.load_vector(spec), spectrum=F)  # F: complex rms amplitude per line (N)
    resp = harmonic_response(basis, [load], Damping(...), f)          # loads summed coherently
    resp.mean_square_velocity()                                       # <v^2> over the surface (m^2/s^2)

Conventions as everywhere in housingfe: rms phasors, time dependence e^{i omega t}; the loads are superposed
with their complex amplitudes (phases respected), so two loads of opposite phase cancel.  The unit-load
transfer functions of `housingfe run` are the special case of one load with a flat spectrum of 1.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np

from housingfe import levels
from housingfe.errors import InputError
from housingfe.response.observers import (
    RESPONSE_POINTS,
    SurfaceObserver,
    band_levels,
    locate_response_points,
    node_key,
    response_point_samples,
    responses,
)
from housingfe.solvers import harmonic, modal

UNITS = {"force": "N", "moment": "N m", "pressure": "Pa"}


@dataclass
class Load:
    """A load case: `vector` (PETSc Vec in the structure's DOFs, per unit amplitude) times a complex rms
    amplitude per frequency.  spectrum: a number (flat spectrum), a function f (Hz, array) -> complex array, or
    a table (frequencies Hz, complex values) interpolated linearly in real and imaginary part; unit: the unit of
    the amplitude ("N", "N m", "Pa")."""

    name: str
    vector: object
    spectrum: object = 1.0
    unit: str = "N"

    def amplitude(self, frequencies) -> np.ndarray:
        """Complex rms amplitude (unit) at `frequencies` (Hz)."""
        f = np.asarray(frequencies, dtype=float)
        s = self.spectrum
        if callable(s):
            return np.broadcast_to(np.asarray(s(f), dtype=complex), f.shape).copy()
        if isinstance(s, tuple):
            fs, vals = np.asarray(s[0], float), np.asarray(s[1], complex)
            return np.interp(f, fs, vals.real) + 1j * np.interp(f, fs, vals.imag)
        return np.full(f.shape, complex(s))

    @classmethod
    def from_spec(cls, structure, spec, key: str | None = None) -> "Load":
        """The load of a scene load spec (housingfe.scene.LoadSpec) on a structure, with its (real) amplitude
        and spectrum."""
        case = structure.load_case(spec, key) if hasattr(structure, "load_case") else None
        vector = case.vector if case is not None else structure.load_vector(spec)
        spectrum = case.amplitude if case is not None else spec.amplitude
        return cls(spec.name, vector, spectrum, UNITS.get(spec.kind, spec.kind))


class StructureObserver(SurfaceObserver):
    """The SurfaceObserver of any Structure: solution vectors in the structure's DOFs are mapped to the housing
    field by structure.to_housing for the surface and point quantities; the load projections use the structure's
    vectors; `nodes` (drivetrain node names) keep their six displacement components (m, rad) as point sets
    named node_key(name) (structures with node_displacement only)."""

    def __init__(self, structure, surface: str, sample_counts, load_cases, extra_points: dict | None = None,
                 nodes=()):
        super().__init__(structure, surface, sample_counts, load_cases, extra_points)
        self.structure = structure
        self.nodes = {node_key(n): n for n in nodes}
        for key in self.nodes:
            self.extra_samples[key] = SimpleNamespace(weights=np.ones(6))

    def reduce(self, vectors):
        red = super().reduce(vectors, [self.structure.to_housing(q) for q in vectors])
        for key, name in self.nodes.items():
            red.points[key] = np.array([self.structure.node_displacement(q, name)
                                        for q in vectors]).reshape(len(vectors), 6).T
        return red


def loss_factor(eta: float) -> harmonic.Damping:
    """Hysteretic damping with one loss factor eta (-) at every frequency."""
    return harmonic.Damping(lambda f: np.full(np.shape(f), float(eta)))


def choose(solver: str, damping: harmonic.Damping, structure) -> str:
    """'auto': modal for proportional damping on a symmetric structure, projected with a damping matrix C or a
    non-symmetric K, direct with per-material loss factors (a matrix D)."""
    non_modal = structure.C is not None or not getattr(structure, "symmetric", True)
    if solver == "auto":
        return "direct" if damping.D is not None else "projected" if non_modal else "modal"
    if solver not in ("modal", "projected", "direct"):
        raise InputError(f"solver: {solver!r} is not one of auto, modal, projected, direct")
    if solver == "modal" and non_modal:
        raise InputError("solver: the structure has a damping matrix or a non-symmetric stiffness; the modal "
                         "solver cannot take it (use \"projected\", \"direct\" or \"auto\")")
    return solver


@dataclass
class Response:
    """The coherent response of a set of loads on a structure, per frequency line.

    frequencies: Hz; area: m^2 of the observed surface; result: the housingfe.response.observers.LoadResponse of
    the summed loads (amplitudes included, so its `amplitude` is 1); harmonic: the HarmonicResult of the sum;
    points: the snapped response points (housingfe.response.observers.ResponsePoint)."""

    frequencies: np.ndarray
    loads: list
    structure: object
    observer: object
    result: object
    harmonic: object
    solver: str
    points: list = field(default_factory=list)
    timings: dict = field(default_factory=dict)

    @property
    def area(self) -> float:
        """Area of the observed (radiating) surface (m^2)."""
        return self.observer.area

    def mean_square_velocity(self) -> np.ndarray:
        """Surface-averaged mean-square normal velocity <v^2> (m^2/s^2, rms^2) per line."""
        return self.result.mean_square_velocity

    @property
    def velocity_level_db(self) -> np.ndarray:
        """L_v (dB re v0 = 5e-8 m/s) per line (a property, as on LoadResponse)."""
        return levels.level(self.mean_square_velocity(), levels.V0)

    def at_points(self, kind: str = "displacement", direction=None) -> dict:
        """Response point name -> complex rms phasors per line: displacement (m), velocity (m/s) or acceleration
        (m/s^2).  direction None: every direction of the point (rows, as requested: x, y, z or one); a label
        ("x", "y", "z", "normal", "given"): that row; a 3-vector: the projection (points with x, y, z rows)."""
        factor = {"displacement": 1.0, "velocity": 1j, "acceleration": -1.0}
        if kind not in factor:
            raise InputError(f"kind: {kind!r} is not displacement, velocity or acceleration")
        omega = 2 * math.pi * self.frequencies
        scale = {"displacement": np.ones_like(omega), "velocity": 1j * omega, "acceleration": -omega**2}[kind]
        values = self.result.extras["point_values"].get(RESPONSE_POINTS)
        out, row = {}, 0
        for rp in self.points:
            rows = values[row:row + len(rp.labels)] * scale
            row += len(rp.labels)
            if direction is None:
                out[rp.name] = rows
            elif isinstance(direction, str):
                if direction not in rp.labels:
                    raise InputError(f"direction: point {rp.name!r} has {', '.join(rp.labels)}, not {direction!r}")
                out[rp.name] = rows[rp.labels.index(direction)]
            else:
                if rp.labels != ["x", "y", "z"]:
                    raise InputError(f"direction: point {rp.name!r} was computed along {rp.labels[0]} only")
                d = np.asarray(direction, float)
                out[rp.name] = (d / np.linalg.norm(d)) @ rows
        return out

    def band_levels(self, f_lo: float | None = None, f_hi: float | None = None):
        """1/3-octave band velocity levels (dB re 5e-8 m/s), energy sums of the lines: (bands, L_v)."""
        f = self.frequencies
        return band_levels(f, self.mean_square_velocity(), f_lo or f.min(), f_hi or f.max(), levels.V0)

    def transfer_db(self, load: str | None = None) -> np.ndarray:
        """TF = L_v - L_load (dB; load level re 1 N, 1 N m or 1 Pa) per line, against the amplitude of `load`
        (by name; default: the only load)."""
        if load is None and len(self.loads) != 1:
            raise InputError("transfer_db: several loads; name the reference load")
        ref = self.loads[0] if load is None else next((ld for ld in self.loads if ld.name == load), None)
        if ref is None:
            raise InputError(f"transfer_db: no load named {load!r}")
        return self.velocity_level_db - levels.level(np.abs(ref.amplitude(self.frequencies)) ** 2, 1.0)


def harmonic_response(structure_or_basis, loads, damping, frequencies, *, surface: str = "outer", points=(),
                      solver: str = "auto", sample_points=(), residual: bool = True,
                      basis_factor: float = 1.5) -> Response:
    """The response of a structure (housingfe.fe.structure.Structure) or of its modal basis (ModalBasis from
    housingfe.solvers.modal.modes) to `loads` (Load or list of Load), summed coherently, on `frequencies` (Hz).

    damping: a housingfe.solvers.harmonic.Damping or a loss factor eta (-); surface: the observed surface;
    points: response point specs (name, point m, direction, surface, tolerance; housingfe.scene.ResponsePointSpec);
    solver: auto | modal | projected | direct (see choose); sample_points: sizes of area-weighted sample-point
    sets; residual: residual flexibility in the modal solver; basis_factor: without a basis, modes up to
    basis_factor * max(frequencies) are computed for the modal / projected solvers."""
    t0 = time.perf_counter()
    basis = structure_or_basis if isinstance(structure_or_basis, modal.ModalBasis) else None
    structure = basis.structure if basis is not None else structure_or_basis
    loads = [loads] if isinstance(loads, Load) else list(loads)
    if not loads:
        raise InputError("loads: at least one load")
    damping = damping if isinstance(damping, harmonic.Damping) else loss_factor(damping)
    f = np.asarray(frequencies, dtype=float)
    extra, located = {}, []
    if points:
        located = locate_response_points(structure.housing, points)
        extra[RESPONSE_POINTS] = response_point_samples(located)
    # the observer projects on the first load's vector only: receptances are not part of a coherent sum
    observer = StructureObserver(structure, surface, tuple(sample_points), loads[:1], extra)
    name = choose(solver, damping, structure)
    K, M, C = structure.K, structure.M, structure.C
    amps = np.array([ld.amplitude(f) for ld in loads])
    every = np.arange(len(f))
    if name in ("modal", "projected"):
        K_sym = K if getattr(structure, "symmetric", True) else structure.basis_stiffness()
        own_basis = basis is None
        if own_basis:   # the residual vectors reuse the eigensolve's factorisation of K - shift M
            basis = modal.solve_modes(K_sym, M, basis_factor * f.max(), keep_solver=True,
                                      null_space=modal.known_null_space(structure))
        try:
            if name == "modal":
                res = harmonic.modal_superposition(K, M, basis, loads, f, damping, observer.reduce,
                                                   residual=residual)
            else:
                res = harmonic.projected(K, M, basis, loads, f, damping, observer.reduce, C=C, K_sym=K_sym)
        finally:
            if own_basis:
                basis.release_solver()
        # every load case shares the reduced basis: the coherent sum is the sum of the amplitude-weighted
        # coefficients
        reduced = res.blocks[0][0].reduced
        coeffs = sum(a[None, :] * res.blocks[j][0].coeffs for j, a in enumerate(amps))
        total = harmonic.HarmonicResult(f, [[harmonic.Block(reduced, coeffs, every)]], res.solver, res.timings,
                                        modal_vectors=res.modal_vectors[:1], unstable=res.unstable)
    else:
        blocks = []
        pair = np.array([[1.0], [1j]])
        for k in range(len(f)):
            # one line at a time: the loads' solution vectors are combined, then reduced, then dropped
            res = harmonic.direct(K, M, loads, f[k:k + 1], damping, lambda vecs: [v.copy() for v in vecs], C=C)
            Ur, Ui = res.blocks[0][0].reduced[0].duplicate(), res.blocks[0][0].reduced[0].duplicate()
            Ur.set(0.0)
            Ui.set(0.0)
            for j, a in enumerate(amps[:, k]):
                ur, ui = res.blocks[j][0].reduced
                Ur.axpy(a.real, ur)
                Ur.axpy(-a.imag, ui)
                Ui.axpy(a.imag, ur)
                Ui.axpy(a.real, ui)
            blocks.append(harmonic.Block(observer.reduce([Ur, Ui]), pair, np.array([k])))
        total = harmonic.HarmonicResult(f, [blocks], "direct")
    case = SimpleNamespace(name=" + ".join(ld.name for ld in loads), kind=loads[0].unit,
                           amplitude=lambda fr: np.ones(np.shape(fr)))
    result = responses(total, observer, [case])[0]
    return Response(f, loads, structure, observer, result, total, total.solver, located,
                    {"harmonic_response_s": time.perf_counter() - t0})
