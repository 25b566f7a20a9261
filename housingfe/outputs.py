"""Result files of every link and command: atomic output folders (a folder that exists is complete), JSON and CSV
writers without NaN surprises, plain-text tables.  The bottom layer beside errors and levels."""
from __future__ import annotations

import atexit
import contextlib
import csv
import dataclasses
import datetime
import fcntl
import glob
import hashlib
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Callable, Iterable, Iterator, Sequence

from housingfe.errors import InputError

# --------------------------------------------------------------------------------------- result folders
# `--out` may replace only a folder that housingfe wrote (issue 27): every result folder carries MARKER, written
# last, and a folder without it is never deleted.  A run first reserves its place (checks + a lock beside the
# folder, before any computation), then writes into a hidden temporary folder that is renamed in at the end:
# the old result is renamed aside first and deleted last, so a kill at any moment leaves either the old or the new
# complete result under the name (or, between the two renames, both complete in hidden folders beside it), and
# the next run into the same place removes the hidden leftovers.  Details: docs/outputs.md.

MARKER = "housingfe-result.json"
# result folders written before the marker existed that are still recognised as results: those `housingfe
# validate` stamped as its cache (it reads them back)
LEGACY_MARKERS = (".validate-key",)


@dataclasses.dataclass
class _Reservation:
    """A place this process holds: the lock file's descriptor and what the marker should record."""
    out: Path
    lock: Path
    fd: int
    inputs: tuple[Path, ...]
    created: list[Path]                # parent folders made by the reservation (removed again if left empty)
    own_files: frozenset[str]


_RESERVED: dict[str, _Reservation] = {}


def _key(out: Path) -> str:
    return os.path.abspath(out)


def _fail(out: Path, what: str) -> InputError:
    return InputError(f"{out}: output folder: {what}")


def is_result_folder(folder: Path, own_files=frozenset()) -> bool:
    """True if `folder` holds housingfe's result marker (or a legacy one, or only files named in own_files)."""
    if any((folder / name).is_file() for name in (MARKER, *LEGACY_MARKERS)):
        return True
    if own_files:
        entries = list(folder.iterdir())
        return bool(entries) and all(e.is_file() and e.name in own_files for e in entries)
    return False


def check_output_place(out_dir: str | os.PathLike, inputs: Iterable[str | os.PathLike] = (),
                       own_files: Iterable[str] = ()) -> Path:
    """Check that a result may be written to `out_dir`, else raise InputError (one line naming the folder).

    Refused: an empty path; a symbolic link; an existing file; an existing folder that is not empty and holds no
    MARKER (a folder of the user's, or a parent of other results); the working folder, the home folder, the
    folder of housingfe's sources, any input file (`inputs`: the scene) or a folder containing one of them; a
    place whose folder cannot be written (checked by creating and removing a probe folder there, so it holds
    for root and read-only file systems too).  `own_files`: names a command wrote before the marker existed
    (a folder holding only those is replaceable).  Returns the path."""
    if not str(out_dir).strip():
        raise InputError("output folder: empty path")
    out = Path(out_dir)
    real = out.resolve()
    protected = [(Path.cwd().resolve(), "the working folder"),
                 (Path(__file__).resolve().parent.parent, "the folder of housingfe's own sources")]
    with contextlib.suppress(RuntimeError, KeyError):     # no home folder known: nothing to protect there
        protected.append((Path.home().resolve(), "your home folder"))
    protected += [(Path(p).resolve(), f"the input file {p}") for p in inputs]
    for path, label in protected:
        if real == path or real in path.parents:
            raise _fail(out, f"replacing it would delete {label}; give a folder of its own (e.g. results/<name>)")
    if out.is_symlink():
        raise _fail(out, "is a symbolic link; give the folder itself")
    if out.exists():
        if not out.is_dir():
            raise _fail(out, "is a file, not a folder; give another --out")
        try:
            empty = not any(out.iterdir())
            ours = empty or is_result_folder(out, frozenset(own_files))
        except OSError as exc:
            raise _fail(out, f"cannot be read ({exc.strerror})") from None
        if not ours:
            raise _fail(out, f"exists and is not a housingfe result (no {MARKER}): only result folders are "
                             "replaced; choose another --out or delete the folder yourself")
    _check_writable(out)
    return out


