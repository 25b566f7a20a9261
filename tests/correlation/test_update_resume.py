"""`housingfe update` as a user meets a long one: progress lines in a log (count, elapsed, estimate), and a run
killed with SIGKILL part-way resumes from the checkpoint <out>.partial/evaluations.jsonl on a re-run of the same
command, with fewer new scene solves and the very same answer as an uninterrupted run (issue 27, item 4).
The problem: a free steel plate's modulus and thickness from two frequencies and the mass (~0.1 s per solve)."""
import json
import os
import re
import signal
import subprocess
import sys

import pytest

from tests.correlation.free_plate import PLATE_SCENE
from tests.interrupt import interruptible

SPEC = """
name = "plate"
max_evaluations = 20
[[parameters]]
name = "E"
keys = ["material.youngs_modulus"]
lower = 150e9
upper = 260e9
start = 210e9
[[parameters]]
name = "h"
keys = ["geometry.h"]
lower = 0.004
upper = 0.0065
start = 0.005
[[targets]]
name = "f1"
scene = "plate.toml"
kind = "frequency"
mode = 1
value = 150.0
[[targets]]
name = "f3"
scene = "plate.toml"
kind = "frequency"
mode = 3
value = 400.0
[[targets]]
name = "mass"
scene = "plate.toml"
kind = "mass"
value = 4.9
"""
PROGRESS = re.compile(r"^update start 1/1: (\d+)/<=20 evaluations, (\d+:\d\d) elapsed")


def _env():
    return {**os.environ, "HOUSINGFE_PROGRESS_SECONDS": "0", "OPENBLAS_NUM_THREADS": "1"}


def _update(folder, out, *extra):
    return [sys.executable, "-m", "housingfe", "update", str(folder / "spec.toml"), "--out", str(out), *extra]


def _start_update(folder, out, stdout=subprocess.DEVNULL):
    """`housingfe update` of folder/spec.toml into `out`, running in the background with its stderr piped."""
    return subprocess.Popen(_update(folder, out), stdout=stdout, stderr=subprocess.PIPE, text=True, env=_env(),
                            cwd=folder, preexec_fn=interruptible)


def _progress_reached(proc, evaluations) -> bool:
    """Read the running update's progress lines until one counts `evaluations`; False if it ended before."""
    for line in proc.stderr:
        m = PROGRESS.match(line)
        if m and int(m.group(1)) >= evaluations:
            return True
    return False


@pytest.fixture(scope="module")
def problem(tmp_path_factory):
    """The spec and scene, and the answer of an uninterrupted run (its stderr too)."""
    folder = tmp_path_factory.mktemp("update")
    (folder / "plate.toml").write_text(PLATE_SCENE)
    (folder / "spec.toml").write_text(SPEC)
    proc = subprocess.run(_update(folder, folder / "whole"), capture_output=True, text=True, env=_env(),
                          cwd=folder, timeout=120)
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((folder / "whole" / "update.json").read_text())
    return folder, summary, proc


def test_progress_lines_in_a_log(problem):
    """stderr is a pipe: plain lines (no carriage returns), one per evaluation here, with count, elapsed time and
    the estimate; the checkpoint of a finished run is gone."""
    folder, summary, proc = problem
    lines = [m for m in map(PROGRESS.match, proc.stderr.splitlines()) if m]
    assert [int(m.group(1)) for m in lines] == list(range(1, len(lines) + 1))
    assert len(lines) == 20 <= summary["fits"][0]["evaluations"]      # the budget spent (then the final Jacobian)
    assert "\r" not in proc.stderr
    # the first two evaluations re-use the setup's solve (the start point): no estimate until one solved something
    assert "left" not in lines[0].string and "left" in lines[2].string
    # the setup's scene solve (no mesh correction here: one scene, one mesh) is counted too
    assert proc.stderr.startswith("update setup: 1/<=1 scene solves, 0:")
    assert not (folder / "whole.partial").exists()
    assert "results: " in proc.stdout and str(folder / "whole") in proc.stdout


