"""One BLAS thread for many small dense solves.

OpenBLAS splits even a 200 x 200 solve over its threads, and on a machine whose cores are busy (or only two)
the hand-over costs more than the solve: 0.68 ms on one thread against 3.7 ms on two for n = 200
(np.linalg.solve, idle 2-core host).  The source's load distribution (thousands of solves of that size per
stiffness curve) and the run-up's batched 91 x 91 reduced solves are of that kind: `single_thread` runs a
function (or a `with` block) with BLAS on one thread and restores the caller's setting after.  Large dense work
(MUMPS fronts, the eigensolver's block products) keeps the caller's threads.  Without threadpoolctl it does
nothing."""
from __future__ import annotations

import contextlib
import functools

_controller = None


def _get_controller():
    global _controller
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