def check_files_folder(out_dir: str | os.PathLike) -> Path:
    """For commands that write named files into a folder (docs pictures, a scene skeleton) rather than a result
    folder: InputError, before any work, unless `out_dir` is a folder or can be made one (no file on its path,
    its nearest existing folder writable).  Nothing is created.  Returns the path."""
    out = Path(out_dir)
    if not str(out_dir).strip():
        raise _fail(out, "empty path")
    if out.exists() and not out.is_dir():
        raise _fail(out, "is a file, not a folder; give another --out")
    place = Path(os.path.abspath(out))
    while not place.exists():
        place = place.parent
    if not place.is_dir():
        raise _fail(out, f"{place} is a file, not a folder")
    if not os.access(place, os.W_OK):
        raise _fail(out, f"cannot write in {place}")
    return out


def _check_writable(out: Path) -> None:
    """InputError unless a folder can be created beside `out` (in its nearest existing ancestor)."""
    place = Path(os.path.abspath(out)).parent
    while not place.exists():
        place = place.parent
    if not place.is_dir():
        raise _fail(out, f"{place} is a file, not a folder")
    try:
        probe = tempfile.mkdtemp(prefix=f".{out.name}.probe-", dir=place)
        os.rmdir(probe)
    except OSError as exc:
        raise _fail(out, f"cannot write in {place} ({exc.strerror})") from None


def reserve_output(out_dir: str | os.PathLike, comm=None, inputs: Iterable[str | os.PathLike] = (),
                   own_files: Iterable[str] = ()) -> Path:
    """Check the output place (check_output_place) and lock it for this process, at the start of a command,
    before any computation: a bad place or a place another run is writing is refused now (InputError, one
    line), not after an hour of work.  The lock (flock on `.<name>.lock` beside the folder, released by the
    kernel if the process dies) is held until atomic_output_dir has renamed the result in, or the process
    ends.  Stale temporary and set-aside folders of killed runs into this place are removed.  With an MPI
    communicator rank 0 decides and every rank raises the same error.  Returns the path."""
    out = Path(out_dir)
    error = None
    if comm is None or comm.rank == 0:
        try:
            _reserve(out, tuple(Path(p) for p in inputs), frozenset(own_files))
        except InputError as exc:
            error = str(exc)
    if comm is not None:
        error = comm.bcast(error, root=0)
    if error is not None:
        raise InputError(error)
    return out


def _reserve(out: Path, inputs: tuple[Path, ...], own_files: frozenset) -> _Reservation:
    key = _key(out)
    if key in _RESERVED:
        check_output_place(out, _RESERVED[key].inputs, _RESERVED[key].own_files)
        return _RESERVED[key]
    check_output_place(out, inputs, own_files)
    parent = Path(key).parent
    created = []
    missing = parent
    while not missing.exists():
        created.append(missing)
        missing = missing.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise _fail(out, f"cannot create {parent} ({exc.strerror})") from None
    lock = parent / f".{out.name}.lock"
    fd = _lock(out, lock)
    reservation = _RESERVED[key] = _Reservation(out, lock, fd, inputs, created, own_files)
    _remove_stale(parent, out.name)
    return reservation


