"""`housingfe validate`: our numbers next to the published ones, for every scene and module that has them.

Rows come from three places:
1. housing scenes with a [reference] and a modal analysis: the rows `housingfe run` already put into
   modes.json, plus scene-specific rows made here (first three modes and empty 1/3-octave bands of the
   Sec. 4.5 gearbox model, the closest mode pair of Sec. 4.3, the gasket's effect on the eigenfrequencies
   of Sec. 4.4) and the Sec. 5.8 bearing-variant study;
2. geometry reconstructions that can be checked without FE (Appendix E plate areas and perimeters);
3. the `published_rows()` of the row providers: every module housingfe/verification/<topic>_rows.py
   (ROW_PROVIDERS; today bearings, radiation, source).

FE results are cached in `<results>/<scene>/` (default `results/`).  A cached result is reused only when its
stamp `.validate-key` holds the same key: a sha256 of the resolved scene (after defaults and overrides) and
of the content of every housingfe source file the computation imported plus `housingfe/data/` (the list is
recorded by the run itself).  File modification times play no part, so a fresh clone, a `git checkout` or
touching an unrelated file reuses what is still valid, and any edit of a file the result depends on reruns it.

Every computation runs in a subprocess; a failure is reported as one line (the log of that run is kept in
`<results>/.validate-logs/`), the remaining rows are still collected and written, and the command exits
non-zero.  `--quick` is a subset for CI (see QUICK_SCENES and docs/verification.md).
"""
from __future__ import annotations

import csv
import hashlib
import importlib
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from housingfe.errors import InputError, SolverError
from housingfe.outputs import atomic_output_dir, dumps_json, reserve_output
from housingfe.scene import load_housing_scene
from housingfe.scenefile import builtin_scenes
from housingfe.verification.published import THESIS, row, thesis, thesis_source

RESULTS = Path("results")
OWN_FILES = ("validate.csv", "validate.md", "checks.csv", "checks.md")     # what --out holds (besides housingfe.outputs.MARKER)
PACKAGE = Path(__file__).resolve().parent.parent   # the housingfe package (this file is in verification/)
STAMP = ".validate-key"
# the bearing-variant study (thesis Sec. 5.8, Fig. 5.18) and the configurations it needs
VARIANT_SCENE = "test-gearbox-interior"
VARIANT_CONFIGS = ("ball", "self_aligning", "ball_zero_moment")
# Ch. 5 run-ups (housingfe.runup): the built-in scene and the overrides of each validated variant
DEFAULT_RUNUP = "test-gearbox-runup"          # the default chain of issue 28's checks
RUNUP_SCENES = ((DEFAULT_RUNUP, ()), ("test-gearbox-runup-double-helical", ()),
                ("test-gearbox-runup-double-helical", ("drivetrain.bearings=fluid_film",)))


def row_providers(package: str = "housingfe.verification") -> tuple[str, ...]:
    """The row providers: every module `<package>.<topic>_rows`, in name order.  Each must define
    published_rows() (tests/verification/test_validate.py checks it, and that no other module of the package
    defines one), so adding a provider is adding its module; a module that fails to import is reported as a
    failed provider by `provider_rows`, not silently dropped."""
    import pkgutil

    path = importlib.import_module(package).__path__
    return tuple(sorted(f"{package}.{m.name}" for m in pkgutil.iter_modules(path) if m.name.endswith("_rows")))


# modules whose published_rows() join the table (found by name, see row_providers)
ROW_PROVIDERS = row_providers()
# Appendix E tables that a gearbox scene's reconstruction is checked against
APPENDIX_E = {"gearbox-model": "scale_model", "test-gearbox": "test_gearbox"}
# `housingfe validate --quick` (CI): the small FE scenes and every row that needs no FE (providers, Appendix E
# geometry); the full run adds the other housing scenes and the bearing-variant study (docs/verification.md)
QUICK_SCENES = ("nafems-fv12", "box-free")


class ComputationFailed(Exception):
    """A subprocess of validate failed; the message is one line."""


# `housingfe validate --only NAME`: a subset computed alone, by the only_rows(results, quick, failures) of a row
# provider (found by name like the providers themselves)
ONLY = {"runup-checks": "housingfe.verification.runup_checks_rows"}


