"""Run-up scenes (`kind = "runup"`): a housing scene, a drivetrain description, a speed and torque range ->
L_omega, L_v, L_W, L_WA over speed.  `housingfe run test-gearbox-runup`.

    [scene]        name, kind = "runup", description
    [housing]      scene = "test-gearbox" (a housing scene with the drivetrain's bores; a .toml path is taken
                   relative to this scene's file), set = [overrides], match = "name" | "position",
                   bores = {bearing = "housing bore"}, bore_tolerance (m): the drivetrain's bearings matched to
                   the housing's bores and checked against the shafts (housingfe.drivetrain.bore_matching)
    [drivetrain]   gearbox = "test_gearbox", gear_set = "A", bearings = "ball", bearing_speed_rpm = 1500,
                   wheel_locating = "configuration" | "front" | "back" (which wheel bearing locates it axially),
                   floating_axial_ratio = 0.0 (the floating bearings' mean axial load / their radial load)
    [runup]        speeds, torques, f_max_hz (highest harmonic line), basis_factor, routes, damping_ratio, ...
    [radiation]    models = ["erp", "foller"], plates = [...]  (the housing's radiating plates)

Only this module reads a run-up scene; the stages get typed arguments (housingfe.runup.chain).
"""
from __future__ import annotations

import time
from pathlib import Path
from typing import Literal, Optional, Union

import numpy as np
from pydantic import Field, PositiveFloat, PositiveInt, field_validator, model_validator

from housingfe.errors import InputError
from housingfe.scene import RadiationPlate
from housingfe.scenefile import (
    SceneInfo,
    _Strict,
    apply_overrides,
    naming_the_override,
    parse_table,
    read_scene_dict,
)
from housingfe.solvers.blas import single_thread
from housingfe.source.roosmalen.dynamics import DEFAULT_ENGAGEMENT, ENGAGEMENT_MODELS
from housingfe.source.roosmalen.operating import SPEED_RANGE_RPM
from housingfe.source.transmission_error import checked_scene, validated_scene_file

# the engagement the run-up also runs (source + routes on the same models) when the default meets an overlap ratio
# near an integer (housingfe.source.roosmalen.overlap.cancellation_note): its range, not a model adopted
BOUND_ENGAGEMENT = "envelope-bound"


def _gearboxes() -> dict:
    """Drivetrain descriptions by name (a registry: a new gearbox is one entry)."""
    from housingfe.drivetrain.description import test_gearbox

    return {"test_gearbox": test_gearbox}


def _checked(key: str, check, value):
    """check(value) for a field validator: its InputError "<key>: ..." becomes a ValueError without the key, which
    the error's location puts in front again."""
    try:
        return check(value)
    except InputError as exc:
        raise ValueError(str(exc).removeprefix(f"{key}: ")) from None


class HousingRef(_Strict):
    """The housing: a housing scene (built-in name or path) with optional --set style overrides, and how the
    drivetrain's bearings find its bores (housingfe.drivetrain.bore_matching): match = "name" (each bearing's own
    bore surface, e.g. bore_pinion_front on the built-in gearbox) or "position" (the one bore on the bearing's
    shaft that holds it); bores = {bearing name: housing bore name} for single bearings; bore_tolerance (m): how
    far a bore's centre may lie off its shaft's axis (and a bearing beyond the bore's ends)."""

    scene: str = "test-gearbox"
    set: list[str] = []
    match: Literal["name", "position"] = "name"
    bores: dict[str, str] = {}
    bore_tolerance: PositiveFloat = Field(1e-3, json_schema_extra={"unit": "m"})


