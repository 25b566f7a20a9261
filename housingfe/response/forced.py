"""The harmonic analysis of a housing run: load specs on a Structure -> solver(s) -> unit-load responses per load
case, with the solver chosen per problem.  Takes explicit specs (no scene); the sound power is a later stage."""
from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field

import numpy as np

from housingfe.response.observers import responses
from housingfe.solvers import harmonic, modal


@dataclass
class ForcedResult:
    """Responses per solver (name -> list of LoadResponse), the load cases, timings and facts."""

    spec: object
    loads: list
    responses: dict
    observer: object
    results: dict
    timings: dict = field(default_factory=dict)
    facts: dict = field(default_factory=dict)
    sound_power: list | None = None
    to_fe: object = None          # structure.to_housing: solver vector -> housing vector, for deflection shapes
    angular_velocity_node: str | None = None
    response_points: list = field(default_factory=list)      # housingfe.response.observers.ResponsePoint
    deflection_shapes: list = field(default_factory=list)    # DeflectionShape, scaled by the load amplitude


@dataclass
class DeflectionShape:
    """Operating deflection shape of load case `load` at the line `frequency` (Hz): the rms displacement
    phasor u = real + i imag (m, housing FE vectors) for the load's amplitude and spectrum at that line,
    time dependence e^{i omega t}; `solver` says which solver produced it."""

    load: str
    frequency: float
    real: object
    imag: object
    solver: str


def damping_model(spec, structure) -> harmonic.Damping:
    """Damping of a DampingSpec (housingfe.scene): global eta, eta per band, modal xi, or per-material eta (the
    structure's material damping matrix D)."""
    if spec.loss_factor is not None:
        eta = spec.loss_factor
        return harmonic.Damping(lambda f: np.full(np.shape(f), eta))
    if spec.loss_factor_bands is not None:
        t = spec.loss_factor_bands
        logf, vals = np.log(t.frequencies), np.asarray(t.values, float)
        return harmonic.Damping(lambda f: np.interp(np.log(f), logf, vals))
    if spec.modal_damping_ratios is not None:
        return harmonic.Damping(lambda f: np.zeros(np.shape(f)), modal_ratios=tuple(spec.modal_damping_ratios))
    if spec.modal_damping_ratio is not None:
        return harmonic.Damping(lambda f: np.zeros(np.shape(f)), modal_ratio=spec.modal_damping_ratio)
    return harmonic.Damping(lambda f: np.zeros(np.shape(f)), D=structure.material_damping_matrix())


def choose_solver(spec, damping: harmonic.Damping, structure=None) -> list[str]:
    """Solvers to run: 'auto' is modal for proportional damping, direct when a non-proportional damping
    matrix (material loss factors, bearing damping) or a non-symmetric stiffness (fluid films) is present."""
    from housingfe.errors import InputError

    if damping.modal_ratios and spec.solver in ("direct", "both"):
        raise InputError("damping.modal_damping_ratios: per-mode damping exists only in the modal solver; "
                         "use solver = \"modal\" or a loss factor")
    non_modal = structure is not None and (structure.C is not None or not getattr(structure, "symmetric", True))
    if non_modal and spec.solver == "modal":
        raise InputError("analysis.harmonic.solver: the interior has bearing damping or a non-symmetric "
                         "stiffness, which the modal solver cannot take; use \"projected\", \"direct\" or \"auto\"")
    if spec.solver == "projected" and damping.D is not None:
        raise InputError("analysis.harmonic.solver: per-material loss factors need solver = \"direct\" or \"auto\"")
    if spec.solver == "both":
        return ["projected" if non_modal else "modal", "direct"]
    if spec.solver == "auto":
        return ["direct"] if damping.D is not None else ["projected"] if non_modal else ["modal"]
    return [spec.solver]


def assemble_loads(structure, loads) -> list:
    """The load cases (housingfe.fe.loads.LoadCase) of load specs in the structure's DOFs (housing surface loads,
    and loads on drivetrain nodes for a coupled structure)."""
    return [structure.load_case(load, f"loads.{i}") for i, load in enumerate(loads)]


def modal_basis(structure, K, f_basis: float, *, keep_solver: bool) -> modal.ModalBasis:
    """The modal basis of the modal / projected solver: every mode of (K, structure.M) below f_basis (Hz), with
    the structure's known rigid motions deflated, checked as the modal path checks it (modal.structure_basis):
    SolverError when the number of zero modes (|lambda| < RIGID_EIGENVALUE_RATIO x the matrix scale) is not
    structure.expected_zero_modes, naming the exact rigid motions the model resists.  A zero mode counted as an
    elastic one would otherwise enter the sweep silently (the free coupled test gearbox's spurious 0.185 Hz mode:
    docs/stability.md, "Hard case").  Where the expected count is unknown (expected_zero_modes None: a supported
    housing without an interior, imported or built, whose partial supports may leave mechanisms) nothing is
    checked and the count found is used, as before.  K: structure.K, or its symmetric stand-in for "projected"."""
    modes = modal.solve_modes(K, structure.M, f_basis, keep_solver=keep_solver,
                              null_space=modal.known_null_space(structure))
    return modal.structure_basis(modes, structure)


