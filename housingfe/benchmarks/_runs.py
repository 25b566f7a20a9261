"""The runs a benchmark finished, kept while it runs: `<out>.partial/runs.jsonl` (for --resume) and
`<out>.partial/runs.csv` (to read), beside the result folder `<out>` (written atomically at the end, so it never
holds a partial table).  `housingfe bench NAME --resume` re-uses the runs an interrupted bench of the same inputs
finished; the folder is deleted once `<out>` was written.  Progress of the runs on stderr (housingfe.progress)."""
from __future__ import annotations

import csv
import os
from typing import Callable

from housingfe.checkpoint import Checkpoint, digest, partial_dir
from housingfe.progress import Progress


class FinishedRuns:
    """Checkpointed runs of benchmark `bench` into `out_dir`: `inputs` (JSON-able: the cases, rounds, reference)
    name them; `total` runs expected.  run(key, compute) returns the value of a finished run (resumed) or computes
    it, records it and counts it in the progress; finish() after the result folder was written."""

    def __init__(self, bench: str, out_dir: str | os.PathLike, inputs, total: int, *, resume: bool = False,
                 unit: str = "runs"):
        import housingfe

        self.bench = bench
        self.folder = partial_dir(out_dir)
        key = digest({"bench": bench, "inputs": inputs, "housingfe": housingfe.__version__})
        self.checkpoint = Checkpoint(self.folder / "runs.jsonl", key, resume=resume,
                                     what=f"housingfe bench {bench}: finished runs")
        self.done = {r["key"]: r["value"] for r in self.checkpoint.records}
        status = self.checkpoint.status
        if self.done:
            print(f"resuming: {len(self.done)} {unit} from {self.checkpoint.path}", flush=True)
        elif status == "ignored":
            print(f"note: {self.checkpoint.path} holds the {unit} of an interrupted bench {bench}; --resume "
                  "re-uses them, this run replaces them", flush=True)
        elif status == "other-inputs":
            print(f"note: {self.checkpoint.path} belongs to other inputs (cases or version changed); starting "
                  "afresh", flush=True)
        self.progress = Progress(f"bench {bench}", total, unit)

    def run(self, key: str, compute: Callable[[], dict], note: str = "",
            keep: Callable[[dict], bool] = lambda value: True) -> dict:
        """The value of run `key`: from the checkpoint, else compute() (recorded if keep(value): e.g. not a
        failed run, which a resume tries again)."""
        if key in self.done:
            self.progress.update(note=f"{note} (resumed)" if note else "resumed", resumed=True)
            return self.done[key]
        value = compute()
        if keep(value):
            self.done[key] = value
            self.checkpoint.append({"key": key, "value": value})
            self._write_csv()
        self.progress.update(note=note)
        return value

    def write(self, text: str) -> None:
        """Print a line without tearing the progress line of a terminal."""
        self.progress.write(text, lambda t: print(t, flush=True))

    def _write_csv(self) -> None:
        """runs.csv: one row per finished run, its scalar values (lists and tables left to runs.jsonl)."""
        columns: list[str] = []
        rows = []
        for key, value in self.done.items():
            flat = {"run": key, **{k: v for k, v in value.items() if isinstance(v, (int, float, str, bool))}}
            columns += [c for c in flat if c not in columns]
            rows.append(flat)
        path = self.folder / "runs.csv"
        tmp = self.folder / f".runs.csv.tmp-{os.getpid()}"
        with open(tmp, "w", newline="") as fh:
            writer = csv.DictWriter(fh, columns)
            writer.writeheader()
            writer.writerows(rows)
        os.replace(tmp, path)

    def finish(self) -> None:
        """The result folder is written: end the progress, delete the checkpoint folder."""
        self.progress.close()
        (self.folder / "runs.csv").unlink(missing_ok=True)
        self.checkpoint.remove()

    def close(self) -> None:
        """End the progress line (the checkpoint stays until finish())."""
        self.progress.close()

    def interrupted(self, exc: BaseException | None = None) -> None:
        """An interruption or error: end the progress line, release the checkpoint; after Ctrl-C (exc a
        KeyboardInterrupt) say on stderr where the finished runs are kept (an error stays one line)."""
        import sys

        self.progress.close()
        self.checkpoint.close()
        if self.done and isinstance(exc, KeyboardInterrupt):
            print(f"bench {self.bench}: {len(self.done)} finished run(s) kept in {self.folder}/ (runs.csv); "
                  f"`housingfe bench {self.bench} --resume` re-uses them", file=sys.stderr, flush=True)


def resumable(main) -> bool:
    """Whether a benchmark's main(out_dir, quick, ...) takes resume=."""
    import inspect

    return "resume" in inspect.signature(main).parameters

