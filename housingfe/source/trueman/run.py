"""Scene runner (`housingfe source trueman-*`) and benchmark rows for the Trueman drive.

Scene layout (TOML, SI units; every key optional unless marked):

    [scene]  name, kind = "source", description
    [source] model = "trueman"
    [machine]                      # defaults for every configuration
    type = "A"                     # "A" (Types A & C data) or "B" (Types B & E)
    boxes = 10
    drive = "headstock"            # or "vs_drive" (4-box rig, Appendix H)
    headstock_inertia_kg_m2 = 1129.8
    elements_per_section = 3
    [[configurations]]             # at least one
    name = "standard A, solid gears"          (required)
    published_rpm = [473, 1413, 2332, 3215, 4052]
    bushed, bush_damping_factor, drawshaft_mid_diameter_m, drawroll_inertia_factor,
    coupling_flexibility_factor, mesh_flexibility_factor, damping_scale, mesh_damping_factor,
    drawroll_damping_factor, type, boxes, drive
    [critical_speeds] count = 5, max_rpm = 6000
    [forced]
    configuration = "standard A, solid gears" (required: which configuration is swept)
    speed_min_rpm = 1000, speed_max_rpm = 4000, speeds = 121
    machines = 100, seed = 1974, te_amplitude_max_rad = 0.0021
    mean_mesh_torque_Nm = 0.565   # steady (yarn) torque per mesh: the tooth-separation check
    histogram_rpm = 2355

Outputs in out_dir: critical_speeds.json / .csv, mesh_load_envelopes.csv / .png,
separation_flags.csv, mesh_force_spectra.csv, thesis_emulation.csv, summary.json, summary.txt.
"""
from __future__ import annotations

import math
import time
from pathlib import Path
from typing import TYPE_CHECKING, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from housingfe.errors import InputError
from housingfe.outputs import format_table, write_csv, write_json
from housingfe.scenefile import SceneInfo, parse_table
from housingfe.source.trueman import data

if TYPE_CHECKING:
    from housingfe.source.trueman.model import DriveConfig


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class _Source(_Strict):
    model: Literal["trueman"]


class _Machine(_Strict):
    type: Literal["A", "B"] = "A"
    boxes: int = Field(10, ge=1, le=100)
    drive: Literal["headstock", "vs_drive"] = "headstock"
    headstock_inertia_kg_m2: float = Field(1.0e4 * data.LBF_IN, gt=0)
    elements_per_section: int = Field(3, ge=1, le=50)


class _Configuration(_Strict):
    name: str
    published_rpm: list[float] = []
    type: Literal["A", "B"] | None = None
    boxes: int | None = Field(None, ge=1, le=100)
    drive: Literal["headstock", "vs_drive"] | None = None
    bushed: bool = False
    bush_damping_factor: float = Field(1.0, ge=0)
    drawshaft_mid_diameter_m: float | None = Field(None, gt=0, lt=0.2)
    drawroll_inertia_factor: float = Field(1.0, gt=0)
    coupling_flexibility_factor: float = Field(1.0, gt=0)
    mesh_flexibility_factor: float = Field(1.0, gt=0)
    damping_scale: float = Field(1.0, ge=0)
    mesh_damping_factor: float = Field(1.0, ge=0)
    drawroll_damping_factor: float = Field(1.0, ge=0)


class _Critical(_Strict):
    count: int = Field(5, ge=1, le=50)
    max_rpm: float = Field(6000.0, gt=0, le=1e5)


