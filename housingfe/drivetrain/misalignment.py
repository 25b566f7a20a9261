"""Misalignment of the gear mesh under load from the drivetrain's FE interior (housingfe.source.misalignment has
the conventions and the lumped model).

"rigid-bores": the FE reduction of the drivetrain (`Drivetrain.to_coupling_spec`: Timoshenko shafts, the gears as
rigid discs on them, the bearings' 6x6 stiffness at the statics loads of the operating torque) with every bore held
fixed, loaded by the mean tooth force F_bn along the contact normal at the operating pitch point (mid face), equal
and opposite on the two gears, with its moments about the gear centres.  The gear-mesh spring is left out (the
mean force is applied instead: the same static state, and no single-point spring pretending to hold the tilt the
distributed mesh holds; that is the load distribution's job, MeshModel with the lead gap).  The spin of each
shaft (free in its bearings) is held at the gear node, after removing the force's moment about the shaft axis, so
it carries no load and changes no tilt.

The shafts' bending under the transverse force between RIGID supports is also in the MeshModel (Euler beams over
the face, Sec. 2.2.3); for a gear centred between its bearings (the test gearbox) it tilts the gear body by zero,
so the two do not overlap.  For an off-centre gear the FE tilt includes that bending tilt, which the MeshModel's
beam then counts a second time through its own (assumed) spans: not corrected here.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from housingfe.errors import InputError
from housingfe.source import misalignment as mis

MISALIGNMENT_MODELS = (*mis.MISALIGNMENT_MODELS, "rigid-bores")
DEFAULT_MISALIGNMENT = "rigid-bores"
# needs the housing model as well (`coupled_misalignment`): the run-up builds it
COUPLED_MODEL = "coupled"


def static_gear_tilts(drivetrain, forces=None, spec=None) -> tuple[np.ndarray, np.ndarray, object]:
    """(theta_pinion, theta_wheel, forces): rotation vectors [rad, housing frame] of the two gear nodes of the FE
    interior on rigid bores under the mean tooth force (see the module docstring); forces: GearForces.  spec: the
    interior's CouplingSpec to use instead of drivetrain.to_coupling_spec(forces) (e.g. with one bearing matrix
    changed, for a sensitivity); the loads stay the drivetrain's."""
    from housingfe.drivetrain.interior import interior_matrices

    forces = forces or drivetrain.gear_forces()
    spec = spec if spec is not None else drivetrain.to_coupling_spec(forces)
    # the drive line beyond the shaft ends is torsion only, and the spin is held here: it changes no tilt
    spec = spec.model_copy(update={"gear_meshes": [], "drive_lines": [], "aux_gearbox": None})
    centres = {}
    for seat in drivetrain.bearings:
        centres[seat.name] = drivetrain.shaft(seat.shaft).point(seat.position)
    K, _, _, names = interior_matrices(spec, centres)
    index = {n: 6 * i for i, n in enumerate(names)}
    # the normal force (mesh_node_loads applies its resultant: cos(beta_b) of it for a double helical set)
    normal_force = float(np.linalg.norm(forces.force_on_pinion)) / forces.resultant
    loads = drivetrain.mesh_node_loads(normal_force, forces)
    f = np.zeros(K.shape[0])
    scale = float(np.max(np.abs(np.diag(K))))
    gear_nodes = {}
    for name in ("pinion", "wheel"):
        node = f"{name}:{drivetrain.shaft_nodes(name)[1]['gear']}"
        gear_nodes[name] = node
        a = np.asarray(drivetrain.shaft(name).axis, float)
        a /= np.linalg.norm(a)
        load = np.real(np.asarray(loads[node], float)).copy()
        load[3:] -= (load[3:] @ a) * a                 # the torque goes down the shaft: not modelled here
        i = index[node]
        f[i:i + 6] += load
        K[i + 3:i + 6, i + 3:i + 6] += scale * np.outer(a, a)     # hold the spin (it carries no load)
    u = np.linalg.solve(K, f)
    if not np.all(np.isfinite(u)):
        raise InputError("misalignment: the interior on rigid bores is not supported (singular)")
    tilt = {k: u[index[n] + 3:index[n] + 6] for k, n in gear_nodes.items()}
    return tilt["pinion"], tilt["wheel"], forces


