"""`housingfe bench imported`: an imported (STEP) housing meshed for 4 kHz: housingfe on 1 and 2 ranks against
CalculiX (C3D10 on the very same mesh), the Craig–Bampton export beside the modal solve, and import + inspect.

The housing: the package's test gearbox (565 x 300 x 375 mm, 10 mm walls, two bores of 170 mm) written to STEP
by its own OpenCASCADE model (housingfe.geometry.cad.write_step, metres) and read back as geometry kind "cad",
P2 on gmsh's linear tetrahedra of mesh.size (full: 13.5 mm, 257 k DOFs; --quick: 60 mm, 28 k; --size MM: 11.5 mm
367 k; ~7.5 mm for 1 M, extrapolated).  --cases picks a subset of CASE_KEYS, --rounds the number of interleaved rounds.

Cases, each in its own process (wall time includes start-up, import, meshing, assembly, solve; peak memory is the
process's own, summed over ranks):
- housingfe modes to 4 kHz with the inertia count (complete or not) on 1 rank and on 2 ranks (mpirun -n 2);
- CalculiX 2.20 (*FREQUENCY, SPOOLES, 2 threads) on a deck of C3D10 elements written from the mesh housingfe
  solved (gmsh's tetrahedra plus their straight edge midpoints: P2 on straight tets and C3D10 are the same
  element geometry); 3 x nodes must equal housingfe's DOFs (checked);
- `housingfe reduce` (Craig–Bampton at the two bore masters, fixed-interface modes to 4 kHz) on 1 rank;
- `housingfe inspect` of the STEP file.
The cases run interleaved, round after round (REPEATS; --quick: 1), with the 1-minute load average before each;
min / median / max wall time.  Error: CalculiX against housingfe on the same mesh (max relative difference of the
elastic modes below 4 kHz; they differ only in the mass integration) -- not a discretisation error: the
converged reference of this geometry is not computed here (see docs/imported-bench.md).
"""
from __future__ import annotations

import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from housingfe.benchmarks._calculix import run_calculix
from housingfe.benchmarks._launch import mpi_environment, run_worker, write_worker_result
from housingfe.benchmarks.modal import load_average
from housingfe.errors import InputError
from housingfe.outputs import atomic_output_dir, format_table, write_csv

F_MAX = 4000.0          # Hz
SIZE = 0.0135           # m: ~0.3 M P2 DOFs on the test gearbox (30 mm: 61 k)
QUICK_SIZE = 0.06       # m: ~25 k DOFs
REPEATS = 2             # interleaved rounds (--quick: 1)
HOLES, QUICK_HOLES = 1250, 200    # bolt holes of the synthetic housing inspected: 5.1 MB, 0.83 MB of STEP


# ------------------------------------------------------------------------------------------ inputs
def write_inputs(folder: Path, size: float) -> dict:
    """The test gearbox as STEP (m) and a free-free cad scene on it with its two bores as selectors; returns
    the paths."""
    from housingfe.geometry.cad import write_step
    from housingfe.scene import load_housing_scene

    geometry = load_housing_scene("test-gearbox")[0].geometry
    step = write_step(geometry, folder / "gearbox.step")
    bores = "\n".join(
        f"[[geometry.bores]]\nname = \"{b.name}\"\naxis = [0, 1, 0]\ncentre = [{b.x}, 0, {geometry.split_height}]\n"
        for b in geometry.bores)
    scene = folder / "gearbox-cad.toml"
    scene.write_text(
        "[scene]\nname = \"gearbox-cad\"\nkind = \"housing\"\n"
        "[geometry]\nkind = \"cad\"\nfile = \"gearbox.step\"\nunits = \"m\"\n" + bores +
        f"[mesh]\nelement = \"tet\"\ndegree = 2\nsize = {size}\n"
        f"[analysis.modal]\nf_max = {F_MAX}\n"
        "[output]\nmode_pictures = 0\nparaview = false\npictures = false\n")
    return {"step": str(step), "scene": str(scene)}


