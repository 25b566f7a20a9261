"""One BLAS thread for the run-up chain's dense work.

OpenBLAS splits even a 200 x 200 solve over its threads, and on a machine whose cores are busy (or only two)
the hand-over costs more than the solve: 0.68 ms on one thread against 3.7 ms on two for n = 200
(np.linalg.solve, idle 2-core host).  The source's load distribution (thousands of solves of that size per
stiffness curve) and the run-up's batched 91 x 91 reduced solves are of that kind.  On a shared machine the
same holds for the large dense work: under a load average of 9-11 on 2 cores, the eigensolver's block Gram
products took 61 s of a 135 s basis with two BLAS threads (cProfile), and the whole chain of `make demo` 253 s
against 24 s on one thread (`housingfe bench chain_speed --quick`).  MPI runs already get one thread per rank
(housingfe.benchmarks._launch).  `single_thread` runs a function (or a `with` block) with BLAS on one thread and
restores the caller's setting after.  A thread count the user chose (OPENBLAS_NUM_THREADS, OMP_NUM_THREADS,
MKL_NUM_THREADS set) is left alone.  Without threadpoolctl it does nothing."""
from __future__ import annotations

import contextlib
import functools
import os

_controller = None


USER_SETTINGS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def _get_controller():
    global _controller
    if _controller is None and any(k in os.environ for k in USER_SETTINGS):
        _controller = False         # the user's choice stands
    if _controller is None:
        try:
            from threadpoolctl import ThreadpoolController
        except ImportError:         # optional: then BLAS keeps its threads
            _controller = False
        else:
            _controller = ThreadpoolController()
    return _controller


@contextlib.contextmanager
def single_thread_blas():
    """A `with` block in which BLAS runs on one thread (nested blocks cost nothing extra)."""
    controller = _get_controller()
    if not controller:
        yield
        return
    with controller.limit(limits=1, user_api="blas"):
        yield


def single_thread(fn):
    """Decorator: `fn` runs with BLAS on one thread (single_thread_blas)."""
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with single_thread_blas():
            return fn(*args, **kwargs)

    return wrapper
