"""`housingfe bench all`: run every benchmark and regenerate docs/benchmarks.md in one command.

Each benchmark (`housingfe bench <name>`) runs in its own process, one after the other, into
<out>/<name>/ (default results/bench-all/<name>/); its wall time, peak resident memory (the child's own
getrusage, so benchmarks do not inherit each other's memory) and the load average before and after are recorded.
The page is generated: a header with the machine, load and versions, a summary table, then per benchmark every
CSV it wrote rendered as a table and every PNG it drew, followed by the hand-written analysis of that benchmark from
docs/benchmarks-notes.md (blocks introduced by `<!-- notes: <name> -->`; text before the first marker goes below
the header).  Regeneration therefore never deletes analysis.  The page and its pictures are written atomically.

In the page every hand-written block sits between `<!-- from notes: <name> -->` and `<!-- end of notes -->`
(the header's: name "header"), so `housingfe bench all --notes` puts edited notes in place without running a
benchmark (refresh_notes).

--quick runs every benchmark's quick mode (a smoke test, minutes) and writes the page to <out>/benchmarks.md,
never to docs/ (quick numbers are not the documented ones).  A full run with a failed benchmark also leaves docs/
alone and writes <out>/benchmarks.md.
"""
from __future__ import annotations

import csv
import datetime
import os
import platform
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

from housingfe.errors import SolverError

# chain_speed compares this tree with an older commit checked out beside it (20 min loaded): run it on its own
NOT_IN_ALL = {"chain_speed"}
# Page order; any other benchmark module found is appended after these.
ORDER = ["modal", "mpi", "frf", "direct", "scenes", "source", "bearings", "radiation", "coupling", "runup"]
MAX_ROWS = 40           # a longer CSV shows its first rows and says how many more the file holds
NOTES_MARK = re.compile(r"^<!--\s*notes:\s*([\w-]+)\s*-->\s*$", re.MULTILINE)
# where a notes block sits in the generated page
PAGE_NOTES = re.compile(r"^<!-- from notes: ([\w-]+) -->\n.*?^<!-- end of notes -->$", re.MULTILINE | re.DOTALL)
HEADER_NOTES = "header"


def benchmarks() -> list[str]:
    """The benchmarks `bench all` runs, in page order."""
    from housingfe.benchmarks._dispatch import available

    names = [n for n in available() if n != "all" and n not in NOT_IN_ALL]
    return [n for n in ORDER if n in names] + [n for n in names if n not in ORDER]


# ------------------------------------------------------------------------------------------------ running
def run_benchmark(name: str, out_dir: Path, quick: bool, timeout_s: float | None = None, resume: bool = False) -> dict:
    """Run `housingfe bench <name>` in a child process; wall time (s), peak RSS (GB), load averages, exit status.
    resume: the child re-uses the runs its interrupted predecessor kept (benchmarks that keep them)."""
    import importlib

    from housingfe.benchmarks._runs import resumable

    out_dir.parent.mkdir(parents=True, exist_ok=True)
    resume = resume and resumable(importlib.import_module(f"housingfe.benchmarks.{name}").main)
    code = ("import sys; from housingfe.benchmarks._dispatch import main; "
            "main(sys.argv[1], sys.argv[2], sys.argv[3] == '1', resume=sys.argv[4] == '1')")
    load_before = os.getloadavg()
    t0 = time.perf_counter()
    log = out_dir.parent / f"{name}.log"
    with open(log, "w") as fh:
        proc = subprocess.Popen([sys.executable, "-c", code, name, str(out_dir), "1" if quick else "0",
                                 "1" if resume else "0"],
                                stdout=fh, stderr=subprocess.STDOUT)
        try:
            _, status, usage = os.wait4(proc.pid, 0)   # this child's own rusage (ru_maxrss in KiB on Linux)
        except KeyboardInterrupt:
            proc.kill()
            raise
        proc.returncode = os.waitstatus_to_exitcode(status)
    wall = time.perf_counter() - t0
    tail = log.read_text(errors="replace").strip().splitlines()[-1:] if proc.returncode else []
    return {"name": name, "exit": proc.returncode, "wall_s": wall, "peak_gb": usage.ru_maxrss / 1024**2,
            "load_before": load_before[0], "load_after": os.getloadavg()[0], "log": str(log),
            "error": tail[0] if tail else ""}