class _Forced(_Strict):
    configuration: str
    speed_min_rpm: float = Field(1000.0, gt=0)
    speed_max_rpm: float = Field(4000.0, gt=0)
    speeds: int = Field(121, ge=1, le=100000)
    machines: int = Field(100, ge=1, le=100000)
    seed: int = Field(1974, ge=0)
    te_amplitude_max_rad: float = Field(data.TE_AMPLITUDE_MAX_RAD, gt=0, lt=0.5)
    mean_mesh_torque_Nm: float = Field(5.0 * data.LBF_IN, gt=0)
    histogram_rpm: float = Field(2355.0, gt=0)

    @model_validator(mode="after")
    def _range(self):
        if self.speed_max_rpm < self.speed_min_rpm:
            raise ValueError("speed_max_rpm must be >= speed_min_rpm")
        return self


class TruemanScene(_Strict):
    """Validated Trueman scene (see module docstring)."""

    scene: SceneInfo
    source: _Source
    machine: _Machine = _Machine()
    configurations: list[_Configuration] = Field(min_length=1)
    critical_speeds: _Critical = _Critical()
    forced: _Forced | None = None

    @model_validator(mode="after")
    def _names(self):
        names = [c.name for c in self.configurations]
        if len(set(names)) != len(names):
            raise ValueError("configuration names must be unique")
        if self.forced is not None and self.forced.configuration not in names:
            raise ValueError(f"forced.configuration {self.forced.configuration!r} is not one of {names}")
        return self


def parse_scene(scene: dict, scene_path: str) -> TruemanScene:
    """Validate a scene dict; bad input -> InputError("<file>: <key>: <problem>")."""
    return parse_table(TruemanScene, scene, scene_path)


def drive_config(sc: TruemanScene, conf) -> DriveConfig:
    """DriveConfig of one scene configuration (machine table as defaults)."""
    from housingfe.source.trueman.model import DriveConfig

    m = sc.machine
    return DriveConfig(
        name=conf.name,
        machine_type=conf.type or m.type,
        boxes=conf.boxes or m.boxes,
        drive=conf.drive or m.drive,
        headstock_inertia=m.headstock_inertia_kg_m2,
        elements_per_section=m.elements_per_section,
        bushed=conf.bushed,
        bush_damping_factor=conf.bush_damping_factor,
        drawshaft_mid_diameter=conf.drawshaft_mid_diameter_m,
        drawroll_inertia_factor=conf.drawroll_inertia_factor,
        coupling_flexibility_factor=conf.coupling_flexibility_factor,
        mesh_flexibility_factor=conf.mesh_flexibility_factor,
        damping_scale=conf.damping_scale,
        mesh_damping_factor=conf.mesh_damping_factor,
        drawroll_damping_factor=conf.drawroll_damping_factor,
    )


# --------------------------------------------------------------------------------------------- outputs
def _critical_outputs(sc: TruemanScene, out_dir: Path) -> list:
    from housingfe.source.trueman.response import critical_speeds

    result, rows = {}, []
    for conf in sc.configurations:
        cfg = drive_config(sc, conf)
        rpm = critical_speeds(cfg, count=sc.critical_speeds.count, max_rpm=sc.critical_speeds.max_rpm,
                              scan_step_rpm=50.0)
        result[conf.name] = [round(r, 2) for r in rpm]
        for i, r in enumerate(rpm):
            pub = conf.published_rpm[i] if i < len(conf.published_rpm) else None
            err = 100.0 * (r - pub) / pub if pub else None
            rows.append([conf.name, i + 1, round(r, 1), pub if pub is not None else "",
                         round(err, 2) if err is not None else ""])
    write_json(out_dir / "critical_speeds.json", result)
    write_csv(out_dir / "critical_speeds.csv",
              ["configuration", "mode", "ours_rpm", "published_rpm", "error_pct"], rows)
    return rows


def helical_mesh_pair():
    """GearPair of the parallel 1:1 drawshaft mesh of Table 2.1 (20 T, normal diametral pitch 12, 20 deg, 45 deg
    helix, 0.8125 in face width)."""
    from housingfe.source.gears import GearPair

    module = data.INCH / 12.0
    helix, alpha = math.radians(45.0), math.radians(20.0)
    return GearPair(module=module, teeth=(20, 20), pressure_angle=alpha, helix_angle=helix,
                    profile_shift=(0.0, 0.0), face_width=(0.8125 * data.INCH,) * 2,
                    centre_distance=20 * module / math.cos(helix), name="Trueman Table 2.1 drawshaft mesh")


