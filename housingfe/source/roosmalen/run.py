"""`housingfe source <scene>` for model = "roosmalen": gear data, stiffness curve, L_omega spectra, run-ups
and bearing spectra of van Roosmalen's Ch. 2 source model, written to a result folder.

Scene layout (all tables forbid unknown keys; lengths in mm and angles in degrees where the key says
so, as in Appendix F):

    [source]              model, torque_Nm, speed_min_rpm, speed_max_rpm, speed_steps, spectrum_speeds_rpm,
                          torque_run_Nm, harmonics, stiffness_positions, slices, torque_configuration,
                          engagement ("face-width" default | "thesis-2d": the thesis' Eq. 2.62 replica |
                          "envelope-bound": the face-width excitation's envelope bound, a bound, not a model)
    [source.gears]        Appendix F data (module_mm, teeth, ..., power_kW, max_speed_rpm)
    [source.corrections]  pinion_um, pinion_mm, wheel_um, wheel_mm, ... (Appendix F, as measured)
    [source.shafts]       bearing spans, shaft diameters, torsion shafts 1-4, coupling inertias
    [source.interior]     optional overrides of the derived masses/inertias, loss factor
    [source.bearings]     pinion, wheel: 5 stiffnesses x, y, z [N/m], theta_x, theta_y [N m/rad]
"""
from __future__ import annotations

import copy
import math
from dataclasses import asdict, replace
from pathlib import Path
from typing import Annotated, Literal, Optional, Union

import numpy as np
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    PositiveFloat,
    PositiveInt,
    field_validator,
    model_validator,
)

from housingfe.errors import InputError
from housingfe.outputs import format_table, write_csv, write_json
from housingfe.source.gears import GearPair, tooth_profile
from housingfe.source.roosmalen import dynamics as dyn
from housingfe.source.roosmalen import overlap
from housingfe.source.stiffness import (
    Corrections,
    MeshModel,
    ShaftBending,
    face_load_share,
    iso6336_stiffness,
    normal_force_from_torque,
    stiffness_curve,
)
from housingfe.source.transmission_error import SAMPLES_PER_MESH_PERIOD, checked_scene, validated_scene_file


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class GearsTable(_Strict):
    module_mm: PositiveFloat
    teeth: tuple[PositiveInt, PositiveInt]
    pressure_angle_deg: PositiveFloat = 20.0
    helix_angle_deg: float = 0.0
    addendum_modification: tuple[float, float] = (0.0, 0.0)
    face_width_mm: list = Field(min_length=2, max_length=2)
    centre_distance_mm: Optional[PositiveFloat] = None     # None: the zero-backlash centre distance
    # basic rack h_aP*, h_fP*, rho_fP*: one value for both gears or [pinion, wheel]
    addendum_coefficient: Union[PositiveFloat, tuple[PositiveFloat, PositiveFloat]] = 1.0
    dedendum_coefficient: Union[PositiveFloat, tuple[PositiveFloat, PositiveFloat]] = 1.25
    rack_tip_radius_factor: Union[Annotated[float, Field(ge=0.0, lt=0.6)],
                                  tuple[Annotated[float, Field(ge=0.0, lt=0.6)],
                                        Annotated[float, Field(ge=0.0, lt=0.6)]]] = 0.38
    tip_diameter_mm: Optional[tuple[PositiveFloat, PositiveFloat]] = None   # the blanks; None: from the rack
    tip_shortening: bool = False           # apply DIN 3960 k m to the rack tips (Appendix F does)
    kind: Optional[Literal["spur", "single_helical", "double_helical"]] = None
    helix_gap_mm: float = Field(0.0, ge=0.0)
    power_kW: PositiveFloat = 300.0
    max_speed_rpm: PositiveFloat = 1500.0


class CorrectionsTable(_Strict):
    pinion_um: float = Field(0.0, ge=0)
    pinion_mm: float = Field(0.0, ge=0)
    wheel_um: float = Field(0.0, ge=0)
    wheel_mm: float = Field(0.0, ge=0)
    pinion_width_relief_um: float = Field(0.0, ge=0)
    pinion_width_relief_mm: float = Field(0.0, ge=0)
    kind: Literal["tip relief", "3-D triangular"] = "tip relief"
    pinion_width_mm: float = Field(0.0, ge=0)
    wheel_width_mm: float = Field(0.0, ge=0)