def machine_info() -> dict:
    """Machine, date and versions recorded at the top of the page."""
    info = {"date (UTC)": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M"),
            "machine": platform.machine(), "cores": str(os.cpu_count()), "os": platform.platform(),
            "python": platform.python_version()}
    try:
        cpu = [ln.split(":", 1)[1].strip() for ln in Path("/proc/cpuinfo").read_text().splitlines()
               if ln.startswith("model name")]
        info["cpu"] = cpu[0] if cpu else "?"
        mem = [ln.split()[1] for ln in Path("/proc/meminfo").read_text().splitlines() if ln.startswith("MemTotal")]
        info["memory"] = f"{int(mem[0]) / 1024**2:.1f} GB"
    except (OSError, IndexError, ValueError):
        pass
    import housingfe

    info["housingfe"] = housingfe.__version__
    try:
        info["git"] = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                                     cwd=Path(__file__).parent, check=False).stdout.strip() or "?"
    except OSError:
        info["git"] = "?"
    for module, attr in (("numpy", "__version__"), ("scipy", "__version__"), ("dolfinx", "__version__"),
                         ("gmsh", "__version__")):
        try:
            info[module] = getattr(__import__(module), attr)
        except Exception:   # noqa: BLE001 - a missing optional package is recorded, not fatal
            info[module] = "not importable"
    try:
        from petsc4py import PETSc
        from slepc4py import SLEPc

        info["PETSc"] = ".".join(map(str, PETSc.Sys.getVersion()))
        info["SLEPc"] = ".".join(map(str, SLEPc.Sys.getVersion()))
    except Exception:   # noqa: BLE001
        pass
    ccx = shutil.which("ccx")
    info["CalculiX"] = ccx or "not installed"
    info["OPENBLAS_NUM_THREADS"] = os.environ.get("OPENBLAS_NUM_THREADS", "unset")
    return info


# ------------------------------------------------------------------------------------------------ the page
def _cell(text: str) -> str:
    """A CSV field as a Markdown table cell: floats to 4 significant digits, pipes escaped."""
    try:
        value = float(text)
        if not text.strip().lstrip("-").isdigit() and value == value and abs(value) != float("inf"):
            text = f"{value:.4g}"
    except ValueError:
        pass
    return text.replace("|", "\\|").replace("\n", " ")


