"""One description of a gearbox's drivetrain, and its two reductions.

A `Drivetrain` holds what the gearbox interior IS (SI units throughout): the gear set (a GearPair of
housingfe.source.gears with its flank corrections: masses, inertias, base circles and helix follow from it), the two
shafts (diameter, where they end, where the gear centre sits in the housing frame), the bearings (designation, or a
6-diagonal, or a full 6x6 K and C; position along the shaft; which housing bore carries them), the quill shafts and
couplings to the motor and the brake (Appendix C's shafts 1-4 and DOFs 13, 14), and the pinion torque of the
operating point (it sets the bearing loads and the mean mesh stiffness).

Two reductions of it:

* `to_lumped()` -> (LumpedInterior, ShaftGeometry, MeshModel): van Roosmalen's 14-DOF source model on RIGID bores
  (housingfe.source.roosmalen.dynamics), what `housingfe source gearset-*` and `housingfe.source.roosmalen.operating.SourceModel` use;
* `to_coupling_spec()` -> CouplingSpec: the FE interior (Timoshenko shafts, rigid gear discs, 6x6 bearings at the
  housing's bores, the gear mesh) that housingfe.drivetrain.interior couples with the housing model.

Where the thesis' two models genuinely differ, the description keeps both as named choices of each reduction
(docs/drivetrain.md says which scene uses which, and why):

* bearing stiffness: `lumped_bearing_stiffness` ("appendix_c": the printed diagonal of Appendix C, the only bearing
  numbers of the source model that survived) vs the bearings' own 6x6 matrices (Lim's model of the designation at
  the load of the operating point) in the FE reduction;
* bearing positions: `lumped_bearing_spans` (bearing to gear FACE, Fig. 2.6 of the source model: 60 mm assumed,
  i.e. 93 / 91 mm from the gear centre) vs `BearingSeat.position` (mid bearing plate of the reconstructed housing,
  107.5 mm, measured on the mesh) in the FE reduction;
* quill shafts and couplings: the same drive line in both (`drive_line_parts`: per shaft the near quill, the coupling's
  polar inertia, the far quill to ground; torsion only), in the FE reduction from the shaft's front end node (the
  shafts end flush with the bearing plates, `ShaftLine.ends`) when `drive_line` = "quill-shafts"; with "none" (the
  description's default, what the housing-side studies and scenes were built with) the FE shafts end there without
  it and the FE gear train has a free rigid rotation (one zero mode).  With "back-to-back" (FE reduction only) the
  far quills do not end at ground but close the rig's loop through the auxiliary gearbox (`AuxGearbox`,
  `aux_gearbox_parts`): its gear pair imposes the ratio, the motor sits on its pinion shaft, the motor's
  electromagnetic stiffness holds the loop's rigid rotation.  The lumped source keeps Appendix C's grounded ends
  (the thesis' model: DOF 15 held to apply the preload), whatever `drive_line` says.

The layer contract puts housingfe.source below housingfe.drivetrain: the interior takes its gears, tooth forces and
mesh stiffness from the source, never the other way round.
"""
from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np

from housingfe.errors import InputError
from housingfe.solvers.blas import single_thread_blas
from housingfe.source.gears import GearPair
from housingfe.source.roosmalen import dynamics as dyn
from housingfe.source.stiffness import (
    Corrections,
    MeshModel,
    ShaftBending,
    normal_force_from_torque,
    stiffness_curve,
)

Vector3 = tuple[float, float, float]
SHAFTS = ("pinion", "wheel")
# the FE reduction's drive line beyond the shaft ends (Drivetrain.drive_line): "quill-shafts" = the lumped model's
# quill shafts and couplings (Appendix C shafts 1-4, DOFs 13, 14), far ends grounded; "none" = shafts ending at the
# bearing plates; "back-to-back" = the same quills and couplings, their far ends on the auxiliary gearbox, which
# closes the rig's loop (Sec. 5.2, Fig. 5.1; `AuxGearbox`)
DRIVE_LINES = ("quill-shafts", "none", "back-to-back")
# The auxiliary gearbox (Sec. 5.2: "the same transmission gear ratio of 3.0 but with different tooth numbers", 19/57
# against the test set's 24/72).  The thesis gives no masses or inertias of it, nor of the motor; the numbers below are
# ASSUMPTIONS (docs/drivetrain.md, "The back-to-back loop"):
# * its gears: the test gearbox's gear bodies (solid cylinders, `GearSet.gear_body`) scaled by the tooth numbers at the
#   same module and face width, i.e. polar inertia x (19/24)^4 = (57/72)^4 = 0.393 (`scaled_aux_gearbox`); its shafts
#   are left out (a Ø80 mm shaft between the bearings is ~0.009 kg m^2 at the pinion, <5 % of what sits there);
AUX_TEETH = (19, 57)
# * the motor's rotor on the aux pinion shaft (the thesis: 20 kW, frequency-controlled, 0-1500 rev/min, i.e. a 4-pole
#   induction motor): 0.15 kg m^2, within the 0.13-0.19 kg m^2 that IEC frame 180 M/L 4-pole 18.5/22 kW catalogue motors
#   list (remembered catalogue range, not one verified data sheet); the torque coupling's flanges near the aux gearbox
#   are not added (unknown; inside the x0.5..x2 sensitivity of docs/drivetrain.md);
MOTOR_ROTOR_INERTIA = 0.15
# * the loop's rigid rotation (the whole rig turning) is held by the motor alone.  A frequency-controlled induction
#   motor pulls its rotor towards the rotating field: at frequencies above its rotor time constant (~0.1-0.3 s at
#   20 kW) the small-signal torque per mechanical angle is of the order of pole pairs x pull-out torque
#   = 2 x 2.5 x T_rated, T_rated = 20 kW / (1500 rev/min) = 127 N m: ~640 N m/rad (an order of magnitude, not the
#   drive's measured characteristic).  A torsion spring of that stiffness from the aux pinion (motor) to ground:
#   the rig's rigid rotation becomes a ~7 Hz mode, below every tooth frequency of the run-up (20 Hz at 50 rev/min)
#   and far below the loop's elastic modes; it restrains nothing else.
MOTOR_POLE_PAIRS = 2
MOTOR_RATED_POWER = 20e3           # W (Sec. 5.2)
MOTOR_SPEED_RPM = 1500.0           # rev/min, the top of the drive's range (Sec. 5.2)
MOTOR_PULLOUT_RATIO = 2.5          # pull-out / rated torque of a standard cage motor (assumed)
MOTOR_STIFFNESS = MOTOR_POLE_PAIRS * MOTOR_PULLOUT_RATIO * MOTOR_RATED_POWER / (MOTOR_SPEED_RPM * math.pi / 30)
# the FE shaft node the drive line leaves from: the front end (node 0).  Fig. 5.1: both quill shafts leave the test
# gearbox on the side of the auxiliary gearbox; which plate that is was not recoverable (assumed).  Torsion only,
# so the side changes only the 140 mm of shaft between gear and end (~2e6 N m/rad, 20x the quills)
DRIVE_LINE_NODE = 0
# the sliding-friction resultants (housingfe.source.stiffness.FRICTION_RESULTANTS) -> their unit loads on the coupled
# model (Drivetrain.friction_node_loads; housingfe.runup.chain.unit_loads with friction on)
FRICTION_LOADS = {"force": "friction_force", "pinion_torque": "friction_pinion_torque",
                  "wheel_torque": "friction_wheel_torque", "tilt_moment": "friction_tilt"}
