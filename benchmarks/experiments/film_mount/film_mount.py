"""Why the double helical set's fluid films lose their advantage over cylindrical rollers on an elastic frame.

docs/design-variants.md / benchmarks/experiments/frame_mount (section d): fluid films - rollers (2000 N m, mean
L_WA over 800-1500 rpm, sigma = 1, tf_omega / mesh_force) is -5.1 / -1.4 dB on the fixed feet and -0.6 / +1.4 dB
on K_v = 1e9 N/m.  This experiment changes ONE thing per run to find which mechanism does it:

  * bearings: cylindrical_roller or fluid_film (the real `housingfe run test-gearbox-runup-double-helical`);
  * mount: fixed feet or K_v (the frame_mount `housing.set`, frame_mount.housing_sets);
  * film damping scale c (films only): the films' 6x6 C multiplied by c (0: no film damping; 1: as computed).
    No scene key does this, so the run goes through `housingfe.cli.main` in a child process whose
    housingfe.bearings.configurations._fluid_film_result is wrapped (`patch`).  An experiment-only control:
    nothing in the package changes;
  * film stiffness: "films" (as computed) or "sym" (K made symmetric, (K + K^T)/2: the thesis' own simplification);
  * mesh moment: "shuttling" (default) or "none" (runup.mesh_moment);
  * radiation: sigma = 1 (the checks') or the numerical sigma beside it.
Each run is compared speed by speed with the rollers' run of the same mesh, mount, moment and radiation.

Usage (PYTHONPATH=$PWD, from the worktree; README.md has the runs made):
  python benchmarks/experiments/film_mount/film_mount.py run --mesh default --case 1e9 --bearings fluid_film \
      --c-scale 0 --k-mode sym
  python benchmarks/experiments/film_mount/film_mount.py table        # film_mount.csv, film_mount_harmonics.csv
  python benchmarks/experiments/film_mount/film_mount.py modes --mesh default   # film_mount_modes.csv
  python benchmarks/experiments/film_mount/film_mount.py plot         # film_mount.png
  python benchmarks/experiments/film_mount/film_mount.py probe --case 1e9 fixed   # film_mount_probe.csv: C changed
      per line on the run-up's own reduced systems (why C raises the higher harmonics on the mount)
  python benchmarks/experiments/film_mount/film_mount.py stiff --case fixed 1e10 3e9 1e9 3e8   # film_mount_stiff.csv:
      C as the lossless stiffness omega C per line: rigid-body / elastic split, bore forces, modes near n = 3-5
  python benchmarks/experiments/film_mount/film_mount.py bores --case fixed 1e9   # film_mount_bores.csv: the bore
      forces and moments of no C and omega C through the housing's own transfer from the bore loads
Run folders: /tmp/film-mount-runs/<label>/ (FILM_MOUNT_RUNS moves them).
"""
from __future__ import annotations

import argparse
import csv
import math
import os
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "frame_mount"))
import frame_mount as fm  # noqa: E402  (housing_sets: the mount's overrides, one definition)

RUNS = Path(os.environ.get("FILM_MOUNT_RUNS", "/tmp/film-mount-runs"))
SCENE = "test-gearbox-runup-double-helical"
MEAN_RPM = (800.0, 1500.0)


def label(case, bearings, mesh, c_scale=1.0, k_mode="films", radiation="erp", moment="shuttling") -> str:
    s = f"{mesh}_{case}_{bearings}"
    if bearings == "fluid_film":
        s += f"_c{c_scale:g}" + ("" if k_mode == "films" else f"_{k_mode}")
    s += "" if moment == "shuttling" else f"_moment-{moment}"
    return s + ("" if radiation == "erp" else f"_{radiation}")


def patch(c_scale: float, k_mode: str) -> None:
    """Wrap the fluid-film position result: C -> c_scale C, K -> (K + K^T)/2 with k_mode "sym"."""
    from housingfe.bearings import configurations as cfg

    original = cfg._fluid_film_result

    def scaled(*args, **kwargs):
        res = original(*args, **kwargs)
        res.C = c_scale * res.C
        if k_mode == "sym":
            res.K = 0.5 * (res.K + res.K.T)
        return res

    cfg._fluid_film_result = scaled
    # the control must act on what the run-up takes (Drivetrain.configuration_matrices -> bearing_matrices ->
    # evaluate): checked here on the configuration's representative load case, not assumed
    loads = cfg.representative_loads("double_helical")
    raw = {p: (original(ch, np.asarray(loads[p], float), cfg.REPRESENTATIVE_SPEEDS_RPM, "reynolds"))
           for p, ch in cfg.configurations()["fluid_film"].positions.items()}
    for p, (K, C) in cfg.bearing_matrices("fluid_film", loads, cfg.REPRESENTATIVE_SPEEDS_RPM).items():
        K_raw = raw[p].K
        K_want = 0.5 * (K_raw + K_raw.T) if k_mode == "sym" else K_raw
        if not (np.allclose(C, c_scale * raw[p].C, rtol=1e-12, atol=0.0)
                and np.allclose(K[:2, :2], K_want[:2, :2], rtol=1e-12, atol=0.0)):
            raise SystemExit(f"film_mount: the patch of _fluid_film_result does not reach bearing_matrices ({p})")


def child(argv) -> int:
    """In the run's own process: patch, then `housingfe` with the given arguments."""
    c_scale, k_mode = float(argv[0]), argv[1]
    if c_scale != 1.0 or k_mode != "films":
        patch(c_scale, k_mode)
    from housingfe.cli import main

    return main(argv[2:])


def run(case, bearings, mesh, c_scale=1.0, k_mode="films", radiation="erp", moment="shuttling",
        speed_min=800.0) -> Path:
    out = RUNS / label(case, bearings, mesh, c_scale, k_mode, radiation, moment)
    args = ["run", SCENE, "--out", str(out), "--set", f"drivetrain.bearings={bearings}",
            "--set", "runup.torques_nm=[2000.0]", "--set", f"runup.speed_min_rpm={speed_min}"]
    for s in fm.runup_overrides(case, mesh):
        args += ["--set", s]
    if moment != "shuttling":
        args += ["--set", f'runup.mesh_moment="{moment}"']
    if radiation == "numerical":
        args += ["--set", 'radiation.models=["erp","foller","numerical"]']
    cmd = [sys.executable, str(Path(__file__).resolve()), "_child", str(c_scale), k_mode] + args
    RUNS.mkdir(parents=True, exist_ok=True)
    fm.timed_run(cmd, out, RUNS / f"{out.name}.log", out.name)
    return out


# ------------------------------------------------------------------------------------------------ reading
def curve(folder: Path, route: str, col: str = "LwA_dB", radiation: str = "erp") -> dict:
    """{speed rpm: value} of runup.csv's column for a route and radiation model."""
    with open(folder / "runup.csv") as fh:
        return {float(r["speed_rpm"]): float(r[col]) for r in csv.DictReader(fh)
                if r["route"] == route and r["radiation"] == radiation and r[col] != ""}


def diff_stats(a: dict, b: dict) -> tuple[float, float]:
    """Mean and s.d. over MEAN_RPM of b - a speed by speed (dB), the thesis' (and the study's) measure."""
    s = [k for k in sorted(a) if MEAN_RPM[0] <= k <= MEAN_RPM[1]]
    d = np.array([b[k] - a[k] for k in s])
    return float(d.mean()), float(d.std())


def harmonics(folder: Path, route: str, col: str, radiation: str = "erp") -> dict:
    """{(speed, harmonic): value} of runup_harmonics.csv."""
    with open(folder / "runup_harmonics.csv") as fh:
        return {(float(r["speed_rpm"]), int(r["harmonic"])): float(r[col]) for r in csv.DictReader(fh)
                if r["route"] == route and r["radiation"] == radiation and r[col] != ""}


