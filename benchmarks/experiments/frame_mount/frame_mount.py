"""The Ch. 5 test gearbox on an elastic frame instead of a rigid base (issue 28, a new hypothesis).

The thesis: "the gearbox stands on a frame" (Ch. 5 test rig); the built-in scene fixes the feet's underside
(`test-gearbox`, supports = foot_bottom fixed).  The frame's stiffness is not published, so it is an INPUT with a
range, never fitted: a total vertical stiffness K_v (N/m) spread uniformly over foot_bottom (0.0735 m^2),
k_n = K_v / area (N/m^3), tangential k_t = k_n / 3 (as in box-supported-elastic).  K_v = 1e8 ... 1e10 N/m and fixed.

Per K_v, through the real command (`housingfe run test-gearbox-runup --set 'housing.set=[...]'`):
  * the issue-28 check rows of the default chain (the same row functions as `housingfe validate --only
    runup-checks`: validate.run_check_rows + runup_checks_rows.default_chain_rows) -> frame_mount_checks.csv
  * the tooth-band slope terms (runup.json slope_terms) -> frame_mount_slopes.csv
and in-process, the same coupled model (housing + shafts, gears, bearings, drive line) -> frame_mount_modes.csv:
  * its lowest modes, each split into rigid-body motion of the whole gearbox (projection on the six exact rigid
    motions, M-orthogonal) by component about the centre of gravity (sway x / sway y / bounce / roll / pitch / yaw)
    and the rest (elastic), with the interior's energy share;
  * the rigid-body estimate: Rayleigh-Ritz on the six rigid motions, R^T K R a = w^2 R^T M R a (the springs and
    the drive line's quills are all that resist a rigid motion) -> the six "rigid_estimate" rows.

Usage (from the worktree, PYTHONPATH=$PWD):
  python benchmarks/experiments/frame_mount/frame_mount.py runs --mesh coarse            # all K_v, coarse mesh
  python benchmarks/experiments/frame_mount/frame_mount.py runs --mesh default --kv 3e8 1e9 fixed
  python benchmarks/experiments/frame_mount/frame_mount.py modes --mesh coarse
  python benchmarks/experiments/frame_mount/frame_mount.py table     # CSV summary + PNG from what was run
Run folders: /tmp/frame-mount-runs/<mesh>_<case>/ (the CLI's output, kept for inspection).
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
RUNS = Path(os.environ.get("FRAME_MOUNT_RUNS", "/tmp/frame-mount-runs"))
FOOT_AREA_M2 = 0.0735            # foot_bottom of test-gearbox (`housingfe describe test-gearbox`)
TANGENTIAL_RATIO = 1.0 / 3.0     # k_t / k_n, as box-supported-elastic
KV_RANGE = ("1e8", "3e8", "1e9", "3e9", "1e10", "fixed")
MESHES = {"coarse": (["mesh.size=0.06"], ["runup.f_max_hz=1500.0"]), "default": ([], [])}
COMPONENTS = ("sway_x", "sway_y", "bounce", "roll", "pitch", "yaw")


def housing_sets(case: str, mesh: str) -> list[str]:
    """The housing scene overrides of a case ("fixed" or a K_v in N/m) on a mesh setting."""
    sets = list(MESHES[mesh][0])
    if case != "fixed":
        kn = float(case) / FOOT_AREA_M2
        sets += ["supports.0.kind=elastic", f"supports.0.normal_stiffness={kn:.6g}",
                 f"supports.0.tangential_stiffness={kn * TANGENTIAL_RATIO:.6g}"]
    return sets


def runup_overrides(case: str, mesh: str) -> list[str]:
    return [f"housing.set={json.dumps(housing_sets(case, mesh))}"] + list(MESHES[mesh][1])


def folder(case: str, mesh: str) -> Path:
    return RUNS / f"{mesh}_{case}"


# ------------------------------------------------------------------------------------------------ runs
def run_case(case: str, mesh: str) -> float:
    """`housingfe run test-gearbox-runup` with the case's overrides; wall time (s)."""
    out = folder(case, mesh)
    cmd = [sys.executable, "-m", "housingfe", "run", "test-gearbox-runup", "--out", str(out)]
    for s in runup_overrides(case, mesh):
        cmd += ["--set", s]
    print(" ".join(cmd), flush=True)
    t0 = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    (RUNS / f"{mesh}_{case}.log").write_text(res.stdout + res.stderr)
    if res.returncode:
        raise SystemExit(f"{case}/{mesh}: exit {res.returncode}\n{res.stderr[-2000:]}")
    (out / "wall_s.txt").write_text(f"{wall:.1f}\n")
    return wall