class ShaftsTable(_Strict):
    pinion_spans_mm: tuple[PositiveFloat, PositiveFloat] = (60.0, 60.0)
    pinion_shaft_diameter_mm: PositiveFloat = 80.0
    wheel_spans_mm: tuple[PositiveFloat, PositiveFloat] = (60.0, 60.0)
    wheel_shaft_diameter_mm: PositiveFloat = 95.0
    torsion_diameters_mm: tuple[PositiveFloat, PositiveFloat, PositiveFloat, PositiveFloat] = (40, 60, 75, 55)
    torsion_lengths_mm: tuple[PositiveFloat, PositiveFloat, PositiveFloat, PositiveFloat] = (1500, 250, 250, 1500)
    coupling_inertia_kgm2: tuple[PositiveFloat, PositiveFloat] = (0.02, 0.05)


class InteriorTable(_Strict):
    loss_factor: float = Field(0.1, gt=0, lt=2)
    pinion_mass_kg: Optional[PositiveFloat] = None
    pinion_inertia_axial_kgm2: Optional[PositiveFloat] = None
    pinion_inertia_diametral_kgm2: Optional[PositiveFloat] = None
    wheel_mass_kg: Optional[PositiveFloat] = None
    wheel_inertia_axial_kgm2: Optional[PositiveFloat] = None
    wheel_inertia_diametral_kgm2: Optional[PositiveFloat] = None


class BearingsTable(_Strict):
    pinion: tuple[PositiveFloat, PositiveFloat, PositiveFloat, PositiveFloat, PositiveFloat] = Field(
        dyn.APPENDIX_C_BEARINGS["pinion"], json_schema_extra={"unit": "N/m (3), N m/rad (2)"})
    wheel: tuple[PositiveFloat, PositiveFloat, PositiveFloat, PositiveFloat, PositiveFloat] = Field(
        dyn.APPENDIX_C_BEARINGS["wheel"], json_schema_extra={"unit": "N/m (3), N m/rad (2)"})


class SourceTable(_Strict):
    model: Literal["roosmalen"]
    torque_Nm: PositiveFloat = 2000.0
    speed_min_rpm: PositiveFloat = 50.0
    speed_max_rpm: PositiveFloat = 1500.0
    speed_steps: int = Field(30, ge=2, le=2000)
    spectrum_speeds_rpm: list[PositiveFloat] = [500.0, 1000.0, 1500.0]
    # pinion torques of the torque run at torque_run_speed_rpm, each once (at least one)
    torque_run_Nm: list[PositiveFloat] = Field([400.0, 800.0, 1200.0, 1600.0, 2000.0], min_length=1)
    torque_run_speed_rpm: PositiveFloat = 1500.0
    harmonics: int = Field(30, ge=2, le=400)
    stiffness_positions: int = Field(dyn.DEFAULT_STIFFNESS_POSITIONS, ge=4, le=512)
    slices: int = Field(16, ge=2, le=200)
    torque_configuration: Literal[1, 2] = 2
    engagement: Literal[dyn.ENGAGEMENT_MODELS] = dyn.DEFAULT_ENGAGEMENT
    # a transmission error the user brings instead of the engagement model (housingfe.source.transmission_error;
    # docs/source.md "A transmission error from a file"): a CSV file relative to the scene file (else to the current
    # folder) whose torques span torque_Nm and torque_run_Nm; "" (default) = the engagement model
    transmission_error: str = Field("", json_schema_extra={"unit": "file"})
    measured_L_omega_dB: Optional[dict[str, float]] = None
    gears: GearsTable
    corrections: CorrectionsTable = CorrectionsTable()
    shafts: ShaftsTable = ShaftsTable()
    interior: InteriorTable = InteriorTable()
    bearings: BearingsTable = BearingsTable()


    _transmission_error = field_validator("transmission_error")(validated_scene_file)

    @field_validator("torque_run_Nm")
    @classmethod
    def _torque_run_once_each(cls, torques):
        twice = [t for i, t in enumerate(torques) if t in torques[:i]]
        if twice:
            raise ValueError(f"{twice[0]:g} N m is given twice")
        return torques

    @model_validator(mode="after")
    def _transmission_error_torques(self):
        return checked_scene(self, {"torque_Nm": [self.torque_Nm], "torque_run_Nm": self.torque_run_Nm})


