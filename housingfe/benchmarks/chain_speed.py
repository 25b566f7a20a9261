"""`housingfe bench chain_speed`: the chain of `make demo` from a fresh process and its re-analyses, this code
interleaved with a baseline commit (issue 28, "Performance").

Per round, each version in turn (the order alternates: old-new, new-old, ...), in a fresh Python process with
PYTHONPATH on that version's tree (housingfe/benchmarks/_chain_driver.py):

* the chain of `housingfe run test-gearbox-runup` (gear set A, ball bearings, 2000 N m, 50-1500 rpm -> L_WA over
  speed): wall time from the process' start to the chain's end (imports, mesh, coupling, basis, Ritz reduction,
  source, routes, report files), the process' CPU time (user + system, all threads) and run_scene's stages;
* re-analyses of the chain's coupled model (chain.with_drivetrain) for 1000 N m, gear set B and self-aligning
  bearings: the re-analysis alone and the whole re-run (re-analysis + source + run-up);
* the 1-minute load average before the process starts.

Accuracy beside speed: the new version's L_WA over speed (every route, radiator and variant) and its modal-basis
and Ritz frequencies against the baseline's, max |dL_WA| (dB) and max relative frequency difference.

The baseline is `git archive`d from the repository this housingfe lives in: commit HOUSINGFE_BENCH_BASELINE
(default 62f2e11, main before the issue-28 speed-ups).  --quick: a coarse housing (mesh.size 0.05), lines to
2 kHz, 6 speeds, 1 round.  Full: 3 rounds (about 10-15 min on 2 idle cores).

Writes chain_speed_runs.csv (one row per process), chain_speed.csv (min / median / max per quantity and
version, ratio of the medians new / old, the interleaved per-round ratios), chain_speed_accuracy.csv,
chain_speed.png and chain_speed.txt (the printed summary).
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from housingfe.errors import InputError
from housingfe.outputs import atomic_output_dir, format_table, write_csv

BASELINE = os.environ.get("HOUSINGFE_BENCH_BASELINE", "62f2e11")
QUICK_OVERRIDES = ['housing.set=["mesh.size=0.05"]', "runup.speed_min_rpm=250.0", "runup.speed_step_rpm=250.0",
                   "runup.f_max_hz=2000.0"]
TARGET_CHAIN_S = 15.0           # issue 28: the whole chain from a fresh process
TARGET_REANALYSIS_S = 1.0       # issue 28: a re-analysis for another torque, gear set or bearing configuration
STAGES = ("mesh_s", "coupling_s", "basis_s", "reduction_s", "source_s", "response_s")


def _baseline_tree(where: Path) -> Path:
    """The baseline's housingfe tree (git archive of BASELINE from this package's repository) under `where`."""
    repo = Path(__file__).resolve().parents[2]
    if not (repo / ".git").exists():
        raise InputError(f"bench chain_speed: {repo} is not a git checkout: the baseline {BASELINE} cannot be read")
    tree = where / f"baseline-{BASELINE}"
    tree.mkdir(parents=True)
    archive = subprocess.run(["git", "-C", str(repo), "archive", BASELINE, "housingfe"], capture_output=True)
    if archive.returncode != 0:
        raise InputError(f"bench chain_speed: HOUSINGFE_BENCH_BASELINE={BASELINE}: "
                         f"{archive.stderr.decode().strip()}")
    subprocess.run(["tar", "-x", "-C", str(tree)], input=archive.stdout, check=True)
    return tree


def _run(version: str, tree: Path, work: Path, tag: str, overrides: list[str]) -> dict:
    """One fresh process of the driver on `tree`: its result dict plus wall, CPU and load."""
    driver = work / "new" / "housingfe" / "benchmarks" / "_chain_driver.py"
    out, result = work / f"{tag}-out", work / f"{tag}.json"
    env = dict(os.environ, PYTHONPATH=str(tree))
    load = os.getloadavg()[0]
    before = os.times()
    t_spawn = time.time()
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", "import runpy, sys; sys.argv = sys.argv[1:]; "
                           "runpy.run_path(sys.argv[0], run_name='__main__')", str(driver), str(out), str(result),
                           *overrides], env=env, cwd=work, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    after = os.times()
    if proc.returncode != 0:
        raise RuntimeError(f"bench chain_speed: {version} run failed:\n{proc.stderr[-3000:]}")
    data = json.loads(result.read_text())
    data.update(version=version, load_1min=load, chain_wall_s=data["chain_end_epoch"] - t_spawn,
                process_wall_s=wall,
                process_cpu_s=(after.children_user - before.children_user)
                + (after.children_system - before.children_system))
    return data


def _flat(run: dict, rnd: int) -> dict:
    row = {"round": rnd, "version": run["version"], "load_1min": run["load_1min"],
           "chain_wall_s": run["chain_wall_s"], "chain_cpu_s": run["chain_cpu_s"]}
    row.update({f"stage_{k}": run["timings"].get(k, float("nan")) for k in STAGES})
    for label, v in run["variants"].items():
        key = label.split()[0] if not label.startswith("gear") else "gear_set"
        key = {"torque": "torque", "gear_set": "gear_set", "self-aligning": "bearings"}[key]
        row[f"reanalysis_{key}_s"] = v["reanalysis_s"]
        row[f"rerun_{key}_s"] = v["rerun_s"]
    row["process_cpu_s"] = run["process_cpu_s"]
    return row


def _accuracy(old: dict, new: dict) -> list[list]:
    """[what, max |dL_WA| dB, max relative frequency difference] of new against old."""
    def lwa_diff(a, b):
        return max(float(np.max(np.abs(np.array(a[k]) - np.array(b[k])))) for k in a)

    def freq_diff(a, b):
        a, b = np.array(a), np.array(b)
        m = min(len(a), len(b))
        keep = a[:m] > 1.0                           # the gears' free turning (0 Hz) has no relative error
        return float(np.max(np.abs(b[:m][keep] / a[:m][keep] - 1.0))) if len(a) == len(b) else float("inf")

    rows = [["chain (set A, ball, 2000 N m)", lwa_diff(old["lwa"], new["lwa"]), freq_diff(old["basis_hz"],
                                                                                        new["basis_hz"]),
             freq_diff(old["ritz_hz"], new["ritz_hz"])]]
    for label in old["variants"]:
        o, n = old["variants"][label], new["variants"][label]
        rows.append([f"re-analysis: {label}", lwa_diff(o["lwa"], n["lwa"]), float("nan"),
                     freq_diff(o["ritz_hz"], n["ritz_hz"])])
    return rows


def _plot(path: Path, rows: list[dict]) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    for version, colour, dx in (("old", "tab:red", -0.2), ("new", "tab:blue", 0.2)):
        sel = [r for r in rows if r["version"] == version]
        if not sel:
            continue
        med = {k: float(np.median([r[f"stage_{k}"] for r in sel])) for k in STAGES}
        left = 0.0
        for i, (k, v) in enumerate(med.items()):
            axes[0].barh([dx], [v], left=left, height=0.35, color=plt.cm.tab10(i),
                         label=k.removesuffix("_s") if version == "new" else None)
            left += v
        axes[0].plot([float(np.median([r["chain_wall_s"] for r in sel]))], [dx], "k|", ms=18)
        keys = [k for k in sel[0] if k.startswith("reanalysis_")]
        axes[1].bar(np.arange(len(keys)) + dx, [float(np.median([r[k] for r in sel])) for k in keys], 0.4,
                    color=colour, label=version)
        axes[1].set_xticks(np.arange(len(keys)), [k.removeprefix("reanalysis_").removesuffix("_s") for k in keys])
    axes[0].set_yticks([-0.2, 0.2], ["old", "new"])
    axes[0].set_xlabel("median wall time [s] (stages; | = whole chain from process start)")
    axes[0].legend(fontsize=7, ncol=3)
    axes[1].axhline(TARGET_REANALYSIS_S, color="k", lw=0.8, ls="--")
    axes[1].set_ylabel("re-analysis (with_drivetrain), median [s]")
    axes[1].legend()
    loads = [r["load_1min"] for r in rows]
    fig.suptitle(f"housingfe bench chain_speed: test-gearbox-runup, baseline {BASELINE}, "
                 f"load average {min(loads):.1f}-{max(loads):.1f}")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(out_dir: Path, quick: bool) -> None:
    """Run the interleaved rounds; print and write the tables and the plot."""
    rounds = 1 if quick else 3
    overrides = QUICK_OVERRIDES if quick else []
    new_tree = Path(__file__).resolve().parents[2]
    runs, raw = [], {"old": [], "new": []}
    with tempfile.TemporaryDirectory(prefix="chain-speed-") as tmp:
        work = Path(tmp)
        # a copy of this tree: editing it while the rounds run must not change the "new" code under test
        new_copy = work / "new"
        shutil.copytree(new_tree / "housingfe", new_copy / "housingfe",
                        ignore=shutil.ignore_patterns("__pycache__"))
        trees = {"old": _baseline_tree(work), "new": new_copy}
        for rnd in range(rounds):
            order = ("old", "new") if rnd % 2 == 0 else ("new", "old")
            for version in order:
                run = _run(version, trees[version], work, f"{version}-{rnd}", overrides)
                raw[version].append(run)
                runs.append(_flat(run, rnd))
                print(f"round {rnd + 1}/{rounds} {version}: chain {run['chain_wall_s']:.1f} s "
                      f"(CPU {run['chain_cpu_s']:.1f} s, load {run['load_1min']:.1f})", flush=True)
    quantities = [k for k in runs[0] if k not in ("round", "version")]
    summary = []
    for q in quantities:
        per = {v: np.array([r[q] for r in runs if r["version"] == v], float) for v in ("old", "new")}
        ratios = [float(n[q] / o[q]) for rnd in range(rounds)
                  for o in runs if o["round"] == rnd and o["version"] == "old"
                  for n in runs if n["round"] == rnd and n["version"] == "new"]
        summary.append([q, *(f(per[v]) for v in ("old", "new") for f in (np.min, np.median, np.max)),
                        float(np.median(per["new"]) / np.median(per["old"])),
                        " ".join(f"{x:.2f}" for x in ratios)])
    header = ["quantity", "old_min", "old_median", "old_max", "new_min", "new_median", "new_max",
              "new/old (medians)", "new/old per round"]
    acc = _accuracy(raw["old"][0], raw["new"][0])
    acc_header = ["case", "max |dL_WA| dB", "basis frequencies, max rel.", "Ritz frequencies, max rel."]
    loads = [r["load_1min"] for r in runs]
    new_chain = float(np.median([r["chain_wall_s"] for r in runs if r["version"] == "new"]))
    new_re = max(float(np.median([r[k] for r in runs if r["version"] == "new"]))
                 for k in runs[0] if k.startswith("reanalysis_"))
    text = [f"housingfe bench chain_speed ({'quick' if quick else 'full'}): test-gearbox-runup, new = this tree, "
            f"old = {BASELINE}, {rounds} interleaved round(s), {os.cpu_count()} cores",
            f"1-minute load average before the runs: {min(loads):.1f}-{max(loads):.1f} "
            f"({' '.join(f'{x:.1f}' for x in loads)})"
            + ("; timings taken UNDER LOAD (shared machine): read the interleaved ratios" if max(loads) > 1.0
               else ""),
            format_table(header, summary, floatfmt="{:.3g}"), "",
            "accuracy, new against old (same scene):", format_table(acc_header, acc, floatfmt="{:.2g}"), "",
            f"target chain <= {TARGET_CHAIN_S:g} s: median new {new_chain:.1f} s "
            f"({'met' if new_chain <= TARGET_CHAIN_S else 'NOT met'} at this load)",
            f"target re-analysis <= {TARGET_REANALYSIS_S:g} s: slowest median new {new_re:.2f} s "
            f"({'met' if new_re <= TARGET_REANALYSIS_S else 'NOT met'} at this load)"]
    print("\n".join(text))
    with atomic_output_dir(out_dir) as tmp:
        write_csv(tmp / "chain_speed_runs.csv", list(runs[0]), [list(r.values()) for r in runs])
        write_csv(tmp / "chain_speed.csv", header, summary)
        write_csv(tmp / "chain_speed_accuracy.csv", acc_header, acc)
        (tmp / "chain_speed.txt").write_text("\n".join(text) + "\n")
        _plot(tmp / "chain_speed.png", runs)
    print(f"results: {out_dir}/")


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--quick"]
    main(Path(args[0]) if args else Path("results/bench-chain_speed"), quick="--quick" in sys.argv)
