"""The frame (mount) stiffness as a sampled input of `housingfe uncertainty`: its cost and how it widens the bands.

`--range mount_stiffness_N_per_m=1e8:1e10` stands each sample's gearbox on an elastic frame of total vertical
stiffness K_v (log-uniform; docs/uncertainty.md), each sample on a housing model and modal basis of its own.
Each case runs the real command with and without the mount, same seed (the other inputs draw the same values):

  python benchmarks/experiments/mount_uncertainty/mount_uncertainty.py cost    # coarse mesh, 4 samples, bearings
  python benchmarks/experiments/mount_uncertainty/mount_uncertainty.py bands   # scene's mesh, 8 samples, bearings
  python benchmarks/experiments/mount_uncertainty/mount_uncertainty.py table   # CSVs and PNG from what was run

Run folders: /tmp/mount-uq-runs/<case>_<fixed|mount>/ (MOUNT_UQ_RUNS moves them); wall time of the whole command
in wall_s.txt beside each.
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
RUNS = Path(os.environ.get("MOUNT_UQ_RUNS", "/tmp/mount-uq-runs"))
MOUNT = "mount_stiffness_N_per_m=1e8:1e10"
COARSE = ['housing.set=["mesh.size=0.06"]', "runup.f_max_hz=1500", "runup.speed_min_rpm=250",
          "runup.speed_step_rpm=250"]
CASES = {
    "cost": {"args": ["--samples", "4", "--seed", "1", "--workers", "1", "--family", "bearings"], "sets": COARSE},
    # concurrent.futures: the mpi4py.futures spawn hung here once (2026-11-27, orted up, no worker after 6 min)
    "bands": {"args": ["--samples", "8", "--seed", "1", "--workers", "2", "--engine", "processes", "--family",
                       "bearings"], "sets": []},
    # the same 24 draws as the documented fixed-feet bands (seed 1), with and without the mount
    "bands24": {"args": ["--samples", "24", "--seed", "1", "--workers", "2", "--engine", "processes", "--family",
                         "bearings"], "sets": []},
}


def folder(case: str, mount: bool) -> Path:
    return RUNS / f"{case}_{'mount' if mount else 'fixed'}"


def run(case: str, mount: bool) -> float:
    out = folder(case, mount)
    cmd = [sys.executable, "-m", "housingfe", "uncertainty", "--out", str(out), *CASES[case]["args"]]
    cmd += [x for s in CASES[case]["sets"] for x in ("--set", s)]
    if mount:
        cmd += ["--range", MOUNT]
    print(" ".join(cmd), flush=True)
    env = {**os.environ, "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1"}
    t0 = time.perf_counter()
    log = RUNS / f"{out.name}.log"
    with open(log, "w") as fh:                  # progress per sample as it comes
        res = subprocess.run(cmd, stdout=fh, stderr=subprocess.STDOUT, text=True, env=env)
    wall = time.perf_counter() - t0
    if res.returncode:
        raise SystemExit(f"{case} mount={mount}: exit {res.returncode}\n{log.read_text()[-2000:]}")
    (out / "wall_s.txt").write_text(f"{wall:.1f}\n")
    print(f"  {wall:.1f} s", flush=True)
    return wall


def cost_rows() -> list[dict]:
    rows = []
    for case in CASES:
        for mount in (False, True):
            f = folder(case, mount)
            if not (f / "uncertainty.json").is_file():
                continue
            d = json.loads((f / "uncertainty.json").read_text())
            t, ms = d["timings_s"], d["metrics"]
            setup = [m["setup_s"] for m in ms if m["setup_s"] > 0]
            setup_cpu = [m.get("setup_cpu_s", float("nan")) for m in ms if m["setup_s"] > 0]
            rows.append({"case": case, "mount": "1e8-1e10" if mount else "fixed", "samples": len(ms),
                         "workers": d["workers"], "command_wall_s": float((f / "wall_s.txt").read_text()),
                         "run_wall_s": round(t["wall_s"], 1),
                         "sample_wall_s": round(float(np.mean([m["seconds"] for m in ms])), 1),
                         "sample_cpu_s": round(float(np.mean([m["cpu_s"] for m in ms])), 1),
                         "bases_built": len(setup), "bases_wall_s": round(float(np.mean(setup)), 1),
                         "bases_cpu_s": round(float(np.mean(setup_cpu)), 1),
                         "sample_with_bases_wall_s": round(float(np.mean([m["seconds"] + m["setup_s"] for m in ms])), 1),
                         "sample_with_bases_cpu_s": round(float(np.mean([m["cpu_s"] + m.get("setup_cpu_s", 0.0)
                                                                         for m in ms])), 1),
                         "rss_mb_max": round(max(m["rss_mb"] for m in ms), 0)})
    return rows


QUANTITIES = ("max_lwa_dBA", "max_lwa_speed_rpm", "slope_dBA_per_doubling", "peaks_in_measured_windows",
              "variant_mean_angular_contact_dB", "variant_mean_self_aligning_dB", "variant_mean_tapered_roller_dB",
              "measured_ranking_holds", "self_aligning_quieter_than_ball")


def band_rows(case: str = "bands") -> list[dict]:
    rows = []
    for mount in (False, True):
        f = folder(case, mount)
        d = json.loads((f / "uncertainty.json").read_text())
        ms = d["metrics"]
        for route in ("tf_omega", "mesh_force"):
            for q in QUANTITIES:
                v = np.array([np.nan if m.get(f"{route}/{q}") is None else m[f"{route}/{q}"] for m in ms], float)
                p5, p50, p95 = np.nanpercentile(v, [5, 50, 95])
                rows.append({"case": case, "mount": "1e8-1e10" if mount else "fixed", "route": route, "quantity": q,
                             "p5": round(p5, 2), "median": round(p50, 2), "p95": round(p95, 2),
                             "min": round(np.nanmin(v), 2), "max": round(np.nanmax(v), 2),
                             "values": " ".join(f"{x:.2f}" for x in v)})
            quiet = [m[f"{route}/quietest"] for m in ms]
            rows.append({"case": case, "mount": "1e8-1e10" if mount else "fixed", "route": route,
                         "quantity": "quietest", "values": " ".join(quiet)})
        rows.append({"case": case, "mount": "1e8-1e10" if mount else "fixed", "route": "", "quantity": "K_v_N_per_m",
                     "values": " ".join("fixed" if s.get("mount_stiffness_N_per_m") is None
                                        else f"{s['mount_stiffness_N_per_m']:.3g}" for s in d["samples"])})
    return rows


def write_csv(path: Path, rows: list[dict]) -> None:
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, keys)
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {path}")


def plot(case: str = "bands") -> None:
    """mount_uncertainty_<case>.png (the 8-sample case keeps its old name mount_uncertainty_bands.png)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(16, 4.8))
    for j, route in enumerate(("tf_omega", "mesh_force")):
        ax = axes[j]
        for mount, colour in ((False, "C0"), (True, "C3")):
            d = json.loads((folder(case, mount) / "uncertainty.json").read_text())
            speeds = np.asarray(d["speeds_rpm"])
            curves = np.array([m[f"{route}/lwa_curve_dBA"] for m in d["metrics"]])
            p5, p50, p95 = np.percentile(curves, [5, 50, 95], axis=0)
            label = "K_v 1e8-1e10 N/m" if mount else "fixed feet"
            ax.plot(speeds, p50, color=colour, label=f"{label}: median")
            ax.fill_between(speeds, p5, p95, color=colour, alpha=0.2, label=f"{label}: 5-95 %")
        ax.set_title(f"set A, ball, {route}: L_WA over speed", fontsize=10)
        ax.set_xlabel("pinion speed [rev/min]")
        ax.set_ylabel("L_WA [dB(A)]")
        ax.legend(fontsize=8)
    ax = axes[2]
    others = ("angular_contact", "self_aligning", "tapered_roller")
    measured = (-4.2, -5.1, -3.6)
    for k, (mount, route) in enumerate([(m, r) for r in ("tf_omega", "mesh_force") for m in (False, True)]):
        d = json.loads((folder(case, mount) / "uncertainty.json").read_text())
        data = [[m[f"{route}/variant_mean_{b}_dB"] for m in d["metrics"]] for b in others]
        box = ax.boxplot(data, positions=np.arange(3) + k * 0.2 - 0.3, widths=0.16, whis=(5, 95),
                         showfliers=False, manage_ticks=False, patch_artist=True)
        for patch in box["boxes"]:
            patch.set_facecolor("C3" if mount else "C0")
            patch.set_alpha(0.3 if route == "tf_omega" else 0.7)
        ax.plot([], [], "s", color="C3" if mount else "C0", alpha=0.3 if route == "tf_omega" else 0.7,
                label=f"{route}, {'mount' if mount else 'fixed'}")
    ax.plot(np.arange(3), measured, "k<", ms=8, label="measured (Sec. 5.8)")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xticks(np.arange(3), others)
    ax.set_ylabel("L_WA - L_WA(ball), mean 800-1500 rpm, set B [dB]")
    ax.legend(fontsize=7)
    fig.suptitle(f"housingfe uncertainty --samples {len(d['metrics'])} --seed 1 --family bearings, with and without "
                 "--range mount_stiffness_N_per_m=1e8:1e10")
    fig.tight_layout()
    fig.savefig(HERE / f"mount_uncertainty_{case}.png", dpi=100)
    print(f"wrote mount_uncertainty_{case}.png")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("what", choices=(*CASES, "table"))
    ap.add_argument("--only", choices=("fixed", "mount"), default=None)
    a = ap.parse_args()
    RUNS.mkdir(parents=True, exist_ok=True)
    if a.what in CASES:
        for mount in (False, True):
            if a.only is None or a.only == ("mount" if mount else "fixed"):
                run(a.what, mount)
        return
    # keep the rows of runs whose folders are gone (the run folders live in /tmp): recomputed rows replace them
    path, fresh = HERE / "mount_uncertainty_cost.csv", cost_rows()
    done = {(r["case"], r["mount"]) for r in fresh}
    kept = [r for r in csv.DictReader(open(path))] if path.is_file() else []
    write_csv(path, [r for r in kept if (r["case"], r["mount"]) not in done] + fresh)
    for case in ("bands", "bands24"):
        if (folder(case, True) / "uncertainty.json").is_file() and (folder(case, False) / "uncertainty.json").is_file():
            write_csv(HERE / f"mount_uncertainty_{case}.csv", band_rows(case))
            plot(case)


if __name__ == "__main__":
    main()
