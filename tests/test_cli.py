"""The command line as a user meets it: bad input gives one clear line and exit code 2, no traceback,
no result folder; a good run writes a complete folder; 1 and 2 MPI ranks agree."""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from housingfe.scenefile import SCENE_DIR

BOX = (SCENE_DIR / "box-free.toml").read_text()
FAST = ["--set", "mesh.degree=2", "--set", "mesh.size=0.04", "--set", "analysis.modal.f_max=2500.0", "--set", "output.pictures=false"]


def housingfe(*args, cwd=None, mpi_ranks=None):
    cmd = [sys.executable, "-m", "housingfe", *args]
    if mpi_ranks:
        cmd = [shutil.which("mpirun") or "mpirun", "-n", str(mpi_ranks), *cmd]
    env = {**os.environ, "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OPENBLAS_NUM_THREADS": "1"}
    return subprocess.run(cmd, capture_output=True, text=True, cwd=cwd, env=env, timeout=300)


BAD_SCENES = {
    "unknown_key": (BOX.replace("length = 0.325", "lenght = 0.325"), "geometry.lenght: unknown key"),
    "negative_thickness": (BOX.replace("wall_thickness = 0.008", "wall_thickness = -0.008"),
                           "geometry.wall_thickness"),
    "zero_thickness": (BOX.replace("flange_thickness = 0.015", "flange_thickness = 0.0"),
                       "geometry.flange_thickness"),
    "poisson": (BOX.replace('name = "steel"', 'name = "steel"\npoisson_ratio = 0.5'), "material.poisson_ratio"),
    "f_max_zero": (BOX.replace("f_max = 4000.0", "f_max = 0.0"), "analysis.modal.f_max"),
    "missing_key": (BOX.replace("height = 0.125", ""), "geometry.height: missing"),
    "wrong_type": (BOX.replace("width = 0.225", 'width = "wide"'), "geometry.width"),
    "malformed": (BOX.replace("[mesh]", "[mesh"), "malformed TOML"),
    "unknown_material": (BOX.replace('name = "steel"', 'name = "unobtainium"'), "material.name"),
    "walls_too_thick": (BOX.replace("wall_thickness = 0.008", "wall_thickness = 0.2"),
                        "geometry.wall_thickness"),
    # a scene written in millimetres, mesh size too: before, nothing stopped it (a 325 m box of 2.4e10 kg)
    "millimetres": (BOX.replace("length = 0.325", "length = 325.0").replace("width = 0.225", "width = 225.0")
                    .replace("height = 0.125", "height = 125.0").replace("[mesh]", "[mesh]\nsize = 40.0"),
                    "geometry.length: 325 m is implausible for a housing (at most 20 m across); scene lengths are "
                    "in m: it looks like millimetres (325 mm = 0.325 m)"),
}


@pytest.mark.parametrize("case", sorted(BAD_SCENES))
def test_bad_scene_gives_one_line_and_exit_2(tmp_path, case):
    text, expected = BAD_SCENES[case]
    scene = tmp_path / f"{case}.toml"
    scene.write_text(text)
    out = tmp_path / "out"
    proc = housingfe("run", str(scene), "--out", str(out))
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert lines[0].startswith("housingfe: error: ") and str(scene) in lines[0]
    assert expected in lines[0], lines[0]
    assert not out.exists() and not list(tmp_path.glob(".out*"))


def test_unknown_scene_and_bad_override(tmp_path):
    proc = housingfe("run", "no-such-scene")
    assert proc.returncode == 2 and "no-such-scene" in proc.stderr and "Traceback" not in proc.stderr
    proc = housingfe("run", "box-free", "--set", "mesh.size")
    assert proc.returncode == 2 and "KEY=VALUE" in proc.stderr
    proc = housingfe("run", str(tmp_path / "missing.toml"))
    assert proc.returncode == 2 and "not found" in proc.stderr


@pytest.mark.parametrize("argv, expected", [
    (["run", "box-free", "--set", "mesh.sise=0.01"], "mesh.sise: unknown key (from --set mesh.sise=0.01)"),
    (["describe", "box-free", "--set", "analysis.modal.f_max=4kHz"],
     "analysis.modal.f_max: Input should be a valid number, unable to parse string as a number "
     "(from --set analysis.modal.f_max=4kHz)"),
    (["run", "test-gearbox-runup", "--set", "runup.enggement=thesis-2d", "--out", "x"],
     "runup.enggement: unknown key (from --set runup.enggement=thesis-2d)"),
])
def test_a_bad_override_is_named_as_the_set_it_came_from(argv, expected, tmp_path, capsys, monkeypatch):
    """A --set typo named only the built-in scene file (which holds no such key); the line now also names the
    --set it came from.  In-process (the console script is covered above)."""
    from housingfe import cli

    monkeypatch.chdir(tmp_path)
    code = cli.main(argv)
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert err.startswith("housingfe: error: ") and err.rstrip().endswith(expected), err
    assert not list(tmp_path.iterdir())


def test_scenes_lists_builtins():
    proc = housingfe("scenes")
    assert proc.returncode == 0
    # one column of names, the descriptions aligned after it (test-gearbox-runup-double-helical ran into its own)
    from housingfe.scenefile import builtin_scenes

    scenes = builtin_scenes()
    starts = {line.index(scenes[line.split()[0]]) for line in proc.stdout.splitlines()}
    assert starts == {max(map(len, scenes)) + 2}, starts
    assert "box-free" in proc.stdout and "nafems-fv12" in proc.stdout


