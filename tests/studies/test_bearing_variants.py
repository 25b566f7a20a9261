"""The bearing-variant study's inputs: gear forces from the source module, bearing loads by statics, and the
built-in test-gearbox-interior scene written from them."""
import numpy as np
import pytest

from housingfe.studies import bearing_variants as bv
from tests.conftest import load_scene


def test_statics_balance_forces_and_moments():
    """The two bearing loads carry the gear force and its moment (about any point, torque about the axis
    excepted); the back bearing takes no axial load."""
    rng = np.random.default_rng(1)
    axis = np.array([0.0, 1.0, 0.0])
    front, back = np.array([0.1, -0.12, 0.2]), np.array([0.1, 0.09, 0.2])
    for _ in range(5):
        f, p = rng.normal(size=3) * 1e4, np.array([0.1, 0.0, 0.2]) + rng.normal(size=3) * 0.05
        lf, lb = bv.shaft_bearing_loads(f, p, front, back, axis)
        assert np.allclose(lf + lb, f, atol=1e-9)
        m = np.cross(front - p, lf) + np.cross(back - p, lb)
        m_gear = np.zeros(3)
        assert np.allclose(m - (m @ axis) * axis, m_gear, atol=1e-8)
        assert abs(lb @ axis) < 1e-9


def test_gear_forces_are_the_source_tooth_loads():
    """Set B at 2000 N m: circumferential T / r_w1 (r_w1 = 50 mm), radial F_t tan(alpha_wt), axial along the
    shaft; the pinion is pushed away from the wheel; the double helical set has no axial force."""
    pin, whl = np.array([-0.126, 0.0, 0.2]), np.array([0.074, 0.0, 0.2])
    g = bv.gear_forces("single_helical", 2000.0, (-0.076, 0.0, 0.2), pin, whl, (0, 1, 0))
    f = g.force_on_pinion
    assert abs(abs(f[2]) - 2000.0 / 0.05) < 1e-6 * 4e4
    assert f[0] == pytest.approx(-abs(f[2]) * np.tan(np.radians(23.099)), rel=2e-3)
    assert abs(f[1]) > 1e3 and abs(np.linalg.norm(g.direction) - 1) < 1e-12
    assert 5e8 < g.stiffness < 2e9                    # ISO 6336 order: c_gamma ~ 20 N/(mm um) x 62 mm
    d = bv.gear_forces("double_helical", 2000.0, (-0.076, 0.0, 0.2), pin, whl, (0, 1, 0))
    assert abs(d.force_on_pinion[1]) < 1e-9 and abs(d.direction[1]) < 1e-12
    # the halves' resultant: T / r_b1 along the transverse line of action, S cos^2(beta_b) (docs/drivetrain.md), as
    # the drivetrain description takes it
    from housingfe.drivetrain.description import test_gearbox

    ref = test_gearbox("double_helical", "cylindrical_roller").gear_forces()
    rb1 = test_gearbox("double_helical", "cylindrical_roller").gears.pair.base_diameter[0] / 2
    assert np.linalg.norm(d.force_on_pinion) == pytest.approx(2000.0 / rb1, rel=1e-12)
    assert d.stiffness == pytest.approx(ref.stiffness, rel=5e-5)


def test_builtin_scene_carries_the_computed_loads_and_mesh():
    """test-gearbox-interior's bearing loads and mesh are what configuration_spec computes for ball bearings."""
    scene = load_scene("test-gearbox-interior")
    _, loads, forces = bv.configuration_spec(scene.coupling, "ball")
    for b in scene.coupling.bearings:
        assert np.allclose(b.load, loads[b.name], atol=0.06), b.name
    mesh = scene.coupling.gear_meshes[0]
    assert mesh.stiffness == pytest.approx(forces.stiffness, rel=1e-4)
    assert np.allclose(mesh.direction, forces.direction, atol=1e-6)


def test_zero_tilt_stiffness_keeps_the_couplings_zero_moment_drops_them():
    """ball_zero_moment (the thesis' stand-in) zeroes the moment rows and columns, ball_zero_tilt_stiffness only the
    tilt block; the locating ball bearings have force-tilt couplings of ~1e7 N/rad, the load centre's axial offset
    |k_x,theta| / k_xx of 1-2 cm (the thesis' printed Sec. 4.6 matrix: 11 mm), which the second keeps."""
    base = load_scene("test-gearbox-interior").coupling
    ball = {b.name: np.array(b.stiffness_matrix) for b in bv.configuration_spec(base, "ball")[0].bearings}
    zero = {b.name: np.array(b.stiffness_matrix) for b in bv.configuration_spec(base, bv.THESIS_SELF_ALIGNING)[0].bearings}
    tilt = {b.name: np.array(b.stiffness_matrix) for b in bv.configuration_spec(base, bv.ZERO_TILT_STIFFNESS)[0].bearings}
    for name, k in ball.items():
        assert np.all(zero[name][3:5] == 0) and np.all(zero[name][:, 3:5] == 0)
        assert np.all(tilt[name][3:5, 3:5] == 0)
        assert np.array_equal(tilt[name][:3], k[:3]) and np.array_equal(tilt[name][:, :3], k[:, :3])
    for name in ("pinion_front", "wheel_front"):                     # the locating (axially loaded) bearings
        k = ball[name]
        offset = max(abs(k[0, 4]) / k[0, 0], abs(k[1, 3]) / k[1, 1])
        assert 0.008 < offset < 0.03, (name, offset)
