"""Checkpoints of long jobs: finished work items (an `update` evaluation, a `bench` run) appended one JSON line
each to a file in `<out>.partial/`, beside the result folder `<out>` and never inside it, so an interrupted job
(Ctrl-C, kill, kill -9, a crash) keeps what it finished and a result folder that exists is still always complete.

The file's first line is a header naming what the records belong to (a hash of the inputs: the spec, the scenes,
the package version); a re-run with other inputs does not use them.  Every record is written with one write() and
fsync'd; a half-written last line (the process killed while writing) is dropped on reading and cut off before
the next append.  A run holds an exclusive lock (flock) on the file: a second run with the same checkpoint stops
with an InputError before any work.  The job deletes its checkpoint after its result folder was written.  Base
layer.
"""
from __future__ import annotations

import hashlib
import json
import os
import weakref
from pathlib import Path


def digest(obj) -> str:
    """A short stable hash (16 hex digits) of a JSON-able object (keys sorted; other objects by str())."""
    text = json.dumps(obj, sort_keys=True, default=str, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def partial_dir(out_dir: str | os.PathLike) -> Path:
    """The checkpoint folder of a result folder: `<out>.partial` beside it."""
    out = Path(out_dir)
    return out.parent / f"{out.name}.partial"


def _read_good_lines(path: Path) -> tuple[list[dict], int]:
    """The JSON objects of the complete, readable lines from the start of a file, and the byte length they
    take (the rest, e.g. a line cut by kill -9, is ignored)."""
    data = path.read_bytes()
    records, good_end, pos = [], 0, 0
    while True:
        end = data.find(b"\n", pos)
        if end < 0:
            break
        try:
            obj = json.loads(data[pos:end])
        except (json.JSONDecodeError, UnicodeDecodeError):
            break
        if not isinstance(obj, dict):
            break
        records.append(obj)
        pos = good_end = end + 1
    return records, good_end


class Checkpoint:
    """An append-only JSON-lines checkpoint at `path` for the inputs named by `key` (see digest()).

    resume=True: records of an earlier run with the same key are loaded (`records`, `resumed` = their count);
    resume=False, or another key: the earlier file is replaced at the first append.  `comm`: MPI communicator;
    rank 0 reads and writes, the records are broadcast.  `what`: a description stored in the header."""

    def __init__(self, path: str | os.PathLike, key: str, *, resume: bool = True, what: str = "", comm=None):
        self.path, self.key, self.what, self.comm = Path(path), key, what, comm
        self.rank = comm.rank if comm is not None else 0
        self.records: list[dict] = []
        self.status = "new"         # new | resumed | other-inputs | ignored (resume=False)
        self._good_end = 0
        self._fd = None             # the file, open and locked (flock) while this run owns it
        busy = None
        if self.rank == 0 and self.path.is_file():
            try:
                self._lock(os.open(self.path, os.O_RDWR))
            except BlockingIOError:
                busy = f"{self.path}: another housingfe run is writing this checkpoint; wait for it or choose " \
                       "another --out"
            else:
                lines, end = _read_good_lines(self.path)
                if lines and lines[0].get("checkpoint") == key:
                    if resume:
                        self.records, self._good_end, self.status = lines[1:], end, "resumed"
                    else:
                        self.status = "ignored"
                else:
                    self.status = "other-inputs"
        if comm is not None:
            self.records, self.status, self._good_end, busy = comm.bcast(
                (self.records, self.status, self._good_end, busy), root=0)
        if busy:
            from housingfe.errors import InputError

            raise InputError(busy)
        self.resumed = len(self.records)
        self._started = self.status == "resumed"     # appending to the loaded file (else: header first)

    def _lock(self, fd: int) -> None:
        """Own the open file fd: an exclusive advisory lock, BlockingIOError if another process holds it."""
        import fcntl

        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise
        self._fd = fd
        # released when this object goes (an exception left the job) even if close() is never reached
        self._release = weakref.finalize(self, os.close, fd)

    def append(self, record: dict) -> None:
        """Add one finished item (rank 0 writes; a JSON object; floats round-trip exactly)."""
        self.records.append(record)
        if self.rank != 0:
            return
        # other objects (paths) as their text
        line = (json.dumps(record, separators=(",", ":"), default=str) + "\n").encode()
        if self._fd is None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            try:
                self._lock(os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644))
            except BlockingIOError:
                from housingfe.errors import InputError

                raise InputError(f"{self.path}: another housingfe run started writing this checkpoint; wait for "
                                 "it or choose another --out") from None
        if not self._started:
            header = (json.dumps({"checkpoint": self.key, "what": self.what}) + "\n").encode()
            os.ftruncate(self._fd, 0)
            os.lseek(self._fd, 0, os.SEEK_SET)
            os.write(self._fd, header)
            self._good_end, self._started = len(header), True
        if os.fstat(self._fd).st_size != self._good_end:
            os.ftruncate(self._fd, self._good_end)      # a half-written line of a killed run
        os.lseek(self._fd, self._good_end, os.SEEK_SET)
        os.write(self._fd, line)
        os.fsync(self._fd)
        self._good_end += len(line)

    def remove(self) -> None:
        """Delete the checkpoint (after the result was written), and its folder if nothing else is in it."""
        if self.rank != 0:
            return
        self.path.unlink(missing_ok=True)
        self.close()
        try:
            self.path.parent.rmdir()
        except OSError:
            pass

    def close(self) -> None:
        """Release the file (the records stay; the lock ends with the process anyway)."""
        if self._fd is not None:
            self._release()
            self._fd = None
