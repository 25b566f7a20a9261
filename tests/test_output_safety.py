"""Issue 27, item 1: a result folder is the only thing an output place may replace.

Every case is hit as a user hits it: the `housingfe` console script in a subprocess on real files (the cheapest
housing scene: a coarse linear-hex box, modal analysis to 200 Hz, about a second), real `kill -9` of a process in
the middle of writing or replacing a result, two real processes into one place.  Asserted: the user's files
survive, exit 2 with one line on stderr and no traceback, the refusal comes before the computation (nothing on
stdout: the run prints its summary only after solving), and no hidden folder is left after the next run.
"""
from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

from housingfe import outputs
from housingfe.errors import InputError

HOUSINGFE = Path(sys.executable).parent / "housingfe"
TINY = """\
[scene]
name = "{name}"
kind = "housing"
description = "output-safety tests: the cheapest housing run"
[geometry]
kind = "box"
length = 0.325
width = 0.225
height = 0.125
wall_thickness = 0.008
flange_thickness = 0.015
flange_width = 0.073
[material]
name = "steel"
[mesh]
element = "hex"
degree = 1
size = 0.04
layers = 1
[analysis.modal]
f_max = 200.0
[output]
mode_pictures = 0
paraview = false
pictures = false
"""

# Writes a result of N files through atomic_output_dir, optionally sleeping inside (to be killed there).
HELPER = """\
import sys, time
from housingfe.outputs import atomic_output_dir
out, n, tag, sleep = sys.argv[1], int(sys.argv[2]), sys.argv[3], float(sys.argv[4])
with atomic_output_dir(out) as tmp:
    for i in range(n):
        (tmp / f"f{i:05d}.txt").write_text(tag)
    print("inside", flush=True)
    time.sleep(sleep)
"""


def _env() -> dict:
    return dict(os.environ, OPENBLAS_NUM_THREADS="1",
                PYTHONPATH=os.pathsep.join([str(Path(outputs.__file__).parent.parent), os.environ.get("PYTHONPATH", "")]))


