"""`housingfe run <scene>`: scene -> geometry -> model -> solver -> report, written atomically."""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from housingfe import outputs, report
from housingfe.errors import InputError
from housingfe.scene import load_housing_scene
from housingfe.verification import published


def _runup_runner(name_or_path: str, out_dir: str | None = None, overrides: list[str] | None = None) -> Path:
    from housingfe.runup.scene import run_scene as run_runup

    return run_runup(name_or_path, out_dir, overrides)


def _source_runner(name_or_path: str, out_dir: str | None = None, overrides: list[str] | None = None) -> Path:
    from housingfe.ranks import on_rank_zero
    from housingfe.source.cli import run

    if overrides:
        raise InputError(f"{name_or_path}: --set: source scenes take no overrides (edit a copy of the scene)")
    # the gear source models are serial: under mpirun rank 0 runs and writes the folder, the other ranks wait
    # (two writers raced for the folder's lock and one stopped with 'another housingfe run is writing it')
    return on_rank_zero(lambda: run(name_or_path, out_dir))


# scene kind -> runner (a registry: a new kind of scene is one entry); "housing" is run_housing_scene below
SCENE_RUNNERS = {"runup": _runup_runner, "source": _source_runner}


def run_scene(name_or_path: str, out_dir: str | None = None, overrides: list[str] | None = None) -> Path:
    """Run a scene of any kind (its [scene].kind picks the runner of SCENE_RUNNERS, housing scenes by default) and
    write its result folder; returns its path."""
    from housingfe.scenefile import read_scene_dict

    data, path = read_scene_dict(name_or_path)
    info = data.get("scene")
    kind = info.get("kind") if isinstance(info, dict) else None
    if not isinstance(info, dict):
        # the other TOML files of the package are no scenes: say which command takes them (else the housing
        # schema reported "name: unknown key (also missing: geometry, analysis; ...)")
        if "variants" in data:
            raise InputError(f"{path}: a design-variant family file ([[variants]]), not a scene: run it with "
                             f"`housingfe study {name_or_path}`")
        if "parameters" in data and "targets" in data:
            raise InputError(f"{path}: a model-updating spec ([[parameters]], [[targets]]), not a scene: run it "
                             f"with `housingfe update {name_or_path}`")
    runner = SCENE_RUNNERS.get(kind, run_housing_scene)
    return runner(name_or_path, out_dir, overrides)


def run_housing_scene(name_or_path: str, out_dir: str | None = None, overrides: list[str] | None = None) -> Path:
    """Run every analysis a housing scene lists and write the result folder; returns its path."""
    from mpi4py import MPI

    t_start = time.perf_counter()
    scene, path = load_housing_scene(name_or_path, overrides)
    comm = MPI.COMM_WORLD
    out = Path(out_dir or f"results/{scene.scene.name}")
    outputs.reserve_output(out, comm, inputs=[path])   # a bad or busy output place stops here, before the mesh
    try:
        return _run(scene, out, comm, t_start)
    except InputError as exc:
        # problems found on the mesh (a load point off its surface, a response point too far) name the key;
        # the file they are in is known only here
        message = str(exc)
        raise InputError(message if message.startswith(str(path)) else f"{path}: {message}") from None


def _run(scene, out: Path, comm, t_start: float) -> Path:
    from housingfe.scene import build_model_from_scene
    from housingfe.solvers import modal

    model = build_model_from_scene(scene, comm)
    structure = model           # a housingfe.fe.structure.Structure: the housing, or housing + interior
    interior = None
    if scene.coupling is not None:
        from housingfe.drivetrain.interior import build_interior

        structure = interior = build_interior(model, scene.coupling, scene.analysis.f_max)
    modal_spec, harmonic_spec = scene.analysis.modal, scene.analysis.harmonic
    modes = None
    if modal_spec is not None:
        modes = modal.modes(structure, modal_spec.f_max, tol=modal_spec.tolerance)
        summary = modal_summary(model, modes, modal_checks(model, modes), time.perf_counter() - t_start)
        if interior is not None:
            summary["interior"] = interior_summary(interior, modes)
            summary["published"] += published.interior_comparison(scene, summary["interior"])
    forced = None
    if harmonic_spec is not None:
        forced = forced_response(scene, model, structure)
        if interior is not None:
            forced.facts["bores"] = bore_records(interior)
    with outputs.atomic_output_dir(out, comm) as tmp:
        if modes is not None:
            housing_modes = modes.to_housing()
            report.write_modal_outputs(tmp, model, housing_modes, summary, comm, scene.output)
        if forced is not None:
            report.write_harmonic_outputs(tmp, model, forced, comm, scene_name=scene.scene.name,
                                          pictures=scene.output.pictures)
    if comm.rank == 0:
        if modes is not None:
            print(report.modal_summary_text(summary))
        if forced is not None:
            print(report.harmonic_summary_text(forced))
            if modes is None and model.resolution is not None:
                print("\n".join(report.resolution_lines(model.resolution.as_dict())))
        print(f"total wall time {time.perf_counter() - t_start:.1f} s; results: {out}/")
    return out


