"""Identify the lost Sec. 4.2 box from the thesis' published numbers (issue 15).

Fig. 4.2, the drawing of van Roosmalen's welded box, is lost; the thesis prints only a few numbers about it:
its mass (24.5 kg), the first elastic mode of the free box (641 Hz), the number of modes below 4 kHz free
(35) and bolted on its flange (29, BC 3), the number below 2 kHz of two boxes bolted together (24) and a close
pair of the bolted box (1167/1176 Hz).  `examples/correlate_box.toml` lets the box's length, width, height and
flange width (plates 8 mm, flange 15 mm: given) fit the first four numbers and holds the last two out.

Each model evaluation builds the box scenes through the scene API with the parameters as overrides
(`load_housing_scene(name, overrides)`, `build_model_from_scene`) and solves their modes
(`solvers.modal.modes`); a mode *count* is an integer, so the fit uses a smooth surrogate, the position of
the band edge between mode N and N + 1.  The search runs on coarse meshes whose frequencies are corrected to
the scenes' own meshes (ratios at the start and at the answer), and the answer is confirmed on them.

    .venv/bin/python examples/correlate_box.py [--small] [--out DIR]

--small fits the height alone to mass and first mode on coarse meshes (about a minute; at most 4 evaluations
per fit, which reach the answer 8 gave: height 0.12627 m); the full study is
`housingfe update examples/correlate_box.toml` (three starts, about 30-40 minutes on one core;
docs/correlation.md).
"""
from __future__ import annotations

import argparse
from pathlib import Path

from mpi4py import MPI

from housingfe.correlation.updating import load_update_spec, run_update
from housingfe.scene import build_model_from_scene, load_housing_scene
from housingfe.solvers.modal import modes

OUTPUTS = ("update.json", "history.csv", "targets.csv", "convergence.png")

# %% the update spec: parameters with bounds, calibration and held-out targets, search and confirmation meshes
parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--small", action="store_true", help="height only, mass and first mode, coarse meshes")
parser.add_argument("--out", default=None, help="write update.json, history.csv, targets.csv, convergence.png")
args = parser.parse_args()

spec = load_update_spec(str(Path(__file__).with_name("correlate_box.toml")))
if args.small:
    spec = spec.model_copy(update={
        "parameters": [p for p in spec.parameters if p.name == "height"],
        "targets": [t for t in spec.targets if t.kind in ("mass", "frequency")],
        "search_overrides": {"box-free": ["mesh.size=0.06"]},
        "confirm_overrides": {"box-free": ["mesh.size=0.045"]},
        "multistart": [], "max_evaluations": 4})

# %% the fit: prints the targets before and after, the parameters with their standard deviations
summary = run_update(spec, args.out)

# %% the identified box as a model of the stage API: its lowest elastic modes on the confirmation mesh
overrides = [f"{key}={value!r}" for p, value in zip(spec.parameters, summary["identified"]) for key in p.keys]
overrides += spec.confirm_overrides.get("box-free", [])
model = build_model_from_scene(load_housing_scene("box-free", overrides)[0], MPI.COMM_WORLD)
basis = modes(model, 1500.0)
print("identified box, free-free: " + ", ".join(f"{f:.0f}" for f in basis.frequencies_hz[basis.rigid_count:])
      + " Hz below 1.5 kHz")
