"""The progress reporter (housingfe.progress) in real processes: plain rate-limited lines into a pipe, one redrawn
line on a terminal (a pseudo-terminal), silence on MPI ranks other than 0; and the JSON-lines checkpoint
(housingfe.checkpoint) surviving a half-written last line."""
import json
import os
import pty
import subprocess
import sys

import pytest

from housingfe.checkpoint import Checkpoint, digest
from housingfe.errors import InputError

# five items of 0.3 s each, a note on the third
SCRIPT = """
import time
from housingfe.progress import Progress
with Progress("bench demo", 5, "cases") as p:
    for k in range(5):
        time.sleep(0.3)
        p.update(note="third" if k == 2 else "")
        if k == 1:
            p.write("a result line")
"""


def _run(env_extra, stderr=subprocess.PIPE):
    env = {k: v for k, v in os.environ.items() if not k.startswith("HOUSINGFE_PROGRESS")}
    env.update(env_extra)
    return subprocess.run([sys.executable, "-c", SCRIPT], stdout=subprocess.PIPE, stderr=stderr, text=True,
                          env=env, timeout=60)


def _read_all(master: int) -> bytes:
    """Everything written to a pseudo-terminal until its other side is closed."""
    chunks = []
    while True:
        try:
            data = os.read(master, 4096)
        except OSError:          # EIO: every writer closed its end
            break
        if not data:
            break
        chunks.append(data)
    return b"".join(chunks)


def test_plain_lines_in_a_log_one_per_item():
    proc = _run({"HOUSINGFE_PROGRESS_SECONDS": "0"})
    lines = proc.stderr.splitlines()
    assert len(lines) == 5 and "\r" not in proc.stderr
    assert lines[0].startswith("bench demo: 1/5 cases, 0:00 elapsed, ~0:01 left")   # 4 x 0.3 s left
    assert lines[2].endswith("(third)")
    assert lines[4].startswith("bench demo: 5/5 cases, 0:0") and "left" not in lines[4]
    assert proc.stdout == "a result line\n"


def test_log_lines_are_rate_limited():
    """The default: at most one line per 10 s, plus the first and the last item."""
    proc = _run({})
    lines = proc.stderr.splitlines()
    assert [line.split(",")[0] for line in lines] == ["bench demo: 1/5 cases", "bench demo: 5/5 cases"]


def test_terminal_gets_one_redrawn_line():
    master, slave = pty.openpty()
    proc = subprocess.Popen([sys.executable, "-c", SCRIPT], stdout=subprocess.PIPE, stderr=slave,
                            env={k: v for k, v in os.environ.items() if not k.startswith("HOUSINGFE_PROGRESS")},
                            text=True)
    os.close(slave)
    out = proc.stdout.read()
    proc.wait(timeout=60)
    chunks = _read_all(master)
    os.close(master)
    tty = chunks.decode()
    assert out == "a result line\n"
    # every redraw returns to the line's start and clears its rest; one newline at the end (the pty adds \r)
    assert tty.count("\r\x1b[K") == 1       # cleared once for the result line printed in between
    assert tty.replace("\r\n", "\n").count("\n") == 1 and tty.endswith("\n")
    assert tty.count("bench demo: ") >= 5 and "bench demo: 5/5 cases" in tty


def test_prints_on_the_same_terminal_do_not_tear_the_line():
    """stdout and stderr on one terminal: a plain print() clears the progress line, prints its own line, and the
    progress line is drawn again below it."""
    master, slave = pty.openpty()
    script = SCRIPT.replace('p.write("a result line")', 'print("a result line")')
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=slave, stderr=slave,
                            env={k: v for k, v in os.environ.items() if not k.startswith("HOUSINGFE_PROGRESS")})
    os.close(slave)
    chunks = _read_all(master)
    proc.wait(timeout=60)
    os.close(master)
    tty = chunks.decode().replace("\r\n", "\n")
    before, after = tty.split("a result line\n")
    assert before.endswith("\r\x1b[K")                      # the progress line cleared first
    assert after.startswith("\rbench demo: 2/5 cases")       # and drawn again below the printed line
    assert tty.count("\n") == 2 and tty.endswith("\n")