class DrivetrainSpec(_Strict):
    """The drivetrain description (housingfe.drivetrain.description): a registered gearbox and its choices."""

    gearbox: str = "test_gearbox"
    gear_set: str = "A"
    bearings: str = "ball"
    # pinion speed at which speed-dependent bearings (fluid films) are taken with runup.bearing_speeds = "fixed"; with
    # "follow" (default) the speed of the model whose basis is re-analysed at each run-up speed
    bearing_speed_rpm: PositiveFloat = 1500.0
    # which of the wheel's two bearings locates it axially (takes the axial mesh force; with a configuration: its
    # locating bearing type sits there, the floating type at the other): "configuration" (the default: the side the
    # thesis states for the bearings -- "back" for angular_contact and tapered_roller, Sec. 5.8: "at the front
    # (pinion) and at the back (wheel)" -- "front" where it states none), or "front" / "back" for any bearings
    wheel_locating: str = "configuration"
    # the mean axial load each floating bearing keeps (its outer ring sticking in the bore: held by friction, at most
    # mu F_r) as a fraction of its own radial load, F_a = ratio |F_r|, the same ratio on both shafts: > 0 the shaft
    # pushes the floating bearing away from its locating bearing (a shaft warmer than its housing), < 0 towards it;
    # the locating bearing takes the reaction.  0 (default): the floating bearings carry no axial load.  |ratio| <=
    # 0.3 (above any lubricated ring-in-bore friction coefficient, 0.13-0.21); not with floating bearings that carry
    # no axial load (cylindrical_roller, fluid_film).  Where the held load would lift a directional locating bearing
    # (angular_contact below about -0.12, tapered_roller -0.06) the floating ring slides: the held load is the most
    # that bearing carries (a warning says so).  docs/bearings.md "The floating bearings' mean axial load"
    floating_axial_ratio: float = Field(0.0, json_schema_extra={"unit": "-"})

    @field_validator("floating_axial_ratio")
    @classmethod
    def _floating_axial_ratio(cls, ratio):
        from housingfe.drivetrain.description import FLOATING_AXIAL_LIMIT

        if not (np.isfinite(ratio) and abs(ratio) <= FLOATING_AXIAL_LIMIT):
            raise ValueError(f"{ratio:g}: must be within +-{FLOATING_AXIAL_LIMIT:g} (a floating ring held by its "
                             "friction in the bore: mu = 0.13-0.21 greased)")
        return float(ratio)

    @model_validator(mode="after")
    def _floating_bearings_carry_it(self):
        if self.floating_axial_ratio != 0.0 and self.gearbox in _gearboxes() and self.bearings != "ball":
            from dataclasses import replace

            dt = _gearboxes()[self.gearbox](self.gear_set, self.bearings, 2000.0, wheel_locating=self.wheel_locating)
            problem = replace(dt, floating_axial_ratio=self.floating_axial_ratio).floating_axial_problem()
            if problem:
                raise ValueError(problem.removeprefix("drivetrain."))
        return self

    @field_validator("gearbox")
    @classmethod
    def _known(cls, name):
        return _one_of(name, _gearboxes(), "a drivetrain description")

    @field_validator("gear_set")
    @classmethod
    def _gear_set(cls, name):
        from housingfe.drivetrain.description import GEAR_SETS

        return _one_of(name, GEAR_SETS, "a gear set")

    @field_validator("wheel_locating")
    @classmethod
    def _wheel_locating(cls, side):
        from housingfe.drivetrain.description import WHEEL_LOCATING

        return _one_of(side, WHEEL_LOCATING, "a bearing side")

    @field_validator("bearings")
    @classmethod
    def _bearings(cls, name):
        from housingfe.bearings.configurations import configurations

        return _one_of(name, configurations(), "a bearing configuration")     # "ball" is one of them


def _one_of(value: str, known, what: str) -> str:
    """value if it is one of `known` (names), else the ValueError a field validator raises: "'x' is not <what>
    (known: ...)"."""
    known = list(known)
    if value not in known:
        raise ValueError(f"{value!r} is not {what} (known: {', '.join(known)})")
    return value


