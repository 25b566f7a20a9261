"""`housingfe update` / `housingfe correlate` bad input: one line naming the file and key, exit 2 (no FE); the
exported modes the same on 1 and 2 MPI ranks, signs included."""
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from housingfe.cli import main

SPEC = """
name = "t"
[[parameters]]
name = "h"
keys = ["geometry.height"]
lower = 0.1
upper = 0.3
start = 0.2
[[targets]]
name = "m"
scene = "box-free"
kind = "mass"
value = 24.5
"""


@pytest.mark.parametrize("edit,message", [
    (lambda s: s.replace('keys = ["geometry.height"]', 'keys = ["geometry.heigth"]'),
     "geometry.heigth: unknown parameter key"),
    (lambda s: s.replace("start = 0.2", "start = 0.5"), "parameters.0.start: must lie within [lower, upper]"),
    (lambda s: s.replace('kind = "mass"', 'kind = "count"'), "targets.0.band_hz: required for a count target"),
    (lambda s: s + "colour = 1\n", "colour: unknown key"),
    (lambda s: s.replace('kind = "mass"', 'kind = "count"\nband_hz = 4000.0').replace("value = 24.5", "value = 0"),
     "targets.0.value: a mode count is a whole number >= 1"),
    (lambda s: s.replace('scene = "box-free"', 'scene = "no-such-scene"'), "no-such-scene: no such scene"),
])
def test_update_bad_spec_is_one_line(tmp_path, capsys, edit, message):
    path = tmp_path / "spec.toml"
    path.write_text(edit(SPEC))
    assert main(["update", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and message in err, err
    assert not (tmp_path / "out").exists()


def test_correlate_needs_one_of_measured_or_export(capsys):
    assert main(["correlate", "box-free"]) == 2
    assert "exactly one of --measured" in capsys.readouterr().err


def test_correlate_unreadable_measured_file(tmp_path, capsys):
    bad = tmp_path / "ema.uff"
    bad.write_text("not a universal file\n")
    assert main(["correlate", "box-free", "--measured", str(bad), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(bad) in err


@pytest.mark.mpi
def test_exported_mode_shapes_are_the_same_on_one_and_two_ranks(tmp_path):
    """An eigenvector's sign is the solver's choice and its start vectors depend on the partition: the exported
    shapes of 1 and 2 ranks had opposite signs in 21 of the 36 modes of box-free (its own mesh).  With the modes
    oriented (housingfe.solvers.modal.orient_modes) the files agree, sign included."""
    from housingfe.correlation.uff import read_uff

    if not shutil.which("mpirun"):
        pytest.skip("mpirun not installed")
    env = {**os.environ, "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OPENBLAS_NUM_THREADS": "1", "PYTHONPATH": str(Path(__file__).resolve().parents[2])}
    args = [sys.executable, "-m", "housingfe", "correlate", "box-free", "--set", "mesh.size=0.04", "--set",
            "mesh.degree=2", "--f-max", "2500", "--points", "12", "--export"]
    shapes = []
    for ranks in (1, 2):
        path = tmp_path / f"ours-{ranks}.uff"
        launcher = [shutil.which("mpirun"), "-n", "2", "--oversubscribe"] if ranks == 2 else []
        proc = subprocess.run(launcher + args + [str(path)], capture_output=True, text=True, env=env, timeout=300)
        assert proc.returncode == 0, proc.stderr[-2000:]
        assert proc.stdout.count("written ") == 1
        shapes.append(read_uff(path).modes.shapes)
    one, two = shapes
    assert one.shape == two.shape and one.shape[1] >= 10
    # each mode against itself (a mode of a repeated frequency may turn within its pair: none below 2.5 kHz here)
    assert np.abs(one - two).max() < 1e-6 * np.abs(one).max()
