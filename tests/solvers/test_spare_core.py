"""solvers.spare_core.Forked: a value computed in a forked child and sent back (the run-up's lumped source)."""
from __future__ import annotations

import os

import numpy as np
import pytest

from housingfe.solvers.spare_core import Forked

forks = pytest.mark.skipif(not hasattr(os, "fork") or len(os.sched_getaffinity(0)) < 2,
                           reason="needs fork and 2 cores")


@forks
def test_the_childs_value_comes_back_bit_for_bit():
    parent = os.getpid()

    def compute():
        rng = np.random.default_rng(3)
        return {"pid": os.getpid(), "x": np.linalg.solve(rng.standard_normal((40, 40)), rng.standard_normal(40))}

    value = Forked(compute).result()
    assert value["pid"] != parent
    assert np.array_equal(value["x"], compute()["x"])


def test_a_failing_child_or_no_child_computes_here():
    parent = os.getpid()

    def only_here():
        if os.getpid() != parent:
            raise RuntimeError("not in the child")
        return os.getpid()

    assert Forked(only_here).result() == parent
    assert Forked(os.getpid, parallel=False).result() == parent


def test_an_error_everywhere_is_raised_here():
    def fails():
        raise ValueError("bad input")

    with pytest.raises(ValueError, match="bad input"):
        Forked(fails).result()


@forks
def test_a_child_that_hangs_is_killed_and_the_value_computed_here(monkeypatch):
    """A child that never ends (e.g. a lock held across the fork) costs CHILD_TIMEOUT_S, not a hung run."""
    import time

    from housingfe import outputs

    monkeypatch.setattr(outputs, "CHILD_TIMEOUT_S", 1.0)
    parent = os.getpid()

    def hangs_in_the_child():
        while os.getpid() != parent:
            time.sleep(0.05)
        return "here"

    t0 = time.monotonic()
    forked = Forked(hangs_in_the_child)
    child = forked.pid
    assert forked.result() == "here" and time.monotonic() - t0 < 10
    with pytest.raises(ChildProcessError):
        os.waitpid(child, os.WNOHANG)          # killed and reaped