def main(out_dir: str | Path = "results/validate", json_path: str | Path | None = None,
         scenes: list[str] | None = None, quick: bool = False, results_dir: str | Path | None = None,
         only: str | None = None, bands: str | Path | None = None, workers: int = 1) -> list[dict]:
    """Collect the rows, print them, write validate.csv and validate.md to out_dir, and the check rows of issue 28
    (housingfe.verification.checks) to checks.csv and checks.md (and the JSON list of rows to json_path if
    given).  scenes: names or paths (only their rows); default every built-in housing scene with a reference and a
    modal analysis plus the other modules' rows; quick: the CI subset; only="runup-checks": the check rows of
    issue 28 alone (runup_checks_rows.only_rows).  results_dir: where FE results are cached (default results/).  bands: a JSON
    file {check_id: [low, high]} of the model's uncertainty bands, attached to the check rows (checks.attach_bands;
    without it every band is "—").  workers: how many of the stale FE computations run at once (each is its own
    subprocess; prefetch), default 1.  Raises SolverError (one line) after writing the table when a computation
    failed."""
    from housingfe.progress import Progress

    if only is not None and only not in ONLY:
        raise InputError(f"validate: --only: {only!r} is not one of {', '.join(ONLY)}")
    if only is not None and scenes:
        raise InputError("validate: --only and scene names: give one or the other")
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise InputError(f"validate: --workers: {workers!r} is not a whole number >= 1")
    from housingfe.verification.checks import attach_bands, read_bands

    band_table = read_bands(bands) if bands is not None else {}
    _FAILED.clear()         # a computation that failed in an earlier call is tried again

    t0 = time.perf_counter()
    results = Path(results_dir) if results_dir is not None else RESULTS
    if results.exists() and not results.is_dir():
        raise InputError(f"{results}: --results: is a file, not a folder (the folder of the cached FE results)")
    if json_path is not None:
        check_json_path(Path(json_path))
    if results.resolve() == Path(out_dir).resolve() or Path(out_dir).resolve() in results.resolve().parents:
        raise InputError(f"{out_dir}: --out: holds the FE result cache {results}/ (--results); give a folder of "
                         f"its own, e.g. {results}/validate")
    # checked and locked before minutes of computation; validate.csv and validate.md alone are an older
    # validate's output (written before result folders carried a marker)
    reserve_output(out_dir, own_files=OWN_FILES)
    if only is not None:
        failures: list[str] = []
        if workers > 1:
            prefetch(fe_results(None, results, quick, only=True), workers)
        rows = importlib.import_module(ONLY[only]).only_rows(results, quick, failures)
        attach_bands(rows, band_table)
        write_outputs(rows, Path(out_dir), json_path)
        from housingfe.verification.checks import checks_markdown

        print(checks_markdown(rows), end="")
        print(f"{len(rows)} check rows in {time.perf_counter() - t0:.0f} s; written to {out_dir}/checks.md, checks.csv, "
              "validate.csv, validate.md" + (f" and {json_path}" if json_path else ""))
        if failures:
            raise SolverError(f"validate: {len(failures)} computation(s) failed, their rows are missing: "
                              + "; ".join(failures))
        return rows
    names = scenes or default_scenes(quick)
    if scenes:
        from housingfe.scenefile import resolve_scene_path

        for name in scenes:     # a misspelt name stops here, not after a progress line (or the scenes before it)
            resolve_scene_path(name)
    rows: list[dict] = []
    failures: list[str] = []
    modal: dict[str, dict] = {}
    # steps: every scene (computed or taken from its up-to-date cache), the bearing-variant study and the run-up
    # scenes (full run), every row provider
    steps = len(names) + (0 if scenes else (0 if quick else 1 + len(RUNUP_SCENES)) + len(ROW_PROVIDERS))
    if workers > 1:
        prefetch(fe_results(names, results, quick, scenes_only=bool(scenes)), workers)
    progress = Progress("validate", steps, "steps")
    for name in names:
        try:
            summary = modal_results(name, results)
        except ComputationFailed as exc:
            failures.append(str(exc))
            continue
        finally:
            progress.update(note=name)
        if summary is None:
            continue
        modal[summary["scene"]] = summary
        rows += summary.get("published", [])
        rows += scene_rows(summary["scene"], summary)
    rows += geometry_rows(names if scenes else list(APPENDIX_E))
    rows += joint_rows(modal)
    if not scenes:
        if not quick:
            try:
                rows += bearing_variant_rows(results)
            except ComputationFailed as exc:
                failures.append(str(exc))
            progress.update(note="bearing variants")
            for name, overrides in RUNUP_SCENES:
                try:
                    rows += runup_rows(name, overrides, results)
                except ComputationFailed as exc:
                    failures.append(str(exc))
                progress.update(note=name)
        rows += provider_rows(failures, progress, results=results, quick=quick)
    progress.close()
    attach_bands(rows, band_table)
    write_outputs(rows, Path(out_dir), json_path)
    print(format_rows(rows))
    print(f"{len(rows)} rows in {time.perf_counter() - t0:.0f} s; written to {out_dir}/validate.csv, validate.md "
          "(sources and notes whole)"
          + (f" and {json_path}" if json_path else ""))
    if failures:
        raise SolverError(f"validate: {len(failures)} computation(s) failed, their rows are missing: "
                          + "; ".join(failures))
    return rows