def parse(name: str) -> dict:
    """The run's settings from its folder name (label)."""
    parts = name.split("_")
    out = {"mesh": parts[0], "case": parts[1], "c_scale": "", "k_mode": "", "moment": "shuttling",
           "radiation": "erp"}
    rest = "_".join(parts[2:])
    out["bearings"] = "fluid_film" if rest.startswith("fluid_film") else "cylindrical_roller"
    tail = rest[len(out["bearings"]):].strip("_").split("_") if rest[len(out["bearings"]):] else []
    for t in tail:
        if t.startswith("c") and out["bearings"] == "fluid_film":
            out["c_scale"] = float(t[1:])
        elif t == "sym":
            out["k_mode"] = "sym"
        elif t.startswith("moment-"):
            out["moment"] = t[len("moment-"):]
        elif t == "numerical":
            out["radiation"] = "numerical"
    if out["bearings"] == "fluid_film" and not out["k_mode"]:
        out["k_mode"] = "films"
    return out


def reference_of(name: str) -> str:
    """The rollers' run on the same mesh, mount, mesh moment and radiation setting."""
    p = parse(name)
    return label(p["case"], "cylindrical_roller", p["mesh"], moment=p["moment"], radiation=p["radiation"])


def table_rows() -> list[dict]:
    """Per run and route: fluid films (or rollers) - rollers of the same setting, mean +- s.d. over 800-1500 rpm
    of L_WA and, split, of the route's source line level and of L_v (the transfer's share), max L_WA."""
    rows = []
    for f in sorted(p for p in RUNS.iterdir() if p.is_dir() and (p / "runup.csv").is_file()):
        p = parse(f.name)
        ref = RUNS / reference_of(f.name)
        if not (ref / "runup.csv").is_file():
            continue
        wall = (f / "wall_s.txt").read_text().strip() if (f / "wall_s.txt").is_file() else ""
        rads = [p["radiation"]] if p["radiation"] == "erp" else ["erp", "numerical"]
        for rad in rads:
            for route in ("tf_omega", "mesh_force"):
                a, b = curve(ref, route, radiation=rad), curve(f, route, radiation=rad)
                m, sd = diff_stats(a, b)
                src = "L_omega_dB" if route == "tf_omega" else "L_omega_coupled_dB"
                ms, _ = diff_stats(curve(ref, route, src, rad), curve(f, route, src, rad))
                mv, _ = diff_stats(curve(ref, route, "Lv_dB", rad), curve(f, route, "Lv_dB", rad))
                kmax = max(b, key=b.get)
                rows.append({"run": f.name, **p, "sigma": rad, "route": route, "reference": ref.name,
                             "dLwA_mean_dB": round(m, 2), "dLwA_sd_dB": round(sd, 2),
                             "dL_omega_mean_dB": round(ms, 2), "dLv_mean_dB": round(mv, 2),
                             "LwA_max_dBA": round(b[kmax], 1), "at_rpm": kmax,
                             "ref_LwA_max_dBA": round(max(a.values()), 1), "wall_s": wall})
    return rows


def energy_db(values) -> float:
    return float(10 * np.log10(np.sum(10 ** (np.asarray(list(values)) / 10))))


def harmonic_rows(n_max: int = 6) -> list[dict]:
    """Per run, route and harmonic n: the L_WA of line n summed (energy) over the run-up speeds 800-1500 rpm, the
    reference's (rollers of the same setting), and the share of the run's total L_WA energy that line carries:
    which lines make the mean, and which the films change."""
    rows = []
    for f in sorted(p for p in RUNS.iterdir() if p.is_dir() and (p / "runup_harmonics.csv").is_file()):
        p = parse(f.name)
        ref = RUNS / reference_of(f.name)
        if p["radiation"] != "erp" or not (ref / "runup_harmonics.csv").is_file():
            continue
        for route in ("tf_omega", "mesh_force"):
            a, b = harmonics(ref, route, "LwA_dB"), harmonics(f, route, "LwA_dB")
            sel = lambda h, n: [v for (k, m), v in h.items() if m == n and MEAN_RPM[0] <= k <= MEAN_RPM[1]]  # noqa: E731
            tot_a = energy_db(v for (k, _), v in a.items() if MEAN_RPM[0] <= k <= MEAN_RPM[1])
            tot_b = energy_db(v for (k, _), v in b.items() if MEAN_RPM[0] <= k <= MEAN_RPM[1])
            for n in range(1, n_max + 1):
                if not sel(a, n):
                    continue
                la, lb = energy_db(sel(a, n)), energy_db(sel(b, n))
                rows.append({"run": f.name, **p, "route": route, "harmonic": n, "LwA_energy_ref_dB": round(la, 2),
                             "LwA_energy_dB": round(lb, 2), "delta_dB": round(lb - la, 2),
                             "share_ref": round(10 ** ((la - tot_a) / 10), 3),
                             "share": round(10 ** ((lb - tot_b) / 10), 3)})
    return rows


