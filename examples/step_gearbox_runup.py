"""# From a STEP file to L_WA over speed: the noise chain on an imported housing

A housing from the design office arrives as STEP.  This example takes one through the whole chain:

1. the STEP file: here the package's own test gearbox housing written by its gmsh/OpenCASCADE model
   (`write_step`, in metres), so that the answer can be compared with the built-in housing's; a user starts with
   her own file instead;
2. what is in it: the file read as `housingfe inspect` reads it (`read_cad`); the candidate bores are the concave
   cylindrical faces grouped by axis (`bore_candidates`): two axis lines, each running through both bearing
   plates;
3. a housing scene (`kind = "cad"`): one bore selector per bearing seat — the axis line, a point on it and
   `span`, the part of the line that seat occupies (here the half of the through-bore in one bearing plate) —
   the feet by box selectors, fixed to a rigid base;
4. a run-up scene whose `[housing]` is that scene, with `match = "position"`: each bearing of the drivetrain
   description (`test_gearbox`: two shafts along y, a front and a back bearing each) finds the one selected bore
   whose axis runs along its shaft and which holds it, and is checked against it (the bore's cylinder fitted on the
   FE mesh: axis within 1 degree, centre within `bore_tolerance` = 1 mm of the shaft's axis);
5. `run_scene`: the coupled gearbox (housing + shafts, gears, bearings), its modal basis, the source over speed,
   L_v, L_W and L_WA per speed (`runup.csv`), exactly as `housingfe run test-gearbox-runup` on the built-in.

Units: SI inside (m, Hz, N m); the STEP file's numbers are metres here (`units = "m"`: gmsh writes a model's raw
numbers), a CAD program's STEP is millimetres (`units = "mm"`); selectors are in metres whatever the file's unit.

Run:  .venv/bin/python examples/step_gearbox_runup.py [--small] [--out DIR]
(--small: a 60 mm mesh, lines to 1.5 kHz and 3 speeds, about 15 s; the full run: lines to 4 kHz, 50-1500 rev/min
in 50 rev/min steps, minutes.)  The commands a user types for the same: docs/cad.md, "From a STEP file to L_WA".
"""
# %%
from __future__ import annotations

import argparse
import csv
import shutil
import tempfile
from pathlib import Path

from housingfe.geometry.cad import gmsh_session, read_cad, write_step
from housingfe.geometry.selectors import bore_candidates
from housingfe.outputs import atomic_output_dir, format_table
from housingfe.runup.scene import run_scene
from housingfe.scene import load_housing_scene

OUTPUTS = ("gearbox.step", "housing.toml", "runup-scene.toml", "runup.csv", "runup.json", "runup.png")


# %% [markdown]
# ## 1-2. The STEP file and what is in it
# The built-in test gearbox housing (10 mm walls, 65 mm bearing plates, two 170 mm through-bores, feet) written
# to STEP; read back, its bores are found on the cylinders the file holds.

# %%
def step_file(folder: Path) -> Path:
    return write_step(load_housing_scene("test-gearbox")[0].geometry, folder / "gearbox.step")


def bore_selectors(step: Path) -> str:
    """[[geometry.bores]] tables: per candidate bore (ordered along x: shaft A, then B) a front and a back seat,
    each the half of the through-bore on its side of the bore's middle (`span`, m along the axis)."""
    with gmsh_session():
        facts = read_cad(step, "m")
    bores = sorted(bore_candidates(facts.faces, 1e-4), key=lambda b: b["centre"][0])
    text = ""
    for shaft, bore in zip("AB", bores):
        half = bore["length"] / 2
        print(f"bore {shaft}: centre {[round(float(x), 4) + 0.0 for x in bore['centre']]} m, axis "
              f"{[round(float(x), 3) + 0.0 for x in bore['axis']]}, radius {bore['radius'] * 1e3:.1f} mm, length "
              f"{bore['length'] * 1e3:.0f} mm")
        for side, span in (("front", (-half, 0.0)), ("back", (0.0, half))):
            text += (f"\n[[geometry.bores]]\nname = \"{shaft}_{side}\"\n"
                     f"axis = [{', '.join(f'{x:.6g}' for x in bore['axis'])}]\n"
                     f"centre = [{', '.join(f'{x:.6g}' for x in bore['centre'])}]\n"
                     f"span = [{span[0]:.6g}, {span[1]:.6g}]\n")
    return text


