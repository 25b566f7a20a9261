"""drivetrain.wheel_locating: which of the wheel's bearings locates it axially (the thesis rig, Sec. 5.8: "at the front
(pinion) and at the back (wheel)").  The loads against the shaft's statics, the configuration's locating bearing at
the locating seat, the default "configuration" (the side the thesis states, "front" where it states none), the
model's axial mesh force onto the bearing the text names, a bad value one line naming the key with exit 2."""
import subprocess
import sys

import numpy as np
import pytest

from housingfe.bearings.configurations import configurations
from housingfe.drivetrain.coupling import axis_frame
from housingfe.drivetrain.description import test_gearbox
from housingfe.errors import InputError
from housingfe.runup.scene import DrivetrainSpec, drivetrain_of


def _global_loads(dt):
    """{seat: (position (m), load on the bearing (N, global))}."""
    loads = dt.bearing_loads()
    out = {}
    for b in dt.bearings:
        line = dt.shaft(b.shaft)
        out[b.name] = (line.point(b.position), axis_frame(line.axis) @ np.asarray(loads[b.name][:3]))
    return out


@pytest.mark.parametrize("config", ["ball", "tapered_roller"])
def test_back_layout_loads_balance_the_mesh_force(config):
    dt = test_gearbox("B", config, 2000.0, wheel_locating="back")
    forces = dt.gear_forces()
    f = -np.asarray(forces.force_on_pinion)              # the pinion pushes the wheel
    a = np.asarray(dt.shaft("wheel").axis, float)
    loads = dt.bearing_loads()
    fa = f @ a
    assert abs(fa) > 5e3                                # gear set B's helix: a real axial force
    assert loads["wheel_back"][2] == pytest.approx(fa, rel=1e-12)       # the back bearing takes all of it
    assert loads["wheel_front"][2] == 0.0
    g = _global_loads(dt)
    (p_f, l_f), (p_b, l_b) = g["wheel_front"], g["wheel_back"]
    np.testing.assert_allclose(l_f + l_b, f, atol=1e-9 * np.linalg.norm(f))          # force balance
    # moment balance about the mesh point, without the torque about the shaft axis (the drive line's)
    m = np.cross(p_f - forces.point, l_f) + np.cross(p_b - forces.point, l_b)
    m -= (m @ a) * a
    assert np.linalg.norm(m) < 1e-9 * np.linalg.norm(f) * 0.2
    # the pinion is located at its front bearing either way
    assert loads["pinion_back"][2] == 0.0 and abs(loads["pinion_front"][2]) == pytest.approx(abs(fa), rel=1e-12)


def test_back_layout_moves_the_locating_bearing_type():
    """tapered_roller: the tapered bearing (axially stiff, k_zz ~ 1e8 N/m and more) goes to the locating seat, the
    deep groove ball bearing (Fz = 0: k_zz from the radial load only) to the floating one."""
    front = test_gearbox("B", "tapered_roller", 2000.0, wheel_locating="front").configuration_matrices()
    back = test_gearbox("B", "tapered_roller", 2000.0, wheel_locating="back").configuration_matrices()
    assert back["wheel_back"][0][2][2] > 10 * back["wheel_front"][0][2][2]
    assert front["wheel_front"][0][2][2] > 10 * front["wheel_back"][0][2][2]
    np.testing.assert_array_equal(back["pinion_front"][0], front["pinion_front"][0])   # the pinion unchanged


# the side of the wheel's locating bearing the thesis states (Sec. 5.8, thesis text l. 2091 and 2100), None: silent
THESIS_SIDES = {"ball": None, "angular_contact": "back", "self_aligning": None, "tapered_roller": "back",
                "cylindrical_roller": None, "fluid_film": None}


