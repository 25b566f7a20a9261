"""Mesh misalignment under load (housingfe.source.misalignment, MeshModel.lead_gap, face_load_share): the load
share with a linear gap against the closed form of a uniform bed of springs, the lumped model's static tilt against
statics by hand, and "none" reproducing the aligned model exactly."""
import math

import numpy as np
import pytest

from housingfe.data import thesis
from housingfe.source.gears import GearPair
from housingfe.source.misalignment import from_tilts, lumped_misalignment
from housingfe.source.roosmalen import dynamics as dyn
from housingfe.source.roosmalen import run as rs
from housingfe.source.roosmalen.operating import SourceModel
from housingfe.source.stiffness import (
    MeshModel,
    contact_loss_fraction,
    face_load_share,
    flank_gaps,
    normal_force_from_torque,
)
from tests.source.thesis_gears import spur_pair

REF = thesis()["gears"]
PAIR = GearPair.from_table(REF["single_helical"])


@pytest.fixture(scope="module")
def bed():
    """A spur pair whose contact points are independent springs, uniform across the face (no plate coupling, no
    shafts, no body torsion): a bed of springs k per unit width; its aligned approach delta0 at one position."""
    model = MeshModel(spur_pair(), shafts=None, n_slices=24, include_plate_coupling=False,
                      include_body_torsion=False)
    force = 40e3
    _, _, delta0 = model.load_distribution(0.0, force)
    return model, force, delta0


def test_linear_gap_gives_a_linear_load_share(bed):
    """Gap gamma w < 2 delta0 over the whole face: q(w) = k (delta - gamma w) with delta = delta0 + gamma b / 2,
    share = 1 - gamma (w - b/2) / delta0.  The residual (<= 4 % of the mean) is the Hertz term, the one non-linear
    spring of the model (its secant compliance falls where the load rises)."""
    model, force, delta0 = bed
    b = model.pair.contact_width
    w = (np.arange(24) + 0.5) / 24 * b
    for gap_ratio in (0.5, 1.0):                        # gap across the face = gap_ratio x 2 delta0
        gamma = gap_ratio * 2 * delta0 / b
        share = face_load_share(model, force, n_positions=1, lead_gap=gamma)[0]
        closed = 1 - gamma * (w - b / 2) / delta0
        assert np.max(np.abs(share - closed)) < 0.04
        assert contact_loss_fraction(share) == 0.0


def test_linear_gap_beyond_the_approach_loses_contact(bed):
    """gamma b > 2 delta0: the flanks separate beyond c = sqrt(2 delta0 b / gamma), where the gap exceeds the
    approach delta = gamma c; the load is linear from the loaded face to c (here c = b / 2)."""
    model, force, delta0 = bed
    b = model.pair.contact_width
    gamma = 4 * 2 * delta0 / b
    share = face_load_share(model, force, n_positions=1, lead_gap=gamma)[0]
    c = math.sqrt(2 * delta0 * b / gamma)
    w = (np.arange(24) + 0.5) / 24 * b
    assert contact_loss_fraction(share) == pytest.approx(0.5)
    assert np.all(share[w > c] == 0.0)
    loaded = w < c - b / 24
    slope, intercept = np.polyfit(w[loaded], share[loaded], 1)
    assert -intercept / slope == pytest.approx(c, rel=0.03)                # where the load runs out
    # a negative slope loads the other face the same way
    mirrored = face_load_share(model, force, n_positions=1, lead_gap=-gamma)[0]
    assert np.allclose(mirrored, share[::-1], atol=1e-6)


def test_lead_gap_zero_is_the_aligned_model():
    """misalignment "none": the gaps, the load share and the operating point are bit for bit those of the aligned
    model (what the chain computed before)."""
    model = MeshModel(PAIR, n_slices=8)
    pts = model.contact_points(0.3 * PAIR.transverse_base_pitch)
    assert np.array_equal(model.gaps(pts), flank_gaps(PAIR, model.corrections, pts["s"], pts["w_local"], pts["w"],
                                                        pts["helix"]))
    source = SourceModel.from_scene("gearset-A")
    assert source.misalignment == "none" and source.lead_gap(2000.0) == 0.0
    op = source._point(2000.0)
    pair, corr, interior, mesh = source.pair, source.corrections, source.interior, source.mesh_model
    plain = rs.OperatingPoint(pair, corr, interior, mesh, 2000.0, source.stiffness_positions)
    assert np.array_equal(op.S, plain.S) and np.array_equal(op.shock, plain.shock)
    assert np.array_equal(op.load_share, plain.load_share)


def test_lumped_tilt_is_the_axial_moment_over_the_bearing_tilt_stiffness():
    """The lumped model holds the gears on Appendix C's bearing diagonal at their centres: statically each gear tilts
    about y by theta_y = -F_bn sin(beta_b) r_w / k_theta_y (the axial force component at the operating pitch
    radius), nothing about x; the plane of action's normal is (-cos a, sin a, 0) (e_w = z), so
    gamma = (theta_y,p - theta_y,w) sin(alpha_wt) and lead_gap = -cos(beta_b) gamma."""
    interior = dyn.derive_interior(PAIR)
    torque = 2000.0
    mats = dyn.assemble(PAIR, interior, 1.1e9)
    result = lumped_misalignment(PAIR, mats, dyn.preload_force(mats, torque), torque, 0.066)
    fn = normal_force_from_torque(PAIR, torque)
    a, bb = PAIR.operating_pressure_angle, PAIR.base_helix_angle
    rw1, rw2 = PAIR.base_diameter / 2 / math.cos(a)
    tp = -fn * math.sin(bb) * rw1 / interior.pinion_bearings[4]
    tw = -fn * math.sin(bb) * rw2 / interior.wheel_bearings[4]
    # the mesh force of the static state is the torque's F_bn up to the torsion chain's share (DOF 15 holds it)
    assert result.tilt_pinion[1] == pytest.approx(tp, rel=1e-6)
    assert result.tilt_wheel[1] == pytest.approx(tw, rel=1e-6)
    assert abs(result.tilt_pinion[0]) < 1e-9 * abs(tp)
    assert result.gamma == pytest.approx((tp - tw) * math.sin(a), rel=1e-6)
    assert result.lead_gap == pytest.approx(-math.cos(bb) * result.gamma, rel=1e-12)
    assert result.gap_across_face == pytest.approx(abs(result.lead_gap) * 0.066)


def test_tilt_about_the_axis_or_the_contact_normal_opens_no_gap():
    """Only the tilt about the normal of the plane of action changes the compression along the face: rotations
    about the face axis (a spin) or about the transverse line of action leave the gap unchanged."""
    n = np.array([math.sin(0.35) * math.cos(0.2), math.cos(0.35) * math.cos(0.2), -math.sin(0.2)])
    l = np.array([math.sin(0.35), math.cos(0.35), 0.0])
    for theta in (np.array([0, 0, 1e-4]), 1e-4 * l):
        r = from_tilts("t", 1.0, theta, np.zeros(3), (0, 0, 1), n, 0.1, 0.2)
        assert abs(r.gamma) < 1e-18 and abs(r.lead_gap) < 1e-18
    m = np.cross([0, 0, 1.0], l)
    r = from_tilts("t", 1.0, 1e-4 * m, np.zeros(3), (0, 0, 1), n, 0.1, 0.2)
    assert r.gamma == pytest.approx(1e-4) and r.lead_gap == pytest.approx(-math.cos(0.2) * 1e-4)
