"""drivetrain.floating_axial_ratio: the floating bearings' friction-held mean axial load (a floating outer ring sticks
in its bore, benchmarks/experiments/floating_axial), F_a = ratio |F_r|, the locating bearing taking the reaction.

* statics: per shaft the two bearings' axial loads add up to the mesh force's axial component (gear sets A-D, the
  ball and a configuration path, both signs), the floating one carries ratio |F_r| away from the locating bearing
  for ratio > 0, the radial loads do not change;
* ratio 0 gives the matrices of the bearings computed with Fz = 0 on the floating positions explicitly;
* a deep groove ball bearing (Lim's model) under added axial load is axially stiffer and gains a radial-axial
  coupling, and the FE matrices take the ratio (configuration and designation paths);
* bad values: InputError naming the key; a floating bearing that carries no axial load is refused;
* a directional locating bearing the held load would lift off: the floating ring slides (held load saturated).
"""
import numpy as np
import pytest

from housingfe.bearings import bearing_stiffness
from housingfe.bearings.configurations import bearing_matrices
from housingfe.drivetrain.description import FLOATING_AXIAL_LIMIT, test_gearbox
from housingfe.errors import InputError


def _with_ratio(dt, ratio):
    from dataclasses import replace

    return replace(dt, floating_axial_ratio=ratio)


@pytest.mark.parametrize("gear_set", ["A", "B", "C", "D"])
@pytest.mark.parametrize("bearings, side", [("ball", "configuration"), ("ball", "back"),
                                            ("angular_contact", "configuration")])
def test_each_shaft_stays_in_axial_equilibrium(gear_set, bearings, side):
    dt0 = test_gearbox(gear_set, bearings, 2000.0, wheel_locating=side)
    forces = dt0.gear_forces()
    base = dt0.bearing_loads(forces)
    for ratio in (-0.2, 0.15, FLOATING_AXIAL_LIMIT):
        dt = _with_ratio(dt0, ratio)
        loads = dt.bearing_loads(forces)
        for shaft, sign in (("pinion", 1.0), ("wheel", -1.0)):
            a = np.asarray(dt.shaft(shaft).axis, float)
            mesh_axial = sign * float(np.asarray(forces.force_on_pinion) @ a)   # on this shaft, along its axis
            assert abs(mesh_axial) > 1e3                                         # single helical: a real one
            seats = [b for b in dt.bearings if b.shaft == shaft]
            loc = next(b for b in seats if b.locating)
            flo = next(b for b in seats if not b.locating)
            # the frames' z is the shaft axis (common to both bearings of a shaft)
            assert loads[loc.name][2] + loads[flo.name][2] == pytest.approx(mesh_axial, rel=1e-12)
            f_r = float(np.hypot(*base[flo.name][:2]))
            away = np.sign(flo.position - loc.position)                          # from locating to floating
            requested, effective = dt.floating_axial_held(forces)[shaft]
            assert requested == pytest.approx(ratio * f_r, rel=1e-12)
            if bearings == "ball" or ratio > 0:                                  # nothing to slide
                assert effective == requested
            assert loads[flo.name][2] == pytest.approx(effective * away, rel=1e-12)
            for b in seats:                                                      # radial loads unchanged
                assert loads[b.name][:2] == pytest.approx(base[b.name][:2], rel=1e-12, abs=1e-9)
                assert loads[b.name][3:] == (0.0, 0.0)


def test_ratio_zero_is_the_bearings_with_no_floating_axial_load():
    """The configuration path at ratio 0 against bearing_matrices with the floating Fz put to 0 by hand (the
    configuration module's own check still refusing any Fz there), and the designation path's load entries."""
    dt = test_gearbox("B", "tapered_roller", 2000.0)
    assert dt.floating_axial_ratio == 0.0
    loads = dt.bearing_loads()
    role = dt.configuration_roles()
    by_hand = {role[n]: (v[0], v[1], v[2] if role[n].endswith("front") else 0.0, 0.0, 0.0) for n, v in loads.items()}
    z1, z2 = dt.gears.pair.teeth
    expected = bearing_matrices("tapered_roller", by_hand, {"pinion": dt.bearing_speed_rpm,
                                                            "wheel": -dt.bearing_speed_rpm * z1 / z2},
                                axial_location="both")
    got = dt.configuration_matrices()
    for name, r in role.items():
        np.testing.assert_array_equal(got[name][0], expected[r][0])
    ball = test_gearbox("A", "ball", 2000.0)
    for entry in ball.to_coupling_spec().bearings:
        if not next(b for b in ball.bearings if b.name == entry.name).locating:
            assert entry.load[2] == 0.0