def test_run_writes_complete_folder_and_mpi_agrees(tmp_path):
    one, two = tmp_path / "one", tmp_path / "two"
    proc = housingfe("run", "box-free", "--out", str(one), *FAST)
    assert proc.returncode == 0, proc.stderr
    modes = json.loads((one / "modes.json").read_text())
    for key in ("scene", "frequencies_hz", "rigid_body_frequencies_hz", "mass_kg", "dofs", "complete",
                "residuals", "wall_time_s"):
        assert key in modes
    assert modes["complete"] and len(modes["rigid_body_frequencies_hz"]) == 6
    assert (one / "summary.txt").exists() and (one / "modes.xdmf").exists()
    if not shutil.which("mpirun"):
        pytest.skip("mpirun not installed")
    proc = housingfe("run", "box-free", "--out", str(two), *FAST, mpi_ranks=2)
    assert proc.returncode == 0, proc.stderr
    modes2 = json.loads((two / "modes.json").read_text())
    assert modes2["mpi_ranks"] == 2 and modes2["dofs"] == modes["dofs"]
    f1, f2 = modes["frequencies_hz"], modes2["frequencies_hz"]
    assert len(f1) == len(f2)
    assert max(abs(a - b) / a for a, b in zip(f1, f2)) < 1e-8
    # the resolution report (longest cell edge per wall, reduced over the ranks) is the same on 1 and 2 ranks
    assert modes2["resolution"] == modes["resolution"]
    assert Path(two / "modes.xdmf").exists()


@pytest.mark.parametrize("env, expected", [({}, "ob1"), ({"OMPI_MCA_pml": "cm"}, "cm"),
                                           ({"OMPI_COMM_WORLD_SIZE": "2"}, None), ({"SLURM_PROCID": "0"}, None)])
def test_a_process_without_launcher_gets_the_shared_memory_mpi_layer(env, expected):
    """A plain process (Open MPI singleton) gets OMPI_MCA_pml=ob1 (UCX's probe costs 0.2 s of MPI_Init and on one
    host ob1 is what Open MPI falls back to anyway); a user's choice and a process started by mpirun or srun are
    left alone."""
    base = {k: v for k, v in os.environ.items()
            if k not in ("OMPI_MCA_pml", "OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "SLURM_PROCID")}
    proc = subprocess.run([sys.executable, "-c", "import os, housingfe; print(os.environ.get('OMPI_MCA_pml'))"],
                          capture_output=True, text=True, env={**base, **env}, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == str(expected)


def test_every_subcommand_help_says_what_it_does():
    """`housingfe CMD --help` (at every level) has a description line, not only usage and options: a newcomer
    reading `housingfe run --help` learns what `run` does.  Before, only `bearing` had one."""
    import argparse

    from housingfe.cli import build_parser

    def walk(parser, path):
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, child in action.choices.items():
                    yield f"{path} {name}", child
                    yield from walk(child, f"{path} {name}")

    commands = dict(walk(build_parser(), "housingfe"))
    assert {"housingfe run", "housingfe study", "housingfe radiation foller"} <= set(commands)
    missing = [cmd for cmd, p in commands.items() if not (p.description or "").strip()]
    assert not missing, f"no description in --help: {missing}"
    assert "Run the analyses a scene lists" in commands["housingfe run"].format_help()
    # one end to end: the console entry prints it and exits 0
    proc = housingfe("scenes", "--help")
    assert proc.returncode == 0 and "List the built-in scenes." in proc.stdout, proc.stdout + proc.stderr
    import housingfe as package

    proc = housingfe("--version")
    assert proc.returncode == 0 and proc.stdout.strip() == f"housingfe {package.__version__}", proc.stdout + proc.stderr


@pytest.mark.parametrize("example, command", [("study_family.toml", "housingfe study"),
                                              ("correlate_box.toml", "housingfe update")])
def test_run_on_a_family_file_or_update_spec_names_the_command_that_takes_it(example, command, tmp_path, capsys,
                                                                            monkeypatch):
    """`housingfe run examples/study_family.toml` (the examples folder holds scenes' neighbours) said "name: unknown
    key (also missing: geometry, analysis; ...)"; now one line naming the command that takes the file."""
    from housingfe import cli

    path = Path(__file__).resolve().parents[1] / "examples" / example
    monkeypatch.chdir(tmp_path)
    code = cli.main(["run", str(path)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert err.startswith(f"housingfe: error: {path}: ") and f"run it with `{command} {path}`" in err, err
    assert not list(tmp_path.iterdir())


def test_a_reader_that_stops_early_ends_the_run_quietly(tmp_path):
    """`housingfe run ... | head`: PETSc, once imported, trapped SIGPIPE and ended the run with "PETSC ERROR: Caught
    signal number 13 Broken Pipe" and MPI_ABORT (exit 59); the CLI now starts PETSc without its signal handlers, so
    the closed pipe is Python's BrokenPipeError, which the CLI turns into a quiet exit 141."""
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    cmd = [sys.executable, "-m", "housingfe", "run", "box-free", "--out", str(tmp_path / "box"), "--set",
           "mesh.degree=1", "--set", "mesh.size=0.04", "--set", "analysis.modal.f_max=300.0", "--set",
           "output.pictures=false"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, cwd=tmp_path)
    proc.stdout.close()                     # the reader is gone before the run prints its summary
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=300) == 141, err
    assert "PETSC ERROR" not in err and "MPI_ABORT" not in err and "Traceback" not in err, err