def default_scenes(quick: bool = False) -> list[str]:
    """Built-in housing scenes that name published data and have a modal analysis (harmonic-only scenes write
    no modes.json); with quick, only QUICK_SCENES."""
    if quick:
        return list(QUICK_SCENES)
    out = []
    for name in builtin_scenes():
        try:
            scene, _ = load_housing_scene(name)
        except InputError:  # source scenes
            continue
        if scene.reference is not None and scene.analysis.modal is not None:
            out.append(name)
    return out


# ------------------------------------------------------------------------------------- cached computations

# Runs one computation in a fresh interpreter and records which housingfe files it imported: the cache key
# depends on exactly those.  Kept out of this module so that editing validate.py invalidates nothing.
_WORKER = r"""
import json, logging, sys
from pathlib import Path
job = json.loads(sys.argv[1])
logging.disable(logging.INFO)
from housingfe.errors import InputError, SolverError
from housingfe.outputs import dumps_json
try:
    if job["kind"] == "run":
        from housingfe.run import run_scene
        run_scene(job["scene"], out_dir=job["out"], overrides=job["overrides"])
    elif job["kind"] == "study":
        from housingfe.studies.design_variants import run_studies
        run_studies([tuple(j) for j in job["jobs"]], job["out"])
    else:
        from housingfe.studies.bearing_variants import run_study
        run_study(job["scene"], job["configs"], job["out"], job["overrides"])
except InputError as exc:
    print(f"input error: {exc}", file=sys.stderr); sys.exit(2)
except SolverError as exc:
    print(f"solver error: {exc}", file=sys.stderr); sys.exit(3)
package = Path(sys.modules["housingfe"].__file__).resolve().parent
files = {str(Path(m.__file__).resolve().relative_to(package)) for m in list(sys.modules.values())
         if getattr(m, "__file__", None) and Path(m.__file__).resolve().is_relative_to(package)}
Path(job["deps"]).write_text(json.dumps(sorted(files)))
"""


def dependency_files(recorded: list[str]) -> list[str]:
    """The files a result depends on: those its run imported (relative to the package) and housingfe/data/
    (published numbers, read as files)."""
    data = [str(p.relative_to(PACKAGE)) for p in sorted((PACKAGE / "data").rglob("*")) if p.is_file()]
    return sorted(set(recorded) | set(data))


def _sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def file_hashes(files) -> dict[str, str | None]:
    """sha256 of the content of each file (relative to the package); None for a file that no longer exists."""
    return {name: _sha((PACKAGE / name).read_bytes()) if (PACKAGE / name).is_file() else None
            for name in sorted(files)}


def scene_hash(scene, extra=None) -> str:
    """sha256 of the resolved scene (the pydantic model after defaults and overrides) and `extra` (JSON-able
    job options)."""
    return _sha(json.dumps([scene.model_dump(mode="json"), extra], sort_keys=True).encode())


def cache_key(scene, files, extra=None) -> str | None:
    """sha256 of the resolved scene, `extra` and the content of `files` (relative to the package); None when
    one of the files no longer exists."""
    hashes = file_hashes(files)
    if None in hashes.values():
        return None
    return _sha(json.dumps([scene_hash(scene, extra), hashes], sort_keys=True).encode())


def stale_reason(folder: Path, scene, result_name: str, extra=None) -> str | None:
    """None if folder/result_name can be reused (its stamp holds the current key), else why not."""
    stamp = folder / STAMP
    if not (folder / result_name).is_file():
        return f"no {result_name}"
    if not stamp.is_file():
        return f"no {STAMP} (computed outside validate)"
    try:
        stored = json.loads(stamp.read_text())
        if stored["key"] == cache_key(scene, stored["files"], extra):
            return None
        if stored.get("scene") != scene_hash(scene, extra):
            return "the scene changed"
        now = file_hashes(stored["files"])
        changed = [n for n, h in now.items() if h != stored["files"][n]]
        return "changed: " + ", ".join(changed[:5]) + (f" and {len(changed) - 5} more" if len(changed) > 5 else "")
    except (ValueError, KeyError, TypeError, AttributeError):
        return f"unreadable {STAMP}"


def is_up_to_date(folder: Path, scene, result_name: str, extra=None) -> bool:
    """True if folder/result_name exists and folder/.validate-key matches the current key."""
    return stale_reason(folder, scene, result_name, extra) is None


def write_stamp(folder: Path, scene, files, extra=None) -> None:
    """Record the key of a fresh result (and the parts it is made of, to say later what changed)."""
    stamp = {"key": cache_key(scene, files, extra), "scene": scene_hash(scene, extra), "files": file_hashes(files)}
    (folder / STAMP).write_text(json.dumps(stamp, indent=0))


