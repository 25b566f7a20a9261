"""Bearing configurations of the test gearbox (thesis Sec. 5.8, 5.9): physics of the 6x6 matrices at the
representative load (pinion torque 1910 N m, Appendix F tooth forces, half per bearing, axial on the front)."""
import math

import numpy as np
import pytest

from housingfe.bearings import bearing_stiffness, lookup
from housingfe.bearings.catalogue import tapered_data
from housingfe.bearings.configurations import (
    MIRROR_Y,
    MIRROR_Z,
    POSITIONS,
    REPRESENTATIVE_SPEEDS_RPM,
    bearing_matrices,
    configurations,
    evaluate,
    representative_loads,
)
from housingfe.errors import InputError

NAMES = ["ball", "angular_contact", "self_aligning", "tapered_roller", "cylindrical_roller", "fluid_film"]


@pytest.fixture(scope="module")
def results():
    return {name: evaluate(name, representative_loads(c.gear_set), REPRESENTATIVE_SPEEDS_RPM)
            for name, c in configurations().items()}


def mirrored(k, t):
    return t[:, None] * k * t[None, :]


def test_representative_load_is_the_appendix_f_case():
    loads = representative_loads("single_helical")
    fx, fy, fz = loads["pinion_front"][:3]
    assert 2 * fx == pytest.approx(38918.0) and fz == 8272.0
    assert -fy / fx == pytest.approx(math.tan(math.radians(23.099)))
    assert loads["wheel_front"][2] == -8272.0 and loads["pinion_back"][2] == 0.0
    # the double helical set: no axial load, and about the 20763 N per bearing of thesis Sec. 3.5
    dh = representative_loads("double_helical")
    assert all(dh[p][2] == 0.0 for p in POSITIONS)
    assert math.hypot(*dh["pinion_front"][:2]) == pytest.approx(20763.0, rel=0.002)


def test_configurations_follow_the_thesis():
    configs = configurations()
    assert list(configs) == NAMES
    assert [c.gear_set for c in configs.values()] == ["single_helical"] * 4 + ["double_helical"] * 2
    for c in configs.values():
        assert set(c.positions) == set(POSITIONS)
        assert "Sec. 5." in c.description
    ac = configs["angular_contact"].positions
    assert ac["pinion_front"].designation == "SKF 7316B" and ac["wheel_front"].designation == "SKF 7219B"
    assert ac["pinion_back"].designation == "SKF 6316" and ac["wheel_back"].designation == "SKF 6219"
    assert ac["pinion_front"].directional and not ac["pinion_back"].directional
    tr = configs["tapered_roller"].positions
    assert tr["pinion_front"].model == "sliced-roller" and tr["pinion_back"].model == "lim-ball"
    assert any(e.startswith("contact_angle") for e in tr["pinion_front"].estimated)
    cyl = configs["cylindrical_roller"].positions
    assert cyl["pinion_back"].designation == "SKF NJ316" and cyl["wheel_front"].designation == "SKF NU2219"
    ff = configs["fluid_film"].positions
    assert ff["pinion_front"].journal.diameter == pytest.approx(0.08025)
    assert ff["wheel_back"].journal.clearance == pytest.approx(100e-6)


@pytest.mark.parametrize("name", NAMES)
def test_four_finite_6x6_matrices(results, name):
    out = results[name]
    assert list(out) == list(POSITIONS)
    for p, r in out.items():
        assert r.K.shape == (6, 6) and np.all(np.isfinite(r.K))
        assert np.all(r.K[5] == 0) and np.all(r.K[:, 5] == 0)
        assert r.K[0, 0] > 0 and r.K[1, 1] > 0                   # every bearing carries its radial load
        if name == "fluid_film":
            assert r.C.shape == (6, 6) and np.all(np.isfinite(r.C))
        else:
            assert r.C is None
            assert np.array_equal(r.K, r.K.T)
            assert np.min(np.linalg.eigvalsh(r.K)) >= -1e-9 * np.max(np.abs(r.K))
    matrices = bearing_matrices(name, representative_loads(configurations()[name].gear_set),
                                REPRESENTATIVE_SPEEDS_RPM)
    for p in POSITIONS:
        assert np.array_equal(matrices[p][0], out[p].K)