def csv_table(path: Path, max_rows: int = MAX_ROWS) -> str:
    """A CSV file (header line + rows) as a Markdown table."""
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    if not rows:
        return f"*{path.name}: empty*\n"
    header, body = rows[0], rows[1:]
    lines = ["| " + " | ".join(_cell(h) for h in header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(_cell(c) for c in row) + " |" for row in body[:max_rows]]
    if len(body) > max_rows:
        lines.append(f"\n… {len(body) - max_rows} more rows in `{path.name}`")
    return "\n".join(lines) + "\n"


def split_notes(text: str) -> tuple[str, dict]:
    """(preamble, {benchmark: notes}) of docs/benchmarks-notes.md: blocks start at `<!-- notes: name -->`."""
    marks = list(NOTES_MARK.finditer(text))
    preamble = text[:marks[0].start()] if marks else text
    preamble = re.sub(r"^\s*<!--.*?-->", "", preamble, count=1, flags=re.DOTALL)   # the file's own explanation
    blocks = {}
    for m, nxt in zip(marks, marks[1:] + [None]):
        blocks[m.group(1)] = text[m.end():nxt.start() if nxt else len(text)].strip()
    return preamble.strip(), blocks


def render_page(results: list[dict], info: dict, notes: str, quick: bool) -> str:
    """The Markdown page: header, summary, then per benchmark its tables ("csvs": paths), pictures ("images":
    links relative to the page) and notes."""
    preamble, blocks = split_notes(notes)
    loads = [r["load_before"] for r in results] + [r["load_after"] for r in results]
    out = ["# Benchmarks: speed next to error", "",
           "<!-- generated by `housingfe bench all` from the benchmarks' CSV files; edit the analysis in "
           "docs/benchmarks-notes.md, not here -->", "",
           f"Generated by `housingfe bench all{' --quick' if quick else ''}` on {info.get('date (UTC)', '?')} UTC"
           + (" — **quick mode: a smoke test, not the documented numbers**" if quick else "") + ".",
           (f"Load average (1 min) during the runs: {min(loads):.2f} – {max(loads):.2f} on {info.get('cores', '?')} "
            "cores" if loads else "No benchmark ran.")
           + " — timings taken on a shared machine are pessimistic; ratios of two codes count only where the "
             "benchmark interleaves them.", "",
           "| machine and versions | |", "|---|---|"]
    out += [f"| {k} | {_cell(str(v))} |" for k, v in info.items()]
    out += ["", "| benchmark | status | wall s | peak memory GB | load before | load after |", "|---|---|---|---|---|---|"]
    for r in results:
        status = "ok" if r["exit"] == 0 else f"**failed** (exit {r['exit']}): {_cell(r.get('error', ''))}"
        out.append(f"| [{r['name']}](#housingfe-bench-{r['name']}) | {status} | {r['wall_s']:.1f} | "
                   f"{r['peak_gb']:.2f} | {r['load_before']:.2f} | {r['load_after']:.2f} |")
    if preamble:
        out += ["", _wrapped(HEADER_NOTES, preamble)]
    for r in results:
        out += render_section(r, blocks)
    rest = [n for n in blocks if n not in {r["name"] for r in results}]
    for name in rest:      # notes of a benchmark that did not run this time are kept, not dropped
        out += ["", f"## {name} (notes only: not run this time)", "", _wrapped(name, blocks[name]), ""]
    return "\n".join(out).rstrip() + "\n"


def render_section(r: dict, blocks: dict, note: str | None = None) -> list[str]:
    """The lines of one benchmark's section: heading, optional note, CSV tables, pictures, hand-written notes."""
    out = ["", f"## housingfe bench {r['name']}", ""]
    if note:
        out += [note, ""]
    for path in r.get("csvs", []):
        out += [f"`{Path(path).name}`", "", csv_table(Path(path))]
    for link in r.get("images", []):
        out += [f"![{r['name']}]({link})", ""]
    if r["name"] in blocks:
        out += [_wrapped(r["name"], blocks[r["name"]]), ""]
    return out


def _wrapped(name: str, block: str) -> str:
    """A notes block between the page's markers (PAGE_NOTES)."""
    return f"<!-- from notes: {name} -->\n{block}\n<!-- end of notes -->"


def refresh_notes(page: Path, notes: str) -> str:
    """The page with every marked notes block replaced by the current text of the notes file (the header's too);
    tables, pictures and timings stay.  SolverError when the page has no marked block (generated before the
    markers: run `housingfe bench all` once) or the notes name a block the page does not show."""
    text = page.read_text()
    preamble, blocks = split_notes(notes)
    blocks = {HEADER_NOTES: preamble, **blocks} if preamble else blocks
    present = {m.group(1) for m in PAGE_NOTES.finditer(text)}
    if not present:
        raise SolverError(f"bench all --notes: {page} has no marked notes blocks; run `housingfe bench all` first")
    missing = sorted(set(blocks) - present)
    if missing:
        raise SolverError(f"bench all --notes: {page} shows no block for {', '.join(missing)}; re-run those "
                          "benchmarks (`housingfe bench all --only ...`)")
    return PAGE_NOTES.sub(lambda m: _wrapped(m.group(1), blocks.get(m.group(1), "")), text)


SECTION = re.compile(r"^## housingfe bench ([\w-]+)\s*$", re.MULTILINE)


def update_sections(page: Path, results: list[dict], info: dict, notes: str) -> str:
    """The existing page with the sections of `results` replaced (benchmarks re-run alone with --only); each
    replaced section says when and how it was re-run, and the header lists the sections re-run since the last
    full run.  Sections of other benchmarks, and the header's machine table, stay as they were."""
    text = page.read_text()
    marks = list(SECTION.finditer(text))
    if not marks:
        raise SolverError(f"bench all --only: {page} has no benchmark sections; run `housingfe bench all` first")
    head = text[:marks[0].start()].rstrip("\n")
    sections = {m.group(1): text[m.start():nxt.start() if nxt else len(text)].strip("\n")
                for m, nxt in zip(marks, marks[1:] + [None])}
    _, blocks = split_notes(notes)
    date = info.get("date (UTC)", "?")
    for r in results:
        note = (f"*Re-run alone by `housingfe bench all --only {','.join(x['name'] for x in results)}` on {date} "
                f"UTC: {r['wall_s']:.1f} s, peak {r['peak_gb']:.2f} GB, load {r['load_before']:.2f} → "
                f"{r['load_after']:.2f}, git {info.get('git', '?')}; the header's tables are from the last "
                "full run.*")
        sections[r["name"]] = "\n".join(render_section(r, blocks, note)).strip("\n")
    line = f"Sections re-run alone since: {_rerun_entries(head, [r['name'] for r in results], date)} (`--only`)."
    head = re.sub(r"\nSections re-run alone since: .*", "", head)
    head = re.sub(r"(\nGenerated by `housingfe bench all[^\n]*)", lambda m: m.group(1) + "\n" + line, head, count=1)
    return head + "\n\n" + "\n\n".join(sections.values()).rstrip() + "\n"


def _rerun_entries(head: str, names: list[str], date: str) -> str:
    """The header's list of sections re-run since the full run, "a, b on DATE UTC; c on DATE UTC", with `names`
    moved to the newest entry."""
    entries = []
    old = re.search(r"\nSections re-run alone since: (.*?) \(`--only`\)\.", head)
    for entry in old.group(1).split("; ") if old else []:
        which, _, when = entry.partition(" on ")
        kept = [n for n in which.split(", ") if n not in names]
        if kept and when:
            entries.append(f"{', '.join(kept)} on {when}")
    return "; ".join(entries + [f"{', '.join(names)} on {date} UTC"])


def write_atomic(path: Path, data: bytes | str) -> None:
    """Write a file through a temporary file in the same folder and a rename."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.parent / f".{path.name}.tmp-{os.getpid()}"
    tmp.write_bytes(data.encode() if isinstance(data, str) else data)
    os.replace(tmp, path)


def publish(results: list[dict], info: dict, notes_path: Path, page: Path, images_dir: Path | None,
            quick: bool, only: bool = False) -> Path:
    """Collect each benchmark's CSVs and PNGs (from r["out"]) and write the page.  images_dir: where the PNGs are
    copied (docs/img/bench), None to link them where they are."""
    for r in results:
        folder = Path(r["out"])
        r["csvs"] = sorted(folder.glob("*.csv")) if folder.is_dir() else []
        r["images"] = []
        for png in sorted(folder.glob("*.png")) if folder.is_dir() else []:
            if images_dir is None:
                r["images"].append(os.path.relpath(png, page.parent))
            else:
                target = images_dir / f"{r['name']}-{png.name}"
                write_atomic(target, png.read_bytes())
                r["images"].append(os.path.relpath(target, page.parent))
    notes = notes_path.read_text() if notes_path.is_file() else ""
    write_atomic(page, update_sections(page, results, info, notes) if only else render_page(results, info, notes, quick))
    return page


def docs_dir() -> Path:
    """docs/ of the source checkout (this file is housingfe/benchmarks/all.py), else ./docs."""
    here = Path(__file__).resolve().parents[2] / "docs"
    return here if here.is_dir() else Path("docs")


def main(out_dir: Path, quick: bool = False, only: list[str] | None = None, notes_only: bool = False,
         resume: bool = False) -> None:
    """Run every benchmark (quick modes with `quick`) into out_dir/<name>/ and write the page (see module doc).
    only: run just these benchmarks and replace their sections of docs/benchmarks.md (full runs only).
    notes_only: run nothing, put the current docs/benchmarks-notes.md into docs/benchmarks.md (refresh_notes).
    Each finished benchmark is recorded in <out>.partial/runs.jsonl; resume: a benchmark an interrupted
    `bench all` finished (its folder still there) is not run again, and the one it was running resumes its
    own kept runs."""
    from housingfe.benchmarks._runs import FinishedRuns

    if notes_only:
        docs = docs_dir()
        page = docs / "benchmarks.md"
        write_atomic(page, refresh_notes(page, (docs / "benchmarks-notes.md").read_text()))
        print(f"bench all: notes of {page} refreshed from {docs / 'benchmarks-notes.md'} (no benchmark ran)")
        return
    out_dir = Path(out_dir)
    names = benchmarks()
    unknown = [n for n in (only or []) if n not in names]
    if unknown:
        from housingfe.errors import InputError

        raise InputError(f"bench all --only: unknown benchmark(s) {', '.join(unknown)} (available: {', '.join(names)})")
    out_dir.mkdir(parents=True, exist_ok=True)
    docs = docs_dir()
    results = []
    selected = [n for n in names if not only or n in only]
    finished = FinishedRuns("all", out_dir, {"names": selected, "quick": quick, "only": only}, len(selected),
                            resume=resume, unit="benchmarks")
    for name in [n for n in finished.done if not (out_dir / n).is_dir()]:
        del finished.done[name]          # its folder is gone: run it again
    try:
        for name in selected:
            if name not in finished.done:
                finished.write(f"bench all: {name} ({'quick' if quick else 'full'}) …")
            # resume passed only when asked: run_benchmark's plain signature stays what callers (tests) replace
            r = dict(finished.run(name, lambda: run_benchmark(name, out_dir / name, quick,
                                                              **({"resume": True} if resume else {})),
                                  note=name, keep=lambda r: r["exit"] == 0))
            r["out"] = out_dir / name
            finished.write(f"bench all: {name}: {'ok' if r['exit'] == 0 else 'FAILED, see ' + str(r.get('log'))} "
                           f"{r['wall_s']:.1f} s, {r['peak_gb']:.2f} GB, load {r['load_before']:.2f} -> "
                           f"{r['load_after']:.2f}")
            results.append(r)
    except BaseException as exc:
        finished.interrupted(exc)
        raise
    finished.close()
    failed = [r["name"] for r in results if r["exit"] != 0]
    info = machine_info()
    if quick or failed:
        page = publish(results, info, docs / "benchmarks-notes.md", out_dir / "benchmarks.md", None, quick)
    else:
        page = publish(results, info, docs / "benchmarks-notes.md", docs / "benchmarks.md", docs / "img" / "bench",
                       quick, only=bool(only))
    finished.finish()
    print(f"bench all: page written to {page}")
    if failed:
        raise SolverError(f"bench all: {len(failed)} benchmark(s) failed ({', '.join(failed)}); logs in {out_dir}; "
                          "docs/benchmarks.md left unchanged")
