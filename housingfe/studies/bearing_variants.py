"""Bearing variants of the test gearbox (thesis Sec. 5.4, 5.8, 5.9): TF_omega(f) for each configuration.

`housingfe bearing-variants` takes a housing scene with an interior (default `test-gearbox-interior`: the test
gearbox, pinion and wheel shafts with their gears, four bearings, the gear mesh, a 1 N m torque at the wheel
centre, modal damping xi = 0.04), builds the housing model once and, for every configuration of
`housingfe.bearings.configurations` (ball, angular contact, self-aligning, tapered roller: single helical gear set B;
cylindrical roller, fluid film: the double helical set), recomputes

  * the gear forces at the pinion torque (housingfe.source: tooth loads, mean mesh stiffness of the set),
  * the mean bearing loads from the statics of each two-bearing shaft (the front bearing locates axially),
  * the bearing matrices (6x6 K, and C for fluid films) at those loads,

couples them with the housing and computes TF_omega = L_v - L_omega (eq. 5.5) on the scene's frequency lines.
Results: TF_omega per configuration (surface average and the scene's sample-point sets), the differences
ball - configuration with mean and standard deviation over the measured speed range (800-1500 rev/min, tooth
frequency 320-600 Hz) and over all lines, CSV + PNG, next to the thesis' 7.3 dB (s.d. 4.5) for ball minus
self-aligning.  The thesis' FEM had no self-aligning bearing model: it used the ball bearing matrices with the
moment terms zeroed; that comparison is the configuration `ball_zero_moment`, next to our spherical roller
model `self_aligning` (whose radial stiffness is several times the ball bearing's).  `ball_zero_tilt_stiffness`
zeroes only the tilt block and keeps the loaded ball bearings' force-tilt couplings: the two differ by what the
couplings (the axial offset of a bearing's load centre) do, which in the test gearbox is all of it.
"""
from __future__ import annotations

import argparse
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from housingfe.errors import InputError

GEAR_SCENES = {"single_helical": "gearset-B", "double_helical": "gearset-double-helical"}
# Sec. 3.5: the fluid-film operating points; signed about the common +y shaft axis (the wheel turns the other way)
SPEEDS_RPM = {"pinion": 1500.0, "wheel": -500.0}
TORQUE_NM = 2000.0                                    # pinion torque, Sec. 5.8 (T = 2000 N m)
SPEED_RANGE_HZ = (320.0, 600.0)                       # tooth frequency at 800-1500 rev/min (0.4 Hz per rpm)
POSITIONS = ("pinion_front", "pinion_back", "wheel_front", "wheel_back")
# the thesis' FEM stand-in for self-aligning bearings (Sec. 5.8): the ball bearing matrices with their moment
# rows and columns zeroed ("the stiffness matrix of the ball bearings was used with zero moment stiffness")
THESIS_SELF_ALIGNING = "ball_zero_moment"
# the same with only the tilt block k_theta,theta zeroed: the force-tilt couplings k_(x,y,z),theta of the loaded ball
# bearings (the axial offset of their load centre, 14-17 mm here) kept.  In the test gearbox the couplings make
# the whole ball - ball_zero_moment difference, the tilt stiffness ~0 dB (benchmarks/experiments/bearing_ranking,
# section 3)
ZERO_TILT_STIFFNESS = "ball_zero_tilt_stiffness"
# a sensitivity of the moment terms: the ball matrices with Appendix C's rotational values (3.4-5.2e6 N m/rad) on
# every bearing.  They are NOT one bearing's moment stiffness: Appendix C's theta values are the lumped shaft's
# tilt on its two bearings, k_theta = k_r L^2 / 4 with one span L = 0.16-0.17 m for all four
# (tests/studies/test_appendix_c_tilt.py); a bearing's own (Lim, Sec. 4.6: 1.7-2.5e5) is 15-30x smaller
APPENDIX_C_MOMENTS = "ball_appendix_c_moments"


# ------------------------------------------------------------------------------------------- gear forces
@dataclass
class GearForces:
    """The mean gear force on the pinion (N, global axes) at the mesh point, the mean mesh stiffness (N/m) along
    the contact normal `direction` (unit, global)."""

    force_on_pinion: np.ndarray
    stiffness: float
    direction: np.ndarray
    gear_set: str


