"""Progress of long jobs (update, bench, validate, run-up studies): count, elapsed time and an estimate of the time
left, on stderr.

On a terminal (stderr is a tty) one line is redrawn in place; anywhere else (a log file, CI, a pipe) plain lines
are written, at most one every HOUSINGFE_PROGRESS_SECONDS seconds (default 10; 0: one line per item), plus the
first and the last item, so a log of a 40-minute job stays readable.  Under MPI only rank 0 writes.
HOUSINGFE_PROGRESS=0 silences it.  Own code rather than tqdm: tqdm writes carriage-return bars into log files
too (or nothing, when disabled off a tty); the plain, rate-limited lines are what logs need.  Base layer.
"""
from __future__ import annotations

import math
import os
import sys
import time

DEFAULT_LOG_SECONDS = 10.0      # plain lines: at most one per this many seconds
TTY_REDRAW_SECONDS = 0.2        # terminal: redraw at most this often


def format_seconds(seconds: float) -> str:
    """h:mm:ss or m:ss (seconds rounded)."""
    s = int(round(max(seconds, 0.0)))
    h, rest = divmod(s, 3600)
    m, s = divmod(rest, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"


def _rank() -> int:
    """This process's MPI rank from the launcher's environment (no MPI import in the base layer)."""
    for var in ("OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK", "SLURM_PROCID"):
        if os.environ.get(var, "").isdigit():
            return int(os.environ[var])
    return 0


def check_environment(environ=None) -> None:
    """InputError naming the variable when HOUSINGFE_PROGRESS_SECONDS is not a number of seconds >= 0 or
    HOUSINGFE_PROGRESS not 0 or 1 (Progress itself falls back to its defaults: a typo was ignored without a word).
    The CLI calls it before any work."""
    from housingfe.errors import InputError

    environ = os.environ if environ is None else environ
    seconds = environ.get("HOUSINGFE_PROGRESS_SECONDS")
    if seconds is not None:
        try:
            value = float(seconds)
        except ValueError:
            value = float("nan")
        if not (math.isfinite(value) and value >= 0.0):
            raise InputError(f"HOUSINGFE_PROGRESS_SECONDS: {seconds!r} is not a number of seconds >= 0 (the longest "
                             f"time between progress lines; default {DEFAULT_LOG_SECONDS:g}, 0: a line per item)")
    enabled = environ.get("HOUSINGFE_PROGRESS")
    if enabled is not None and enabled.strip() not in ("0", "1"):
        raise InputError(f"HOUSINGFE_PROGRESS: {enabled!r}: give 0 (no progress lines) or 1 (the default)")


class Progress:
    """Progress of `total` items (None: unknown) named `unit`, with a `label` in front.  `at_most`: the total is
    an upper bound (a budget, e.g. max_evaluations), shown as "<= N" and the estimate as "<= ...".
    update(n, note) counts n finished items; write(text) prints a line to stdout without tearing the terminal
    line; close() ends it (also as a context manager).  `comm`: an MPI communicator (only its rank 0 writes;
    default: the launcher's rank).  `stream`: default sys.stderr."""

    def __init__(self, label: str, total: int | None = None, unit: str = "items", *, at_most: bool = False,
                 comm=None, stream=None, done: int = 0):
        self.label, self.total, self.unit, self.at_most = label, total, unit, at_most
        self.stream = stream if stream is not None else sys.stderr
        rank = comm.rank if comm is not None else _rank()
        self.enabled = rank == 0 and os.environ.get("HOUSINGFE_PROGRESS", "1") != "0"
        try:
            self.tty = bool(self.stream.isatty())
        except (AttributeError, ValueError):
            self.tty = False
        try:
            self.every = float(os.environ.get("HOUSINGFE_PROGRESS_SECONDS", DEFAULT_LOG_SECONDS))
        except ValueError:
            self.every = DEFAULT_LOG_SECONDS
        self.done, self.skipped = done, done      # items finished before this run (resumed) do not time the rest
        self.t0 = time.monotonic()
        self.last_shown, self.shown_count, self.drawn, self.visible = -1e30, -1, False, False
        self.note = ""
        self._stdout = self._stderr = None
        if self.enabled and self.tty and _same_terminal(sys.stdout, self.stream):
            # prints to the same terminal clear the progress line first and redraw it after their line
            self._stdout, sys.stdout = sys.stdout, _LineAware(self, sys.stdout, redraw=True)
        if self.enabled and self.tty and sys.stderr is self.stream:
            # other writes to stderr (a warning, the error that ends the command) clear it and are not followed
            # by it: the next update draws it again
            self._stderr, sys.stderr = sys.stderr, _LineAware(self, sys.stderr, redraw=False)

    # ---------------------------------------------------------------------------------------------- text
    def line(self) -> str:
        """The progress text: label, count, elapsed, estimate of the time left."""
        elapsed = time.monotonic() - self.t0
        count = f"{self.done}"
        if self.total is not None:
            count += f"/{'<=' if self.at_most else ''}{self.total}"
        text = f"{self.label}: {count} {self.unit}, {format_seconds(elapsed)} elapsed"
        fresh = self.done - self.skipped
        if self.total is not None and fresh > 0 and self.done < self.total:
            left = elapsed / fresh * (self.total - self.done)
            text += f", {'<= ' if self.at_most else '~'}{format_seconds(left)} left"
        if self.note:
            text += f" ({self.note})"
        return text

    # ---------------------------------------------------------------------------------------------- output
    def update(self, n: int = 1, note: str = "", resumed: bool = False) -> None:
        """n more items finished; `note`: a short remark shown after the estimate (e.g. the current case);
        `resumed`: they were taken from a checkpoint (not counted in the rate of the estimate)."""
        self.done += n
        if resumed:
            self.skipped += n
        self.note = note
        if not self.enabled:
            return
        now = time.monotonic()
        if self.tty:
            if now - self.last_shown >= TTY_REDRAW_SECONDS or (self.total is not None and self.done >= self.total):
                self._draw(now)
        elif (self.shown_count < 0 or now - self.last_shown >= self.every
              or (self.total is not None and self.done >= self.total)):
            self._emit(now)

    def _draw(self, now: float) -> None:
        import shutil

        # a line longer than the terminal would wrap, and "\r" would then redraw only its last part
        width = shutil.get_terminal_size((120, 24)).columns - 1
        self.stream.write("\r" + self.line()[:max(width, 20)] + "\x1b[K")
        self.stream.flush()
        self.last_shown, self.shown_count, self.drawn, self.visible = now, self.done, True, True

    def _clear(self) -> None:
        if self.visible:
            self.stream.write("\r\x1b[K")
            self.stream.flush()
            self.visible = False

    def _emit(self, now: float) -> None:
        self.stream.write(self.line() + "\n")
        self.stream.flush()
        self.last_shown, self.shown_count = now, self.done

    def write(self, text: str, echo=None) -> None:
        """Print text (with `echo`, default print to stdout) without tearing the terminal's progress line:
        clear it, print, redraw."""
        if self.enabled and self.tty:
            self._clear()
        if echo is None:
            print(text, flush=True)
        else:
            echo(text)
        if self.enabled and self.tty and self.drawn and not self.visible:
            self._draw(time.monotonic())

    def close(self) -> None:
        """End the progress: the terminal line is finished with a newline; a log gets the last count if it was
        not written yet."""
        if not self.enabled:
            return
        if self._stdout is not None and isinstance(sys.stdout, _LineAware) and sys.stdout.progress is self:
            sys.stdout = self._stdout
        if self._stderr is not None and isinstance(sys.stderr, _LineAware) and sys.stderr.progress is self:
            sys.stderr = self._stderr
        if self.tty:
            if self.drawn or self.done:
                self._draw(time.monotonic())
                self.stream.write("\n")
                self.stream.flush()
        elif self.done and self.shown_count != self.done:
            self._emit(time.monotonic())
        self.enabled = self.visible = False

    def __enter__(self) -> "Progress":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _same_terminal(a, b) -> bool:
    """Whether two streams write to the same terminal."""
    try:
        return a.isatty() and b.isatty() and os.path.samestat(os.fstat(a.fileno()), os.fstat(b.fileno()))
    except (AttributeError, ValueError, OSError):
        return False


class _LineAware:
    """sys.stdout or sys.stderr while a progress line is shown on their terminal: a write clears the line; with
    `redraw`, a finished line draws it again below."""

    def __init__(self, progress: Progress, stream, redraw: bool):
        self.progress, self.stream, self.redraw = progress, stream, redraw

    def write(self, text: str) -> int:
        if self.progress.enabled:
            self.progress._clear()
        n = self.stream.write(text)
        if self.redraw and text.endswith("\n") and self.progress.enabled and self.progress.drawn:
            self.stream.flush()
            self.progress._draw(time.monotonic())
        return n

    def flush(self) -> None:
        self.stream.flush()

    def __getattr__(self, name):
        return getattr(self.stream, name)
