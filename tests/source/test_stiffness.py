"""Analytic tooth stiffness (van Roosmalen 1994 Sec. 2.2-2.4) against independent solutions and the
thesis' published statements."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_bvp

from housingfe.errors import InputError
from housingfe.source.gears import GearPair
from housingfe.source.stiffness import (
    Corrections,
    MeshModel,
    ShaftBending,
    beam_influence,
    iso6336_blank_factor,
    iso6336_stiffness,
    normal_force_from_torque,
    plate_green,
    plate_green_blocks,
    plate_green_matrix,
    stiffness_curve,
)
from tests.source.thesis_gears import REF
from tests.source.thesis_gears import SYMMETRIC_SHAFTS as SHAFTS


@pytest.fixture(scope="module")
def test_gear():
    return MeshModel(GearPair.from_table(REF["single_helical"]), shafts=SHAFTS)


# ---------------------------------------------------------------- Schmidt plate (eq. 2.7-2.29)
@pytest.mark.parametrize("S1,S2,S3", [(18.5, 1.29e6, 1.87e10),     # complex roots (tooth-like, eq. 2.19)
                                      (18.5, 4.0e6, 1.0e10)])      # real roots (eq. 2.17)
def test_plate_green_against_finite_difference_bvp(S1, S2, S3):
    length, xi = 0.06, 0.021
    x = np.linspace(0, length, 61)
    ours = plate_green(length, S1, S2, S3, xi, x)
    # independent: solve_bvp on both sides with the same free-end and jump conditions
    a = S2 / S1

    def rhs(t, y, p):      # y = [f, f', f'', f'''] on the left (t in [0, xi]) and right (mapped) parts
        fl, fr = y[:4], y[4:]
        return np.vstack([fl[1], fl[2], fl[3], a * fl[2] - S3 / S1 * fl[0],
                          fr[1] * (length - xi) / xi, fr[2] * (length - xi) / xi, fr[3] * (length - xi) / xi,
                          (a * fr[2] - S3 / S1 * fr[0]) * (length - xi) / xi])

    def bc(ya, yb, p):
        return np.array([ya[2], ya[3] - a * ya[1], yb[6], yb[7] - a * yb[5],
                         yb[0] - ya[4], yb[1] - ya[5], yb[2] - ya[6], ya[7] - yb[3] - 1 / S1])

    t = np.linspace(0, xi, 400)
    sol = solve_bvp(lambda t, y: rhs(t, y, None), lambda ya, yb: bc(ya, yb, None), t, np.zeros((8, t.size)),
                    tol=1e-10, max_nodes=200000)
    assert sol.success
    left = x <= xi
    ref = np.empty_like(x)
    ref[left] = sol.sol(x[left])[0]
    ref[~left] = sol.sol((x[~left] - xi) * xi / (length - xi))[4]
    assert np.max(np.abs(ours - ref)) < 1e-4 * np.max(np.abs(ref))


def test_plate_green_equilibrium_and_reciprocity():
    S1, S2, S3, length = 18.5, 1.29e6, 1.87e10, 0.066
    x = np.linspace(0, length, 4001)
    for xi in (0.0, 0.01, 0.033, length):
        f = plate_green(length, S1, S2, S3, xi, x)
        assert S3 * np.trapz(f, x) == pytest.approx(1.0, rel=1e-4)   # eq. 2.28: foundation carries P
    assert plate_green(length, S1, S2, S3, 0.01, [0.04])[0] == pytest.approx(
        plate_green(length, S1, S2, S3, 0.04, [0.01])[0], rel=1e-9)   # Maxwell-Betti


def test_beam_influence_uniform_simply_supported():
    # a uniform simply supported beam: midspan deflection P L^3 / (48 E I)
    shaft = ShaftBending(0.1, 0.1, 0.05)
    a = beam_influence(np.array([0.025]), shaft, 0.05, 0.05, 0.0, 2.1e11, n_grid=4001)
    EI = 2.1e11 * math.pi * 0.05**4 / 64
    assert a[0, 0] == pytest.approx(0.25**3 / (48 * EI), rel=1e-4)


def test_beam_influence_matrix_is_the_uniform_beams_influence_function():
    # every entry, loads left and right of the point and on it: w(x) = P b x (L^2 - b^2 - x^2) / (6 E I L) for
    # x <= a, b = L - a (load at a); the prefix-sum evaluation must split the unit-load integral at the right points
    shaft = ShaftBending(0.1, 0.07, 0.05)
    z = np.array([0.0, 0.003, 0.02, 0.02, 0.041, 0.05])
    got = beam_influence(z, shaft, 0.05, 0.05, 0.0, 2.1e11, n_grid=4001)
    EI, L = 2.1e11 * math.pi * 0.05**4 / 64, 0.22
    x = 0.1 + z
    lo, hi = np.minimum.outer(x, x), np.maximum.outer(x, x)
    exact = (L - hi) * lo * (L**2 - (L - hi) ** 2 - lo**2) / (6 * EI * L)
    np.testing.assert_allclose(got, exact, rtol=1e-5)


def test_cached_plate_matrices_give_the_compliance_of_a_fresh_model():
    # MeshModel keeps the plate matrices of contact lines it has seen (a line inside the path of contact recurs at
    # every position, the edge-refined solve reuses the uncut lines): the compliance after a sweep over positions
    # must be exactly that of a model that never saw one
    pair = GearPair.from_table(REF["single_helical"])
    corr = Corrections(tip_relief=(20e-6, 20e-6), tip_relief_length=(3e-3, 3e-3))
    warm = MeshModel(pair, shafts=SHAFTS, corrections=corr)
    pbt = pair.transverse_base_pitch
    for x in np.arange(6) / 6:
        warm.load_distribution(x * pbt, 20e3)
    assert warm._plate_memo                       # the sweep filled the cache
    for u in (0.0, 0.5 * pbt):                     # seen (refined lines in the cache) and unseen
        pts = warm.contact_points(u)
        fresh = MeshModel(pair, shafts=SHAFTS, corrections=corr)
        assert np.array_equal(warm.compliance(pts), fresh.compliance(pts))
        blocks = plate_green_blocks(pair.contact_width, *fresh.plate[0], [pts["w_local"][:5], pts["w_local"][5:12]])
        for block, w in zip(blocks, (pts["w_local"][:5], pts["w_local"][5:12])):
            assert np.array_equal(block, plate_green_matrix(pair.contact_width, *fresh.plate[0], w, w))


# ---------------------------------------------------------------- the test gears of Chapter 5
def test_deflection_at_max_load_is_about_40um(test_gear):
    # Sec. 5.2: "tooth deflections ... in the order of 40 um" at the maximum tooth load of 41.5 kN
    curve = stiffness_curve(test_gear, 41.5e3, n_positions=12)
    assert 32e-6 < curve.deflection.mean() < 48e-6


def test_mean_stiffness_near_iso6336_mesh_stiffness(test_gear):
    pair = test_gear.pair
    curve = stiffness_curve(test_gear, normal_force_from_torque(pair, 1910.0), n_positions=12)
    iso = iso6336_stiffness(pair)
    # ISO's c_gamma_alpha contains the empirical C_M = 0.8 and C_B factors; the analytic model is a
    # theoretical stiffness: agreement within 25 % is what the two methods can promise
    assert 0.75 < curve.per_width.mean() / iso["c_gamma_alpha_N_per_m2"] < 1.25
    assert curve.per_width.mean() > iso["c_prime_N_per_m2"]     # a mesh of ~1.4 pairs is stiffer than one pair


def test_iso6336_single_stiffness_textbook_value():
    # ISO 6336-1 q' for x = 0, z -> infinity equals C1 = 0.04723: c'_th = 21.17 N/(mm um)
    pair = GearPair(4e-3, (2000, 2000), math.radians(20), 0.0, (0.0, 0.0), (0.05, 0.05), kind="spur")
    iso = iso6336_stiffness(pair)
    assert iso["c_th_N_per_mm_um"] == pytest.approx(1 / (0.04723 + 0.15551 / 2000 + 0.25791 / 2000), rel=1e-9)
    assert 20 < iso["c_th_N_per_mm_um"] < 22                  # the standard's units, not N/m^2
    # solid blanks, standard rack h_fP* = 1.25, alpha_n = 20 deg: c' = c'_th * 0.8 * 1 * 0.975
    assert iso["C_B"] == pytest.approx(0.975, rel=1e-12)
    assert iso["c_prime_N_per_mm_um"] == pytest.approx(iso["c_th_N_per_mm_um"] * 0.8 * 0.975, rel=1e-12)
    assert iso["c_prime_N_per_m2"] == pytest.approx(iso["c_prime_N_per_mm_um"] * 1e9, rel=1e-15)


def test_iso6336_basic_rack_per_gear_and_blank_factor():
    table = REF["single_helical"]
    same = iso6336_stiffness(GearPair.from_table(table))                      # h_fP* = 1.4 both
    mixed = iso6336_stiffness(GearPair.from_table({**table, "dedendum_coefficient": [1.4, 1.25]}))
    assert same["C_B"] == pytest.approx(0.9, rel=1e-12)                       # 1 + 0.5 (1.2 - 1.4)
    assert mixed["C_B"] == pytest.approx(0.5 * (0.9 + 0.975), rel=1e-12)      # mean of the two racks
    # C_R = 1 + ln(b_s/b) / (5 exp(s_R / (5 m_n))): b_s/b = 0.2, s_R = m_n -> 1 + ln(0.2) / (5 e^0.2)
    c_r = iso6336_blank_factor(0.01, 0.05, 0.004, 0.004)
    assert c_r == pytest.approx(1 + math.log(0.2) / (5 * math.exp(0.2)), rel=1e-12)
    assert iso6336_blank_factor(0.001, 0.05, 0.001, 0.004) == pytest.approx(c_r, rel=1e-12)   # limits 0.2, 1
    assert iso6336_blank_factor(None, 0.05, None, 0.004) == 1.0                                 # solid disc
    webbed = iso6336_stiffness(GearPair.from_table(table), blank_factor=c_r)
    assert webbed["c_prime_N_per_mm_um"] == pytest.approx(c_r * same["c_prime_N_per_mm_um"], rel=1e-12)


def test_stiffness_is_periodic_in_the_base_pitch(test_gear):
    pbt = test_gear.pair.transverse_base_pitch
    F = 40e3
    for u in (0.1 * pbt, 0.63 * pbt):
        assert test_gear.stiffness_at(u, F)["stiffness"] == pytest.approx(
            test_gear.stiffness_at(u + pbt, F)["stiffness"], rel=1e-9)


def test_load_distribution_balances_and_has_equal_approach(test_gear):
    pts, F, delta = test_gear.load_distribution(0.37 * test_gear.pair.transverse_base_pitch, 40e3)
    assert F.sum() == pytest.approx(40e3, rel=1e-12)
    loaded = F > 0
    approach = test_gear.compliance(pts) @ F + test_gear.hertz(pts, F) * loaded + test_gear.gaps(pts)
    assert np.allclose(approach[loaded], delta, rtol=1e-6)


def test_spur_stiffness_is_a_block_function():
    # Fig. 2.8: two levels; the double-contact share of the period equals eps_alpha - 1
    pair = GearPair(2.25e-3, (18, 90), math.radians(20), 0.0, (0.472, -0.110), (0.04, 0.04), None,
                    1.0, 1.25, 0.38, kind="spur", tip_shortening=True)
    curve = stiffness_curve(MeshModel(pair, n_slices=8), 50e3 * 0.04, n_positions=60)
    k = curve.stiffness
    high = k > 0.5 * (k.max() + k.min())
    assert high.mean() == pytest.approx(pair.transverse_contact_ratio - 1, abs=2 / 60)
    assert 1.3 < k[high].mean() / k[~high].mean() < 2.2
    # levels are flat inside each block: the within-block spread is small next to the jump
    assert np.ptp(k[high]) < 0.5 * (k[high].mean() - k[~high].mean())


def _overlap_study_pair(width):
    # Sec. 2.4: z = 18/90, m = 2.25, alpha = 20, h_a = 1, h_f = 1.25, x = 0.472/-0.110; the helix angle is
    # not printed: beta = asin(pi/18) = 10.05 deg makes B = 20.25 ... 81 mm give eps_beta = 0.5 ... 2.0
    return GearPair(2.25e-3, (18, 90), math.radians(20), math.asin(math.pi / 18), (0.472, -0.110),
                    (width, width), None, 1.0, 1.25, 0.38, tip_shortening=True)


def test_overlap_ratio_study_trends():
    amp = {}
    for width in (0.02025, 0.030375, 0.0405, 0.050625, 0.070875, 0.081):
        pair = _overlap_study_pair(width)
        force = 50e3 * width / math.cos(pair.base_helix_angle)     # F/B = 50 N/mm
        curve = stiffness_curve(MeshModel(pair, n_slices=16), force, n_positions=24)
        amp[round(pair.overlap_ratio, 2)] = curve.amplitude / pair.total_contact_width
    assert amp[0.5] > 3 * max(amp[e] for e in amp if e >= 0.8)      # small amplitude for eps_beta >= 0.8
    assert amp[1.0] < amp[0.75] and amp[1.0] < amp[1.25]               # minimum at eps_beta = 1
    assert amp[2.0] < amp[1.75]                                        # and falling towards 2


def test_profile_corrections_barely_change_mean_stiffness():
    pair = GearPair.from_table(REF["single_helical"])
    force = normal_force_from_torque(pair, 2000.0)
    means = {}
    for name in ("uncorrected", "A", "D"):
        model = MeshModel(pair, shafts=SHAFTS, corrections=Corrections.from_table(REF["profile_corrections"][name]),
                          n_slices=16)
        means[name] = stiffness_curve(model, force, n_positions=12).per_width.mean()
    for name in ("A", "D"):
        assert abs(means[name] / means["uncorrected"] - 1) < 0.05     # Fig. 2.17


def test_bad_corrections_are_input_errors():
    with pytest.raises(InputError, match="unknown key"):
        Corrections.from_table({"pinion_um": 3, "pinon_mm": 2})
    with pytest.raises(InputError, match="amount and a length"):
        Corrections.from_table({"pinion_um": 3})


def test_double_helical_helices_share_the_load_equally_without_body_coupling():
    # with rigid wheel bodies (no torsion, no shaft bending) the two helices are mirror images:
    # each carries half the load, point by point mirrored across the face
    pair = GearPair.from_table(REF["double_helical"])
    model = MeshModel(pair, n_slices=8)
    model.G_shear = math.inf
    pts, F, _ = model.load_distribution(0.3 * pair.transverse_base_pitch, 50e3)
    h0, h1 = pts["helix"] == 0, pts["helix"] == 1
    assert F[h0].sum() == pytest.approx(25e3, rel=1e-9) and F[h1].sum() == pytest.approx(25e3, rel=1e-9)
    key0 = sorted(zip(np.round(pts["s"][h0], 12), F[h0], pts["w_local"][h0]))
    key1 = sorted(zip(np.round(pts["s"][h1], 12), F[h1], pts["w_local"][h1]))
    assert np.allclose([k[1] for k in key0], [k[1] for k in key1], rtol=1e-9)
    # opposite hand: the same point of the path of contact sits at mirrored face positions
    b = pair.contact_width
    assert np.allclose([k[2] for k in key0], [b - k[2] for k in key1], atol=1e-12)


def test_face_load_share_follows_where_the_torques_enter():
    """Sec. 2.3, Fig. 2.7: wheel-body torsion loads the face where the torques enter.  With both torques entering at
    w = 0 (configuration 1) the mesh stiffness per unit width is highest there and falls towards the far face (the
    last bin may rise a little again: the plate's free edge); with the wheel torque leaving at the far face
    (configuration 2) the two twists partly compensate and the face is more even."""
    from housingfe.source.stiffness import face_load_share

    pair = GearPair.from_table(REF["single_helical"])
    force = normal_force_from_torque(pair, 2000.0)
    share = {c: face_load_share(MeshModel(pair, shafts=SHAFTS, n_slices=8, torque_configuration=c), force,
                                n_bins=8, n_positions=8)[0] for c in (1, 2)}
    for c, phi in share.items():
        assert phi.shape == (8,) and phi.mean() == pytest.approx(1.0, rel=1e-12)
    for phi in share.values():
        assert np.argmax(phi) == 0 and phi[:4].mean() > 1.02 > 0.98 > phi[4:].mean()
    assert share[2][0] / share[2][-1] < share[1][0] / share[1][-1]


def test_correction_d_is_read_as_appendix_f_and_its_triangle_edge_is_a_contact_line():
    """Set D (App. F, Fig. F.1; Sec. 2.7 table): pinion 30 um over 5.2 mm, wheel 37 um over 6.0 mm along the line
    of action from Q to P, triangle widths 25 / 30 mm.  The thesis: line P-R "is parallel to the lines of contact",
    so on every contact line inside the triangle the relief is one value (the engagement runs out linearly from Q,
    in time, not across the line), the wheel's contact starts at its corner Q with the full 37 um, and P-R itself is
    unrelieved.  The published W tan(beta_b) = 5.98 / 4.98 mm against L = 6.0 / 5.2 mm bounds the residual slope
    along a line by C |1 - W tan(beta_b) / L|: 0.14 um (wheel), 1.3 um (pinion).  A triangle mirrored across the
    face (corner at the wrong face) varies by the full amount along a line and fails."""
    from housingfe.scenefile import read_scene_dict
    from housingfe.source.roosmalen import run as rs
    from housingfe.source.stiffness import flank_gaps

    data, path = read_scene_dict("gearset-D")
    pair, corr, _, _, model = rs.build(rs.parse(data, str(path)), str(path))
    assert corr.triangular
    assert np.allclose(corr.tip_relief, (30e-6, 37e-6))
    assert np.allclose(corr.tip_relief_length, (5.2e-3, 6.0e-3))
    assert np.allclose(corr.triangle_width, (25e-3, 30e-3))
    tb = math.tan(pair.base_helix_angle)
    A, _ = pair.path_of_contact
    b = pair.contact_width
    for g in (0, 1):
        bound = corr.tip_relief[g] * abs(1 - corr.triangle_width[g] * tb / corr.tip_relief_length[g])
        only = Corrections(tip_relief=tuple(corr.tip_relief[i] if i == g else 0.0 for i in (0, 1)),
                           tip_relief_length=corr.tip_relief_length, triangular=True,
                           triangle_width=corr.triangle_width)
        spreads, relieved = [], 0
        for u in np.linspace(0.0, pair.transverse_base_pitch, 13, endpoint=False):
            pts = MeshModel(pair, corrections=only, n_slices=64).contact_points(float(u))
            gap = flank_gaps(pair, only, pts["s"], pts["w_local"], pts["w"], pts["helix"])
            for k in np.unique(pts["pair"]):
                inside = (pts["pair"] == k) & (gap > 0)
                if inside.sum() >= 2:
                    relieved += 1
                    spreads.append(np.ptp(gap[inside]))
        assert relieved >= 3
        assert max(spreads) <= bound + 1e-9 * corr.tip_relief[g], (g, max(spreads) * 1e6, bound * 1e6)
    # the wheel's first contact point (s = A) is its corner Q at the face w = b, with the full relief
    q = flank_gaps(pair, Corrections(tip_relief=(0.0, 37e-6), tip_relief_length=(0.0, 6.0e-3), triangular=True,
                                     triangle_width=(0.0, 30e-3)), A, b, b, 0)
    assert q == pytest.approx(37e-6, rel=1e-12)


# ---------------------------------------------------------------- up to the torque limit (GearPair.torque_problem)
@pytest.mark.parametrize("scene", ["gearset-A", "gearset-C", "gearset-double-helical"])
def test_load_distribution_converges_up_to_the_torque_limit(scene):
    """Between the thesis' test torque and the physical limit the source must answer (a torque above it is refused
    as input): the scene's own mesh model (corrections, shafts, 24 slices, 32 positions) just below the limit.
    Before Weber's approach was held >= 0 the double helical set failed from 5000 N m (2.5 x its test torque) and
    set A from about 12 kN m (above its limit): slivers of a contact line with a negative Hertzian compliance made the iteration cycle."""
    from housingfe.scenefile import read_scene_dict
    from housingfe.source import gears
    from housingfe.source.roosmalen import run as roosmalen

    data, path = read_scene_dict(scene)
    table = roosmalen.parse(data, str(path))
    pair, _, _, _, model = roosmalen.build(table, str(path))
    highest = (gears.UNIT_TOOTH_LOAD_LIMIT_PA * pair.total_contact_width * pair.module
               * float(pair.pitch_diameter[0]) / 2)
    force = normal_force_from_torque(pair, 0.99 * highest)
    curve = stiffness_curve(model, force, table.stiffness_positions)
    assert np.all(np.isfinite(curve.stiffness)) and np.all(curve.stiffness > 0)
    # the approach grows with the load: above its value at the test torque, and below the module (tooth scale)
    nominal = stiffness_curve(model, normal_force_from_torque(pair, 2000.0), 8)
    assert curve.deflection.mean() > nominal.deflection.mean()
    assert curve.deflection.max() < pair.module
    with pytest.raises(InputError, match="875 N/mm"):
        stiffness_curve(model, normal_force_from_torque(pair, 1.01 * highest), 4)


# ---------------------------------------------------------------- contact lines that vanish at the path's ends
def test_hertz_approach_grows_with_the_load_and_its_compliance_as_one_over_the_width(test_gear):
    """Weber's approach (eq. 2.40) F (ln(arg) - nu/(1-nu)) with arg ~ L/F peaks and falls at line loads far beyond
    the tooth's (Hertzian half-width ~ the tooth thickness).  An approach must grow with the load, and a segment's
    compliance must grow as 1/L as its width L -> 0 (a line load of finite approach): at least 2 (1 - nu^2) /
    (pi E L), the Weber bracket's value at its peak."""
    p = test_gear.pair
    pts = {k: v[:1] for k, v in test_gear.contact_points(0.3 * p.transverse_base_pitch).items()}
    E, nu = p.youngs_modulus, p.poisson_ratio
    forces = np.logspace(-3, 7, 400)
    for width in (1e-3, 1e-5, 1e-7):
        pts["width"] = np.array([width])
        approach = np.array([test_gear.hertz(pts, np.array([f]))[0] for f in forces])
        assert np.all(np.diff(approach) > 0)
        floor = 2 * (1 - nu**2) / (math.pi * E * width / math.cos(p.base_helix_angle))
        assert np.all(approach / forces >= floor * (1 - 1e-12))
    # at tooth-like line loads (1e5 N/m .. 1e6 N/m) the bracket is Weber's: ln(arg) - nu/(1-nu) >= 3
    width = 1e-3
    pts["width"] = np.array([width])
    floor = 2 * (1 - nu**2) / (math.pi * E * width / math.cos(p.base_helix_angle))
    for q in (1e5, 1e6):
        assert test_gear.hertz(pts, np.array([q * width]))[0] / (q * width) >= 3 * floor