_GEAR_FORCES: dict = {}        # Drivetrain.gear_forces per what it depends on (repr)
# Drivetrain.floating_axial_ratio: the mean axial load a floating bearing's outer ring keeps when it sticks in its bore,
# as a fraction of its radial load.  Sticking bounds it by the ring's friction in the bore, |F_a| <= mu F_r; a greased
# steel ring in a cast iron / steel bore has mu = 0.13-0.21 (benchmarks/experiments/floating_axial), dry cast iron on
# steel 0.23 sliding / 0.4 static.  0.3 lies above every lubricated value: a larger ratio is no friction-held load of a
# floating ring (it would be a second locating bearing), so it is refused.
FLOATING_AXIAL_LIMIT = 0.3
FLOATING_AXIAL_KEY = "drivetrain.floating_axial_ratio"
# The held load's bisection tolerance (N) where a floating ring slides (Drivetrain._held_by_locating): well below the
# held loads (0.06-0.3 of radial loads of kN) and the mesh's axial force; its results are remembered per load (and
# estimated bearing internals in effect).
SLIDE_TOLERANCE = 1.0
_SLIDE: dict = {}


# ------------------------------------------------------------------------------------------------ parts
@dataclass(frozen=True)
class GearSet:
    """The gear pair with its flank corrections and the settings of its mesh-stiffness model (housingfe.source):
    n_slices points per contact line, torque_configuration of Fig. 2.7.  `name` labels it (e.g. "gearset-A")."""

    name: str
    pair: GearPair
    corrections: Corrections = field(default_factory=Corrections)
    n_slices: int = 24
    torque_configuration: int = 2

    @classmethod
    def from_scene(cls, scene: str) -> "GearSet":
        """The gear set of a source scene (a built-in name such as "gearset-A", or a path to a TOML file)."""
        from housingfe.scenefile import read_scene_dict
        from housingfe.source.roosmalen import run as roosmalen

        data, path = read_scene_dict(scene)
        table = roosmalen.parse(data, str(path))
        pair, corr, _, _, model = roosmalen.build(table, str(path))
        return cls(data.get("scene", {}).get("name", str(scene)), pair, corr, model.n_slices,
                   model.torque_configuration)

    def gear_body(self, gear: int) -> tuple[float, float, float]:
        """(outer diameter, axial width, mass-equivalent) of gear 0 (pinion) / 1 (wheel) as a solid cylinder: the
        mean of tip and root diameter over its face width (both helices and the gap of a double helical gear), m."""
        p = self.pair
        width = p.face_width[gear] * (2 if p.kind == "double_helical" else 1) + (
            p.helix_gap if p.kind == "double_helical" else 0.0)
        return 0.5 * float(p.tip_diameter[gear] + p.root_diameter[gear]), width, p.density


@dataclass(frozen=True)
class ShaftLine:
    """A gear shaft: solid `diameter` (m) between its ends, the gear centre at `centre` (m, housing frame), the
    shaft along the unit `axis`; `ends` (m) are the shaft ends along the axis from the gear centre (the FE shaft)."""

    name: Literal["pinion", "wheel"]
    diameter: float
    centre: Vector3
    axis: Vector3
    ends: tuple[float, float]

    def point(self, s: float) -> np.ndarray:
        """Position (m) of the point `s` (m) along the axis from the gear centre."""
        a = np.asarray(self.axis, float) / np.linalg.norm(self.axis)
        return np.asarray(self.centre, float) + s * a


@dataclass(frozen=True)
class BearingSeat:
    """A bearing of the FE reduction: on shaft `shaft` at `position` (m along its axis from the gear centre), in
    the housing bore surface `bore`.  One of designation (catalogue; its load follows from the gear forces at the
    drivetrain's torque), stiffness (6-diagonal, N/m, N m/rad) or stiffness_matrix (6x6, with optional
    damping_matrix, N s/m).  `locating`: takes the shaft's axial force."""

    name: str
    shaft: Literal["pinion", "wheel"]
    position: float
    bore: str
    locating: bool = False
    designation: str | None = None
    model: str | None = None
    stiffness: tuple[float, ...] | None = None
    stiffness_matrix: tuple[tuple[float, ...], ...] | None = None
    damping_matrix: tuple[tuple[float, ...], ...] | None = None


@dataclass(frozen=True)
class QuillShaft:
    """A torsion shaft outside the gearbox (Appendix C, shafts 1-4): solid, diameter and length (m)."""

    name: str
    diameter: float
    length: float

    def stiffness(self, shear_modulus: float) -> float:
        """Torsional stiffness pi G d^4 / (32 l) [N m/rad]."""
        return math.pi * shear_modulus * self.diameter**4 / (32 * self.length)


@dataclass(frozen=True)
class Coupling:
    """A coupling between two quill shafts (Appendix C DOFs 13 and 14): its polar inertia (kg m^2)."""

    name: str
    inertia: float


@dataclass(frozen=True)
class GearForces:
    """Mean gear force on the pinion (N, housing frame) at the mesh `point` (m); mean mesh stiffness (N/m) along
    the unit contact normal `direction`; `resultant` [-]: the length of the resultant of a unit normal mesh force
    (1; cos(beta_b) for a double helical set, whose halves' normals cos(beta_b) l +- sin(beta_b) a add up to
    cos(beta_b) l: `direction` is then the transverse line of action l, `stiffness` the normal stiffness S times
    cos^2(beta_b) and the force T1 / r_b1 along it; docs/drivetrain.md)."""

    force_on_pinion: np.ndarray
    stiffness: float
    direction: np.ndarray
    point: np.ndarray
    resultant: float = 1.0


@dataclass(frozen=True)
class AuxGearbox:
    """The auxiliary gearbox of a back-to-back rig with the drive motor (Sec. 5.2, Fig. 5.1): tooth numbers
    (pinion, wheel), polar inertias (kg m^2) of its pinion and wheel (each with what turns rigidly with it), the motor
    rotor's polar inertia on the pinion shaft (kg m^2), and motor_stiffness (N m/rad), the torsion spring from the
    motor to ground that stands for the motor's hold on the loop's rigid rotation (0: the rotation is free).  Its gears
    are rigid: the pair imposes the ratio, aux wheel angle = -aux pinion angle / ratio, the same sense as the test
    pair (so the loop through both pairs closes).  Numbers: `scaled_aux_gearbox` and the constants above."""

    teeth: tuple[int, int]
    pinion_inertia: float
    wheel_inertia: float
    motor_inertia: float = MOTOR_ROTOR_INERTIA
    motor_stiffness: float = MOTOR_STIFFNESS

    def __post_init__(self):
        if not (len(self.teeth) == 2 and all(int(z) == z and z > 0 for z in self.teeth)):
            raise InputError(f"aux_gearbox: teeth: {self.teeth!r} must be two positive integers")
        for key in ("pinion_inertia", "wheel_inertia", "motor_inertia"):
            value = getattr(self, key)
            if not (math.isfinite(value) and value > 0):
                raise InputError(f"aux_gearbox: {key}: {value} kg m^2 must be finite and > 0")
        if not (math.isfinite(self.motor_stiffness) and self.motor_stiffness >= 0):
            raise InputError(f"aux_gearbox: motor_stiffness: {self.motor_stiffness} N m/rad must be finite and >= 0")

    @property
    def ratio(self) -> float:
        """z_wheel / z_pinion."""
        return self.teeth[1] / self.teeth[0]

    def inertia_at_pinion(self) -> float:
        """Polar inertia (kg m^2) of the gearbox and motor about the aux pinion's angle: pinion + motor + wheel /
        ratio^2 (rigid gears)."""
        return self.pinion_inertia + self.motor_inertia + self.wheel_inertia / self.ratio**2