def gear_forces(gear_set: str, torque: float, point, pinion_centre, wheel_centre, shaft_axis) -> GearForces:
    """Tooth forces and mean mesh stiffness of a gear set (housingfe.source) for a pinion torque (N m), placed
    in the housing: the line of action lies in the transverse plane at the operating pressure angle from the
    common tangent, tilted out of it by the base helix angle; a double helical set's two halves cancel axially:
    the transverse line of action with S cos^2(beta_b) and T1 / r_b1 (docs/drivetrain.md)."""
    from housingfe.drivetrain.description import mesh_line_of_action
    from housingfe.scenefile import read_scene_dict
    from housingfe.source.roosmalen import run as roosmalen
    from housingfe.source.stiffness import normal_force_from_torque, stiffness_curve

    data, path = read_scene_dict(GEAR_SCENES[gear_set])
    pair, _, _, _, model = roosmalen.build(roosmalen.parse(data, str(path)), str(path))
    normal = normal_force_from_torque(pair, torque)
    stiffness = stiffness_curve(model, normal, 16).mean
    n, resultant, _ = mesh_line_of_action(pair, pinion_centre, wheel_centre, shaft_axis)
    # the wheel pushes the pinion along -n: away from the wheel (radial), against the tangent, axially -a
    return GearForces(-normal * resultant * n, stiffness * resultant**2, n, gear_set)


