"""Contact loss of the gear source (issue 30): where the dynamic mesh force exceeds the mean the teeth separate and
the linear harmonic balance is invalid; a user running the source sees it flagged, never a silently wrong level."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

import housingfe
from housingfe.source.roosmalen import dynamics as dyn

SCENES = Path(housingfe.__file__).parent / "scenes"


def _scene(tmp_path, torque: float, speeds: tuple[float, float]) -> Path:
    text = (SCENES / "gearset-D.toml").read_text()
    for key, value in (("speed_steps", "2"), ("stiffness_positions", "16"), ("harmonics", "30"),
                       ("torque_run_Nm", f"[{torque}]"), ("torque_Nm", f"{torque}"),
                       ("speed_min_rpm", f"{speeds[0]}"), ("speed_max_rpm", f"{speeds[1]}"),
                       ("spectrum_speeds_rpm", f"[{speeds[0]}]"), ("torque_run_speed_rpm", f"{speeds[0]}")):
        lines = [ln for ln in text.splitlines() if ln.startswith(f"{key} =")]
        if lines:
            text = text.replace(lines[0], f"{key} = {value}")
        else:
            text = text.replace("[source.gears]", f"{key} = {value}\n[source.gears]")
    path = tmp_path / "contact.toml"
    path.write_text(text)
    return path


def test_contact_loss_flagged_in_the_result(tmp_path):
    """Gear set D at 10 N m, 7750 rpm (mesh resonance): `housingfe source` prints and stores the contact loss."""
    out = tmp_path / "res"
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    proc = subprocess.run([sys.executable, "-m", "housingfe", "source", str(_scene(tmp_path, 10.0, (7750.0, 7800.0))),
                           "--out", str(out)], capture_output=True, text=True, env=env, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "WARNING: contact loss at 10 N m, 7750 rpm" in proc.stdout
    assert "WARNING: contact loss at 10 N m, 7750 rpm" in (out / "summary.txt").read_text()
    check = json.loads((out / "contact_check.json").read_text())
    assert check["contact_loss"] and check["min_over_mean_mesh_force"] < 0


def test_contact_check_of_a_synthetic_state():
    """The check reads the mesh force's time history: a mean of 100 N with a 150 N first harmonic separates, with
    50 N it does not."""
    n = np.arange(-3, 4)
    for amplitude, lost in ((150.0, True), (50.0, False)):
        force = np.zeros(7, complex)
        force[3] = 100.0
        force[4] = force[2] = amplitude / 2
        state = dyn.SteadyState(tooth_frequency=1000.0, harmonics=n, Q=np.zeros((7, 14)), mesh_force=force)
        c = dyn.contact_check(state, 10.0, 500.0)
        assert c.lost == lost
        assert abs(c.min_force_N - (100.0 - amplitude)) < 1e-9
        assert ("contact loss at 10 N m, 500 rpm" in c.message) == lost