def scaled_aux_gearbox(gears: GearSet, teeth: tuple[int, int] = AUX_TEETH, motor_inertia: float = MOTOR_ROTOR_INERTIA,
                       motor_stiffness: float = MOTOR_STIFFNESS) -> AuxGearbox:
    """The auxiliary gearbox as the test gears scaled by the tooth numbers at the same module and face width (an
    ASSUMPTION, see AUX_TEETH): each gear body a solid cylinder (`GearSet.gear_body`) whose diameter scales with
    z_aux / z_test, polar inertia x (z_aux / z_test)^4."""
    pair = gears.pair
    inertia = []
    for g in (0, 1):
        d, width, rho = gears.gear_body(g)
        d_aux = d * teeth[g] / pair.teeth[g]
        inertia.append(rho * math.pi * d_aux**4 * width / 32)
    return AuxGearbox(tuple(int(z) for z in teeth), inertia[0], inertia[1], motor_inertia, motor_stiffness)


# ------------------------------------------------------------------------------------------- description
@dataclass(frozen=True)
class Drivetrain:
    """The drivetrain of a gearbox (see the module docstring).  torque: pinion torque (N m) of the operating point;
    loss_factor: of the lumped model's modal damping (Sec. 2.5).

    Reduction choices: lumped_bearing_stiffness ("appendix_c" or {"pinion": 5 values, "wheel": 5 values}, x, y, z
    [N/m], theta_x, theta_y [N m/rad]); lumped_bearing_spans {"pinion": (front, back), "wheel": ...} bearing to
    gear face (m); coupling_mesh_positions: mesh positions per pitch for the FE's mean mesh stiffness;
    elements_per_segment of the FE shafts; hold_tilt: the FE bearings' tilt held at zero by the shaft.
    bearing_configuration: a configuration of housingfe.bearings.configurations ("angular_contact",
    "self_aligning", "tapered_roller", "cylindrical_roller", "fluid_film") whose 6x6 K (and C) replace the seats'
    own bearings in the FE reduction, at the statics loads of `torque` and, for the speed-dependent fluid film, the
    pinion speed bearing_speed_rpm (rev/min; the wheel turns the other way at z1/z2 of it); None: the seats' own
    designations / matrices.  drive_line (DRIVE_LINES): the FE reduction's drive line beyond the shaft ends,
    "quill-shafts" (`drive_line_parts`, the lumped model's, far ends grounded), "none", or "back-to-back" (the same
    quills, their far ends closing the loop through `aux_gearbox`, `aux_gearbox_parts`).  aux_gearbox: the rig's
    auxiliary gearbox and motor (AuxGearbox; needed by "back-to-back" only).
    floating_axial_ratio: the mean axial load of each shaft's floating bearing as a fraction of its own radial
    load, F_a = ratio |F_r| (|ratio| <= FLOATING_AXIAL_LIMIT; 0: the floating bearings take no axial load), > 0 when
    the shaft pushes the floating bearing away from the shaft's locating bearing (a shaft warmer than its housing,
    grown longer while the outer ring sticks in its bore), < 0 towards it; the locating bearing takes the reaction
    (`bearing_loads`).  It acts wherever the bearing loads do: the FE bearings' 6x6 matrices (designation and
    configuration) and so the coupled model and the rigid-bores misalignment; the lumped source's bearings are
    Appendix C's printed diagonal, which no load changes."""

    gears: GearSet
    shafts: tuple[ShaftLine, ShaftLine]
    bearings: tuple[BearingSeat, ...]
    quill_shafts: tuple[QuillShaft, QuillShaft, QuillShaft, QuillShaft]
    couplings: tuple[Coupling, Coupling]
    torque: float = 2000.0
    loss_factor: float = 0.1
    lumped_bearing_stiffness: str | dict = "appendix_c"
    lumped_bearing_spans: dict = field(default_factory=lambda: {"pinion": (0.06, 0.06), "wheel": (0.06, 0.06)})
    coupling_mesh_positions: int = 16
    elements_per_segment: int = 4
    hold_tilt: bool = True
    bearing_configuration: str | None = None
    bearing_speed_rpm: float = 1500.0
    drive_line: str = "none"
    aux_gearbox: AuxGearbox | None = None
    floating_axial_ratio: float = 0.0

    def __post_init__(self):
        r = self.floating_axial_ratio
        if not (isinstance(r, (int, float)) and math.isfinite(r) and abs(r) <= FLOATING_AXIAL_LIMIT):
            raise InputError(f"{FLOATING_AXIAL_KEY}: {r!r}: must be a number within +-{FLOATING_AXIAL_LIMIT:g} (a "
                             "floating ring held by its friction in the bore, mu <= 0.21 greased)")
        if self.drive_line not in DRIVE_LINES:
            raise InputError(f"drive_line: {self.drive_line!r} is not one of {', '.join(DRIVE_LINES)}")
        if self.drive_line == "back-to-back" and self.aux_gearbox is None:
            raise InputError("drive_line: 'back-to-back' needs the rig's auxiliary gearbox (Drivetrain.aux_gearbox), "
                             "this drivetrain has none")
        if [s.name for s in self.shafts] != list(SHAFTS):
            raise InputError("drivetrain: shafts: need (pinion, wheel)")
        if not (math.isfinite(self.torque) and self.torque > 0):
            raise InputError(f"drivetrain: torque: {self.torque} N m must be finite and > 0")
        for b in self.bearings:
            if sum(x is not None for x in (b.designation, b.stiffness, b.stiffness_matrix)) != 1:
                raise InputError(f"drivetrain: bearings: {b.name}: give one of designation, stiffness, "
                                 "stiffness_matrix")
            lo, hi = self.shaft(b.shaft).ends
            if not lo < b.position < hi:
                raise InputError(f"drivetrain: bearings: {b.name}: position {b.position} m is off the shaft "
                                 f"({lo}..{hi} m)")

    def shaft(self, name: str) -> ShaftLine:
        return self.shafts[SHAFTS.index(name)]

    def with_bores(self, surfaces: dict[str, str]) -> "Drivetrain":
        """The same drivetrain with its bearings' housing bores renamed: {bearing name: housing surface group}
        (housingfe.drivetrain.bore_matching.match_bores); bearings not named keep theirs."""
        return replace(self, bearings=tuple(replace(b, bore=surfaces.get(b.name, b.bore)) for b in self.bearings))

    # ---------------------------------------------------------------------------------- gear properties
    def gear_inertia(self, gear: int) -> tuple[float, float, float]:
        """Mass (kg), polar and diametral inertia (kg m^2, about the gear centre) of the gear body alone (solid
        cylinder of `GearSet.gear_body`, no shaft, no bore)."""
        d, width, rho = self.gears.gear_body(gear)
        return dyn._cylinder(rho, d, width)

    # ---------------------------------------------------------------------------------- lumped reduction
    def lumped_bearings(self) -> dict:
        """{"pinion": 5 values, "wheel": 5 values}: the bearing diagonal of the lumped model."""
        if self.lumped_bearing_stiffness == "appendix_c":
            return {k: tuple(v) for k, v in dyn.APPENDIX_C_BEARINGS.items()}
        if isinstance(self.lumped_bearing_stiffness, dict):
            return {k: tuple(self.lumped_bearing_stiffness[k]) for k in SHAFTS}
        raise InputError(f"drivetrain: lumped_bearing_stiffness: {self.lumped_bearing_stiffness!r} (known: "
                         "'appendix_c' or a dict of diagonals)")

    def shaft_geometry(self) -> dyn.ShaftGeometry:
        """The ShaftGeometry of the lumped model."""
        spans = self.lumped_bearing_spans
        return dyn.ShaftGeometry(
            pinion_spans=tuple(spans["pinion"]), pinion_shaft_diameter=self.shaft("pinion").diameter,
            wheel_spans=tuple(spans["wheel"]), wheel_shaft_diameter=self.shaft("wheel").diameter,
            torsion_diameters=tuple(q.diameter for q in self.quill_shafts),
            torsion_lengths=tuple(q.length for q in self.quill_shafts),
            coupling_inertia=tuple(c.inertia for c in self.couplings))

    def to_lumped(self) -> tuple[dyn.LumpedInterior, dyn.ShaftGeometry, MeshModel]:
        """The lumped source model on rigid bores: (LumpedInterior, ShaftGeometry, MeshModel).  Masses and
        inertias: gear body + its shaft between the bearings (housingfe.source.roosmalen.dynamics.derive_interior)."""
        geometry = self.shaft_geometry()
        interior = dyn.derive_interior(self.gears.pair, geometry, self.loss_factor, self.lumped_bearings())
        model = MeshModel(self.gears.pair,
                          shafts=(ShaftBending(*geometry.pinion_spans, geometry.pinion_shaft_diameter),
                                  ShaftBending(*geometry.wheel_spans, geometry.wheel_shaft_diameter)),
                          corrections=self.gears.corrections, n_slices=self.gears.n_slices,
                          torque_configuration=self.gears.torque_configuration)
        return interior, geometry, model

    def source_model(self, misalignment="none", **kwargs):
        """housingfe.source.roosmalen.operating.SourceModel of the lumped reduction (kwargs: its options).  misalignment:
        "none", "lumped" (the 14-DOF model's own static tilt) or a function torque [N m] -> MeshModel.lead_gap [m/m],
        e.g. housingfe.drivetrain.misalignment.lead_gap_law(drivetrain, "rigid-bores")."""
        from housingfe.source.roosmalen.operating import SourceModel

        interior, geometry, model = self.to_lumped()
        return SourceModel(self.gears.pair, self.gears.corrections, interior, geometry, mesh_model=model,
                           misalignment=misalignment, **kwargs)

    def drive_line_parts(self) -> dict:
        """{"pinion" | "wheel": (near quill k [N m/rad], coupling polar inertia [kg m^2], far quill k [N m/rad])}:
        the drive line of each shaft in the lumped model's topology (housingfe.source.roosmalen.dynamics.assemble:
        pinion -shaft 2- coupling DOF 13 -shaft 1- held far end; wheel -shaft 3- coupling DOF 14 -shaft 4-
        ground), k = pi G d^4 / (32 l) with the gear material's G = E / (2 (1 + nu)) as `derive_interior` takes it.
        Both reductions take these numbers."""
        p = self.gears.pair
        G = p.youngs_modulus / (2 * (1 + p.poisson_ratio))
        k = [q.stiffness(G) for q in self.quill_shafts]          # shafts 1, 2, 3, 4
        return {"pinion": (k[1], self.couplings[0].inertia, k[0]),
                "wheel": (k[2], self.couplings[1].inertia, k[3])}

    def aux_gearbox_parts(self) -> dict:
        """The back-to-back loop's auxiliary gearbox as the FE reduction takes it: {"inertia": polar inertia at the
        aux pinion's angle phi [kg m^2] (`AuxGearbox.inertia_at_pinion`), "ratio": z_wheel / z_pinion,
        "ground_stiffness": the motor's torsion spring to ground on phi [N m/rad]}.  The pinion line's far quill
        (shaft 1) ends on the aux pinion (angle phi), the wheel line's (shaft 4) on the aux wheel (angle
        -phi / ratio)."""
        aux = self.aux_gearbox
        if aux is None:
            raise InputError("drive_line: 'back-to-back' needs the rig's auxiliary gearbox (Drivetrain.aux_gearbox)")
        return {"inertia": aux.inertia_at_pinion(), "ratio": aux.ratio, "ground_stiffness": aux.motor_stiffness}

    # ------------------------------------------------------------------------- lumped <-> housing frames
    def lumped_frame(self) -> np.ndarray:
        """3x3, columns = the lumped model's x, y, z in the housing frame: x along the centre line (pinion to
        wheel), z along the shaft axis, y = z cross x (housingfe.source.roosmalen.dynamics.mesh_direction)."""
        p, w = self.shaft("pinion"), self.shaft("wheel")
        a = np.asarray(p.axis, float) / np.linalg.norm(p.axis)
        c = np.asarray(w.centre, float) - np.asarray(p.centre, float)
        e_c = c - (c @ a) * a
        e_c /= np.linalg.norm(e_c)
        return np.column_stack([e_c, np.cross(a, e_c), a])

    def lumped_to_housing(self, values: np.ndarray) -> np.ndarray:
        """Forces and moments (or displacements and rotations) of the lumped model, (6, ...) = (x, y, z, theta_x,
        theta_y, theta_z) in its frame, as (6, ...) in the housing frame.

        The two reductions have opposite helix hands: the lumped mesh normal has the axial component
        -sin(beta_b) (dynamics.mesh_direction), the FE one +sin(beta_b) (`gear_forces`); Appendix F does not give
        the hand and each model is mirror-symmetric, so each is computed as it was, and vectors passed from the
        lumped model to the housing are mirrored z -> -z first: vectors (x, y, -z), pseudo-vectors (-x, -y, z)."""
        v = np.asarray(values)
        R = self.lumped_frame()
        f = np.tensordot(R * np.array([1.0, 1.0, -1.0]), v[:3], axes=1)
        m = np.tensordot(R * np.array([-1.0, -1.0, 1.0]), v[3:6], axes=1)
        return np.concatenate([f, m])

    def lumped_bearing_position(self, shaft: str, z: float) -> np.ndarray:
        """Housing position (m) of a point at lumped axial coordinate z (m, BearingSpectra.z) on a shaft
        (mirrored like `lumped_to_housing`)."""
        return self.shaft(shaft).point(-z)

    # -------------------------------------------------------------------------------------- FE reduction
    def mesh_node_loads(self, force: complex = 1.0, forces: GearForces | None = None) -> dict:
        """{gear node of the FE reduction: (6,) load [N, N m] in the housing frame} of a mesh force `force` (N,
        positive = compression, e.g. Excitation.mesh_force[n]) along the FE contact normal at the contact point:
        -force n on the pinion, +force n on the wheel, with their moments about the gear centres (the loads the
        gear-mesh element of the coupled model carries).  `force` is the NORMAL mesh force (of both helices of a
        double helical set), n its resultant per unit (GearForces.resultant: cos(beta_b) l for double helical)."""
        forces = forces or self.gear_forces()
        n = forces.direction * forces.resultant
        out = {}
        for name, sign in (("pinion", -1.0), ("wheel", 1.0)):
            node = f"{name}:{self.shaft_nodes(name)[1]['gear']}"
            f = sign * force * n
            arm = forces.point - np.asarray(self.shaft(name).centre, float)
            out[node] = np.concatenate([f, np.cross(arm, n) * sign * force])
        return out

    def mesh_face_direction(self) -> np.ndarray:
        """Unit vector (housing frame) along which the mesh model's axial position w grows (MeshModel w: from its
        face w = 0 over the gear; housingfe.source.stiffness).

        The hand comes from the FE contact normal (`gear_forces`): n = cos(beta_b) d + sin(beta_b) a, with d along
        the transverse line of action in the direction of growing s (from T1 to T2: the force on the wheel, pinion
        driving) and a the pinion's shaft axis.  A contact line lies on the flank, so it is normal to n; in the
        MeshModel it runs s = s0 + w tan(beta_b), i.e. along tan(beta_b) d + (dw/da) a, and normal to n only with
        dw/da = -1: w grows along -a, the MeshModel's face w = 0 sits at the +a end of the gear.  For a spur or a
        double helical set (whose FE normal has no axial part) the same -a is a convention: a spur pair's centre
        does not move axially, a symmetric double helical pair's halves move it in opposite senses."""
        a = np.asarray(self.shaft("pinion").axis, float)
        return -a / np.linalg.norm(a)

    def shuttle_node_loads(self, moment: complex = 1.0, forces: GearForces | None = None) -> dict:
        """{gear node: (6,) load [N, N m]} of the mesh force's contact point moved along the gear axis: the
        `moment` [N m] = F dw of a normal mesh force F [N] whose point moves by dw [m] along `mesh_face_direction`
        (w grows): the forces do not change, the moments about the gear centres change by +/- F (dw e_w x n):
        +moment (e_w x n) on the wheel, -moment (e_w x n) on the pinion (as `mesh_node_loads`: +F n on the wheel).
        Self-equilibrated; |e_w x n| = cos(beta_b) (n: the resultant per unit normal force, as `mesh_node_loads`)."""
        forces = forces or self.gear_forces()
        m = np.cross(self.mesh_face_direction(), forces.direction * forces.resultant) * moment
        out = {}
        for name, sign in (("pinion", -1.0), ("wheel", 1.0)):
            node = f"{name}:{self.shaft_nodes(name)[1]['gear']}"
            out[node] = np.concatenate([np.zeros(3, dtype=np.result_type(m)), sign * m])
        return out

    def friction_directions(self, forces: GearForces | None = None) -> dict:
        """Housing-frame unit vectors of the sliding-friction resultants (housingfe.source.stiffness
        .friction_resultants): "d" the transverse line of action from T1 to T2 (the FE normal without its axial
        part), "e_f" from the pinion centre to T1 (normal to the plane of action, in the transverse plane), "e_1"
        = e_f x d the pinion's rotation vector (pinion driving; friction_resultants: e_f = d x e_1), "e_2" = -e_1
        the wheel's, "tilt" = e_w x e_f (e_w: `mesh_face_direction`)."""
        forces = forces or self.gear_forces()
        a = np.asarray(self.shaft("pinion").axis, float)
        a /= np.linalg.norm(a)
        n = forces.direction
        d = n - (n @ a) * a
        d /= np.linalg.norm(d)
        c = np.asarray(self.shaft("wheel").centre, float) - np.asarray(self.shaft("pinion").centre, float)
        c -= (c @ a) * a
        # centre to centre = (r_b1 + r_b2) e_f + T1T2 d: its part normal to d points along e_f
        e_f = c - (c @ d) * d
        e_f /= np.linalg.norm(e_f)
        e_1 = np.cross(e_f, d)
        return {"d": d, "e_f": e_f, "e_1": e_1, "e_2": -e_1, "tilt": np.cross(self.mesh_face_direction(), e_f)}

    def friction_node_loads(self, resultant: str, amount: complex = 1.0, forces: GearForces | None = None) -> dict:
        """{gear node: (6,) load [N, N m]} of one sliding-friction resultant (`FRICTION_LOADS`' keys, as
        housingfe.source.stiffness.friction_resultants returns them) of size `amount`: "force" [N] +e_f on the
        pinion and -e_f on the wheel (at the gear centres), "pinion_torque" [N m] about e_1 on the pinion,
        "wheel_torque" [N m] about e_2 on the wheel, "tilt_moment" [N m] +(e_w x e_f) on the pinion and the
        opposite on the wheel (`friction_directions`).  The force pair and the two torques are not
        self-equilibrated each; with the amounts of one load distribution they are (the torques carry the
        levers s and L - s of the force about the two centres, and the centres lie (r_b1 + r_b2) e_f + L d
        apart), the tilt pair is."""
        if resultant not in FRICTION_LOADS:
            raise InputError(f"mesh_friction: {resultant!r} is not one of {', '.join(FRICTION_LOADS)}")
        e = self.friction_directions(forces)
        z = np.zeros(3)
        pinion, wheel = {"force": ((e["e_f"], z), (-e["e_f"], z)), "pinion_torque": ((z, e["e_1"]), (z, z)),
                         "wheel_torque": ((z, z), (z, e["e_2"])),
                         "tilt_moment": ((z, e["tilt"]), (z, -e["tilt"]))}[resultant]
        return {f"{name}:{self.shaft_nodes(name)[1]['gear']}": np.concatenate(parts) * amount
                for name, parts in (("pinion", pinion), ("wheel", wheel))}

    def gear_forces(self) -> GearForces:
        """Mean tooth force and mean mesh stiffness at `torque`, placed in the housing: the line of action in the
        transverse plane at the operating pressure angle from the common tangent, tilted out of it by the base
        helix angle; a double helical set's halves cancel axially, so its direction is the transverse line of
        action, its stiffness S cos^2(beta_b) and its force T1 / r_b1 (GearForces.resultant = cos(beta_b), as the
        lumped model's housingfe.source.roosmalen.dynamics.mesh_direction); contact at the operating pitch
        point.  Remembered per gear set, shaft lines, lumped spans, torque and mesh positions (what it depends
        on; not the FE bearings, so another bearing configuration shares it): the mean mesh stiffness is a
        stiffness curve (0.2-0.8 s), and one run-up asks for it five times (coupling spec, unit loads,
        misalignment, re-analysis)."""
        key = repr((self.gears, self.shafts, self.lumped_bearing_spans, float(self.torque),
                    self.coupling_mesh_positions))
        cached = _GEAR_FORCES.get(key)
        if cached is None:
            with single_thread_blas():
                cached = self._gear_forces()
            if len(_GEAR_FORCES) >= 64:             # studies make many drivetrains: keep the newest
                _GEAR_FORCES.pop(next(iter(_GEAR_FORCES)))
            _GEAR_FORCES[key] = cached
        return cached

    def _gear_forces(self) -> GearForces:
        pair = self.gears.pair
        lumped_model = self.to_lumped()[2]
        normal = normal_force_from_torque(pair, self.torque)
        stiffness = stiffness_curve(lumped_model, normal, self.coupling_mesh_positions).mean
        p, w = self.shaft("pinion"), self.shaft("wheel")
        n, resultant, e_c = mesh_line_of_action(pair, p.centre, w.centre, p.axis)
        stiffness *= resultant**2
        z1, z2 = pair.teeth
        point = np.asarray(p.centre, float) + pair.centre_distance * z1 / (z1 + z2) * e_c
        # the wheel pushes the pinion along -n
        arrays = [np.array(a, float) for a in (-normal * resultant * n, n, point)]
        for a in arrays:                    # shared by every caller (gear_forces remembers it): read-only
            a.setflags(write=False)
        return GearForces(arrays[0], stiffness, arrays[1], arrays[2], resultant)

    def bearing_loads(self, forces: GearForces | None = None) -> dict:
        """{bearing name: (Fx, Fy, Fz, Mx, My)} (N) in each bearing's frame (housingfe.drivetrain.coupling.axis_frame
        of the shaft axis): the mean gear force shared by the two bearings of each shaft by statics, the
        locating bearing taking all of the axial force -- with floating_axial_ratio != 0 less the floating
        bearing's ratio |F_r| (along the shaft from the locating towards the floating bearing for ratio > 0), so
        that each shaft's bearings still carry its mesh force's axial component between them.  A floating bearing
        that cannot carry an axial load with ratio != 0: InputError naming the key (`floating_axial_problem`).  Where
        that held load would leave a directional locating bearing (single-row angular contact, tapered roller)
        without an equilibrium, the ring slides and the held load is the largest the locating bearing still
        carries (`floating_axial_held` gives the requested and the effective one)."""
        return self._statics(forces)[0]

    def _statics(self, forces: GearForces | None = None) -> tuple[dict, dict]:
        """(bearing_loads, {shaft: (requested, effective) held axial load (N)}) -- see bearing_loads and
        floating_axial_held."""
        from housingfe.drivetrain.coupling import axis_frame

        problem = self.floating_axial_problem()
        if problem:
            raise InputError(problem)
        forces = forces or self.gear_forces()
        out, held_loads = {}, {s: (0.0, 0.0) for s in SHAFTS}
        for shaft, sign in (("pinion", 1.0), ("wheel", -1.0)):
            line = self.shaft(shaft)
            seats = [b for b in self.bearings if b.shaft == shaft]
            if len(seats) != 2 or sum(b.locating for b in seats) != 1:
                raise InputError(f"drivetrain: bearings: shaft {shaft} needs two bearings, one locating")
            front = next(b for b in seats if b.locating)
            back = next(b for b in seats if not b.locating)
            a = np.asarray(line.axis, float) / np.linalg.norm(line.axis)
            f = sign * forces.force_on_pinion
            axial = (f @ a) * a
            m = np.cross(forces.point - line.point(front.position), f)
            m -= (m @ a) * a
            r_back = np.cross(m, a) / (back.position - front.position)
            front_load, back_load = (f - axial) - r_back + axial, r_back
            if self.floating_axial_ratio != 0.0:       # the floating ring's friction-held axial load
                away = math.copysign(1.0, back.position - front.position)
                requested = self.floating_axial_ratio * float(np.linalg.norm(r_back))
                effective = self._held_by_locating(front, axis_frame(line.axis).T, front_load, a, requested * away)
                held = effective * a
                front_load, back_load = front_load - held, back_load + held
                held_loads[shaft] = (requested, effective * away)
            for seat, load in ((front, front_load), (back, back_load)):
                local = axis_frame(line.axis).T @ load
                out[seat.name] = (float(local[0]), float(local[1]), float(local[2]), 0.0, 0.0)
        return out, held_loads

    def _held_by_locating(self, front: BearingSeat, to_local: np.ndarray, front_load: np.ndarray, a: np.ndarray,
                          held: float) -> float:
        """The held axial load (N, along the shaft axis `a`) the floating ring keeps: `held` if the locating
        bearing of the configuration finds an equilibrium under front_load - held a, else the ring slides -- the
        largest |held| (same sign) at which it still does, by bisection on the bearing model itself
        (housingfe.bearings.configurations.carries) to SLIDE_TOLERANCE.  Without a configuration, or where the
        locating bearing carries no equilibrium even at held = 0: `held` unchanged (the bearing model names the
        load it cannot carry later, as without the ratio)."""
        if self.bearing_configuration is None:
            return held
        from housingfe.bearings.catalogue import internals_in_effect
        from housingfe.bearings.configurations import carries, configurations

        config = configurations().get(self.bearing_configuration)
        position = f"{front.shaft}_front"
        if config is None or not config.positions[position].directional:
            return held                         # a ball / self-aligning / roller locating bearing: either direction

        def ok(h: float) -> bool:
            local = to_local @ (front_load - h * a)
            return carries(self.bearing_configuration, position, (*local, 0.0, 0.0))

        # the estimated internals (an uncertainty sample's) move where the bearing lifts off: part of the key
        key = (self.bearing_configuration, position, tuple(np.round(front_load, 9)), tuple(np.round(a, 12)), held,
               internals_in_effect())
        if key in _SLIDE:
            return _SLIDE[key]
        if ok(held) or not ok(0.0):
            result = held
        else:
            lo, hi = 0.0, 1.0                   # fractions of the requested held load: lo carried, hi not
            while (hi - lo) * abs(held) > SLIDE_TOLERANCE:
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if ok(mid * held) else (lo, mid)
            result = lo * held
            # once per load (remembered below): the user sees that the ring slid, not only the statics' report
            print(f"housingfe: warning: {FLOATING_AXIAL_KEY} = {self.floating_axial_ratio:g}: the {front.shaft}'s "
                  f"floating ring slides: held load {abs(held):.0f} -> {abs(result):.0f} N, the most its locating "
                  f"bearing ({self.bearing_configuration}) carries (Drivetrain.floating_axial_held)", file=sys.stderr)
        if len(_SLIDE) >= 256:
            _SLIDE.pop(next(iter(_SLIDE)))
        _SLIDE[key] = result
        return result

    def floating_axial_held(self, forces: GearForces | None = None) -> dict[str, tuple[float, float]]:
        """{shaft: (requested, effective)} held axial load of each shaft's floating bearing (N, > 0 pushed away
        from the locating bearing): requested = floating_axial_ratio |F_r|; effective = what bearing_loads applies,
        of smaller magnitude where the locating bearing (a single-row angular contact or tapered roller bearing)
        would lift off under the requested one -- the shaft then moves axially and the floating ring slides in its
        bore until the locating bearing just holds (`_held_by_locating`).  Both 0.0 at ratio 0."""
        return self._statics(forces)[1]

    def floating_axial_report(self, forces: GearForces | None = None) -> dict[str, dict]:
        """What each shaft's floating bearing holds, for result files: {shaft: {"requested_N", "held_N" (N, signs of
        floating_axial_held), "slid" (the held load saturated below the requested one: `floating_axial_held`'s
        effective != requested)}}.  Empty at ratio 0 (nothing to report)."""
        if self.floating_axial_ratio == 0.0:
            return {}
        return {shaft: {"requested_N": requested, "held_N": effective, "slid": effective != requested}
                for shaft, (requested, effective) in self.floating_axial_held(forces).items()}

    def floating_axial_problem(self) -> str:
        """Why floating_axial_ratio cannot act on this drivetrain ("" when it can, or when it is 0): a floating
        bearing that carries no axial load in its model -- a fluid-film journal (no axial stiffness) or a
        cylindrical roller bearing (the roller-raceway contacts carry none; such a floating bearing lets the shaft
        slide inside it, so its ring keeps no friction-held axial load in the bore either)."""
        if self.floating_axial_ratio == 0.0:
            return ""
        kinds = {}
        if self.bearing_configuration is not None:
            from housingfe.bearings.configurations import configurations

            config = configurations().get(self.bearing_configuration)
            if config is not None:
                for b in self.bearings:
                    if not b.locating:
                        choice = config.positions[f"{b.shaft}_back"]
                        kinds[b.name] = ("fluid_film" if choice.kind == "fluid_film"
                                         else _catalogue_kind(choice.designation))
        else:
            for b in self.bearings:
                if not b.locating and b.designation is not None:
                    kinds[b.name] = _catalogue_kind(b.designation)
        bad = {n: k for n, k in kinds.items() if k in ("fluid_film", "cylindrical_roller")}
        if not bad:
            return ""
        what = ", ".join(f"{n} ({k.replace('_', ' ')})" for n, k in bad.items())
        return (f"{FLOATING_AXIAL_KEY}: {self.floating_axial_ratio:g}: the floating bearing(s) {what} of "
                f"bearings = {self.bearing_configuration or 'designations'!r} carry no axial load (a journal has no "
                "axial stiffness, a cylindrical roller bearing lets the shaft slide inside it); use 0")

    @property
    def speed_dependent_bearings(self) -> bool:
        """Whether the FE bearings' K, C depend on the shaft speed (a configuration with a fluid-film position:
        taken at bearing_speed_rpm); rolling-element bearings and the seats' own matrices do not."""
        if self.bearing_configuration is None:
            return False
        from housingfe.bearings.configurations import configurations

        config = configurations().get(self.bearing_configuration)
        return config is not None and any(c.kind == "fluid_film" for c in config.positions.values())

    def configuration_matrices(self, loads: dict | None = None) -> dict | None:
        """{seat name: (K 6x6, C 6x6 or None)} of `bearing_configuration` at the statics loads (None without a
        configuration).  Each shaft's locating seat gets the configuration's locating bearing (its *_front
        position), the other its floating one (`configuration_roles`); both locating bearings locate axially (a
        double helical wheel is otherwise axially free)."""
        if self.bearing_configuration is None:
            return None
        from housingfe.bearings.configurations import bearing_matrices, configurations

        if self.bearing_configuration not in configurations():
            raise InputError(f"drivetrain: bearings: {self.bearing_configuration!r} unknown (known: ball, "
                             f"{', '.join(configurations())})")
        loads = loads or self.bearing_loads()
        z1, z2 = self.gears.pair.teeth
        speeds = {"pinion": self.bearing_speed_rpm, "wheel": -self.bearing_speed_rpm * z1 / z2}
        # the configuration's positions are roles: <shaft>_front its locating model (taking Fz), <shaft>_back the
        # floating one; each seat gets the role of its `locating` flag (the identity with the front seats locating)
        role = self.configuration_roles()
        try:
            by_role = bearing_matrices(self.bearing_configuration, {role[n]: v for n, v in loads.items()}, speeds,
                                       axial_location="both", floating_axial=self.floating_axial_ratio != 0.0)
        except InputError as exc:
            held = ""
            if self.floating_axial_ratio != 0.0:    # the held load moved axial load off (or onto) the locating one
                held = (f" (with {FLOATING_AXIAL_KEY} = {self.floating_axial_ratio:g}: the locating bearings carry "
                        "the mesh's axial force less the floating bearings' held load)")
            raise InputError(f"drivetrain: bearings = {self.bearing_configuration!r} at {self.torque:g} N m{held}: "
                             f"{exc}") from None
        return {name: by_role[r] for name, r in role.items()}

    def configuration_roles(self) -> dict[str, str]:
        """{seat name: configuration position} -- the locating seat of each shaft gets "<shaft>_front" (the
        configuration's locating bearing), the floating one "<shaft>_back", whichever side of the gearbox they
        sit on (housingfe.bearings.configurations: "front" means "locating")."""
        return {b.name: f"{b.shaft}_{'front' if b.locating else 'back'}" for b in self.bearings}

    def shaft_nodes(self, name: str) -> tuple[list[list[float]], dict]:
        """FE segments [[length, diameter], ...] (m) of a shaft from its front end, split at its bearings and the
        gear centre, and {"gear" | bearing name: node index} (elements_per_segment elements per segment)."""
        line = self.shaft(name)
        stops = {"gear": 0.0, **{b.name: b.position for b in self.bearings if b.shaft == name}}
        cuts = sorted({line.ends[0], line.ends[1], *stops.values()})
        segments = [[hi - lo, line.diameter] for lo, hi in zip(cuts[:-1], cuts[1:])]
        nodes = {k: cuts.index(s) * self.elements_per_segment for k, s in stops.items()}
        return segments, nodes

    def to_coupling_spec(self, forces: GearForces | None = None):
        """The FE interior on the housing's bores (housingfe.drivetrain.interior.CouplingSpec): bore masters of
        kind rbe2 at the bearing bores, the two shafts with their gears as rigid discs bored to the shaft, the
        bearings (designation at the statics load, tilt held), the gear mesh (mean stiffness at `torque`), and with
        drive_line = "quill-shafts" the drive lines (`drive_line_parts` from each shaft's front end node to a
        coupling node "coupling_<motor|brake>" and on to ground; housingfe.drivetrain.interior.DriveLineSpec)."""
        from housingfe.drivetrain.interior import CouplingSpec

        forces = forces or self.gear_forces()
        loads = self.bearing_loads(forces)
        matrices = self.configuration_matrices(loads)
        shafts, bearings, nodes = [], [], {}
        for g, name in enumerate(SHAFTS):
            line = self.shaft(name)
            segments, index = self.shaft_nodes(name)
            nodes[name] = index
            d, width, _ = self.gears.gear_body(g)
            shafts.append({"name": name, "origin": tuple(float(x) for x in line.point(line.ends[0])),
                           "axis": line.axis, "segments": segments, "elements_per_segment": self.elements_per_segment,
                           "discs": [{"node": index["gear"], "outer_diameter": d, "width": width,
                                      "inner_diameter": line.diameter}]})
        for b in sorted(self.bearings, key=lambda b: (SHAFTS.index(b.shaft), b.position)):
            entry = {"name": b.name, "shaft_node": f"{b.shaft}:{nodes[b.shaft][b.name]}", "bore": b.name,
                     "axis": self.shaft(b.shaft).axis}
            if matrices is not None:
                K, C = matrices[b.name]
                entry.update(stiffness_matrix=np.asarray(K, float).tolist(),
                             damping_matrix=None if C is None else np.asarray(C, float).tolist())
            elif b.designation is not None:
                entry.update(designation=b.designation, load=loads[b.name], model=b.model,
                             fixed_tilt=(0.0, 0.0) if self.hold_tilt else None)
            elif b.stiffness is not None:
                entry["stiffness"] = b.stiffness
            else:
                entry.update(stiffness_matrix=[list(r) for r in b.stiffness_matrix],
                             damping_matrix=None if b.damping_matrix is None else [list(r) for r in b.damping_matrix])
            bearings.append(entry)
        bores = [{"name": b["name"], "surface": s.bore, "axis": b["axis"]}
                 for b, s in zip(bearings, sorted(self.bearings, key=lambda b: (SHAFTS.index(b.shaft), b.position)))]
        mesh = {"a": f"pinion:{nodes['pinion']['gear']}", "b": f"wheel:{nodes['wheel']['gear']}",
                "stiffness": forces.stiffness, "point": tuple(float(x) for x in forces.point),
                "direction": tuple(float(x) for x in forces.direction)}
        drive_lines = []
        if self.drive_line in ("quill-shafts", "back-to-back"):
            for name, (near, inertia, far) in self.drive_line_parts().items():
                coupling = self.couplings[SHAFTS.index(name)].name
                drive_lines.append({"name": f"coupling_{coupling}", "shaft_node": f"{name}:{DRIVE_LINE_NODE}",
                                    "near_stiffness": near, "inertia": inertia, "far_stiffness": far})
        extra = {}
        if self.drive_line == "back-to-back":
            # the pinion quill ends on the aux pinion (the motor's shaft), the wheel quill on the aux wheel
            extra["aux_gearbox"] = {"name": "aux_gearbox", "axis": self.shaft("pinion").axis,
                                    "pinion_line": drive_lines[0]["name"], "wheel_line": drive_lines[1]["name"],
                                    **self.aux_gearbox_parts()}
        return CouplingSpec.model_validate({"bores": bores, "shafts": shafts, "bearings": bearings,
                                            "gear_meshes": [mesh], "drive_lines": drive_lines, **extra})


