"""Result files of every link and command: atomic output folders (a folder that exists is complete), JSON and CSV
writers without NaN surprises, plain-text tables.  The bottom layer beside errors and levels."""
from __future__ import annotations

import contextlib
import csv
import json
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


def write_json(path: Path, data) -> None:
    """Write `data` as indented JSON (numpy scalars and arrays converted)."""
    def default(o):
        if hasattr(o, "tolist"):
            return o.tolist()
        raise TypeError(f"not JSON serialisable: {type(o)}")

    path.write_text(json.dumps(data, indent=2, default=default) + "\n")


def write_csv(path: Path, header: Sequence[str], rows: Iterable[Sequence]) -> None:
    """Write rows under a header line as CSV."""
    with open(path, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(header)
        for row in rows:
            writer.writerow(row)


TERMINAL_WIDTH = 120   # the widest table a terminal is shown (the CSV / Markdown files keep every column whole)


def format_table(header: Sequence[str], rows: Sequence[Sequence], floatfmt: str = "{:.4g}",
                 width: int | None = TERMINAL_WIDTH) -> str:
    """A plain-text table with aligned columns (for terminals and summary.txt), at most `width` characters wide
    (None: any width).  A wider table is split into blocks of columns, each repeating the first column; a text
    column still too wide for one block is shortened with "…" (the full text belongs in the CSV beside it)."""
    cells = [[str(h) for h in header]]
    for row in rows:
        cells.append([floatfmt.format(v) if isinstance(v, float) else str(v) for v in row])
    widths = [max(len(r[i]) for r in cells) for i in range(len(header))]
    if width is None or sum(widths) + 2 * (len(widths) - 1) <= width or len(widths) < 2:
        return _aligned(cells, widths)
    # every column must fit beside the first one: shorten the first, then each other, to half the width
    limit = width // 2 - 1
    for i in range(len(widths)):
        if widths[i] > limit:
            for r in cells:
                if len(r[i]) > limit:
                    r[i] = r[i][:limit - 1] + "…"
            widths[i] = limit
    blocks, current = [], []
    for i in range(1, len(widths)):
        if current and widths[0] + sum(widths[j] + 2 for j in current + [i]) > width:
            blocks.append(current)
            current = []
        current.append(i)
    blocks.append(current)
    return "\n\n".join(_aligned([[r[0]] + [r[j] for j in block] for r in cells],
                                 [widths[0]] + [widths[j] for j in block]) for block in blocks)


def _aligned(cells: list[list[str]], widths: list[int]) -> str:
    lines = ["  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in cells]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


# ------------------------------------------------------------------------------------------ modal results
