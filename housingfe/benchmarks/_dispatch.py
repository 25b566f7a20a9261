"""`housingfe bench <name>`: dispatch to housingfe.benchmarks.<name>.main(out_dir, quick)."""
from __future__ import annotations

import importlib
import math
import pkgutil
from pathlib import Path

from housingfe.errors import InputError
from housingfe.outputs import reserve_output


def available() -> list[str]:
    """Names of the benchmarks that exist."""
    return sorted(m.name for m in pkgutil.iter_modules([str(Path(__file__).parent)]) if not m.name.startswith("_"))


def main(which: str, out_dir: str | None = None, quick: bool = False, only: list[str] | None = None,
         notes_only: bool = False, resume: bool = False, size_mm: float | None = None,
         cases: list[str] | None = None, rounds: int | None = None) -> None:
    """Run one benchmark; results go to out_dir (default results/bench-<which>).  only: for `all`, the subset to
    re-run (their sections of docs/benchmarks.md are replaced).  notes_only: for `all`, run nothing and refresh the
    page's hand-written notes from docs/benchmarks-notes.md.  resume: re-use the runs an interrupted bench left in
    <out>.partial/ (the benchmarks that keep their runs: resumable()).  size_mm (element size, mm), cases (the
    subset of cases to run) and rounds (interleaved rounds): for the benchmarks whose main takes them."""
    from housingfe.benchmarks._runs import resumable

    if which not in available():
        raise InputError(f"bench: unknown benchmark {which!r} (available: {', '.join(available())})")
    module = importlib.import_module(f"housingfe.benchmarks.{which}")
    if resume:
        if notes_only:
            raise InputError("bench: --resume and --notes exclude each other")
        if not resumable(module.main):
            keeping = [n for n in available() if resumable(importlib.import_module(f"housingfe.benchmarks.{n}").main)]
            raise InputError(f"bench: --resume: {which} does not keep its runs (those that do: {', '.join(keeping)})")
        extra = {"resume": True}
    else:
        extra = {}
    extra.update(_tuning(which, module, {"size_mm": size_mm, "cases": cases, "rounds": rounds}))
    if notes_only:
        if which != "all" or only or quick:
            raise InputError("bench: --notes applies to `housingfe bench all` alone (no --only, no --quick)")
        module.main(Path(out_dir or f"results/bench-{which}"), notes_only=True)
        return
    if only:
        if which != "all":
            raise InputError("bench: --only applies to `housingfe bench all`")
        module.main(Path(out_dir or f"results/bench-{which}"), quick, only=only, **extra)
        return
    out = Path(out_dir or f"results/bench-{which}")
    if which != "all":      # `all` writes a folder of result folders (each checked by its own run)
        reserve_output(out)     # a bad or busy output place stops here, before the rounds
    module.main(out, quick, **extra)


def _tuning(which: str, module, given: dict) -> dict:
    """The options given (not None) that the benchmark's main takes; InputError, before any output place is
    taken, for one it does not take, a non-positive number or cases its selected_cases() refuses."""
    import inspect

    option = {"size_mm": "--size", "cases": "--cases", "rounds": "--rounds"}
    takes = inspect.signature(module.main).parameters
    out = {}
    for key, value in given.items():
        if value is None:
            continue
        if key not in takes:
            users = [n for n in available() if n != "all"
                     and key in inspect.signature(importlib.import_module(f"housingfe.benchmarks.{n}").main).parameters]
            raise InputError(f"bench: {option[key]}: {which} does not take it (those that do: {', '.join(users)})")
        if key != "cases" and not (value > 0 and math.isfinite(value)):
            raise InputError(f"bench: {option[key]}: {value:g} must be a finite positive number")
        if key == "cases" and hasattr(module, "selected_cases"):
            module.selected_cases(value)
        out[key] = value
    return out