# ------------------------------------------------------------------------------------------ test gearbox
# The thesis' Ch. 5 test gearbox in the frame of the `test-gearbox` housing scene: shafts along +y, gear centres
# in the plane y = 0 at x = -0.126 (pinion) / 0.074 (wheel), z = 0.200 m; shafts ending flush with the outer faces
# of the bearing plates (y = -/+0.140 m), bearings mid-plate (y = -/+0.1075 m).
TEST_GEARBOX_CENTRES = {"pinion": (-0.126, 0.0, 0.200), "wheel": (0.074, 0.0, 0.200)}
TEST_GEARBOX_BEARINGS = {"ball": {"pinion": "SKF 6316", "wheel": "SKF 6219"}}
# which of a shaft's two bearings (at -/+0.1075 m along +y) locates it axially
LOCATING_SIDES = ("front", "back")
# test_gearbox(wheel_locating=...): "configuration" (the default) = the side the thesis states for the bearing
# configuration (housingfe.bearings.configurations: Configuration.wheel_locating), "front" where it states none;
# "front" / "back" = that side for every configuration
WHEEL_LOCATING = ("configuration", *LOCATING_SIDES)


def slid_rings(report: dict[str, dict]) -> list[str]:
    """The shafts whose floating ring slid in a Drivetrain.floating_axial_report, in shaft order."""
    return [shaft for shaft, r in report.items() if r["slid"]]


