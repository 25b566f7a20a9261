"""Commands under `mpirun -n 2` as a user starts them (housingfe.ranks, cli.main): serial commands run once and
write once, bad input found on one rank stops every rank instead of hanging, an error is printed once."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.skipif(shutil.which("mpirun") is None, reason="mpirun not installed")


def _run(args, ranks=1, cwd=None, timeout=120):
    cmd = [sys.executable, *args]
    if ranks > 1:
        cmd = [shutil.which("mpirun"), "-n", str(ranks), "--oversubscribe", *cmd]
    env = {**os.environ, "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OPENBLAS_NUM_THREADS": "1", "PYTHONPATH": str(ROOT)}
    t0 = time.monotonic()
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=cwd or ROOT, env=env, timeout=timeout)
    return proc, time.monotonic() - t0


def _errors(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if line.startswith("housingfe: ")]


def test_a_meshing_error_on_rank_0_stops_both_ranks_with_one_line(tmp_path):
    """Rank 0 alone meshes; hexahedra asked for a housing with round bores is found there.  The other rank waited
    in a broadcast for ever (timeout after 120 s); now both stop at once, exit 2, one line, no folder."""
    out = tmp_path / "out"
    proc, seconds = _run(["-m", "housingfe", "run", "gearbox-model", "--set", 'mesh.element="hex"', "--out",
                          str(out)], ranks=2, timeout=90)
    assert proc.returncode == 2, proc.stderr[-2000:]
    assert _errors(proc.stderr) == [f"housingfe: error: {ROOT}/housingfe/scenes/gearbox-model.toml: mesh.element: "
                                    "a geometry with round bores needs element = \"tet\""], proc.stderr
    assert "Traceback" not in proc.stderr and not out.exists() and seconds < 60


def test_an_error_on_one_rank_alone_aborts_the_job_instead_of_hanging():
    """One rank stops (stop_together) while the other waits in a barrier: without the abort MPI_Finalize and the
    barrier wait for each other for ever (measured: still hanging after 60 s)."""
    script = ("import sys\nfrom mpi4py import MPI\nfrom housingfe import ranks\nc = MPI.COMM_WORLD\n"
              "if c.rank == 1:\n    sys.exit(ranks.stop_together('housingfe: error: rank 1 alone', 2, c, grace_s=1.0))\n"
              "c.barrier()\nprint('rank 0 passed the barrier')\n")
    proc, seconds = _run(["-c", script], ranks=2, timeout=60)
    assert proc.returncode == 2 and seconds < 30
    assert "housingfe: error: rank 1 alone" in proc.stderr and "passed the barrier" not in proc.stdout


def test_a_source_scene_runs_once_on_two_ranks_and_gives_the_one_rank_files(tmp_path):
    """Gear source scenes are serial: both ranks used to reserve the folder and one stopped with 'another
    housingfe run (PID ...) is writing it' (exit 2).  Now rank 0 writes it, the same files as one rank, once."""
    one, two = tmp_path / "one", tmp_path / "two"
    proc1, _ = _run(["-m", "housingfe", "run", "fukuma-series-a", "--out", str(one)])
    proc2, _ = _run(["-m", "housingfe", "run", "fukuma-series-a", "--out", str(two)], ranks=2)
    assert proc1.returncode == 0 and proc2.returncode == 0, proc2.stderr[-2000:]
    assert proc2.stdout.count("results in") == 1
    names = sorted(p.name for p in one.iterdir())
    assert names == sorted(p.name for p in two.iterdir()) and "bearing_loads.csv" in names
    for name in names:
        if name.endswith((".csv", ".txt")):
            assert (one / name).read_text() == (two / name).read_text(), name
    assert sorted(p.name for p in tmp_path.iterdir()) == ["one", "two"]      # no leftover temporary folders


def test_serial_commands_say_so_and_print_once_and_drivers_refuse():
    """describe (serial) prints its text once on two ranks, with one note that it is serial (a run-up scene: its
    modules import petsc4py, whose start is collective, and rank 0 waited there for the idle rank for ever); bench
    starts processes of its own and refuses mpirun with one line, exit 2."""
    one, _ = _run(["-m", "housingfe", "describe", "test-gearbox-runup"])
    two, _ = _run(["-m", "housingfe", "describe", "test-gearbox-runup"], ranks=2, timeout=60)
    assert one.returncode == two.returncode == 0, two.stderr
    assert two.stdout == one.stdout and "run-up scene test-gearbox-runup" in one.stdout
    assert _errors(two.stderr) == ["housingfe: note: `describe` is serial: rank 0 runs it, the other 1 rank(s) "
                                   "wait (it needs no mpirun)"]
    # every rank parses the command line; --help and a usage error are printed by rank 0 alone
    help_one, _ = _run(["-m", "housingfe", "describe", "--help"])
    help_two, _ = _run(["-m", "housingfe", "describe", "--help"], ranks=2)
    assert help_two.returncode == 0 and help_two.stdout == help_one.stdout
    usage, _ = _run(["-m", "housingfe", "describe"], ranks=2)
    assert usage.returncode == 2 and usage.stderr.count("error: the following arguments are required") == 1
    bench, _ = _run(["-m", "housingfe", "bench", "modal", "--quick"], ranks=2)
    assert bench.returncode == 2
    errors = _errors(bench.stderr)
    assert len(errors) == 1 and errors[0].startswith("housingfe: error: bench: runs its cases in processes of its "
                                                     "own"), bench.stderr


def test_two_ranks_draw_the_one_rank_mode_picture(tmp_path):
    """modes.png was left out on more than one rank; the shapes are now gathered on rank 0: the same picture
    (mean pixel difference < 1e-3: the same grid, its cells in another order)."""
    import matplotlib.image

    fast = ["--set", "mesh.size=0.04", "--set", "mesh.degree=2", "--set", "analysis.modal.f_max=2500.0",
            "--set", "output.mode_pictures=3"]
    pictures = []
    for ranks in (1, 2):
        out = tmp_path / f"n{ranks}"
        proc, _ = _run(["-m", "housingfe", "run", "box-free", "--out", str(out), *fast], ranks=ranks)
        assert proc.returncode == 0, proc.stderr[-2000:]
        pictures.append(matplotlib.image.imread(out / "modes.png"))
    one, two = pictures
    assert one.shape == two.shape and abs(one - two).mean() < 1e-3
