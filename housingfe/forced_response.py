"""The harmonic analysis of a scene: loads -> solver(s) -> responses, with the solver chosen per problem."""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from housingfe.loads import assemble_load
from housingfe.response import SurfaceObserver, responses
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


def damping_model(scene, model) -> harmonic.Damping:
    """Damping of the scene: global eta, eta per band, modal xi, or per-material eta (matrix D)."""
    spec = scene.damping
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
    D = _material_damping_matrix(model)
    return harmonic.Damping(lambda f: np.zeros(np.shape(f)), D=D)


def _material_damping_matrix(model):
    """K_eta = int eta sigma:eps dx from per-material loss factors (None if all are zero)."""
    from dolfinx.fem.petsc import assemble_matrix

    from housingfe.solvers.elasticity import stiffness_form

    eta = model.materials.eta
    if model.V.mesh.comm.allreduce(float(np.abs(eta.x.array).max(initial=0.0)), op=_max()) == 0.0:
        return None
    D = assemble_matrix(stiffness_form(model.V, model.materials, weight=eta), bcs=model.bcs, diagonal=0.0)
    D.assemble()
    return D


def _max():
    from mpi4py import MPI

    return MPI.MAX


def choose_solver(spec, damping: harmonic.Damping) -> list[str]:
    """Solvers to run: 'auto' is modal for proportional damping, direct when a non-proportional damping
    matrix is present."""
    if damping.modal_ratios and spec.solver in ("direct", "both"):
        from housingfe.errors import InputError

        raise InputError("damping.modal_damping_ratios: per-mode damping exists only in the modal solver; "
                         "use solver = \"modal\" or a loss factor")
    if spec.solver == "both":
        return ["modal", "direct"]
    if spec.solver == "auto":
        return ["direct"] if damping.D is not None else ["modal"]
    return [spec.solver]


def run(model, spec) -> ForcedResult:
    """Assemble the loads, run the chosen solver(s) on spec.frequencies and evaluate the responses."""
    scene = model.scene
    t0 = time.perf_counter()
    loads = [assemble_load(load, model.housing, model.V, model.bcs) for load in scene.loads]
    extra, plate_ids = {}, None
    if scene.radiation is not None and scene.radiation.model == "numerical":
        from housingfe.radiation.housing import RADIATION_POINTS, radiation_points

        extra[RADIATION_POINTS], plate_ids = radiation_points(model, scene.radiation)
    observer = SurfaceObserver(model, spec.surface, spec.sample_points, loads, extra)
    damping = damping_model(scene, model)
    freqs = spec.frequencies
    timings = {"loads_and_observer_s": time.perf_counter() - t0}
    facts = {"frequencies": len(freqs), "df_hz": spec.df, "surface_area_m2": observer.area}
    results, resp = {}, {}
    for solver in choose_solver(spec, damping):
        t1 = time.perf_counter()
        if solver == "modal":
            f_basis = spec.modal_basis_factor * spec.f_max
            modes = modal.solve_modes(model.K, model.M, f_basis)
            timings["modal_eigensolve_s"] = time.perf_counter() - t1
            facts.update(modes_in_basis=len(modes.eigenvalues) - modes.rigid_count,
                         rigid_modes=modes.rigid_count, basis_f_max_hz=f_basis)
            result = harmonic.modal_superposition(model.K, model.M, modes, loads, freqs, damping,
                                                  observer.reduce, residual=spec.residual)
            if spec.solver == "both" and spec.residual:
                plain = harmonic.modal_superposition(model.K, model.M, modes, loads, freqs, damping,
                                                     observer.reduce, residual=False)
                results["modal"], resp["modal"] = plain, responses(plain, observer, loads)
            name = result.solver
        else:
            result = harmonic.direct(model.K, model.M, loads, freqs, damping, observer.reduce)
            name = "direct"
        timings[f"{name}_s"] = time.perf_counter() - t1
        results[name], resp[name] = result, responses(result, observer, loads)
    forced = ForcedResult(spec, loads, resp, observer, results, timings, facts)
    if scene.radiation is not None:
        from housingfe.radiation.housing import sound_power

        t1 = time.perf_counter()
        forced.sound_power = sound_power(forced, model, plate_ids)
        timings["radiation_s"] = time.perf_counter() - t1
    return forced


def deflection_shape(result: ForcedResult, load_index: int, frequency: float):
    """Complex displacement field (real, imaginary PETSc Vecs) of a load case at the grid line nearest
    `frequency` (modal solver), for ParaView."""
    res = next((r for r in result.results.values() if r.modal_vectors is not None), None)
    if res is None:
        return None
    k = int(np.argmin(abs(res.frequencies - frequency)))
    basis = res.modal_vectors[load_index]
    c = res.blocks[load_index][0].coeffs[:, k]
    ur, ui = basis[0].duplicate(), basis[0].duplicate()
    ur.set(0.0)
    ui.set(0.0)
    for vec, ck in zip(basis, c):
        ur.axpy(ck.real, vec)
        ui.axpy(ck.imag, vec)
    return res.frequencies[k], ur, ui


