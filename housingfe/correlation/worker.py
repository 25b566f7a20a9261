"""A worker process for model evaluations (housingfe.correlation.updating.SceneEvaluator): reads pickled
(function name, args) tasks from stdin, writes pickled (ok, result or exception) to its original stdout.
Anything the FE libraries print goes to stderr, so it cannot corrupt the replies.  The parent replaces the
worker every few tasks to return the memory a model build leaves behind."""
from __future__ import annotations

import os
import pickle
import struct
import subprocess
import sys


def _read(stream) -> bytes | None:
    head = stream.read(8)
    if len(head) < 8:
        return None
    (size,) = struct.unpack("<Q", head)
    return stream.read(size)


def _write(stream, payload: bytes) -> None:
    stream.write(struct.pack("<Q", len(payload)) + payload)
    stream.flush()


def main() -> None:
    reply = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)                              # prints of the FE stack go to stderr
    sys.stdout = sys.stderr
    import importlib

    while True:
        task = _read(sys.stdin.buffer)
        if task is None:
            return
        module, name, args = pickle.loads(task)
        try:
            # the module is named by the caller, so that this module imports none of its callers (no cycle)
            out = (True, getattr(importlib.import_module(module), name)(*args))
        except Exception as exc:  # noqa: BLE001 - sent back and re-raised in the parent
            out = (False, exc)
        _write(reply, pickle.dumps(out))


class Worker:
    """One worker subprocess; call(name, *args) runs <module>.<name>(*args) in it (module: a dotted module name,
    e.g. housingfe.correlation.updating) and returns the result or re-raises its exception; restarted after
    `tasks` calls."""

    def __init__(self, tasks: int = 20, module: str = "housingfe.correlation.updating"):
        self.tasks, self.done, self.proc, self.module = tasks, 0, None, module

    def call(self, name: str, *args):
        if self.proc is not None and self.done >= self.tasks:
            self.close()
        if self.proc is None:
            self.proc = subprocess.Popen([sys.executable, "-m", "housingfe.correlation.worker"],
                                         stdin=subprocess.PIPE, stdout=subprocess.PIPE)
            self.done = 0
        _write(self.proc.stdin, pickle.dumps((self.module, name, args)))
        payload = _read(self.proc.stdout)
        self.done += 1
        if payload is None:
            code = self.proc.wait()
            self.proc = None
            raise RuntimeError(f"model evaluation worker died (exit code {code})")
        ok, value = pickle.loads(payload)
        if not ok:
            raise value
        return value

    def close(self) -> None:
        if self.proc is not None:
            self.proc.stdin.close()
            self.proc.wait()
            self.proc = None


if __name__ == "__main__":
    main()