def test_ball_bearings_have_moment_stiffness(results):
    for r in results["ball"].values():
        assert r.K[3, 3] > 0 and r.K[4, 4] > 0
        assert np.linalg.det(r.K[3:5, 3:5]) > 0


def test_self_aligning_has_zero_tilt_rows_and_columns(results):
    for r in results["self_aligning"].values():
        assert np.all(r.K[3:5] == 0) and np.all(r.K[:, 3:5] == 0)
        assert r.K[2, 2] > 0


def test_angular_contact_front_is_axially_stiffer_than_its_deep_groove_partner(results):
    out = results["angular_contact"]
    for shaft in ("pinion", "wheel"):
        # the floating deep groove bearing (Fz = 0) has only the geometric axial stiffness sum(Q_j / A_j)
        assert out[f"{shaft}_front"].K[2, 2] > 2 * out[f"{shaft}_back"].K[2, 2]


def test_single_angular_contact_bearing_below_its_e_factor():
    # SKF gives e = 1.14 for the 40 deg series: with Fa/Fr = 0.39 < e a single bearing runs with a load zone of
    # less than half the balls, at a contact angle well below 40 deg (the ring moves back until the induced
    # axial force matches Fa); under a pure axial load every ball carries and the bearing is far stiffer
    # axially than the deep groove bearing
    load = representative_loads()["pinion_front"]
    res = bearing_stiffness("SKF 7316B", load, fixed_tilt=(0.0, 0.0))
    on = res.element_loads > 0
    assert 0 < on.sum() < lookup("7316B").n_elements / 2
    assert np.all(np.degrees(res.contact_angles[on]) < 30.0)
    axial = (0.0, 0.0, load[2], 0.0, 0.0)
    assert bearing_stiffness("SKF 7316B", axial).K[2, 2] > 3 * bearing_stiffness("SKF 6316", axial).K[2, 2]


@pytest.mark.parametrize("name", ["ball", "angular_contact", "self_aligning", "tapered_roller"])
def test_mirrored_axial_load_gives_the_mirrored_matrix(results, name):
    loads = representative_loads()
    flipped = dict(loads)
    for p in ("pinion_front", "wheel_front"):
        f = list(loads[p])
        f[2] = -f[2]
        flipped[p] = tuple(f)
    out = evaluate(name, flipped)
    for p in ("pinion_front", "wheel_front"):
        k, k_flip = results[name][p].K, out[p].K
        assert np.max(np.abs(k_flip - mirrored(k, MIRROR_Z))) < 1e-7 * np.max(np.abs(k))
        if name != "self_aligning":
            # the axial-radial and tilt-radial couplings change sign, axial-tilt coupling does not
            for i, j in ((0, 2), (1, 2), (0, 4), (1, 3)):
                assert abs(k[i, j]) > 1e-3 * math.sqrt(k[i, i] * k[j, j])
                assert np.sign(k_flip[i, j]) == -np.sign(k[i, j])
            assert np.sign(k_flip[2, 3]) == np.sign(k[2, 3])
    # the single-row angular bearings are mounted the other way round, the symmetric ones need not be
    directional = name in ("angular_contact", "tapered_roller")
    assert out["pinion_front"].mirrored == directional and results[name]["wheel_front"].mirrored == directional


def test_deep_groove_mirror_symmetry_is_physical_not_constructed():
    # a deep groove bearing is symmetric about its mid-plane: K(-Fz) = T K(Fz) T without any mirroring in the
    # code, which checks the reflection operator used for the angular bearings
    f = np.array([5000.0, -12000.0, 6000.0, 0.0, 0.0])
    k = bearing_stiffness("SKF 6219", f, fixed_tilt=(0.0, 0.0)).K
    k_flip = bearing_stiffness("SKF 6219", MIRROR_Z[:5] * f, fixed_tilt=(0.0, 0.0)).K
    assert np.max(np.abs(k_flip - mirrored(k, MIRROR_Z))) < 1e-7 * np.max(np.abs(k))