def helical_mesh_geometry() -> dict:
    """Parallel 1:1 drawshaft mesh of Table 2.1 (20 T, normal diametral pitch 12, 20 deg, 45 deg helix)
    from the shared gear geometry: pitch radius [m], normal pressure and helix angles [rad]."""
    pair = helical_mesh_pair()
    return {"pitch_radius": float(pair.pitch_diameter[0]) / 2.0, "pressure_angle": pair.pressure_angle,
            "helix_angle": pair.helix_angle}


def check_operating_points(sc: "TruemanScene", scene_path: str) -> None:
    """InputError naming the first [forced] speed or torque that is no operating point of the drawshaft mesh
    (GearPair.speed_problem / torque_problem, docs/source.md).  Speeds are drawroll r.p.m., checked on the
    drawshaft gears' pitch circle."""
    f = sc.forced
    if f is None:
        return
    pair = helical_mesh_pair()
    problems = [(key, pair.speed_problem(getattr(f, key))) for key in ("speed_min_rpm", "speed_max_rpm",
                                                                       "histogram_rpm")]
    problems.append(("mean_mesh_torque_Nm", pair.torque_problem(f.mean_mesh_torque_Nm)))
    for key, problem in problems:
        if problem is not None:
            raise InputError(f"{scene_path}: forced.{key}: {problem}")


def _forced_outputs(sc: TruemanScene, out_dir: Path) -> dict:
    from housingfe.source.trueman.model import MESH_POSITIONS, build_drive
    from housingfe.source.trueman.response import mesh_transfer, random_te, rpm_to_omega

    f = sc.forced
    conf = next(c for c in sc.configurations if c.name == f.configuration)
    cfg = drive_config(sc, conf)
    n_mesh = cfg.boxes * MESH_POSITIONS
    rpm = np.linspace(f.speed_min_rpm, f.speed_max_rpm, f.speeds)
    te = random_te(f.machines, n_mesh, f.te_amplitude_max_rad, f.seed)
    t0 = time.perf_counter()
    lo, mean, hi = (np.empty((len(rpm), n_mesh)) for _ in range(3))
    n_exceed = np.zeros((len(rpm), n_mesh), dtype=int)
    first_machine = np.empty((len(rpm), n_mesh), dtype=complex)
    model = None if cfg.speed_dependent else build_drive(cfg)
    for s, r in enumerate(rpm):
        m = build_drive(cfg, r) if cfg.speed_dependent else model
        t = te @ mesh_transfer(m, float(rpm_to_omega(r))).T
        mag = np.abs(t)
        lo[s], mean[s], hi[s] = mag.min(0), mag.mean(0), mag.max(0)
        n_exceed[s] = (mag > f.mean_mesh_torque_Nm).sum(0)
        first_machine[s] = t[0]
    wall = time.perf_counter() - t0
    labels = [(b, p) for b in range(1, cfg.boxes + 1) for p in range(1, MESH_POSITIONS + 1)]
    write_csv(out_dir / "mesh_load_envelopes.csv",
              ["rpm", "box", "position", "min_Nm", "mean_Nm", "max_Nm"],
              ([f"{r:.3f}", b, p, f"{lo[s, i]:.6g}", f"{mean[s, i]:.6g}", f"{hi[s, i]:.6g}"]
               for s, r in enumerate(rpm) for i, (b, p) in enumerate(labels)))
    # validity of the linear TE source: teeth separate once the dynamic torque exceeds the mean torque
    flags = [(s, i) for s in range(len(rpm)) for i in range(n_mesh) if hi[s, i] > f.mean_mesh_torque_Nm]
    write_csv(out_dir / "separation_flags.csv",
              ["rpm", "box", "position", "max_dynamic_Nm", "mean_transmitted_Nm", "machines_exceeding"],
              ([f"{rpm[s]:.3f}", *labels[i], f"{hi[s, i]:.6g}", f"{f.mean_mesh_torque_Nm:.6g}",
               n_exceed[s, i]] for s, i in flags))
    # gear-mesh force spectrum of machine 0 (fundamental only): tangential, radial, axial at the pitch circle
    g = helical_mesh_geometry()
    ft = np.abs(first_machine) / g["pitch_radius"]
    fr = ft * math.tan(g["pressure_angle"]) / math.cos(g["helix_angle"])
    fa = ft * math.tan(g["helix_angle"])
    freq = np.asarray(rpm_to_omega(rpm)) / (2 * math.pi)
    write_csv(out_dir / "mesh_force_spectra.csv",
              ["rpm", "frequency_Hz", "box", "position", "Ft_N", "Fr_N", "Fa_N"],
              ([f"{r:.3f}", f"{freq[s]:.5g}", b, p, f"{ft[s, i]:.6g}", f"{fr[s, i]:.6g}", f"{fa[s, i]:.6g}"]
               for s, r in enumerate(rpm) for i, (b, p) in enumerate(labels)))
    _plot_envelopes(out_dir / "mesh_load_envelopes.png", rpm, lo, mean, hi, labels, cfg, f)
    emulation = _thesis_emulation(cfg, f, te, labels, out_dir)
    worst = np.unravel_index(np.argmax(hi), hi.shape)
    return {
        "configuration": conf.name, "machines": f.machines, "seed": f.seed, "speeds": len(rpm),
        "dof": int(m.n_dof), "wall_s": round(wall, 3),
        "max_dynamic_torque_Nm": float(hi.max()), "max_dynamic_torque_lbf_in": float(hi.max() / data.LBF_IN),
        "at_rpm": float(rpm[worst[0]]), "at_mesh": list(labels[worst[1]]),
        "mean_mesh_torque_Nm": f.mean_mesh_torque_Nm,
        "separation_flagged_points": len(flags),
        "separation_first_rpm": float(min(rpm[s] for s, _ in flags)) if flags else None,
        "thesis_emulation": emulation,
    }


