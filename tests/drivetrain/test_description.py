"""One drivetrain description (housingfe.drivetrain.description): its lumped reduction is the source model of the
gearset-* scenes, its FE reduction the [coupling] of test-gearbox-interior, and the gear bodies agree between both."""
import math

import numpy as np
import pytest

from housingfe.drivetrain.description import GEAR_SETS, BearingSeat, test_gearbox
from housingfe.drivetrain.interior import CouplingSpec
from housingfe.drivetrain.shafts import STEEL, RigidDisc
from housingfe.errors import InputError
from housingfe.scenefile import read_scene_dict
from housingfe.source.roosmalen import run as roosmalen


def _scene_source(name):
    data, path = read_scene_dict(name)
    return roosmalen.build(roosmalen.parse(data, str(path)), str(path))


@pytest.mark.parametrize("gear_set", list(GEAR_SETS))
def test_lumped_reduction_is_the_gearset_scene(gear_set):
    pair, corr, geometry, interior, model = _scene_source(GEAR_SETS[gear_set])
    li, geo, mm = test_gearbox(gear_set).to_lumped()
    assert geo == geometry                      # 60 mm spans, 80 / 95 mm shafts, quill shafts 1-4, couplings
    assert li == interior                       # exactly: masses, inertias, torsion, Appendix C bearings
    assert mm.shafts == model.shafts and mm.corrections == corr
    assert (mm.n_slices, mm.torque_configuration) == (model.n_slices, model.torque_configuration)


def test_gear_bodies_agree_between_the_reductions():
    """Gear mass and inertias from the GearPair (solid cylinder of the mean of tip and root diameter, thesis
    Appendix C lumping) against (a) the lumped model = gear + its shaft between the bearings and (b) the FE disc
    (bored to the shaft) + the shaft through it."""
    d = test_gearbox("A")
    pair = d.gears.pair
    li, geo, _ = d.to_lumped()
    for g, (mass, jp, jd), dshaft, spans in ((0, (li.pinion_mass, li.pinion_inertia_axial, li.pinion_inertia_diametral),
                                              geo.pinion_shaft_diameter, geo.pinion_spans),
                                             (1, (li.wheel_mass, li.wheel_inertia_axial, li.wheel_inertia_diametral),
                                              geo.wheel_shaft_diameter, geo.wheel_spans)):
        dg = 0.5 * (pair.tip_diameter[g] + pair.root_diameter[g])
        b = pair.face_width[g]
        m_gear = 7850.0 * math.pi * dg**2 / 4 * b
        m_gear_d, jp_gear, jd_gear = d.gear_inertia(g)
        assert m_gear_d == pytest.approx(m_gear, rel=1e-12)
        assert jp_gear == pytest.approx(m_gear * dg**2 / 8, rel=1e-12)
        assert jd_gear == pytest.approx(m_gear * (3 * dg**2 / 4 + b**2) / 12, rel=1e-12)
        # (a) lumped: plus the shaft between the bearings
        m_shaft = 7850.0 * math.pi * dshaft**2 / 4 * sum(spans)
        assert mass == pytest.approx(m_gear + m_shaft, rel=1e-12)
        assert jp == pytest.approx(jp_gear + m_shaft * dshaft**2 / 8, rel=1e-12)
        assert jd > jd_gear
        # (b) FE: the bored disc plus the shaft inside the face width is the same solid cylinder
        disc = RigidDisc.cylinder(dg, b, dshaft, rho=STEEL.density)
        m_core = STEEL.density * math.pi * dshaft**2 / 4 * b
        assert disc.mass + m_core == pytest.approx(m_gear, rel=1e-12)
        assert disc.polar_inertia + m_core * dshaft**2 / 8 == pytest.approx(jp_gear, rel=1e-12)


def test_coupling_reduction_is_the_test_gearbox_interior():
    """The FE reduction of the gear set B description against the scene's [coupling] table (written to 5-6
    significant digits: loads to 0.1 N, the mesh stiffness to 5 digits)."""
    data, _ = read_scene_dict("test-gearbox-interior")
    ref = CouplingSpec.model_validate(data["coupling"])
    spec = test_gearbox("B").to_coupling_spec()
    assert spec.bores == ref.bores
    for s, r in zip(spec.shafts, ref.shafts, strict=True):
        assert (s.name, s.axis, s.elements_per_segment) == (r.name, r.axis, r.elements_per_segment)
        np.testing.assert_allclose(s.origin, r.origin, atol=1e-12)
        np.testing.assert_allclose(s.segments, r.segments, atol=1e-12)
        assert [dd.node for dd in s.discs] == [dd.node for dd in r.discs]
        assert s.discs[0].outer_diameter == pytest.approx(r.discs[0].outer_diameter, abs=1e-6)
        assert (s.discs[0].width, s.discs[0].inner_diameter) == (r.discs[0].width, r.discs[0].inner_diameter)
    for b, r in zip(spec.bearings, ref.bearings, strict=True):
        assert (b.name, b.shaft_node, b.bore, b.axis, b.designation, b.model, b.fixed_tilt) == \
               (r.name, r.shaft_node, r.bore, r.axis, r.designation, r.model, r.fixed_tilt)
        np.testing.assert_allclose(b.load, r.load, atol=0.051)
    (m,), (mr,) = spec.gear_meshes, ref.gear_meshes
    assert (m.a, m.b) == (mr.a, mr.b)
    assert m.stiffness == pytest.approx(mr.stiffness, rel=5e-5)
    np.testing.assert_allclose(m.point, mr.point, atol=1e-12)
    np.testing.assert_allclose(m.direction, mr.direction, atol=6e-7)