def write_bolted_housing(path: Path, holes: int) -> Path:
    """A synthetic cast-housing-like STEP file (mm) for the import + inspect timing: an open box 600 x 300 x
    400 mm with 15 mm walls and `holes` bolt holes of 8 mm through its floor (1250 holes: 5.1 MB, the issue's
    "5 MB STEP file")."""
    import math

    from housingfe.geometry.cad import _native_output_captured, gmsh_session

    with gmsh_session() as gmsh:
        occ = gmsh.model.occ
        gmsh.model.add("bolted")
        outer = occ.addBox(0, 0, 0, 600, 300, 400)
        occ.cut([(3, outer)], [(3, occ.addBox(15, 15, 15, 570, 270, 400))])
        nx = int(math.sqrt(2 * holes))
        ny = max(1, holes // nx)
        tools = [(3, occ.addCylinder(30 + i * 540 / max(nx - 1, 1), 30 + j * 240 / max(ny - 1, 1), -5, 0, 0, 30,
                                     4)) for i in range(nx) for j in range(ny)]
        occ.cut([(3, outer)], tools)
        occ.synchronize()
        with _native_output_captured():
            gmsh.write(str(path))
    return path


# ----------------------------------------------------------------------------------------- one case
def run_housingfe_case(scene_path: str) -> dict:
    """Free modes to F_MAX of the scene in this process (all its ranks): DOFs, elastic frequencies, the inertia
    count's verdict, timings."""
    t0 = time.perf_counter()
    from mpi4py import MPI

    from housingfe.scene import build_model_from_scene, load_housing_scene
    from housingfe.solvers import modal

    scene, _ = load_housing_scene(scene_path)
    model = build_model_from_scene(scene, MPI.COMM_WORLD)
    null = modal.known_null_space(model)
    result = modal.solve_modes(model.K, model.M, F_MAX, null_space=null)
    freqs = result.frequencies_hz[result.rigid_count:]
    return {"dofs": model.dofs, "frequencies_hz": freqs.tolist(), "rigid": int(result.rigid_count),
            "complete": bool(result.complete), "timings_s": {**model.timings, **result.timings},
            "wall_s": time.perf_counter() - t0}


def write_c3d10_deck(scene_path: str, deck: Path, modes: int) -> dict:
    """Mesh the scene's CAD housing as housingfe does (one rank) and write it as a CalculiX deck of C3D10
    elements (corner nodes + straight edge midpoints), steel of the scene, *FREQUENCY for `modes` modes up to
    F_MAX.  Returns nodes, elements, vertices, edges."""
    from mpi4py import MPI

    from housingfe.fe.model import element_size
    from housingfe.geometry import build_mesh
    from housingfe.scene import load_housing_scene

    scene, _ = load_housing_scene(scene_path)
    size = element_size(scene.mesh, scene.geometry, F_MAX, scene.material.resolve())
    housing = build_mesh(scene.geometry, "tet", size, 1, MPI.COMM_SELF)
    mesh = housing.mesh
    x = mesh.geometry.x
    cells = mesh.geometry.dofmap.array.reshape(-1, 4)
    # C3D10 node order: corners 1-4, then midpoints of 1-2, 2-3, 3-1, 1-4, 2-4, 3-4
    pairs = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]
    ends = np.sort(np.stack([cells[:, [a, b]] for a, b in pairs], axis=1).reshape(-1, 2), axis=1)
    edges, edge_of = np.unique(ends, axis=0, return_inverse=True)
    mid = 0.5 * (x[edges[:, 0]] + x[edges[:, 1]])
    nodes = np.vstack([x, mid])
    conn = np.hstack([cells, len(x) + edge_of.reshape(-1, 6)]) + 1
    m = scene.material.resolve()
    with open(deck, "w") as fh:
        fh.write("*NODE, NSET=NALL\n")
        np.savetxt(fh, np.column_stack([np.arange(1, len(nodes) + 1), nodes]), fmt="%d,%.12e,%.12e,%.12e")
        fh.write("*ELEMENT, TYPE=C3D10, ELSET=EALL\n")
        np.savetxt(fh, np.column_stack([np.arange(1, len(conn) + 1), conn]), fmt="%d", delimiter=",")
        fh.write("*MATERIAL,NAME=STEEL\n*ELASTIC\n"
                 f"{m.youngs_modulus:.6e},{m.poisson_ratio}\n*DENSITY\n{m.density}\n"
                 "*SOLID SECTION,ELSET=EALL,MATERIAL=STEEL\n"
                 f"*STEP\n*FREQUENCY,SOLVER=SPOOLES\n{modes},0.,{F_MAX}\n*END STEP\n")
    return {"nodes": len(nodes), "elements": len(conn), "vertices": len(x), "edges": len(edges)}


def run_calculix_case(deck: str, workdir: Path) -> dict:
    """ccx on a copy of the deck (2 threads); elastic frequencies (> 1 Hz) and wall time."""
    shutil.copy(deck, workdir / "housing.inp")
    freqs, wall = run_calculix(workdir, "housing")
    return {"frequencies_hz": freqs.tolist(), "wall_s": wall}