def _thesis_emulation(cfg, f, te, labels, out_dir: Path) -> dict:
    """Per-mesh loads at `histogram_rpm` from the consistent solution and from an emulation of the thesis's
    superposition (induced terms scaled by K_B / K_4), to show where its published magnitudes come from."""
    from housingfe.source.trueman.model import build_drive
    from housingfe.source.trueman.response import mesh_transfer, rpm_to_omega, thesis_style_transfer

    model = build_drive(cfg, f.histogram_rpm)
    omega = float(rpm_to_omega(f.histogram_rpm))
    ours = np.abs(te @ mesh_transfer(model, omega).T)
    thesis = np.abs(te @ thesis_style_transfer(model, omega).T)
    write_csv(out_dir / "thesis_emulation.csv",
              ["rpm", "box", "position", "consistent_min_Nm", "consistent_mean_Nm", "consistent_max_Nm",
               "thesis_style_min_Nm", "thesis_style_mean_Nm", "thesis_style_max_Nm"],
              ([f"{f.histogram_rpm:.3f}", b, p, *(f"{v:.6g}" for v in (ours[:, i].min(), ours[:, i].mean(),
                                                                       ours[:, i].max(), thesis[:, i].min(),
                                                                       thesis[:, i].mean(), thesis[:, i].max()))]
               for i, (b, p) in enumerate(labels)))
    tail = [i for i, (b, _) in enumerate(labels) if b == cfg.boxes]
    return {"rpm": f.histogram_rpm,
            "last_box_consistent_lbf_in": [float(ours[:, tail].min() / data.LBF_IN),
                                           float(ours[:, tail].max() / data.LBF_IN)],
            "last_box_thesis_style_lbf_in": [float(thesis[:, tail].min() / data.LBF_IN),
                                             float(thesis[:, tail].max() / data.LBF_IN)]}