def _gear_loads(drivetrain, forces) -> tuple[dict, dict]:
    """({gear node: (6,) load of the mean tooth force without its moment about the shaft axis}, {gear node: unit
    shaft axis})."""
    loads = drivetrain.mesh_node_loads(float(np.linalg.norm(forces.force_on_pinion)) / forces.resultant, forces)
    out, axes = {}, {}
    for name in ("pinion", "wheel"):
        node = f"{name}:{drivetrain.shaft_nodes(name)[1]['gear']}"
        a = np.asarray(drivetrain.shaft(name).axis, float)
        a /= np.linalg.norm(a)
        load = np.real(np.asarray(loads[node], float)).copy()
        load[3:] -= (load[3:] @ a) * a
        out[node], axes[node] = load, a
    return out, axes


def coupled_gear_tilts(housing_model, drivetrain, forces=None) -> tuple[np.ndarray, np.ndarray, object]:
    """As `static_gear_tilts`, with the bores on the flexible housing: the FE interior (no gear-mesh spring) coupled
    with `housing_model` (a HousingModel with the drivetrain's bores, supported: its feet fixed) as the run-up
    couples it, the spin of each gear held by a spring to ground that carries no load; one direct (MUMPS) solve.
    Collective under MPI."""
    from petsc4py import PETSc

    from housingfe.drivetrain import coupling as cp
    from housingfe.drivetrain.interior import bore_centres, parts

    forces = forces or drivetrain.gear_forces()
    spec = drivetrain.to_coupling_spec(forces).model_copy(update={"gear_meshes": [], "drive_lines": [],
                                                                  "aux_gearbox": None})
    centres = bore_centres(housing_model, spec)
    p = parts(spec, centres)
    loads, axes = _gear_loads(drivetrain, forces)
    holds = []
    for node, a in axes.items():
        k6 = np.zeros((6, 6))
        k6[3:, 3:] = 1e9 * np.outer(a, a)            # N m/rad; any value: it carries no load
        holds.append(cp.spring(node, None, k6))
    system = cp.couple(housing_model, p.connections, p.elements + holds, p.shafts, [])
    f = system.load(node_loads=loads)
    from housingfe.solvers.mumps import SingularMatrix, set_up_factor, set_workspace

    def make_ksp(workspace_percent):
        ksp = PETSc.KSP().create(system.K.getComm())
        ksp.setOperators(system.K)
        ksp.setType("preonly")
        pc = ksp.getPC()
        pc.setType("lu")
        pc.setFactorSolverType("mumps")
        set_workspace(ksp, workspace_percent)
        return ksp

    u = system.K.createVecRight()
    try:
        ksp = set_up_factor(make_ksp, what="misalignment")   # a failed factor raises instead of solving garbage
        ksp.solve(f, u)
    except (SingularMatrix, PETSc.Error):
        raise InputError("misalignment: the coupled gearbox is singular (a free housing? the coupled model needs "
                         "the housing's supports)") from None
    if ksp.getConvergedReason() < 0 or not np.isfinite(u.norm()):
        raise InputError("misalignment: the coupled gearbox is singular (a free housing? the coupled model needs "
                         "the housing's supports)")
    names = list(loads)
    tilt = [np.asarray(system.node_displacement(u, n), float)[3:6] for n in names]
    ksp.destroy()
    return tilt[0], tilt[1], forces


def coupled_misalignment(housing_model, drivetrain) -> mis.Misalignment:
    """The "coupled" Misalignment of a drivetrain at its torque, on the flexible housing (`coupled_gear_tilts`)."""
    theta_p, theta_w, forces = coupled_gear_tilts(housing_model, drivetrain)
    a = np.asarray(drivetrain.shaft("pinion").axis, float)
    return mis.from_tilts(COUPLED_MODEL, drivetrain.torque, theta_p, theta_w, -a, forces.direction,
                          drivetrain.to_lumped()[2].total_width, drivetrain.gears.pair.base_helix_angle)