def write_table() -> list[dict]:
    rows = table_rows()
    with open(HERE / "film_mount.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    hrows = harmonic_rows()
    with open(HERE / "film_mount_harmonics.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(hrows[0]))
        w.writeheader()
        w.writerows(hrows)
    for r in rows:
        print(f"{r['run']:48s} {r['sigma']:9s} {r['route']:10s} d {r['dLwA_mean_dB']:+6.2f} +- {r['dLwA_sd_dB']:4.2f}"
              f"  src {r['dL_omega_mean_dB']:+6.2f}  Lv {r['dLv_mean_dB']:+6.2f}  max {r['LwA_max_dBA']:5.1f}"
              f" @{r['at_rpm']:g} (ref {r['ref_LwA_max_dBA']:5.1f})  {r['wall_s']} s")
    return rows


# ------------------------------------------------------------------------------------------------ modes
def gearbox_model(case: str, bearings: str, mesh: str, extra: tuple = ()):
    """The run-up's coupled gearbox model (2000 N m, bearings at drivetrain.bearing_speed_rpm = 1500 rpm), built as
    `housingfe run` builds it (frame_mount.coupled_model on the double helical scene); with `extra` overrides.
    Returns (model, scene spec, drivetrain)."""
    from mpi4py import MPI

    from housingfe.runup.chain import build_gearbox_model
    from housingfe.runup.scene import drivetrain_of, housing_model_for, load_runup_scene, matched_drivetrains
    from housingfe.scene import load_housing_scene

    over = fm.runup_overrides(case, mesh) + [f"drivetrain.bearings={bearings}", "runup.torques_nm=[2000.0]", *extra]
    scene, path = load_runup_scene(SCENE, over)
    spec = scene.runup
    hs, _ = load_housing_scene(scene.housing.scene, list(scene.housing.set))
    dts = {2000.0: drivetrain_of(scene.drivetrain, 2000.0, spec.drive_line_model)}
    model = housing_model_for(hs, spec.f_max_hz, MPI.COMM_WORLD)
    dts, _ = matched_drivetrains(scene.housing, model, dts, path)
    gm = build_gearbox_model(model, dts[2000.0], spec.f_max_hz, damping_ratio=spec.damping_ratio,
                             basis_factor=spec.basis_factor)
    return gm, spec, dts[2000.0]


def mode_rows(case: str, mesh: str, f_top: float = 1100.0) -> list[dict]:
    """Per bearing configuration the coupled modes up to f_top (Hz): frequency, interior share of the kinetic
    energy, share of the strain energy in the mount's springs (u^T K_f u / omega^2), and the damping ratio the
    films' C alone gives the (undamped, symmetric-K) mode, zeta_film = phi^T C phi / (2 omega phi^T M phi): what
    the films add to the modal 4 %."""
    from housingfe.solvers import blocks
    from housingfe.solvers.harmonic import project

    rows = []
    for bearings in ("cylindrical_roller", "fluid_film"):
        gm = gearbox_model(case, bearings, mesh)[0]
        st, basis = gm.structure, gm.basis
        n0 = basis.rigid_count
        freqs = np.asarray(basis.frequencies_hz[n0:])
        keep = int(np.sum(freqs <= f_top))
        vecs = list(basis.vectors[n0:n0 + keep])
        _, Mm, Cm = project(vecs, st.K, st.M, st.C) if st.C is not None else (None, project(vecs, st.K, st.M)[1],
                                                                               None)
        omega = 2 * np.pi * freqs[:keep]
        zeta = np.zeros(keep) if Cm is None else np.diag(Cm) / (2 * omega * np.diag(Mm))
        mount = np.zeros(keep)
        if case != "fixed":
            from dolfinx.fem.petsc import assemble_matrix

            from housingfe.fe.model import foundation_forms

            housing = st.model
            (form,) = foundation_forms(housing.scene.supports, housing.housing, housing.V)
            Kf = assemble_matrix(form)
            Kf.assemble()
            U = blocks.columns([st.fe_vector(q) for q in vecs])
            mount = np.einsum("ij,ij->j", U, blocks.mat_block(Kf, U)) / (omega ** 2 * np.diag(Mm))
        if bearings == "fluid_film":
            rows += stability_rows(gm, case, mesh)
        for i in range(keep):
            share = float(gm.interior_share[i])
            kind = "on the mount" if mount[i] >= 0.5 else "interior" if share >= 0.5 else "housing"
            rows.append({"mesh": mesh, "case": case, "bearings": bearings, "index": i + 1,
                         "frequency_hz": round(float(freqs[i]), 1), "type": kind,
                         "interior_share": round(share, 3), "mount_energy_share": round(float(mount[i]), 3),
                         "zeta_film": round(float(zeta[i]), 4)})
    return rows


def stability_rows(gm, case: str, mesh: str, f_top: float = 3000.0) -> list[dict]:
    """The films' model at 1500 rpm on its Ritz space with the films' C scaled by 0 and 1 (and K as computed or
    made symmetric), modal 4 % on top: the complex modes up to f_top, their damping ratio -Re(s)/|s|; a mode with
    Re(s) > 0 is self-excited (oil whirl): a harmonic response of it has no physical meaning."""
    sysr = gm.reduction.system
    n = sysr.Kr.shape[0]
    rows = []
    for k_mode in ("films", "sym"):
        K = sysr.Kr if k_mode == "films" else 0.5 * (sysr.Kr + sysr.Kr.T)
        for c in (0.0, 1.0):
            C = c * sysr.Cr + (sysr.D if sysr.D is not None else 0.0)
            Minv = np.linalg.inv(sysr.Mr)
            A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
            lam = np.linalg.eigvals(A)
            lam = lam[(lam.imag > 0) & (lam.imag / (2 * np.pi) <= f_top)]
            lam = lam[np.argsort(lam.imag)]
            for i, s_ in enumerate(lam):
                rows.append({"mesh": mesh, "case": case, "bearings": f"fluid_film c{c:g} {k_mode}",
                             "index": i + 1, "frequency_hz": round(float(abs(s_)) / (2 * np.pi), 1),
                             "type": "complex mode" + (" UNSTABLE" if s_.real > 0 else ""), "interior_share": "",
                             "mount_energy_share": "", "zeta_film": round(float(-s_.real / abs(s_)), 4)})
    return rows


def merge_rows(path: Path, cases, mesh, compute) -> list[dict]:
    """Rows of `path` for other meshes/cases kept, those of (mesh, cases) computed anew by compute(case, mesh)."""
    old = []
    if path.is_file():
        with open(path) as fh:
            old = [r for r in csv.DictReader(fh) if not (r["mesh"] == mesh and r["case"] in cases)]
    rows = old + [r for c in cases for r in compute(c, mesh)]
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[-1]))
        w.writeheader()
        w.writerows(rows)
    return rows


def write_modes(cases, mesh) -> None:
    rows = merge_rows(HERE / "film_mount_modes.csv", cases, mesh, mode_rows)
    for r in rows:
        print(r)


# ------------------------------------------------------------------------------------------------ probe (why C raises
# the higher harmonics on the mount): the run-up's own model, the films' C changed on the reduced system only
def probe_model(case: str, mesh: str):
    """(scene spec, the run-up's coupled model following the speeds, the source) of the films' run (K made
    symmetric, C as computed: `patch(1, "sym")`), built as `housingfe run` builds it (housingfe.runup.scene
    .run_scene: one torque, 2000 N m)."""
    from housingfe.runup.chain import follow_speeds
    from housingfe.runup.scene import _source

    patch(1.0, "sym")
    gm, spec, dt = gearbox_model(case, "fluid_film", mesh, ("runup.speed_min_rpm=800.0",))
    source = _source(dt, spec, spec.misalignment_model)
    source.adopt(source.prepared(spec.torques_nm))
    return spec, follow_speeds(gm, spec.speeds), source


def film_damping(m, select=None) -> np.ndarray:
    """The films' C projected on the Ritz vectors of speed model m: sum over the bearings of X_e^T C_e X_e (N s/m
    in Ritz coordinates; X_e the vectors' rows at the element's nodes).  select(element, i, j) -> bool keeps
    entry (i, j) of C_e (default all)."""
    from housingfe.drivetrain.bore_loads import node_rows

    els = m.structure.parts.bearings
    rows = node_rows(m.structure, m.reduction.vectors, sorted({n for e in els for n in e.nodes}))
    n = len(m.reduction.vectors)
    out = np.zeros((n, n))
    for e in els:
        if e.C is None:
            continue
        X = np.vstack([rows[node] for node in e.nodes])
        Ce = np.array(e.C, float)
        if select is not None:
            Ce = Ce * np.array([[select(e, i, j) for j in range(Ce.shape[1])] for i in range(Ce.shape[0])], float)
        out += X.T @ Ce @ X
    return out


def variant(m, change):
    """The model following the speeds with each speed model's reduced C replaced: change(speed model, Cr) -> new
    Cr (N s/m in Ritz coordinates; Cr the film's C as the run has it, the modal D stays)."""
    from dataclasses import replace

    done = {}
    sm = {}
    for s, mv in m.speed_models.items():
        if id(mv) not in done:
            Cr = mv.reduction.system.Cr
            done[id(mv)] = replace(mv, reduction=mv.reduction.with_change(np.zeros_like(Cr), change(mv, Cr) - Cr))
        sm[s] = done[id(mv)]
    return replace(m, speed_models=sm)


def line_matrix(s, w: float, K, C):
    """The reduced dynamic stiffness K + i omega (C + D) - omega^2 Mr (N/m in Ritz coordinates) at omega (rad/s)."""
    return K + 1j * w * (C + s.D) - w * w * s.Mr


