"""The forced response checks its modal basis' zero-mode count as the modal path does (modal.structure_basis).

The case is the hard one of tests/drivetrain/test_free_housing_zero_modes.py as the forced path reaches it: the
`test-gearbox-interior` scene (gear set B's interior) on the FREE test gearbox, 60 mm mesh.  It must have 7 zero
modes: the housing's six rigid motions and the gear train's free rotation.  With the old zero-length bearings (bore
masters at the bounding boxes' centres, 0.3-0.4 mm off the shaft lines, no rigid arm) the model resists the rotations about x and y, one of the
seven comes out at 0.185 Hz, and the forced path used to count it as an elastic mode of its basis without a word.
docs/stability.md, "Hard case"."""
import json
import re
import shutil
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from housingfe.drivetrain import bore_axis
from housingfe.drivetrain import coupling as cp
from housingfe.drivetrain.interior import build_interior
from housingfe.errors import SolverError
from housingfe.response.forced import run as run_forced
from housingfe.scene import build_model_from_scene, load_housing_scene
from tests.two_ranks import module_result

FREE = ["supports=[]", "mesh.size=0.06"]
# the same message as the modal path's: 7 expected, 6 found, the resisted rotations' Rayleigh quotients (rad^2/s^2)
RESISTED = r"must have 7 rigid-body / mechanism modes, found 6: .* exact rigid motions .*: rx 2\.8\d, ry 12\.5 \("
# the old coupling: the bearing a zero-length spring between the shaft node and the bore master, and the master at
# the bounding-box centre of the coarse bore, 0.29-0.42 mm off the shaft line (now on the fitted bore axis,
# housingfe.drivetrain.bore_axis, where the old bearings strain nothing either)
OLD_BEARINGS = ("from dataclasses import replace\n"
                "from housingfe.drivetrain import bore_axis\n"
                "from housingfe.drivetrain import coupling as cp\n"
                "plain, fitted = cp.bearing, bore_axis.fit_bore\n"
                "cp.bearing = lambda a, b, K, axis, C=None, offset=None: plain(a, b, K, axis, C)\n"
                "bore_axis.fit_bore = lambda m, s: replace(fitted(m, s), centre=cp.surface_centre(m, s))\n")


@pytest.fixture(scope="module")
def free_scene(comm):
    scene, _ = load_housing_scene("test-gearbox-interior", FREE)
    return scene, build_model_from_scene(scene, comm)


def _forced(scene, model, solver):
    structure = build_interior(model, scene.coupling, scene.analysis.f_max)
    spec = scene.analysis.harmonic.model_copy(update={"solver": solver})
    return run_forced(structure, spec, scene.loads, scene.damping)


def test_free_coupled_gearbox_basis_has_its_seven_zero_modes(free_scene):
    """The fixed coupling: the forced path's basis (to 1.5 x 1000 Hz) counts exactly the 7 zero modes expected,
    the rest are elastic, and the sweep runs (TF_omega finite at every line)."""
    forced = _forced(*free_scene, "modal")
    assert forced.facts["rigid_modes_expected"] == 7
    assert forced.facts["rigid_modes"] == 7
    assert forced.facts["modes_in_basis"] >= 1
    [response] = forced.responses["modal+residual"]
    assert np.all(np.isfinite(response.extras["TF_omega_dB"]))


@pytest.mark.parametrize("solver", ["modal", "projected"])
def test_a_rigid_motion_the_model_resists_stops_the_forced_response(free_scene, monkeypatch, solver):
    """The old zero-length bearings (and bounding-box bore centres) put back: both basis solvers refuse the count (6 of 7) and name the rigid motions
    the model resists (rx 2.83, ry 12.5 rad^2/s^2 above the zero-mode limit 0.194), instead of sweeping with a
    0.185 Hz 'elastic' mode."""
    plain, fitted = cp.bearing, bore_axis.fit_bore
    monkeypatch.setattr(cp, "bearing", lambda a, b, K, axis, C=None, offset=None: plain(a, b, K, axis, C))
    monkeypatch.setattr(bore_axis, "fit_bore", lambda m, s: replace(fitted(m, s), centre=cp.surface_centre(m, s)))
    with pytest.raises(SolverError, match=RESISTED):
        _forced(*free_scene, solver)


def _cli(tmp_path, out, prelude=""):
    """`housingfe run test-gearbox-interior` on the free 60 mm housing in a process of its own (4-5 s)."""
    args = ["run", "test-gearbox-interior", "--out", str(out), *[a for s in FREE for a in ("--set", s)]]
    code = prelude + "import sys\nfrom housingfe.cli import main\nsys.exit(main(sys.argv[1:]))\n"
    return subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, timeout=300,
                          cwd=tmp_path)


def test_cli_free_coupled_gearbox_reports_its_zero_modes(tmp_path):
    """As a user runs it: exit 0, harmonic.json says 7 zero modes found of 7 expected."""
    out = tmp_path / "free"
    proc = _cli(tmp_path, out)
    assert proc.returncode == 0, proc.stderr
    facts = json.loads((out / "harmonic.json").read_text())
    assert facts["rigid_modes"] == facts["rigid_modes_expected"] == 7


def test_cli_a_wrong_zero_mode_count_is_one_line_exit_3_no_folder(tmp_path):
    """The same command with the old bearings put back in the process (no scene can build that coupling any
    more): one line `housingfe: solver error: ...` naming the resisted rotations besides the mesh-quality warning,
    exit 3, no traceback, no result folder (not even a temporary one)."""
    out = tmp_path / "free"
    proc = _cli(tmp_path, out, prelude=OLD_BEARINGS)
    assert proc.returncode == 3, proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip() and not ln.startswith("housingfe: warning:")]
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert lines[0].startswith("housingfe: solver error: ")
    assert re.search(RESISTED, lines[0]), lines[0]
    assert not out.exists() and not list(tmp_path.glob(".free*"))


def forced_summary(comm) -> dict:
    """The free coupled test gearbox's forced response (modal basis): zero-mode facts and TF_omega (dB) per line."""
    scene, _ = load_housing_scene("test-gearbox-interior", FREE)
    forced = _forced(scene, build_model_from_scene(scene, comm), "modal")
    [response] = forced.responses["modal+residual"]
    return {"ranks": comm.size, "rigid_modes": forced.facts["rigid_modes"],
            "expected": forced.facts["rigid_modes_expected"], "modes": forced.facts["modes_in_basis"],
            "tf_omega_dB": np.asarray(response.extras["TF_omega_dB"], float).ravel().tolist()}


def test_forced_zero_mode_check_on_two_ranks(comm):
    """1 and 2 MPI ranks: the forced path finds the same 7 of 7 zero modes, the same number of elastic modes in
    its basis, and the same TF_omega at every line (to 1e-6 dB)."""
    if comm.size > 1 or not shutil.which("mpirun"):
        pytest.skip("runs from a one-rank session with mpirun installed")
    one = forced_summary(comm)
    two = module_result("tests.response.test_forced_zero_modes")
    assert two["ranks"] == 2 and two["rigid_modes"] == two["expected"] == one["rigid_modes"] == 7
    assert two["modes"] == one["modes"] and len(one["tf_omega_dB"]) > 10
    assert np.allclose(two["tf_omega_dB"], one["tf_omega_dB"], rtol=0, atol=1e-6)


if __name__ == "__main__":     # mpirun -n 2 python -m tests.response.test_forced_zero_modes
    from mpi4py import MPI

    result = forced_summary(MPI.COMM_WORLD)
    if MPI.COMM_WORLD.rank == 0:
        print(json.dumps(result))