def _plot_envelopes(path, rpm, lo, mean, hi, labels, cfg, f):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(9, 8))
    to_lbf = 1.0 / data.LBF_IN
    tail = [i for i, (b, _) in enumerate(labels) if b == cfg.boxes]
    ax1.fill_between(rpm, lo[:, tail].min(1) * to_lbf, hi[:, tail].max(1) * to_lbf, alpha=0.3,
                     label=f"box {cfg.boxes}: min-max over machines and positions")
    ax1.plot(rpm, mean[:, tail].mean(1) * to_lbf, label=f"box {cfg.boxes}: mean")
    ax1.plot(rpm, hi.max(1) * to_lbf, "k--", lw=0.8, label="whole machine: max")
    ax1.axhline(f.mean_mesh_torque_Nm * to_lbf, color="r", lw=0.8, label="mean transmitted torque")
    ax1.set_yscale("log")
    ax1.set_xlabel("drawroll speed [r.p.m.]")
    ax1.set_ylabel("dynamic mesh torque [lbf in]")
    ax1.set_title(f"{cfg.name}: {f.machines} random machines (seed {f.seed})")
    ax1.legend(fontsize=7)
    s = int(np.argmin(np.abs(rpm - f.histogram_rpm)))
    x = np.arange(len(labels))
    ax2.vlines(x, lo[s] * to_lbf, hi[s] * to_lbf, color="C0", label="min-max over machines")
    ax2.plot(x, mean[s] * to_lbf, "o", ms=3, color="C1", label="mean")
    ax2.set_xticks(x[::6], [f"box {b}" for b, p in labels[::6]], fontsize=7)
    ax2.set_ylabel("dynamic mesh torque [lbf in]")
    ax2.set_title(f"per mesh at {rpm[s]:.0f} r.p.m. (HISTOLIMITPLUS style)")
    ax2.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def run_scene(scene: dict, scene_path: str, out_dir: Path) -> None:
    """Run a Trueman scene: critical speeds of every configuration (`critical_speeds.json`:
    {configuration: [drawroll r.p.m., ...]}), and, when a [forced] table is present, the Monte-Carlo
    dynamic mesh loads over speed with min/mean/max envelopes, the tooth-separation flags and the
    fundamental gear-mesh force spectrum.  Writes into the existing folder `out_dir`."""
    sc = parse_scene(scene, scene_path)
    check_operating_points(sc, scene_path)
    out_dir = Path(out_dir)
    rows = _critical_outputs(sc, out_dir)
    summary = {"scene": sc.scene.name, "critical_speeds_rpm": "critical_speeds.json"}
    text = [f"{sc.scene.name}: {sc.scene.description}", "",
            "Critical speeds (drawroll r.p.m.), ours vs published:",
            format_table(["configuration", "mode", "ours", "published", "error %"], rows)]
    if sc.forced is not None:
        forced = _forced_outputs(sc, out_dir)
        summary["forced"] = forced
        text += ["", (f"Forced response ({forced['configuration']}, {forced['machines']} machines, "
                      f"seed {forced['seed']}): max dynamic mesh torque {forced['max_dynamic_torque_Nm']:.4g} "
                      f"N m ({forced['max_dynamic_torque_lbf_in']:.4g} lbf in) at {forced['at_rpm']:.0f} "
                      f"r.p.m., mesh {forced['at_mesh']}"),
                 (f"Tooth separation (|T_dyn| > mean torque {forced['mean_mesh_torque_Nm']:.3g} N m) at "
                  f"{forced['separation_flagged_points']} speed/mesh points; first at "
                  f"{forced['separation_first_rpm']} r.p.m.  A linear TE source is not valid there.")]
    write_json(out_dir / "summary.json", summary)
    (out_dir / "summary.txt").write_text("\n".join(text) + "\n")