def test_an_error_line_on_the_terminal_replaces_the_progress_line():
    """A command that fails part-way prints its one error line on stderr: it replaces the progress line (cleared
    first), and the progress line is not drawn again after it."""
    master, slave = pty.openpty()
    script = ("import sys\nfrom housingfe.progress import Progress\np = Progress('run-up x', 3, 'steps')\n"
              "p.update(note='housing model')\nprint('housingfe: solver error: boom', file=sys.stderr)\n"
              "sys.exit(3)\n")
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=slave, stderr=slave,
                            env={k: v for k, v in os.environ.items() if not k.startswith("HOUSINGFE_PROGRESS")})
    os.close(slave)
    chunks = _read_all(master)
    assert proc.wait(timeout=60) == 3
    os.close(master)
    tty = chunks.decode().replace("\r\n", "\n")
    assert tty.startswith("\rrun-up x: 1/3 steps, 0:00 elapsed")
    assert tty.endswith("\r\x1b[Khousingfe: solver error: boom\n")


def test_only_rank_0_reports():
    proc = _run({"HOUSINGFE_PROGRESS_SECONDS": "0", "OMPI_COMM_WORLD_RANK": "1"})
    assert proc.stderr == "" and proc.stdout == "a result line\n"


def test_checkpoint_survives_a_cut_line(tmp_path):
    path = tmp_path / "run.partial" / "runs.jsonl"
    key = digest({"spec": [1, 2.5], "version": "x"})
    first = Checkpoint(path, key)
    assert first.status == "new" and first.resumed == 0
    first.append({"case": "a", "wall_s": 0.1 + 0.2})
    first.append({"case": "b", "wall_s": 1e-300})
    # a second run while this one writes: one line, before any work (flock; a second process behaves the same)
    with pytest.raises(InputError, match="runs.jsonl: another housingfe run is writing this checkpoint"):
        Checkpoint(path, key)
    first.close()                                    # the process ends
    with open(path, "ab") as fh:                     # it was killed in the middle of the third record
        fh.write(b'{"case": "c", "wa')
    again = Checkpoint(path, key)
    assert again.status == "resumed" and again.records == [{"case": "a", "wall_s": 0.30000000000000004},
                                                           {"case": "b", "wall_s": 1e-300}]
    again.append({"case": "c", "wall_s": 2.0})
    lines = path.read_text().splitlines()
    assert [json.loads(x) for x in lines[1:]][-1] == {"case": "c", "wall_s": 2.0} and len(lines) == 4
    again.close()
    other = Checkpoint(path, digest({"spec": [1, 2.6], "version": "x"}))
    assert other.status == "other-inputs"
    other.close()
    fresh = Checkpoint(path, key, resume=False)
    assert fresh.status == "ignored" and fresh.records == []
    fresh.append({"case": "z"})
    assert len(path.read_text().splitlines()) == 2
    fresh.remove()
    assert not path.parent.exists()


@pytest.mark.parametrize("name, value, message", [
    ("HOUSINGFE_PROGRESS_SECONDS", "abc", "HOUSINGFE_PROGRESS_SECONDS: 'abc' is not a number of seconds >= 0"),
    ("HOUSINGFE_PROGRESS_SECONDS", "-1", "HOUSINGFE_PROGRESS_SECONDS: '-1' is not a number of seconds >= 0"),
    ("HOUSINGFE_PROGRESS_SECONDS", "nan", "HOUSINGFE_PROGRESS_SECONDS: 'nan'"),
    ("HOUSINGFE_PROGRESS", "false", "HOUSINGFE_PROGRESS: 'false': give 0 (no progress lines) or 1"),
])
def test_a_bad_progress_variable_stops_the_command_with_one_line(name, value, message, tmp_path):
    """A typo in the variables was ignored without a word (the default taken): now one line, exit 2, before any
    work; 0 and 2.5 are taken."""
    from housingfe.progress import check_environment

    with pytest.raises(InputError, match=message.replace("(", r"\(").replace(")", r"\)")):
        check_environment({name: value})
    check_environment({"HOUSINGFE_PROGRESS_SECONDS": "2.5", "HOUSINGFE_PROGRESS": "0"})
    env = {**os.environ, name: value}
    proc = subprocess.run([sys.executable, "-m", "housingfe", "run", "box-free", "--out", str(tmp_path / "r")],
                          capture_output=True, text=True, env=env, timeout=120, cwd=tmp_path)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and lines[0].startswith("housingfe: error: " + message), lines
    assert not list(tmp_path.iterdir())
