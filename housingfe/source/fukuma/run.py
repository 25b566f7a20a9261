"""Scene runner (`housingfe source fukuma-*`) and benchmark rows for the Fukuma gear-shaft model.

Scene layout (TOML, SI units):

    [scene]  name, kind = "source", description
    [source] model = "fukuma"
    [shaft]                                  # Table 1 of the paper
    length_m = 0.220
    shaft_stiffness_N_per_m = 9.5026e7       # K_s (9690 kg/mm)
    equivalent_radius_m = 0.0226             # r_eq: also the cross-section that carries the mass (assumed)
    inner_radius_m = 0.0
    fixity = 0.152                           # lambda
    bearing_stiffness_v_N_per_m = 2.3928e7   # K_pV (2440 kg/mm)
    bearing_stiffness_h_N_per_m = 1.4024e7   # K_pH (1430 kg/mm)
    density_kg_m3 = 7850.0                   # assumed
    youngs_modulus_Pa = 2.06e11              # assumed; only for the K_s(r_eq) consistency check
    [gear]
    module_m = 0.003, teeth = 36, face_width_m = 0.010, pressure_angle_deg = 20.0, centre_distance_m = 0.1083
    mesh_stiffness_N_per_m = 2.0e8           # assumed
    zeta = 0.07
    blank_outer_radius_m                     # default: pitch radius (assumed solid disc)
    sensor_radius_m                          # default: base radius
    [sweep]  z_min = 0.05, z_max = 0.95, points = 37, speeds_rpm = [700.0]
    [loads]  gear_positions_m = [0.110], speed_rpm = 1000.0, te_harmonics_m = [1e-6], torque_Nm = 39.2

Outputs: conversion_ratios.csv / .png, bearing_loads.csv, summary.json, summary.txt.
"""
from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from housingfe.errors import InputError
from housingfe.outputs import format_table, write_csv, write_json
from housingfe.scenefile import SceneInfo, parse_table


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class _Source(_Strict):
    model: Literal["fukuma"]


class _Shaft(_Strict):
    length_m: float = Field(gt=0, lt=10)
    shaft_stiffness_N_per_m: float = Field(gt=0)
    equivalent_radius_m: float = Field(gt=0, lt=1)
    inner_radius_m: float = Field(0.0, ge=0)
    fixity: float = Field(ge=0, le=1)
    bearing_stiffness_v_N_per_m: float = Field(gt=0)
    bearing_stiffness_h_N_per_m: float = Field(gt=0)
    density_kg_m3: float = Field(7850.0, gt=0)
    youngs_modulus_Pa: float = Field(2.06e11, gt=0)

    @model_validator(mode="after")
    def _radii(self):
        if self.inner_radius_m >= self.equivalent_radius_m:
            raise ValueError("inner_radius_m must be smaller than equivalent_radius_m")
        return self


class _Gear(_Strict):
    module_m: float = Field(gt=0, lt=0.1)
    teeth: int = Field(ge=5, le=1000)
    face_width_m: float = Field(gt=0, lt=1)
    pressure_angle_deg: float = Field(20.0, gt=0, lt=45)
    centre_distance_m: float = Field(gt=0)
    mesh_stiffness_N_per_m: float = Field(gt=0)
    zeta: float = Field(0.07, ge=0, lt=1)
    blank_outer_radius_m: float | None = Field(None, gt=0)
    sensor_radius_m: float | None = Field(None, gt=0)


class _Sweep(_Strict):
    z_min: float = Field(0.05, gt=0, lt=1)
    z_max: float = Field(0.95, gt=0, lt=1)
    points: int = Field(37, ge=2, le=10000)
    speeds_rpm: list[float] = Field([700.0], min_length=1)

    @model_validator(mode="after")
    def _range(self):
        if self.z_max <= self.z_min:
            raise ValueError("z_max must exceed z_min")
        if min(self.speeds_rpm) <= 0:
            raise ValueError("speeds_rpm must be > 0")
        return self