def parse(scene: dict, scene_path: str) -> SourceTable:
    """Validate the [source] table; InputError naming the file and the first bad key."""
    from housingfe.scenefile import parse_table

    return parse_table(SourceTable, scene.get("source", {}), scene_path, prefix="source.")


def scene_pair(name_or_path: str) -> GearPair:
    """The GearPair of a roosmalen source scene (built-in name or TOML path), e.g. to check an operating torque
    (GearPair.torque_problem) before any computation."""
    from housingfe.scenefile import read_scene_dict

    scene, path = read_scene_dict(name_or_path)
    table = parse(scene, str(path))
    return GearPair.from_table(table.gears.model_dump(exclude_none=True), where=f"{path}: source.gears")


def build(table: SourceTable, scene_path: str = "scene"):
    """GearPair, Corrections, ShaftGeometry, LumpedInterior and MeshModel from a validated table."""
    gears = table.gears.model_dump(exclude_none=True)
    pair = GearPair.from_table(gears, where=f"{scene_path}: source.gears")
    corr = Corrections.from_table(table.corrections.model_dump(), where=f"{scene_path}: source.corrections")
    sh = table.shafts
    geometry = dyn.ShaftGeometry(
        pinion_spans=tuple(x * 1e-3 for x in sh.pinion_spans_mm), pinion_shaft_diameter=sh.pinion_shaft_diameter_mm * 1e-3,
        wheel_spans=tuple(x * 1e-3 for x in sh.wheel_spans_mm), wheel_shaft_diameter=sh.wheel_shaft_diameter_mm * 1e-3,
        torsion_diameters=tuple(x * 1e-3 for x in sh.torsion_diameters_mm),
        torsion_lengths=tuple(x * 1e-3 for x in sh.torsion_lengths_mm), coupling_inertia=sh.coupling_inertia_kgm2)
    interior = dyn.derive_interior(pair, geometry, table.interior.loss_factor,
                                   {"pinion": table.bearings.pinion, "wheel": table.bearings.wheel})
    overrides = {k.removesuffix("_kg").removesuffix("_kgm2"): v
                 for k, v in table.interior.model_dump(exclude_none=True).items() if k != "loss_factor"}
    interior = replace(interior, **overrides)
    model = MeshModel(pair, shafts=(ShaftBending(*geometry.pinion_spans, geometry.pinion_shaft_diameter),
                                    ShaftBending(*geometry.wheel_spans, geometry.wheel_shaft_diameter)),
                      corrections=corr, n_slices=table.slices, torque_configuration=table.torque_configuration)
    return pair, corr, geometry, interior, model


