"""`housingfe bench scenes`: cost of every housing scene of the library at its default accuracy, next to
its discretisation error.

Per scene, one process runs `housingfe run` (so wall time includes start-up, meshing, form compilation from
the cache, assembly, the eigensolve and the result files, and the peak memory is the process' own).
Error: the scene is run again with 1.5 x the elements per wavelength (mesh.elements_per_wavelength = 9
instead of 6); the error is the max and mean relative difference of the elastic eigenfrequencies below
0.9 f_max, paired by order, against that finer run (an estimate of the default mesh's error, not a
converged reference).  --quick: the default runs only, no error estimate.
"""
from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from housingfe.outputs import atomic_output_dir, format_table, write_csv

SCENES = ["box-supported", "box-supported-bc1", "box-supported-bc2", "box-supported-elastic", "box-halves",
          "box-halves-gasket", "gearbox-model", "gearbox-model-norim", "test-gearbox"]
QUICK_SCENES = ["box-supported", "gearbox-model"]
FINER = "mesh.elements_per_wavelength=9"

_CHILD = """
import json, resource, sys
from housingfe.run import run_scene
run_scene(sys.argv[1], sys.argv[2], sys.argv[3:])
print("PEAK_KB", resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
"""


def run_case(scene: str, overrides: list[str]) -> dict:
    """Run one scene in a fresh process; its modes.json plus the wall time and the peak memory."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "run"
        proc = subprocess.run([sys.executable, "-c", _CHILD, scene, str(out), *overrides], check=True,
                              capture_output=True, text=True)
        peak_kb = int(next(line.split()[1] for line in proc.stdout.splitlines() if line.startswith("PEAK_KB")))
        summary = json.loads((out / "modes.json").read_text())
    summary["peak_memory_gb"] = peak_kb / 1024**2
    return summary


def frequency_error(freqs, reference, f_limit: float) -> tuple[float, float]:
    """Max and mean relative difference of the eigenfrequencies below f_limit (Hz), paired by order."""
    ref = np.asarray(reference)
    ref = ref[ref < f_limit]
    n = min(len(ref), len(freqs))
    rel = np.abs(np.asarray(freqs[:n]) - ref[:n]) / ref[:n]
    return float(rel.max()), float(rel.mean())


HEADER = ["scene", "element", "DOFs", "mesh s", "assembly s", "eigensolve s", "wall s", "peak GB",
          "modes < f_max", "min quality", "max err vs finer", "mean err vs finer", "finer DOFs", "finer wall s"]


def main(out_dir: Path, quick: bool = False, resume: bool = False) -> None:
    """One row per scene (its default run, and a finer one unless quick); every finished run is kept in
    <out>.partial/ until the result folder is written; resume: re-use them."""
    from housingfe.benchmarks._runs import FinishedRuns

    scenes = QUICK_SCENES if quick else SCENES
    finished = FinishedRuns("scenes", out_dir, {"scenes": scenes, "quick": quick, "finer": FINER},
                            len(scenes) * (1 if quick else 2), resume=resume)
    try:
        rows = _rows(scenes, quick, finished)
    except BaseException as exc:
        finished.interrupted(exc)
        raise
    finished.close()
    with atomic_output_dir(out_dir) as tmp:
        write_csv(tmp / "bench-scenes.csv", HEADER, rows)
        (tmp / "bench-scenes.txt").write_text(format_table(HEADER, rows, "{:.3g}") + "\n")
        _plot(tmp / "bench-scenes.png", rows)
    finished.finish()
    print(format_table(HEADER, rows, "{:.3g}"))
    print(f"results: {out_dir}/")


def _rows(scenes: list[str], quick: bool, finished) -> list[list]:
    rows = []
    for scene in scenes:
        s = finished.run(f"{scene} default", lambda: run_case(scene, []), note=scene)
        t = s["timings_s"]
        eig = t.get("eigensolve_s", 0.0) + t.get("inertia_s", 0.0)
        row = [scene, s["element"], s["dofs"], t.get("mesh_s", float("nan")), t.get("assembly_s", float("nan")),
               eig, s["wall_time_s"], s["peak_memory_gb"], len(s["frequencies_hz"]), s["mesh_quality"]["min"]]
        if quick:
            row += [float("nan")] * 4
        else:
            fine = finished.run(f"{scene} finer", lambda: run_case(scene, [FINER]), note=f"{scene} finer")
            err_max, err_mean = frequency_error(s["frequencies_hz"], fine["frequencies_hz"], 0.9 * s["f_max_hz"])
            row += [err_max, err_mean, fine["dofs"], fine["wall_time_s"]]
        rows.append(row)
        finished.write(format_table(HEADER, [row], "{:.3g}", width=None).splitlines()[-1])
    return rows


def _plot(path: Path, rows: list) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4.5))
    for r in rows:
        ax.scatter(r[6], r[10] * 100 if r[10] == r[10] else 0.0, s=20 + r[2] / 1000)
        ax.annotate(r[0], (r[6], r[10] * 100 if r[10] == r[10] else 0.0), fontsize=7)
    ax.set_xlabel("wall time per scene (s), default accuracy")
    ax.set_ylabel("max eigenfrequency change vs 1.5x finer mesh (%)")
    ax.set_title("housing scenes: cost against discretisation error (marker size ~ DOFs)")
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