def compute(job: dict, scene, folder: Path, results: Path, label: str, extra=None, reason: str = "") -> None:
    """Run `job` in a subprocess (the worker), then stamp the folder with the key of what it imported.
    Any failure -> ComputationFailed with one line; the full output is kept in <results>/.validate-logs/.  A
    computation that already failed in this process (in prefetch) is not run again: its failure is raised."""
    if folder.resolve() in _FAILED:
        raise _FAILED[folder.resolve()]
    logs = results / ".validate-logs"
    logs.mkdir(parents=True, exist_ok=True)
    log = logs / f"{folder.name}.log"
    deps = logs / f"{folder.name}.deps.json"
    deps.unlink(missing_ok=True)
    job = {**job, "out": str(folder), "deps": str(deps)}
    print(f"validate: computing {label} -> {folder}/" + (f" ({reason})" if reason else ""), flush=True)
    t0 = time.perf_counter()
    with open(log, "w") as fh:
        proc = subprocess.run([sys.executable, "-c", _WORKER, json.dumps(job)], stdout=fh,
                              stderr=subprocess.PIPE, text=True)
        fh.write(proc.stderr)
    if proc.returncode != 0 or not deps.is_file():
        lines = [line.strip() for line in proc.stderr.splitlines() if line.strip()]
        last = lines[-1] if lines else "no error message"
        _FAILED[folder.resolve()] = ComputationFailed(f"{label}: exit {proc.returncode}: {last} (log: {log})")
        raise _FAILED[folder.resolve()]
    files = dependency_files(json.loads(deps.read_text()))
    write_stamp(folder, scene, files, extra)
    print(f"validate: {label} done in {time.perf_counter() - t0:.0f} s", flush=True)


# result folder -> the ComputationFailed of its computation in this process (compute does not run it twice)
_FAILED: dict[Path, ComputationFailed] = {}


def fe_results(names: list[str] | None, results: Path, quick: bool = False, scenes_only: bool = False,
               only: bool = False) -> list:
    """The FE results a validate reads, as callables that compute each when stale (else cost nothing), the longest
    first.  Nothing heavier than the housing scenes `names` with quick or scenes_only; else also the run-ups
    (RUNUP_SCENES; with only, the default's alone), the bearing-variant study (not with only), and what each row
    provider declares in its optional `fe_results(results, quick)` -> [(seconds, callable)] (the design-variant
    study, the default run-up as made; `only`: the providers `--only runup-checks` reads).  The seconds are a rough
    cost, used for the order alone."""
    from functools import partial

    jobs = []
    if not (quick or scenes_only):
        runups = [(DEFAULT_RUNUP, ())] if only else list(RUNUP_SCENES)
        jobs += [(60.0, partial(runup_folder, name, overrides, results, quick)) for name, overrides in runups]
        if not only:
            jobs.append((60.0, partial(bearing_variant_folder, results)))
        providers = ("housingfe.verification.runup_checks_rows", "housingfe.verification.study_rows") if only \
            else ROW_PROVIDERS
        for module_name in providers:
            declared = getattr(importlib.import_module(module_name), "fe_results", None)
            jobs += declared(results, quick) if declared is not None else []
    jobs = [job for _, job in sorted(jobs, key=lambda j: -j[0])]       # stable: equal costs keep their order
    return jobs + [partial(modal_results, name, results) for name in (names or [])]


def prefetch(jobs: list, workers: int) -> None:
    """Run `jobs` (fe_results) `workers` at a time.  Each computation is its own subprocess (compute), so threads
    of concurrent.futures only start and wait on them; a failure is remembered (compute raises it again when the
    rows are collected, without re-running) and printed there, so here it is passed over."""
    from concurrent.futures import ThreadPoolExecutor

    t0 = time.perf_counter()
    with ThreadPoolExecutor(max_workers=workers) as pool:
        for future in [pool.submit(job) for job in jobs]:
            try:
                future.result()
            except (ComputationFailed, InputError, SolverError):
                pass
    print(f"validate: {len(jobs)} FE results up to date ({workers} at a time) in {time.perf_counter() - t0:.0f} s",
          flush=True)


def modal_results(name: str, results: Path | None = None) -> dict | None:
    """modes.json of a scene, reused from <results>/<scene> when its key matches, else computed first;
    None (with a note) for a scene without a modal analysis."""
    results = RESULTS if results is None else results
    scene, path = load_housing_scene(name)
    if scene.analysis.modal is None:
        print(f"validate: {scene.scene.name} has no modal analysis (harmonic only): no modal rows", flush=True)
        return None
    folder = results / scene.scene.name
    reason = stale_reason(folder, scene, "modes.json")
    if reason:
        compute({"kind": "run", "scene": str(path), "overrides": []}, scene, folder, results,
                f"housingfe run {scene.scene.name}", reason=reason)
    with open(folder / "modes.json") as fh:
        return json.load(fh)


# ------------------------------------------------------------------------------------- scene-specific rows


