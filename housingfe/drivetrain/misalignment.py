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


def static_gear_tilts(drivetrain, forces=None) -> tuple[np.ndarray, np.ndarray, object]:
    """(theta_pinion, theta_wheel, forces): rotation vectors [rad, housing frame] of the two gear nodes of the FE
    interior on rigid bores under the mean tooth force (see the module docstring); forces: GearForces."""
    from housingfe.drivetrain.interior import interior_matrices

    forces = forces or drivetrain.gear_forces()
    spec = drivetrain.to_coupling_spec(forces)
    spec = spec.model_copy(update={"gear_meshes": []})
    centres = {}
    for seat in drivetrain.bearings:
        centres[seat.name] = drivetrain.shaft(seat.shaft).point(seat.position)
    K, _, _, names = interior_matrices(spec, centres)
    index = {n: 6 * i for i, n in enumerate(names)}
    normal_force = float(np.linalg.norm(forces.force_on_pinion))
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


def rigid_bore_misalignment(drivetrain) -> mis.Misalignment:
    """The "rigid-bores" Misalignment of a drivetrain at its torque: e_w = -(pinion axis) (the FE reduction's mesh
    normal has +sin(beta_b) along the axis, housingfe.source.misalignment), the FE contact normal."""
    theta_p, theta_w, forces = static_gear_tilts(drivetrain)
    pair = drivetrain.gears.pair
    a = np.asarray(drivetrain.shaft("pinion").axis, float)
    total = drivetrain.to_lumped()[2].total_width
    return mis.from_tilts("rigid-bores", drivetrain.torque, theta_p, theta_w, -a, forces.direction, total,
                          pair.base_helix_angle)


def mesh_misalignment(drivetrain, model: str = DEFAULT_MISALIGNMENT) -> mis.Misalignment:
    """The Misalignment of `drivetrain` at its torque by `model` (MISALIGNMENT_MODELS)."""
    from housingfe.source import dynamics as dyn
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
    torque), for housingfe.source.operating.SourceModel(misalignment=...)."""
    mis.check_model(model, MISALIGNMENT_MODELS)
    cache: dict = {}

    def law(torque: float) -> float:
        if torque not in cache:
            cache[torque] = mesh_misalignment(replace(drivetrain, torque=float(torque)), model).lead_gap
        return cache[torque]

    law.model = model
    return law
