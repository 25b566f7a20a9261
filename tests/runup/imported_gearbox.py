"""The built-in test gearbox housing written to STEP and described by a `cad` housing scene with one bore selector
per bearing seat and the feet by boxes, plus a run-up scene on it (shared by the bore-matching and run-up tests)."""
from __future__ import annotations

from pathlib import Path

# the test gearbox's shaft axes (x, z) and its bearings mid-plate at y = -/+0.1075 m (bearing plates 75-140 mm)
SHAFTS = {"A": -0.126, "B": 0.074}
SEATS = {"front": -0.1075, "back": 0.1075}

HOUSING = """[scene]
name = "step-gearbox"
kind = "housing"
description = "the test gearbox housing from STEP"

[geometry]
kind = "cad"
file = "gearbox.step"
units = "m"
{bores}
[[geometry.surfaces]]
name = "foot_front"
box = {{ min = [-0.25, -0.151, -0.001], max = [0.25, -0.074, 0.001] }}

[[geometry.surfaces]]
name = "foot_back"
box = {{ min = [-0.25, 0.074, -0.001], max = [0.25, 0.151, 0.001] }}

[material]
name = "steel"

[mesh]
element = "tet"
degree = 2
elements_per_wavelength = 6
size = {size}

[[supports]]
surface = "foot_front"
kind = "fixed"

[[supports]]
surface = "foot_back"
kind = "fixed"

[analysis.modal]
f_max = 1500.0
"""

RUNUP = """[scene]
name = "step-gearbox-runup"
kind = "runup"
description = "run-up on the STEP housing"

[housing]
scene = "housing.toml"
match = "position"

[drivetrain]
gearbox = "test_gearbox"

[runup]
speed_min_rpm = 500.0
speed_max_rpm = 1100.0
speed_step_rpm = 300.0
torques_nm = [2000.0]
f_max_hz = 1500.0
spectrum_speeds_rpm = [500.0]

[radiation]
models = ["erp"]
"""


def write_imported_gearbox(folder: Path, size: float = 0.06) -> Path:
    """gearbox.step, housing.toml (bores A_front, A_back, B_front, B_back) and runup.toml in `folder`; returns the
    run-up scene's path."""
    from housingfe.geometry.cad import write_step
    from housingfe.scene import load_housing_scene

    folder.mkdir(parents=True, exist_ok=True)
    write_step(load_housing_scene("test-gearbox")[0].geometry, folder / "gearbox.step")
    bores = ""
    for shaft, x in SHAFTS.items():
        for side, y in SEATS.items():
            bores += (f'\n[[geometry.bores]]\nname = "{shaft}_{side}"\naxis = [0, 1, 0]\ncentre = [{x}, {y}, 0.2]\n'
                      f"span = [-0.04, 0.04]\n")
    (folder / "housing.toml").write_text(HOUSING.format(bores=bores, size=size))
    (folder / "runup.toml").write_text(RUNUP)
    return folder / "runup.toml"