def test_tapered_roller_locating_bearing(results):
    out = results["tapered_roller"]
    for shaft, designation in (("pinion", "30316J2"), ("wheel", "30219J2")):
        front, back = out[f"{shaft}_front"], out[f"{shaft}_back"]
        assert front.K[3, 3] > 0 and front.K[4, 4] > 0             # the slicing gives tilt stiffness
        assert front.K[2, 2] > 5 * back.K[2, 2]
        b = lookup(designation)
        assert math.tan(b.contact_angle) == pytest.approx(tapered_data(designation)["e"] / 1.5)
        assert "element_diameter" in b.estimated and "radial_clearance" in b.estimated
        # a single tapered bearing needs Fa >= 0.5 Fr / Y (catalogue rule) at the representative load
        fr = math.hypot(*representative_loads()[f"{shaft}_front"][:2])
        assert 8272.0 > 0.5 * fr / tapered_data(designation)["Y"]
    assert out["wheel_front"].mirrored and not out["pinion_front"].mirrored
    # its radial force line passes through the pressure centre off the bearing centre: a zero moment cannot
    # be carried by the single bearing, only the held tilt (the shaft) gives it the moment Fr * a
    assert abs(out["pinion_front"].load[4]) > 0.005 * math.hypot(*out["pinion_front"].load[:2])
    with pytest.raises(InputError, match="tapered_roller pinion_front.*30316"):
        evaluate("tapered_roller", representative_loads(), hold_tilt=False)


def test_cylindrical_roller_without_axial_load(results):
    out = results["cylindrical_roller"]
    nj = bearing_stiffness("SKF NJ316", representative_loads("double_helical")["pinion_front"],
                           fixed_tilt=(0.0, 0.0)).K
    stand_in = 0.5 * (nj[0, 0] + nj[1, 1])
    assert out["pinion_front"].axial_added == pytest.approx(stand_in)
    assert out["pinion_front"].K[2, 2] == pytest.approx(stand_in)       # the roller contacts add no axial term
    for p in ("pinion_back", "wheel_front", "wheel_back"):
        assert out[p].K[2, 2] == 0.0 and out[p].axial_added == 0.0
        assert np.all(out[p].K[2] == 0)
    assert out["pinion_front"].K[3, 3] > 0                                # sliced rollers resist tilt
    both = evaluate("cylindrical_roller", representative_loads("double_helical"), axial_location="both")
    assert both["wheel_front"].K[2, 2] > 0 and both["wheel_back"].K[2, 2] == 0
    none = evaluate("cylindrical_roller", representative_loads("double_helical"), axial_location="none")
    assert all(none[p].K[2, 2] == 0 for p in POSITIONS)
    given = evaluate("cylindrical_roller", representative_loads("double_helical"), locating_axial_stiffness=2e8)
    assert given["pinion_front"].K[2, 2] == 2e8
    with pytest.raises(InputError, match="cylindrical_roller pinion_front.*NJ316.*cannot carry"):
        evaluate("cylindrical_roller", representative_loads("single_helical"))


def test_fluid_film_coefficients(results):
    out = results["fluid_film"]
    cyl = results["cylindrical_roller"]
    for p, r in out.items():
        k, c = r.K, r.C
        assert abs(k[0, 1] - k[1, 0]) > 0.1 * max(abs(k[0, 1]), abs(k[1, 0]))       # non-symmetric K
        assert np.min(np.linalg.eigvalsh(0.5 * (c[:2, :2] + c[:2, :2].T))) > 0
        assert np.min(np.linalg.eigvalsh(0.5 * (c[3:5, 3:5] + c[3:5, 3:5].T))) > 0
        assert c[2, 2] == 0 and np.all(c[5] == 0)
        # tilt from the misaligned-journal film: the sign pattern of the radial coefficients spread over the
        # length, L^2/12 [[k_yy, -k_yx], [-k_xy, k_xx]], but less (the pressure peaks at mid-length)
        length = r.choice.journal.length
        uniform = length**2 / 12 * np.array([[k[1, 1], -k[1, 0]], [-k[0, 1], k[0, 0]]])
        assert np.all(np.sign(k[3:5, 3:5]) == np.sign(uniform))
        assert np.all(np.diag(k[3:5, 3:5]) / np.diag(uniform) > 0.3)
        assert np.all(np.diag(k[3:5, 3:5]) / np.diag(uniform) < 1.0)
        assert r.K[2, 2] == cyl[p].K[2, 2]                        # same axial stand-in as the NJ/NU set
        assert 0.8 < r.detail.eccentricity_ratio < 0.95           # thesis Sec. 3.5: 0.82 / 0.83 (graphs)
    assert out["wheel_front"].mirrored and not out["pinion_front"].mirrored     # the wheel turns about -z


