"""The shuttling moment's centre of pressure (housingfe.source.mesh_moments) against the exact geometry of the
contact lines in the plane of action and the analytic sawtooth at an integer overlap ratio."""
import math
from dataclasses import replace

import numpy as np
import pytest

from housingfe.source.gears import GearPair
from housingfe.source.mesh_moments import CentreOfPressure, centre_of_pressure_curve, one_sided_harmonics
from housingfe.source.stiffness import (
    MeshModel,
    load_centre,
    normal_force_from_torque,
    stiffness_curve,
)
from tests.source.thesis_gears import REF, SYMMETRIC_SHAFTS


def exact_uniform_centroid(pair: GearPair, u: float) -> tuple[float, float]:
    """(total axial length [m], axial centroid [m]) of the contact lines inside the path of contact for a uniform
    load per unit contact length, from the geometry alone: line k is s = u + k p_bt + w tan(beta_b), 0 <= w <= b,
    cut to A <= s <= E; a line's length is its axial extent / cos(beta_b), so the weight per unit w is uniform."""
    A, E = pair.path_of_contact
    p, tb, b = pair.transverse_base_pitch, math.tan(pair.base_helix_angle), pair.contact_width
    length = moment = 0.0
    for k in range(-200, 200):
        s0 = u + k * p
        lo, hi = max(0.0, (A - s0) / tb), min(b, (E - s0) / tb)
        if hi > lo:
            length += hi - lo
            moment += 0.5 * (hi * hi - lo * lo)
    return length, moment / length


def single_helical(face_width: float | None = None) -> GearPair:
    pair = GearPair.from_table(REF["single_helical"])
    return pair if face_width is None else replace(pair, face_width=(face_width, face_width))


def test_spur_pair_has_no_axial_shuttling():
    """Spur contact lines span the whole face at every position: with symmetric supports and no body torsion the
    load is symmetric about the face centre at every position, so w_c = b/2 and nothing moves axially."""
    pair = GearPair(4e-3, (24, 72), math.radians(20), 0.0, (0.0, 0.0), (0.05, 0.05), kind="spur")
    model = MeshModel(pair, shafts=SYMMETRIC_SHAFTS, n_slices=8, include_body_torsion=False)
    cop = centre_of_pressure_curve(model, 20e3, n_positions=12)
    assert np.allclose(cop.axial_centre, 0.025, atol=1e-9)
    assert np.allclose(cop.total_force, 20e3, rtol=1e-9)
    assert np.max(np.abs(cop.axial_arm_harmonics(6))) < 1e-9


@pytest.mark.parametrize("face_width", [None, 0.047, 0.081])
def test_uniform_centroid_equals_exact_line_geometry(face_width):
    """The code's centre of pressure with uniform weights per unit contact length on `contact_points` against the
    exact centroid of the line segments inside A..E (midpoints of equal segments integrate w exactly)."""
    pair = single_helical(face_width)
    model = MeshModel(pair, n_slices=5)
    for x in np.linspace(0.0, 1.0, 11)[:-1]:
        u = x * pair.transverse_base_pitch
        pts = model.contact_points(u)
        total, w_c, _ = load_centre(pts, pts["width"])
        length, ref = exact_uniform_centroid(pair, u)
        assert total == pytest.approx(length, rel=1e-12)
        assert w_c == pytest.approx(ref, rel=1e-12)


def test_integer_overlap_ratio_constant_length_but_moving_centroid():
    """At eps_beta = 1 with a uniform load per unit length the total contact length is constant ((E - A) /
    tan(beta_b): no transmission error from the face-width engagement), while the axial centroid is the mean of the
    sawtooth w = ((s - u) mod p_bt) / tan(beta_b) over A <= s <= E, whose first harmonic has the amplitude
    b |sin(pi eps_alpha)| / (pi^2 eps_alpha)."""
    base = single_helical()
    b = math.pi * base.module / math.sin(base.helix_angle)        # eps_beta = b sin(beta) / (pi m_n) = 1
    pair = single_helical(b)
    assert pair.overlap_ratio == pytest.approx(1.0, rel=1e-12)
    model = MeshModel(pair, n_slices=7)
    pos = np.arange(64) / 64
    lengths, centres = [], []
    for x in pos:
        pts = model.contact_points(x * pair.transverse_base_pitch)
        total, w_c, _ = load_centre(pts, pts["width"])
        lengths.append(total)
        centres.append(w_c)
    A, E = pair.path_of_contact
    assert np.allclose(lengths, (E - A) / math.tan(pair.base_helix_angle), rtol=1e-9)
    eps_a = (E - A) / pair.transverse_base_pitch
    first = abs(np.fft.fft(centres)[1]) * 2 / len(pos)
    analytic = b * abs(math.sin(math.pi * eps_a)) / (math.pi**2 * eps_a)
    assert analytic > 0.03 * b                   # not small: a few % of the face width
    assert first == pytest.approx(analytic, rel=2e-3)


def test_stiffness_curve_records_the_centre_of_pressure():
    """The stiffness curve's recorded centres are those of the load distribution at the same positions and force
    (what the run-up reuses instead of a second distribution), and the harmonics follow S(t)'s convention: a shift
    of the positions by a quarter period turns harmonic n by exp(i n pi / 2)."""
    pair = single_helical()
    model = MeshModel(pair, shafts=SYMMETRIC_SHAFTS, n_slices=8)
    F = normal_force_from_torque(pair, 2000.0)
    curve = stiffness_curve(model, F, 8)
    direct = centre_of_pressure_curve(model, F, 8)
    reused = CentreOfPressure.of_curve(curve)
    assert np.allclose(reused.axial_centre, direct.axial_centre, rtol=0, atol=1e-12)
    assert np.allclose(direct.total_force, F, rtol=1e-9)
    # convention: x(t) = mean + Re(A_1 exp(i 2 pi t)) for a cosine sampled at the positions
    pos = np.arange(32) / 32
    a = one_sided_harmonics(pos, 3.0 * np.cos(2 * math.pi * (pos - 0.25)), 3)
    assert a[0] == pytest.approx(3.0 * np.exp(-1j * math.pi / 2), abs=1e-2)
    assert abs(a[1]) < 1e-9
