"""An interrupted `housingfe bench` keeps the runs it finished (issue 27, item 4): `bench modal --quick` stopped by
SIGINT after its first run leaves no result folder but <out>.partial/runs.csv with that run's row (and runs.jsonl);
a re-run with --resume takes the run from there instead of solving it again (it is stopped too: the remaining
quick cases, CalculiX among them, take minutes).  Also `bench all`: a benchmark an interrupted `bench all` finished
is not run again by `bench all --resume`."""
import csv
import json
import os
import re
import signal
import subprocess
import sys

import pytest

from housingfe.benchmarks import all as bench_all
from tests.interrupt import interruptible

PROGRESS = re.compile(r"^bench modal: (\d+)/3 runs, \d+:\d\d elapsed")


def _bench(out, *extra):
    env = {**os.environ, "HOUSINGFE_PROGRESS_SECONDS": "0", "OPENBLAS_NUM_THREADS": "1"}
    return subprocess.Popen([sys.executable, "-m", "housingfe", "bench", "modal", "--quick", "--out", str(out),
                             *extra], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                            preexec_fn=interruptible)


def _interrupt_after(proc, count: int) -> tuple[list[str], str]:
    """Read progress lines until `count` runs are done, then SIGINT; (progress lines, rest of stderr)."""
    seen = []
    for line in proc.stderr:
        m = PROGRESS.match(line)
        if m:
            seen.append(line.rstrip())
            if int(m.group(1)) >= count:
                proc.send_signal(signal.SIGINT)
                break
    rest = proc.stderr.read()
    assert proc.wait(timeout=60) == 130, rest
    return seen, rest


def test_interrupted_bench_keeps_its_finished_runs(tmp_path):
    out = tmp_path / "bench"
    partial = tmp_path / "bench.partial"
    seen, rest = _interrupt_after(_bench(out), 1)
    assert seen[0].startswith("bench modal: 1/3 runs") and "left" in seen[0] and "Q2 hex h=23.4mm x1" in seen[0]
    assert not out.exists()                                   # no result folder that looks complete
    assert f"1 finished run(s) kept in {partial}/" in rest and "--resume" in rest
    with open(partial / "runs.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    # the Q2 hexahedra at 23.4 mm: 38 997 DOFs (docs/benchmarks.md), 37 elastic modes below 1.08 x 4 kHz
    assert [r["run"] for r in rows] == ["round 1 Q2 hex h=23.4mm x1"]
    assert int(rows[0]["dofs"]) == 38997 and float(rows[0]["process_wall_s"]) > 0
    record = json.loads((partial / "runs.jsonl").read_text().splitlines()[1])
    assert len(record["value"]["frequencies_hz"]) == 37

    proc = _bench(out, "--resume")
    head = [proc.stdout.readline(), proc.stdout.readline()]   # the run taken from the checkpoint is reported first
    proc.send_signal(signal.SIGINT)
    _, rest = proc.communicate(timeout=60)
    assert proc.returncode == 130
    assert head[0] == f"resuming: 1 runs from {partial / 'runs.jsonl'}\n"
    assert head[1].startswith("round 1/1  Q2 hex h=23.4mm x1")   # its row, not solved again
    first = rest.splitlines()[0]
    assert first.startswith("bench modal: 1/3 runs") and "(Q2 hex h=23.4mm x1 (resumed))" in first
    assert len(list(csv.DictReader(open(partial / "runs.csv")))) == 1 and not out.exists()


def test_bench_all_resume_skips_finished_benchmarks(tmp_path, monkeypatch):
    """`bench all` interrupted during its second benchmark: the first stays recorded; `--resume` runs only the
    second (run_benchmark replaced: the real ones take minutes to hours)."""
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "benchmarks-notes.md").write_text("")
    monkeypatch.setattr(bench_all, "docs_dir", lambda: docs)
    monkeypatch.setattr(bench_all, "benchmarks", lambda: ["modal", "frf"])
    ran, interrupt = [], {"frf"}

    def fake_run(name, out_dir, quick, resume=False):
        ran.append((name, resume))
        if name in interrupt:
            raise KeyboardInterrupt
        out_dir.mkdir(parents=True, exist_ok=True)
        (out_dir / f"{name}.csv").write_text("case,x\na,1\n")
        return {"name": name, "exit": 0, "wall_s": 1.0, "peak_gb": 0.1, "load_before": 0.5, "load_after": 0.5,
                "log": str(out_dir.parent / f"{name}.log"), "error": ""}

    monkeypatch.setattr(bench_all, "run_benchmark", fake_run)
    with pytest.raises(KeyboardInterrupt):
        bench_all.main(tmp_path / "out", quick=True)
    assert (tmp_path / "out.partial" / "runs.csv").read_text().splitlines()[1].startswith("modal,modal,0,1.0")
    interrupt.clear()
    ran.clear()
    bench_all.main(tmp_path / "out", quick=True, resume=True)
    assert ran == [("frf", True)]
    page = (tmp_path / "out" / "benchmarks.md").read_text()
    assert "[modal](#housingfe-bench-modal) | ok" in page and "[frf](#housingfe-bench-frf) | ok" in page
    assert not (tmp_path / "out.partial").exists()
