"""Involute gear pair geometry (van Roosmalen 1994, Appendix B and F; DIN 3960 / ISO 21771 formulas).

All quantities are SI: lengths in m, angles in rad, forces in N, torques in N m, speeds in rad/s
unless a name says otherwise (`_rpm`, `_deg`, `_mm`).  Index 0 is the pinion (driving gear, gear 1),
index 1 the wheel (gear 2).  External gears only.

Main API
--------
`GearPair` (frozen dataclass) built from the basic rack and blank data; its properties give the
derived geometry (pitch/base/tip/root diameters, transverse and operating pressure angles, base
helix angle, addendum reduction k*m, transverse/overlap/total contact ratios, path of contact) and
`tooth_loads(torque)` the loads of Appendix F.  `GearPair.from_table(d)` builds one from a scene /
reference table with millimetre and degree keys.  `tooth_profile(pair, gear)` gives the transverse
tooth outline (involute + trochoid fillet) as points.

Definitions used (DIN 3960 / ISO 21771; Appendix F's printed values follow from exactly these):
  d = m z / cos(beta), alpha_t = atan(tan(alpha_n)/cos(beta)), d_b = d cos(alpha_t),
  zero-backlash centre distance a_w: inv(alpha_wt0) = inv(alpha_t) + 2 (x1 + x2) tan(alpha_n) / (z1 + z2),
      a_w = a0 cos(alpha_t) / cos(alpha_wt0) with a0 = (d1 + d2)/2,
  operating centre distance a (default a_w; a < a_w is an error, a > a_w means backlash):
      cos(alpha_wt) = a0 cos(alpha_t) / a,
  circumferential backlash on the operating pitch circles j_wt = 2 a (inv(alpha_wt) - inv(alpha_wt0)),
      normal backlash j_bn = j_wt cos(alpha_wt) cos(beta_b),
  k m = (a_w - a0) - (x1 + x2) m   (DIN 3960 addendum reduction, <= 0: a property of the blanks, never of
      the mounting distance),
  tip diameters belong to the gear blanks: d_a = d + 2 m (h_aP + x) by default, + 2 k m only with
      tip_shortening=True, or the given blank_tip_diameter;  d_f = d - 2 m (h_fP - x),
  eps_alpha = (sqrt(r_a1^2 - r_b1^2) + sqrt(r_a2^2 - r_b2^2) - a sin(alpha_wt)) / p_bt,
  eps_beta = b sin(beta) / (pi m) with b the smaller (per helix) face width.
The basic rack (h_aP*, h_fP*, rho_fP*) may differ per gear: give a pair instead of a number.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field

import numpy as np

from housingfe.errors import InputError

KINDS = ("spur", "single_helical", "double_helical")


def involute(angle):
    """Involute function inv(a) = tan(a) - a (angle in rad)."""
    return np.tan(angle) - angle


def inverse_involute(value: float) -> float:
    """The angle a in [0, pi/2) [rad] with inv(a) = value (>= 0), by Newton's method from Cheng's start."""
    if not value >= 0:
        raise InputError(f"inverse involute: need a value >= 0, got {value}")
    if value == 0:
        return 0.0
    a = min((3.0 * value) ** (1.0 / 3.0), 1.5)        # inv(a) ~ a^3/3 for small a
    for _ in range(60):
        step = (math.tan(a) - a - value) / math.tan(a) ** 2     # d inv / da = tan^2(a)
        a = min(max(a - step, 0.5 * a), 0.5 * (a + math.pi / 2))
        if abs(step) < 1e-15:
            break
    return a


# ----------------------------------------------------------------------------- physical operating limits
# A pinion torque or speed beyond these is no operating point of any steel gear (docs/source.md, "Operating
# limits").  They are bounds of physics, not of the model: far above every realistic overload, never tuned.
#
# Unit tooth load F_t / (b m_n): ISO 6336-3 gives the nominal tooth-root stress sigma_F0 = F_t / (b m_n) Y_F Y_S
# Y_beta, with Y_F Y_S >= 4 for teeth of the standard basic rack (its minimum, near x = +0.5..1 and z -> inf) and
# Y_beta >= 0.75, so sigma_F0 >= 3 F_t / (b m_n).  The strongest material of ISO 6336-5 (case-hardened wrought
# steel, grade ME: sigma_Flim = 525 MPa, sigma_FE = 2 sigma_Flim) with the static life factor Y_NT = 2.5 carries
# at most 2625 MPa in the root.  Above 2625 / 3 = 875 N/mm^2 the teeth of any steel gear break at the first
# load.  For the thesis' set A at its test torque of 2000 N m (F_t = 40.8 kN over 62 mm, m_n = 4 mm) the unit load
# is 164 N/mm^2: the limit is 5.3 x that (10.6 kN m), 3.5 x for the double helical set, while ISO 6336-1's
# application factor K_A for heavy shocks is 2.25.
UNIT_TOOTH_LOAD_LIMIT_PA = 2625e6 / 3.0
# Pitch-line velocity: a solid steel disc whose rim runs at v carries (3 + nu) / 8 rho v^2 at its centre, 3.2 GPa
# at 1000 m/s (rho = 7850 kg/m^3, nu = 0.3), beyond the tensile strength of any steel: the wheel bursts.  The
# fastest gears in service (turbo gears, API 613 / ISO 13691) run at pitch-line velocities of up to about 200 m/s.
PITCH_LINE_VELOCITY_LIMIT_M_S = 1000.0


def unit_tooth_load(torque: float, pitch_diameter: float, face_width: float, module: float) -> float:
    """F_t / (b m_n) [N/m^2] of a gear carrying `torque` [N m] on pitch diameter d [m] (F_t = 2 T / d), face
    width b [m] (all helices) and normal module m_n [m] (ISO 6336-3's nominal root-stress load)."""
    return 2.0 * torque / pitch_diameter / (face_width * module)


def torque_problem(torque, pitch_diameter: float, face_width: float, module: float) -> str | None:
    """Why `torque` [N m] on a gear (pitch diameter, face width over all helices and normal module, m) is no
    operating torque, or None.  Refused: not a finite number > 0, or a unit tooth load F_t / (b m_n) above
    UNIT_TOOTH_LOAD_LIMIT_PA (the teeth of any steel gear break)."""
    if isinstance(torque, bool) or not isinstance(torque, numbers.Real) or not math.isfinite(torque) or torque <= 0:
        return f"{torque!r} must be a finite torque > 0 N m"
    load = unit_tooth_load(torque, pitch_diameter, face_width, module)
    if load > UNIT_TOOTH_LOAD_LIMIT_PA:
        highest = torque * UNIT_TOOTH_LOAD_LIMIT_PA / load
        return (f"{torque:g} N m loads the teeth with F_t/(b m_n) = {load / 1e6:.4g} N/mm^2, above the "
                f"{UNIT_TOOTH_LOAD_LIMIT_PA / 1e6:g} N/mm^2 at which the teeth of any steel gear break (ISO 6336-3/-5 "
                f"static strength); this gear carries at most {highest:.4g} N m (docs/source.md: operating limits)")
    return None


def speed_problem(speed_rpm, pitch_diameter: float) -> str | None:
    """Why `speed_rpm` [rev/min] of a gear of pitch diameter [m] is no operating speed, or None.  Refused: not a
    finite number > 0, or a pitch-line velocity above PITCH_LINE_VELOCITY_LIMIT_M_S (the wheel bursts)."""
    if isinstance(speed_rpm, bool) or not isinstance(speed_rpm, numbers.Real) or not math.isfinite(speed_rpm) \
            or speed_rpm <= 0:
        return f"{speed_rpm!r} must be a finite speed > 0 rev/min"
    velocity = math.pi * pitch_diameter * speed_rpm / 60.0
    if velocity > PITCH_LINE_VELOCITY_LIMIT_M_S:
        highest = speed_rpm * PITCH_LINE_VELOCITY_LIMIT_M_S / velocity
        return (f"{speed_rpm:g} rev/min is a pitch-line velocity of {velocity:.4g} m/s, above the "
                f"{PITCH_LINE_VELOCITY_LIMIT_M_S:g} m/s at which a steel wheel bursts; this gear runs at most "
                f"{highest:.4g} rev/min (docs/source.md: operating limits)")
    return None


def _pair(value, key: str, where: str) -> tuple[float, float]:
    """A number or a (pinion, wheel) pair -> (float, float)."""
    if isinstance(value, (int, float)):
        return (float(value), float(value))
    try:
        first, second = value
        return (float(first), float(second))
    except (TypeError, ValueError):
        raise InputError(f"{where}: {key}: need a number or a pair (pinion, wheel), got {value!r}") from None


@dataclass(frozen=True)
class GearPair:
    """An external involute gear pair.

    Attributes (SI):
      module: normal module m_n [m]
      teeth: (z1, z2)
      pressure_angle: normal pressure angle alpha_n [rad]
      helix_angle: helix angle beta at the pitch circle [rad] (0 for spur)
      profile_shift: addendum modification factors (x1, x2) [-]
      face_width: (b1, b2) [m]; for double helical gears the width of ONE helix
      centre_distance: operating centre distance a [m]; None (default): the zero-backlash centre distance
          a_w of the profile shifts.  a < a_w is an InputError (the teeth would interfere); a > a_w gives
          backlash (`normal_backlash`) and never changes the tips.
      addendum_coefficient: h_aP* of the basic rack [-] (Appendix F: 1.0), a number or (pinion, wheel)
      dedendum_coefficient: h_fP* of the basic rack [-] (Appendix F: 1.4), a number or (pinion, wheel)
      rack_tip_radius_factor: rho_fP* = rho_fP / m of the cutter tip [-] (Appendix F: 0.4), number or pair
      kind: "spur", "single_helical" or "double_helical"
      helix_gap: gap between the two helices of a double helical gear [m]
      youngs_modulus, poisson_ratio, density: material (steel default) [Pa, -, kg/m^3]
      blank_tip_diameter: (d_a1, d_a2) of the gear blanks as made [m]; None: from the basic rack
      tip_shortening: True applies the DIN 3960 tip shortening k m (computed at a_w) to the rack tips; an
          explicit choice (Appendix F's tips include it); never derived from the mounting distance
    The per-gear values are stored as (pinion, wheel) tuples; the resolved centre distance in
    `centre_distance`.
    """

    module: float
    teeth: tuple[int, int]
    pressure_angle: float
    helix_angle: float
    profile_shift: tuple[float, float]
    face_width: tuple[float, float]
    centre_distance: float | None = None
    addendum_coefficient: float | tuple[float, float] = 1.0
    dedendum_coefficient: float | tuple[float, float] = 1.25
    rack_tip_radius_factor: float | tuple[float, float] = 0.38
    kind: str = "single_helical"
    helix_gap: float = 0.0
    youngs_modulus: float = 2.06e11
    poisson_ratio: float = 0.3
    density: float = 7850.0
    name: str = field(default="", compare=False)
    blank_tip_diameter: tuple[float, float] | None = None
    tip_shortening: bool = False

    def __post_init__(self):
        where = self.name or "gear pair"
        if self.kind not in KINDS:
            raise InputError(f"{where}: kind: {self.kind!r} is not one of {', '.join(KINDS)}")
        if not self.module > 0:
            raise InputError(f"{where}: module: must be > 0, got {self.module}")
        if len(self.teeth) != 2 or min(self.teeth) < 5:
            raise InputError(f"{where}: teeth: need two tooth numbers >= 5, got {self.teeth}")
        if not 0 < self.pressure_angle < math.radians(45):
            raise InputError(f"{where}: pressure_angle: must lie in (0, 45) deg")
        if not 0 <= abs(self.helix_angle) < math.radians(60):
            raise InputError(f"{where}: helix_angle: must lie in [0, 60) deg")
        if self.kind == "spur" and self.helix_angle != 0:
            raise InputError(f"{where}: helix_angle: a spur gear has helix angle 0")
        if self.kind != "spur" and self.helix_angle == 0:
            raise InputError(f"{where}: helix_angle: a {self.kind} gear needs a helix angle > 0")
        if min(self.face_width) <= 0:
            raise InputError(f"{where}: face_width: must be > 0")
        # frozen dataclass: normalise the per-gear rack values and resolve the default centre distance
        for key in ("addendum_coefficient", "dedendum_coefficient", "rack_tip_radius_factor"):
            object.__setattr__(self, key, _pair(getattr(self, key), key, where))
        if min(self.addendum_coefficient) <= 0 or min(self.dedendum_coefficient) <= 0:
            raise InputError(f"{where}: addendum_coefficient/dedendum_coefficient: must be > 0")
        if not all(0 <= r < 0.6 for r in self.rack_tip_radius_factor):
            raise InputError(f"{where}: rack_tip_radius_factor: must lie in [0, 0.6)")
        a_w = self.zero_backlash_centre_distance
        if self.centre_distance is None:
            object.__setattr__(self, "centre_distance", a_w)
        elif not (isinstance(self.centre_distance, (int, float)) and math.isfinite(self.centre_distance)):
            raise InputError(f"{where}: centre_distance: need a number in m, got {self.centre_distance!r}")
        elif self.centre_distance < a_w - 1e-6 * self.module:     # round-off of printed shifts: < 1 um/mm
            raise InputError(
                f"{where}: centre_distance: {self.centre_distance * 1e3:.4f} mm is smaller than the zero-backlash "
                f"centre distance a_w = {a_w * 1e3:.4f} mm of these profile shifts: the teeth would interfere "
                "(increase it, lower the profile shifts, or leave it out for a_w)")
        if self.blank_tip_diameter is not None:
            if self.tip_shortening:
                raise InputError(f"{where}: tip_shortening: give either blank tip diameters or tip_shortening")
            tips = _pair(self.blank_tip_diameter, "blank_tip_diameter", where)
            object.__setattr__(self, "blank_tip_diameter", tips)
            for g in (0, 1):
                if not tips[g] > max(self.root_diameter[g], self.base_diameter[g]):
                    raise InputError(f"{where}: blank_tip_diameter: {tips[g] * 1e3:.4f} mm of gear {g + 1} "
                                     "must exceed its root and base diameters")
        s_a = self.tip_thickness
        for g in (0, 1):
            if not s_a[g] > 0:
                raise InputError(f"{where}: tip diameter {self.tip_diameter[g] * 1e3:.4f} mm of gear {g + 1}: "
                                 "the teeth come to a point below it (lower the tip diameter or the profile shift)")
        clearance = self.tip_clearance
        for g in (0, 1):
            if clearance[g] < -1e-6 * self.module:      # round-off of an exact tip shortening
                raise InputError(
                    f"{where}: the tip of gear {g + 1} reaches {-clearance[g] * 1e3:.4f} mm into the root of its "
                    "mate at this centre distance: set tip_shortening, give smaller blank tip diameters, or a "
                    "larger dedendum")
        if self.contact_length_tip_limited() <= 0:
            raise InputError(
                f"{where}: no path of contact: at centre distance {self.centre_distance * 1e3:.4f} mm "
                f"({self.radial_play * 1e3:.4f} mm beyond the zero-backlash a_w = {a_w * 1e3:.4f} mm) the tips "
                f"(d_a = {self.tip_diameter[0] * 1e3:.4f}, {self.tip_diameter[1] * 1e3:.4f} mm) do not reach each "
                "other's flanks (check the centre distance and the profile shifts)")

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_table(cls, t: dict, where: str = "gears") -> "GearPair":
        """Build from a table with Appendix F style keys in mm / degrees:
        module_mm, teeth, pressure_angle_deg, helix_angle_deg, addendum_modification, face_width_mm
        (a pair, or for double helical pairs of [b, b]), centre_distance_mm (optional: default the
        zero-backlash a_w), addendum_coefficient, dedendum_coefficient, rack_tip_radius_factor (each a
        number or a [pinion, wheel] pair), kind (optional), helix_gap_mm (optional), tip_diameter_mm
        (optional: the blanks' tip diameters, e.g. Appendix F's printed ones), tip_shortening (optional bool).
        Other keys (derived values of a reference table) are ignored."""
        try:
            widths = t["face_width_mm"]
            double = isinstance(widths[0], (list, tuple))
            kind = t.get("kind", "double_helical" if double else
                         ("spur" if float(t.get("helix_angle_deg", 0.0)) == 0 else "single_helical"))
            if double:
                widths = [w[0] for w in widths]
            return cls(
                module=float(t["module_mm"]) * 1e-3,
                teeth=(int(t["teeth"][0]), int(t["teeth"][1])),
                pressure_angle=math.radians(float(t["pressure_angle_deg"])),
                helix_angle=math.radians(float(t.get("helix_angle_deg", 0.0))),
                profile_shift=(float(t["addendum_modification"][0]), float(t["addendum_modification"][1])),
                face_width=(float(widths[0]) * 1e-3, float(widths[1]) * 1e-3),
                centre_distance=(None if t.get("centre_distance_mm") is None
                                 else float(t["centre_distance_mm"]) * 1e-3),
                addendum_coefficient=_pair(t.get("addendum_coefficient", 1.0), "addendum_coefficient", where),
                dedendum_coefficient=_pair(t.get("dedendum_coefficient", 1.25), "dedendum_coefficient", where),
                rack_tip_radius_factor=_pair(t.get("rack_tip_radius_factor", 0.38), "rack_tip_radius_factor",
                                             where),
                kind=kind,
                helix_gap=float(t.get("helix_gap_mm", 0.0)) * 1e-3,
                name=where,
                blank_tip_diameter=(None if t.get("tip_diameter_mm") is None
                                    else tuple(float(v) * 1e-3 for v in t["tip_diameter_mm"])),
                tip_shortening=bool(t.get("tip_shortening", False)),
            )
        except KeyError as exc:
            raise InputError(f"{where}: missing key {exc.args[0]}") from None
        except (TypeError, ValueError, IndexError) as exc:
            raise InputError(f"{where}: malformed value ({exc})") from None

    # ------------------------------------------------------------------ basic geometry
    @property
    def ratio(self) -> float:
        """Gear ratio u = z2 / z1 [-]."""
        return self.teeth[1] / self.teeth[0]

    @property
    def transverse_module(self) -> float:
        """m_t = m / cos(beta) [m]."""
        return self.module / math.cos(self.helix_angle)

    @property
    def transverse_pressure_angle(self) -> float:
        """alpha_t [rad]."""
        return math.atan(math.tan(self.pressure_angle) / math.cos(self.helix_angle))

    @property
    def base_helix_angle(self) -> float:
        """beta_b [rad]: tan(beta_b) = tan(beta) cos(alpha_t)."""
        return math.atan(math.tan(self.helix_angle) * math.cos(self.transverse_pressure_angle))

    @property
    def pitch_diameter(self) -> np.ndarray:
        """(d1, d2) = m_t z [m]."""
        return self.transverse_module * np.array(self.teeth, dtype=float)

    @property
    def base_diameter(self) -> np.ndarray:
        """(d_b1, d_b2) = d cos(alpha_t) [m]."""
        return self.pitch_diameter * math.cos(self.transverse_pressure_angle)

    @property
    def reference_centre_distance(self) -> float:
        """a0 = (d1 + d2) / 2 [m]."""
        return 0.5 * float(self.pitch_diameter.sum())

    @property
    def operating_pressure_angle(self) -> float:
        """Operating transverse pressure angle alpha_wt [rad] at the given centre distance."""
        return math.acos(self.reference_centre_distance * math.cos(self.transverse_pressure_angle)
                         / self.centre_distance)

    @property
    def zero_backlash_pressure_angle(self) -> float:
        """alpha_wt0 [rad]: inv(alpha_wt0) = inv(alpha_t) + 2 (x1 + x2) tan(alpha_n) / (z1 + z2) (DIN 3960)."""
        target = float(involute(self.transverse_pressure_angle)) \
            + 2 * math.tan(self.pressure_angle) * sum(self.profile_shift) / sum(self.teeth)
        if target <= 0:
            where = self.name or "gear pair"
            raise InputError(f"{where}: addendum_modification: the sum {sum(self.profile_shift)} is so negative "
                             "that no centre distance gives a backlash-free mesh")
        return inverse_involute(target)

    @property
    def zero_backlash_centre_distance(self) -> float:
        """a_w = a0 cos(alpha_t) / cos(alpha_wt0) [m]: the profile shifts mesh without backlash (DIN 3960)."""
        return self.reference_centre_distance * math.cos(self.transverse_pressure_angle) \
            / math.cos(self.zero_backlash_pressure_angle)

    @property
    def radial_play(self) -> float:
        """a - a_w [m] (>= 0)."""
        return self.centre_distance - self.zero_backlash_centre_distance

    @property
    def circumferential_backlash(self) -> float:
        """j_wt = 2 a (inv(alpha_wt) - inv(alpha_wt0)) [m] on the operating pitch circles (tooth thicknesses as
        generated by the profile shifts, no thickness tolerances)."""
        j = 2 * self.centre_distance * float(involute(self.operating_pressure_angle)
                                             - involute(self.zero_backlash_pressure_angle))
        return max(j, 0.0)      # a within round-off below a_w counts as zero backlash

    @property
    def normal_backlash(self) -> float:
        """j_bn = j_wt cos(alpha_wt) cos(beta_b) [m], normal to the flanks (= 2 m_n sin(alpha_n) times the
        profile-shift sum missing for zero backlash at a)."""
        return self.circumferential_backlash * math.cos(self.operating_pressure_angle) * math.cos(self.base_helix_angle)

    @property
    def addendum_reduction(self) -> float:
        """DIN 3960 k m = (a_w - a0) - (x1 + x2) m [m] (<= 0) of the blanks: what tip shortening would take off
        each tip radius to keep the rack's tip clearance at the zero-backlash centre distance.  Applied to the
        tips only with tip_shortening=True."""
        return (self.zero_backlash_centre_distance - self.reference_centre_distance) \
            - sum(self.profile_shift) * self.module

    @property
    def tip_diameter(self) -> np.ndarray:
        """(d_a1, d_a2) [m]: the blanks' given tip diameters, else d + 2 m (h_aP* + x) (+ 2 k m with
        tip_shortening).  Independent of the centre distance."""
        if self.blank_tip_diameter is not None:
            return np.array(self.blank_tip_diameter, dtype=float)
        x = np.array(self.profile_shift)
        shortening = 2 * self.addendum_reduction if self.tip_shortening else 0.0
        return self.pitch_diameter + 2 * self.module * (np.array(self.addendum_coefficient) + x) + shortening

    @property
    def root_diameter(self) -> np.ndarray:
        """(d_f1, d_f2) = d - 2 m (h_fP* - x) [m]."""
        x = np.array(self.profile_shift)
        return self.pitch_diameter - 2 * self.module * (np.array(self.dedendum_coefficient) - x)

    @property
    def tip_clearance(self) -> np.ndarray:
        """(c1, c2) = a - d_a1/2 - d_f2/2, a - d_a2/2 - d_f1/2 [m]: radial room between each tip and the mate's
        root circle at the operating centre distance."""
        da, df = self.tip_diameter, self.root_diameter
        return self.centre_distance - 0.5 * (da + df[::-1])

    @property
    def tip_thickness(self) -> np.ndarray:
        """Transverse tooth thickness on the tip circle (s_at1, s_at2) [m] (generated thickness, no backlash
        allowance); <= 0 means pointed teeth."""
        at = self.transverse_pressure_angle
        da, db = self.tip_diameter, self.base_diameter
        x = np.array(self.profile_shift)
        alpha_a = np.arccos(np.minimum(db / da, 1.0))
        half = (math.pi / 2 + 2 * x * math.tan(self.pressure_angle)) / np.array(self.teeth, float)
        return da * (half + float(involute(at)) - involute(alpha_a))

    @property
    def transverse_base_pitch(self) -> float:
        """p_bt = pi m_t cos(alpha_t) [m]: the distance between successive contacts on the line of action."""
        return math.pi * self.transverse_module * math.cos(self.transverse_pressure_angle)

    @property
    def contact_width(self) -> float:
        """Face width in contact per helix b = min(b1, b2) [m]."""
        return min(self.face_width)

    @property
    def total_contact_width(self) -> float:
        """Face width in contact over all helices [m] (2 b for double helical gears)."""
        return self.contact_width * (2 if self.kind == "double_helical" else 1)

    # ------------------------------------------------------------------ path of contact
    def contact_length_tip_limited(self) -> float:
        """Length g_alpha of the path of contact in the transverse plane [m] (tips limit it)."""
        ra, rb = self.tip_diameter / 2, self.base_diameter / 2
        return float(np.sqrt(ra[0]**2 - rb[0]**2) + np.sqrt(ra[1]**2 - rb[1]**2)
                     - self.centre_distance * math.sin(self.operating_pressure_angle))

    @property
    def line_of_action_length(self) -> float:
        """T1T2 = a sin(alpha_wt) [m]: the common tangent between the base circles."""
        return self.centre_distance * math.sin(self.operating_pressure_angle)

    @property
    def path_of_contact(self) -> tuple[float, float]:
        """(start, end) of contact measured along the line of action from the pinion's tangent point
        T1 [m]: start A = T1T2 - sqrt(r_a2^2 - r_b2^2) (wheel tip engages the pinion root),
        end E = sqrt(r_a1^2 - r_b1^2) (pinion tip)."""
        ra, rb = self.tip_diameter / 2, self.base_diameter / 2
        start = self.line_of_action_length - math.sqrt(ra[1]**2 - rb[1]**2)
        end = math.sqrt(ra[0]**2 - rb[0]**2)
        return start, end

    @property
    def transverse_contact_ratio(self) -> float:
        """eps_alpha = g_alpha / p_bt [-]."""
        return self.contact_length_tip_limited() / self.transverse_base_pitch

    @property
    def overlap_ratio(self) -> float:
        """eps_beta = b sin(beta) / (pi m) [-], per helix, b = the smaller face width."""
        return self.contact_width * math.sin(self.helix_angle) / (math.pi * self.module)

    @property
    def total_contact_ratio(self) -> float:
        """eps_gamma = eps_alpha + eps_beta [-] (per helix for double helical gears, as Appendix F)."""
        return self.transverse_contact_ratio + self.overlap_ratio

    # ------------------------------------------------------------------ loads and kinematics
    def pitch_line_velocity(self, pinion_speed_rpm: float) -> float:
        """v = pi d1 n1 / 60 [m/s]."""
        return math.pi * float(self.pitch_diameter[0]) * pinion_speed_rpm / 60.0

    def torque_problem(self, pinion_torque) -> str | None:
        """Why a pinion torque [N m] is no operating torque of this pair, or None (module `torque_problem`: over
        the pinion's pitch diameter, the face width in contact over all helices and the normal module)."""
        return torque_problem(pinion_torque, float(self.pitch_diameter[0]), self.total_contact_width, self.module)

    def speed_problem(self, pinion_speed_rpm) -> str | None:
        """Why a pinion speed [rev/min] is no operating speed of this pair, or None (module `speed_problem`: the
        pitch-line velocity is the same on both gears)."""
        return speed_problem(pinion_speed_rpm, float(self.pitch_diameter[0]))

    def tooth_frequency(self, pinion_speed_rpm: float) -> float:
        """Tooth (mesh) frequency z1 n1 / 60 [Hz]."""
        return self.teeth[0] * pinion_speed_rpm / 60.0

    def tooth_loads(self, pinion_torque: float) -> dict[str, float]:
        """Loads for a pinion torque T1 [N m]: circumferential F_t = 2 T1 / d1, axial F_ax = F_t tan(beta)
        (per gear; 0 net for double helical), radial F_r = F_t tan(alpha_wt), normal on the base
        plane F_bn = F_t / (cos(alpha_wt) cos(beta_b)) computed with the operating transverse pressure
        angle [N]; wheel torque T2 = T1 u [N m]."""
        ft = 2.0 * pinion_torque / float(self.pitch_diameter[0])
        fax = 0.0 if self.kind == "double_helical" else ft * math.tan(self.helix_angle)
        ft_w = 2.0 * pinion_torque / float(self.base_diameter[0]) * math.cos(self.operating_pressure_angle)
        return {
            "circumferential_N": ft,
            "axial_N": fax,
            "radial_N": ft_w * math.tan(self.operating_pressure_angle),
            "normal_N": 2.0 * pinion_torque / float(self.base_diameter[0]) / math.cos(self.base_helix_angle),
            "wheel_torque_Nm": pinion_torque * self.ratio,
        }

    def appendix_f_table(self, power_W: float | None = None, pinion_speed_rpm: float | None = None) -> dict:
        """The derived quantities of Appendix F with its names, lengths in mm and angles in degrees."""
        out = {
            "pitch_diameter_mm": (self.pitch_diameter * 1e3).tolist(),
            "tip_diameter_mm": (self.tip_diameter * 1e3).tolist(),
            "root_diameter_mm": (self.root_diameter * 1e3).tolist(),
            "base_diameter_mm": (self.base_diameter * 1e3).tolist(),
            "addendum_reduction_mm": self.addendum_reduction * 1e3,
            "tip_shortening_applied": bool(self.tip_shortening),
            "tip_diameter_from": ("blank" if self.blank_tip_diameter is not None else
                                  "basic rack + tip shortening" if self.tip_shortening else "basic rack"),
            "centre_distance_mm": self.centre_distance * 1e3,
            "normal_backlash_mm": self.normal_backlash * 1e3,
            "transverse_contact_ratio": self.transverse_contact_ratio,
            ("overlap_ratio_per_helix" if self.kind == "double_helical" else "overlap_ratio"): self.overlap_ratio,
            "total_contact_ratio": self.total_contact_ratio,
            "transverse_pressure_angle_deg": math.degrees(self.transverse_pressure_angle),
            "operating_transverse_pressure_angle_deg": math.degrees(self.operating_pressure_angle),
            "base_helix_angle_deg": math.degrees(self.base_helix_angle),
            "gear_ratio": self.ratio,
            "transverse_base_pitch_mm": self.transverse_base_pitch * 1e3,
            "zero_backlash_centre_distance_mm": self.zero_backlash_centre_distance * 1e3,
        }
        if power_W is not None and pinion_speed_rpm is not None:
            torque = power_W / (pinion_speed_rpm * math.pi / 30.0)
            loads = self.tooth_loads(torque)
            out.update({
                "pitch_line_velocity_m_per_s": self.pitch_line_velocity(pinion_speed_rpm),
                "circumferential_tooth_load_N": loads["circumferential_N"],
                "axial_tooth_load_N": loads["axial_N"],
                "torque_Nm": [torque, loads["wheel_torque_Nm"]],
            })
        return out


# ---------------------------------------------------------------------- tooth profile (Appendix B)
def _rack_boundary(pair: GearPair, gear: int, n: int = 200) -> np.ndarray:
    """Transverse outline of the cutting rack tooth to the right of the gap that forms a gear tooth
    centred on u = 0: flank, tip rounding (radius rho m), tip line.  Coordinates (u, v) in m, u along
    the pitch line, v radial from the gear's pitch circle (v < 0 towards the gear centre)."""
    m, mt, at = pair.module, pair.transverse_module, pair.transverse_pressure_angle
    x = pair.profile_shift[gear]
    rho = pair.rack_tip_radius_factor[gear] * m
    v_tip = (x - pair.dedendum_coefficient[gear]) * m
    # above the rack's own addendum so that a blank tip larger than the rack tip is still cut
    v_top = (x + max(pair.addendum_coefficient[gear], (pair.tip_diameter[gear] - pair.pitch_diameter[gear])
                     / (2 * m) - x) + 0.5) * m

    def flank_u(v):
        return math.pi * mt / 4 - (v - x * m) * math.tan(at)   # gap widens towards the gear centre

    vc = v_tip + rho
    uc = flank_u(vc) + rho / math.cos(at)
    v_touch = vc - rho * math.sin(at)
    flank_v = np.linspace(v_top, v_touch, n)
    flank = np.column_stack([flank_u(flank_v), flank_v])
    angles = np.linspace(math.pi + at, 1.5 * math.pi, n)
    arc = np.column_stack([uc + rho * np.cos(angles), vc + rho * np.sin(angles)])
    # the tip line only up to the rack tooth's centre: beyond it the other flank's rounding takes over
    tip = np.column_stack([np.linspace(uc, max(uc, math.pi * mt / 2), n // 4), np.full(n // 4, v_tip)])
    return np.vstack([flank, arc, tip])


def tooth_profile(pair: GearPair, gear: int, n_radii: int = 120) -> dict[str, np.ndarray]:
    """Transverse outline of one tooth of gear 0 (pinion) or 1 (wheel) as generated by the basic rack
    (Appendix B, Fig. B.2): involute flank, trochoid fillet cut by the rack's tip rounding (radius
    rho m), root circle, tip circle.  The envelope is computed numerically: the rack outline is rolled
    over the pitch circle and, at every radius, the tooth boundary is the smallest polar angle the rack
    reaches.  (The small elliptical distortion of the tip rounding in the transverse section of a
    helical gear is neglected, as in eq. B-5.)

    Returns arrays in m, frame centred on the gear axis, tooth symmetry line along +y:
      'right_flank' (n, 2) from root to tip, 'radius' (n,) and 'half_angle' (n,) [rad] of that flank,
      'form_radius' [m] where fillet and involute meet, 'outline' (closed, both flanks and tip arc)."""
    if gear not in (0, 1):
        raise InputError(f"tooth_profile: gear must be 0 (pinion) or 1 (wheel), got {gear}")
    x = pair.profile_shift[gear]
    r = float(pair.pitch_diameter[gear]) / 2
    ra = float(pair.tip_diameter[gear]) / 2
    rf = float(pair.root_diameter[gear]) / 2
    rack = _rack_boundary(pair, gear, n=400)
    phi_max = 2.5 * (pair.dedendum_coefficient[gear] + pair.addendum_coefficient[gear] + 1) * pair.module / r + 0.3
    phis = np.linspace(-phi_max, phi_max, 3000)
    # Rack translated by r*phi, gear frame rotated back by phi (pure rolling on the pitch circle).
    X = rack[None, :, 0] + r * phis[:, None]
    Y = r + rack[None, :, 1]
    c, s = np.cos(phis)[:, None], np.sin(phis)[:, None]
    gx, gy = X * c - Y * s, X * s + Y * c
    R = np.hypot(gx, gy).ravel()
    radii = np.linspace(rf, ra, n_radii)
    # Narrow radius windows keep the bias small: the flank angle changes ~tan(alpha) * window / r.
    window = 2e-4 * pair.module
    # the tooth boundary at radii[k]: the smallest polar angle of the points with radii[k] - window <= R <
    # radii[k] + window.  The windows do not overlap (2 window << the radii's spacing), so each point belongs to
    # at most one: the last window whose lower edge lies at or below it (no sort of the 10^6 points)
    lower, upper = radii - window, radii + window
    if not np.all(upper[:-1] <= lower[1:]):
        raise ValueError(f"tooth_profile: n_radii = {n_radii} is too fine for the radius window {window:g} m")
    k = np.searchsorted(lower, R, side="right") - 1
    inside = np.flatnonzero((k >= 0) & (R < upper[np.maximum(k, 0)]))
    theta = np.arctan2(gx.ravel()[inside], gy.ravel()[inside])
    half = np.full(n_radii, np.inf)
    np.minimum.at(half, k[inside], theta)
    half[np.isinf(half)] = np.nan                       # an empty window (as before: filled below or NaN)
    half[0] = half[1] if np.isnan(half[0]) else half[0]
    rb = float(pair.base_diameter[gear]) / 2
    psi_b = (math.pi / 2 + 2 * x * math.tan(pair.pressure_angle)) / pair.teeth[gear] \
        + float(involute(pair.transverse_pressure_angle))
    involute_half = np.where(radii >= rb, psi_b - involute(np.arccos(np.minimum(rb / radii, 1.0))), np.nan)
    on_involute = np.abs(half - involute_half) * radii < 1e-3 * pair.module   # within 1 per mille of m
    # form radius: from here up to the tip the flank is the involute
    # first radius from which 10 consecutive samples lie on the involute (isolated sampling outliers of
    # a few um higher up do not move it)
    runs = np.convolve(on_involute.astype(int), np.ones(10, dtype=int), mode="valid") == 10
    form_radius = float(radii[np.argmax(runs)]) if runs.any() else float(radii[0])
    right = np.column_stack([radii * np.sin(half), radii * np.cos(half)])
    tip_angles = np.linspace(half[-1], -half[-1], 20)
    tip = np.column_stack([ra * np.sin(tip_angles), ra * np.cos(tip_angles)])
    left = right[::-1] * np.array([-1.0, 1.0])
    outline = np.vstack([right, tip[1:-1], left])
    return {"right_flank": right, "radius": radii, "half_angle": half, "form_radius": form_radius,
            "outline": outline}