def _subprocess(cmd: list[str], cwd: str | None = None) -> tuple[float, int, str]:
    """Run a command; (wall s, peak RSS of the command's processes in GB, stderr tail)."""
    t0 = time.perf_counter()
    proc = subprocess.run(["/usr/bin/time", "-f", "MAXRSS %M"] + cmd, capture_output=True, text=True,
                          env=mpi_environment(), cwd=cwd)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(proc.stderr.strip().splitlines()[-1] if proc.stderr.strip() else "failed")
    rss = [line for line in proc.stderr.splitlines() if line.startswith("MAXRSS")]
    return wall, int(rss[-1].split()[1]) / 1024**2 if rss else float("nan"), proc.stdout


def _case(kind: str, job: dict) -> dict:
    """One case in a fresh interpreter (ranks from job); adds process wall time and peak memory (GB)."""
    with tempfile.TemporaryDirectory(prefix="bench-imported-") as tmp:
        if kind == "reduce":
            wall, rss, _ = _subprocess([sys.executable, "-m", "housingfe", "reduce", job["scene"], "--cutoff",
                                      str(F_MAX), "--master", "bore_pinion", "--master", "bore_wheel", "--out", str(Path(tmp) / "reduced")])
            summary = json.loads((Path(tmp) / "reduced" / "summary.json").read_text())
            return {"process_wall_s": wall, "peak_memory_gb": rss, "summary": summary}
        if kind == "inspect":
            wall, rss, out = _subprocess([sys.executable, "-m", "housingfe", "inspect", job["bolted"], "--units",
                                          "mm", "--out", tmp])
            return {"process_wall_s": wall, "peak_memory_gb": rss, "report_tail": out.strip().splitlines()[-1]}
        out, _, last = run_worker("housingfe.benchmarks.imported", {"kind": kind, **job}, Path(tmp),
                                  job.get("ranks", 1))
        if out is None:
            if "InputError: " in last:       # the case refused its input (e.g. the memory guard): say so in one line
                raise InputError(f"bench imported: case {kind}: {last.split('InputError: ', 1)[1]}")
            raise RuntimeError(last)
        return out


def _worker(job_path: str) -> None:
    job = json.loads(Path(job_path).read_text())
    if job["kind"] == "housingfe":
        out = run_housingfe_case(job["scene"])
    elif job["kind"] == "deck":
        out = write_c3d10_deck(job["scene"], Path(job["deck"]), job["modes"])
    else:
        out = run_calculix_case(job["deck"], Path(job["workdir"]))
    write_worker_result(out, job["workdir"])


# ------------------------------------------------------------------------------------------ driver
CASES = [("housingfe", {"ranks": 1}), ("calculix", {}), ("housingfe", {"ranks": 2}), ("reduce", {}),
         ("inspect", {})]
CASE_KEYS = ("housingfe1", "calculix", "housingfe2", "reduce", "inspect")     # --cases names, in CASES' order


def label(kind: str, job: dict) -> str:
    return {"housingfe": f"housingfe P2 {job.get('ranks', 1)} rank(s)", "calculix": "ccx C3D10 (2 threads)",
            "reduce": "housingfe reduce (CB, 1 rank)", "inspect": "housingfe inspect"}[kind]


def selected_cases(cases: list[str] | None) -> list[tuple[str, dict]]:
    """The (kind, job) of the named cases (CASE_KEYS; None: all) in the bench's order; InputError for an unknown
    name, or CalculiX without housingfe on 1 rank (its deck and reference are that run's)."""
    from housingfe.errors import InputError

    keys = list(CASE_KEYS) if cases is None else cases
    unknown = [k for k in keys if k not in CASE_KEYS]
    if unknown or not keys:
        raise InputError(f"bench: --cases: unknown case {', '.join(unknown) or '(none)'} "
                         f"(cases: {', '.join(CASE_KEYS)})")
    if "calculix" in keys and "housingfe1" not in keys:
        raise InputError("bench: --cases: calculix needs housingfe1 (the deck is the mesh that run solved)")
    return [case for key, case in zip(CASE_KEYS, CASES) if key in keys]