def solve_line(m, speed: float, frequency: float, make, amps: dict, i: int):
    """One line on its speed's reduced system with (K, C) = make(speed model, omega, system): the coordinates under
    the route's 1 N m wheel torque (tf_omega) and under the line's mesh excitation (mesh_force, amplitudes `amps`
    indexed by line i), and the speed model, its ReducedSystem, omega (rad/s) and the K used."""
    mv = m.at_speed(speed)
    s, names = mv.reduction.system, mv.reduction.names
    w = 2 * math.pi * frequency
    K, C = make(mv, w, s)
    Z = line_matrix(s, w, K, C)
    F = sum(s.Fr[:, names.index(k)] * (a[i] if np.ndim(a) else a) for k, a in amps.items())
    sol = np.linalg.solve(Z, np.column_stack([s.Fr[:, names.index("wheel_torque")], F]))
    return sol[:, 0], sol[:, 1], mv, s, w, K


def solve_lines(m, lines, make) -> dict:
    """Both routes on every line of `lines`, each line solved on its speed's reduced system with (K, C) =
    make(speed model, omega rad/s, its ReducedSystem) in place of (Kr, Cr) (the modal D stays):
    (Kr' + i omega (Cr' + D) - omega^2 Mr) c = Fr.  Returns per line (dB): Lv_tf = the source's L_omega + TF_omega
    (eq. 5.5), Lv_unit and Lw_unit (housing L_v and the wheel's L_omega under the route's 1 N m: TF_omega =
    Lv_unit - Lw_unit), Lv_mf (the mesh_force route: lines' mesh excitation and shuttling moment)."""

    from housingfe.runup.chain import _wheel_omega_level

    red = m.reduction
    f, sp = lines.frequency, lines.speed
    amps = lines.mesh_amplitudes()
    n = len(red.vectors)
    cu, cm = np.zeros((n, len(f)), complex), np.zeros((n, len(f)), complex)
    for i in range(len(f)):
        cu[:, i], cm[:, i] = solve_line(m, sp[i], f[i], make, amps, i)[:2]
    ru, rm = red.response_of(f, cu), red.response_of(f, cm)
    Lvu, Lwu = ru.velocity_level_db, _wheel_omega_level(m, ru, f)
    return {"Lv_tf": lines.L_omega + Lvu - Lwu, "Lv_unit": Lvu, "Lw_unit": Lwu, "Lv_mf": rm.velocity_level_db}


def line_energy(lines, values, n) -> float:
    """10 lg sum over 800-1500 rpm of 10^((value + A(f))/10) on harmonic n: for L_v the line's L_WA energy up to
    the constant L_S (sigma = 1), the measure of film_mount_harmonics.csv (dB)."""

    sel = np.flatnonzero((lines.harmonic == n) & (lines.speed >= MEAN_RPM[0]) & (lines.speed <= MEAN_RPM[1]))
    return line_energy_at(lines, sel, np.asarray(values)[sel])


def _is_pinion(e, i, j):
    return e.nodes[0].startswith("pinion")


def _is_wheel(e, i, j):
    return e.nodes[0].startswith("wheel")


def _translations(e, i, j):
    return i % 6 < 3 and j % 6 < 3


def _tilts(e, i, j):
    return i % 6 >= 3 and j % 6 >= 3


def _modal_diagonal(mv, w, s):
    """The films' C as a proportional damping: only the diagonal of Y^T Cr Y on the reduced system's undamped modes
    Y (mass-normalised), back in Ritz coordinates: Ms Y diag(Y^T Cr Y) Y^T Ms."""
    MY = 0.5 * (s.Mr + s.Mr.T) @ s.Y
    return s.Kr, (MY * np.diag(s.Y.T @ s.Cr @ s.Y)) @ MY.T


def probe_variants() -> dict:
    """{name: make(speed model, omega, ReducedSystem) -> (K, C)}: the films' C (Cr, the films only: checked in
    `probe`) changed on the reduced system, one change each; "c0" is the reference."""

    memo = {}

    def part(select):
        def make(mv, w, s):
            key = (id(mv), select.__name__)
            if key not in memo:
                memo[key] = film_damping(mv, select)
            return s.Kr, memo[key]
        return make

    return {
        "c1 (C as computed)": lambda mv, w, s: (s.Kr, s.Cr),
        "c0 (no C)": lambda mv, w, s: (s.Kr, 0 * s.Cr),
        "C replaced by the stiffness omega C (no loss)": lambda mv, w, s: (s.Kr + w * s.Cr, 0 * s.Cr),
        "C x 0.25": lambda mv, w, s: (s.Kr, 0.25 * s.Cr),
        "C x 4": lambda mv, w, s: (s.Kr, 4 * s.Cr),
        "C x 20": lambda mv, w, s: (s.Kr, 20 * s.Cr),
        "C only on lines below 1 kHz": lambda mv, w, s: (s.Kr, s.Cr if w < 2 * math.pi * 1000 else 0 * s.Cr),
        "C only on lines above 1 kHz": lambda mv, w, s: (s.Kr, s.Cr if w >= 2 * math.pi * 1000 else 0 * s.Cr),
        "C diagonal on the undamped modes (no modal coupling)": _modal_diagonal,
        "C translations only": part(_translations),
        "C tilts only": part(_tilts),
        "C pinion bearings only": part(_is_pinion),
        "C wheel bearings only": part(_is_wheel),
    }


def probe_rows(case: str, mesh: str) -> list[dict]:
    """Why C raises the higher harmonics on the mount: per variant (`probe_variants`; plus the excitation of the
    no-C model on the C model, and the films held at 1500 rpm for every line), route and harmonic n the line's
    L_WA energy 800-1500 rpm (sigma = 1, up to the constant L_S) and its change against no C; for tf_omega also the
    changes of TF_omega's parts (housing L_v and wheel L_omega under 1 N m), for mesh_force of L_F."""
    import time
    from dataclasses import replace

    from housingfe import levels
    from housingfe.runup.chain import run_source

    t0 = time.perf_counter()
    spec, m, source = probe_model(case, mesh)
    mv = m.at_speed(1500.0)
    err = np.linalg.norm(mv.reduction.system.Cr - film_damping(mv)) / np.linalg.norm(mv.reduction.system.Cr)
    if err > 1e-10:
        raise SystemExit(f"film_mount probe: the reduced C is not the films' alone (rel. difference {err:.1e})")
    t_build = time.perf_counter() - t0

    def source_lines(model):
        return run_source(model, source, spec.speeds, [2000.0], spec.f_max_hz, spec.source_receptance,
                          spec.mesh_moment_model, spec.mesh_friction)[0]

    variants = probe_variants()
    m0 = variant(m, lambda mv, Cr: 0 * Cr)
    lines1, lines0 = source_lines(m), source_lines(m0)
    res = {k: (lines1, solve_lines(m, lines1, make)) for k, make in variants.items()}
    res["c1 with the excitation of c0 (coupled source without C)"] = (lines0, solve_lines(
        m, lines0, variants["c1 (C as computed)"]))
    fixed = replace(m, speed_models={s: m.at_speed(1500.0) for s in m.speed_models})
    lf = source_lines(fixed)
    for c in (1, 0):
        res[f"c{c}, films at 1500 rpm for every line"] = (lf, solve_lines(fixed, lf, variants[
            "c1 (C as computed)" if c else "c0 (no C)"]))
    L_F = {1: levels.level(np.abs(lines1.mesh_excitation) ** 2, levels.F0),
           0: levels.level(np.abs(lines0.mesh_excitation) ** 2, levels.F0)}
    rows = []
    for name, (ln, q) in res.items():
        ref_ln, ref = res["c0, films at 1500 rpm for every line" if "1500 rpm" in name else "c0 (no C)"]
        for route, key in (("tf_omega", "Lv_tf"), ("mesh_force", "Lv_mf")):
            for n in range(1, 6):
                e, e0 = line_energy(ln, q[key], n), line_energy(ref_ln, ref[key], n)
                row = {"mesh": mesh, "case": case, "variant": name, "route": route, "harmonic": n,
                       "LwA_energy_minus_LS_dB": round(e, 2), "delta_vs_no_C_dB": round(e - e0, 2)}
                if route == "tf_omega":
                    for k in ("Lv_unit", "Lw_unit"):
                        row[f"d_{k}_dB"] = round(line_energy(ln, q[k], n) - line_energy(ref_ln, ref[k], n), 2)
                    row["d_L_F_dB"] = ""
                else:
                    row["d_Lv_unit_dB"] = row["d_Lw_unit_dB"] = ""
                    row["d_L_F_dB"] = (round(line_energy(lines1, L_F[1], n) - line_energy(lines0, L_F[0], n), 2)
                                       if name == "c1 (C as computed)" else "")
                rows.append(row)
    wall = time.perf_counter() - t0
    print(f"probe {case} {mesh}: model {t_build:.1f} s, total {wall:.1f} s")
    return rows