def check_rows(case: str, mesh: str) -> list[dict]:
    """The issue-28 rows of the default chain on a run's folder (as `validate --only runup-checks` makes them)."""
    from housingfe.verification import checks as ck
    from housingfe.verification import runup_checks_rows as rr
    from housingfe.verification import validate

    f = folder(case, mesh)
    data = json.loads((f / "runup.json").read_text())
    rows = validate.run_check_rows(case, data["checks"]) + rr.default_chain_rows(case, f)
    out = []
    for r in ck.check_rows(rows):
        out.append({"mesh": mesh, "K_v_N_per_m": case, "check_id": r["check_id"], "ours": r["ours"],
                    "measured": r.get("measured"), "passed": r.get("passed"), "why": r.get("why", "")})
    return out


def slope_rows(case: str, mesh: str) -> list[dict]:
    f = folder(case, mesh)
    data = json.loads((f / "runup.json").read_text())
    out = []
    for s in data["slope_terms"]:
        if s["radiation"] != data["scene_settings"]["radiation"]["models"][0]:
            continue
        sl = s["slopes_dB_per_doubling"]
        out.append({"mesh": mesh, "K_v_N_per_m": case, "route": s["route"], "basis": s["basis"],
                    **{k: round(sl[k], 2) for k in ("excitation", "transfer", "L_sigma", "A_weighting", "L_WA")},
                    "made_by": s["made_by"]})
    return out


# ------------------------------------------------------------------------------------------------ modes
def coupled_model(case: str, mesh: str):
    """The run-up's coupled gearbox model of a case, built as `housingfe run` builds it."""
    from mpi4py import MPI

    from housingfe.runup.chain import build_gearbox_model
    from housingfe.runup.scene import (
        drivetrain_of,
        housing_model_for,
        load_runup_scene,
        matched_drivetrains,
    )
    from housingfe.scene import load_housing_scene

    scene, path = load_runup_scene("test-gearbox-runup", runup_overrides(case, mesh))
    spec = scene.runup
    hs, _ = load_housing_scene(scene.housing.scene, list(scene.housing.set))
    torque = max(spec.torques_nm)
    dts = {torque: drivetrain_of(scene.drivetrain, torque, spec.drive_line_model)}
    model = housing_model_for(hs, spec.f_max_hz, MPI.COMM_WORLD)
    dts, _ = matched_drivetrains(scene.housing, model, dts, path)
    return build_gearbox_model(model, dts[torque], spec.f_max_hz, damping_ratio=spec.damping_ratio,
                               basis_factor=spec.basis_factor)


def mode_rows(case: str, mesh: str, n_modes: int = 12) -> list[dict]:
    """The lowest modes of the coupled gearbox with their rigid-body content, and the six-DOF rigid estimate."""
    from housingfe.solvers import blocks

    gm = coupled_model(case, mesh)
    system = gm.structure.system
    R = blocks.columns(system.rigid_body_vectors(gm.structure.model.V))
    MR = blocks.mat_block(system.M, R)
    KR = blocks.mat_block(system.K, R)
    Mrr, Krr = R.T @ MR, R.T @ KR
    Mrr, Krr = (Mrr + Mrr.T) / 2, (Krr + Krr.T) / 2
    mass = float(np.mean(np.diag(Mrr)[:3]))
    c = np.array([Mrr[1, 5], Mrr[2, 3], Mrr[0, 4]]) / mass        # centre of gravity (rigid_body_mass_properties)
    # rigid motions about the centre of gravity: translation t_c = t + theta x c, rotation theta
    T = np.eye(6)
    for j in range(3):
        T[0:3, 3 + j] = np.cross(np.eye(3)[j], c)
    Tinv = np.linalg.inv(T)
    Mc = Tinv.T @ Mrr @ Tinv                                         # block diagonal: m I, inertia about c
    rows = []
    basis = gm.basis
    n0 = basis.rigid_count
    freqs = basis.frequencies_hz[n0:]
    Q = blocks.columns(basis.vectors[n0:n0 + n_modes])
    share = gm.interior_share
    for i in range(Q.shape[1]):
        q = Q[:, i]
        Mq = blocks.mat_block(system.M, q[:, None])[:, 0]
        a = np.linalg.solve(Mrr, R.T @ Mq)                           # M-orthogonal projection on the rigid motions
        total = float(q @ Mq)
        rigid = float(a @ Mrr @ a) / total
        ac = T @ a
        energy = np.diag(Mc) * ac ** 2
        parts = energy / max(energy.sum(), 1e-300)
        order = np.argsort(parts)[::-1]
        # the rigid motion named only where it is a real part of the mode (an elastic mode's few % are noise)
        what = (" + ".join(f"{COMPONENTS[j]} {parts[j]:.0%}" for j in order[:2] if parts[j] > 0.1)
                if rigid >= 0.2 else "")
        kind = "rigid-body" if rigid >= 0.5 else "interior" if share[i] >= 0.5 else "housing elastic"
        rows.append({"mesh": mesh, "K_v_N_per_m": case, "kind": "coupled_mode", "index": i + 1, "type": kind,
                     "frequency_hz": round(float(freqs[i]), 1), "rigid_body_share": round(rigid, 3),
                     "rigid_motion": what, "interior_share": round(float(share[i]), 3),
                     **{COMPONENTS[j]: round(float(parts[j] * rigid), 3) for j in range(6)}})
    # Rayleigh-Ritz on the six rigid motions: an upper bound of the six rigid-body frequencies of the mount
    from scipy.linalg import eigh

    w2, vec = eigh(Krr, Mrr)
    for i in range(6):
        ac = T @ vec[:, i]
        energy = np.diag(Mc) * ac ** 2
        parts = energy / energy.sum()
        order = np.argsort(parts)[::-1]
        rows.append({"mesh": mesh, "K_v_N_per_m": case, "kind": "rigid_estimate", "index": i + 1, "type": "",
                     "frequency_hz": round(float(np.sqrt(max(w2[i], 0.0)) / 2 / np.pi), 1), "rigid_body_share": 1.0,
                     "rigid_motion": " + ".join(f"{COMPONENTS[j]} {parts[j]:.0%}" for j in order[:2]
                                                if parts[j] > 0.1),
                     "interior_share": "", **{COMPONENTS[j]: round(float(parts[j]), 3) for j in range(6)}})
    rows.append({"mesh": mesh, "K_v_N_per_m": case, "kind": "mass", "index": 0, "type": "", "frequency_hz": "",
                 "rigid_body_share": "", "rigid_motion": f"total {mass:.1f} kg, centre of gravity "
                 f"({c[0]:.3f}, {c[1]:.3f}, {c[2]:.3f}) m", "interior_share": ""})
    return rows