# %% [markdown]
# ## 3-4. The housing scene and the run-up scene
# The feet's undersides by boxes (the flat faces at z = 0 outside the side walls); the radiating surface is the
# outer skin the import finds.  The run-up scene names the housing scene by its file (relative to itself).

# %%
HOUSING = """[scene]
name = "step-gearbox"
kind = "housing"
description = "the test gearbox housing from STEP, feet fixed to a rigid base"

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
{size}
[[supports]]
surface = "foot_front"
kind = "fixed"

[[supports]]
surface = "foot_back"
kind = "fixed"

[analysis.modal]
f_max = {f_max}
"""

RUNUP = """[scene]
name = "step-gearbox-runup"
kind = "runup"
description = "gear set A, ball bearings, 2000 N m on the housing imported from STEP"

[housing]
scene = "housing.toml"
match = "position"          # each bearing finds the selected bore on its shaft that holds it
bore_tolerance = 0.001      # m: a bore centre farther off its shaft's axis is an error

[drivetrain]
gearbox = "test_gearbox"
gear_set = "A"
bearings = "ball"

[runup]
speed_min_rpm = {speed_min}
speed_max_rpm = {speed_max}
speed_step_rpm = {speed_step}
torques_nm = [2000.0]
f_max_hz = {f_max}
spectrum_speeds_rpm = [{spectrum}]

[radiation]
models = ["erp"]
"""


# %% [markdown]
# ## 5. The run-up

# %%
def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0].lstrip("# "))
    parser.add_argument("--small", action="store_true", help="60 mm mesh, lines to 1.5 kHz, 3 speeds")
    parser.add_argument("--out", default=None, help="folder for the STEP file, the scenes and the run-up results")
    args = parser.parse_args(argv)

    f_max, speed_min, speed_step = (1500.0, 900.0, 300.0) if args.small else (4000.0, 50.0, 50.0)
    work = Path(tempfile.mkdtemp(prefix="step-gearbox-"))
    try:
        step = step_file(work)
        (work / "housing.toml").write_text(HOUSING.format(
            bores=bore_selectors(step), f_max=f_max, size="size = 0.06\n" if args.small else ""))
        (work / "runup-scene.toml").write_text(RUNUP.format(
            speed_min=speed_min, speed_max=1500.0, speed_step=speed_step, f_max=f_max, spectrum=f"{speed_min:g}.0"))
        results = run_scene(str(work / "runup-scene.toml"), out_dir=str(work / "results"))

        with open(results / "runup.csv") as fh:
            rows = [r for r in csv.DictReader(fh) if r["radiation"] == "erp"]
        table = [[r["route"], float(r["speed_rpm"]), float(r["Lv_dB"]), float(r["LwA_dB"])] for r in rows]
        print(format_table(["route", "speed_rpm", "Lv_dB", "LwA_dBA"], table, floatfmt="{:.1f}"))
        for route in ("tf_omega", "mesh_force"):
            best = max((r for r in table if r[0] == route), key=lambda r: r[3])
            print(f"{route}: max L_WA {best[3]:.1f} dB(A) at {best[1]:g} rev/min (imported housing)")

        if args.out:
            with atomic_output_dir(args.out) as tmp:
                for name in OUTPUTS:
                    source = results / name if (results / name).exists() else work / name
                    shutil.copy(source, tmp / name)
            for name in OUTPUTS:
                print(f"wrote {args.out}/{name}")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