def scene_rows(scene: str, summary: dict) -> list[dict]:
    """Rows beyond modes.json's automatic ones."""
    freqs = np.asarray(summary["frequencies_hz"], dtype=float)
    if scene.startswith("gearbox-model") and "interior" not in scene:
        return gearbox_model_rows(scene, freqs)
    if scene.startswith("box-supported"):
        return close_pair_rows(scene, freqs)
    return []


def gearbox_model_rows(scene: str, freqs: np.ndarray) -> list[dict]:
    """Sec. 4.5: the first three elastic modes and the mode count of the sparse 1/3-octave bands."""
    from housingfe.levels import third_octave_bands

    data = thesis()["gearbox_model_empty"]
    src = thesis_source("gearbox_model_empty")
    out = [row(scene, f"elastic mode {i + 1} (thesis FEM)", float(freqs[i]), f, "Hz", src)
           for i, f in enumerate(data["fem_first_three_elastic_Hz"]) if i < len(freqs)]
    bands = third_octave_bands(300, 1300)
    counts = {int(n): int(np.sum((freqs >= lo) & (freqs < hi)))
              for n, lo, hi in zip(bands.nominal, bands.lower, bands.upper)}
    for nominal, expected in [(b, 1) for b in data["third_octave_bands_with_one_mode_Hz"]] + \
                             [(b, 0) for b in data["third_octave_bands_with_no_mode_Hz"]]:
        out.append(row(scene, f"modes in the {nominal} Hz 1/3-octave band", counts[int(nominal)], expected, "-",
                       src))
    return out


def close_pair_rows(scene: str, freqs: np.ndarray) -> list[dict]:
    """Sec. 4.3 mentions two modes almost coinciding at 1167/1176 Hz: our closest pair below 4 kHz."""
    f_lo, f_hi = thesis()["box_supported"]["fem_close_pair_Hz"]
    src = thesis_source("box_supported")
    if len(freqs) < 2:
        return []
    spacing = np.diff(freqs) / freqs[:-1]
    i = int(np.argmin(spacing))
    return [row(scene, f"closest mode pair: relative spacing (ours {freqs[i]:.0f}/{freqs[i + 1]:.0f} Hz)",
                float(spacing[i]), (f_hi - f_lo) / f_lo, "-", src)]


def bearing_variant_rows(results: Path | None = None) -> list[dict]:
    """Sec. 5.8 / Fig. 5.18: TF_omega of ball minus self-aligning bearings in the test gearbox (thesis FEM 7.3 dB
    mean, s.d. 4.5 dB).  Reuses <results>/bearing-variants-<scene>/variants.json when its key matches, else runs
    the study for VARIANT_CONFIGS first (a few minutes)."""
    scene, folder = bearing_variant_folder(results)
    with open(folder / "variants.json") as fh:
        data = json.load(fh)
    ref = thesis()["test_gearbox"]["bearings"]
    src = thesis_source("test_gearbox.bearings", "Fig. 5.18")
    out = []
    names = {"ball_zero_moment": "ball - ball with zero moment stiffness (the thesis' FEM)",
             "self_aligning": "ball - spherical roller (our self-aligning model)"}
    for r in data["differences"]:
        if r["configuration"] not in names or r["average"] not in ("surface", "8 points"):
            continue
        label = f"{names[r['configuration']]}, {'surface average' if r['average'] == 'surface' else '8 points'}"
        out.append(row(scene.scene.name, f"TF_omega {label}: mean over 320-600 Hz",
                       r["mean_dB_320_600Hz"], ref["fem_TF_ball_minus_self_aligning_mean_dB"], "dB", src))
        out.append(row(scene.scene.name, f"TF_omega {label}: s.d. over 320-600 Hz",
                       r["sd_dB_320_600Hz"], ref["fem_TF_ball_minus_self_aligning_sd_dB"], "dB", src))
    return out


def bearing_variant_folder(results: Path | None = None) -> tuple:
    """(scene, folder) of the bearing-variant study's cached result <results>/bearing-variants-<scene>/
    (variants.json), computed first when its key does not match (a few minutes)."""
    results = RESULTS if results is None else results
    scene, path = load_housing_scene(VARIANT_SCENE)
    folder = results / f"bearing-variants-{scene.scene.name}"
    extra = {"configs": list(VARIANT_CONFIGS)}
    reason = stale_reason(folder, scene, "variants.json", extra)
    if reason:
        compute({"kind": "bearing-variants", "scene": str(path), "configs": list(VARIANT_CONFIGS), "overrides": []},
                scene, folder, results, f"housingfe bearing-variants --scene {scene.scene.name}", extra, reason)
    return scene, folder


