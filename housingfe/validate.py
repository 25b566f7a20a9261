"""`housingfe validate`: our numbers next to the published ones, for every scene and module that has them.

Rows come from three places:
1. housing scenes with a [reference] (modal results): the rows `housingfe run` already put into
   modes.json, plus scene-specific rows made here (first three modes and empty 1/3-octave bands of the
   Sec. 4.5 gearbox model, the closest mode pair of Sec. 4.3, the gasket's effect on the eigenfrequencies
   of Sec. 4.4);
2. geometry reconstructions that can be checked without FE (Appendix E plate areas and perimeters);
3. other modules' `published_rows()` (bearings, and radiation/source once they provide one).

FE results are reused from `results/<scene>/modes.json` when that folder is newer than the scene file and
every source the modal result depends on (geometry/, solvers/, model.py, scene.py, run.py, materials.py,
published.py, data/); otherwise the scene is run (`housingfe run <scene> --out results/<scene>`,
in a subprocess) first.  A full validate on 2 cores takes a few minutes the first time, seconds afterwards.
"""
from __future__ import annotations

import csv
import importlib
import json
import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from housingfe.errors import InputError
from housingfe.published import THESIS, row, thesis
from housingfe.scene import builtin_scenes, load_housing_scene

RESULTS = Path("results")
PACKAGE = Path(__file__).parent
# the sources a modal result depends on: a result older than any of them is recomputed
MODAL_SOURCES = ("geometry", "solvers", "model.py", "scene.py", "run.py", "materials.py", "published.py", "data",
                 "interior.py", "coupling.py", "shafts.py", "bearings")
# the bearing-variant study (thesis Sec. 5.8, Fig. 5.18) and what its result depends on
VARIANT_SCENE = "test-gearbox-interior"
VARIANT_SOURCES = MODAL_SOURCES + ("forced_response.py", "response.py", "loads.py", "bearing_variants.py", "source")
# modules whose published_rows() join the table when they exist
ROW_PROVIDERS = ("housingfe.bearings.validation", "housingfe.radiation.validation", "housingfe.source.validation",
                 "housingfe.radiation", "housingfe.source", "housingfe.response", "housingfe.coupling")
# Appendix E tables that a gearbox scene's reconstruction is checked against
APPENDIX_E = {"gearbox-model": "scale_model", "test-gearbox": "test_gearbox"}


def main(out_dir: str | Path = "results/validate", json_path: str | Path | None = None,
         scenes: list[str] | None = None) -> list[dict]:
    """Collect the rows, print them, write validate.csv and validate.md to out_dir (and the JSON list of
    rows to json_path if given).  scenes: names or paths; default every built-in housing scene with a
    reference plus the other modules' rows."""
    t0 = time.perf_counter()
    names = scenes or default_scenes()
    rows: list[dict] = []
    modal: dict[str, dict] = {}
    for name in names:
        summary = modal_results(name)
        modal[summary["scene"]] = summary
        rows += summary.get("published", [])
        rows += scene_rows(summary["scene"], summary)
    rows += geometry_rows(names if scenes else list(APPENDIX_E))
    rows += joint_rows(modal)
    if not scenes:
        rows += bearing_variant_rows()
        rows += provider_rows()
    write_outputs(rows, Path(out_dir), json_path)
    print(format_rows(rows))
    print(f"{len(rows)} rows in {time.perf_counter() - t0:.0f} s; written to {out_dir}/validate.csv, validate.md"
          + (f" and {json_path}" if json_path else ""))
    return rows


def default_scenes() -> list[str]:
    """Built-in housing scenes that name published data."""
    out = []
    for name in builtin_scenes():
        try:
            scene, _ = load_housing_scene(name)
        except InputError:  # source scenes
            continue
        if scene.reference is not None:
            out.append(name)
    return out


def modal_results(name: str) -> dict:
    """modes.json of a scene: reused from results/<scene> when up to date, else computed first."""
    scene, path = load_housing_scene(name)
    folder = RESULTS / scene.scene.name
    if not is_up_to_date(folder, path):
        print(f"validate: running {scene.scene.name} (no up-to-date {folder}/modes.json)", flush=True)
        subprocess.run([sys.executable, "-m", "housingfe", "run", str(path), "--out", str(folder)], check=True,
                       stdout=subprocess.DEVNULL)
    with open(folder / "modes.json") as fh:
        return json.load(fh)