# ------------------------------------------------------------------------------------------- benchmark
def bench_rows(quick: bool) -> list[dict]:
    """Benchmark rows for `housingfe bench source`: speed next to error.

    - critical speeds of the 10-box standard Type A machine vs Table 6.1 (max relative error);
    - a 1000-speed (quick: 100) forced sweep of the 10-box drive (1281 DOF, 60 TE sources, all meshes
      solved per speed with one sparse LU);
    - 100 Monte-Carlo machines over the same sweep (the per-speed transfer matrix is reused, so machines
      are a 60 x 60 matrix product each)."""
    from housingfe.source.trueman.response import (
        DriveConfig,
        build_drive,
        critical_speeds,
        mesh_load_envelopes,
        mesh_torques,
        random_te,
        rpm_to_omega,
    )

    rows = []
    cfg = DriveConfig()
    t0 = time.perf_counter()
    ours = critical_speeds(cfg, count=5)
    wall = time.perf_counter() - t0
    pub = np.array(data.TABLE_6_1_RPM["standard A, solid gears"])
    rows.append({"case": "trueman critical speeds, 10-box type A", "wall_s": wall,
                 "error": float(np.max(np.abs(np.array(ours) - pub) / pub)),
                 "note": "max relative error vs Table 6.1 (5 criticals)"})
    model = build_drive(cfg)
    n_speeds = 100 if quick else 1000
    rpm = np.linspace(1000.0, 4000.0, n_speeds)
    te1 = random_te(1, 60, seed=1974)
    t0 = time.perf_counter()
    sweep = mesh_torques(cfg, rpm, te1)
    wall = time.perf_counter() - t0
    # error: the sparse-LU transfer-matrix result at one speed against a dense solve of the same Z(omega)
    s = n_speeds // 2
    omega = float(rpm_to_omega(rpm[s]))
    a, b = model.mesh_dofs[:, 0], model.mesh_dofs[:, 1]
    kb = model.mesh_stiffness + 1j * omega * model.mesh_damping
    rhs = np.zeros(model.n_dof, dtype=complex)
    np.add.at(rhs, a, kb * te1[0])
    np.add.at(rhs, b, -kb * te1[0])
    x = np.linalg.solve(model.dynamic_stiffness(omega).toarray(), rhs)
    dense = kb * (x[a] - x[b] - te1[0])
    err = float(np.max(np.abs(sweep[s, 0] - dense)) / np.max(np.abs(dense)))
    rows.append({"case": f"trueman {n_speeds}-speed sweep, 10-box type A ({model.n_dof} DOF, 60 meshes)",
                 "wall_s": wall, "error": err,
                 "note": "sparse LU per speed, 60 RHS; error: vs dense solve of the same Z at one speed"})
    te = random_te(100, 60, seed=1974)
    t0 = time.perf_counter()
    env = mesh_load_envelopes(cfg, rpm, te)
    wall = time.perf_counter() - t0
    # error: envelope max at that speed vs the 100 machines solved one by one (dense)
    direct = []
    for e in te:
        rhs = np.zeros(model.n_dof, dtype=complex)
        np.add.at(rhs, a, kb * e)
        np.add.at(rhs, b, -kb * e)
        direct.append(rhs)
    xs = np.linalg.solve(model.dynamic_stiffness(omega).toarray(), np.array(direct).T)
    mags = np.abs(kb[:, None] * (xs[a] - xs[b] - te.T))
    err = float(np.max(np.abs(env["max"][s] - mags.max(1))) / mags.max())
    rows.append({"case": f"trueman 100 Monte-Carlo machines x {n_speeds} speeds", "wall_s": wall,
                 "error": err, "note": "min/mean/max envelopes; error: max envelope vs 100 direct solves"})
    return rows