class RunupSpec(_Strict):
    """Speeds (pinion, rev/min) from speed_min to speed_max in speed_step; torques (pinion, N m); the harmonics of
    the tooth frequency up to f_max_hz; a modal basis to basis_factor x f_max_hz; routes of
    housingfe.runup.chain.ROUTES; modal damping ratio (Sec. 5.4: 0.04); harmonics of the source's harmonic balance;
    spectra at spectrum_speeds_rpm; the observed (radiating) surface; the source's engagement shock model; the
    receptance around the mesh in the source's harmonic balance; the mesh misalignment under load in its mesh
    stiffness and load share (docs/misalignment.md)."""

    speed_min_rpm: PositiveFloat = 50.0
    speed_max_rpm: PositiveFloat = 1500.0
    speed_step_rpm: PositiveFloat = 50.0
    torques_nm: list[PositiveFloat] = Field(default=[2000.0], min_length=1)
    f_max_hz: PositiveFloat = 4000.0
    basis_factor: float = Field(1.5, ge=1.0, le=4.0)
    routes: list[str] = Field(default=["tf_omega", "mesh_force"], min_length=1)
    damping_ratio: float = Field(0.04, gt=0.0, lt=1.0)
    harmonics: int = Field(30, ge=1, le=400)     # of the source's harmonic balance (at most 400, as [source] harmonics)
    spectrum_speeds_rpm: list[PositiveFloat] = [500.0, 1000.0, 1500.0]
    surface: str = "outer"
    # the source's engagement shock (housingfe.source.roosmalen.dynamics.ENGAGEMENT_MODELS): "face-width" distributes
    # Eq. 2.62 over the face-width slices; "thesis-2d" is the thesis' two-dimensional shock (the replica);
    # "envelope-bound" the face-width excitation's envelope bound near an integer overlap ratio (a bound, not a model)
    engagement: Literal[ENGAGEMENT_MODELS] = DEFAULT_ENGAGEMENT
    # a transmission error the user brings instead of the engagement model (housingfe.source.transmission_error;
    # docs/source.md "A transmission error from a file"): a CSV file (relative to the scene file, else to the current
    # folder) with columns torque_Nm, harmonic, amplitude_um (or _mm, _m), phase_deg (optional): the quasi-static TE
    # per tooth harmonic, measured or from another code, at torques that span runup.torques_nm; the mesh stiffness
    # S(t) stays the model's.  "" (default) = the engagement model
    transmission_error: str = Field("", json_schema_extra={"unit": "file"})
    # the run-up per micrometre of transmission error (housingfe.runup.chain.te_sensitivity; te_sensitivity.csv): the
    # tooth harmonics n at which 1 um of TE alone drives the same chain (no mesh moment, no friction): the L_WA a TE
    # target gives, and how a measured level splits into source and transfer; [] = none (each costs one source and
    # response pass, ~1 s)
    te_sensitivity: list[PositiveInt] = Field(default=[1], json_schema_extra={"unit": "tooth harmonic"})
    # a measured run-up laid over the chain's (housingfe.runup.measured; docs/runup.md "Your measured run-up beside
    # the chain's"): a CSV file (relative to the scene file, else to the current folder) with columns speed_rpm,
    # torque_Nm (optional with one torque) and one or more of L_WA_dBA, L_W_dB, L_v_dB, L_omega_dB (the chain's dB
    # references); its torques must be the run's.  Writes measured_comparison.csv, the summary's ours - measured
    # (mean +- s.d., maxima, slopes), runup.json "measured" and the points on runup.png.  "" (default) = none
    measured: str = Field("", json_schema_extra={"unit": "file"})
    # the receptance around the mesh in the source's harmonic balance (housingfe.runup.chain.SOURCE_RECEPTANCES):
    # "coupled" = the coupled gearbox (housing, bearings, shafts, gear bodies) from the Ritz reduction;
    # "rigid-bores" = the lumped interior on rigid bores (the thesis' Ch. 2 source)
    source_receptance: Literal["coupled", "rigid-bores"] = "coupled"
    # the mesh misalignment under load in the source's mesh stiffness and load share
    # (housingfe.drivetrain.misalignment): "rigid-bores" = static tilt of the FE interior (shafts, bearings at their
    # loaded 6x6 stiffness) on rigid bores at each torque; "coupled" = the same on the flexible housing (one static
    # solve of the coupled model per torque); "lumped" = of the 14-DOF source model; "none" = aligned gears.
    # Default: "rigid-bores" with the face-width engagement (and its envelope bound), "none" with the thesis' replica
    # "thesis-2d"
    misalignment: Optional[Literal["rigid-bores", "coupled", "lumped", "none"]] = None
    # the mesh moment applied with the mesh excitation on the coupled model (housingfe.runup.chain.MESH_MOMENTS):
    # "shuttling" = the moment of the mesh force whose centre of pressure moves axially over the face as the
    # contact lines move (issue 28; docs/source.md "The shuttling moment"), on the mesh_force route; "none" = the
    # force alone.  Default: housingfe.runup.chain.DEFAULT_MESH_MOMENT, and "none" with the thesis' replica
    # "thesis-2d"
    mesh_moment: Optional[Literal["shuttling", "none"]] = None
    # the sliding friction at the flanks applied with the mesh excitation on the mesh_force route (and in the coupled
    # source's L_omega; housingfe.runup.chain.MESH_FRICTIONS; docs/source.md "Sliding friction"): "none" (default);
    # "iso13989" = the mean coefficient of ISO/TR 13989-1 at each speed and torque (oil 0.049 Pa s, Ra 0.4 um,
    # assumed) -- that formula was written from memory and is NOT verified against the standard's text, hence off by
    # default; or a number = a fixed mean coefficient, 0 < mu < 0.3
    mesh_friction: Union[Literal["none", "iso13989"], float] = Field("none", json_schema_extra={"unit": "-"})
    # the test rig's drive line in the coupled FE model (housingfe.drivetrain.description.DRIVE_LINES): "quill-shafts"
    # = the quill shafts and couplings to the motor and the brake (torsion springs, coupling inertias: the lumped
    # source's, Appendix C shafts 1-4) from the shafts' front ends to ground, which restrain the gear train's rigid
    # rotation (a rig torsion mode near 76 Hz instead of a zero mode); "none" = the shafts end at the bearing
    # plates; "back-to-back" = the same quills and couplings, their far ends closing the rig's loop through the
    # auxiliary gearbox (ratio 57/19, rigid gears) with the drive motor on its pinion shaft (ASSUMED inertias and the
    # motor's hold on the loop's rotation: housingfe.drivetrain.description.AuxGearbox, docs/drivetrain.md).
    # Default: "quill-shafts", and "none" with the thesis' replica "thesis-2d" (docs/runup.md)
    drive_line: Optional[Literal["quill-shafts", "none", "back-to-back"]] = None
    # gears as made (housingfe.runup.as_made; docs/runup.md "Gears as made in the run-up"): "none" = the periodic
    # lines of identical teeth alone; an ISO 1328-1 accuracy grade 0..12 (e.g. 5, the thesis' DIN 5) = also the
    # expected shaft-order sidebands of tooth-to-tooth deviations uniform within that grade's tolerances, through the
    # same routes, in runup_as_made.csv beside the periodic outputs (runup.csv, runup_harmonics.csv and the checks
    # stay the periodic model's)
    as_made: Union[Literal["none"], int] = Field("none", json_schema_extra={"unit": "ISO 1328-1 grade"})
    # the shape of the as-made pitch deviations' order spectrum (housingfe.source.as_made.PITCH_MODELS; docs/source.md
    # "Pitch deviations: independent per tooth or runout"): "independent" = single pitch deviations independent per
    # tooth within f_pt and F_p (sidebands at every shaft order: the upper bound of the high-order sideband energy);
    # "runout" = the tooth positions one order-1 sinusoid per gear, amplitude uniform within F_p / 2 (sidebands only
    # at tooth orders +- 1 shaft order); "none" = no pitch deviations (the first-order limit of a pure eccentricity:
    # no tooth-band sidebands).  The flank deviations stay independent per tooth; used only with runup.as_made on
    as_made_pitch: Literal["independent", "runout", "none"] = "independent"
    # gears as made in the totals (housingfe.runup.as_made.folded_result; docs/runup.md "Gears as made in the
    # totals"): false (default) = runup.csv, runup_harmonics.csv, the spectra, the slope terms and the checks are the
    # periodic model's, the sidebands only in runup_as_made.csv; true = all of them hold the expected sidebands as
    # incoherent lines beside the periodic harmonics (energies add; the tooth band the lines in the 1/3-octave band of
    # f_tooth).  Needs runup.as_made = <ISO grade>
    as_made_totals: bool = False
    # speed-dependent bearings (the fluid-film journal bearings, drivetrain.bearings = "fluid_film") over the run-up
    # (housingfe.runup.chain.BEARING_SPEEDS; docs/runup.md "Fluid films over the run-up"): "fixed" = their K, C at the
    # one pinion speed drivetrain.bearing_speed_rpm at every run-up speed; "follow" = at each run-up speed (pinion at
    # the run-up speed, the wheel at z1/z2 of it), a re-analysis per speed on the same Ritz vectors; below the speed
    # at which a film carries its load the nearest speed that carries it (flagged in runup.json).  Rolling-element
    # bearings do not depend on speed: the same either way.  Default "follow" (since 2026-11-27; the physical one)
    bearing_speeds: Literal["fixed", "follow"] = "follow"

    _transmission_error = field_validator("transmission_error")(validated_scene_file)

    @field_validator("measured")
    @classmethod
    def _measured_file(cls, value, info):
        from housingfe.runup import measured
        from housingfe.scenefile import scene_file_key

        return scene_file_key(value, info, measured.read)

    @model_validator(mode="after")
    def _measured_torques(self):
        from housingfe.runup.measured import checked_scene as measured_checked

        return measured_checked(self)

    @model_validator(mode="after")
    def _te_sensitivity(self):
        if len(set(self.te_sensitivity)) != len(self.te_sensitivity):
            raise ValueError(f"te_sensitivity: {self.te_sensitivity}: a harmonic is named twice")
        too_high = [n for n in self.te_sensitivity if n > self.harmonics]
        if too_high:
            raise ValueError(f"te_sensitivity: harmonic {too_high[0]} is above the source's runup.harmonics = "
                             f"{self.harmonics}")
        return self

    @model_validator(mode="after")
    def _transmission_error_torques(self):
        return checked_scene(self, {"runup.torques_nm": self.torques_nm})

    @field_validator("as_made", mode="before")
    @classmethod
    def _as_made(cls, value):
        from housingfe.runup.as_made import check_as_made

        return _checked("as_made", check_as_made, value)

    @model_validator(mode="after")
    def _as_made_totals(self):
        if self.as_made_totals and self.as_made == "none":
            raise ValueError("as_made_totals: true needs runup.as_made = <ISO 1328-1 grade 0..12> (the sidebands to "
                             "fold into the totals), but runup.as_made is \"none\"")
        return self

    @field_validator("as_made_pitch", mode="before")
    @classmethod
    def _as_made_pitch(cls, value):
        from housingfe.source.as_made import check_pitch_model

        return _checked("as_made_pitch", check_pitch_model, value)

    @property
    def drive_line_model(self) -> str:
        """The FE drive line in effect (see `drive_line`)."""
        if self.drive_line is not None:
            return self.drive_line
        return "none" if self.engagement == "thesis-2d" else "quill-shafts"

    @property
    def mesh_moment_model(self) -> str:
        """The mesh moment in effect (see `mesh_moment`)."""
        from housingfe.runup.chain import DEFAULT_MESH_MOMENT

        if self.mesh_moment is not None:
            return self.mesh_moment
        return "none" if self.engagement == "thesis-2d" else DEFAULT_MESH_MOMENT

    @field_validator("mesh_friction", mode="before")
    @classmethod
    def _mesh_friction(cls, value):
        from housingfe.runup.chain import check_mesh_friction

        return _checked("mesh_friction", check_mesh_friction, value)

    @property
    def misalignment_model(self) -> str:
        """The misalignment model in effect (see `misalignment`)."""
        if self.misalignment is not None:
            return self.misalignment
        return "none" if self.engagement == "thesis-2d" else "rigid-bores"

    @field_validator("routes")
    @classmethod
    def _routes(cls, names):
        from housingfe.runup.chain import ROUTES

        for name in names:
            if name not in ROUTES:
                raise ValueError(f"{name!r} is not a route (known: {', '.join(ROUTES)})")
        return names

    @model_validator(mode="after")
    def _range(self):
        lo, hi = SPEED_RANGE_RPM
        if self.speed_min_rpm > self.speed_max_rpm:
            raise ValueError(f"speed_min_rpm: {self.speed_min_rpm:g} is above speed_max_rpm {self.speed_max_rpm:g}")
        span = self.speed_max_rpm - self.speed_min_rpm
        if span > 0.0 and self.speed_step_rpm > span * (1.0 + 1e-9):     # else one speed, speed_max never reached
            raise ValueError(f"speed_step_rpm: {self.speed_step_rpm:g} rev/min is larger than the run-up "
                             f"{self.speed_min_rpm:g}..{self.speed_max_rpm:g} rev/min: it would run speed_min_rpm "
                             "alone (for one speed give speed_max_rpm = speed_min_rpm)")
        for key in ("torques_nm", "routes"):     # a repeat ran (and reported) the same run-up twice
            values = getattr(self, key)
            twice = [v for i, v in enumerate(values) if v in values[:i]]
            if twice:
                raise ValueError(f"{key}: {twice[0]!r} is given twice")
        keys = [("speed_min_rpm", self.speed_min_rpm), ("speed_max_rpm", self.speed_max_rpm)]
        # a spectrum speed outside the run-up was skipped without a word (no spectra_<speed>rpm.csv)
        keys += [("spectrum_speeds_rpm", s) for s in self.spectrum_speeds_rpm]
        for key, v in keys:
            if not lo <= v <= hi:
                raise ValueError(f"{key}: {v:g} rev/min is outside the range the source supports ({lo:g}..{hi:g} "
                                 "rev/min, the thesis' run-up)")
        return self

    @property
    def speeds(self) -> np.ndarray:
        n = int(np.floor((self.speed_max_rpm - self.speed_min_rpm) / self.speed_step_rpm + 1e-9)) + 1
        return self.speed_min_rpm + self.speed_step_rpm * np.arange(n)