def test_each_configuration_carries_the_side_the_thesis_states():
    configs = configurations()
    assert {name: c.wheel_locating for name, c in configs.items()} == THESIS_SIDES
    for name, c in configs.items():
        assert c.wheel_locating_source, name                        # the words, or why there are none
    assert "at the back (wheel)" in configs["angular_contact"].wheel_locating_source
    # drawn by `housingfe uncertainty`: the single helical configurations whose side the text leaves open
    assert [n for n, c in configs.items() if c.wheel_side_uncertain] == ["ball", "self_aligning"]


@pytest.mark.parametrize("config", list(THESIS_SIDES))
def test_default_is_the_configurations_stated_side(config):
    """The scene's default "configuration": the stated side, "front" where none is stated -- the same drivetrain
    as the explicit override of that side (so ball and self-aligning are the layout of every number before)."""
    assert DrivetrainSpec().wheel_locating == "configuration"
    side = THESIS_SIDES[config] or "front"
    gear_set = "double_helical" if config in ("cylindrical_roller", "fluid_film") else "B"
    dt = drivetrain_of(DrivetrainSpec(gear_set=gear_set, bearings=config), 2000.0)
    assert [b.name for b in dt.bearings if b.locating] == ["pinion_front", f"wheel_{side}"]
    explicit = test_gearbox(gear_set, config, 2000.0, wheel_locating=side)
    assert dt.to_coupling_spec().model_dump() == explicit.to_coupling_spec().model_dump()
    assert test_gearbox(gear_set, config, 2000.0).bearings == dt.bearings       # the Python default is the same


@pytest.mark.parametrize("gear_set", ["A", "B", "C", "D", "uncorrected"])
def test_the_mesh_pushes_each_shaft_onto_the_bearing_the_text_names(gear_set):
    """Sec. 5.8: the angular contact bearing sat "at the shaft side where the axial force is encountered by the
    bearings ... at the front (pinion) and at the back (wheel)".  The model's own mesh force (its helix hand and
    direction of load, housingfe.drivetrain.description.mesh_line_of_action) must push the pinion towards its front
    and the wheel towards its back, so that each locating bearing of the text's layout is pressed outwards, towards
    its own side of the gearbox, by |F_a| = F_t tan(beta) (8272 N at 1910 N m, App. F, scaled to 2000 N m); a sign
    error in the axial force would put it on the side the text does not name."""
    fa_expected = 8272.0 * 2000.0 / 1910.0
    for config in ("angular_contact", "tapered_roller"):            # the configurations whose side is stated
        dt = test_gearbox(gear_set, config, 2000.0)
        g = _global_loads(dt)
        for shaft, side in (("pinion", "front"), ("wheel", THESIS_SIDES[config])):
            locating = [b for b in dt.bearings if b.shaft == shaft and b.locating]
            assert [b.name for b in locating] == [f"{shaft}_{side}"]
            seat = locating[0]
            a = np.asarray(dt.shaft(shaft).axis, float)
            centre = np.asarray(dt.shaft(shaft).point(0.0), float)          # the gear centre
            outwards = np.sign((g[seat.name][0] - centre) @ a)              # from the gear towards the seat's side
            fa = g[seat.name][1] @ a                                        # the axial load on the bearing
            assert fa * outwards == pytest.approx(fa_expected, rel=2e-3), (config, shaft)
            other = next(b for b in dt.bearings if b.shaft == shaft and not b.locating)
            assert g[other.name][1] @ a == 0.0                              # the floating one takes none


def test_bad_value_in_python():
    with pytest.raises(InputError, match=r"wheel_locating: 'middle' unknown \(known: configuration, front, back\)"):
        test_gearbox("B", "ball", 2000.0, wheel_locating="middle")


@pytest.mark.parametrize("command", [["run", "test-gearbox-runup"], ["study", "bearings"]])
def test_cli_bad_value_one_line_exit_2(tmp_path, command):
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "housingfe", *command, "--out", str(out),
                           "--set", "drivetrain.wheel_locating=middle"], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2, proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "drivetrain.wheel_locating: 'middle' is not a bearing side" in lines[0], proc.stderr
    assert "Traceback" not in proc.stderr and not out.exists()
