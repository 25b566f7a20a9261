"""Checkpoints of long jobs: finished work items (an `update` evaluation, a `bench` run) appended one JSON line
each to a file in `<out>.partial/`, beside the result folder `<out>` and never inside it, so an interrupted job
(Ctrl-C, kill, kill -9, a crash) keeps what it finished and a result folder that exists is still always complete.

The file's first line is a header naming what the records belong to (a hash of the inputs: the spec, the scenes,
the package version); a re-run with other inputs does not use them.  Every record is written with one write() and
fsync'd; a half-written last line (the process killed while writing) is dropped on reading and cut off before
the next append.  The job deletes its checkpoint after its result folder was written.  Base layer.
"""
from __future__ import annotations

import hashlib
import json
import os
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
        if self.rank == 0 and self.path.is_file():
            lines, end = _read_good_lines(self.path)
            if lines and lines[0].get("checkpoint") == key:
                if resume:
                    self.records, self._good_end, self.status = lines[1:], end, "resumed"
                else:
                    self.status = "ignored"
            else:
                self.status = "other-inputs"
        if comm is not None:
            self.records, self.status, self._good_end = comm.bcast((self.records, self.status, self._good_end), root=0)
        self.resumed = len(self.records)
        self._open = self.status == "resumed"     # appending to the loaded file (else: a new file at first append)

    def append(self, record: dict) -> None:
        """Add one finished item (rank 0 writes; a JSON object; floats round-trip exactly)."""
        self.records.append(record)
        if self.rank != 0:
            return
        # other objects (paths) as their text
        line = (json.dumps(record, separators=(",", ":"), default=str) + "\n").encode()
        if not self._open:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            header = json.dumps({"checkpoint": self.key, "what": self.what}) + "\n"
            tmp = self.path.parent / f".{self.path.name}.tmp-{os.getpid()}"
            tmp.write_bytes(header.encode())
            os.replace(tmp, self.path)
            self._good_end = len(header.encode())
            self._open = True
        fd = os.open(self.path, os.O_WRONLY)
        try:
            if os.fstat(fd).st_size != self._good_end:
                os.ftruncate(fd, self._good_end)      # a half-written line of a killed run
            os.lseek(fd, self._good_end, os.SEEK_SET)
            os.write(fd, line)
            os.fsync(fd)
        finally:
            os.close(fd)
        self._good_end += len(line)

    def remove(self) -> None:
        """Delete the checkpoint (after the result was written), and its folder if nothing else is in it."""
        if self.rank != 0:
            return
        self.path.unlink(missing_ok=True)
        try:
            self.path.parent.rmdir()
        except OSError:
            pass