class RunupRadiation(_Strict):
    """Radiation models (housingfe.radiation.radiators.RADIATORS) computed side by side; the first is the one the
    checks use.  plates: the radiating plates (Föller, numerical)."""

    models: list[str] = Field(default=["erp", "foller"], min_length=1)
    plates: list[RadiationPlate] = []

    @field_validator("models")
    @classmethod
    def _registered(cls, names):
        from housingfe.radiation.radiators import check_radiator

        twice = [n for i, n in enumerate(names) if n in names[:i]]
        if twice:        # computed and reported twice
            raise ValueError(f"{twice[0]!r} is given twice")
        return [check_radiator(n) for n in names]

    @model_validator(mode="after")
    def _plates(self):
        from housingfe.radiation.radiators import RADIATORS

        needs = [m for m in self.models if RADIATORS[m].needs_plates]
        if needs and not self.plates:
            raise ValueError(f"plates: the model(s) {', '.join(needs)} need the radiating plates")
        return self


class RunupScene(_Strict):
    scene: SceneInfo
    housing: HousingRef = HousingRef()
    drivetrain: Optional[DrivetrainSpec] = None
    runup: RunupSpec = RunupSpec()
    radiation: RunupRadiation = RunupRadiation(models=["erp"])
    reference: Optional[dict] = None

    @model_validator(mode="after")
    def _kind(self):
        if self.scene.kind != "runup":
            raise ValueError("scene.kind: a run-up scene has kind = \"runup\"")
        if self.drivetrain is None:
            raise ValueError(f"drivetrain: missing [drivetrain]: the routes {', '.join(self.runup.routes)} act on "
                             "the gears and shafts of a drivetrain description (e.g. gearbox = \"test_gearbox\")")
        return self