def floating_axial_text(report: dict[str, dict]) -> str:
    """One shaft after the other as the summaries write a Drivetrain.floating_axial_report: "pinion -3155 -> -3131 N
    (slid), wheel -3712 N" (requested -> held where the ring slid; N, > 0 away from the locating bearing)."""
    return ", ".join(f"{shaft} {r['requested_N']:.0f} -> {r['held_N']:.0f} N (slid)" if r["slid"]
                     else f"{shaft} {r['held_N']:.0f} N" for shaft, r in report.items())


def _catalogue_kind(designation: str) -> str:
    """The catalogue kind ("ball", "cylindrical_roller", ...) of a bearing designation."""
    from housingfe.bearings.catalogue import lookup

    return lookup(designation).kind


def wheel_locating_side(bearings: str, wheel_locating: str = "configuration") -> str:
    """The side ("front" | "back") of the test gearbox's wheel bearing that locates the wheel axially, for the
    bearing configuration `bearings` and the choice `wheel_locating` (WHEEL_LOCATING): "configuration" gives the
    side the thesis states for it (angular_contact, tapered_roller: "back", Sec. 5.8), "front" where the text states
    none (ball, self_aligning; the double helical configurations, whose wheel no bearing locates)."""
    if wheel_locating not in WHEEL_LOCATING:
        raise InputError(f"test_gearbox: wheel_locating: {wheel_locating!r} unknown (known: "
                         f"{', '.join(WHEEL_LOCATING)})")
    if wheel_locating != "configuration":
        return wheel_locating
    from housingfe.bearings.configurations import configurations

    config = configurations().get(bearings)
    return (config.wheel_locating if config is not None else None) or "front"