def test_killed_update_resumes_with_the_same_answer(problem):
    folder, whole, _ = problem
    out = folder / "killed"
    checkpoint = folder / "killed.partial" / "evaluations.jsonl"
    proc = _start_update(folder, out)
    assert _progress_reached(proc, 8)
    proc.send_signal(signal.SIGKILL)
    assert proc.wait(timeout=60) == -signal.SIGKILL
    assert not out.exists()                             # no result folder that looks complete
    finished = checkpoint.read_text().count("\n") - 1   # header line
    assert finished >= 4
    with open(checkpoint, "a") as fh:                   # a record cut by the kill: ignored and cut off
        fh.write('{"key": ["plate.toml", [2.1e11')
    proc = subprocess.run(_update(folder, out), capture_output=True, text=True, env=_env(), cwd=folder, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert f"resuming: {finished} evaluations (scene solves) from {checkpoint}" in proc.stdout
    resumed = json.loads((out / "update.json").read_text())
    assert resumed["scene_solves_resumed"] == finished
    assert resumed["scene_solves"] == whole["scene_solves"]      # the same path: the fresh solves were only the rest
    assert resumed["identified"] == whole["identified"]          # bit for bit
    assert resumed["after"] == whole["after"] and resumed["std"] == whole["std"]
    assert not checkpoint.parent.exists()


def test_checkpoint_of_other_inputs_is_not_used(problem, tmp_path):
    """A checkpoint left by a spec with another target value is not re-used (nor is one with --no-resume)."""
    folder, whole, _ = problem
    import shutil

    for name in ("plate.toml", "spec.toml"):
        shutil.copy(folder / name, tmp_path / name)
    out = tmp_path / "out"
    # An evaluation takes ~0.1-0.2 s: the signal comes during the 2nd-3rd of 20.  (Two CI dry runs failed here with
    # exit 0 after all 20 evaluations: they ran with SIGINT ignored, inherited from the background shell that
    # started them, not a race of the pipe -- _interruptible.)
    proc = _start_update(tmp_path, out)
    assert _progress_reached(proc, 1)
    proc.send_signal(signal.SIGINT)
    rest = proc.stderr.read()
    code = proc.wait(timeout=60)
    assert code == 130, rest
    checkpoint = tmp_path / "out.partial" / "evaluations.jsonl"
    assert not out.exists() and checkpoint.is_file()
    kept = checkpoint.read_text().count("\n") - 1
    assert f"housingfe update: {kept} finished evaluation(s) kept in {checkpoint}; the same command resumes" in rest
    (tmp_path / "spec.toml").write_text(SPEC.replace("value = 400.0", "value = 410.0"))
    proc = subprocess.run(_update(tmp_path, out, "--no-resume"), capture_output=True, text=True, env=_env(),
                          cwd=tmp_path, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "resuming" not in proc.stdout and "starting afresh" in proc.stdout
    assert json.loads((out / "update.json").read_text())["scene_solves_resumed"] == 0


def test_second_run_on_the_same_checkpoint_stops_before_work(problem, tmp_path):
    """Two updates into one --out at once: the second finds the first's checkpoint locked and stops with one line,
    exit 2; the first finishes with the uninterrupted answer."""
    folder, whole, _ = problem
    out = tmp_path / "out"
    first = _start_update(folder, out, stdout=subprocess.PIPE)
    assert _progress_reached(first, 2)
    second = subprocess.run(_update(folder, out), capture_output=True, text=True, env=_env(), cwd=folder,
                            timeout=120)
    first.stderr.read()
    assert first.wait(timeout=120) == 0
    assert second.returncode == 2
    # the output folder's reservation (housingfe.outputs) stops it first, before it reads the checkpoint
    assert re.fullmatch(rf"housingfe: error: {re.escape(str(out))}: output folder: another housingfe run \(PID "
                        rf"{first.pid}\) is writing it; wait for it to finish or choose another --out\n", second.stderr)
    assert json.loads((out / "update.json").read_text())["identified"] == whole["identified"]