def rigid_bore_misalignment(drivetrain, spec=None) -> mis.Misalignment:
    """The "rigid-bores" Misalignment of a drivetrain at its torque: e_w = -(pinion axis) (the FE reduction's mesh
    normal has +sin(beta_b) along the axis, housingfe.source.misalignment), the FE contact normal.  spec: an
    interior CouplingSpec instead of the drivetrain's (`static_gear_tilts`)."""
    theta_p, theta_w, forces = static_gear_tilts(drivetrain, spec=spec)
    pair = drivetrain.gears.pair
    a = np.asarray(drivetrain.shaft("pinion").axis, float)
    total = drivetrain.to_lumped()[2].total_width
    return mis.from_tilts("rigid-bores", drivetrain.torque, theta_p, theta_w, -a, forces.direction, total,
                          pair.base_helix_angle)


def mesh_misalignment(drivetrain, model: str = DEFAULT_MISALIGNMENT) -> mis.Misalignment:
    """The Misalignment of `drivetrain` at its torque by `model` (MISALIGNMENT_MODELS)."""
    from housingfe.source.roosmalen import dynamics as dyn
    from housingfe.source.stiffness import normal_force_from_torque, stiffness_curve

    mis.check_model(model, MISALIGNMENT_MODELS)
    lumped_model = drivetrain.to_lumped()
    total = lumped_model[2].total_width
    if model == "none":
        return mis.Misalignment("none", drivetrain.torque, 0.0, 0.0, 0.0)
    if model == "rigid-bores":
        return rigid_bore_misalignment(drivetrain)
    interior, _, mesh = lumped_model
    pair = drivetrain.gears.pair
    k_m = stiffness_curve(mesh, normal_force_from_torque(pair, drivetrain.torque),
                          drivetrain.coupling_mesh_positions).mean
    mats = dyn.assemble(pair, interior, k_m)
    return mis.lumped_misalignment(pair, mats, dyn.preload_force(mats, drivetrain.torque), drivetrain.torque, total)


def lead_gap_law(drivetrain, model: str = DEFAULT_MISALIGNMENT):
    """A function torque [N m] -> MeshModel.lead_gap [m/m] of `drivetrain` at that torque by `model` (cached per
    torque), for housingfe.source.roosmalen.operating.SourceModel(misalignment=...)."""
    mis.check_model(model, MISALIGNMENT_MODELS)
    cache: dict = {}

    def law(torque: float) -> float:
        if torque not in cache:
            cache[torque] = mesh_misalignment(replace(drivetrain, torque=float(torque)), model).lead_gap
        return cache[torque]

    law.model = model
    return law


# ------------------------------------------------------------------------------------------------ study and CLI
def misalignment_rows(gear_sets=("A",), bearings: str = "ball", torques=(2000.0,),
                      models=("none", "lumped", "rigid-bores"), harmonics: int = 6, stiffness_positions: int = 32
                      ) -> list[dict]:
    """gamma and what it does to the mesh, per gear set of the test gearbox (housingfe.drivetrain.description
    .test_gearbox), torque (pinion, N m) and misalignment model: gamma_urad, the gap across the face (um), the mean
    approach F/S (um), the face-width load share's min and max, the contact loss (fraction of the face), the mean
    mesh stiffness (N/m) and the quasi-static excitation k_m (d - mean d), d = (F - F_e)/S(t), per tooth harmonic
    n = 1..harmonics (N, one-sided; `housingfe source-spectrum`'s quantity, face-width engagement)."""
    from housingfe.drivetrain.description import test_gearbox
    from housingfe.source.roosmalen import run as rs
    from housingfe.source.stiffness import contact_loss_fraction

    for m in models:
        mis.check_model(m, MISALIGNMENT_MODELS)
    rows = []
    for gear_set in gear_sets:
        for torque in torques:
            dt = test_gearbox(gear_set, bearings, float(torque))
            interior, _, mesh = dt.to_lumped()
            pair, corr = dt.gears.pair, dt.gears.corrections
            for model in models:
                result = mesh_misalignment(dt, model)
                op = rs.OperatingPoint(pair, corr, interior, mesh, float(torque), stiffness_positions,
                                       lead_gap=result.lead_gap)
                d = (op.normal_force - op.shock) / op.S
                excitation = op.curve.mean * (d - d.mean())
                amp = 2 * np.abs(np.fft.rfft(excitation)[1:harmonics + 1]) / excitation.size
                row = {"gear_set": gear_set, "bearings": bearings, "torque_nm": float(torque), "model": model,
                       "gamma_urad": result.gamma * 1e6, "gap_across_face_um": result.gap_across_face * 1e6,
                       "approach_um": op.normal_force / op.curve.mean * 1e6,
                       "share_min": float(op.load_share.min()), "share_max": float(op.load_share.max()),
                       "contact_loss": contact_loss_fraction(op.load_share), "mesh_stiffness_N_per_m": op.curve.mean}
                row.update({f"excitation_n{n}_N": float(a) for n, a in enumerate(amp, start=1)})
                rows.append(row)
    return rows