class _Loads(_Strict):
    gear_positions_m: list[float] = Field(min_length=1)
    speed_rpm: float = Field(1000.0, gt=0)
    te_harmonics_m: list[float] = Field([1e-6], min_length=1)
    torque_Nm: float = Field(0.0, ge=0)


class FukumaScene(_Strict):
    """Validated Fukuma scene (see module docstring)."""

    scene: SceneInfo
    source: _Source
    shaft: _Shaft
    gear: _Gear
    sweep: _Sweep = _Sweep()
    loads: _Loads | None = None

    @model_validator(mode="after")
    def _positions(self):
        if self.loads is not None:
            for p in self.loads.gear_positions_m:
                if not 0 < p < self.shaft.length_m:
                    raise ValueError(f"loads.gear_positions_m: {p} m is not between the bearings")
        return self


def parse_scene(scene: dict, scene_path: str) -> FukumaScene:
    """Validate a scene dict; bad input -> InputError("<file>: <key>: <problem>")."""
    return parse_table(FukumaScene, scene, scene_path)


def build_pair(sc: FukumaScene):
    """FukumaPair of a scene: pressure angle and radii from the shared spur-gear geometry."""
    from housingfe.source.fukuma import model as fk
    from housingfe.source.gears import GearPair

    g = sc.gear
    geo = GearPair(module=g.module_m, teeth=(g.teeth, g.teeth), pressure_angle=math.radians(g.pressure_angle_deg),
                   helix_angle=0.0, profile_shift=(0.0, 0.0), face_width=(g.face_width_m,) * 2,
                   centre_distance=g.centre_distance_m, kind="spur", name=f"{sc.scene.name} gears")
    pitch_radius = float(geo.pitch_diameter[0]) / 2.0
    base_radius = float(geo.base_diameter[0]) / 2.0
    s = sc.shaft
    shaft = fk.ShaftBearing(length=s.length_m, shaft_stiffness=s.shaft_stiffness_N_per_m,
                            bearing_stiffness_v=s.bearing_stiffness_v_N_per_m,
                            bearing_stiffness_h=s.bearing_stiffness_h_N_per_m, fixity=s.fixity,
                            mass_radius_outer=s.equivalent_radius_m, mass_radius_inner=s.inner_radius_m,
                            density=s.density_kg_m3)
    blank = fk.GearBody.solid_disc(g.blank_outer_radius_m or pitch_radius, s.equivalent_radius_m,
                                   g.face_width_m, base_radius, s.density_kg_m3)
    pair = fk.FukumaPair(shaft=shaft, gear=blank, mesh_stiffness=g.mesh_stiffness_N_per_m,
                         pressure_angle=float(geo.operating_pressure_angle), zeta=g.zeta, teeth=g.teeth)
    return pair, geo


def check_operating_points(sc: FukumaScene, geo, scene_path: str) -> None:
    """InputError naming the first speed or torque of the scene that is no operating point of its gears `geo` (a
    GearPair: GearPair.speed_problem / torque_problem, docs/source.md).  torque_Nm = 0 is accepted: the model is
    linear and only records it."""
    speeds = [("loads.speed_rpm", sc.loads.speed_rpm)]
    speeds += [(f"sweep.speeds_rpm.{i}", s) for i, s in enumerate(sc.sweep.speeds_rpm)]
    problems = [(key, geo.speed_problem(s)) for key, s in speeds]
    if sc.loads.torque_Nm != 0:
        problems.append(("loads.torque_Nm", geo.torque_problem(sc.loads.torque_Nm)))
    for key, problem in problems:
        if problem is not None:
            raise InputError(f"{scene_path}: {key}: {problem}")