def test_bearing_loads_balance_the_gear_force():
    """Statics of each two-bearing shaft: the bearing loads add up to the tooth force (2000 N m on the pinion:
    the tangential force is T / r_b per unit normal), the locating bearing takes all of the axial force."""
    d = test_gearbox("A")
    forces = d.gear_forces()
    loads = d.bearing_loads(forces)
    rb1 = d.gears.pair.base_diameter[0] / 2
    # torque about the pinion axis (global y) = 2000 N m
    arm = forces.point - np.asarray(d.shaft("pinion").centre)
    assert abs(np.cross(arm, forces.force_on_pinion)[1]) == pytest.approx(2000.0, rel=1e-9)
    assert np.linalg.norm(forces.force_on_pinion) == pytest.approx(
        2000.0 / (rb1 * math.cos(d.gears.pair.base_helix_angle)), rel=1e-9)
    from housingfe.drivetrain.coupling import axis_frame

    R = axis_frame((0.0, 1.0, 0.0))
    for shaft, sign in (("pinion", 1.0), ("wheel", -1.0)):
        total = R @ (np.array(loads[f"{shaft}_front"][:3]) + np.array(loads[f"{shaft}_back"][:3]))
        np.testing.assert_allclose(total, sign * forces.force_on_pinion, atol=1e-8)
        assert loads[f"{shaft}_back"][2] == 0.0


def test_bad_descriptions_are_input_errors():
    with pytest.raises(InputError, match="gear_set"):
        test_gearbox("Z")
    with pytest.raises(InputError, match="bearings"):
        test_gearbox("A", bearings="magnetic")
    d = test_gearbox("A")
    import dataclasses

    off = BearingSeat("pinion_front", "pinion", -0.2, "bore_pinion_front", locating=True, designation="SKF 6316")
    with pytest.raises(InputError, match="off the shaft"):
        dataclasses.replace(d, bearings=(off, *d.bearings[1:]))
    with pytest.raises(InputError, match="torque"):
        dataclasses.replace(d, torque=0.0)


@pytest.mark.parametrize("gear_set", ["A", "C", "double_helical"])
def test_lumped_mesh_loads_map_onto_the_fe_mesh_loads(gear_set):
    """The lumped model's generalized mesh force on each gear (-F h, Appendix C with the axial tilt term) moved into
    the housing frame (`lumped_to_housing`, mirrored for the helix hand) is the FE reduction's mesh load on the gear
    node: force along the contact normal and its moment about the gear centre, all six components.  Double helical:
    both take the resultant of the two halves' normals, cos(beta_b) along the transverse line of action, no axial
    force, no tilting moment (docs/drivetrain.md)."""
    from housingfe.source.roosmalen.dynamics import mesh_direction

    d = test_gearbox(gear_set)
    h = mesh_direction(d.gears.pair)
    fe = d.mesh_node_loads(1.0)
    for node, dofs in (("pinion:8", slice(0, 6)), ("wheel:8", slice(6, 12))):
        np.testing.assert_allclose(d.lumped_to_housing(-h[dofs]), fe[node], atol=1e-12)
    # action = reaction: the forces cancel
    np.testing.assert_allclose(fe["pinion:8"][:3] + fe["wheel:8"][:3], 0.0, atol=1e-15)


