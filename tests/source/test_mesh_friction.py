"""Sliding friction over the mesh period (housingfe.source.mesh_friction) against the kinematics of the pitch point
and the constant contact length on either side of the pitch line at an integer overlap ratio."""
import math
from dataclasses import replace

import numpy as np
import pytest

from housingfe.source.gears import GearPair
from housingfe.source.mesh_friction import FrictionCurve, friction_curve
from housingfe.source.stiffness import MeshModel, friction_resultants, stiffness_curve
from tests.source.thesis_gears import REF, SYMMETRIC_SHAFTS

MU = 0.05


def pitch_point(pair: GearPair) -> float:
    """s_P [m] from T1: where the rolling velocities omega_1 s and omega_2 (T1T2 - s) are equal."""
    return float(pair.base_diameter[0]) / 2 * math.tan(pair.operating_pressure_angle)


def test_single_spur_line_flips_sign_exactly_at_the_pitch_point():
    """A spur pair in its single-contact zone: the one contact line carries the whole force F; just before the
    pitch point (approach) the friction on the pinion is -mu F e_f and helps the pinion (+mu F s), just after it
    (recess) +mu F e_f and brakes it; the wheel's lever is T1T2 - s."""
    pair = GearPair(4e-3, (24, 72), math.radians(20), 0.0, (0.0, 0.0), (0.05, 0.05), kind="spur")
    A, E = pair.path_of_contact
    p, sp, L = pair.transverse_base_pitch, pitch_point(pair), pair.line_of_action_length
    assert E - p < sp < A + p                     # the pitch point lies in the single-contact zone
    model = MeshModel(pair, shafts=SYMMETRIC_SHAFTS, n_slices=4, include_body_torsion=False)
    F = 20e3
    for side in (-1.0, 1.0):
        s_line = sp + side * 1e-7                 # 0.1 um from the pitch point
        pts, forces, _ = model.load_distribution(s_line % p, F)
        assert np.unique(pts["pair"]).size == 1 and np.allclose(pts["s"], s_line, atol=1e-12)
        r = friction_resultants(pair, pts, forces, model.total_width, MU)
        assert r["force"] == pytest.approx(side * MU * F, rel=1e-9)
        assert r["pinion_torque"] == pytest.approx(-side * MU * F * s_line, rel=1e-9)
        assert r["wheel_torque"] == pytest.approx(side * MU * F * (L - s_line), rel=1e-9)
        # dissipation: -T1 omega_1 ... the power of the pair is <= 0 for any speeds in the gear ratio
        w1, w2 = 1.0, pair.teeth[0] / pair.teeth[1]
        assert r["pinion_torque"] * w1 + r["wheel_torque"] * w2 < 0


def single_helical_at_overlap(eps_beta: float) -> GearPair:
    base = GearPair.from_table(REF["single_helical"])
    b = eps_beta * math.pi * base.module / math.sin(base.helix_angle)
    return replace(base, face_width=(b, b))


def uniform_friction_force(pair: GearPair, n_positions: int = 64) -> np.ndarray:
    """Friction force [N] with a uniform load q = 1e5 N/m per unit axial length of contact line (weights = the
    points' segment widths), over one mesh period."""
    model = MeshModel(pair, n_slices=7)
    out = []
    for x in np.arange(n_positions) / n_positions:
        pts = model.contact_points(x * pair.transverse_base_pitch)
        out.append(friction_resultants(pair, pts, 1e5 * pts["width"], model.total_width, MU)["force"])
    return np.array(out)


def test_integer_overlap_ratio_uniform_load_gives_constant_friction_force():
    """At eps_beta = 1 the axial length of contact with s > s_P is (E - s_P)/tan(beta_b) at every position, that
    with s < s_P is (s_P - A)/tan(beta_b): the friction force is the constant mu q (E + A - 2 s_P)/tan(beta_b).  At
    eps_beta = 0.75 the same load gives a fluctuating force."""
    pair = single_helical_at_overlap(1.0)
    assert pair.overlap_ratio == pytest.approx(1.0, rel=1e-12)
    A, E = pair.path_of_contact
    exact = MU * 1e5 * (E + A - 2 * pitch_point(pair)) / math.tan(pair.base_helix_angle)
    force = uniform_friction_force(pair)
    assert abs(exact) > 10.0                     # not trivially zero: the pitch point is off the path's middle
    assert np.allclose(force, exact, rtol=1e-9, atol=1e-9 * abs(exact))
    other = uniform_friction_force(single_helical_at_overlap(0.75))
    assert np.ptp(other) > 0.2 * MU * 1e5 * pair.transverse_base_pitch / math.tan(pair.base_helix_angle)


def test_zero_friction_coefficient_gives_zero_and_the_curve_reuses_the_stiffness_distributions():
    """mu = 0: no friction.  The stiffness curve's recorded resultants per unit mu, scaled, are those of a direct
    computation from the load distributions at the same positions and force."""
    pair = GearPair.from_table(REF["single_helical"])
    model = MeshModel(pair, shafts=SYMMETRIC_SHAFTS, n_slices=6)
    F = 40e3
    zero = friction_curve(model, F, 0.0, n_positions=4)
    for name in ("force", "pinion_torque", "wheel_torque", "tilt_moment"):
        assert np.all(getattr(zero, name) == 0.0)
        assert np.all(zero.harmonics(name, 6) == 0.0)
    direct = friction_curve(model, F, MU, n_positions=4)
    reused = FrictionCurve.of_curve(stiffness_curve(model, F, 4), MU)
    assert abs(direct.mean("force")) > 1e-3 * MU * F
    for name in ("force", "pinion_torque", "wheel_torque", "tilt_moment"):
        assert np.allclose(getattr(reused, name), getattr(direct, name), rtol=1e-9, atol=1e-9)