def write_probe(cases, mesh) -> None:
    rows = merge_rows(HERE / "film_mount_probe.csv", cases, mesh, probe_rows)
    for c in cases:
        for route in ("tf_omega", "mesh_force"):
            print(f"{c} {route}: change against no C, n = 1..5 (dB)")
            for v in dict.fromkeys(r["variant"] for r in rows):
                d = [r["delta_vs_no_C_dB"] for r in rows if r["case"] == c and r["route"] == route
                     and r["variant"] == v and r["mesh"] == mesh]
                print(f"  {v:58s} " + " ".join(f"{float(x):+6.2f}" for x in d))


# ------------------------------------------------------------------------------------------------ stiff (why a stiff
# shaft-bore link raises the lines on the mount and lowers them on the fixed feet)
STIFF_VARIANTS = ("c0 (no C)", "C replaced by the stiffness omega C (no loss)", "c1 (C as computed)")
STIFF_BAND_HZ = (900.0, 3100.0)     # the n = 3-5 lines over 800-1500 rpm: 0.96-3.0 kHz


BORE_TRANSLATIONS = "C translations only, as the stiffness omega C"


def _stiff_make(name):
    """make(speed model, omega, ReducedSystem) -> (K, C) of a `probe_variants` entry, or of BORE_TRANSLATIONS (C's
    translation block as the lossless stiffness omega C, for `bores`)."""
    variants = probe_variants()
    if name == BORE_TRANSLATIONS:
        part = variants["C translations only"]
        return lambda mv, w, s: (s.Kr + w * part(mv, w, s)[1], 0 * s.Cr)
    return variants[name]


def rigid_projector(m):
    """(P, Q) of the housing's surface normal velocity and its six rigid-body motions: P = X^T W R (vectors x 6),
    Q = R^T W R (6 x 6); X the Ritz vectors' housing fields, R the coupled structure's exact rigid-body motions'
    housing fields, W the observed surface's normal Gram form (m^2).  The rigid part of a response c is the
    W-orthogonal projection a = Q^-1 P^T c, its <v_n^2> share a^H Q a / c^H G c."""
    from housingfe.solvers import blocks

    st, red = m.structure, m.reduction
    W = red.observer.W
    R = blocks.columns([st.fe_vector(r) for r in st.rigid_body_vectors()])
    X = blocks.columns([st.fe_vector(q) for q in red.vectors])
    WR = blocks.mat_block(W, R)
    return blocks.gram(X, WR, W.getComm()), blocks.gram(R, WR, W.getComm())


def _rigid_share(c, G, P, Q):
    a = np.linalg.solve(Q, P.T @ c)
    return float(np.real(np.conj(a) @ Q @ a) / np.real(np.conj(c) @ G @ c))


def _bore_force(mv, memo, w, vname, c) -> float:
    """Sum over the bearings of |f|^2 (N^2, rms) of the three force components the films put on the bore masters
    at Ritz solution c: f = bore rows of (K_e + i omega C_e) X_e c, with the variant's C (none; as the stiffness
    omega C; as computed)."""
    return float(np.sum(np.abs(bore_loads(mv, memo, w, vname, c).reshape(-1, 6)[:, :3]) ** 2))


def bore_loads(mv, memo, w, vname, c) -> np.ndarray:
    """The loads the films put on the bore masters at Ritz solution(s) c, bore by bore (Fx Fy Fz Mx My Mz: N, N m;
    (6 bearings,) for one solution, (6 bearings, k) for k columns): housingfe.drivetrain.bore_loads.bore_loads,
    bore rows of -(K_e + s C_e) X_e c, with the variant's C (none; as the stiffness omega C, s = omega; as computed,
    s = i omega)."""
    from dataclasses import replace

    from housingfe.drivetrain.bore_loads import bore_loads as library_bore_loads

    els = _bore_elements(mv, memo)
    if vname == BORE_TRANSLATIONS:
        mask = np.array([[_translations(None, i, j) for j in range(12)] for i in range(12)], float)
        els = [replace(e, C=e.C * mask) for e in els]
    if vname.startswith("c0"):
        els = [replace(e, C=0 * e.C) for e in els]
    c = np.asarray(c)
    n = 1 if c.ndim == 1 else c.shape[1]
    s = w if "stiffness" in vname else 1j * w
    out = library_bore_loads(els, w / (2 * math.pi), c, c_factor=np.full(n, s))
    return out.reshape(-1) if c.ndim == 1 else out.reshape(n, -1).T


def _bore_elements(mv, memo) -> list:
    """The speed model's bearing elements (housingfe.drivetrain.bore_loads.BearingElement: 12x12 K_e, C_e at the
    shaft node and bore master, X_e the Ritz vectors' rows at the two nodes); memoised per speed model."""
    from housingfe.drivetrain.bore_loads import structure_bearing_elements

    key = id(mv)
    if key not in memo:
        memo[key] = structure_bearing_elements(mv.structure, mv.reduction.vectors)
    return memo[key]