# ------------------------------------------------------------------------------------------------ output
def write_csv(path: Path, rows: list[dict], key=("mesh", "K_v_N_per_m")) -> None:
    """Merge rows into a CSV: rows of the same (mesh, case) replace the old ones."""
    old = []
    if path.is_file():
        with open(path, newline="") as fh:
            old = list(csv.DictReader(fh))
    new_keys = {tuple(str(r[k]) for k in key) for r in rows}
    kept = [r for r in old if tuple(r[k] for k in key) not in new_keys]
    allrows = kept + rows
    fields = list(dict.fromkeys(k for r in allrows for k in r))
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields)
        w.writeheader()
        w.writerows(allrows)


def plot(mesh: str, cases: list[str]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), sharey=True)
    for ax, route in zip(axes, ("tf_omega", "mesh_force")):
        for case in cases:
            f = folder(case, mesh) / "runup.csv"
            if not f.is_file():
                continue
            with open(f, newline="") as fh:
                rows = [r for r in csv.DictReader(fh) if r["route"] == route and r["radiation"] == "erp"]
            label = "fixed (today)" if case == "fixed" else f"K_v = {float(case):.0e} N/m"
            ax.plot([float(r["speed_rpm"]) for r in rows], [float(r["LwA_dB"]) for r in rows], label=label,
                    lw=2.2 if case == "fixed" else 1.2, color="k" if case == "fixed" else None)
        for lo, hi in ((450, 500), (850, 950), (1300, 1350)):
            ax.axvspan(lo, hi, color="0.85", zorder=0)
        ax.plot([250, 500, 1000, 1500], [74, 80, 86, 89], "ks", label="measured (Fig. 5.10, thesis' reading)")
        ax.set_title(f"{route}, set A, ball, 2000 N m, sigma = 1 ({mesh} mesh)")
        ax.set_xlabel("pinion speed (rpm)")
        ax.set_ylim(30, 105)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("L_WA dB(A); grey: measured L_v peak speeds")
    axes[1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(HERE / f"frame_mount_lwa_{mesh}.png", dpi=110)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("what", choices=("runs", "modes", "plot"))
    ap.add_argument("--mesh", choices=tuple(MESHES), default="coarse")
    ap.add_argument("--kv", nargs="*", default=list(KV_RANGE), help="K_v in N/m, or 'fixed'")
    args = ap.parse_args()
    RUNS.mkdir(parents=True, exist_ok=True)
    if args.what == "runs":
        for case in args.kv:
            wall = run_case(case, args.mesh)
            rows = check_rows(case, args.mesh)
            for r in rows:
                r["wall_s"] = round(wall, 1)
            write_csv(HERE / "frame_mount_checks.csv", rows)
            write_csv(HERE / "frame_mount_slopes.csv", slope_rows(case, args.mesh))
            print(f"{case}: {wall:.1f} s", flush=True)
        plot(args.mesh, list(KV_RANGE))
    elif args.what == "modes":
        for case in args.kv:
            t0 = time.perf_counter()
            rows = mode_rows(case, args.mesh)
            write_csv(HERE / "frame_mount_modes.csv", rows)
            print(f"{case}: modes in {time.perf_counter() - t0:.1f} s", flush=True)
    else:
        plot(args.mesh, list(KV_RANGE))


if __name__ == "__main__":
    main()
