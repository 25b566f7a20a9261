"""Speed and answer of the mesh stiffness curve: this tree's code against an older copy of the package.

Each case runs in its own process (old and new interleaved, the order alternating per round), builds the model the
way the run-up does (`SourceModel.from_scene`: the scene's MeshModel with shafts, torque configuration 2) and times
only the call named by the case; the curves of both codes are saved and compared number by number.

    git archive 625341e | tar -x -C /tmp/stiffness-speed/base
    PYTHONPATH=. OPENBLAS_NUM_THREADS=1 /work/main/.venv/bin/python \
        benchmarks/experiments/stiffness_speed/stiffness_speed.py --base /tmp/stiffness-speed/base --rounds 3

Cases: "curve:<set>" = stiffness_curve at 2000 N m with 128 positions per base pitch (dyn.DEFAULT_STIFFNESS_POSITIONS);
"source:double-helical" = SourceModel.prepared at 500/1000/1500/2000 N m (the source part of a double-helical family
member: stiffness curve, face-width load share, matrices, shock per torque).  Writes stiffness_speed.csv (summary:
min/median/max seconds per code, speed-up, largest relative difference), stiffness_speed_runs.csv (every run with the
1-min load average before it) and stiffness_speed.png next to this script.
"""
from __future__ import annotations

import argparse
import csv
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[2]
SETS = ("A", "B", "uncorrected", "double-helical")
FAMILY_TORQUES = (500.0, 1000.0, 1500.0, 2000.0)
QUANTITIES = ("stiffness", "deflection", "axial_centre", "line_centre", "force", "pinion_torque", "wheel_torque",
              "tilt_moment")


def worker(case: str, out: str, positions: int) -> None:
    """Run one case in this process and save its seconds and curves to `out` (npz)."""
    from housingfe.source.roosmalen.operating import SourceModel
    from housingfe.source.stiffness import normal_force_from_torque, stiffness_curve

    kind, name = case.split(":")
    sm = SourceModel.from_scene(f"gearset-{name}")
    sm.stiffness_positions = positions
    res = {}
    if kind == "curve":
        force = normal_force_from_torque(sm.pair, 2000.0)
        t0 = time.perf_counter()
        curves = [stiffness_curve(sm.mesh_model, force, positions)]
        seconds = time.perf_counter() - t0
    else:
        t0 = time.perf_counter()
        points = sm.prepared(FAMILY_TORQUES)
        seconds = time.perf_counter() - t0
        curves = [points[t].curve for t in FAMILY_TORQUES]
        res["load_share"] = np.concatenate([points[t].load_share.ravel() for t in FAMILY_TORQUES])
    for q in QUANTITIES:
        res[q] = np.concatenate([c.unit_friction[q] if q in c.unit_friction else getattr(c, q) for c in curves])
    np.savez(out, seconds=seconds, **res)


def run_case(code: Path, case: str, positions: int, tmp: Path, tag: str) -> tuple[float, dict, float]:
    out = tmp / f"{tag}.npz"
    env = dict(os.environ, PYTHONPATH=str(code), OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    load = os.getloadavg()[0]
    subprocess.run([sys.executable, __file__, "--worker", case, "--out", str(out), "--positions", str(positions)],
                   env=env, check=True, cwd=tmp)
    data = np.load(out)
    return float(data["seconds"]), {k: data[k] for k in data.files if k != "seconds"}, load


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", help="directory holding the old housingfe package")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--positions", type=int, default=128)
    ap.add_argument("--cases", default=",".join([f"curve:{s}" for s in SETS] + ["source:double-helical"]))
    ap.add_argument("--worker")
    ap.add_argument("--out")
    a = ap.parse_args()
    if a.worker:
        worker(a.worker, a.out, a.positions)
        return
    codes = {"old": Path(a.base).resolve(), "new": REPO}
    cases = a.cases.split(",")
    runs, answers = [], {}
    with tempfile.TemporaryDirectory() as tmpdir:
        tmp = Path(tmpdir)
        for r in range(a.rounds):
            for case in cases:
                order = ("old", "new") if (r + cases.index(case)) % 2 == 0 else ("new", "old")
                for code in order:
                    sec, ans, load = run_case(codes[code], case, a.positions, tmp, f"{code}-{r}")
                    answers[(case, code)] = ans
                    runs.append({"round": r, "case": case, "code": code, "seconds": round(sec, 4),
                                 "load_1min": round(load, 2)})
                    print(f"round {r} {case:24s} {code}: {sec:7.3f} s  (load {load:.2f})", flush=True)
    with open(HERE / "stiffness_speed_runs.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(runs[0]))
        w.writeheader()
        w.writerows(runs)
    rows = []
    for case in cases:
        row = {"case": case}
        for code in ("old", "new"):
            t = np.array([x["seconds"] for x in runs if x["case"] == case and x["code"] == code])
            row.update({f"{code}_min_s": t.min(), f"{code}_median_s": float(np.median(t)), f"{code}_max_s": t.max()})
        ratios = [x["seconds"] / y["seconds"] for x in runs for y in runs
                  if x["case"] == y["case"] == case and x["round"] == y["round"] and x["code"] == "old"
                  and y["code"] == "new"]
        row.update({"speedup_median": float(np.median(ratios)), "speedup_min": min(ratios),
                    "speedup_max": max(ratios)})
        old, new = answers[(case, "old")], answers[(case, "new")]
        worst, identical = 0.0, True
        for q in old:
            scale = np.max(np.abs(old[q]))
            identical &= bool(np.array_equal(old[q], new[q]))
            rel = float(np.max(np.abs(old[q] - new[q])) / scale)
            row[f"rel_{q}"] = rel
            worst = max(worst, rel)
        row.update({"max_rel_difference": worst, "bit_identical": identical})
        rows.append({k: (f"{v:.4g}" if isinstance(v, float) else v) for k, v in row.items()})
    fields = list(dict.fromkeys(k for r in rows for k in r))
    with open(HERE / "stiffness_speed.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        w.writerows(rows)
    for r in rows:
        print(r)
    plot(rows)


def plot(rows) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4.2))
    x = np.arange(len(rows))
    for k, (code, colour) in enumerate((("old", "tab:grey"), ("new", "tab:blue"))):
        med = np.array([float(r[f"{code}_median_s"]) for r in rows])
        lo = med - np.array([float(r[f"{code}_min_s"]) for r in rows])
        hi = np.array([float(r[f"{code}_max_s"]) for r in rows]) - med
        ax.bar(x + (k - 0.5) * 0.38, med, 0.38, yerr=[lo, hi], color=colour, capsize=3,
               label=f"{code} (median, min-max)")
    for i, r in enumerate(rows):
        top = float(r["old_max_s"])
        ax.annotate(f"{float(r['speedup_median']):.2f}x\nmax rel diff {float(r['max_rel_difference']):.1e}",
                    (i, top), textcoords="offset points", xytext=(0, 4), ha="center", fontsize=7)
    ax.set_xticks(x, [r["case"].replace(":", "\n") for r in rows], fontsize=8)
    ax.set_ylabel("wall time [s]")
    ax.set_title("stiffness curve, 128 positions/pitch: old vs new code (interleaved)")
    ax.set_ylim(0, 1.3 * max(float(r["old_max_s"]) for r in rows))
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(HERE / "stiffness_speed.png", dpi=120)


if __name__ == "__main__":
    main()