GEAR_SETS = {"A": "gearset-A", "B": "gearset-B", "C": "gearset-C", "D": "gearset-D",
             "uncorrected": "gearset-uncorrected", "double_helical": "gearset-double-helical"}


def mesh_line_of_action(pair, pinion_centre, wheel_centre, shaft_axis) -> tuple[np.ndarray, float, np.ndarray]:
    """The contact normal of a gear pair placed in the housing: (n, resultant, e_c).

    n (unit, global): the transverse line of action at the operating pressure angle from the common tangent, tilted
    out of the transverse plane by the base helix angle along +shaft_axis; for a double helical pair the transverse
    line itself, because the halves' normals cos(beta_b) l +- sin(beta_b) a, S / 2 each, add up to S cos^2(beta_b)
    l l^T and a force F_n cos(beta_b) along l (the axial S sin^2(beta_b) of the halves against each other is not
    excited).  resultant: the factor on the normal force (and, squared, on the normal stiffness) along n: cos(beta_b)
    for double helical, 1 otherwise.  e_c (unit): from the pinion centre towards the wheel centre, normal to the
    axis.  Centres in m; the axis need not be unit."""
    a = np.asarray(shaft_axis, float) / np.linalg.norm(shaft_axis)
    centres = np.asarray(wheel_centre, float) - np.asarray(pinion_centre, float)
    e_c = centres - (centres @ a) * a
    e_c /= np.linalg.norm(e_c)
    tangent = np.cross(a, e_c)
    alpha = pair.operating_pressure_angle
    beta_b = pair.base_helix_angle
    transverse = np.sin(alpha) * e_c + np.cos(alpha) * tangent
    if pair.kind == "double_helical":
        return transverse, math.cos(beta_b), e_c
    return np.cos(beta_b) * transverse + np.sin(beta_b) * a, 1.0, e_c