@pytest.mark.parametrize("gear_set", ["A", "double_helical"])
def test_shuttle_loads_are_the_mesh_force_with_its_point_moved(gear_set):
    """The unit load of the shuttling moment: the mesh force pair of F with its contact point moved by dw along the
    direction in which the MeshModel's w grows changes only the moments, by +/- F dw (e_w x n); and that direction is
    the MeshModel's hand: its contact lines s = s0 + w tan(beta_b) must lie on the flank, i.e. normal to the FE
    contact normal n (whose axial part is +sin(beta_b) along the shaft axis); a shift along the line of action adds
    tan(beta_b) ds to the arm on the same axis."""
    from dataclasses import replace

    d = test_gearbox(gear_set)
    forces = d.gear_forces()
    e_w = d.mesh_face_direction()
    F, dw = 4.4e4, 3e-3
    moved = replace(forces, point=forces.point + dw * e_w)
    base, shifted = d.mesh_node_loads(F, forces), d.mesh_node_loads(F, moved)
    shuttle = d.shuttle_node_loads(F * dw, forces)
    assert set(shuttle) == set(base)
    for node in base:
        np.testing.assert_allclose(shifted[node] - base[node], shuttle[node], atol=1e-9 * F)
        assert np.allclose(shuttle[node][:3], 0.0)
    n = forces.direction
    pair = d.gears.pair
    axis = np.asarray(d.shaft("pinion").axis, float)
    if gear_set == "A":
        d_t = n - (n @ axis) * axis
        d_t /= np.linalg.norm(d_t)                      # transverse line of action, growing s
        line = math.tan(pair.base_helix_angle) * d_t + e_w      # the MeshModel's contact line per unit w
        assert n @ axis == pytest.approx(math.sin(pair.base_helix_angle), rel=1e-12)
        assert abs(line @ n) < 1e-12
        # the other hand would not lie on the flank
        assert abs((math.tan(pair.base_helix_angle) * d_t - e_w) @ n) > 0.3
        # a shift ds along the line of action acts on the same axis: moment F (dw + tan(beta_b) ds) (e_w x n)
        # (housingfe.source.mesh_moments.CentreOfPressure.moment_arm_harmonics)
        ds = 2e-3
        both = d.mesh_node_loads(F, replace(forces, point=forces.point + dw * e_w + ds * d_t))
        arm = dw + math.tan(pair.base_helix_angle) * ds
        for node in base:
            np.testing.assert_allclose(both[node] - base[node], d.shuttle_node_loads(F * arm, forces)[node],
                                       atol=1e-9 * F)
    m = np.cross(e_w, n * forces.resultant)
    assert np.linalg.norm(m) == pytest.approx(math.cos(pair.base_helix_angle), rel=1e-12)


def test_double_helical_mesh_of_both_reductions_is_the_transverse_resultant():
    """Double helical, 2000 N m: the halves' normals cos(bb) l +- sin(bb) a (S / 2 each) add up to the stiffness
    S cos^2(bb) along the transverse line of action l and the force F_n cos(bb) = T / r_b1.  The FE reduction's
    gear forces and the lumped model (mesh_direction, its static state under the preload) give the same transverse
    stiffness and force for the same normal stiffness S (the MeshModel's, at the FE's mesh positions); no axial
    part, and the FE force balances the pinion torque T."""
    from housingfe.source.roosmalen import dynamics as dyn
    from housingfe.source.stiffness import normal_force_from_torque, stiffness_curve

    d = test_gearbox("double_helical", bearings="cylindrical_roller")
    pair = d.gears.pair
    forces = d.gear_forces()
    S = stiffness_curve(d.to_lumped()[2], normal_force_from_torque(pair, d.torque), d.coupling_mesh_positions).mean
    cb = math.cos(pair.base_helix_angle)
    axis = np.asarray(d.shaft("pinion").axis, float)
    assert forces.resultant == cb and forces.direction @ axis == 0.0
    assert forces.stiffness == pytest.approx(S * cb**2, rel=1e-12)
    rb1 = pair.base_diameter[0] / 2
    assert np.linalg.norm(forces.force_on_pinion) == pytest.approx(d.torque / rb1, rel=1e-12)
    arm = forces.point - np.asarray(d.shaft("pinion").centre)
    assert abs(np.cross(arm, forces.force_on_pinion) @ axis) == pytest.approx(d.torque, rel=1e-12)
    # the lumped model with the same S: stiffness along its transverse unit vector, static transverse mesh force
    interior, _, _ = d.to_lumped()
    mats = dyn.assemble(pair, interior, S)
    h = mats.h
    assert S * (h[0] ** 2 + h[1] ** 2) == pytest.approx(forces.stiffness, rel=1e-12)
    q = np.linalg.solve(mats.K0 + S * np.outer(h, h), dyn.preload_force(mats, d.torque))
    f = S * (h @ q) * h[:6]
    assert f[2] == 0.0 and f[3] == 0.0 and f[4] == 0.0
    assert math.hypot(f[0], f[1]) == pytest.approx(np.linalg.norm(forces.force_on_pinion), rel=1e-12)


def test_single_helical_gear_forces_are_unchanged():
    """Set A: bit for bit the unit normal cos(bb) l + sin(bb) a, the MeshModel's normal stiffness S and the force
    -F_n n (the double helical resultant does not touch a single helical set)."""
    from housingfe.source.stiffness import normal_force_from_torque, stiffness_curve

    d = test_gearbox("A")
    pair = d.gears.pair
    forces = d.gear_forces()
    normal = normal_force_from_torque(pair, d.torque)
    assert forces.resultant == 1.0
    assert forces.stiffness == stiffness_curve(d.to_lumped()[2], normal, d.coupling_mesh_positions).mean
    a = np.asarray(d.shaft("pinion").axis, float) / np.linalg.norm(d.shaft("pinion").axis)
    c = np.asarray(d.shaft("wheel").centre, float) - np.asarray(d.shaft("pinion").centre, float)
    e_c = c - (c @ a) * a
    e_c /= np.linalg.norm(e_c)
    alpha, bb = pair.operating_pressure_angle, pair.base_helix_angle
    n = np.cos(bb) * (np.sin(alpha) * e_c + np.cos(alpha) * np.cross(a, e_c)) + np.sin(bb) * a
    assert np.array_equal(forces.direction, n)
    assert np.array_equal(forces.force_on_pinion, -normal * n)