def shaft_bearing_loads(force, point, front, back, axis) -> tuple[np.ndarray, np.ndarray]:
    """Loads (N, global) that a shaft carrying `force` at `point` puts on its front (locating: takes the axial
    force) and back (floating) bearings at positions front, back on the shaft axis: force and moment balance."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    f, p = np.asarray(force, float), np.asarray(point, float)
    front, back = np.asarray(front, float), np.asarray(back, float)
    axial = (f @ a) * a
    radial = f - axial
    # moment of the force about the front bearing centre, without its axial-axis component (the torque)
    m = np.cross(p - front, f)
    m -= (m @ a) * a
    span = (back - front) @ a
    # back bearing radial load R_b: (back - front) x R_b = m  ->  R_b = (m x a) / span (R_b perpendicular to a)
    r_back = np.cross(m, a) / span
    return radial - r_back + axial, r_back


def to_bearing_frame(load: np.ndarray, axis) -> tuple[float, float, float, float, float]:
    """(Fx, Fy, Fz, Mx, My) in the bearing frame of housingfe.drivetrain.coupling.axis_frame(axis) (z = shaft axis)."""
    from housingfe.drivetrain.coupling import axis_frame

    local = axis_frame(axis).T @ load
    return (float(local[0]), float(local[1]), float(local[2]), 0.0, 0.0)


# ------------------------------------------------------------------------------------------ configurations
def configuration_spec(base, config: str, torque: float = TORQUE_NM):
    """The scene's [coupling] spec with the bearings and gear mesh of one configuration.

    base: CouplingSpec with bearings named by POSITIONS and one gear mesh between two shaft nodes.  Returns
    (spec, loads {position: (Fx, Fy, Fz, Mx, My)}, GearForces)."""
    from housingfe.bearings.configurations import bearing_matrices, configurations

    configs = configurations()
    if config == THESIS_SELF_ALIGNING:
        return _ball_with_moment_stiffness(base, torque, {"pinion": (0.0, 0.0), "wheel": (0.0, 0.0)})
    if config == ZERO_TILT_STIFFNESS:
        return _ball_with_moment_stiffness(base, torque, {"pinion": (0.0, 0.0), "wheel": (0.0, 0.0)},
                                           keep_couplings=True)
    if config == APPENDIX_C_MOMENTS:
        from housingfe.verification.published import thesis

        diag = thesis()["gears"]["interior_model"]["bearing_stiffness_diag"]
        return _ball_with_moment_stiffness(base, torque, {"pinion": (diag["thx1"], diag["thy1"]),
                                                          "wheel": (diag["thx2"], diag["thy2"])})
    if config not in configs:
        raise InputError(f"bearing configuration {config!r}: unknown (known: {', '.join(configs)})")
    if len(base.gear_meshes) != 1:
        raise InputError("bearing-variants: the scene's [coupling] needs exactly one gear mesh")
    bearings = {b.name: b for b in base.bearings}
    missing = [p for p in POSITIONS if p not in bearings]
    if missing:
        raise InputError(f"bearing-variants: the scene's bearings need the names {', '.join(POSITIONS)} "
                         f"(missing {', '.join(missing)})")
    shafts = {s.name: s for s in base.shafts}
    mesh = base.gear_meshes[0]
    pos = _node_positions(base)
    axis = np.asarray(shafts[mesh.a.split(":")[0]].axis, float)
    forces = gear_forces(configs[config].gear_set, torque, mesh.point, pos[mesh.a], pos[mesh.b], axis)
    loads = {}
    for shaft, node, sign in (("pinion", mesh.a, 1.0), ("wheel", mesh.b, -1.0)):
        front, back = bearings[f"{shaft}_front"], bearings[f"{shaft}_back"]
        lf, lb = shaft_bearing_loads(sign * forces.force_on_pinion, mesh.point, pos[front.shaft_node],
                                     pos[back.shaft_node], axis)
        loads[f"{shaft}_front"] = to_bearing_frame(lf, front.axis)
        loads[f"{shaft}_back"] = to_bearing_frame(lb, back.axis)
    # both front bearings locate axially (a double helical wheel is otherwise axially free: its mesh has no
    # axial component)
    matrices = bearing_matrices(config, loads, SPEEDS_RPM, axial_location="both")
    new_bearings = []
    for b in base.bearings:
        K, C = matrices[b.name]
        new_bearings.append(b.model_copy(update={
            "designation": None, "load": None, "model": None, "fixed_tilt": None, "stiffness": None,
            "stiffness_matrix": np.asarray(K, float).tolist(),
            "damping_matrix": None if C is None else np.asarray(C, float).tolist()}))
    new_mesh = mesh.model_copy(update={"stiffness": forces.stiffness, "direction": tuple(forces.direction)})
    spec = base.model_copy(update={"bearings": new_bearings, "gear_meshes": [new_mesh]})
    return spec, loads, forces


def _ball_with_moment_stiffness(base, torque: float, moments: dict, keep_couplings: bool = False):
    """The ball configuration with the moment rows and columns of every bearing replaced by the diagonal
    (k_theta_x, k_theta_y) of `moments` {"pinion"|"wheel": (N m/rad, N m/rad)}; keep_couplings: only the tilt
    block (rows and columns 3-4 among themselves) replaced, the force-tilt couplings kept."""
    spec, loads, forces = configuration_spec(base, "ball", torque)
    bearings = []
    for b in spec.bearings:
        k = np.array(b.stiffness_matrix)
        if keep_couplings:
            k[3:5, 3:5] = 0.0
        else:
            k[3:5, :] = 0.0
            k[:, 3:5] = 0.0
        k[3, 3], k[4, 4] = moments[b.name.split("_")[0]]
        bearings.append(b.model_copy(update={"stiffness_matrix": k.tolist()}))
    return spec.model_copy(update={"bearings": bearings}), loads, forces


def _node_positions(spec) -> dict:
    """Shaft node name -> position (m) from the shaft specs (without building anything)."""
    from housingfe.drivetrain.shafts import Shaft

    out = {}
    for s in spec.shafts:
        shaft = Shaft.stepped([tuple(seg) for seg in s.segments], origin=s.origin, axis=s.axis,
                              elements_per_segment=s.elements_per_segment)
        out.update({f"{s.name}:{i}": x for i, x in enumerate(shaft.nodes)})
    return out


# ------------------------------------------------------------------------------------------------ study
@dataclass
class VariantResult:
    name: str
    frequencies: np.ndarray
    tf_omega_db: np.ndarray            # surface average (exact)
    tf_omega_points_db: dict           # sample-point set size -> TF_omega (dB)
    solver: str
    loads: dict
    mesh_stiffness: float
    timings: dict


def run_study(scene_name: str = "test-gearbox-interior", configs=None, out_dir=None, overrides=(),
              torque: float = TORQUE_NM) -> dict:
    """Run every configuration on one housing model; write CSV/PNG/summary atomically; return the results."""
    from mpi4py import MPI

    from housingfe import levels, outputs
    from housingfe.bearings.configurations import configurations
    from housingfe.drivetrain.interior import build_interior
    from housingfe.response import forced as forced_response
    from housingfe.scene import build_model_from_scene, load_housing_scene

    t_start = time.perf_counter()
    scene, scene_path = load_housing_scene(scene_name, list(overrides))
    if scene.coupling is None or scene.analysis.harmonic is None or not scene.analysis.harmonic.angular_velocity_node:
        raise InputError(f"{scene_name}: bearing-variants needs a scene with [coupling], [analysis.harmonic] and "
                         "analysis.harmonic.angular_velocity_node")
    configs = list(configs or [*configurations(), THESIS_SELF_ALIGNING, ZERO_TILT_STIFFNESS, APPENDIX_C_MOMENTS])
    from housingfe.progress import Progress

    comm = MPI.COMM_WORLD
    out = Path(out_dir or f"results/bearing-variants-{scene.scene.name}")
    outputs.reserve_output(out, comm, inputs=[scene_path])     # before the model is built
    progress = Progress(f"bearing-variants {scene.scene.name}", 1 + len(configs), "steps", comm=comm)
    model = build_model_from_scene(scene, comm)
    t_model = time.perf_counter() - t_start
    progress.update(note=f"housing model, {model.dofs} DOFs")
    spec = scene.analysis.harmonic
    results = {}
    for name in configs:
        t0 = time.perf_counter()
        cspec, loads, forces = configuration_spec(scene.coupling, name, torque)
        interior = build_interior(model, cspec, spec.modal_basis_factor * spec.f_max)
        forced = forced_response.run(interior, spec, scene.loads, scene.damping)
        solver = next(iter(forced.responses))
        r = forced.responses[solver][0]
        omega2 = r.extras["omega_mean_square"]
        points = {N: levels.level(ms, levels.V0) - levels.level(omega2, levels.OMEGA0)
                  for N, ms in r.point_mean_square_velocity.items()}
        results[name] = VariantResult(name, r.frequencies, r.extras["TF_omega_dB"], points, solver, loads,
                                      forces.stiffness, {"total_s": time.perf_counter() - t0, **forced.timings})
        if comm.rank == 0:
            print(f"{name:20s} {solver:15s} {time.perf_counter() - t0:6.1f} s", flush=True)
        progress.update(note=name)
    progress.close()
    summary = differences(results, "ball" if "ball" in results else configs[0])
    with outputs.atomic_output_dir(out, comm) as tmp:
        if comm.rank == 0:
            write_outputs(tmp, results, summary, scene, model, t_model)
    if comm.rank == 0:
        print(summary_text(summary, model, t_model))
        print(f"total wall time {time.perf_counter() - t_start:.1f} s; results: {out}/")
    return {"results": results, "summary": summary}


def differences(results: dict, reference: str = "ball", band=SPEED_RANGE_HZ) -> list[dict]:
    """Mean and standard deviation (dB) of TF_omega(reference) - TF_omega(config) over the speed range and over
    all lines, for the surface average and every sample-point set."""
    if reference not in results:
        return []
    ref = results[reference]
    f = ref.frequencies
    in_band = (f >= band[0]) & (f <= band[1])
    rows = []
    for name, r in results.items():
        if name == reference:
            continue
        for label, a, b in [("surface", ref.tf_omega_db, r.tf_omega_db)] + [
                (f"{N} points", ref.tf_omega_points_db[N], r.tf_omega_points_db[N]) for N in ref.tf_omega_points_db]:
            d = np.asarray(a) - np.asarray(b)
            rows.append({"configuration": name, "reference": reference, "average": label,
                         "mean_dB_320_600Hz": float(d[in_band].mean()), "sd_dB_320_600Hz": float(d[in_band].std()),
                         "mean_dB_all": float(d.mean()), "sd_dB_all": float(d.std()),
                         "min_dB_all": float(d.min()), "max_dB_all": float(d.max())})
    return rows


def summary_text(rows: list[dict], model, t_model: float) -> str:
    from housingfe.outputs import format_table
    from housingfe.verification import published

    data = published.thesis()["test_gearbox"]["bearings"]
    reference = rows[0]["reference"] if rows else "ball"
    lines = [f"housing model {model.dofs} DOFs built in {t_model:.1f} s; TF_omega differences {reference} - configuration "
             f"(dB; positive = the configuration transmits less); thesis FEM ball - self-aligning: "
             f"{data['fem_TF_ball_minus_self_aligning_mean_dB']} dB mean, s.d. "
             f"{data['fem_TF_ball_minus_self_aligning_sd_dB']} dB"]
    lines.append(format_table(["configuration", "average", "mean 320-600 Hz", "s.d.", "mean all", "s.d. all"],
                              [[r["configuration"], r["average"], round(r["mean_dB_320_600Hz"], 2),
                                round(r["sd_dB_320_600Hz"], 2), round(r["mean_dB_all"], 2), round(r["sd_dB_all"], 2)]
                               for r in rows]))
    return "\n".join(lines)


def write_outputs(folder: Path, results: dict, rows: list[dict], scene, model, t_model: float) -> None:
    from housingfe.outputs import write_csv, write_json

    names = list(results)
    first = results[names[0]]
    write_csv(folder / "tf_omega.csv", ["frequency_hz"] + [f"TF_omega_{n}_dB" for n in names],
              [[f] + [results[n].tf_omega_db[k] for n in names] for k, f in enumerate(first.frequencies)])
    write_csv(folder / "differences.csv", list(rows[0]) if rows else ["configuration"],
              [list(r.values()) for r in rows])
    write_json(folder / "variants.json", {
        "scene": scene.scene.name, "housing_dofs": model.dofs, "housing_model_s": t_model,
        "differences": rows,
        "configurations": {n: {"solver": r.solver, "bearing_loads_N": r.loads, "mesh_stiffness_N_per_m":
                               r.mesh_stiffness, "timings_s": r.timings} for n, r in results.items()}})
    (folder / "summary.txt").write_text(summary_text(rows, model, t_model) + "\n")
    if scene.output.pictures:
        plot(folder / "tf_omega.png", results)


def plot(path: Path, results: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    for n, r in results.items():
        ax1.plot(r.frequencies, r.tf_omega_db, label=n)
    ax1.set_ylabel("TF_omega = L_v - L_omega [dB]")
    ax1.legend(fontsize=8)
    name = "ball" if "ball" in results else next(iter(results))
    ref = results[name]
    if len(results) > 1:
        for n, r in results.items():
            if n != name:
                ax2.plot(r.frequencies, ref.tf_omega_db - r.tf_omega_db, label=f"{name} - {n}")
        ax2.axvspan(*SPEED_RANGE_HZ, color="0.9", label="800-1500 rev/min")
        ax2.axhline(7.3, color="k", ls="--", lw=0.8, label="thesis FEM mean, ball - self-aligning")
    ax2.set_xlabel("frequency [Hz]")
    ax2.set_ylabel("difference [dB]")
    ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# --------------------------------------------------------------------------------------------------- CLI
def register_cli(subparsers) -> None:
    p = subparsers.add_parser("bearing-variants",
                              help="TF_omega of the test gearbox with each bearing configuration (Sec. 5.8/5.9)")
    p.add_argument("--scene", default="test-gearbox-interior", help="housing scene with an interior (default test-gearbox-interior)")
    p.add_argument("--configs", nargs="+", default=None,
                   help="configurations (default: all of housingfe.bearings.configurations, ball_zero_moment (the "
                        "thesis' FEM stand-in for self-aligning bearings: moment rows and columns zeroed), "
                        "ball_zero_tilt_stiffness (only the tilt block zeroed) and ball_appendix_c_moments; 'ball' is "
                        "the reference)")
    p.add_argument("--torque", type=float, default=TORQUE_NM, help=f"pinion torque [N m] (default {TORQUE_NM:g})")
    p.add_argument("--out", default=None, help="result folder (default results/bearing-variants-<scene>)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scene value")
    p.set_defaults(func=_cmd)


def _cmd(args: argparse.Namespace) -> int:
    if not (args.torque > 0 and np.isfinite(args.torque)):      # else "stiffness: total force must be > 0 N"
        raise InputError(f"bearing-variants: --torque: {args.torque:g} must be a pinion torque > 0 N m")
    from housingfe.bearings.configurations import configurations
    from housingfe.source.roosmalen.run import scene_pair

    known = configurations()
    # a misspelt configuration stops here, not after the housing model is built (16 s)
    names = [*known, THESIS_SELF_ALIGNING, ZERO_TILT_STIFFNESS, APPENDIX_C_MOMENTS]
    unknown = [c for c in args.configs or () if c not in names]
    if unknown:
        raise InputError(f"bearing-variants: --configs: {', '.join(map(repr, unknown))}: unknown (known: "
                         f"{', '.join(names)})")
    for gear_set in sorted({known[c].gear_set for c in (args.configs or known) if c in known}):
        problem = scene_pair(GEAR_SCENES[gear_set]).torque_problem(args.torque)
        if problem is not None:       # beyond the teeth's strength: no load distribution (docs/source.md)
            raise InputError(f"bearing-variants: --torque: gear set {gear_set}: {problem}")
    run_study(args.scene, args.configs, args.out, args.set or [], args.torque)
    return 0