def runup_folder(name: str, overrides=(), results: Path | None = None, quick: bool = False) -> tuple[str, Path] | None:
    """(label, folder) of a run-up scene's cached result <results>/<label>/ (runup.json, runup.csv,
    runup_harmonics.csv), computed first when its key does not match (about a minute); with quick a stale result is
    not computed: None, and a note on the console."""
    from housingfe.runup.scene import load_runup_scene

    results = RESULTS if results is None else results
    scene, path = load_runup_scene(name, list(overrides))
    housing, _ = load_housing_scene(scene.housing.scene, list(scene.housing.set))
    label = scene.scene.name + "".join(f"-{o.split('=', 1)[1]}" for o in overrides)
    folder = results / label
    extra = {"overrides": list(overrides), "housing": housing.model_dump(mode="json")}
    reason = stale_reason(folder, scene, "runup.json", extra)
    if reason:
        if quick:
            print(f"validate: {label} rows left out with --quick (no valid cached {folder}/: {reason}; "
                  "`housingfe validate` computes it)", flush=True)
            return None
        compute({"kind": "run", "scene": str(path), "overrides": list(overrides)}, scene, folder, results,
                f"housingfe run {name}" + "".join(f" --set {o}" for o in overrides), extra, reason)
    return label, folder


def runup_rows(name: str, overrides=(), results: Path | None = None, quick: bool = False) -> list[dict]:
    """Ch. 5 checks of a run-up scene (housingfe.runup.checks: L_WA maximum, resonant speeds, speed and torque
    laws, L_omega in the tooth band) as validate rows; runup.json reused when its key matches, else computed
    (about a minute; not with quick: no rows).  The default scene's rows that are checks of issue 28 carry their
    check_id (tag_default_runup)."""
    found = runup_folder(name, overrides, results, quick)
    if found is None:
        return []
    label, folder = found
    with open(folder / "runup.json") as fh:
        data = json.load(fh)
    return run_check_rows(label, data["checks"], tagged=name == DEFAULT_RUNUP and not overrides)


def run_check_rows(label: str, run_checks: list[dict], tagged: bool = True) -> list[dict]:
    """Validate rows of a run-up's checks (runup.json "checks", or housingfe.runup.checks.evaluate); tagged: the
    default run-up's, whose rows that are checks of issue 28 carry their check_id (tag_default_runup).  The
    Monte-Carlo of `housingfe uncertainty` calls this on each sample's run."""
    src = thesis_source("test_gearbox", "Ch. 5")
    out = []
    for c in run_checks:
        ours, published = c["ours"], c["measured"]
        note = "; ".join(x for x in (f"goal: {c['goal']}" if c["goal"] else "",
                                     f"passed: {c['passed']}" if c["passed"] else "",
                                     f"thesis calculated {c['thesis_calculated']}" if c["thesis_calculated"]
                                     is not None else "", c["note"]) if x)
        unit = "rpm" if c["check"] in ("resonant_speeds", "L_omega_resonance") else "dB(A)" if c["check"] in (
            "LwA_max", "speed_law", "torque_law") else "dB"
        r = row(label, c["quantity"], ours, published, unit, src, note)
        if tagged:
            tag_default_runup(r, c, run_checks)
        out.append(r)
    return out


def tag_default_runup(r: dict, c: dict, run_checks: list[dict] = ()) -> dict:
    """Give a row of the default run-up (test-gearbox-runup) its issue-28 check_id where it is one: the L_WA
    maximum per route, the speed law per route, L_omega on the flexible housing at 500/1000/1500 rpm and where its
    resonance lies.  c: the run's check (runup.json "checks"); run_checks: all of them (the L_WA maximum's row says
    how far the route's excitation, L_omega in the tooth band, is from the measured one)."""
    from housingfe.verification.checks import tag

    route = c["quantity"].split(":", 1)[0]
    common = {"measured": c["measured"], "thesis_calculated": c["thesis_calculated"], "passed": c["passed"]}
    if c["check"] == "LwA_max":
        # the route's excitation: tf_omega multiplies the rigid-bore source's L_omega, mesh_force drives the coupled
        # model with the source on the flexible housing
        kind = "L_omega" if route == "tf_omega" else "L_omega_flexible"
        gaps = [x["ours"] - x["measured"] for x in run_checks if x["check"] == kind
                and isinstance(x["ours"], (int, float)) and isinstance(x["measured"], (int, float))]
        which = "rigid-bore source" if kind == "L_omega" else "flexible housing"
        why = (f"the route's excitation, L_omega in the tooth band ({which}), is {np.mean(gaps):+.1f} dB from the "
               f"measured (mean over the measured speeds 500/1000/1500 rpm the run has: {len(gaps)})") if gaps else ""
        target = next((x for x in run_checks if x["check"] == "te_target" and x["quantity"].startswith(f"{route}:")),
                      None)
        if target is not None:
            why += ("; " if why else "") + (f"a tooth-frequency TE of {target['ours']} um would make the measured "
                                            f"maximum through this chain ({target['note'].split(' (')[0]})")
        tag(r, f"28.default.max_lwa.{route}", tolerance="3 dB", why=why, **common)
    elif c["check"] == "speed_law":
        tag(r, f"28.speed_law.{route}", tolerance="2 dB", why=c["note"].split("; total")[0], **common)
    elif c["check"] == "L_omega_flexible":
        speed = c["quantity"].rsplit(" at ", 1)[1].split()[0]
        rigid = next((x["ours"] for x in run_checks if x["check"] == "L_omega"
                      and x["quantity"].endswith(f" at {speed} rpm")), None)
        why = c["note"]
        if isinstance(rigid, (int, float)) and isinstance(c["ours"], (int, float)):
            why = (f"the rigid-bore source gives {rigid:.1f} dB here: the flexible housing moves it by "
                   f"{c['ours'] - rigid:+.1f} dB; {why}")
        tag(r, f"28.l_omega.flexible.{speed}rpm", tolerance="6 dB", why=why, **common)
    elif c["check"] == "L_omega_resonance":
        tag(r, "28.l_omega.resonance", tolerance="moved from the rigid-bore source's towards 1500 rpm",
            why=c["note"], **common)
    return r