def main(out_dir: Path, quick: bool = False, resume: bool = False, size_mm: float | None = None,
         cases: list[str] | None = None, rounds: int | None = None) -> None:
    """Write the inputs, run the cases interleaved, print the table; imported_bench.csv/.png/.txt in out_dir.
    size_mm: the element size (mm; default 13.5, --quick 60); cases: a subset of CASE_KEYS; rounds: interleaved
    rounds (default REPEATS, --quick 1)."""
    from housingfe.benchmarks._runs import FinishedRuns

    size = size_mm / 1e3 if size_mm else QUICK_SIZE if quick else SIZE
    repeats = rounds or (1 if quick else REPEATS)
    order = [(k, j) for k, j in selected_cases(cases) if k != "calculix" or shutil.which("ccx")]
    # the checkpoint first: a second bench into the same --out stops here, before it touches the inputs folder
    finished = FinishedRuns("imported", out_dir, {"size": size, "repeats": repeats, "order": order},
                            repeats * len(order) + 1, resume=resume)
    # beside <out>.partial: the inputs, rewritten by every run, and the C3D10 deck, which a --resume re-uses once
    # the checkpoint holds its run (the "deck" record): kept after a refusal or interruption only then
    work = Path(f"{out_dir}.inputs")
    try:
        work.mkdir(parents=True, exist_ok=True)
        inputs = write_inputs(work, size)
        bolted_mb = float("nan")
        if any(k == "inspect" for k, _ in order):
            bolted = work / f"bolted-{QUICK_HOLES if quick else HOLES}.step"
            if not bolted.exists():
                write_bolted_housing(bolted, QUICK_HOLES if quick else HOLES)
            inputs["bolted"] = str(bolted)
            bolted_mb = bolted.stat().st_size / 1e6
        step_mb = Path(inputs["step"]).stat().st_size / 1e6
    except BaseException as exc:
        finished.interrupted(exc)
        _drop_inputs(work, finished)
        raise
    runs: dict[str, list] = {label(k, j): [] for k, j in order}
    last: dict[str, dict] = {}
    deck_info = None
    try:
        for rnd in range(repeats):
            for kind, job in order:
                name = label(kind, job)
                if kind == "calculix" and deck_info is None:
                    ref = last[label("housingfe", {"ranks": 1})]
                    deck = str(work / "housing.inp")
                    modes = ref["rigid"] + len(ref["frequencies_hz"]) + 10
                    deck_info = finished.run("deck", lambda: _case("deck", {**inputs, "deck": deck,
                                                                            "modes": modes}), note="deck")
                    if 3 * deck_info["nodes"] != ref["dofs"]:
                        raise RuntimeError(f"the C3D10 deck has {deck_info['nodes']} nodes, x 3 = "
                                           f"{3 * deck_info['nodes']} != housingfe's {ref['dofs']} DOFs")
                case_job = {**inputs, **job, "deck": str(work / "housing.inp")}
                load = load_average()
                res = finished.run(f"round {rnd + 1} {name}", lambda: {**_case(kind, case_job),
                                                                       "load_before": load}, note=name)
                runs[name].append((res["process_wall_s"], res["load_before"]))
                last[name] = res
                finished.write(f"round {rnd + 1}/{repeats}  {name:32s} wall {res['process_wall_s']:8.2f} s  "
                               f"load before {res['load_before']:.2f}")
    except BaseException as exc:
        finished.interrupted(exc)
        _drop_inputs(work, finished)
        raise
    finished.close()
    rows, header, summary = _table(runs, last, deck_info, step_mb, size, bolted_mb)
    with atomic_output_dir(out_dir) as tmp:
        write_csv(tmp / "imported_bench.csv", header, rows)
        _plot(tmp / "imported_bench.png", rows)
        table = format_table(header, rows)
        idle = max(load for times in runs.values() for _, load in times)
        note = (f"{repeats} interleaved round(s); highest 1-min load average before a run: {idle:.2f} "
                f"({'machine otherwise idle' if idle < 1.0 else 'NOT idle (shared machine): timings pessimistic'}"
                f"; {os.cpu_count()} cores)")
        (tmp / "imported_bench.txt").write_text(table + "\n" + summary + "\n" + note + "\n")
        (tmp / "runs.json").write_text(json.dumps({"runs": runs, "last": last, "deck": deck_info}, indent=1))
    finished.finish()
    shutil.rmtree(work, ignore_errors=True)
    print(table)
    print(summary)
    print(note)
    print(f"results: {out_dir}/")


def _drop_inputs(work: Path, finished) -> None:
    """After a refusal (InputError), an error or an interruption: remove the inputs folder unless the checkpoint
    holds the deck run, whose C3D10 deck (work/housing.inp) a --resume re-uses instead of writing it again."""
    if "deck" not in finished.done:
        shutil.rmtree(work, ignore_errors=True)


