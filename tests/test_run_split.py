"""outputs.run_split: file jobs shared between this process and a forked child (the run-up report's pictures)."""
from __future__ import annotations

import os

import pytest

from housingfe import outputs


def _job(path, fail_in_child_of=None, always_fail=False):
    def run():
        if always_fail or (fail_in_child_of is not None and os.getpid() != fail_in_child_of):
            raise RuntimeError("job failed")
        path.write_text(str(os.getpid()))
    return run


@pytest.mark.skipif(not hasattr(os, "fork") or len(os.sched_getaffinity(0)) < 2, reason="needs fork and 2 cores")
def test_jobs_run_on_two_processes_and_each_file_is_written(tmp_path):
    paths = [tmp_path / f"f{i}.txt" for i in range(5)]
    outputs.run_split([(1.0 + i, _job(p)) for i, p in enumerate(paths)])
    pids = {int(p.read_text()) for p in paths}
    assert len(pids) == 2 and os.getpid() in pids


def test_a_job_failing_in_the_child_is_run_again_here(tmp_path):
    paths = [tmp_path / f"f{i}.txt" for i in range(4)]
    outputs.run_split([(1.0, _job(p, fail_in_child_of=os.getpid())) for p in paths])
    assert all(int(p.read_text()) == os.getpid() for p in paths)


def test_a_job_that_fails_everywhere_raises_here(tmp_path):
    jobs = [(1.0, _job(tmp_path / "a.txt")), (2.0, _job(tmp_path / "b.txt", always_fail=True))]
    with pytest.raises(RuntimeError, match="job failed"):
        outputs.run_split(jobs)


@pytest.mark.skipif(not hasattr(os, "fork") or len(os.sched_getaffinity(0)) < 2, reason="needs fork and 2 cores")
def test_a_child_that_hangs_is_killed_and_its_jobs_run_here(tmp_path, monkeypatch):
    """A child that never ends costs CHILD_TIMEOUT_S, not a hung run: it is killed and its files written here."""
    import time

    monkeypatch.setattr(outputs, "CHILD_TIMEOUT_S", 1.0)
    parent = os.getpid()

    def job(path):
        def run():
            while os.getpid() != parent:
                time.sleep(0.05)
            path.write_text(str(os.getpid()))
        return run

    paths = [tmp_path / f"f{i}.txt" for i in range(4)]
    t0 = time.monotonic()
    outputs.run_split([(1.0, job(p)) for p in paths])
    assert all(int(p.read_text()) == parent for p in paths) and time.monotonic() - t0 < 10