def is_up_to_date(folder: Path, scene_path: Path, result_name: str = "modes.json",
                  depends_on: tuple = MODAL_SOURCES) -> bool:
    """True if folder/result_name is newer than the scene file and every source in depends_on."""
    result = folder / result_name
    if not result.is_file():
        return False
    sources = [scene_path]
    for name in depends_on:
        p = PACKAGE / name
        sources += [f for f in p.rglob("*") if f.is_file()] if p.is_dir() else [p]
    newest = max(f.stat().st_mtime for f in sources if f.suffix in (".py", ".toml"))
    return result.stat().st_mtime >= newest


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
    src = f"{THESIS} [gearbox_model_empty]"
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
    src = f"{THESIS} [box_supported]"
    if len(freqs) < 2:
        return []
    spacing = np.diff(freqs) / freqs[:-1]
    i = int(np.argmin(spacing))
    return [row(scene, f"closest mode pair: relative spacing (ours {freqs[i]:.0f}/{freqs[i + 1]:.0f} Hz)",
                float(spacing[i]), (f_hi - f_lo) / f_lo, "-", src)]


def bearing_variant_rows() -> list[dict]:
    """Sec. 5.8 / Fig. 5.18: TF_omega of ball minus self-aligning bearings in the test gearbox (thesis FEM 7.3 dB
    mean, s.d. 4.5 dB).  Reuses results/bearing-variants-<scene>/variants.json when up to date, else runs
    `housingfe bearing-variants --configs ball self_aligning` first (about a minute)."""
    scene, path = load_housing_scene(VARIANT_SCENE)
    folder = RESULTS / f"bearing-variants-{scene.scene.name}"
    fresh = is_up_to_date(folder, path, "variants.json", VARIANT_SOURCES)
    if fresh:
        with open(folder / "variants.json") as fh:
            data = json.load(fh)
        fresh = {"self_aligning", "ball_zero_moment"} <= set(data["configurations"])
    if not fresh:
        print(f"validate: running the bearing-variant study ({folder}/variants.json is missing or stale)", flush=True)
        subprocess.run([sys.executable, "-m", "housingfe", "bearing-variants", "--scene", str(path), "--configs",
                        "ball", "self_aligning", "ball_zero_moment", "--out", str(folder)], check=True, stdout=subprocess.DEVNULL)
        with open(folder / "variants.json") as fh:
            data = json.load(fh)
    ref = thesis()["test_gearbox"]["bearings"]
    src = f"{THESIS} [test_gearbox.bearings], Fig. 5.18"
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
    src = f"{THESIS} [box_halves] (EMA with/without gasket)"
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


def provider_rows() -> list[dict]:
    """published_rows() of the modules that have one."""
    out = []
    for module_name in ROW_PROVIDERS:
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as exc:
            if exc.name and module_name.startswith(exc.name):
                continue
            raise
        if hasattr(module, "published_rows"):
            out += module.published_rows()
    return out


# ----------------------------------------------------------------------------------------------- output

COLUMNS = ("scene", "quantity", "ours", "published", "difference", "unit", "source")


def _fmt(value) -> str:
    if isinstance(value, float):
        return "nan" if math.isnan(value) else f"{value:.4g}"
    return str(value)


def _difference(r: dict) -> str:
    if "relative_difference" in r and r["unit"] != "-":
        return f"{r['difference']:+.4g} ({100 * r['relative_difference']:+.1f} %)"
    if "difference" in r:
        return f"{r['difference']:+.4g}"
    return ""


def format_rows(rows: list[dict]) -> str:
    """A plain-text table of the rows."""
    from housingfe.report import format_table

    return format_table(COLUMNS, [[r["scene"], r["quantity"], _fmt(r["ours"]), _fmt(r["published"]),
                                   _difference(r), r["unit"], r["source"]] for r in rows])


def write_outputs(rows: list[dict], out_dir: Path, json_path) -> None:
    """validate.csv and validate.md in out_dir; the list of rows as JSON in json_path."""
    out_dir.mkdir(parents=True, exist_ok=True)
    with open(out_dir / "validate.csv", "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(COLUMNS)
        for r in rows:
            writer.writerow([r["scene"], r["quantity"], r["ours"], r["published"], r.get("difference", ""),
                             r["unit"], r["source"]])
    lines = ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    for r in rows:
        lines.append("| " + " | ".join([r["scene"], r["quantity"], _fmt(r["ours"]), _fmt(r["published"]),
                                        _difference(r), r["unit"], r["source"]]) + " |")
    (out_dir / "validate.md").write_text("\n".join(lines) + "\n")
    if json_path:
        Path(json_path).parent.mkdir(parents=True, exist_ok=True)
        keys = ("scene", "quantity", "ours", "published", "unit", "source")
        with open(json_path, "w") as fh:
            json.dump([{k: _jsonable(r[k]) for k in keys} for r in rows], fh, indent=1)


def _jsonable(v):
    if isinstance(v, np.integer):
        return int(v)
    if isinstance(v, (float, np.floating)):
        return None if math.isnan(v) else float(v)   # JSON has no NaN
    return v