def test_a_floating_deep_groove_bearing_stiffens_axially_under_the_held_load():
    """Lim's model: an axial load on a radially loaded deep groove ball bearing loads more balls and turns their
    contact angle, so k_zz grows with F_a and a radial-axial coupling k_yz appears (none at F_a = 0)."""
    dt = test_gearbox("A", "ball", 2000.0)
    f_r = float(np.hypot(*dt.bearing_loads()["wheel_back"][:2]))
    k = {}
    for ratio in (0.0, 0.1, 0.2):
        load = _with_ratio(dt, ratio).bearing_loads()["wheel_back"]
        assert load[2] == pytest.approx(ratio * f_r, rel=1e-12)
        k[ratio] = bearing_stiffness("SKF 6219", load, model="lim-ball", fixed_tilt=(0.0, 0.0)).K
    assert k[0.0][2, 2] < k[0.1][2, 2] < k[0.2][2, 2]
    assert k[0.2][2, 2] > 1.3 * k[0.0][2, 2]                   # not a rounding effect: measured x1.92 (2026-11-28)
    c0 = abs(k[0.0][2, :2]).max() / np.sqrt(k[0.0][2, 2] * k[0.0][:2, :2].trace())
    c2 = abs(k[0.2][2, :2]).max() / np.sqrt(k[0.2][2, 2] * k[0.2][:2, :2].trace())
    assert c0 < 1e-9 and c2 > 0.05


def test_the_fe_matrices_take_the_ratio():
    """Both places the loads are used: a configuration's floating deep groove bearing (its K at the held load, as
    the bearing model gives it) and a designation's load entry (the coupling spec builds its K from it)."""
    dt = _with_ratio(test_gearbox("B", "angular_contact", 2000.0), 0.15)
    loads = dt.bearing_loads()
    mats = dt.configuration_matrices(loads)
    floating = next(b for b in dt.bearings if b.shaft == "pinion" and not b.locating)
    own = bearing_stiffness("SKF 6316", loads[floating.name], model="lim-ball", fixed_tilt=(0.0, 0.0)).K
    own[5, :] = own[:, 5] = 0.0
    np.testing.assert_allclose(mats[floating.name][0], own, rtol=1e-12, atol=1e-6)
    assert loads[floating.name][2] != 0.0
    ball = _with_ratio(test_gearbox("A", "ball", 2000.0), -0.15)
    held = ball.bearing_loads()
    for entry in ball.to_coupling_spec().bearings:
        assert tuple(entry.load) == pytest.approx(held[entry.name])


@pytest.mark.parametrize("ratio", [0.31, -0.5, float("nan"), float("inf")])
def test_a_ratio_beyond_any_ring_friction_is_refused(ratio):
    with pytest.raises(InputError, match=r"^drivetrain\.floating_axial_ratio: .*must be a number within \+-0\.3"):
        _with_ratio(test_gearbox("A", "ball"), ratio)


@pytest.mark.parametrize("gear_set, bearings", [("double_helical", "fluid_film"),
                                                ("double_helical", "cylindrical_roller")])
def test_floating_bearings_without_axial_capacity_are_refused(gear_set, bearings):
    dt = test_gearbox(gear_set, bearings, 1000.0)
    dt.to_coupling_spec()                                           # ratio 0: as before
    with pytest.raises(InputError, match=r"^drivetrain\.floating_axial_ratio: 0\.1: the floating bearing"):
        _with_ratio(dt, 0.1).to_coupling_spec()