def _lock(out: Path, lock: Path) -> int:
    """Open and flock `lock` (non-blocking); InputError naming the holder's PID if another process has it."""
    while True:
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise _fail(out, f"cannot create the lock file {lock} ({exc.strerror})") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.read(fd, 64).decode(errors="replace").strip() or "?"
            os.close(fd)
            raise _fail(out, f"another housingfe run (PID {holder}) is writing it; wait for it to finish or "
                             "choose another --out") from None
        try:
            same = os.stat(lock).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            same = False
        if same:        # else the holder removed the file between our open and flock: lock the new one
            os.ftruncate(fd, 0)
            os.write(fd, f"{os.getpid()}\n".encode())
            return fd
        os.close(fd)


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _remove_stale(parent: Path, name: str) -> None:
    """Remove `.<name>.tmp-PID` / `.<name>.old-PID` folders left by killed runs (the caller holds the lock, so
    no housingfe run of this version writes them; a folder of a live PID other than ours is left alone).  If
    the run was killed between its two renames (no folder under the name), the newest complete result among
    them is renamed in first: a new one that holds MARKER, else the old one set aside."""
    stale = []
    for kind in ("tmp", "old"):
        for path in parent.glob(f".{glob.escape(name)}.{kind}-*"):
            pid = path.name.rsplit("-", 1)[-1]
            if pid.isdigit() and (int(pid) == os.getpid() or not _pid_alive(int(pid))) and path.is_dir() \
                    and not path.is_symlink():
                stale.append(path)
    out = parent / name
    if stale and not os.path.lexists(out):
        complete = [p for p in stale if ".tmp-" in p.name and (p / MARKER).is_file()] + \
                   [p for p in stale if ".old-" in p.name]
        if complete:
            os.rename(complete[0], out)
            stale.remove(complete[0])
    for path in stale:
        _remove_tree(path)


def _remove_tree(path: Path) -> None:
    """rmtree that also removes read-only sub-folders of its own (a result copied with its permissions)."""
    def retry(func, p, _exc):
        os.chmod(os.path.dirname(p) or ".", 0o700)
        func(p)

    shutil.rmtree(path, onerror=retry)


def release_output(out_dir: str | os.PathLike) -> None:
    """Give up a place reserved by this process (unlock; remove the lock file and the parent folders the
    reservation created if they are still empty)."""
    reservation = _RESERVED.pop(_key(Path(out_dir)), None)
    if reservation is None:
        return
    with contextlib.suppress(OSError):
        os.unlink(reservation.lock)      # while still locked: a waiting process re-checks the inode
    os.close(reservation.fd)
    for folder in reservation.created:
        with contextlib.suppress(OSError):
            folder.rmdir()


def release_all() -> None:
    """Release every place this process holds (end of a command, or exit)."""
    for key in list(_RESERVED):
        release_output(key)


atexit.register(release_all)