def _table(runs: dict, last: dict, deck_info: dict | None, step_mb: float, size: float, bolted_mb: float):
    header = ["case", "dofs", "wall_min_s", "wall_median_s", "wall_max_s", "runs", "max_load_before",
              "solve_s", "peak_memory_gb", "bytes_per_dof", "us_per_dof", "modes_below_4khz", "complete",
              "max_diff_vs_housingfe_1rank_pct"]
    base = last.get(label("housingfe", {"ranks": 1}))
    ref = np.asarray(base["frequencies_hz"]) if base else None
    dofs = base["dofs"] if base else float("nan")
    rows = []
    for name, times in runs.items():
        if not times:
            continue
        res = last[name]
        walls = [t for t, _ in times]
        med = statistics.median(walls)
        freqs = np.asarray(res.get("frequencies_hz", []))
        freqs = freqs[freqs < F_MAX] if len(freqs) else freqs
        diff = float("nan")
        if ref is not None and len(freqs) and name.startswith(("housingfe P2", "ccx")):
            n = min(len(freqs), len(ref))
            diff = 100 * float(np.abs(freqs[:n] / ref[:n] - 1).max()) if len(freqs) == len(ref) else float("nan")
        solve = res.get("timings_s", {}).get("eigensolve_s", float("nan"))
        mem = res.get("peak_memory_gb", float("nan"))
        case_dofs = res.get("dofs", 3 * deck_info["nodes"] if name.startswith("ccx") and deck_info else dofs)
        complete = res.get("complete")
        if name.startswith("ccx"):
            complete = len(freqs) == len(ref) if ref is not None else None
        if name.startswith("housingfe reduce"):
            solve = float(res["summary"]["timings_s"].get("reduction_s", float("nan")))
            case_dofs = res["summary"]["fe_dofs"]
        if name == "housingfe inspect":
            case_dofs = f"{bolted_mb:.2f} MB"
        rows.append([name, case_dofs, min(walls), med, max(walls), len(walls), max(ld for _, ld in times), solve,
                     mem, mem * 1e9 / case_dofs if isinstance(case_dofs, int) else float("nan"),
                     med * 1e6 / case_dofs if isinstance(case_dofs, int) else float("nan"),
                     len(freqs) if name.startswith(("housingfe P2", "ccx")) else "", complete, diff])
    by = {r[0]: r for r in rows}
    lines = [f"test gearbox from STEP ({step_mb:.2f} MB), P2 tets of {1e3 * size:g} mm, {dofs} DOFs"]
    one, two = by.get(label("housingfe", {"ranks": 1})), by.get(label("housingfe", {"ranks": 2}))
    ccx, red = by.get(label("calculix", {})), by.get(label("reduce", {}))
    if one and two:
        lines.append(f"2 ranks vs 1: {one[3] / two[3]:.2f}x (medians {one[3]:.1f} / {two[3]:.1f} s)")
    if one and ccx:
        lines.append(f"CalculiX C3D10 on the same mesh ({deck_info['nodes']} nodes x 3 = {3 * deck_info['nodes']} "
                     f"DOFs): {ccx[3]:.1f} s median, {ccx[3] / one[3]:.1f}x housingfe on 1 rank"
                     + (f", {ccx[3] / two[3]:.1f}x on 2 ranks" if two else "")
                     + f"; max frequency difference {ccx[13]:.3g} %")
    if one and red:
        lines.append(f"Craig-Bampton export (`housingfe reduce`, cutoff {F_MAX:g} Hz): {red[3]:.1f} s median = "
                     f"{red[3] / one[3]:.2f}x the modal run")
    ins = by.get("housingfe inspect")
    if ins:
        lines.append(f"import + inspect of a {bolted_mb:.2f} MB STEP (open box with {QUICK_HOLES if bolted_mb < 2 else HOLES} "
                     f"bolt holes): {ins[3]:.1f} s median (target < 10 s); {last['housingfe inspect']['report_tail']}")
    return rows, header, "\n".join(lines)


def _plot(path: Path, rows: list) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 4))
    names = [r[0] for r in rows]
    med = np.array([r[3] for r in rows])
    lo, hi = med - [r[2] for r in rows], np.array([r[4] for r in rows]) - med
    ax.barh(names, med, xerr=[lo, hi], capsize=3, color="tab:blue")
    for i, r in enumerate(rows):
        if r[8] == r[8]:
            ax.annotate(f"{r[8]:.2f} GB", (r[3], i), xytext=(4, -3), textcoords="offset points", fontsize=7)
    ax.set_xlabel("wall time per run, median (bars: min-max) (s)")
    inspect = [r[1] for r in rows if r[0] == "housingfe inspect"]
    ax.set_title(f"imported gearbox housing (STEP), {rows[0][1]} DOFs, modes to 4 kHz"
                 + (f"; inspect: {inspect[0]}" if inspect else ""))
    ax.grid(alpha=0.3, axis="x")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    _worker(sys.argv[1])