def load_runup_scene(name_or_path: str, overrides: list[str] | None = None) -> tuple[RunupScene, Path]:
    """Read and validate a run-up scene; InputError naming the file and key on any problem."""
    data, path = read_scene_dict(name_or_path)
    apply_overrides(data, overrides or [])
    kind = data.get("scene", {}).get("kind") if isinstance(data.get("scene"), dict) else None
    if kind in ("housing", "source"):      # else its housing keys were reported as unknown run-up keys
        raise InputError(f"{path}: scene.kind: {kind!r}: this command takes a run-up scene (kind = \"runup\", "
                         f"e.g. test-gearbox-runup); run a {kind} scene with `housingfe "
                         f"{'run' if kind == 'housing' else 'source'}`")
    housing = data.get("housing")
    if isinstance(housing, dict) and isinstance(housing.get("scene"), str):
        # a housing scene file beside the run-up scene (an imported housing) is found from anywhere
        ref = Path(housing["scene"]).expanduser()
        if ref.suffix == ".toml" and not ref.is_absolute() and (path.parent / ref).is_file():
            housing["scene"] = str(path.parent / ref)
    try:
        scene = parse_table(RunupScene, data, path)
    except InputError as exc:
        raise naming_the_override(exc, overrides) from None
    # a torque beyond the teeth's strength has no load distribution (GearPair.torque_problem, docs/source.md): named
    # here, before the housing is meshed, instead of a solver error in the mesh stiffness
    pair = drivetrain_of(scene.drivetrain, scene.runup.torques_nm[0]).gears.pair
    for i, torque in enumerate(scene.runup.torques_nm):
        problem = pair.torque_problem(torque)
        if problem is not None:
            raise InputError(f"{path}: runup.torques_nm.{i}: {problem}")
    # below the lowest tooth frequency no line is computed at any speed, and the housing is meshed for f_max_hz (a
    # mesh of elements metres wide: gmsh did not finish in minutes)
    f_tooth = pair.tooth_frequency(scene.runup.speed_min_rpm)
    if scene.runup.f_max_hz < f_tooth:
        raise InputError(f"{path}: runup.f_max_hz: {scene.runup.f_max_hz:g} Hz is below the tooth frequency "
                         f"{f_tooth:.4g} Hz at runup.speed_min_rpm = {scene.runup.speed_min_rpm:g} rev/min: no line "
                         "of the run-up would lie below it")
    return scene, path