def stiff_rows(case: str, mesh: str) -> list[dict]:
    """Per variant of STIFF_VARIANTS (no C, C as the lossless stiffness omega C, C as computed), route (tf_omega:
    housing L_v under the wheel's 1 N m; mesh_force) and harmonic n = 1..5, over 800-1500 rpm (line energies with
    A(f), sigma = 1, as `probe`): the housing's L_v energy, its split into the surface's rigid-body part and its
    elastic rest (W-orthogonal, `rigid_projector`), and the changes against no C; for n = 3-5 the modal picture:
    each line's Ritz solution on the undamped modes of (Ks + omega Cs [stiff variant] or Ks, Ms) at that line's
    speed model, z = Y^T Ms c, shares Re(z_i^* (Y^T G Y z)_i) / c^H G c (sum 1), the energy-weighted share per
    50 Hz bin of mode frequency; `diag_share` = sum_i |z_i|^2 (Y^T G Y)_ii / c^H G c (1 without cross terms)."""
    import time

    import scipy.linalg

    from housingfe import levels
    from housingfe.runup.chain import _wheel_omega_level, run_source

    t0 = time.perf_counter()
    spec, m, source = probe_model(case, mesh)
    lines = run_source(m, source, spec.speeds, [2000.0], spec.f_max_hz, spec.source_receptance,
                       spec.mesh_moment_model, spec.mesh_friction)[0]
    P, Q = rigid_projector(m)
    red = m.reduction
    G = red.reduced.gram
    t_build = time.perf_counter() - t0
    f, sp = lines.frequency, lines.speed
    amps = lines.mesh_amplitudes()
    A = levels.a_weighting_db(f)
    band = (sp >= MEAN_RPM[0]) & (sp <= MEAN_RPM[1])
    out, memo = {}, {}
    els = m.at_speed(1500.0).structure.parts.bearings
    if any(len(e.nodes) != 2 or np.shape(e.K) != (12, 12) for e in els):
        raise SystemExit("film_mount stiff: a bearing element is not a 12x12 shaft-node/bore pair")
    for vname in STIFF_VARIANTS:
        make = _stiff_make(vname)
        n = len(red.vectors)
        cu, cm = np.zeros((n, len(f)), complex), np.zeros((n, len(f)), complex)
        modal = {"tf_omega": {}, "mesh_force": {}}
        fb = {"tf_omega": np.zeros(len(f)), "mesh_force": np.zeros(len(f))}
        for i in range(len(f)):
            cu[:, i], cm[:, i], mv, s, w, K = solve_line(m, sp[i], f[i], make, amps, i)
            for route, c in (("tf_omega", cu[:, i]), ("mesh_force", cm[:, i])):
                fb[route][i] = _bore_force(mv, memo, w, vname, c)
            if band[i] and lines.harmonic[i] in (3, 4, 5):
                Ms = 0.5 * (s.Mr + s.Mr.T)
                lam, Y = scipy.linalg.eigh(0.5 * (K + K.T), Ms)
                fy = np.sqrt(np.clip(lam, 0, None)) / (2 * math.pi)
                GY = Y.T @ G @ Y
                for route, c in (("tf_omega", cu[:, i]), ("mesh_force", cm[:, i])):
                    z = Y.T @ Ms @ c
                    tot = np.real(np.conj(c) @ G @ c)
                    part = np.real(np.conj(z) * (GY @ z)) / tot
                    modal[route][i] = (fy, part, float(np.sum(np.abs(z) ** 2 * np.diag(GY)) / tot))
        ru = red.response_of(f, cu)
        out[(vname, "tf_line")] = lines.L_omega + ru.velocity_level_db - _wheel_omega_level(m, ru, f)
        for route, c in (("tf_omega", cu), ("mesh_force", cm)):
            Lv = red.response_of(f, c).velocity_level_db
            rb = np.array([_rigid_share(c[:, i], G, P, Q) for i in range(len(f))])
            out[(vname, route)] = (Lv, rb, modal[route], levels.level(fb[route], levels.F0))
    rows = []
    for (vname, route), value in out.items():
        if route == "tf_line":
            continue
        Lv, rb, modal, LF = value
        Lv0, rb0, _, LF0 = out[(STIFF_VARIANTS[0], route)]
        tf, tf0 = out[(vname, "tf_line")], out[(STIFF_VARIANTS[0], "tf_line")]
        for nh in range(1, 6):
            def e(values):
                return line_energy(lines, values, nh)
            tot, rig = e(Lv), e(Lv + 10 * np.log10(np.clip(rb, 1e-30, None)))
            ela = e(Lv + 10 * np.log10(np.clip(1 - rb, 1e-30, None)))
            tot0, rig0 = e(Lv0), e(Lv0 + 10 * np.log10(np.clip(rb0, 1e-30, None)))
            ela0 = e(Lv0 + 10 * np.log10(np.clip(1 - rb0, 1e-30, None)))
            row = {"mesh": mesh, "case": case, "variant": vname, "route": route, "harmonic": nh,
                   "Lv_energy_dB": round(tot, 2), "rigid_share": round(10 ** ((rig - tot) / 10), 3),
                   "d_Lv_vs_no_C_dB": round(tot - tot0, 2), "d_rigid_vs_no_C_dB": round(rig - rig0, 2),
                   "d_elastic_vs_no_C_dB": round(ela - ela0, 2),
                   "d_bore_force_vs_no_C_dB": round(e(LF) - e(LF0), 2),
                   "d_tf_line_vs_no_C_dB": round(e(tf) - e(tf0), 2) if route == "tf_omega" else "",
                   "diag_share": "", "top_modes": ""}
            sel = [i for i in modal if lines.harmonic[i] == nh]
            if sel:
                wts = np.array([10 ** ((Lv[i] + A[i]) / 10) for i in sel])
                wts /= wts.sum()
                bins = {}
                for wgt, i in zip(wts, sel):
                    fy, part, _ = modal[i]
                    for fb, p in zip(np.round(fy / 50) * 50, part):
                        bins[fb] = bins.get(fb, 0.0) + wgt * p
                top = sorted(bins.items(), key=lambda kv: -kv[1])[:5]
                row["diag_share"] = round(float(sum(wgt * modal[i][2] for wgt, i in zip(wts, sel))), 3)
                row["top_modes"] = " ".join(f"{fb:.0f}Hz:{p:.2f}" for fb, p in top)
            rows.append(row)
    # the modes in the n = 3-5 band of the 1500 rpm speed model: undamped Ks, and Ks + omega Cs at 1.2 / 2 / 3 kHz
    mv = m.at_speed(1500.0)
    s = mv.reduction.system
    Ms = 0.5 * (s.Mr + s.Mr.T)
    for tag, Kx in [("Ks", s.Kr)] + [(f"Ks + omega C at {fk:g} Hz", s.Kr + 2 * math.pi * fk * s.Cr)
                                      for fk in (1200.0, 2000.0, 3000.0)]:
        lam, Y = scipy.linalg.eigh(0.5 * (Kx + Kx.T), Ms)
        fy = np.sqrt(np.clip(lam, 0, None)) / (2 * math.pi)
        inb = np.flatnonzero((fy >= STIFF_BAND_HZ[0]) & (fy <= STIFF_BAND_HZ[1]))
        rs = [_rigid_share(Y[:, k], G, P, Q) for k in inb]
        rows.append({"mesh": mesh, "case": case, "variant": f"modes 1500 rpm: {tag}", "route": "", "harmonic": "",
                     "Lv_energy_dB": "", "rigid_share": "", "d_Lv_vs_no_C_dB": "", "d_rigid_vs_no_C_dB": "",
                     "d_elastic_vs_no_C_dB": "", "d_bore_force_vs_no_C_dB": "", "d_tf_line_vs_no_C_dB": "",
                     "diag_share": len(inb),
                     "top_modes": " ".join(f"{fy[k]:.0f}Hz(rb{r:.2f})" for k, r in zip(inb, rs))})
    print(f"stiff {case} {mesh}: model {t_build:.1f} s, total {time.perf_counter() - t0:.1f} s", flush=True)
    return rows


def write_stiff(cases, mesh) -> None:
    rows = merge_rows(HERE / "film_mount_stiff.csv", cases, mesh, stiff_rows)
    for r in rows:
        if r["mesh"] == mesh and r["case"] in cases:
            print({k: v for k, v in r.items() if k != "mesh"})


# ------------------------------------------------------------------------------------------------ bores (why the
# clamped housing answers the stiff link's bore forces with less L_v)
# no C, C as omega C (all of it; its translation block only): all C-free, so one dynamic stiffness per line
BORE_VARIANTS = STIFF_VARIANTS[:2] + (BORE_TRANSLATIONS,)
BORE_QUANTITIES = ("Lv", "Lv_from_bore_loads", "F2", "M2", "resultant_F2", "resp_forces", "resp_moments",
                   "resp_forces_incoherent")