def joint_rows(modal: dict[str, dict]) -> list[dict]:
    """Sec. 4.4: the paper gasket changed the measured eigenfrequencies by at most 3 %, 1 % on average.
    Ours: box-halves-gasket against box-halves, modes paired by order (valid while no modes swap)."""
    if "box-halves" not in modal or "box-halves-gasket" not in modal:
        return []
    a = np.asarray(modal["box-halves"]["frequencies_hz"])
    b = np.asarray(modal["box-halves-gasket"]["frequencies_hz"])
    n = min(len(a), len(b))
    change = np.abs(b[:n] - a[:n]) / a[:n]
    data = thesis()["box_halves"]
    src = thesis_source("box_halves", "EMA with/without gasket")
    return [row("box-halves-gasket", "gasket: max relative eigenfrequency change", float(change.max()),
                data["gasket_eigenfrequency_change_max"], "-", src),
            row("box-halves-gasket", "gasket: mean relative eigenfrequency change", float(change.mean()),
                data["gasket_eigenfrequency_change_mean"], "-", src)]


def geometry_rows(names: list[str]) -> list[dict]:
    """Appendix E plate areas and perimeters of the reconstructed gearboxes against the table."""
    from housingfe.geometry.housings import appendix_e_plates, appendix_e_total_area

    out = []
    for name in names:
        scene, _ = load_housing_scene(name)
        table_name = APPENDIX_E.get(scene.scene.name)
        if table_name is None or scene.geometry.kind != "gearbox":
            continue
        table = thesis()["radiation"][table_name]
        src = f"{THESIS}, Appendix E [{table_name}]"
        ours = appendix_e_plates(scene.geometry)
        for plate, count, S, U, h, _ in table["plates"]:
            if plate not in ours:
                continue
            out.append(row(scene.scene.name, f"plate '{plate}' area", ours[plate][0], S, "m2", src))
            out.append(row(scene.scene.name, f"plate '{plate}' perimeter", ours[plate][1], U, "m", src))
        table_total = math.fsum(r[1] * r[2] for r in table["plates"])
        out.append(row(scene.scene.name, "total plate area (Appendix E sum)", appendix_e_total_area(scene.geometry),
                       table_total, "m2", src))
        if table_name == "scale_model":
            out.append(row(scene.scene.name, "total surface (Sec. 4.7, L_S = -3.9 dB)",
                           appendix_e_total_area(scene.geometry), thesis()["gearbox_model_empty"]["surface_area_m2"],
                           "m2", f"{THESIS}, Sec. 4.7"))
    return out


def provider_rows(failures: list[str] | None = None, progress=None, *, results: Path | None = None,
                  quick: bool = False) -> list[dict]:
    """published_rows() of every module in ROW_PROVIDERS; a provider whose published_rows takes `results` (the FE
    result cache) and `quick` (validate --quick: compute nothing heavy) gets them, and one that takes `failures` the
    list, to report a part of its rows lost without losing the rest.  A provider that fails is
    reported on one line (appended to `failures`, or raised as SolverError when no list is given); the others
    still count.  progress: a housingfe.progress.Progress counting one step per provider."""
    import inspect

    out = []
    for module_name in ROW_PROVIDERS:
        try:
            t0 = time.perf_counter()
            provide = importlib.import_module(module_name).published_rows
            accepted = inspect.signature(provide).parameters
            options = {k: v for k, v in (("results", results), ("quick", quick), ("failures", failures))
                       if k in accepted}
            rows = provide(**options)
            print(f"validate: {module_name}: {len(rows)} rows in {time.perf_counter() - t0:.1f} s", flush=True)
            out += rows
        except Exception as exc:  # noqa: BLE001 - reported on one line, the exit code says it failed
            message = f"{module_name}.published_rows(): {type(exc).__name__}: {exc}".replace("\n", " ")
            if failures is None:
                raise SolverError(message) from exc
            print(f"validate: failed: {message}", file=sys.stderr, flush=True)
            failures.append(message)
        finally:
            if progress is not None:
                progress.update(note=module_name.rsplit(".", 1)[-1])
    return out