def forced_response(scene, model, structure):
    """The harmonic stages of a scene: forced response of the structure to the scene's loads, then the sound
    power of the scene's radiation spec (if any) stored on the result."""
    from housingfe.response import forced as forced_stage

    radiation = scene.radiation
    radiator = None
    if radiation is not None:
        from housingfe.radiation.radiators import radiator_from_spec

        # the radiator says which extra surface points it needs (the numerical model: its plates' facet points)
        radiator = radiator_from_spec(radiation, model.housing, model.material)
    extra = radiator.extra_points(structure) if radiator is not None else {}
    forced = forced_stage.run(structure, scene.analysis.harmonic, scene.loads, scene.damping, extra_points=extra)
    if radiator is not None:
        from housingfe.radiation.housing import sound_power

        t1 = time.perf_counter()
        forced.sound_power = sound_power(forced, model, radiation, radiator=radiator)
        forced.timings["radiation_s"] = time.perf_counter() - t1
    return forced


def modal_checks(model, result) -> dict:
    """Rigid-body count (result: a ModalBasis, checked against its structure's expected zero modes) and the mass /
    centre of gravity that the rigid modes carry (free structures).  With an
    interior the expected zero modes are the housing's plus the interior's mechanisms on fixed bores (counted
    independently on the small interior matrices), and the mass includes shafts and gears."""
    from housingfe.solvers import modal

    n_rigid = result.rigid_count
    expected = result.expected_zero_modes
    checks: dict = {"rigid_modes_expected": expected or 0}
    result.check_zero_modes()
    if model.rigid_modes_expected == 6 and n_rigid >= 6:
        structure = result.structure
        checks.update(modal.rigid_body_mass_properties(structure.M, result.vectors[:n_rigid],
                                                       structure.rigid_body_vectors()))
    checks["geometry_mass_kg"] = model.material.density * model.housing.volume
    checks["geometry_centre_of_gravity_m"] = model.housing.centroid
    return checks


# more eigenvalues below f_max than this share of the DOFs: warned (a resolved mesh has under 1 %)
MODES_PER_DOF_SUSPECT = 0.1


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
        # complete = every eigenvalue of the discrete model below f_max was found (inertia count): how close the
        # discrete model's eigenvalues are to the housing's is the resolution's estimate
        "complete": result.complete,
        "complete_means": "all eigenvalues of the discrete FE model below f_max were found (inertia count); its "
                          "discretisation error is estimated under resolution",
        "eigenvalues_below_f_max_by_inertia": result.expected_count,
        "residuals": result.residuals[n_rigid:],
        "rigid_body_residuals": result.residuals[:n_rigid],
        "element": f"{model.housing.element}{'27' if model.housing.element == 'hex' else '10'}"
                   if model.element_degree == 2 else f"{model.housing.element} P{model.element_degree}",
        "element_size_m": model.housing.element_size,
        # the size the resolution rule gave before it was rounded down to 3 significant digits (reproducible
        # meshes, housingfe.fe.model.quantise_derived_size); null when mesh.size was given
        "element_size_unrounded_m": getattr(model, "derived_element_size", None),
        # the meshes made for a derived size, first the derived one: finer sizes of the ladder only where the quality
        # rule refused it (housingfe.fe.model.mesh_on_size_ladder); null when mesh.size was given
        "element_size_tries": getattr(model, "element_size_tries", None),
        "mesh_quality": model.housing.quality,
        "mpi_ranks": model.V.mesh.comm.size,
        "timings_s": {**model.timings, **result.timings},
        "wall_time_s": wall_time_s,
        "resolution": model.resolution.as_dict() if model.resolution is not None else None,
    }
    resolution = summary["resolution"]
    # a mesh that resolves f_max has far more DOFs than modes below it (box-free: 39 k DOFs, 42 modes); eigenvalues
    # near the top of the discrete spectrum are mesh artefacts, whatever the inertia count proves
    if resolution is not None and result.expected_count > MODES_PER_DOF_SUSPECT * model.dofs:
        resolution["warnings"].append(
            f"{result.expected_count} eigenvalues below f_max on {model.dofs} DOFs: f_max lies in the top of the "
            "discrete spectrum, where the modes are the mesh's, not the housing's")
    summary["published"] = published.modal_comparison(scene, summary)
    return summary


def interior_summary(interior, result) -> dict:
    """The interior's share of the coupled modes and its modes on rigid bores (Sec. 4.6's two models)."""
    n_rigid = result.rigid_count
    share = interior.interior_fraction(result.vectors[n_rigid:])
    freqs = result.frequencies_hz[n_rigid:]
    rigid = interior.rigid
    el = rigid.frequencies_hz[rigid.mechanisms:]
    return {
        "rigid_bores_frequencies_hz": el,
        "rigid_bores_bearing_energy": rigid.bearing_energy[rigid.mechanisms:],
        "rigid_bores_mechanisms": rigid.mechanisms,
        "rigid_bores_dofs": rigid.dofs,
        "coupled_interior_energy_share": share,
        "coupled_interior_modes_hz": freqs[share > 0.5],
        "coupled_interior_mode_numbers": (np.flatnonzero(share > 0.5) + 1).tolist(),
        "coupled_housing_modes": int(np.sum(share <= 0.5)),
        "coupled_dofs": interior.system.size,
        "coupling_s": interior.model.timings.get("coupling_s"),
        "bores": bore_records(interior),
    }


def bore_records(interior) -> dict:
    """Where each bore master went (housingfe.drivetrain.bore_axis.BoreFit.summary; None: the scene gave the
    centre), for summary.json and harmonic.json."""
    return {name: None if fit is None else fit.summary() for name, fit in interior.bores.items()}