def bore_line(mv, memo, s, w, K, G, c_lines, vname) -> tuple[list[dict], float]:
    """One line: the housing's own transfer from the bore loads to the surface, A = H^H G H (6 per bore), and per
    Ritz solution in c_lines the energies of BORE_QUANTITIES (<v_n^2>-proportional c^H G c for responses, N^2 and
    (N m)^2 for loads) and the bore-by-bore sum |f|^2.  H comes from the coupled model itself: unit loads e_j on the
    bore masters give solutions V and total bore loads E = I + (film loads of V); the surface sees only the bore
    loads, so H = V E^-1 (checked: Lv_from_bore_loads = h^H A h against c^H G c).  Also returns A."""
    B = np.vstack([e.X[6:12] for e in _bore_elements(mv, memo)])
    V = np.linalg.solve(line_matrix(s, w, K, 0 * K), B.T)
    H = V @ np.linalg.inv(np.eye(B.shape[0]) + bore_loads(mv, memo, w, vname, V))
    A = np.conj(H.T) @ G @ H
    tr = np.tile(np.arange(6) < 3, B.shape[0] // 6)
    out = []
    for c in c_lines:
        h = bore_loads(mv, memo, w, vname, c)
        f, mo = h[tr], h[~tr]
        out.append({"Lv": np.real(np.conj(c) @ G @ c), "Lv_from_bore_loads": np.real(np.conj(h) @ A @ h),
                    "F2": np.sum(np.abs(f) ** 2), "M2": np.sum(np.abs(mo) ** 2),
                    "resultant_F2": np.sum(np.abs(f.reshape(-1, 3).sum(axis=0)) ** 2),
                    "resp_forces": np.real(np.conj(f) @ A[np.ix_(tr, tr)] @ f),
                    "resp_moments": np.real(np.conj(mo) @ A[np.ix_(~tr, ~tr)] @ mo),
                    "resp_forces_incoherent": np.real(np.sum(np.abs(f) ** 2 * np.diag(A)[tr])),
                    "per_bore_F2": np.sum(np.abs(f.reshape(-1, 3)) ** 2, axis=1)})
    return out, A


def bores_rows(case: str, mesh: str) -> list[dict]:
    """Per variant of BORE_VARIANTS, route and harmonic n = 3-5 over 800-1500 rpm (line energies with A(f), sigma
    = 1, as `stiff`): the housing's L_v, the same rebuilt from the bore loads (check), Sigma|f|^2, Sigma|m|^2, the
    bores' resultant force |Sigma_b f_b|^2 (on the fixed feet it goes into the feet), and the L_v the forces alone,
    the moments alone and the forces without their phases (Sigma_j |f_j|^2 A_jj) give through the housing's
    transfer A (`bore_line`); the bores' shares of Sigma|f|^2; the change of A between the variants (should be 0:
    it is the housing's own).  Last rows per route and n: each variant - no C (dB)."""
    import time

    from housingfe import levels
    from housingfe.runup.chain import run_source

    t0 = time.perf_counter()
    spec, m, source = probe_model(case, mesh)
    lines = run_source(m, source, spec.speeds, [2000.0], spec.f_max_hz, spec.source_receptance,
                       spec.mesh_moment_model, spec.mesh_friction)[0]
    G = m.reduction.reduced.gram
    f, sp, amps = lines.frequency, lines.speed, lines.mesh_amplitudes()
    sel = np.flatnonzero((sp >= MEAN_RPM[0]) & (sp <= MEAN_RPM[1]) & np.isin(lines.harmonic, (3, 4, 5)))
    Lv = {}
    for vname in BORE_VARIANTS:
        make = _stiff_make(vname)
        n = len(m.reduction.vectors)
        cu, cm = np.zeros((n, len(f)), complex), np.zeros((n, len(f)), complex)
        for i in range(len(f)):
            cu[:, i], cm[:, i] = solve_line(m, sp[i], f[i], make, amps, i)[:2]
        Lv[vname] = {"tf_omega": m.reduction.response_of(f, cu).velocity_level_db,
                     "mesh_force": m.reduction.response_of(f, cm).velocity_level_db, "cu": cu, "cm": cm}
    res, memo, A0, dA = {}, {}, {}, {}
    bore_names = [e.nodes[1] for e in m.at_speed(1500.0).structure.parts.bearings]
    for vname in BORE_VARIANTS:
        make = _stiff_make(vname)
        for i in sel:
            mv = m.at_speed(sp[i])
            s, w = mv.reduction.system, 2 * math.pi * f[i]
            K = make(mv, w, s)[0]
            q, A = bore_line(mv, memo, s, w, K, G, (Lv[vname]["cu"][:, i], Lv[vname]["cm"][:, i]), vname)
            if vname == BORE_VARIANTS[0]:
                A0[i] = A
            else:
                dA[(vname, i)] = np.linalg.norm(A - A0[i]) / np.linalg.norm(A0[i])
            for route, qq in zip(("tf_omega", "mesh_force"), q):
                res[(vname, route, i)] = qq
    rows = []
    for route in ("tf_omega", "mesh_force"):
        for nh in (3, 4, 5):
            idx = [i for i in sel if lines.harmonic[i] == nh]
            vals = {}
            for vname in BORE_VARIANTS:
                L = Lv[vname][route]
                r = {"mesh": mesh, "case": case, "variant": vname, "route": route, "harmonic": nh}
                for k in BORE_QUANTITIES:
                    x = np.array([res[(vname, route, i)][k] for i in idx])
                    if k.startswith(("Lv_", "resp_")):      # a response: the line's L_v scaled by its energy ratio
                        x = L[idx] + 10 * np.log10(x / np.array([res[(vname, route, i)]["Lv"] for i in idx]))
                    elif k == "Lv":
                        x = L[idx]
                    else:
                        x = levels.level(x, levels.F0)
                    r[k + "_dB"] = vals.setdefault(vname, {})[k] = round(line_energy_at(lines, idx, x), 2)
                pb = np.sum([res[(vname, route, i)]["per_bore_F2"] for i in idx], axis=0)
                r["bore_F2_shares"] = " ".join(f"{b}:{v:.2f}" for b, v in zip(bore_names, pb / pb.sum()))
                r["A_change"] = round(float(np.mean([dA[(vname, i)] for i in idx])), 4) if vname != BORE_VARIANTS[0] else ""
                rows.append(r)
            for vname in BORE_VARIANTS[1:]:
                d = {"mesh": mesh, "case": case, "variant": f"{vname} - no C", "route": route, "harmonic": nh}
                d.update({k + "_dB": round(vals[vname][k] - vals[BORE_VARIANTS[0]][k], 2) for k in BORE_QUANTITIES})
                rows.append({**d, "bore_F2_shares": "", "A_change": ""})
    print(f"bores {case} {mesh}: {time.perf_counter() - t0:.1f} s", flush=True)
    return rows


def line_energy_at(lines, idx, values) -> float:
    """10 lg sum over the lines idx of 10^((value + A(f))/10) (dB): `line_energy` on a chosen set of lines."""
    from housingfe import levels

    return energy_db(np.asarray(values) + levels.a_weighting_db(lines.frequency[idx]))


def write_bores(cases, mesh) -> None:
    rows = merge_rows(HERE / "film_mount_bores.csv", cases, mesh, bores_rows)
    for r in rows:
        if r["mesh"] == mesh and r["case"] in cases:
            print({k: v for k, v in r.items() if k != "mesh"})


# ------------------------------------------------------------------------------------------------ plot
DECOMPOSITION = (("stiffness: the films' K (made symmetric), no C", "c0_sym", None),
                 ("film damping C (on the symmetric K)", "c1_sym", "c0_sym"),
                 ("cross-coupled K (with C)", "c1", "c1_sym"))


def decomposition(rows: list[dict], mesh: str, case: str, route: str) -> list[tuple[str, float]]:
    """Fluid films - rollers split into the steps rollers -> the films' symmetric K without C -> with the films' C
    -> the films as computed (non-symmetric K): (step, Delta mean dB) each, from film_mount.csv's rows (sigma = 1,
    shuttling moment)."""
    def d(tag):
        if tag is None:
            return 0.0
        hit = [r for r in rows if r["run"] == f"{mesh}_{case}_fluid_film_{tag}" and r["route"] == route
               and r["sigma"] == "erp"]
        return float(hit[0]["dLwA_mean_dB"]) if hit else float("nan")
    out = [(lab, d(a) - d(b)) for lab, a, b in DECOMPOSITION]
    if not np.isfinite(d("c1_sym")):       # not run: C and the cross-coupled K together (the latter <= 0.01 dB)
        out[1] = (out[1][0], d("c1") - d("c0_sym"))
    return out


def plot(mesh: str = "default") -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with open(HERE / "film_mount.csv") as fh:
        rows = list(csv.DictReader(fh))
    with open(HERE / "film_mount_harmonics.csv") as fh:
        hrows = list(csv.DictReader(fh))
    fig, ax = plt.subplots(2, 2, figsize=(12, 8.5))
    styles = {("fixed", "cylindrical_roller"): ("k", "-"), ("fixed", "fluid_film_c1"): ("k", "--"),
              ("1e9", "cylindrical_roller"): ("tab:red", "-"), ("1e9", "fluid_film_c1"): ("tab:red", "--"),
              ("fixed", "fluid_film_c0_sym"): ("k", ":"), ("1e9", "fluid_film_c0_sym"): ("tab:red", ":")}
    for j, route in enumerate(("tf_omega", "mesh_force")):
        a = ax[0, j]
        for (case, b), (col, ls) in styles.items():
            f = RUNS / f"{mesh}_{case}_{b}"
            if not (f / "runup.csv").is_file():
                continue
            c = curve(f, route)
            k = sorted(c)
            name = {"cylindrical_roller": "rollers", "fluid_film_c1": "fluid films",
                    "fluid_film_c0_sym": "fluid films without C (K symmetric)"}[b]
            a.plot(k, [c[x] for x in k], color=col, ls=ls, label=f"{'fixed feet' if case == 'fixed' else 'K_v 1e9 N/m'}: {name}")
        a.set_title(f"{route}: double helical, 2000 N m ({mesh} mesh, sigma = 1)", fontsize=10)
        a.set_xlabel("pinion speed (rev/min)")
        a.set_ylabel("L_WA (dB(A))")
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    a = ax[1, 0]
    width = 0.2
    for i, (case, route, col) in enumerate((("fixed", "tf_omega", "0.4"), ("1e9", "tf_omega", "tab:red"),
                                            ("fixed", "mesh_force", "0.75"), ("1e9", "mesh_force", "salmon"))):
        hs = [r for r in hrows if r["run"] == f"{mesh}_{case}_fluid_film_c1" and r["route"] == route]
        n = np.array([int(r["harmonic"]) for r in hs])
        a.bar(n + (i - 1.5) * width, [float(r["delta_dB"]) for r in hs], width, color=col,
              label=f"{route}, {'fixed' if case == 'fixed' else '1e9'}")
        for x, r in zip(n, hs):
            if float(r["share_ref"]) >= 0.2:
                a.text(x + (i - 1.5) * width, 0.3 if float(r["delta_dB"]) < 0 else float(r["delta_dB"]) + 0.3,
                       f"{float(r['share_ref']):.0%}", ha="center", fontsize=6, rotation=90)
    a.axhline(0, color="k", lw=0.5)
    a.set_xlabel("harmonic n of the tooth frequency (800-1500 rpm: n x 320-600 Hz)")
    a.set_ylabel("films - rollers, line energy 800-1500 rpm (dB)")
    a.set_title("which lines the films change (labels: the rollers' share of L_WA >= 20 %)", fontsize=9)
    a.legend(fontsize=7)
    a.grid(alpha=0.3)
    a = ax[1, 1]
    cases = [c for c in ("fixed", "1e9", "3e8") if (RUNS / f"{mesh}_{c}_fluid_film_c0_sym").is_dir()]
    groups = [(c, r) for r in ("tf_omega", "mesh_force") for c in cases]
    for i, (case, route) in enumerate(groups):
        parts = decomposition(rows, mesh, case, route)
        bottom_pos = bottom_neg = 0.0
        for (lab, v), col in zip(parts, ("tab:blue", "tab:orange", "tab:green")):
            if not np.isfinite(v):
                continue
            b0 = bottom_pos if v >= 0 else bottom_neg
            a.bar(i, v, 0.6, bottom=b0, color=col, label=lab if i == 0 else None)
            if v >= 0:
                bottom_pos += v
            else:
                bottom_neg += v
        total = sum(v for _, v in parts if np.isfinite(v))
        a.plot(i, total, "kD")
        a.text(i + 0.33, total, f"{total:+.1f}", va="center", fontsize=8)
    a.set_xticks(range(len(groups)), [f"{r}\n{'fixed' if c == 'fixed' else 'K_v ' + c}" for c, r in groups], fontsize=8)
    a.axhline(0, color="k", lw=0.5)
    a.set_ylabel("fluid films - rollers, mean 800-1500 rpm (dB)")
    a.set_ylim(-6.0, 2.5)
    a.set_xlim(-0.5, len(groups) - 0.2)
    a.set_title("the films' difference, one change at a time (diamond: total)", fontsize=9)
    a.legend(fontsize=7)
    a.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    fig.savefig(HERE / "film_mount.png", dpi=110)
    print(HERE / "film_mount.png")


def main() -> None:
    if len(sys.argv) > 1 and sys.argv[1] == "_child":
        raise SystemExit(child(sys.argv[2:]))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("--case", default="fixed")
    r.add_argument("--bearings", default="fluid_film")
    r.add_argument("--mesh", default="coarse", choices=tuple(fm.MESHES))
    r.add_argument("--c-scale", type=float, default=1.0)
    r.add_argument("--k-mode", default="films", choices=("films", "sym"))
    r.add_argument("--radiation", default="erp", choices=("erp", "numerical"))
    r.add_argument("--moment", default="shuttling", choices=("shuttling", "none"))
    r.add_argument("--speed-min", type=float, default=800.0)
    sub.add_parser("table")
    pl = sub.add_parser("plot")
    pl.add_argument("--mesh", default="default", choices=tuple(fm.MESHES))
    pr = sub.add_parser("probe")
    pr.add_argument("--case", nargs="+", default=["fixed", "1e9"])
    pr.add_argument("--mesh", default="default", choices=tuple(fm.MESHES))
    st = sub.add_parser("stiff")
    st.add_argument("--case", nargs="+", default=["fixed", "1e10", "3e9", "1e9", "3e8"])
    st.add_argument("--mesh", default="default", choices=tuple(fm.MESHES))
    bo = sub.add_parser("bores")
    bo.add_argument("--case", nargs="+", default=["fixed", "1e9"])
    bo.add_argument("--mesh", default="default", choices=tuple(fm.MESHES))
    m = sub.add_parser("modes")
    m.add_argument("--case", nargs="+", default=["fixed", "1e9"])
    m.add_argument("--mesh", default="coarse", choices=tuple(fm.MESHES))
    a = ap.parse_args()
    if a.cmd == "table":
        write_table()
    elif a.cmd == "plot":
        plot(a.mesh)
    elif a.cmd == "modes":
        write_modes(a.case, a.mesh)
    elif a.cmd == "probe":
        write_probe(a.case, a.mesh)
    elif a.cmd == "stiff":
        write_stiff(a.case, a.mesh)
    elif a.cmd == "bores":
        write_bores(a.case, a.mesh)
    if a.cmd == "run":
        run(a.case, a.bearings, a.mesh, a.c_scale, a.k_mode, a.radiation, a.moment, a.speed_min)


if __name__ == "__main__":
    main()