def _marker(reservation: _Reservation | None) -> dict:
    import housingfe

    inputs = []
    for p in reservation.inputs if reservation is not None else ():
        try:
            inputs.append({"path": str(p), "sha256": hashlib.sha256(p.read_bytes()).hexdigest()})
        except OSError:
            inputs.append({"path": str(p), "sha256": None})
    return {"written_by": "housingfe", "version": housingfe.__version__, "git_commit": _git_commit(),
            "command": sys.argv, "working_folder": os.getcwd(), "inputs": inputs,
            "created_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "complete": True}


def _git_commit() -> str | None:
    source = Path(__file__).resolve().parent
    try:
        proc = subprocess.run(["git", "-C", str(source), "rev-parse", "HEAD"], capture_output=True, text=True,
                              timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    if proc.returncode != 0:
        return None
    return proc.stdout.strip() or None


@contextlib.contextmanager
def atomic_output_dir(out_dir: str | os.PathLike, comm=None) -> Iterator[Path]:
    """Yield a temporary folder beside `out_dir`; on success MARKER is written into it and it replaces
    `out_dir`, on any error it is removed, so a result folder that exists is always complete.  The place is
    reserved (reserve_output: checks and lock) unless the command did so already at its start, which it
    should, so that a bad place is refused before the computation.  The old folder is renamed aside before the
    new one is renamed in and deleted last.  With an MPI communicator every rank gets the same folder (rank 0
    checks, creates and renames it); without one the caller is the only writer."""
    out = Path(out_dir)
    rank = comm.rank if comm is not None else 0
    tmp = error = None
    if rank == 0:
        try:
            reservation = _reserve(out, (), frozenset())
            tmp = out.parent / f".{out.name}.tmp-{os.getpid()}"
            if tmp.exists():
                _remove_tree(tmp)
            tmp.mkdir()
        except InputError as exc:
            error = str(exc)
    if comm is not None:
        tmp, error = comm.bcast((tmp, error), root=0)
    if error is not None:
        if rank == 0:
            release_output(out)
        raise InputError(error)
    aside = None
    try:
        yield tmp
        if comm is not None:
            comm.barrier()
        if rank == 0:
            write_json(tmp / MARKER, _marker(reservation))     # last: a folder with the marker is complete
            if out.is_dir() and not out.is_symlink():
                aside = out.parent / f".{out.name}.old-{os.getpid()}"
                os.rename(out, aside)
            os.rename(tmp, out)
            old, aside = aside, None
            if old is not None:
                with contextlib.suppress(OSError):     # the result is in place; the next run removes what is left
                    _remove_tree(old)
    except BaseException:
        if rank == 0:
            if aside is not None and not out.exists():     # the new one failed to go in: put the old one back
                os.rename(aside, out)
            shutil.rmtree(tmp, ignore_errors=True)
            release_output(out)
        raise
    if rank == 0:
        release_output(out)


def json_safe(data):
    """`data` with numpy scalars and arrays as Python lists and numbers, tuples as lists, and every NaN or
    infinity as None: strict JSON (RFC 8259 has no NaN; Python's json would write a bare `NaN`)."""
    if isinstance(data, dict):
        return {k: json_safe(v) for k, v in data.items()}
    if isinstance(data, (list, tuple)):
        return [json_safe(v) for v in data]
    if hasattr(data, "tolist") and not isinstance(data, (str, bytes)):
        return json_safe(data.tolist())
    if isinstance(data, float) and not math.isfinite(data):
        return None
    return data


def dumps_json(data, **kwargs) -> str:
    """json.dumps of json_safe(data), refusing anything that still is not strict JSON (allow_nan=False)."""
    return json.dumps(json_safe(data), allow_nan=False, **kwargs)


def write_json(path: Path, data) -> None:
    """Write `data` as indented strict JSON (numpy scalars and arrays converted, NaN and infinities as null)."""
    path.write_text(dumps_json(data, indent=2) + "\n")


def write_csv(path: Path, header: Sequence[str], rows: Iterable[Sequence]) -> None:
    """Write rows under a header line as CSV."""
    with open(path, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(header)
        for row in rows:
            writer.writerow(row)


def write_records(path: Path, records: Sequence[dict], floatfmt: str = "{:.6g}") -> None:
    """Write dict rows as CSV, the first row's keys as the header, floats with `floatfmt`; nothing when empty."""
    if records:
        write_csv(path, list(records[0]), ([floatfmt.format(v) if isinstance(v, float) else v for v in r.values()]
                                           for r in records))


TERMINAL_WIDTH = 120   # the widest table a terminal is shown (the CSV / Markdown files keep every column whole)


def format_table(header: Sequence[str], rows: Sequence[Sequence], floatfmt: str = "{:.4g}",
                 width: int | None = TERMINAL_WIDTH, keys: int = 1) -> str:
    """A plain-text table with aligned columns (for terminals and summary.txt), at most `width` characters wide
    (None: any width).  A wider table is split into blocks of columns, each repeating the first `keys` columns
    (those that tell the rows apart); a text column still too wide for one block is shortened with "…" (the full
    text belongs in the CSV beside it)."""
    cells = [[str(h) for h in header]]
    for row in rows:
        cells.append([floatfmt.format(v) if isinstance(v, float) else str(v) for v in row])
    widths = [max(len(r[i]) for r in cells) for i in range(len(header))]
    keys = max(1, min(keys, len(widths) - 1))
    if width is None or sum(widths) + 2 * (len(widths) - 1) <= width or len(widths) < 2:
        return _aligned(cells, widths)
    # every column must fit beside the key columns: the keys together, then each other column, to half the width
    # (the first key column gives up what the keys exceed)
    limit = width // 2 - 1
    cut = [max(4, widths[0] - (sum(widths[:keys]) + 2 * (keys - 1) - limit))] + [limit] * (len(widths) - 1)
    for i in range(len(widths)):
        if widths[i] > cut[i]:
            for r in cells:
                if len(r[i]) > cut[i]:
                    r[i] = r[i][:cut[i] - 1] + "…"
            widths[i] = cut[i]
    key_width = sum(widths[:keys]) + 2 * (keys - 1)
    blocks, current = [], []
    for i in range(keys, len(widths)):
        if current and key_width + sum(widths[j] + 2 for j in current + [i]) > width:
            blocks.append(current)
            current = []
        current.append(i)
    blocks.append(current)
    return "\n\n".join(_aligned([r[:keys] + [r[j] for j in block] for r in cells],
                                 widths[:keys] + [widths[j] for j in block]) for block in blocks)


def _aligned(cells: list[list[str]], widths: list[int]) -> str:
    lines = ["  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in cells]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


# ------------------------------------------------------------------------------------------ modal results


# ---------------------------------------------------------------------------------------- file jobs on two cores
def _spare_core() -> bool:
    """Whether this process may fork a child onto a second core (Linux: its CPU affinity holds two or more)."""
    return hasattr(os, "fork") and hasattr(os, "sched_getaffinity") and len(os.sched_getaffinity(0)) >= 2


# A forked child that has not finished by then is killed and its work redone here: a child that hangs (e.g. on a
# library lock held by another thread at the fork) must cost a delay, never a hung run.
CHILD_TIMEOUT_S = 120.0


def wait_child(pid: int, timeout: float | None = None) -> int:
    """The exit status of the forked child `pid`, or -1 after killing it (SIGKILL) when it has not ended within
    `timeout` s (None: CHILD_TIMEOUT_S)."""
    deadline, delay = time.monotonic() + (CHILD_TIMEOUT_S if timeout is None else timeout), 0.002
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            return status
        if time.monotonic() > deadline:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            return -1
        time.sleep(delay)
        delay = min(2 * delay, 0.02)


def run_split(jobs: Sequence[tuple[float, Callable[[], object]]], parallel: bool = True) -> None:
    """Run independent jobs that write files (e.g. a report's pictures: matplotlib's layout is pure Python, ~0.2-0.5 s
    a figure) as two halves of about equal estimated cost: one in this process, the other in a forked child on
    another core, where this process may use two (os.sched_getaffinity) and the platform forks; otherwise all here.
    jobs: (estimated cost, callable with no arguments); results are discarded, each job's files are its output.
    The child only runs its jobs (no MPI, no atexit handlers: os._exit) and reports success by its exit status; if
    it fails, is killed or has not ended CHILD_TIMEOUT_S after this process' half, its jobs run again here, so an error is raised in this process with its traceback.  The
    files are the same either way (each job writes its own).  parallel=False: all here (e.g. under MPI with more
    than one rank, whose other ranks already have the cores)."""
    jobs = list(jobs)
    if not parallel or len(jobs) < 2 or not _spare_core():
        for _, job in jobs:
            job()
        return
    here, there, load = [], [], [0.0, 0.0]
    for cost, job in sorted(jobs, key=lambda j: -j[0]):       # greedy: the costliest first, to the lighter half
        side = 0 if load[0] <= load[1] else 1
        (here if side == 0 else there).append(job)
        load[side] += cost
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:                                                # the child: its jobs, then out without cleanup
        status = 1
        try:
            for job in there:
                job()
            status = 0
        except BaseException:                                   # noqa: BLE001 - the parent re-runs and reports
            pass
        finally:
            os._exit(status)
    try:
        for job in here:
            job()
    finally:
        status = wait_child(pid)
    if status != 0:
        for job in there:
            job()
