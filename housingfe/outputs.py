"""Result files of every link and command: atomic output folders (a folder that exists is complete), JSON and CSV
writers without NaN surprises, plain-text tables.  The bottom layer beside errors and levels."""
from __future__ import annotations

import contextlib
import csv
import json
import math
import os
import shutil
from pathlib import Path
from typing import Iterable, Iterator, Sequence


@contextlib.contextmanager
def atomic_output_dir(out_dir: str | os.PathLike, comm=None) -> Iterator[Path]:
    """Yield a temporary folder beside `out_dir`; on success it replaces `out_dir`, on any error it is
    removed, so a result folder that exists is always complete.  With an MPI communicator every rank gets
    the same folder (rank 0 creates and renames it); without one the caller is the only writer."""
    out = Path(out_dir)
    rank = comm.rank if comm is not None else 0
    tmp = out.parent / f".{out.name}.tmp-{os.getpid()}"
    if comm is not None:
        tmp = comm.bcast(tmp, root=0)
    if rank == 0:
        out.parent.mkdir(parents=True, exist_ok=True)
        if tmp.exists():
            shutil.rmtree(tmp)
        tmp.mkdir()
    if comm is not None:
        comm.barrier()
    try:
        yield tmp
        if comm is not None:
            comm.barrier()
    except BaseException:
        if rank == 0:
            shutil.rmtree(tmp, ignore_errors=True)
        raise
    if rank == 0:
        if out.exists():
            shutil.rmtree(out)
        os.replace(tmp, out)


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


def format_table(header: Sequence[str], rows: Sequence[Sequence], floatfmt: str = "{:.4g}") -> str:
    """A plain-text table with aligned columns (for terminals and summary.txt)."""
    cells = [[str(h) for h in header]]
    for row in rows:
        cells.append([floatfmt.format(v) if isinstance(v, float) else str(v) for v in row])
    widths = [max(len(r[i]) for r in cells) for i in range(len(header))]
    lines = ["  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in cells]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


# ------------------------------------------------------------------------------------------ modal results