def basis_facts(modes: modal.ModalBasis, f_basis: float) -> dict:
    """harmonic.json's facts of a modal basis: elastic modes in it, zero modes found and expected (None: not
    known, not checked), its f_max (Hz)."""
    return {"modes_in_basis": len(modes.eigenvalues) - modes.rigid_count, "rigid_modes": modes.rigid_count,
            "rigid_modes_expected": modes.expected_zero_modes, "basis_f_max_hz": f_basis}


def run(structure, spec, loads, damping, *, extra_points: dict | None = None) -> ForcedResult:
    """Assemble the loads, run the chosen solver(s) on spec.frequencies and evaluate the responses.

    structure: a housingfe.fe.structure.Structure (the housing model, or the housing coupled with its interior);
    spec: the harmonic spec (housingfe.scene.HarmonicSpec); loads: load specs (housingfe.scene.LoadSpec); damping:
    a housingfe.scene.DampingSpec; extra_points: named point sets whose complex displacements are kept per line
    (e.g. the radiating facets for the numerical radiation model: housingfe.radiation.housing.radiation_points).
    The sound power is not computed here (housingfe.radiation).  The modal / projected solvers' basis must have
    the structure's expected number of zero modes (modal_basis: SolverError otherwise); the direct solver uses
    no basis and checks nothing."""
    from housingfe.response.harmonic import StructureObserver

    t0 = time.perf_counter()
    loads = assemble_loads(structure, loads)
    extra = dict(extra_points or {})
    if spec.points:
        from housingfe.response.observers import (
            RESPONSE_POINTS,
            locate_response_points,
            response_point_samples,
        )

        points = locate_response_points(structure.housing, spec.points)
        extra[RESPONSE_POINTS] = response_point_samples(points)
    else:
        points = []
    nodes = [spec.angular_velocity_node] if spec.angular_velocity_node else []
    for node in nodes:
        structure.shaft_axis(node)     # a clear error for a node that is not on a shaft
    observer = StructureObserver(structure, spec.surface, spec.sample_points, loads, extra, nodes)
    K, M, C = structure.K, structure.M, structure.C
    damping = damping_model(damping, structure)
    freqs = spec.frequencies
    timings = {"loads_and_observer_s": time.perf_counter() - t0}
    facts = {"frequencies": len(freqs), "df_hz": spec.df, "surface_area_m2": observer.area,
             "dofs": K.getSize()[0]}
    results, resp = {}, {}
    for solver in choose_solver(spec, damping, structure):
        t1 = time.perf_counter()
        if solver == "modal":
            f_basis = spec.modal_basis_factor * spec.f_max
            # the residual vectors reuse the eigensolve's factorisation of K - shift M
            modes = modal_basis(structure, K, f_basis, keep_solver=spec.residual)
            timings["modal_eigensolve_s"] = time.perf_counter() - t1
            facts.update(basis_facts(modes, f_basis))
            result = harmonic.modal_superposition(K, M, modes, loads, freqs, damping,
                                                  observer.reduce, residual=spec.residual)
            modes.release_solver()
            if spec.solver == "both" and spec.residual:
                plain = harmonic.modal_superposition(K, M, modes, loads, freqs, damping,
                                                     observer.reduce, residual=False)
                results["modal"], resp["modal"] = plain, responses(plain, observer, loads)
            name = result.solver
        elif solver == "projected":
            f_basis = spec.modal_basis_factor * spec.f_max
            K_sym = K if getattr(structure, "symmetric", True) else structure.basis_stiffness()
            modes = modal_basis(structure, K_sym, f_basis, keep_solver=True)
            timings["modal_eigensolve_s"] = time.perf_counter() - t1
            facts.update(basis_facts(modes, f_basis))
            result = harmonic.projected(K, M, modes, loads, freqs, damping, observer.reduce, C=C, K_sym=K_sym)
            modes.release_solver()
            name = "projected"
            if result.unstable:
                # a self-excited mode (oil whirl of a fluid film): the steady-state response is not what happens
                top = result.unstable[0]
                facts["unstable_modes"] = result.unstable
                facts["stability"] = (f"unstable: {len(result.unstable)} self-excited mode(s), the fastest at "
                                      f"{top['frequency_hz']:.4g} Hz growing at {top['growth_rate_per_s']:.3g} 1/s "
                                      "(oil whirl of a fluid-film bearing?): the steady-state response is invalid")
                if K.getComm().getRank() == 0:
                    print(f"housingfe: warning: {facts['stability']}", file=sys.stderr)
        else:
            result = harmonic.direct(K, M, loads, freqs, damping, observer.reduce, C=C)
            name = "direct"
        timings[f"{name}_s"] = time.perf_counter() - t1
        results[name], resp[name] = result, responses(result, observer, loads)
    forced = ForcedResult(spec, loads, resp, observer, results, timings, facts,
                          to_fe=structure.to_housing,
                          angular_velocity_node=spec.angular_velocity_node, response_points=points)
    if spec.deflection_shapes_hz:
        t1 = time.perf_counter()
        forced.deflection_shapes = deflection_shapes(forced, K, M, damping, C)
        timings["deflection_shapes_s"] = time.perf_counter() - t1
    if spec.angular_velocity_node:
        add_angular_velocity_transfer(forced, structure)
    return forced