# ----------------------------------------------------------------------------------------------- output

COLUMNS = ("scene", "quantity", "ours", "published", "difference", "unit", "source", "note")


def _fmt(value) -> str:
    if value is None:
        return "-"          # a published number we do not reproduce (the note says why)
    if isinstance(value, float):
        return "nan" if math.isnan(value) else f"{value:.4g}"
    return str(value)


def _difference(r: dict) -> str:
    if "relative_difference" in r and r["unit"] not in ("-", "dB", "dB(A)"):   # % of a level means nothing
        return f"{r['difference']:+.4g} ({100 * r['relative_difference']:+.1f} %)"
    if "difference" in r:
        return f"{r['difference']:+.4g}"
    return ""


def _cells(r: dict) -> list[str]:
    return [r["scene"], r["quantity"], _fmt(r["ours"]), _fmt(r["published"]), _difference(r), r["unit"], r["source"],
            r.get("note", "")]


def format_rows(rows: list[dict], width: int = 120) -> str:
    """A plain-text table of the rows for a terminal, at most `width` characters wide: the numbers whole, the
    source and note shortened with "…" where they would not fit (validate.md and validate.csv hold them whole)."""
    from housingfe.outputs import format_table

    cells = [_cells(r) for r in rows]
    numbers = [c[:6] for c in cells]
    fixed = [max([len(COLUMNS[i])] + [len(c[i]) for c in numbers]) for i in range(6)]
    room = width - sum(fixed) - 2 * 6    # what is left for "source  note" (two column gaps)
    source_w = max(len("source"), min(max((len(c[6]) for c in cells), default=0), room // 3))
    note_w = max(len("note"), room - source_w - 2)

    def cut(text: str, n: int) -> str:
        return text if len(text) <= n else text[:n - 1] + "…"

    return format_table(COLUMNS, [c[:6] + [cut(c[6], source_w), cut(c[7], note_w)] for c in cells], width=width)


def check_json_path(path: Path) -> None:
    """InputError, before any computation, unless --json `path` can be written as a file (its missing folders
    are made)."""
    if path.is_dir():
        raise InputError(f"{path}: --json: is a folder; give a file name, e.g. {path / 'validate.json'}")
    place = path.parent
    while not place.exists() and place != place.parent:
        place = place.parent
    if not place.is_dir():
        raise InputError(f"{path}: --json: {place} is a file, not a folder")
    if not os.access(place, os.W_OK):
        raise InputError(f"{path}: --json: cannot write in {place}")


def write_outputs(rows: list[dict], out_dir: Path, json_path) -> None:
    """validate.csv and validate.md in out_dir; the list of rows as JSON in json_path.  In the CSV an empty
    `ours` is a published number we do not reproduce (see `note`).  out_dir is written atomically (a result
    folder: housingfe.outputs)."""
    with atomic_output_dir(out_dir) as tmp:
        with open(tmp / "validate.csv", "w", newline="") as fh:
            writer = csv.writer(fh)
            writer.writerow(COLUMNS)
            for r in rows:
                writer.writerow([r["scene"], r["quantity"], _csv(r["ours"]), _csv(r["published"]),
                                 r.get("difference", ""), r["unit"], r["source"], r.get("note", "")])
        lines = ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
        for r in rows:
            lines.append("| " + " | ".join(c.replace("|", "/") for c in _cells(r)) + " |")
        (tmp / "validate.md").write_text("\n".join(lines) + "\n")
        from housingfe.verification.checks import write_checks

        write_checks(rows, tmp)
    if json_path:
        Path(json_path).parent.mkdir(parents=True, exist_ok=True)
        keys = ("scene", "quantity", "ours", "published", "unit", "source", "note")
        check_keys = ("check_id", "measured", "thesis_calculated", "tolerance", "passed", "why", "band",
                      "band_passes", "band_note")
        with open(json_path, "w") as fh:
            fh.write(dumps_json([{k: _jsonable(r.get(k, "")) for k in keys + (check_keys if r.get("check_id") else ())}
                                 for r in rows], indent=1))


def _csv(v):
    return "" if v is None or (isinstance(v, float) and math.isnan(v)) else v


def _jsonable(v):
    if isinstance(v, np.integer):
        return int(v)
    if isinstance(v, (float, np.floating)):
        return None if math.isnan(v) else float(v)   # JSON has no NaN
    return v
