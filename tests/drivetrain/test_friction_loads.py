"""The sliding-friction unit loads on the FE interior (Drivetrain.friction_node_loads, used by the run-up with
runup.mesh_friction on).

* With the resultants of one load distribution (the source's stiffness curve at each mesh position) the four loads
  together are self-equilibrated on the FE geometry (the gear nodes where the coupling spec puts them): the friction
  forces act at the contact points, equal and opposite on the two flanks, so their sum and moment vanish; the force
  pair alone and the torques alone do not (the torques carry the levers s and L - s).
* Their power on the gears' rotation (pinion driving: each rotation vector from the mean mesh force, not from the
  friction's own directions) is negative at every position: friction dissipates (friction_resultants' docstring).
"""
import numpy as np
import pytest

from housingfe.drivetrain.description import FRICTION_LOADS, test_gearbox


def _gear_node_positions(dt) -> dict:
    """{gear node name: (3,) m} from the coupling spec's shafts (origin + axis x the segments up to the node)."""
    spec = dt.to_coupling_spec()
    out = {}
    for shaft in spec.shafts:
        node = shaft.discs[0].node
        per = shaft.elements_per_segment
        length = sum(seg[0] for seg in shaft.segments[:node // per])
        axis = np.asarray(shaft.axis, float) / np.linalg.norm(shaft.axis)
        out[f"{shaft.name}:{node}"] = np.asarray(shaft.origin, float) + length * axis
    return out


def _resultant(loads: dict, positions: dict) -> tuple[np.ndarray, np.ndarray]:
    force = sum(v[:3] for v in loads.values())
    moment = sum(v[3:] + np.cross(positions[k], v[:3]) for k, v in loads.items())
    return force, moment


@pytest.mark.parametrize("gear_set", ["A", "double_helical"])
def test_friction_loads_are_self_equilibrated_and_dissipate(gear_set):
    dt = test_gearbox(gear_set)
    positions = _gear_node_positions(dt)
    curve = dt.source_model().friction_curve(2000.0, 0.06)
    forces = dt.gear_forces()
    scale = np.max(np.abs(curve.force))              # N
    assert scale > 100.0                              # 0.06 of a ~30 kN mesh force, not a degenerate case
    n = forces.direction
    rotation = {}
    for name in ("pinion", "wheel"):
        # pinion driving: the mesh force on the pinion (-F n) brakes it, on the wheel (+F n) drives it, so both
        # turn along (contact point - centre) x n
        c = np.asarray(dt.shaft(name).centre, float)
        r = np.cross(forces.point - c, n)
        a = np.asarray(dt.shaft(name).axis, float)
        rotation[name] = np.sign(r @ a) * a / np.linalg.norm(a)
    z1, z2 = dt.gears.pair.teeth
    omega = {"pinion": 1.0, "wheel": z1 / z2}         # rad/s, rolling without slip at the pitch point
    nodes = {name: f"{name}:{dt.shaft_nodes(name)[1]['gear']}" for name in omega}
    for k in range(len(curve.position)):
        total = {}
        for resultant in FRICTION_LOADS:
            for node, load in dt.friction_node_loads(resultant, getattr(curve, resultant)[k]).items():
                total[node] = total.get(node, 0.0) + load
        f, m = _resultant(total, positions)
        assert np.linalg.norm(f) < 1e-9 * scale
        assert np.linalg.norm(m) < 1e-9 * scale * 0.2       # moments about the origin: levers ~0.2 m
        power = sum(total[nodes[g]][3:] @ rotation[g] * omega[g] for g in omega)
        assert power < -1e-3 * scale * 0.01                  # W at 1 rad/s: a clear loss, not round-off
    # the parts alone are not in equilibrium: the torques hold the force's levers
    pair_only = dt.friction_node_loads("force", scale)
    assert np.linalg.norm(_resultant(pair_only, positions)[1]) > 1e-3 * scale
    with pytest.raises(Exception, match="mesh_friction"):
        dt.friction_node_loads("normal", 1.0)