def drivetrain_of(spec: DrivetrainSpec, torque: float, drive_line: str = "none"):
    """The Drivetrain of a scene's [drivetrain] at a pinion torque (N m), with the FE drive line `drive_line`
    (a run-up's RunupSpec.drive_line_model; housingfe.drivetrain.description.DRIVE_LINES)."""
    from dataclasses import replace

    dt = _gearboxes()[spec.gearbox](spec.gear_set, spec.bearings, torque, wheel_locating=spec.wheel_locating)
    return replace(dt, bearing_speed_rpm=spec.bearing_speed_rpm, drive_line=drive_line,
                   floating_axial_ratio=spec.floating_axial_ratio)


@single_thread
def run_scene(name_or_path: str, out_dir: str | None = None, overrides: list[str] | None = None) -> Path:
    """`housingfe run <runup scene>`: build the coupled gearbox once, run the source and the routes over speed and
    torque, write runup.csv, runup_harmonics.csv, spectra, plots, checks and runup.json atomically."""
    from mpi4py import MPI

    from housingfe import outputs
    from housingfe.runup import checks, report, slopes
    from housingfe.runup.chain import (
        build_gearbox_model,
        follow_speeds,
        held_speed_note,
        run_source,
        runup,
        with_drivetrain,
    )
    from housingfe.scene import load_housing_scene

    t_start = time.perf_counter()
    scene, path = load_runup_scene(name_or_path, overrides)
    comm = MPI.COMM_WORLD
    out = Path(out_dir or f"results/{scene.scene.name}")
    outputs.reserve_output(out, comm, inputs=[path])   # a bad or busy output place stops here, before any work
    spec = scene.runup
    housing_scene, _ = load_housing_scene(scene.housing.scene, list(scene.housing.set))
    try:
        drivetrains = {t: drivetrain_of(scene.drivetrain, t, spec.drive_line_model) for t in spec.torques_nm}
        for t, dt in drivetrains.items():     # a bearing that cannot carry its load stops here, before any FE
            dt.to_coupling_spec()
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None
    from housingfe.progress import Progress

    timings = {}
    # steps: the housing model, the coupled model with its basis, the run-up over speed at every torque
    progress = Progress(f"run-up {scene.scene.name}", 2 + len(spec.torques_nm), "steps", comm=comm)
    t0 = time.perf_counter()
    model = housing_model_for(housing_scene, spec.f_max_hz, comm)
    if spec.surface not in model.housing.facet_groups:     # else found after the basis, named as a housing-scene key
        raise InputError(f"{path}: runup.surface: no surface {spec.surface!r} on the housing {scene.housing.scene} "
                         f"(known: {', '.join(sorted(model.housing.facet_groups))})")
    try:
        radiators = radiators_of(scene.radiation, model)
    except InputError as exc:       # a plate's surface the housing lacks: name the run-up scene too
        raise InputError(f"{path}: {exc}") from None
    timings["mesh_s"] = time.perf_counter() - t0
    progress.update(note=f"housing model, {model.dofs} DOFs")
    reference_torque = max(spec.torques_nm)
    drivetrains, bores = matched_drivetrains(scene.housing, model, drivetrains, path)
    if comm.rank == 0:
        for row in bores:
            print(f"bearing {row['bearing']} -> {row['surface']}: centre "
                  f"[{', '.join(f'{x + 0.0:.4g}' for x in row['centre_m'])}] m, radius {row['radius_m'] * 1e3:.4g} mm")
    source = prepared = None
    if spec.misalignment_model != "coupled":
        # the lumped source's operating points (stiffness curve, load share: ~0.4 s) need no FE here: computed on the
        # spare core while the coupled model is built (the same code on the same inputs: the same numbers)
        from housingfe.solvers.spare_core import Forked

        source = _source(drivetrains[reference_torque], spec, spec.misalignment_model)
        prepared = Forked(lambda: source.prepared(spec.torques_nm), parallel=comm.size == 1)
    gm = build_gearbox_model(model, drivetrains[reference_torque], spec.f_max_hz, damping_ratio=spec.damping_ratio,
                             basis_factor=spec.basis_factor, radiators=radiators, surface=spec.surface,
                             friction=spec.mesh_friction != "none")
    gm.bores = bores
    timings.update({k: gm.timings[k] for k in ("coupling_s", "basis_s", "reduction_s")})
    progress.update(note="coupled model and modal basis")
    misalignment = spec.misalignment_model
    if source is not None:
        t1 = time.perf_counter()
        source.adopt(prepared.result())
        timings["source_wait_s"] = time.perf_counter() - t1
    elif misalignment == "coupled":         # the static tilt on the flexible housing, per torque
        from housingfe.drivetrain.misalignment import coupled_misalignment

        t1 = time.perf_counter()
        gaps = {float(t): coupled_misalignment(model, dt).lead_gap for t, dt in drivetrains.items()}
        timings["misalignment_s"] = time.perf_counter() - t1

        def misalignment(torque: float) -> float:
            return gaps[float(torque)]

        source = _source(drivetrains[reference_torque], spec, misalignment)
    results = {}
    for torque in spec.torques_nm:
        t1 = time.perf_counter()
        m = gm if torque == reference_torque else with_drivetrain(gm, drivetrains[torque])
        timings[f"reanalysis_{torque:g}Nm_s"] = time.perf_counter() - t1 if m is not gm else 0.0
        if spec.bearing_speeds == "follow":     # fluid films at each run-up speed (rolling bearings: m itself)
            t1 = time.perf_counter()
            try:
                m = follow_speeds(m, spec.speeds)
            except InputError as exc:
                raise InputError(f"{path}: {torque:g} N m: {exc}") from None
            if m.speed_models:
                timings[f"bearing_speeds_{torque:g}Nm_s"] = time.perf_counter() - t1
                for k in ("bearing_matrices_s", "ritz_rows_s"):
                    timings[f"bearing_speeds_{torque:g}Nm_{k}"] = m.timings[k]
        lines, t_src = run_source(m, source, spec.speeds, [torque], spec.f_max_hz, spec.source_receptance,
                                  spec.mesh_moment_model, spec.mesh_friction)
        timings["source_s"] = timings.get("source_s", 0.0) + t_src
        res = runup(m, None, spec.speeds, [torque], routes=tuple(spec.routes), lines=lines)
        for k, v in res.timings.items():
            timings[k] = timings.get(k, 0.0) + v
        results[torque] = (m, res)
        if comm.rank == 0 and spec.misalignment_model != "none":
            print(f"misalignment ({spec.misalignment_model}) at {torque:g} N m: lead gap "
                  f"{source.lead_gap(torque) * 1e6 + 0.0:.1f} um/m over the face (MeshModel.lead_gap)")
        progress.update(note=f"{torque:g} N m: {len(spec.speeds)} speeds, {len(lines.frequency)} lines")
    progress.close()
    check_rows, contributions = checks.evaluate(scene, results, gm)
    note = source.overlap_note(reference_torque)      # cached operating point: milliseconds
    notes = [note] if note else []
    notes += [n for t, (m, _) in results.items() if (n := held_speed_note(m, t))]
    sensitivity = None
    if spec.te_sensitivity:         # the chain per um of TE on the same models (~1 s per harmonic)
        from housingfe.runup.chain import te_sensitivity

        sensitivity, timings["te_sensitivity_s"] = te_sensitivity(
            {t: m for t, (m, _) in results.items()}, source, spec.te_sensitivity, spec.speeds, spec.f_max_hz,
            spec.source_receptance, routes=tuple(spec.routes))
    te = source.transmission_error
    if te is not None:
        notes.append(f"  excitation: the transmission error of {te.source} (sha256 {te.sha256[:12]}, harmonics "
                     f"{int(te.harmonics[0])}..{int(te.harmonics[-1])}, torques "
                     f"{', '.join(f'{t:g}' for t in te.torques)} N m) instead of the engagement model, on the model's "
                     "mesh stiffness S(t) (runup.transmission_error; docs/source.md)")
    bound = bound_checks = None
    if note:      # the face-width default at the helix's cancellation: the envelope bound on the same models
        from housingfe.runup.chain import engagement_rerun

        bound, timings["envelope_bound_s"] = engagement_rerun(
            {t: m for t, (m, _) in results.items()}, source, BOUND_ENGAGEMENT, spec.speeds, spec.f_max_hz,
            spec.source_receptance, spec.routes, spec.mesh_moment_model, spec.mesh_friction)
        notes += report.bound_lines(results, bound, scene.radiation.models[0])
        # the same checks on the bound's curves (the validate rows 28.bound.*: reported beside the checks, not judged)
        t1 = time.perf_counter()
        bound_checks = checks.evaluate(scene, {t: (results[t][0], res) for t, res in bound.items()}, gm)
        timings["envelope_bound_checks_s"] = time.perf_counter() - t1
    as_made = None
    if spec.as_made != "none":     # the expected sidebands of gears as made, on the same models
        from housingfe.runup.as_made import as_made_run, summary_lines

        as_made = as_made_run(results, source, spec.as_made, spec.f_max_hz, spec.routes, spec.as_made_pitch)
        timings["as_made_s"] = as_made.seconds
        notes += summary_lines(as_made, scene.radiation.models[0])
        if spec.as_made_totals:     # one set of lines, the sidebands flagged incoherent: totals, spectra, checks
            from housingfe.runup.as_made import folded_result

            t1 = time.perf_counter()
            results = {t: (m, folded_result(m, res, as_made.sidebands[t])) for t, (m, res) in results.items()}
            check_rows, contributions = checks.evaluate(scene, results, gm)
            timings["as_made_totals_s"] = time.perf_counter() - t1
            notes.append(f"  gears as made in the totals (runup.as_made_totals): runup.csv, runup_harmonics.csv, the "
                         f"spectra, the slope terms and the checks hold the expected sidebands of ISO 1328-1 grade "
                         f"{as_made.grade} (pitch {as_made.pitch_model}) beside the periodic harmonics, energies "
                         "added")
    decompositions = [d for _, res in results.values() for d in slopes.decompose_all(res)]
    timings["total_s"] = time.perf_counter() - t_start
    check_rows = check_rows + checks.te_transfer_rows(scene, sensitivity)
    comparison = None
    if spec.measured:       # the user's measured run-up beside ours (housingfe.runup.measured)
        comparison = measured_comparison(spec, [r for _, res in results.values() for r in res.totals])
        notes += comparison["summary"]
    with outputs.atomic_output_dir(out, comm) as tmp:
        if comm.rank == 0:
            report.write(tmp, scene, results, gm, check_rows, contributions, timings, decompositions, notes,
                         bound, bound_checks, as_made, sensitivity, comparison)
            write_transmission_error(tmp / "transmission_error.csv", source, spec)
    if comm.rank == 0:
        print(report.summary_text(scene, results, gm, check_rows, timings, decompositions, notes, sensitivity))
        print(f"total wall time {time.perf_counter() - t_start:.1f} s; results: {out}/")
    return out


