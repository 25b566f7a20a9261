"""housingfe.solvers.blas: the chain's dense work on one BLAS thread, the caller's setting restored after, and an
explicit user thread count left alone."""
import numpy as np  # noqa: F401  (loads the BLAS whose threads are counted)
import pytest

threadpoolctl = pytest.importorskip("threadpoolctl")


def _blas_threads() -> list[int]:
    return [i["num_threads"] for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas"]


@pytest.fixture
def fresh(monkeypatch):
    from housingfe.solvers import blas

    monkeypatch.setattr(blas, "_controller", None)
    return blas


def test_single_thread_limits_blas_and_restores_it(fresh, monkeypatch):
    for key in fresh.USER_SETTINGS:
        monkeypatch.delenv(key, raising=False)
    before = _blas_threads()
    assert before, "no BLAS found to limit"
    with threadpoolctl.threadpool_limits(2, user_api="blas"):
        outer = _blas_threads()
        with fresh.single_thread_blas():
            assert _blas_threads() == [1] * len(outer)
        assert _blas_threads() == outer
    assert fresh.single_thread(lambda: _blas_threads())() == [1] * len(before)


def test_a_thread_count_the_user_set_is_left_alone(fresh, monkeypatch):
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "2")
    with threadpoolctl.threadpool_limits(2, user_api="blas"):
        outer = _blas_threads()
        with fresh.single_thread_blas():
            assert _blas_threads() == outer
