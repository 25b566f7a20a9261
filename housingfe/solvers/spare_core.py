"""Work that needs nothing of what this process is doing, done on a spare core by a forked child: the run-up's lumped
source (its stiffness curve and load share, ~0.4 s) while the coupled FE model gets its modal basis.  A fork, not a
thread: the eigensolve's many short dense products would each wait for the interpreter lock that a Python-heavy
thread holds (measured: a thread made the basis 6 -> 10 s)."""
from __future__ import annotations

import os
import pickle
import select
import time
from typing import Callable

from housingfe import outputs


class Forked:
    """fn() computed in a forked child (where this process may use two cores and the platform forks), its result
    sent back pickled; `result()` returns it, or computes fn() here if the child failed, had not finished within
    outputs.CHILD_TIMEOUT_S (it is then killed) or there was no child.  The
    child only computes and pickles (no MPI, no atexit handlers: os._exit).  The value is the same either way
    (pickle keeps every float's bits)."""

    def __init__(self, fn: Callable[[], object], parallel: bool = True):
        self.fn, self.pid, self.fd = fn, None, None
        if not parallel or not (hasattr(os, "fork") and hasattr(os, "sched_getaffinity")
                                and len(os.sched_getaffinity(0)) >= 2):
            return
        read, write = os.pipe()
        pid = os.fork()
        if pid == 0:                                    # the child
            status = 1
            try:
                os.close(read)
                data = pickle.dumps(fn(), protocol=pickle.HIGHEST_PROTOCOL)
                with os.fdopen(write, "wb") as out:
                    out.write(data)
                status = 0
            except BaseException:                       # noqa: BLE001 - the parent computes it again and reports
                pass
            finally:
                os._exit(status)
        os.close(write)
        self.pid, self.fd = pid, read

    def result(self):
        """fn()'s value (from the child if it succeeded, else computed here)."""
        if self.pid is None:
            return self.fn()
        data = _read_until(self.fd, time.monotonic() + outputs.CHILD_TIMEOUT_S)
        os.close(self.fd)
        status = outputs.wait_child(self.pid, timeout=0.0 if data is None else None)
        self.pid = None
        if status != 0 or not data:
            return self.fn()
        return pickle.loads(data)


def _read_until(fd: int, deadline: float) -> bytes | None:
    """Everything written to the pipe `fd` until its writer closes it, or None if that has not happened by
    `deadline` (time.monotonic(), s)."""
    chunks = []
    while True:
        left = deadline - time.monotonic()
        if left <= 0 or not select.select([fd], [], [], left)[0]:
            return None
        chunk = os.read(fd, 1 << 20)
        if not chunk:
            return b"".join(chunks)
        chunks.append(chunk)