def measured_comparison(spec: RunupSpec, totals: list[dict]) -> dict:
    """The run's totals (runup.csv rows) beside the measured run-up of spec.measured (housingfe.runup.measured):
    {"measured": MeasuredRunup, "rows": compare's rows, "statistics": per series, "outside": measured points outside
    the run's speeds, "summary": the summary's lines (first radiation model)}."""
    from housingfe.runup import measured

    data = measured.read(spec.measured)
    rows, outside = measured.compare(data, totals, spec.torques_nm)
    stats = measured.statistics(rows)
    radiation = totals[0]["radiation"] if totals else ""
    return {"measured": data, "rows": rows, "statistics": stats, "outside": outside,
            "summary": measured.summary_lines(data, stats, outside, radiation)}


def write_transmission_error(path: Path, source, spec: RunupSpec) -> None:
    """The quasi-static transmission error the run's source had at each torque, harmonics 1..spec.harmonics, in the
    format runup.transmission_error reads (housingfe.source.transmission_error): the model's, or the file's."""
    from housingfe.source.transmission_error import write

    what = (f"the file {spec.transmission_error}" if spec.transmission_error else
            f"the engagement model {spec.engagement!r} on the model's mesh stiffness")
    count = spec.harmonics
    write(path, spec.torques_nm, range(1, count + 1),
          [source.quasi_static_transmission_error(t, count) for t in spec.torques_nm],
          comment=f"quasi-static transmission error of the run-up's source: {what}\n"
                  "e = d_qs - mean d_qs, d_qs = (F - F_e) / S(t); t = 0 at the mesh position T1 (docs/source.md)")


