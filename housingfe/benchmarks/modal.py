"""`housingfe bench modal`: speed against error of the free-box eigenmodes below 4 kHz, with CalculiX as peer.

Every case runs in its own process (so wall time includes start-up, meshing, form compilation from the
cache, assembly and the eigensolve, and peak memory is the case's own).  Error = max and mean relative
difference of all elastic eigenfrequencies below F_MAX against a converged reference (sorted order).

Reference: Q3 hexahedra (tri-cubic Lagrange), h = 10 mm, one layer through every wall, from this same
code (527 k DOFs); its own uncertainty is estimated from the next-coarser Q3 mesh (15 mm): the first
modes move by ~0.1 % between them (see docs/benchmarks.md).
CalculiX 2.20 (SPOOLES, the Debian build) solves the same gmsh block geometry with C3D20R / C3D20 / C3D10
elements, exported from the same gmsh model.
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from housingfe.outputs import atomic_output_dir, format_table, write_csv

F_MAX = 4000.0          # Hz, the range of the thesis' free-box study
SOLVE_TO = 1.08 * F_MAX  # solve a little beyond, so coarse meshes still deliver every reference mode
REFERENCE = {"code": "housingfe", "element": "hex", "degree": 3, "size": 0.010, "layers": 1}
# --quick is a smoke test (`housingfe bench all --quick` in minutes): its errors are against Q3 30 mm (~1 % off the
# reference above, 60 k DOFs) instead of the 527 k-DOF reference, which alone takes minutes and ~11 GB
QUICK_REFERENCE = {"code": "housingfe", "element": "hex", "degree": 3, "size": 0.030, "layers": 1}

HOUSINGFE_CASES = [
    {"element": "hex", "degree": 2, "size": 0.040, "layers": 1},
    {"element": "hex", "degree": 2, "size": 0.030, "layers": 1},
    {"element": "hex", "degree": 2, "size": 0.0234, "layers": 1},
    {"element": "hex", "degree": 2, "size": 0.015, "layers": 1},
    {"element": "hex", "degree": 2, "size": 0.0234, "layers": 2},
    {"element": "hex", "degree": 3, "size": 0.040, "layers": 1},
    {"element": "hex", "degree": 3, "size": 0.030, "layers": 1},
    {"element": "tet", "degree": 2, "size": 0.020, "layers": 1},
    {"element": "tet", "degree": 2, "size": 0.012, "layers": 1},
]
CALCULIX_CASES = [
    {"element": "hex", "ccx_type": "C3D20R", "size": 0.030, "layers": 1},
    {"element": "hex", "ccx_type": "C3D20R", "size": 0.0234, "layers": 1},
    {"element": "hex", "ccx_type": "C3D20R", "size": 0.015, "layers": 1},
    {"element": "hex", "ccx_type": "C3D20", "size": 0.0234, "layers": 1},
    {"element": "tet", "ccx_type": "C3D10", "size": 0.012, "layers": 1},
]
QUICK_HOUSINGFE = [HOUSINGFE_CASES[0], HOUSINGFE_CASES[2]]
QUICK_CALCULIX = [CALCULIX_CASES[1]]


# ----------------------------------------------------------------------------------------- one case
def run_housingfe_case(case: dict) -> dict:
    """Solve the free box with one discretisation in this process; returns timings and frequencies."""
    t0 = time.perf_counter()
    from mpi4py import MPI

    from housingfe.scene import build_model_from_scene, load_housing_scene
    from housingfe.solvers import modal

    overrides = [f"mesh.element=\"{case['element']}\"", f"mesh.degree={case['degree']}",
                 f"mesh.size={case['size']}", f"mesh.layers={case['layers']}",
                 f"analysis.modal.f_max={SOLVE_TO}"]
    scene, _ = load_housing_scene("box-free", overrides)
    model = build_model_from_scene(scene, MPI.COMM_WORLD)
    result = modal.solve_modes(model.K, model.M, SOLVE_TO)
    freqs = result.frequencies_hz[result.rigid_count:]
    return {"dofs": model.dofs, "frequencies_hz": freqs.tolist(), "complete": result.complete,
            "timings_s": {**model.timings, **result.timings}, "wall_s": time.perf_counter() - t0}


def run_calculix_case(case: dict, workdir: Path) -> dict:
    """Export the same gmsh geometry as an Abaqus/CalculiX deck and run ccx *FREQUENCY on it."""
    deck = workdir / "box.inp"
    n_nodes, n_elements = write_calculix_deck(case, deck)
    env = {**os.environ, "OMP_NUM_THREADS": "2", "CCX_NPROC_EQUATION_SOLVER": "2"}
    t0 = time.perf_counter()
    proc = subprocess.run(["ccx", "-i", "box"], cwd=workdir, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"ccx failed: {proc.stdout[-2000:]}")
    freqs = parse_calculix_frequencies(workdir / "box.dat")
    return {"dofs": 3 * n_nodes, "elements": n_elements, "frequencies_hz": freqs[freqs > 1.0].tolist(),
            "wall_s": wall, "complete": None}


def write_calculix_deck(case: dict, path: Path) -> tuple[int, int]:
    """The box-free geometry meshed by the housingfe block builder, as a ccx deck (nodes, elements, steel,
    *FREQUENCY up to SOLVE_TO).  Returns (nodes, elements)."""
    import gmsh

    from housingfe.geometry.blocks import build_gmsh_model
    from housingfe.geometry.mesh import block_model_for
    from housingfe.scene import load_housing_scene

    scene, _ = load_housing_scene("box-free")
    gmsh.initialize()
    try:
        gmsh.model.add("ccx")
        build_gmsh_model(block_model_for(scene.geometry), case["element"], case["size"], case["layers"])
        gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 1)  # 20-node hexes (C3D20/C3D20R)
        gmsh.model.mesh.setOrder(2)
        raw = path.with_suffix(".gmsh.inp")
        gmsh.write(str(raw))
    finally:
        gmsh.finalize()
    nodes, elements = _volume_part_of_inp(raw.read_text(), case["ccx_type"])
    m = scene.material.resolve()
    path.write_text(nodes + elements + (
        "*MATERIAL,NAME=STEEL\n*ELASTIC\n"
        f"{m.youngs_modulus:.6e},{m.poisson_ratio}\n*DENSITY\n{m.density}\n"
        "*SOLID SECTION,ELSET=EALL,MATERIAL=STEEL\n"
        f"*STEP\n*FREQUENCY,SOLVER=SPOOLES\n60,0.,{SOLVE_TO}\n*END STEP\n"))
    return nodes.count("\n") - 1, elements.count("\n") - elements.count("*")


def _volume_part_of_inp(text: str, ccx_type: str) -> tuple[str, str]:
    """Keep the node block and the 3-D element blocks of a gmsh INP file, all in ELSET EALL."""
    blocks = re.split(r"(?m)^(?=\*)", text)
    nodes = "".join(b for b in blocks if b.upper().startswith("*NODE"))
    elements = []
    for b in blocks:
        head, _, body = b.partition("\n")
        if head.upper().startswith("*ELEMENT") and "C3D" in head.upper():
            elements.append(f"*ELEMENT, TYPE={ccx_type}, ELSET=EALL\n{body}")
    return nodes, "".join(elements)


def parse_calculix_frequencies(dat: Path) -> np.ndarray:
    """Eigenfrequencies (Hz, column CYCLES/TIME) from a ccx .dat file."""
    freqs, reading = [], False
    for line in dat.read_text().splitlines():
        if "E I G E N V A L U E   O U T P U T" in line:
            reading, freqs = True, []
            continue
        if reading:
            parts = line.split()
            if len(parts) >= 4 and parts[0].isdigit():
                freqs.append(float(parts[3]))
            elif freqs and not parts:
                reading = False
    return np.array(freqs)


# ------------------------------------------------------------------------------------------ driver
def _case_in_subprocess(code: str, case: dict) -> dict:
    """Run one case in a fresh interpreter; also returns its peak resident memory (GB)."""
    with tempfile.TemporaryDirectory() as tmp:
        job = Path(tmp) / "job.json"
        job.write_text(json.dumps({"code": code, "case": case, "workdir": tmp}))
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, "-m", "housingfe.benchmarks.modal", str(job)],
                              capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if proc.returncode != 0:
            return {"error": proc.stderr.strip().splitlines()[-1] if proc.stderr.strip() else "failed",
                    "process_wall_s": wall}
        out = json.loads((Path(tmp) / "result.json").read_text())
        out["process_wall_s"] = wall
        return out


def _worker(job_path: str) -> None:
    import resource

    job = json.loads(Path(job_path).read_text())
    if job["code"] == "housingfe":
        out = run_housingfe_case(job["case"])
    else:
        out = run_calculix_case(job["case"], Path(job["workdir"]))
    self_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    child_kb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    out["peak_memory_gb"] = max(self_kb, child_kb) / 1024**2
    (Path(job["workdir"]) / "result.json").write_text(json.dumps(out))


def errors_against(reference: np.ndarray, freqs: list) -> tuple[float, float]:
    """Max and mean relative error of the first len(reference) frequencies (nan if too few)."""
    f = np.asarray(freqs)
    if len(f) < len(reference):
        return float("nan"), float("nan")
    rel = np.abs(f[:len(reference)] / reference - 1)
    return float(rel.max()), float(rel.mean())


def label(code: str, case: dict) -> str:
    if code == "calculix":
        return f"ccx {case['ccx_type']} h={case['size'] * 1e3:g}mm"
    order = {2: "Q2" if case["element"] == "hex" else "P2", 3: "Q3" if case["element"] == "hex" else "P3",
             1: "Q1" if case["element"] == "hex" else "P1"}[case["degree"]]
    return f"{order} {case['element']} h={case['size'] * 1e3:g}mm x{case['layers']}"


def main(out_dir: Path, quick: bool = False) -> None:
    """Run all cases, print the table, write modal_bench.csv and modal_bench.png."""
    ccx = shutil.which("ccx")
    reference = QUICK_REFERENCE if quick else REFERENCE
    ref_run = _case_in_subprocess("housingfe", reference)
    if "error" in ref_run:
        raise RuntimeError(f"reference run failed: {ref_run['error']}")
    ref = np.asarray(ref_run["frequencies_hz"])
    ref = ref[ref < F_MAX]
    rows = []
    cases = [("housingfe", c) for c in (QUICK_HOUSINGFE if quick else HOUSINGFE_CASES)]
    if ccx:
        cases += [("calculix", c) for c in (QUICK_CALCULIX if quick else CALCULIX_CASES)]
    for code, case in cases:
        res = _case_in_subprocess(code, case)
        if "error" in res:
            print(f"{label(code, case)}: failed: {res['error']}")
            continue
        emax, emean = errors_against(ref, res["frequencies_hz"])
        solve = res.get("timings_s", {}).get("eigensolve_s", float("nan"))
        rows.append([code, label(code, case), res["dofs"], res["process_wall_s"], solve,
                     res["peak_memory_gb"], emax * 100, emean * 100, len(res["frequencies_hz"])])
        print(f"{rows[-1][1]:32s} dofs {res['dofs']:8d}  wall {res['process_wall_s']:7.2f} s  "
              f"max err {emax * 100:6.3f} %", flush=True)
    header = ["code", "case", "dofs", "wall_s", "eigensolve_s", "peak_memory_gb", "max_error_pct",
              "mean_error_pct", "modes_returned"]
    with atomic_output_dir(out_dir) as tmp:
        write_csv(tmp / "modal_bench.csv", header, rows)
        (tmp / "reference.json").write_text(json.dumps({"case": reference, "dofs": ref_run["dofs"],
                                                        "wall_s": ref_run["process_wall_s"],
                                                        "frequencies_hz": ref.tolist()}, indent=1))
        _plot(tmp / "modal_bench.png", rows)
        table = format_table(header, rows)
        speedup = _speedup_at(rows, 1.0)
        ccx_best = min((r[6] for r in rows if r[0] == "calculix"), default=None)
        if ccx_best is not None:
            speedup += "\n" + _speedup_at(rows, ccx_best)
        (tmp / "modal_bench.txt").write_text(table + "\n" + speedup + "\n")
    print(f"reference: {label('housingfe', reference)}, {ref_run['dofs']} DOFs, {len(ref)} elastic modes "
          f"below {F_MAX:g} Hz, first {ref[0]:.2f} Hz")
    print(table)
    print(speedup)
    print(f"results: {out_dir}/")


def _speedup_at(rows: list, max_error_pct: float) -> str:
    """Fastest case of each code reaching max error <= max_error_pct, and the ratio of their wall times."""
    best = {}
    for r in rows:
        if r[6] <= max_error_pct and (r[0] not in best or r[3] < best[r[0]][3]):
            best[r[0]] = r
    if "housingfe" in best and "calculix" in best:
        h, c = best["housingfe"], best["calculix"]
        return (f"at <= {max_error_pct:g} % max error: housingfe {h[1]} {h[3]:.1f} s vs CalculiX {c[1]} "
                f"{c[3]:.1f} s -> {c[3] / h[3]:.1f}x faster")
    return f"at <= {max_error_pct:g} % max error: best per code: " + ", ".join(
        f"{k}: {v[1]} {v[3]:.1f} s" for k, v in best.items())


def _plot(path: Path, rows: list) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 5))
    for code, marker in (("housingfe", "o"), ("calculix", "s")):
        sel = [r for r in rows if r[0] == code]
        if sel:
            ax.loglog([r[3] for r in sel], [r[6] for r in sel], marker, label=code)
            for r in sel:
                ax.annotate(r[1].replace("ccx ", ""), (r[3], r[6]), fontsize=6, xytext=(3, 3),
                            textcoords="offset points")
    ax.axhline(1.0, color="grey", ls="--", lw=0.8)
    ax.set_xlabel("wall time per run (s, 2 cores)")
    ax.set_ylabel("max relative error of modes < 4 kHz (%)")
    ax.set_title("free box: speed against error")
    ax.grid(alpha=0.3, which="both")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    _worker(sys.argv[1])