def test_fluid_film_reversed_rotation_and_ocvirk():
    loads = {p: (0.0, 0.0, 0.0, 0.0, 0.0) for p in POSITIONS}
    for p in POSITIONS:
        loads[p] = (-20000.0, 0.0, 0.0, 0.0, 0.0)       # load along -x: symmetric under y -> -y
    fwd = evaluate("fluid_film", loads, {"pinion": 1500.0, "wheel": 500.0})
    rev = evaluate("fluid_film", loads, {"pinion": -1500.0, "wheel": -500.0})
    for p in ("pinion_front", "wheel_back"):
        assert np.max(np.abs(rev[p].K - mirrored(fwd[p].K, MIRROR_Y))) < 1e-9 * np.max(np.abs(fwd[p].K))
        # the journal swerves to the other side (attitude angle), the cross-coupling changes sign
        assert np.sign(rev[p].displacement[1]) == -np.sign(fwd[p].displacement[1]) != 0
        assert np.sign(rev[p].K[0, 1]) == -np.sign(fwd[p].K[0, 1])
    short = evaluate("fluid_film", loads, {"pinion": 1500.0, "wheel": 500.0}, fluid_film_model="ocvirk")
    k = short["pinion_front"].K
    assert k[3, 3] == pytest.approx(k[1, 1] * 0.056**2 / 12)
    assert k[3, 4] == pytest.approx(-k[1, 0] * 0.056**2 / 12)
    # the short bearing overestimates the load capacity at L/D = 0.7: lower eccentricity than the finite one
    assert short["pinion_front"].detail.eccentricity_ratio < fwd["pinion_front"].detail.eccentricity_ratio


@pytest.mark.parametrize("name,loads,speeds,kwargs,match", [
    ("angular_contact", {**representative_loads(), "pinion_front": (19459.0, -8300.0, 0.0, 0.0, 0.0)}, None, {},
     "angular_contact pinion_front.*7316B.*axial load"),
    ("ball", {**representative_loads(), "wheel_back": (19459.0, -8300.0, 100.0, 0.0, 0.0)}, None, {},
     "ball wheel_back.*floating"),
    ("ball", {**representative_loads(), "pinion_back": (19459.0, -8300.0, 0.0, 50.0, 0.0)}, None, {},
     "ball pinion_back.*tilt is held"),
    ("self_aligning", {**representative_loads(), "pinion_back": (19459.0, -8300.0, 0.0, 50.0, 0.0)}, None,
     {"hold_tilt": False}, "self_aligning pinion_back.*21316CC.*no moment"),
    ("fluid_film", representative_loads("double_helical"), None, {}, "fluid_film pinion_front.*speeds_rpm"),
    ("fluid_film", representative_loads("double_helical"), {"pinion": 1500.0, "wheel": 0.0}, {},
     "fluid_film wheel_front.*rotation"),
    ("ball", {"pinion_front": (0, -1e4, 0, 0, 0)}, None, {}, "missing"),
    ("ball", representative_loads(), None, {"axial_location": "wheel"}, "axial_location"),
    ("roller", representative_loads(), None, {}, "must be one of"),
])
def test_bad_input_names_configuration_and_position(name, loads, speeds, kwargs, match):
    with pytest.raises(InputError, match=match):
        evaluate(name, loads, speeds, **kwargs)


def test_carries_is_the_bearing_model_s_equilibrium():
    """configurations.carries: a single-row tapered roller bearing needs an axial load for its radial one (no
    equilibrium at Fz = 0, one at Fz = the thesis' 8.7 kN), a deep groove ball bearing takes Fz = 0 and either sign."""
    from housingfe.bearings.configurations import carries

    radial = (10000.0, -20000.0)
    assert not carries("tapered_roller", "pinion_front", (*radial, 0.0, 0.0, 0.0))
    assert carries("tapered_roller", "pinion_front", (*radial, 8663.0, 0.0, 0.0))
    for fz in (0.0, 3000.0, -3000.0):
        assert carries("ball", "pinion_back", (*radial, fz, 0.0, 0.0))
    assert carries("fluid_film", "pinion_back", (*radial, 0.0, 0.0, 0.0))