def test_gearbox(gear_set: str = "A", bearings: str = "ball", torque: float = 2000.0,
                 wheel_locating: str = "configuration") -> Drivetrain:
    """The Ch. 5 test gearbox (van Roosmalen 1994) as one description: gear set A-D, "uncorrected" or
    "double_helical" (the gear data of the gearset-* scenes), bearings "ball" (SKF 6316 pinion / 6219 wheel, Lim's
    model, the front bearings locating) or a configuration of housingfe.bearings.configurations (Secs. 5.8, 5.9:
    "angular_contact", "self_aligning", "tapered_roller" with the single helical sets; "cylindrical_roller",
    "fluid_film" with the double helical set, which puts no axial load on them), pinion torque (N m).  Shaft, quill-shaft and coupling dimensions are the
    ASSUMPTIONS of docs/source.md (Appendix C's parameter table did not survive); the auxiliary gearbox and motor
    (for drive_line "back-to-back") those of `scaled_aux_gearbox` and MOTOR_*.  wheel_locating (WHEEL_LOCATING,
    `wheel_locating_side`): which of the wheel's bearings locates it axially, "configuration" (default: the side
    the thesis states for the configuration -- "back" for angular contact, Sec. 5.8: "at the front (pinion) and at
    the back (wheel)", and tapered rollers, "the same reasons" -- "front" where it states none), or "front" /
    "back" for every configuration; the pinion is located at its front bearing either way."""
    if gear_set not in GEAR_SETS:
        raise InputError(f"test_gearbox: gear_set: {gear_set!r} unknown (known: {', '.join(GEAR_SETS)})")
    from housingfe.bearings.configurations import configurations

    known = list(dict.fromkeys(["ball", *configurations()]))     # "ball" is a configuration too: named once
    if bearings not in known:
        raise InputError(f"test_gearbox: bearings: {bearings!r} unknown (known: {', '.join(known)})")
    axis = (0.0, 1.0, 0.0)
    shafts = (ShaftLine("pinion", 0.080, TEST_GEARBOX_CENTRES["pinion"], axis, (-0.140, 0.140)),   # SKF 6316 bore
              ShaftLine("wheel", 0.095, TEST_GEARBOX_CENTRES["wheel"], axis, (-0.140, 0.140)))      # SKF 6219 bore
    located = {"pinion": "front", "wheel": wheel_locating_side(bearings, wheel_locating)}
    seats = tuple(BearingSeat(f"{shaft}_{side}", shaft, s, f"bore_{shaft}_{side}", locating=side == located[shaft],
                              designation=TEST_GEARBOX_BEARINGS["ball"][shaft])
                  for shaft in SHAFTS for side, s in (("front", -0.1075), ("back", 0.1075)))
    quills = (QuillShaft("motor_far", 0.040, 1.5), QuillShaft("motor_pinion", 0.060, 0.25),
              QuillShaft("wheel_brake", 0.075, 0.25), QuillShaft("brake_far", 0.055, 1.5))
    gears = GearSet.from_scene(GEAR_SETS[gear_set])
    return Drivetrain(gears=gears, shafts=shafts, bearings=seats,
                      quill_shafts=quills, couplings=(Coupling("motor", 0.02), Coupling("brake", 0.05)),
                      torque=torque, bearing_configuration=None if bearings == "ball" else bearings,
                      aux_gearbox=scaled_aux_gearbox(gears))


test_gearbox.__test__ = False     # not a pytest test despite its name


def with_torque(drivetrain: Drivetrain, torque: float) -> Drivetrain:
    """The same drivetrain at another pinion torque (N m)."""
    return replace(drivetrain, torque=torque)