def test_the_scene_key_names_itself():
    from housingfe.runup.scene import load_runup_scene

    scene, _ = load_runup_scene("test-gearbox-runup", ["drivetrain.floating_axial_ratio=-0.15"])
    assert scene.drivetrain.floating_axial_ratio == -0.15
    for sets, what in ((["drivetrain.floating_axial_ratio=0.35"], "must be within"),
                       (["drivetrain.floating_axial_ratio=0.1", "drivetrain.gear_set=double_helical",
                         "drivetrain.bearings=fluid_film"], r"pinion_back \(fluid film\)")):
        with pytest.raises(InputError, match=rf"drivetrain\.floating_axial_ratio: .*{what}"):
            load_runup_scene("test-gearbox-runup", sets)


@pytest.mark.parametrize("bearings", ["angular_contact", "tapered_roller"])
def test_a_relieved_directional_locating_bearing_lets_the_floating_ring_slide(bearings):
    """Angular contact and tapered roller bearings locate each shaft on the side its mesh force pushes it to (Sec.
    5.8); a negative ratio takes axial load off them, and a single-row bearing without enough axial load has no
    equilibrium under its radial load (measured boundary: -0.06 to -0.07 tapered, -0.12 to -0.13 angular contact,
    2026-11-28).  Then the shaft moves and the floating ring slides: the held load is the largest the locating
    bearing carries -- below the requested one in magnitude, same sign, the bound being the bearing model's own."""
    from housingfe.bearings.configurations import carries
    from housingfe.drivetrain.description import SLIDE_TOLERANCE

    dt = _with_ratio(test_gearbox("B", bearings, 2000.0), -0.2)
    forces = dt.gear_forces()
    held = dt.floating_axial_held(forces)
    loads = dt.bearing_loads(forces)
    dt.configuration_matrices(loads)                              # runs: no InputError any more
    base = _with_ratio(dt, 0.0).bearing_loads(forces)
    for shaft, sign in (("pinion", 1.0), ("wheel", -1.0)):
        requested, effective = held[shaft]
        loc = next(b for b in dt.bearings if b.shaft == shaft and b.locating)
        flo = next(b for b in dt.bearings if b.shaft == shaft and not b.locating)
        f_r = float(np.hypot(*base[flo.name][:2]))
        assert requested == pytest.approx(-0.2 * f_r, rel=1e-12)
        assert requested < effective < 0.0                        # (a) slid: smaller, same sign
        away = np.sign(flo.position - loc.position)
        assert loads[flo.name][2] == pytest.approx(effective * away, rel=1e-12)
        # (c) the shaft's axial equilibrium with the effective held load
        a = np.asarray(dt.shaft(shaft).axis, float)
        mesh_axial = sign * float(np.asarray(forces.force_on_pinion) @ a)
        assert loads[loc.name][2] + loads[flo.name][2] == pytest.approx(mesh_axial, rel=1e-12)
        # (b) at the effective load the locating bearing holds, at 10 tolerances more it does not
        position = f"{shaft}_front"
        assert carries(bearings, position, loads[loc.name])
        more = np.array(loads[loc.name]) - 10 * SLIDE_TOLERANCE * np.sign(effective) * away * np.r_[0, 0, 1, 0, 0]
        assert abs(more[2]) < abs(loads[loc.name][2])             # relieved further
        assert not carries(bearings, position, more)
        assert carries(bearings, position, base[loc.name])        # ratio 0: it carries
    # the radial loads stay those of the statics
    for name in loads:
        assert loads[name][:2] == pytest.approx(base[name][:2], rel=1e-12, abs=1e-9)


def test_a_held_load_the_locating_bearing_carries_is_kept():
    """No sliding where none is needed: the loads at -0.05 and +0.15 are ratio |F_r| exactly (tapered rollers,
    boundary about -0.06), and a ball locating bearing takes -0.2 in either direction."""
    for bearings, ratio in (("tapered_roller", -0.05), ("tapered_roller", 0.15), ("ball", -0.2),
                            ("self_aligning", -0.2)):
        dt = _with_ratio(test_gearbox("B", bearings, 2000.0), ratio)
        for requested, effective in dt.floating_axial_held().values():
            assert effective == requested != 0.0
    assert _with_ratio(test_gearbox("B", "angular_contact"), 0.0).floating_axial_held() == {
        "pinion": (0.0, 0.0), "wheel": (0.0, 0.0)}