def _cmd_misalignment(args) -> int:
    from pathlib import Path

    from housingfe.drivetrain.description import GEAR_SETS
    from housingfe.outputs import atomic_output_dir, format_table, reserve_output, write_csv

    for g in args.gear_sets:
        if g not in GEAR_SETS:
            raise InputError(f"misalignment: --gear-sets: {g!r} unknown (known: {', '.join(GEAR_SETS)})")
    for t in args.torques:
        if not (np.isfinite(t) and t > 0):
            raise InputError(f"misalignment: --torques: {t:g} must be a pinion torque > 0 N m")
    from housingfe.source.roosmalen.run import scene_pair

    for g in args.gear_sets:          # beyond the teeth's strength: no load distribution (docs/source.md)
        pair = scene_pair(GEAR_SETS[g])
        for t in args.torques:
            problem = pair.torque_problem(t)
            if problem is not None:
                raise InputError(f"misalignment: --torques: gear set {g}: {problem}")
    for m in args.models:
        mis.check_model(m, MISALIGNMENT_MODELS)
    out = Path(args.out)
    reserve_output(out)
    rows = misalignment_rows(tuple(args.gear_sets), args.bearings, tuple(args.torques), tuple(args.models))
    header = list(rows[0])
    short = ["gear_set", "torque_nm", "model", "gamma_urad", "gap_across_face_um", "approach_um", "share_min",
             "share_max", "contact_loss", *[k for k in header if k.startswith("excitation_n")]]
    text = format_table(short, [[r[k] for k in short] for r in rows], floatfmt="{:.4g}")
    with atomic_output_dir(out) as tmp:
        write_csv(tmp / "misalignment.csv", header, [[r[k] for k in header] for r in rows])
        (tmp / "misalignment.txt").write_text(text + "\n")
    print(text)
    print(f"results in {out}")
    return 0


def register_cli(subparsers) -> None:
    """Add `housingfe misalignment [--gear-sets A ...] [--bearings ball] [--torques 2000 ...] [--models ...]`."""
    p = subparsers.add_parser("misalignment", help="mesh misalignment under load (gamma per gear set and torque) "
                              "and what it does to the load share and the quasi-static excitation")
    p.add_argument("--gear-sets", nargs="+", default=["A"], help="gear sets of the test gearbox (default A)")
    p.add_argument("--bearings", default="ball", help="bearing configuration (default ball)")
    p.add_argument("--torques", nargs="+", type=float, default=[1000.0, 2000.0], help="pinion torques, N m (default 1000 2000)")
    p.add_argument("--models", nargs="+", default=["none", "lumped", "rigid-bores"],
                   help=f"misalignment models ({', '.join(MISALIGNMENT_MODELS)}; default all)")
    p.add_argument("--out", default="results/misalignment", help="result folder (default results/misalignment)")
    p.set_defaults(func=_cmd_misalignment, mpi="serial")