class OperatingPoint:
    """Stiffness curve, matrices, shock force and preload for one pinion torque [N m].  engagement: the shock
    model (housingfe.source.roosmalen.dynamics.ENGAGEMENT_MODELS): "face-width" (default) distributes Eq. 2.62 over the
    face-width slices with the load share of `face_load_share`, "thesis-2d" is the thesis' Eq. 2.62, "envelope-bound"
    the envelope bound of the face-width excitation (same load share; dynamics.engagement_force_envelope_bound).
    lead_gap [m/m]: the misalignment under load (MeshModel.lead_gap, housingfe.source.misalignment), in the
    stiffness curve and the load share (0: aligned gears, exactly as before).  transmission_error: a
    housingfe.source.transmission_error.TransmissionError the user brings, which replaces the engagement model: F_e
    is then the shock whose quasi-static compression is the file's TE at this torque on the model's S(t)
    (dyn.engagement_force_from_transmission_error); None (default) = the engagement model."""

    def __init__(self, pair, corr, interior, model, torque: float, n_positions: int, n_samples: int = SAMPLES_PER_MESH_PERIOD,
                 engagement: str = dyn.DEFAULT_ENGAGEMENT, lead_gap: float = 0.0, transmission_error=None):
        self.torque = torque
        self.engagement = engagement
        self.transmission_error = transmission_error
        self.n_positions = n_positions
        self.lead_gap = float(lead_gap)
        if self.lead_gap != 0.0:
            model = replace(model, lead_gap=self.lead_gap)
        self.mesh_model = model
        self.normal_force = normal_force_from_torque(pair, torque)
        self.curve = stiffness_curve(model, self.normal_force, n_positions)
        t = np.arange(n_samples) / n_samples
        self.S = np.interp(t, self.curve.position, self.curve.stiffness, period=1.0)
        if transmission_error is not None:
            self.load_share = None
            self.shock = dyn.engagement_force_from_transmission_error(
                self.S, self.normal_force, transmission_error.samples(torque, n_samples))
        else:
            self.load_share = (face_load_share(model, self.normal_force, n_positions=n_positions)
                               if engagement in ("face-width", "envelope-bound") else None)
            self.shock = dyn.engagement_shock(engagement, pair, corr, self.S, self.normal_force, self.load_share)
        self.mats = dyn.assemble(pair, interior, self.curve.mean)
        self.f0 = dyn.preload_force(self.mats, torque)

    def with_engagement(self, pair: GearPair, corr: Corrections, engagement: str) -> "OperatingPoint":
        """This operating point with another engagement shock model (ENGAGEMENT_MODELS): the stiffness curve, load
        share, matrices and preload reused (the load share computed if this point has none), only F_e recomputed
        (milliseconds; exactly what a new OperatingPoint with that engagement holds)."""
        if engagement not in dyn.ENGAGEMENT_MODELS:
            raise InputError(f"engagement: {engagement!r} is not one of {', '.join(dyn.ENGAGEMENT_MODELS)}")
        other = copy.copy(self)
        other.engagement = engagement
        other.transmission_error = None
        if other.load_share is None and engagement != "thesis-2d":
            other.load_share = face_load_share(self.mesh_model, self.normal_force, n_positions=self.n_positions)
        other.shock = dyn.engagement_shock(engagement, pair, corr, self.S, self.normal_force, other.load_share)
        return other

    def with_transmission_error(self, transmission_error) -> "OperatingPoint":
        """This operating point driven by a TE the user brings (housingfe.source.transmission_error
        .TransmissionError, covering this torque) instead of its engagement model: the stiffness curve, matrices and
        preload reused, only F_e recomputed (dyn.engagement_force_from_transmission_error)."""
        other = copy.copy(self)
        other.transmission_error = transmission_error
        other.shock = dyn.engagement_force_from_transmission_error(
            self.S, self.normal_force, transmission_error.samples(self.torque, self.S.size))
        return other

    def steady_state(self, pair: GearPair, speed_rpm: float, harmonics: int) -> dyn.SteadyState:
        return dyn.harmonic_balance(self.mats, self.S, self.shock, self.f0, pair.tooth_frequency(speed_rpm),
                                    H=harmonics)


def check_operating_points(table: SourceTable, pair: GearPair, scene_path: str) -> None:
    """InputError naming the key of the first torque or speed of the scene that is no operating point of the pair
    (GearPair.torque_problem / speed_problem: beyond the teeth's strength, or a wheel that bursts)."""
    g = table.gears
    torques = [("source.torque_Nm", table.torque_Nm)]
    torques += [(f"source.torque_run_Nm.{i}", t) for i, t in enumerate(table.torque_run_Nm)]
    speeds = [("source.speed_min_rpm", table.speed_min_rpm), ("source.speed_max_rpm", table.speed_max_rpm),
              ("source.torque_run_speed_rpm", table.torque_run_speed_rpm),
              ("source.gears.max_speed_rpm", g.max_speed_rpm)]
    speeds += [(f"source.spectrum_speeds_rpm.{i}", s) for i, s in enumerate(table.spectrum_speeds_rpm)]
    for key, speed in speeds:
        problem = pair.speed_problem(speed)
        if problem is not None:
            raise InputError(f"{scene_path}: {key}: {problem}")
    for key, torque in torques:
        problem = pair.torque_problem(torque)
        if problem is not None:
            raise InputError(f"{scene_path}: {key}: {problem}")
    rated = g.power_kW * 1e3 / (g.max_speed_rpm * math.pi / 30.0)     # the Appendix F table's pinion torque
    problem = pair.torque_problem(rated)
    if problem is not None:
        raise InputError(f"{scene_path}: source.gears.power_kW: {g.power_kW:g} kW at {g.max_speed_rpm:g} rev/min, "
                         f"pinion torque {problem}")