def add_angular_velocity_transfer(forced: ForcedResult, structure) -> None:
    """TF_omega = L_v - L_omega (dB, v0 = omega0 = 5e-8, thesis eq. 5.5) per load response, with omega the
    angular velocity of `angular_velocity_node` about its shaft axis; stored in response.extras as
    "L_omega_dB" (per unit load) and "TF_omega_dB"."""
    from housingfe import levels
    from housingfe.response.observers import node_key

    node = forced.angular_velocity_node
    axis = structure.shaft_axis(node)
    for resps in forced.responses.values():
        for r in resps:
            theta = axis @ r.extras["point_values"][node_key(node)][3:6]
            omega2 = (2 * np.pi * r.frequencies) ** 2 * np.abs(theta) ** 2
            r.extras["omega_mean_square"] = omega2
            r.extras["L_omega_dB"] = levels.level(omega2, levels.OMEGA0)
            r.extras["TF_omega_dB"] = r.transfer_db - r.extras["L_omega_dB"]


def deflection_shapes(forced: ForcedResult, K, M, damping, C=None) -> list[DeflectionShape]:
    """Operating deflection shapes of every load case at the grid lines nearest `spec.deflection_shapes_hz`,
    scaled by the load amplitude (rms phasors, m).  From the direct solver when it ran (re-solved at those
    lines, since the sweep keeps no vectors), else from the modal basis of the modal / projected solver."""
    spec = forced.spec
    freqs = spec.frequencies
    lines = sorted({int(np.argmin(abs(freqs - f))) for f in spec.deflection_shapes_hz})
    f_lines = freqs[lines]
    if "direct" in forced.results:
        res = harmonic.direct(K, M, forced.loads, f_lines, damping, lambda vecs: [v.copy() for v in vecs], C=C)
        solver, index = "direct", list(range(len(lines)))
    else:
        # the last modal-type result: "modal+residual" or "projected" rather than the plain "modal" of "both"
        solver, res = [(n, r) for n, r in forced.results.items() if r.modal_vectors is not None][-1]
        index = lines
    out = []
    for j, lc in enumerate(forced.loads):
        amplitude = lc.amplitude(f_lines)
        for m, k in enumerate(index):
            if res.modal_vectors is not None:
                basis, c = res.modal_vectors[j], res.blocks[j][0].coeffs[:, k]
            else:
                block = res.blocks[j][k]
                basis, c = block.reduced, block.coeffs[:, 0]
            ur, ui = basis[0].duplicate(), basis[0].duplicate()
            ur.set(0.0)
            ui.set(0.0)
            for vec, ck in zip(basis, c * amplitude[m]):
                ur.axpy(ck.real, vec)
                ui.axpy(ck.imag, vec)
            if forced.to_fe is not None:
                ur, ui = forced.to_fe(ur), forced.to_fe(ui)
            out.append(DeflectionShape(lc.name, float(f_lines[m]), ur, ui, solver))
    return out


def point_rows(forced: ForcedResult) -> list:
    """Rows of points.csv: per solver, load case, response point, direction and line, the receptance H (m per
    unit load: m/N, m/(N m) or m/Pa), mobility i omega H and accelerance -omega^2 H (re, im, magnitude,
    phase in degrees, time dependence e^{i omega t}), then the load's rms amplitude and the rms displacement,
    velocity and acceleration it causes there."""
    from housingfe.response.observers import RESPONSE_POINTS

    if not forced.response_points:
        return []
    unit = {"force": "N", "moment": "N m", "pressure": "Pa"}
    rows = []
    for solver, resps in forced.responses.items():
        for r in resps:
            values = r.extras["point_values"][RESPONSE_POINTS]
            omega = 2 * np.pi * r.frequencies
            row = 0
            for rp in forced.response_points:
                for d, label in zip(rp.directions, rp.labels):
                    H = values[row]
                    row += 1
                    frfs = (H, 1j * omega * H, -omega**2 * H)
                    for k, f in enumerate(r.frequencies):
                        cells = []
                        for h in frfs:
                            cells += [h[k].real, h[k].imag, abs(h[k]), float(np.degrees(np.angle(h[k])))]
                        a = r.amplitude[k]
                        rows.append([r.name, solver, rp.name, label, d[0], d[1], d[2], f, unit.get(r.kind, r.kind)]
                                    + cells + [a, abs(frfs[0][k]) * a, abs(frfs[1][k]) * a, abs(frfs[2][k]) * a])
    return rows


POINT_COLUMNS = (["load_case", "solver", "point", "direction", "dx", "dy", "dz", "frequency_hz", "load_unit"]
                 + [f"{q}_{p}" for q in ("receptance", "mobility", "accelerance")
                    for p in ("re", "im", "abs", "phase_deg")]
                 + ["load_rms", "displacement_rms_m", "velocity_rms_m_s", "acceleration_rms_m_s2"])
