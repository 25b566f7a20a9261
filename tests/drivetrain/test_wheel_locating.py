"""drivetrain.wheel_locating: which of the wheel's bearings locates it axially (the thesis rig, Sec. 5.8: "at the front
(pinion) and at the back (wheel)").  The loads against the shaft's statics, the configuration's locating bearing at
the locating seat, the default layout unchanged, a bad value one line naming the key with exit 2."""
import subprocess
import sys

import numpy as np
import pytest

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
    front = test_gearbox("B", "tapered_roller", 2000.0).configuration_matrices()
    back = test_gearbox("B", "tapered_roller", 2000.0, wheel_locating="back").configuration_matrices()
    assert back["wheel_back"][0][2][2] > 10 * back["wheel_front"][0][2][2]
    assert front["wheel_front"][0][2][2] > 10 * front["wheel_back"][0][2][2]
    np.testing.assert_array_equal(back["pinion_front"][0], front["pinion_front"][0])   # the pinion unchanged


def test_default_is_front_and_unchanged():
    assert DrivetrainSpec().wheel_locating == "front"
    dt = drivetrain_of(DrivetrainSpec(gear_set="B", bearings="tapered_roller"), 2000.0)
    assert [b.name for b in dt.bearings if b.locating] == ["pinion_front", "wheel_front"]
    old = test_gearbox("B", "tapered_roller", 2000.0)
    assert dt.to_coupling_spec().model_dump() == old.to_coupling_spec().model_dump()


def test_bad_value_in_python():
    with pytest.raises(InputError, match="wheel_locating: 'middle' unknown"):
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