def _source(drivetrain, spec: RunupSpec, misalignment):
    """The lumped source of a run-up's reference drivetrain: `misalignment` a lead-gap law [m/m] of the torque, or
    "rigid-bores" (its law on the drivetrain's rigid bores), or "none"."""
    if misalignment == "rigid-bores":
        from housingfe.drivetrain.misalignment import lead_gap_law

        misalignment = lead_gap_law(drivetrain, "rigid-bores")
    te = None
    if spec.transmission_error:
        from housingfe.source.transmission_error import read

        te = read(spec.transmission_error)
    return drivetrain.source_model(harmonics=spec.harmonics, engagement=spec.engagement, misalignment=misalignment,
                                   transmission_error=te)


def matched_drivetrains(ref: HousingRef, model, drivetrains: dict, path) -> tuple[dict, list[dict]]:
    """The drivetrains (per torque) with their bearings on the housing model's bores as `ref` matches them
    (housingfe.drivetrain.bore_matching.match_bores; InputError "<path>: housing.bores...: ..."), and a report row
    per bearing (matched_bores_summary)."""
    from housingfe.drivetrain.bore_matching import match_bores, matched_bores_summary

    first = next(iter(drivetrains.values()))
    try:
        surfaces = match_bores(model, first, ref.bores, ref.match, ref.bore_tolerance)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None
    return ({t: dt.with_bores(surfaces) for t, dt in drivetrains.items()},
            matched_bores_summary(model, surfaces))


def housing_model_for(housing_scene, f_lines_max: float, comm):
    """The housing FE model, meshed for the highest line of the run-up (the scene's mesh rule at f_lines_max)."""
    from housingfe.fe.model import build_model

    model = build_model(housing_scene.geometry, housing_scene.material.resolve(), housing_scene.mesh, f_lines_max,
                        comm, regions=housing_scene.regions, supports=housing_scene.supports)
    model.scene = housing_scene
    return model


def radiators_of(spec: RunupRadiation, model) -> dict:
    """{name: Radiator} of a run-up scene's [radiation] on a housing model (its mesh and material)."""
    from housingfe.radiation.radiators import RADIATORS

    return {name: RADIATORS[name].from_spec(spec, model.housing, model.material) for name in spec.models}