def housingfe(*args, cwd: Path, prefix=(), timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run([*prefix, str(HOUSINGFE), *map(str, args)], cwd=cwd, capture_output=True, text=True,
                          timeout=timeout, env=_env(), check=False)


def assert_refused(proc: subprocess.CompletedProcess, *needles: str) -> None:
    """Exit 2, one line on stderr naming what matters, no traceback, nothing computed (no summary printed)."""
    lines = [line for line in proc.stderr.splitlines() if line.strip()]
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr
    assert len(lines) == 1 and lines[0].startswith("housingfe: error: "), lines
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
    assert "DOFs" not in proc.stdout and "wall time" not in proc.stdout, proc.stdout


def hidden(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


@pytest.fixture
def work(tmp_path) -> Path:
    (tmp_path / "tiny.toml").write_text(TINY.format(name="tiny"))
    return tmp_path


def test_a_run_writes_a_marked_result_and_replaces_its_own_result(work):
    """The normal case still works: the marker is written, a second run replaces the first run's result."""
    for f_max in (200.0, 300.0):
        proc = housingfe("run", "tiny.toml", "--set", f"analysis.modal.f_max={f_max}", cwd=work)
        assert proc.returncode == 0, proc.stderr
    marker = json.loads((work / "results" / "tiny" / outputs.MARKER).read_text())
    assert marker["complete"] is True and marker["written_by"] == "housingfe"
    assert marker["inputs"][0]["path"] == "tiny.toml" and len(marker["inputs"][0]["sha256"]) == 64
    assert json.loads((work / "results" / "tiny" / "modes.json").read_text())["f_max_hz"] == 300.0
    assert hidden(work / "results") == []


def _earlier_result(folder: Path) -> None:
    """A result folder as a run leaves it (written through the outputs API: marker included)."""
    with outputs.atomic_output_dir(folder) as tmp:
        (tmp / "modes.json").write_text("{}")


def _refusal_case(case: str, work: Path):
    """(out, words of the message, working folder, environment) of one way of pointing --out at user data."""
    elsewhere = work.parent     # a working folder that does not contain the scene's folder
    return {
        "user-folder": ("mine", "is not a housingfe result", work, {}),
        "dot": (".", "the working folder", work, {}),
        "scene-folder": (str(work), "the input file", elsewhere, {}),
        "parent-of-results": ("results", "is not a housingfe result", work, {}),
        "file": ("afile", "is a file", work, {}),
        "symlink": ("link", "symbolic link", work, {}),
        "home": (str(work), "your home folder", elsewhere, {"HOME": str(work)}),
        "under-a-file": ("afile/sub", "is a file", work, {}),
    }[case]


def _user_files(work: Path) -> list[str]:
    mine = work / "mine"
    mine.mkdir()
    (mine / "thesis.txt").write_text("precious")
    (work / "afile").write_text("precious")
    _earlier_result(work / "results" / "tiny")
    (work / "link").symlink_to(work / "results" / "tiny")
    return sorted(p.relative_to(work).as_posix() for p in work.rglob("*"))


@pytest.mark.parametrize("case", ["user-folder", "dot", "scene-folder", "parent-of-results", "file", "symlink",
                                  "home", "under-a-file"])
def test_out_that_is_not_a_result_folder_is_refused_before_any_work(case, work, capsys, monkeypatch):
    """Each of these deleted the user's files (or ran the whole computation, then crashed) before issue 27.
    In-process through the CLI's main (a subprocess each would cost seconds of imports; the console script
    is run end to end below)."""
    from housingfe import cli

    before = _user_files(work)
    out, needle, cwd, env = _refusal_case(case, work)
    monkeypatch.chdir(cwd)
    for key, value in env.items():
        monkeypatch.setenv(key, value)
    code = cli.main(["run", str(work / "tiny.toml"), "--out", out])
    captured = capsys.readouterr()
    assert_refused(subprocess.CompletedProcess([], code, captured.out, captured.err), out, needle)
    assert sorted(p.relative_to(work).as_posix() for p in work.rglob("*")) == before


@pytest.mark.parametrize("case", ["user-folder", "dot"])
def test_console_script_refuses_a_user_folder(case, work):
    before = _user_files(work)
    out, needle, cwd, _ = _refusal_case(case, work)
    assert_refused(housingfe("run", work / "tiny.toml", "--out", out, cwd=cwd), out, needle)
    assert (work / "mine" / "thesis.txt").read_text() == "precious"
    assert sorted(p.relative_to(work).as_posix() for p in work.rglob("*")) == before


def test_other_commands_refuse_a_user_folder_too(work):
    mine = work / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("precious")
    assert_refused(housingfe("source", "gearset-A", "--out", "mine", cwd=work), "mine", "not a housingfe result")
    assert_refused(housingfe("bench", "scenes", "--quick", "--out", "mine", cwd=work), "mine")
    # reduce checks the place before the model (it refused only after the reduction; tiny.toml has no bores, so a
    # later check would stop at 'no masters' instead)
    assert_refused(housingfe("reduce", "tiny.toml", "--cutoff", "2000", "--out", "mine", cwd=work), "mine",
                   "not a housingfe result")
    assert_refused(housingfe("validate", "--quick", "--results", work / "cache", "--out", "mine", cwd=work), "mine")
    assert_refused(housingfe("validate", "--quick", "--results", work / "cache", "--out", work / "cache", cwd=work),
                   "--out", "result cache")
    assert (mine / "notes.txt").read_text() == "precious"
    assert not (work / "cache").exists()


@pytest.mark.parametrize("argv, module, attr", [
    (["source-spectrum"], "housingfe.source.roosmalen.studies", "excitation_spectrum"),
    (["radiation", "foller", "builtin:scale-model"], "housingfe.radiation.foller", "foller_radiation_index"),
])
def test_spectrum_and_foller_refuse_a_user_folder_before_computing(argv, module, attr, work, capsys, monkeypatch):
    """`source-spectrum --out mine` computed for over a minute before refusing; `radiation foller --out mine`
    printed its whole table (looking like a finished run) and then refused.  Now the place is checked first: the
    computation is never reached, nothing on stdout."""
    import importlib

    from housingfe import cli

    mine = work / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("precious")

    def reached(*args, **kwargs):
        raise AssertionError(f"{attr} ran before the output place was checked")

    monkeypatch.setattr(importlib.import_module(module), attr, reached)
    monkeypatch.chdir(work)
    code = cli.main([*argv, "--out", "mine"])
    captured = capsys.readouterr()
    assert_refused(subprocess.CompletedProcess([], code, captured.out, captured.err), "mine", "not a housingfe result")
    assert not captured.out.strip(), captured.out
    assert (mine / "notes.txt").read_text() == "precious" and sorted(p.name for p in mine.iterdir()) == ["notes.txt"]


@pytest.mark.parametrize("name", ["", "  ", ".", "..", "../escaped", "a/b", ".hidden", "back\\\\slash"])
def test_empty_or_path_like_scene_name_is_refused(name, work, capsys, monkeypatch):
    """name = "" used to make results/ itself the output (every earlier result deleted), "../x" a place outside.
    (In-process: the console script path is the same as above.)"""
    from housingfe import cli

    earlier = work / "results" / "earlier"
    earlier.mkdir(parents=True)
    (earlier / outputs.MARKER).write_text("{}")
    (work / "named.toml").write_text(TINY.format(name=name))
    monkeypatch.chdir(work)
    code = cli.main(["run", "named.toml"])
    captured = capsys.readouterr()
    assert_refused(subprocess.CompletedProcess([], code, captured.out, captured.err), "named.toml: scene.name:")
    assert sorted(p.name for p in work.iterdir()) == ["named.toml", "results", "tiny.toml"]
    assert [p.name for p in (work / "results").iterdir()] == ["earlier"]


def test_source_scene_with_a_path_like_name_is_refused(work):
    text = (Path(outputs.__file__).parent / "scenes" / "gearset-A.toml").read_text()
    assert 'name = "gearset-A"' in text
    (work / "g.toml").write_text(text.replace('name = "gearset-A"', 'name = "../g"'))
    assert_refused(housingfe("source", "g.toml", cwd=work), "g.toml: scene.name:")
    assert not (work / "results").exists() and not (work.parent / "g").exists()


def test_read_only_folder_is_refused_before_the_computation():
    """Checked by really creating a folder there (root ignores permission bits, so run as nobody when root)."""
    prefix = ()
    if os.geteuid() == 0:
        if shutil.which("setpriv") is None:
            pytest.skip("root without setpriv: cannot drop to an unprivileged user")
        prefix = ("setpriv", "--reuid=nobody", "--regid=nogroup", "--clear-groups")
    base = Path(tempfile.mkdtemp(prefix="housingfe-ro-"))
    try:
        base.chmod(0o777)
        (base / "tiny.toml").write_text(TINY.format(name="tiny"))
        (base / "tiny.toml").chmod(0o644)
        locked = base / "locked"
        locked.mkdir()
        locked.chmod(0o555)
        proc = housingfe("run", "tiny.toml", "--out", "locked/box", cwd=base, prefix=(*prefix, "env", f"HOME={base}"))
        assert_refused(proc, "locked/box", "cannot write in", "Permission denied")
        assert list(locked.iterdir()) == []
    finally:
        (base / "locked").chmod(0o755)
        shutil.rmtree(base)


def _helper(tmp_path: Path, out: str, n: int, tag: str, sleep: float = 0.0, wait: bool = True):
    script = tmp_path / "helper.py"
    script.write_text(HELPER)
    args = [sys.executable, str(script), out, str(n), tag, str(sleep)]
    if wait:
        return subprocess.run(args, cwd=tmp_path, env=_env(), capture_output=True, text=True, check=True)
    return subprocess.Popen(args, cwd=tmp_path, env=_env(), stdout=subprocess.PIPE, text=True)


def _complete_result(folder: Path) -> str | None:
    """The tag of a complete helper result in folder (the marker and all files of one version), else None."""
    files = [p for p in folder.iterdir() if p.name != outputs.MARKER]
    tags = {p.read_text() for p in files}
    if not (folder / outputs.MARKER).is_file() or len(tags) != 1:
        return None
    tag = tags.pop()
    return tag if len(files) == {"old": 4000, "new": 10}[tag] else None


def test_kill_9_during_the_replacement_of_a_large_result_never_loses_a_complete_result(tmp_path):
    """The old result (4000 files) is replaced by a new one (10 files) and the writer is killed with SIGKILL at
    several moments, once while the old folder is being deleted.  Before issue 27 the old files were partly
    deleted and the new result hidden in .tmp.  Now the name holds a complete result (old or new) at every
    moment, except between the two renames when both complete ones are beside it; the next run cleans up."""
    out = tmp_path / "big"
    seen_aside = False
    for attempt in range(3):
        shutil.rmtree(out, ignore_errors=True)
        _helper(tmp_path, "big", 4000, "old")
        proc = _helper(tmp_path, "big", 10, "new", wait=False)
        if attempt == 0:        # the moment the old result is being deleted
            deadline = time.monotonic() + 20
            while not list(tmp_path.glob(".big.old-*")) and proc.poll() is None and time.monotonic() < deadline:
                time.sleep(0.0005)
            seen_aside = bool(list(tmp_path.glob(".big.old-*")))
        else:                   # after the "inside" line, or a little later
            assert proc.stdout.readline().strip() == "inside"
            time.sleep(0.002 * (attempt - 1))
        proc.kill()
        proc.wait()
        proc.stdout.close()
        if out.is_dir():
            assert _complete_result(out) in ("old", "new")
        else:                   # between the two renames: both complete, hidden beside the name
            # .big.old-PID (the old result set aside) and .big.tmp-PID (the new one), in any name order
            assert sorted(_complete_result(p) for p in tmp_path.glob(".big.*-*")) == ["new", "old"]
        _helper(tmp_path, "big", 10, "new")        # the next run into the same place
        assert _complete_result(out) == "new"
        assert hidden(tmp_path) == [], f"attempt {attempt}"
    assert seen_aside, "never saw the old result set aside: the kill did not land during its deletion"


def test_stale_temporary_folder_of_a_killed_run_is_removed_by_the_next_run(tmp_path):
    proc = _helper(tmp_path, "res", 5, "new", sleep=60, wait=False)
    assert proc.stdout.readline().strip() == "inside"
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    proc.stdout.close()
    assert f".res.tmp-{proc.pid}" in hidden(tmp_path)
    (tmp_path / "tiny.toml").write_text(TINY.format(name="tiny"))
    done = housingfe("run", "tiny.toml", "--out", "res", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert hidden(tmp_path) == []
    assert (tmp_path / "res" / "modes.json").is_file()


def test_a_run_killed_between_its_two_renames_is_recovered_by_the_next_run(tmp_path):
    """The instant between `old -> .old-PID` and `.tmp-PID -> name`: no folder under the name, both results
    complete beside it.  The next run into the place first puts the new one (it has the marker) in place; if
    that run then fails before writing, the user still has the newest complete result."""
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    for kind, tag in (("old", "old"), ("tmp", "new")):
        folder = tmp_path / f".res.{kind}-{dead.pid}"
        folder.mkdir()
        (folder / "f.txt").write_text(tag)
        (folder / outputs.MARKER).write_text("{}")
    outputs.reserve_output(tmp_path / "res")
    outputs.release_output(tmp_path / "res")
    assert (tmp_path / "res" / "f.txt").read_text() == "new"
    assert hidden(tmp_path) == []


def test_second_run_into_a_busy_place_is_refused_naming_the_holder(work):
    """Before issue 27 both runs reported success and one result was silently discarded."""
    holder = _helper(work, "busy", 3, "first", sleep=60, wait=False)
    try:
        assert holder.stdout.readline().strip() == "inside"
        proc = housingfe("run", "tiny.toml", "--out", "busy", cwd=work)
        assert_refused(proc, "busy", f"PID {holder.pid}", "another housingfe run")
    finally:
        holder.kill()
        holder.wait()
        holder.stdout.close()
    again = housingfe("run", "tiny.toml", "--out", "busy", cwd=work)    # the holder died: the place is free
    assert again.returncode == 0, again.stderr
    assert hidden(work) == []


def test_two_ranks_refuse_a_user_folder(work):
    """Rank 0 decides and every rank stops with the same message (exit 2).  (A good place on 2 ranks is the
    normal MPI run of the other tests of the package.)"""
    if shutil.which("mpirun") is None:
        pytest.skip("no mpirun")
    mine = work / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("precious")
    mpi = ("mpirun", "-n", "2", "--allow-run-as-root", "--oversubscribe", "-x", "PYTHONPATH", "-x",
           "OPENBLAS_NUM_THREADS")
    proc = housingfe("run", "tiny.toml", "--out", "mine", cwd=work, prefix=mpi)
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr and "DOFs" not in proc.stdout
    lines = [line for line in proc.stderr.splitlines() if line.startswith("housingfe: error:")]
    assert len(lines) in (1, 2) and len(set(lines)) == 1 and "not a housingfe result" in lines[0], proc.stderr
    assert [p.name for p in mine.iterdir()] == ["notes.txt"] and hidden(work) == []


def test_check_output_place_accepts_results_and_empty_folders(tmp_path):
    """What may be replaced: nothing there, an empty folder, a marked result, a result validate stamped before
    the marker existed, a folder of a command's own files (validate's two tables)."""
    empty = tmp_path / "empty"
    empty.mkdir()
    marked = tmp_path / "marked"
    marked.mkdir()
    (marked / outputs.MARKER).write_text("{}")
    (marked / "modes.json").write_text("{}")
    stamped = tmp_path / "stamped"
    stamped.mkdir()
    (stamped / ".validate-key").write_text("{}")
    tables = tmp_path / "tables"
    tables.mkdir()
    (tables / "validate.csv").write_text("")
    for folder in (tmp_path / "absent", empty, marked, stamped):
        outputs.check_output_place(folder)
    outputs.check_output_place(tables, own_files=("validate.csv", "validate.md"))
    with pytest.raises(InputError, match="not a housingfe result"):
        outputs.check_output_place(tables)
    (tables / "mine.txt").write_text("")
    with pytest.raises(InputError, match="not a housingfe result"):
        outputs.check_output_place(tables, own_files=("validate.csv", "validate.md"))
    with pytest.raises(InputError, match="input file"):
        outputs.check_output_place(marked, inputs=[marked / "modes.json"])


# ---------------------------------------------------------------- commands that write single files (the CLI sweep)
NIST_STEP = Path(__file__).parent / "geometry" / "data" / "nist_ftc_06_asme1_rd.stp"


def test_inspect_keeps_an_edited_scene_skeleton(tmp_path):
    """`housingfe inspect part.stp` writes part-scene.toml beside the part for the user to edit; a second inspect
    replaced the edited scene without a word.  Now it is refused (the picture is not written either), and an
    unedited skeleton from the same inputs is still rewritten."""
    shutil.copy(NIST_STEP, tmp_path / "part.stp")
    first = housingfe("inspect", "part.stp", "--no-picture", cwd=tmp_path)
    assert first.returncode == 0, first.stderr
    again = housingfe("inspect", "part.stp", "--no-picture", cwd=tmp_path)     # unedited: same text, allowed
    assert again.returncode == 0, again.stderr
    skeleton = tmp_path / "part-scene.toml"
    edited = skeleton.read_text().replace('element = "tet"', 'element = "tet"   # mine')
    skeleton.write_text(edited)
    assert_refused(housingfe("inspect", "part.stp", cwd=tmp_path), "part-scene.toml", "does not overwrite")
    assert skeleton.read_text() == edited
    assert not (tmp_path / "part-inspect.png").exists()


@pytest.mark.parametrize("case", ["out-is-a-file", "out-under-a-file", "cad-file-is-a-folder"])
def test_inspect_refuses_a_file_as_its_folder_before_reading(case, tmp_path):
    """A file given as --out (or a folder under one) was a FileExistsError / NotADirectoryError traceback after
    the CAD file was read; a folder named like a CAD file was 'no such file'."""
    shutil.copy(NIST_STEP, tmp_path / "part.stp")
    (tmp_path / "afile").write_text("precious")
    (tmp_path / "folder.stp").mkdir()
    args, needles = {"out-is-a-file": (["part.stp", "--out", "afile"], ["afile", "is a file, not a folder"]),
                     "out-under-a-file": (["part.stp", "--out", "afile/sub"], ["afile/sub", "is a file"]),
                     "cad-file-is-a-folder": (["folder.stp"], ["folder.stp", "is a folder, not a CAD file"])}[case]
    assert_refused(housingfe("inspect", *args, cwd=tmp_path), *needles)
    assert (tmp_path / "afile").read_text() == "precious"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile", "folder.stp", "part.stp"]


def test_foller_default_folder_is_named_after_the_table_not_its_path(tmp_path):
    """`housingfe radiation foller tables/box.toml` wrote results/radiation-foller-tables/box/ (the path pasted
    into the folder name; an absolute path gave results/radiation-foller-/home/...)."""
    (tmp_path / "tables").mkdir()
    (tmp_path / "tables" / "box.toml").write_text(
        'plates = [{name = "side", count = 4, area_m2 = 0.06, perimeter_m = 1.0, thickness_m = 0.008, '
        'fc_hz = 1500.0}]\n')
    proc = housingfe("radiation", "foller", "tables/box.toml", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert [p.name for p in (tmp_path / "results").iterdir()] == ["radiation-foller-box"]
    assert (tmp_path / "results" / "radiation-foller-box" / "foller.csv").is_file()