def test_a_vanishing_contact_line_carries_a_vanishing_load(test_gear):
    """The contact line that enters the path of contact at its end E is eps long (axially) at the mesh position
    where it starts; at a given approach its load must go to zero with eps (no tip relief here).  Before Weber's
    approach was held at its peak value a line of 30 um .. 0.1 um carried ~9.6 % of the 1000 N m mesh force (one
    of its 24 points took it with zero Hertz compliance)."""
    p = test_gear.pair
    _, E_ = p.path_of_contact
    tb, pbt = math.tan(p.base_helix_angle), p.transverse_base_pitch
    force = normal_force_from_torque(p, 1000.0)
    shares, deltas = [], []
    for eps in (1e-4, 3e-5, 1e-6, 1e-7):
        u = (E_ - eps * tb) % pbt
        pts, F, delta = test_gear.load_distribution(u, force)
        line = pts["pair"] == round((E_ - eps * tb - u) / pbt)
        assert pts["width"][line].sum() == pytest.approx(eps, rel=1e-6)
        shares.append(F[line].sum() / force)
        deltas.append(delta)
    assert shares[-2] < 1e-3 and shares[-1] < 1e-4
    # the line load (force per length) tends to a finite limit: load proportional to eps
    assert shares[-1] / 1e-7 == pytest.approx(shares[-2] / 1e-6, rel=0.02)
    assert shares[1] / 3e-5 == pytest.approx(shares[-1] / 1e-7, rel=0.1)
    # the mean approach tends to that without the line
    assert np.ptp(deltas[2:]) < 1e-4 * deltas[-1]
