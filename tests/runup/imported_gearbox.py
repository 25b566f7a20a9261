"""The built-in test gearbox housing written to STEP and described by a `cad` housing scene with one bore selector
per bearing seat and the feet by boxes, plus a run-up scene on it (shared by the bore-matching and run-up tests).

The steps and the scene text are those of examples/step_gearbox_runup.py (a literate example keeps them in place;
this helper loads the example by its path, as tests/test_examples.py finds the examples), here on a coarse mesh,
lines to 1.5 kHz and 500/800/1100 rev/min."""
from __future__ import annotations

import functools
import importlib.util
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "step_gearbox_runup.py"
F_MAX = 1500.0      # Hz: the housing's modes and the run-up's lines


@functools.cache
def example():
    """The example module (examples/ is no package: loaded from its file)."""
    spec = importlib.util.spec_from_file_location("examples_step_gearbox_runup", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def write_imported_gearbox(folder: Path, size: float = 0.06) -> Path:
    """gearbox.step, housing.toml (bores A_front, A_back, B_front, B_back: each the half of a through-bore in one
    bearing plate, from the STEP file's candidates) and runup.toml in `folder`; returns the run-up scene's path.
    size: the tetrahedra's size (m)."""
    ex = example()
    folder.mkdir(parents=True, exist_ok=True)
    step = ex.step_file(folder)
    (folder / "housing.toml").write_text(ex.HOUSING.format(bores=ex.bore_selectors(step), f_max=F_MAX,
                                                           size=f"size = {size}\n"))
    (folder / "runup.toml").write_text(ex.RUNUP.format(speed_min=500.0, speed_max=1100.0, speed_step=300.0,
                                                       f_max=F_MAX, spectrum="500.0"))
    return folder / "runup.toml"
