"""`housingfe run <scene>`: scene -> geometry -> model -> solver -> report, written atomically."""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from housingfe import published, report
from housingfe.errors import SolverError
from housingfe.scene import load_housing_scene


def run_scene(name_or_path: str, out_dir: str | None = None, overrides: list[str] | None = None) -> Path:
    """Run every analysis the scene lists and write the result folder; returns its path."""
    from mpi4py import MPI

    t_start = time.perf_counter()
    scene, path = load_housing_scene(name_or_path, overrides)
    comm = MPI.COMM_WORLD
    out = Path(out_dir or f"results/{scene.scene.name}")

    from housingfe.model import build_model
    from housingfe.solvers import modal

    model = build_model(scene, comm)
    modal_spec, harmonic_spec = scene.analysis.modal, scene.analysis.harmonic
    modes = None
    if modal_spec is not None:
        modes = modal.solve_modes(model.K, model.M, modal_spec.f_max, tol=modal_spec.tolerance)
        summary = modal_summary(model, modes, modal_checks(model, modes), time.perf_counter() - t_start)
    forced = None
    if harmonic_spec is not None:
        from housingfe import forced_response

        forced = forced_response.run(model, harmonic_spec)
    with report.atomic_output_dir(out, comm) as tmp:
        if modes is not None:
            report.write_modal_outputs(tmp, model, modes, summary, comm)
        if forced is not None:
            report.write_harmonic_outputs(tmp, model, forced, comm)
    if comm.rank == 0:
        if modes is not None:
            print(report.modal_summary_text(summary))
        if forced is not None:
            print(report.harmonic_summary_text(forced))
        print(f"total wall time {time.perf_counter() - t_start:.1f} s; results: {out}/")
    return out


def modal_checks(model, result) -> dict:
    """Rigid-body count and the mass / centre of gravity that the rigid modes carry (free structures)."""
    from housingfe.solvers import elasticity, modal

    freqs = result.frequencies_hz
    n_rigid = result.rigid_count
    checks: dict = {"rigid_modes_expected": model.rigid_modes_expected}
    if model.rigid_modes_expected and n_rigid != model.rigid_modes_expected:
        raise SolverError(f"a free structure must have {model.rigid_modes_expected} rigid-body modes, found "
                          f"{n_rigid}: lowest frequencies {np.round(freqs[:7], 4).tolist()} Hz")
    if n_rigid == 6:
        props = modal.rigid_body_mass_properties(model.M, result.vectors[:n_rigid],
                                                 elasticity.rigid_body_vectors(model.V))
        checks.update(props)
    checks["geometry_mass_kg"] = model.material.density * model.housing.volume
    checks["geometry_centre_of_gravity_m"] = model.housing.centroid
    return checks


def modal_summary(model, result, checks: dict, wall_time_s: float) -> dict:
    """The content of modes.json."""
    n_rigid = result.rigid_count
    freqs = result.frequencies_hz
    scene = model.scene
    summary = {
        "scene": scene.scene.name,
        "description": scene.scene.description,
        "frequencies_hz": freqs[n_rigid:],
        "rigid_body_frequencies_hz": freqs[:n_rigid],
        "mass_kg": checks["geometry_mass_kg"],
        "mass_from_rigid_modes_kg": checks.get("mass_kg"),
        "centre_of_gravity_m": checks["geometry_centre_of_gravity_m"],
        "centre_of_gravity_from_rigid_modes_m": checks.get("centre_of_gravity_m"),
        "dofs": model.dofs,
        "f_max_hz": result.f_max,
        "complete": result.complete,
        "eigenvalues_below_f_max_by_inertia": result.expected_count,
        "residuals": result.residuals[n_rigid:],
        "rigid_body_residuals": result.residuals[:n_rigid],
        "element": f"{model.housing.element}{'27' if model.housing.element == 'hex' else '10'}"
                   if model.scene.mesh.degree == 2 else f"{model.housing.element} P{model.scene.mesh.degree}",
        "element_size_m": model.housing.element_size,
        "mesh_quality": model.housing.quality,
        "mpi_ranks": model.V.mesh.comm.size,
        "timings_s": {**model.timings, **result.timings},
        "wall_time_s": wall_time_s,
    }
    summary["published"] = published.modal_comparison(scene, summary)
    return summary