def run_scene(scene: dict, scene_path: str, out_dir: Path) -> dict:
    """Compute everything a roosmalen source scene asks for and write it into `out_dir` (exists)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    table = parse(scene, scene_path)
    if table.speed_min_rpm >= table.speed_max_rpm:
        raise InputError(f"{scene_path}: source.speed_max_rpm: must exceed speed_min_rpm")
    pair, corr, geometry, interior, model = build(table, scene_path)
    check_operating_points(table, pair, scene_path)
    g = table.gears
    name = scene.get("scene", {}).get("name", Path(scene_path).stem)

    # ---- gear data
    geo = pair.appendix_f_table(power_W=g.power_kW * 1e3, pinion_speed_rpm=g.max_speed_rpm)
    geo.update({"kind": pair.kind, "module_mm": g.module_mm, "teeth": list(pair.teeth),
                "pressure_angle_deg": g.pressure_angle_deg, "helix_angle_deg": g.helix_angle_deg,
                "addendum_modification": list(pair.profile_shift), "face_width_mm": g.face_width_mm,
                "centre_distance_mm": pair.centre_distance * 1e3})
    write_json(out_dir / "gear_geometry.json", geo)
    fig, axes = plt.subplots(1, 2, figsize=(9, 4.5))
    for ax, gear, label in zip(axes, (0, 1), ("pinion", "wheel")):
        prof = tooth_profile(pair, gear)
        ax.plot(prof["outline"][:, 0] * 1e3, prof["outline"][:, 1] * 1e3, "k-")
        th = np.linspace(-0.15, 0.15, 50)
        for r, style in ((pair.base_diameter[gear] / 2, "b:"), (pair.pitch_diameter[gear] / 2, "g--"),
                         (prof["form_radius"], "r:")):
            ax.plot(r * np.sin(th) * 1e3, r * np.cos(th) * 1e3, style, lw=0.8)
        ax.set_aspect("equal")
        ax.set_xlim(-1.6 * pair.module * 1e3, 1.6 * pair.module * 1e3)
        ax.set_title(f"{label} (z = {pair.teeth[gear]}), transverse section")
        ax.set_xlabel("mm")
        write_csv(out_dir / f"tooth_profile_{label}.csv", ["x_mm", "y_mm"], (prof["outline"] * 1e3).tolist())
    fig.suptitle("tooth profiles: involute + trochoid fillet (black), base (blue), pitch (green), form circle (red)",
                 fontsize=8)
    fig.tight_layout()
    fig.savefig(out_dir / "tooth_profiles.png", dpi=120)
    plt.close(fig)

    # ---- stiffness at the scene torque
    te = None
    if table.transmission_error:
        from housingfe.source.transmission_error import read

        te = read(table.transmission_error)
    op = OperatingPoint(pair, corr, interior, model, table.torque_Nm, table.stiffness_positions,
                        engagement=table.engagement, transmission_error=te)
    c = op.curve
    iso = iso6336_stiffness(pair)
    write_csv(out_dir / "stiffness.csv", ["position_fraction_of_pitch", "mesh_stiffness_N_per_m",
                                          "s_N_per_mm_um", "deflection_um"],
              [[float(x), float(k), float(s) / 1e9, float(d) * 1e6] for x, k, s, d in
               zip(c.position, c.stiffness, c.per_width, c.deflection)])
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(np.append(c.position, 1.0) * 100, np.append(c.per_width, c.per_width[0]) / 1e9, "o-", ms=3,
            label="analytic (Sec. 2.2-2.3)")
    ax.axhline(iso["c_gamma_alpha_N_per_mm_um"], color="r", ls="--", label="ISO 6336-1 c_gamma_alpha")
    ax.axhline(iso["c_prime_N_per_mm_um"], color="g", ls=":", label="ISO 6336-1 c'")
    ax.set_xlabel("mesh position [% of base pitch]")
    ax.set_ylabel("s [N/(mm um)]")
    ax.set_title(f"{name}: tooth stiffness per unit width at T1 = {table.torque_Nm:g} N m")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out_dir / "stiffness.png", dpi=120)
    plt.close(fig)

    # ---- spectra at chosen speeds
    H = table.harmonics
    rows_spec, rows_band = [], []
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for rpm in table.spectrum_speeds_rpm:
        st = op.steady_state(pair, rpm, H)
        lv = dyn.wheel_levels(st)
        rows_spec += [[rpm, float(f), float(L)] for f, L in zip(lv["f"], lv["L_omega"])]
        rows_band += [[rpm, float(n), float(cc), float(L)] for n, cc, L in
                      zip(lv["band_nominal"], lv["band_center"], lv["band_L_omega"])]
        filled = np.isfinite(lv["band_L_omega"])            # bands without a harmonic line stay empty
        line, = ax.step(lv["band_center"][filled], lv["band_L_omega"][filled], where="mid",
                        label=f"{rpm:g} rpm: 1/3 octaves (lines: narrow band)")
        ax.plot(lv["f"], lv["L_omega"], ".", ms=4, color=line.get_color())
    write_csv(out_dir / "L_omega_narrowband.csv", ["speed_rpm", "frequency_hz", "L_omega_dB"], rows_spec)
    write_csv(out_dir / "L_omega_third_octave.csv", ["speed_rpm", "band_nominal_hz", "band_center_hz",
                                                     "L_omega_dB"], rows_band)
    ax.set_xscale("log")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("L_omega wheel [dB re 5e-8 rad/s]")
    ax.set_ylim(bottom=40)
    ax.legend(fontsize=8)
    ax.set_title(f"{name}: wheel angular velocity level, T1 = {table.torque_Nm:g} N m")
    fig.tight_layout()
    fig.savefig(out_dir / "L_omega_spectra.png", dpi=120)
    plt.close(fig)

    # ---- run-up over speed (+ bearing spectra for the housing chain)
    speeds = np.linspace(table.speed_min_rpm, table.speed_max_rpm, table.speed_steps)
    runup, spectra, mesh_rows = [], [], []
    contact = []            # dyn.contact_check of every operating point: teeth separating invalidate the levels
    for rpm in speeds:
        st = op.steady_state(pair, float(rpm), H)
        contact.append(dyn.contact_check(st, table.torque_Nm, float(rpm)))
        runup.append([float(rpm), table.torque_Nm, pair.tooth_frequency(rpm), dyn.tooth_band_level(st)])
        bs = dyn.bearing_spectra(st, op.mats, interior, geometry, pair, float(rpm), table.torque_Nm)
        spectra.append(bs)
        f_mesh, a_mesh = st.one_sided(st.mesh_force)
        mesh_rows += [[float(rpm), float(f), float(abs(a))] for f, a in zip(f_mesh[:10], a_mesh[:10])]
    write_csv(out_dir / "runup.csv", ["speed_rpm", "torque_Nm", "tooth_frequency_hz", "L_omega_tooth_band_dB"], runup)
    write_csv(out_dir / "mesh_force.csv", ["speed_rpm", "frequency_hz", "dynamic_mesh_force_amplitude_N"], mesh_rows)
    write_json(out_dir / "bearing_spectra.json", {
        "description": "complex one-sided amplitudes [re, im] of loads the shafts exert on the housing at "
                       "the bearings; load(t) = Re(sum A exp(i 2 pi f t)); components Fx Fy Fz [N] Mx My Mz [N m]; "
                       "z [m] along the shaft from the gear centre plane (see housingfe.source.roosmalen.dynamics.BearingSpectra)",
        "components": ["Fx", "Fy", "Fz", "Mx", "My", "Mz"],
        "operating_points": [{"speed_rpm": b.speed_rpm, "torque_Nm": b.torque_Nm, "frequency_hz": b.frequency,
                              "bearings": [{"name": n, "z_m": float(z), "re": ld.real, "im": ld.imag}
                                           for n, z, ld in zip(b.names, b.z, b.loads)],
                              "lumped_at_gear_centre": [{"shaft": sh, "components": ["Fx", "Fy", "Fz", "Mx", "My"],
                                                         "re": lp.real, "im": lp.imag}
                                                        for sh, lp in zip(("pinion", "wheel"), b.lumped)]}
                             for b in spectra]})

    # ---- torque run at one speed
    torque_rows = []
    for T in table.torque_run_Nm:
        opT = op if T == table.torque_Nm else OperatingPoint(pair, corr, interior, model, T, table.stiffness_positions,
                                                             engagement=table.engagement, transmission_error=te)
        st = opT.steady_state(pair, table.torque_run_speed_rpm, H)
        contact.append(dyn.contact_check(st, T, table.torque_run_speed_rpm))
        torque_rows.append([table.torque_run_speed_rpm, T, pair.tooth_frequency(table.torque_run_speed_rpm),
                            dyn.tooth_band_level(st), opT.curve.mean, opT.curve.deflection.mean() * 1e6])
    write_csv(out_dir / "torque_run.csv", ["speed_rpm", "torque_Nm", "tooth_frequency_hz", "L_omega_tooth_band_dB",
                                           "mean_mesh_stiffness_N_per_m", "mean_deflection_um"], torque_rows)

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    runup_arr = np.array(runup)
    axes[0].plot(runup_arr[:, 0], runup_arr[:, 3], "o-", ms=3, label="calculated")
    comparison = []
    if table.measured_L_omega_dB:
        ms = sorted((float(k), v) for k, v in table.measured_L_omega_dB.items())
        axes[0].plot([m[0] for m in ms], [m[1] for m in ms], "rs", label="measured (Sec. 5.3)")
        for rpm, meas in ms:
            ours = dyn.tooth_band_level(op.steady_state(pair, rpm, H))
            comparison.append([rpm, meas, ours, ours - meas])
    axes[0].set_xlabel("pinion speed [rpm]")
    axes[0].set_ylabel("L_omega in tooth-frequency band [dB]")
    axes[0].legend(fontsize=8)
    axes[0].set_title(f"run-up at T1 = {table.torque_Nm:g} N m")
    tr = np.array(torque_rows)
    axes[1].plot(tr[:, 1], tr[:, 3], "o-")
    axes[1].set_xlabel("pinion torque [N m]")
    axes[1].set_ylabel("L_omega in tooth-frequency band [dB]")
    axes[1].set_title(f"torque run at {table.torque_run_speed_rpm:g} rpm")
    fig.tight_layout()
    fig.savefig(out_dir / "runup.png", dpi=120)
    plt.close(fig)

    params = asdict(interior)
    params["natural_frequencies_hz"] = dyn.natural_frequencies(op.mats)
    params["mean_mesh_stiffness_N_per_m"] = c.mean
    write_json(out_dir / "interior_parameters.json", params)

    summary = [
        f"scene {name} ({scene_path})",
        "",
        format_table(["quantity", "value"], [
            ["centre distance / zero-backlash a_w [mm]",
             f"{pair.centre_distance * 1e3:.4f} / {pair.zero_backlash_centre_distance * 1e3:.4f}"],
            ["normal backlash j_bn [mm]", f"{pair.normal_backlash * 1e3:.4f}"],
            ["tip diameters [mm]", f"{pair.tip_diameter[0] * 1e3:.3f}, {pair.tip_diameter[1] * 1e3:.3f} "
             f"({geo['tip_diameter_from']})"],
            ["transverse contact ratio", f"{pair.transverse_contact_ratio:.3f}"],
            ["overlap ratio", f"{pair.overlap_ratio:.3f}"],
            ["mean s [N/(mm um)]", f"{c.per_width.mean() / 1e9:.2f}"],
            ["ISO 6336-1 c' / c_gamma_alpha [N/(mm um)]",
             f"{iso['c_prime_N_per_mm_um']:.2f} / {iso['c_gamma_alpha_N_per_mm_um']:.2f}"],
            ["mean deflection [um]", f"{c.deflection.mean() * 1e6:.1f}"],
            ["stiffness peak-to-peak / mean", f"{np.ptp(c.stiffness) / c.mean:.4f}"],
        ]),
    ]
    if comparison:
        summary += ["", "L_omega in the tooth-frequency band, ours vs measured (Sec. 5.3):",
                    format_table(["speed_rpm", "measured_dB", "ours_dB", "difference_dB"], comparison,
                                 floatfmt="{:.1f}")]
        write_csv(out_dir / "L_omega_vs_measured.csv", ["speed_rpm", "measured_dB", "ours_dB", "difference_dB"],
                  comparison)
    note = overlap.cancellation_note(pair, corr, op)     # face-width engagement at a near-integer eps_beta
    if note:
        summary += ["", note]
    if te is not None:
        summary += ["", f"excitation: the transmission error of {te.source} (sha256 {te.sha256[:12]}) instead of the "
                        "engagement model, on the model's mesh stiffness S(t) (source.transmission_error)"]
    # the quasi-static TE the source had, in the format source.transmission_error / runup.transmission_error read
    from housingfe.source.transmission_error import harmonics_of, write

    write(out_dir / "transmission_error.csv", [table.torque_Nm], range(1, H + 1),
          [harmonics_of(dyn.quasi_static_compression(op.S, op.shock, op.normal_force), H)],
          comment="quasi-static transmission error of the source at source.torque_Nm: "
                  + (f"the file {te.source}" if te is not None else f"the engagement model {table.engagement!r}")
                  + "\ne = d_qs - mean d_qs, d_qs = (F - F_e) / S(t); t = 0 at the mesh position T1 (docs/source.md)")
    lost = [x.message for x in contact if x.lost]
    write_json(out_dir / "contact_check.json", {"contact_loss": lost, "min_over_mean_mesh_force": min(
        x.min_force_N / x.mean_force_N for x in contact)})
    if lost:
        summary += ["", f"WARNING: {lost[0]} ({len(lost)} of {len(contact)} operating points: contact_check.json)"]
    (out_dir / "summary.txt").write_text("\n".join(summary) + "\n")
    print("\n".join(summary))
    return {"runup": runup, "comparison": comparison, "stiffness_mean": c.mean, "contact_loss": lost}


def correction_study(scenes: tuple[str, ...] = ("gearset-uncorrected", "gearset-A", "gearset-B", "gearset-C",
                                                "gearset-D"),
                     torques: tuple[float, ...] = (400.0, 800.0, 1200.0, 1600.0, 2000.0),
                     speeds_rpm: tuple[float, ...] = tuple(np.linspace(800.0, 1500.0, 15)),
                     harmonics: int = 20, engagement: str | None = None) -> dict:
    """L_omega in the tooth band for the built-in gear sets over torque (at 1500 rpm, as Fig. 2.18) and
    the mean over `speeds_rpm` at each torque; engagement: the shock model (None: each scene's own).
    Returns {scene: {"torque": [...], "L_1500": [...], "L_mean": [...]}} in dB."""
    from housingfe.source.cli import load_scene

    out = {}
    for name in scenes:
        scene, path = load_scene(name)
        table = parse(scene, str(path))
        pair, corr, _, interior, model = build(table, str(path))
        rows = {"torque": list(torques), "L_1500": [], "L_mean": []}
        for T in torques:
            op = OperatingPoint(pair, corr, interior, model, T, table.stiffness_positions,
                                engagement=engagement or table.engagement)
            rows["L_1500"].append(dyn.tooth_band_level(op.steady_state(pair, 1500.0, harmonics)))
            levels = [dyn.tooth_band_level(op.steady_state(pair, float(s), harmonics)) for s in speeds_rpm]
            # energy mean over the speeds (a level average would weight dips too much)
            rows["L_mean"].append(float(10 * np.log10(np.mean(10 ** (np.array(levels) / 10)))))
        out[name] = rows
    return out