def run_scene(scene: dict, scene_path: str, out_dir: Path) -> None:
    """Run a Fukuma scene: influence coefficients, equivalent inertia and radial / axial conversion ratios
    over the gear position (CSV + PNG), bearing force and moment spectra at the listed gear positions, the
    Table 1 shaft-stiffness check.  Writes into the existing folder `out_dir`."""
    from housingfe.source.fukuma import model as fk

    sc = parse_scene(scene, scene_path)
    out_dir = Path(out_dir)
    pair, geo = build_pair(sc)
    check_operating_points(sc, geo, scene_path)
    sw = sc.sweep
    zs = np.linspace(sw.z_min, sw.z_max, sw.points)
    rows, ratios = [], {rpm: [] for rpm in sw.speeds_rpm}
    for z in zs:
        coef = fk.influence_coefficients(pair.shaft, pair.shaft.bearing_stiffness_v, z)
        inert = fk.equivalent_inertia(pair.shaft, pair.shaft.bearing_stiffness_v, z, pair.gear)
        row = [f"{z:.5f}", f"{z * pair.shaft.length * 1e3:.3f}"]
        row += [f"{coef[k]:.6g}" for k in ("alpha", "beta", "gamma", "Lambda")]
        row += [f"{inert[k]:.6g}" for k in ("m", "I", "C")]
        for rpm in sw.speeds_rpm:
            cr = fk.conversion_ratios(pair, z, fk.mesh_frequency(pair, rpm), sc.gear.sensor_radius_m)
            ratios[rpm].append(cr)
            row += [f"{cr['K_r']:.6g}", f"{cr['K_z']:.6g}",
                    f"{cr['K_z'] / cr['K_r']:.6g}", f"{cr['a_t']:.6g}"]
        rows.append(row)
    header = ["z", "zl_mm", "alpha_V_m_per_N", "beta_V_per_N", "gamma_V_per_Nm", "Lambda_V", "m_V_kg",
              "I_V_kgm2", "C_V_kgm"]
    for rpm in sw.speeds_rpm:
        header += [f"K_r@{rpm:g}rpm", f"K_z@{rpm:g}rpm", f"K_z/K_r@{rpm:g}rpm", f"a_t_rms_per_N@{rpm:g}rpm"]
    write_csv(out_dir / "conversion_ratios.csv", header, rows)
    _plot(out_dir / "conversion_ratios.png", zs * pair.shaft.length * 1e3, ratios, sc.scene.name)

    s = sc.shaft
    ks_from_radius = fk.shaft_stiffness_from_radius(s.youngs_modulus_Pa, s.length_m, s.equivalent_radius_m,
                                                    s.inner_radius_m)
    mid = len(zs) // 2
    summary = {
        "scene": sc.scene.name,
        "shaft_stiffness_table1_N_per_m": s.shaft_stiffness_N_per_m,
        "shaft_stiffness_from_equivalent_radius_N_per_m": ks_from_radius,
        "shaft_stiffness_rel_difference": ks_from_radius / s.shaft_stiffness_N_per_m - 1.0,
        "operating_pressure_angle_deg": math.degrees(pair.pressure_angle),
        "gear_mass_kg": pair.gear.mass, "shaft_mass_kg": s.density_kg_m3 * pair.shaft.area * s.length_m,
        "conversion_ratio_ends_and_middle": {
            f"{rpm:g} rpm": {"z": [float(zs[0]), float(zs[mid]), float(zs[-1])],
                             "K_r": [ratios[rpm][i]["K_r"] for i in (0, mid, -1)],
                             "K_z": [ratios[rpm][i]["K_z"] for i in (0, mid, -1)]}
            for rpm in sw.speeds_rpm},
    }
    if sc.loads is not None:
        summary["bearing_loads"] = _bearing_outputs(sc, pair, out_dir)
    write_json(out_dir / "summary.json", summary)
    text = [f"{sc.scene.name}: {sc.scene.description}",
            (f"K_s Table 1 {s.shaft_stiffness_N_per_m:.5g} N/m, from r_eq {ks_from_radius:.5g} N/m "
             f"({100 * summary['shaft_stiffness_rel_difference']:+.2f} %)"), "",
            format_table(["z", "zl mm", *[f"K_r {r:g}" for r in sw.speeds_rpm],
                          *[f"K_z {r:g}" for r in sw.speeds_rpm]],
                         [[float(z), float(z * s.length_m * 1e3), *[ratios[r][i]["K_r"] for r in sw.speeds_rpm],
                           *[ratios[r][i]["K_z"] for r in sw.speeds_rpm]] for i, z in enumerate(zs)])]
    (out_dir / "summary.txt").write_text("\n".join(text) + "\n")


def _bearing_outputs(sc: FukumaScene, pair, out_dir: Path) -> list:
    from housingfe.source.fukuma import model as fk

    rows, out = [], []
    for pos in sc.loads.gear_positions_m:
        spec = fk.bearing_load_spectra(pair, pos / sc.shaft.length_m, sc.loads.speed_rpm, sc.loads.te_harmonics_m,
                                       torque_Nm=sc.loads.torque_Nm)
        dofs = ("Fx", "Fy", "Fz", "Mx", "My", "Mz")
        for b, name in enumerate(spec.names):
            for d, dof in enumerate(dofs):
                for h, f in enumerate(spec.frequency):
                    v = spec.loads[b, d, h]
                    rows.append([f"{pos:.4f}", name, f"{spec.z[b]:.4f}", dof, f"{f:.4f}", f"{abs(v):.6g}",
                                 f"{math.degrees(np.angle(v)):.3f}"])
        out.append({"gear_position_m": pos,
                    "max_bearing_force_N": float(np.abs(spec.loads[:, :3]).max()),
                    "max_bearing_moment_Nm": float(np.abs(spec.loads[:, 3:]).max())})
    write_csv(out_dir / "bearing_loads.csv",
              ["gear_position_m", "bearing", "bearing_z_m", "dof", "frequency_Hz", "amplitude", "phase_deg"], rows)
    return out


def _plot(path, zl_mm, ratios, title):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(12, 4))
    for rpm, rs in ratios.items():
        axes[0].plot(zl_mm, [r["K_r"] for r in rs], label=f"{rpm:g} r.p.m.")
        axes[1].plot(zl_mm, [r["K_z"] for r in rs], label=f"{rpm:g} r.p.m.")
        axes[2].plot(zl_mm, [r["K_z"] / r["K_r"] for r in rs], label=f"{rpm:g} r.p.m.")
    for ax, lab in zip(axes, ("radial K_r = a_r / a_t", "axial K_z = a_z / a_t", "axial / radial K_z / K_r")):
        ax.set_xlabel("gear position zl [mm]")
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"{title}: conversion ratios (linear harmonic response at the mesh frequency)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def bench_rows(quick: bool) -> list[dict]:
    """One row: time of a 37-point gear-position sweep (Series A); error = relative difference between
    Table 1's K_s and K_s computed from its equivalent radius (E = 206 GPa assumed)."""
    import tomllib

    from housingfe.source.fukuma import model as fk

    path = Path(__file__).parents[2] / "scenes" / "fukuma-series-a.toml"
    scene = tomllib.loads(path.read_text())
    sc = parse_scene(scene, str(path))
    pair, _ = build_pair(sc)
    t0 = time.perf_counter()
    for z in np.linspace(0.05, 0.95, 37 if not quick else 10):
        fk.conversion_ratios(pair, z, fk.mesh_frequency(pair, 700.0))
    wall = time.perf_counter() - t0
    s = sc.shaft
    ks = fk.shaft_stiffness_from_radius(s.youngs_modulus_Pa, s.length_m, s.equivalent_radius_m)
    return [{"case": "fukuma series A gear-position sweep", "wall_s": wall,
             "error": abs(ks / s.shaft_stiffness_N_per_m - 1.0),
             "note": "error: K_s(r_eq) vs Table 1 (E assumed 206 GPa)"}]
