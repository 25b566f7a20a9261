"""The bearing configurations of the thesis' test gearbox (van Roosmalen 1994, Sec. 5.8 and 5.9) as 6x6 matrices.

    configurations() -> {name: Configuration}
        "ball", "angular_contact", "self_aligning", "tapered_roller"  (single helical gear set B, Sec. 5.8)
        "cylindrical_roller", "fluid_film"                             (double helical gear set, Sec. 5.9)
    bearing_matrices(name, loads, speeds_rpm=None) -> {position: (K 6x6, C 6x6 or None)}
    evaluate(name, loads, speeds_rpm=None) -> {position: PositionResult} (the same plus operating points)
    representative_loads(gear_set) / REPRESENTATIVE_SPEEDS_RPM: the load case of the tests and docs table.

Positions "pinion_front", "pinion_back", "wheel_front", "wheel_back".  Frames and loads: each bearing's own frame,
z = shaft axis, DOF order (x, y, z, theta_x, theta_y, theta_z); `loads[position]` = (Fx, Fy, Fz, Mx, My) [N, N m]
applied by the shaft to the bearing (inner ring / journal), as everywhere in housingfe.bearings.  The caller's
convention: *_front is the locating bearing of its shaft and takes the axial force Fz (either sign), *_back is
floating and must get Fz = 0 (unless evaluate(..., floating_axial=True): a floating ring's friction-held axial
load).  ("front" here means "locating", not the physical side: which of the wheel's two seats locates is
`Configuration.wheel_locating`, the side the thesis states, placed by housingfe.drivetrain.description.)
K [N/m, N/rad, N m/rad], C [N s/m, ...];
row/column 6 (spin) is zero; K is symmetric for rolling bearings, non-symmetric for the fluid film.

Assumptions (also in docs/bearings.md):
  * Tilt held at zero (hold_tilt=True, default): a bearing on a shaft held by a second bearing has the tilt the
    shaft gives it, not a zero moment; the moment the zero tilt needs is in PositionResult.load.  This is what
    reproduces the signs of the thesis' own Sec. 4.6 matrices (see validation.py).  The Mx, My of `loads` must
    then be 0 (InputError otherwise); hold_tilt=False applies them and lets the ring tilt (for the single-row
    tapered bearings at the test gearbox load no equilibrium exists then: InputError).
  * ball: SKF 6316 (pinion) / 6219 (wheel) at all four positions, Lim's ball model (Sec. 5.1, 5.8).
  * angular_contact: SKF 7316 B / 7219 B at the locating positions, deep groove 6316 / 6219 at the floating
    ones (Sec. 5.8).  A single-row angular bearing carries Fz in one direction only: for Fz < 0 the bearing
    is mounted mirrored (z -> -z), i.e. K = T K(T f) T with T = diag(1, 1, -1, -1, -1, 1) (z and the tilts
    change sign under the reflection, x, y and the spin do not).  Fz = 0 with a radial load -> InputError.
  * self_aligning: SKF 21316 CC / 22219 CC at all four positions, moment rows/columns zero by construction
    (the thesis zeroed the moment terms of its ball matrices instead, Sec. 5.8).
  * tapered_roller: the thesis names no type ("taper roller bearings ... in combination with ball bearings ...
    only two of such bearings", Sec. 5.8).  Estimated catalogue entries SKF 30316 J2 / 30219 J2 (same d, D, B
    as 6316 / 6219; contact angle from the catalogue factor e; internal geometry estimated, see catalogue.py)
    at the locating positions with the sliced-roller model (Sec. 3.3.2), mirrored like the angular contact
    bearings, deep groove 6316 / 6219 at the floating positions.
  * cylindrical_roller: SKF NJ 316 (pinion) / NU 2219 (wheel) at all four positions, sliced-roller model
    (Sec. 5.9).  The roller-raceway contacts carry no axial load (Fz != 0 -> InputError) and give k_zz = 0
    exactly.  The NJ rib that locates the pinion is a contact without mean load (the double helix puts no
    axial force on it), so a Hertz contact would add nothing; a stand-in axial stiffness is added at the
    locating positions (axial_location, below) so that the shaft is not axially free.
  * fluid_film: the Sec. 3.5 plain journal bearings (pinion D 80.25 mm, L 56 mm, C 125 um; wheel D 95.2 mm,
    L 70 mm, C 100 um; eta 0.049 Pa s) at the given speed and radial load (Fx, Fy): eccentricity, K and C of
    x, y, theta_x, theta_y from the finite-length Reynolds equation with the Swift-Stieber condition
    (fluid_film.journal_bearing_coefficients: the tilt/moment coefficients are those of the misaligned
    journal, computed, not estimated).  fluid_film_model="ocvirk": the short-bearing K, C instead, with
    tilt coefficients from the radial ones spread uniformly over the length, k_tilt = L^2/12 [[k_yy, -k_yx],
    [-k_xy, k_xx]] (the same for C).  The film has no axial stiffness: the same axial stand-in as the
    cylindrical roller configuration is added (the thesis' pinion thrust bearings "only position the gears
    axially", like the NJ rib, Sec. 5.9), no axial damping.  The journal must be aligned: Mx = My = 0.
    speeds_rpm are signed: > 0 the shaft turns about +z of its bearing frame, < 0 about -z (counter-rotating
    shafts in frames with a common z); a reversed rotation is the reflection y -> -y of the film,
    K(-omega, W) = T K(+omega, P W) T with P = diag(1, -1), T = diag(1, -1, 1, -1, 1, -1).
    The thesis made K symmetric (mean of k_xy and k_yx) and dropped C for its FE model (Sec. 3.5); here both
    are returned as computed.
  * The wheel's locating side (Configuration.wheel_locating, the physical side of its locating seat): "back" for
    angular_contact (Sec. 5.8: "at the front (pinion) and at the back (wheel) of the gearbox") and tapered_roller
    ("the same reasons apply"); None where the text does not say (ball, self_aligning) and for the double helical
    configurations, whose wheel no bearing locates (Sec. 5.9).  The pinion is located at its front either way.
  * Axial stand-in (cylindrical_roller and fluid_film; axial_location): "thesis" (default) adds it at
    pinion_front only: the pinion is located, the wheel is positioned by the double helix of the mesh
    (Sec. 5.9), so the caller's model must couple the wheel axially to the pinion through the mesh (or its
    wheel shaft has a zero-frequency axial mode); "both" adds it at wheel_front too (stand-in for the mesh
    location), "none" adds nothing.  Value: locating_axial_stiffness [N/m] if given, else the mean radial
    stiffness (k_xx + k_yy)/2 of the NJ 316 (pinion) / NU 2219 (wheel) at that position's radial load (an
    order-of-magnitude rule: the rib taken as stiff as the roller set is radially; not a contact result).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from housingfe.errors import InputError

POSITIONS = ("pinion_front", "pinion_back", "wheel_front", "wheel_back")
SHAFT = {"pinion_front": "pinion", "pinion_back": "pinion", "wheel_front": "wheel", "wheel_back": "wheel"}
LOCATING = {"pinion_front": True, "pinion_back": False, "wheel_front": True, "wheel_back": False}
AXIAL_LOCATION = {"thesis": ("pinion_front",), "both": ("pinion_front", "wheel_front"), "none": ()}
# reflection z -> -z (mirrored angular bearing) and y -> -y (reversed rotation) on (x, y, z, bx, by, bz):
# forces transform as vectors, rotations as pseudovectors (extra factor det = -1)
MIRROR_Z = np.array([1.0, 1.0, -1.0, -1.0, -1.0, 1.0])
MIRROR_Y = np.array([1.0, -1.0, 1.0, -1.0, 1.0, -1.0])
# pinion turns +z, wheel -z in frames with a common z (the shafts counter-rotate); Sec. 3.5 speeds
REPRESENTATIVE_SPEEDS_RPM = {"pinion": 1500.0, "wheel": -500.0}


@dataclass(frozen=True)
class BearingChoice:
    """One bearing position of a configuration.

    kind "rolling" (designation from the catalogue) or "fluid_film" (journal: fluid_film.JournalBearing);
    model: the stiffness model ("lim-ball", "sliced-roller", "self-aligning", "reynolds" or "ocvirk" (chosen at
    evaluation for the fluid film)); locating: takes the axial force; directional: single-row angular bearing
    (carries Fz one way, mirrored for Fz < 0); estimated: what is not published (field: rule)."""
    position: str
    kind: str
    model: str
    locating: bool
    designation: str | None = None
    journal: object | None = None
    directional: bool = False
    estimated: tuple[str, ...] = ()
    note: str = ""


@dataclass(frozen=True)
class Configuration:
    """A bearing configuration of the test gearbox: name, description (with the thesis section), gear_set
    ("single_helical" Sec. 5.8 or "double_helical" Sec. 5.9), positions {position: BearingChoice}, and
    wheel_locating: the physical side of the gearbox ("front" | "back") at which the thesis puts the wheel's
    locating bearing, None where the text does not say; wheel_locating_source: the thesis' words, or why none."""
    name: str
    description: str
    gear_set: str
    positions: dict = field(default_factory=dict)
    wheel_locating: str | None = None
    wheel_locating_source: str = ""

    @property
    def wheel_side_uncertain(self) -> bool:
        """Whether the wheel's locating side is an input the text leaves open: a single helical set pushes the
        wheel axially onto one of its bearings, and the thesis does not say which.  (The double helical sets put no
        axial force on the wheel, Sec. 5.9: there the side only places the model's axial stand-in.)"""
        return self.wheel_locating is None and self.gear_set == "single_helical"


@dataclass
class PositionResult:
    """K, C of one position and how they were obtained.

    load: (Fx, Fy, Fz, Mx, My, Mz) the bearing takes [N, N m] (with held tilt: the moments the zero tilt
    needs); displacement: mean inner ring / journal displacement [m, rad]; mirrored: computed as the mirror
    image (angular bearing with Fz < 0, journal turning about -z); axial_added: the axial stand-in [N/m] added to
    K[2, 2] (0 if none); detail: the BearingResult / FluidFilmResult of the (unmirrored) computation."""
    position: str
    choice: BearingChoice
    K: np.ndarray
    C: np.ndarray | None
    load: np.ndarray
    displacement: np.ndarray
    mirrored: bool = False
    axial_added: float = 0.0
    detail: object = None


# ----------------------------------------------------------------------------------------- configurations
def _rolling(position: str, designation: str, model: str, note: str = "") -> BearingChoice:
    from housingfe.bearings.catalogue import lookup

    bearing = lookup(designation)
    directional = bearing.kind in ("ball", "tapered_roller") and bearing.contact_angle > 0 and bearing.rows == 1
    estimated = tuple(f"{key}: {rule}" for key, rule in bearing.estimated.items())
    return BearingChoice(position=position, kind="rolling", model=model, locating=LOCATING[position],
                         designation=bearing.designation, directional=directional, estimated=estimated,
                         note=note)


def journal_bearings() -> dict:
    """{"pinion": JournalBearing, "wheel": JournalBearing} of thesis Sec. 3.5 (housingfe/data/roosmalen1994.toml)."""
    from housingfe.bearings.fluid_film import JournalBearing
    from housingfe.data import thesis

    out = {}
    for shaft in ("pinion", "wheel"):
        d = thesis()["fluid_film_bearings"][shaft]
        out[shaft] = JournalBearing(d["D_mm"] * 1e-3, d["L_mm"] * 1e-3, d["radial_clearance_um"] * 1e-6,
                                    d["viscosity_Pa_s"])
    return out


def _journal(position: str) -> BearingChoice:
    journal = journal_bearings()[SHAFT[position]]
    axial = ("axial stiffness: stand-in at the locating position(s) (axial_location), the mean radial "
             "stiffness of the NJ 316 / NU 2219 at the same load; the film itself has none")
    estimated = ("coefficients: finite-length Reynolds equation instead of the thesis' graphs (Lund, Kikuchi, "
                 "Mukherjee & Rao), which are not in the text", axial)
    return BearingChoice(position=position, kind="fluid_film", model="reynolds", locating=LOCATING[position],
                         journal=journal, estimated=estimated,
                         note="plain journal bearing, Sec. 3.5 / 5.9 (pinion Glyco E-135-80, wheel Glacier 095 KSA 070)")


# The wheel's locating side per configuration (Configuration.wheel_locating): taken from the thesis text where it
# states it, never from which side makes a variant agree with the measurement; where the text is silent it stays
# None (the drivetrain then locates the wheel at its front bearing, and `housingfe uncertainty` draws the side).
_STATED = {
    "angular_contact": 'Sec. 5.8: "On every shaft an angular contact ball bearing was situated at the shaft side '
                       'where the axial force is encountered by the bearings ... The angular contact ball bearings '
                       'were situated at the front (pinion) and at the back (wheel) of the gearbox."',
    "tapered_roller": 'Sec. 5.8: "The same reasons apply as for the angular contact ball bearings to use only two '
                      'of such bearings" (the angular contact ones: "at the front (pinion) and at the back (wheel)")',
}
_UNSTATED = {
    "ball": "not stated: Sec. 5.8 does not say which of the reference's deep groove ball bearings takes the axial "
            "force",
    "self_aligning": "not stated: Sec. 5.8 puts SKF 21316 CC / 22219 CC at all four positions and does not say "
                     "which takes the axial force",
    "double_helical": 'no wheel bearing locates: "both wheel bearings can freely move in axial direction. The '
                      'wheel is axially positioned by the double helix of the gear mesh" (Sec. 5.9); the double '
                      "helical set puts no axial load on them, the side only places the model's axial stand-in",
}


def configurations() -> dict[str, Configuration]:
    """The six bearing configurations of the test gearbox (assumptions: module docstring)."""
    pin, whl = "SKF 6316", "SKF 6219"
    ball = {p: _rolling(p, pin if SHAFT[p] == "pinion" else whl, "lim-ball") for p in POSITIONS}
    configs = [
        Configuration("ball", "Deep groove ball bearings SKF 6316 (pinion) / 6219 (wheel) at all four positions; "
                      "the reference configuration (thesis Sec. 5.1, 5.8)", "single_helical", ball,
                      None, _UNSTATED["ball"]),
        Configuration("angular_contact", "Single-row angular contact ball bearings SKF 7316 B (pinion) / 7219 B "
                      "(wheel) at the locating positions, deep groove 6316 / 6219 at the floating ones "
                      "(thesis Sec. 5.8)", "single_helical",
                      {"pinion_front": _rolling("pinion_front", "SKF 7316B", "lim-ball",
                                                "mirrored (z -> -z) when Fz < 0"),
                       "pinion_back": ball["pinion_back"],
                       "wheel_front": _rolling("wheel_front", "SKF 7219B", "lim-ball",
                                               "mirrored (z -> -z) when Fz < 0"),
                       "wheel_back": ball["wheel_back"]},
                      # Sec. 5.8 (thesis text l. 2091): "The angular contact ball bearings were situated at the
                      # front (pinion) and at the back (wheel) of the gearbox."
                      "back", _STATED["angular_contact"]),
        Configuration("self_aligning", "Double-row self-aligning (spherical) roller bearings SKF 21316 CC "
                      "(pinion) / 22219 CC (wheel) at all four positions, zero moment stiffness (thesis Sec. 5.8)",
                      "single_helical",
                      {p: _rolling(p, "SKF 21316CC" if SHAFT[p] == "pinion" else "SKF 22219CC", "self-aligning")
                       for p in POSITIONS}, None, _UNSTATED["self_aligning"]),
        Configuration("tapered_roller", "Single-row taper roller bearings at the locating positions (estimated "
                      "SKF 30316 J2 / 30219 J2, sliced-roller model of Sec. 3.3.2), deep groove 6316 / 6219 at "
                      "the floating ones (thesis Sec. 5.8)", "single_helical",
                      {"pinion_front": _rolling("pinion_front", "SKF 30316 J2", "sliced-roller",
                                                "type not in the thesis: estimated; mirrored when Fz < 0"),
                       "pinion_back": ball["pinion_back"],
                       "wheel_front": _rolling("wheel_front", "SKF 30219 J2", "sliced-roller",
                                               "type not in the thesis: estimated; mirrored when Fz < 0"),
                       "wheel_back": ball["wheel_back"]},
                      # Sec. 5.8 (thesis text l. 2100): "The same reasons apply as for the angular contact ball
                      # bearings to use only two of such bearings" -- i.e. at the side where each shaft's axial
                      # force is met, the wheel's at the back (l. 2091)
                      "back", _STATED["tapered_roller"]),
        Configuration("cylindrical_roller", "Single-row cylindrical roller bearings SKF NJ 316 (pinion) / NU 2219 "
                      "(wheel) at all four positions, double helical gears without axial load (thesis Sec. 5.9)",
                      "double_helical",
                      {p: _rolling(p, "SKF NJ316" if SHAFT[p] == "pinion" else "SKF NU2219", "sliced-roller",
                                   "no axial load; axial stand-in at the locating position(s)")
                       for p in POSITIONS}, None, _UNSTATED["double_helical"]),
        Configuration("fluid_film", "Plain fluid-film journal bearings of thesis Sec. 3.5 at all four positions, "
                      "double helical gears (thesis Sec. 5.9)", "double_helical",
                      {p: _journal(p) for p in POSITIONS}, None, _UNSTATED["double_helical"]),
    ]
    return {c.name: c for c in configs}


# ----------------------------------------------------------------------------------------- loads
def representative_loads(gear_set: str = "single_helical", pinion_torque: float = 1910.0) -> dict[str, tuple]:
    """The representative test gearbox load case of the tests and the docs table (Appendix F tooth forces).

    Circumferential F_t (38918 N single / 38136 N double helical at 1910 N m, scaled with the torque), radial
    F_r = F_t tan(alpha_wt) with the operating transverse pressure angle (23.099 / 23.250 deg), axial F_a
    (8272 N / 0).  Half of the radial and circumferential force on each bearing of a shaft, F_a on the locating
    (front) bearing.  Frames (stated, any other is the caller's choice): common z for both shafts, x along the
    circumferential force on the pinion, y along the line of centres; pinion bearings (F_t/2, -F_r/2, F_a on the
    front), wheel bearings the reaction (-F_t/2, +F_r/2, -F_a on the front); no moments."""
    from housingfe.data import thesis

    if gear_set not in ("single_helical", "double_helical"):
        raise InputError(f"gear_set={gear_set!r}: must be 'single_helical' or 'double_helical'")
    g = thesis()["gears"][gear_set]
    scale = pinion_torque / g["torque_Nm"][0]
    ft = g["circumferential_tooth_load_N"] * scale
    fr = ft * math.tan(math.radians(g["operating_transverse_pressure_angle_deg"]))
    fa = g["axial_tooth_load_N"] * scale
    return {"pinion_front": (ft / 2, -fr / 2, fa, 0.0, 0.0), "pinion_back": (ft / 2, -fr / 2, 0.0, 0.0, 0.0),
            "wheel_front": (-ft / 2, fr / 2, -fa, 0.0, 0.0), "wheel_back": (-ft / 2, fr / 2, 0.0, 0.0, 0.0)}


def _check_loads(name: str, loads, floating_axial: bool = False) -> dict[str, np.ndarray]:
    if not isinstance(loads, dict):
        raise InputError(f"{name}: loads: need a dict {{position: (Fx, Fy, Fz, Mx, My)}}")
    unknown = sorted(set(loads) - set(POSITIONS))
    missing = [p for p in POSITIONS if p not in loads]
    if unknown or missing:
        raise InputError(f"{name}: loads: positions must be {', '.join(POSITIONS)} "
                         f"(unknown: {unknown or 'none'}, missing: {missing or 'none'})")
    out = {}
    for p in POSITIONS:
        f = np.asarray(loads[p], dtype=float).ravel()
        if f.size == 6 and f[5] == 0.0:
            f = f[:5]
        if f.size != 5 or not np.all(np.isfinite(f)):
            raise InputError(f"{name} {p}: load {np.asarray(loads[p]).tolist()}: need 5 finite values "
                             "(Fx, Fy, Fz, Mx, My) in N, N m")
        if not LOCATING[p] and f[2] != 0.0 and not floating_axial:
            raise InputError(f"{name} {p}: Fz={f[2]} N: the back bearing of a shaft is the floating one and "
                             "takes no axial force (put Fz on the *_front bearing)")
        out[p] = f
    return out


# ----------------------------------------------------------------------------------------- evaluation
def evaluate(name: str, loads, speeds_rpm=None, *, hold_tilt: bool = True, axial_location: str = "thesis",
             locating_axial_stiffness: float | None = None,
             fluid_film_model: str = "reynolds", floating_axial: bool = False) -> dict[str, PositionResult]:
    """K (and C) of every position of configuration `name` at the mean loads (see the module docstring).

    loads {position: (Fx, Fy, Fz, Mx, My)} [N, N m]; speeds_rpm {"pinion": n1, "wheel": n2} [rev/min, signed]
    (fluid film only); hold_tilt, axial_location ("thesis", "both", "none"), locating_axial_stiffness [N/m]
    and fluid_film_model ("reynolds", "ocvirk"): module docstring.  floating_axial: accept an axial load Fz on the
    floating (*_back) positions too (the friction-held load of a floating ring that sticks in its bore,
    housingfe.drivetrain.description.Drivetrain.floating_axial_ratio); a position whose bearing cannot carry it
    (cylindrical roller, fluid film) still refuses it.  Raises InputError naming the configuration,
    position and bearing for a load the bearing cannot carry or a bad argument."""
    configs = configurations()
    if name not in configs:
        raise InputError(f"bearing configuration {name!r}: must be one of {', '.join(configs)}")
    if axial_location not in AXIAL_LOCATION:
        raise InputError(f"{name}: axial_location={axial_location!r}: must be one of {', '.join(AXIAL_LOCATION)}")
    if fluid_film_model not in ("reynolds", "ocvirk"):
        raise InputError(f"{name}: fluid_film_model={fluid_film_model!r}: must be 'reynolds' or 'ocvirk'")
    if locating_axial_stiffness is not None and not (locating_axial_stiffness >= 0
                                                     and math.isfinite(locating_axial_stiffness)):
        raise InputError(f"{name}: locating_axial_stiffness={locating_axial_stiffness}: must be >= 0 N/m")
    config = configs[name]
    f_all = _check_loads(name, loads, floating_axial)
    out = {}
    for position, choice in config.positions.items():
        f = f_all[position]
        label = f"{name} {position} ({choice.designation or 'journal bearing'})"
        if hold_tilt and np.any(f[3:5] != 0.0):
            raise InputError(f"{label}: Mx={f[3]}, My={f[4]} N m given but the tilt is held at zero "
                             "(hold_tilt=True): pass zero moments or hold_tilt=False")
        try:
            if choice.kind == "rolling":
                res = _rolling_result(choice, f, hold_tilt)
            else:
                res = _fluid_film_result(choice, f, speeds_rpm, fluid_film_model)
        except InputError as err:
            raise InputError(f"{label}: {err}") from None
        if config.gear_set == "double_helical" and position in AXIAL_LOCATION[axial_location]:
            k_ax = locating_axial_stiffness
            if k_ax is None:
                k_ax = _axial_stand_in(position, f, label)
            res.K[2, 2] += k_ax
            res.axial_added = k_ax
        res.K[5, :] = 0.0
        res.K[:, 5] = 0.0
        out[position] = res
    return out


def carries(name: str, position: str, load, hold_tilt: bool = True) -> bool:
    """Whether the bearing of configuration `name` at `position` finds an equilibrium under `load` (Fx, Fy, Fz, Mx,
    My) [N, N m] in its frame -- the bearing model of `evaluate` itself (a single-row angular contact or tapered roller
    bearing needs enough Fz for its radial load).  A fluid-film position: True (it takes no axial load in any case)."""
    configs = configurations()
    if name not in configs or position not in configs[name].positions:
        raise InputError(f"bearing configuration {name!r}: no position {position!r}")
    choice = configs[name].positions[position]
    if choice.kind != "rolling":
        return True
    try:
        _rolling_result(choice, np.asarray(load, float).ravel()[:5], hold_tilt)
    except InputError:
        return False
    return True


def bearing_matrices(name: str, loads, speeds_rpm=None, **options) -> dict[str, tuple]:
    """{position: (K 6x6, C 6x6 or None)} of configuration `name` in each bearing's frame (see evaluate)."""
    return {p: (r.K, r.C) for p, r in evaluate(name, loads, speeds_rpm, **options).items()}


def _rolling_result(choice: BearingChoice, f: np.ndarray, hold_tilt: bool) -> PositionResult:
    from housingfe.bearings import bearing_stiffness

    mirrored = choice.directional and f[2] < 0.0
    t = MIRROR_Z[:5] if mirrored else np.ones(5)
    if choice.directional and f[2] == 0.0 and np.any(f[:2] != 0.0):
        raise InputError(f"Fz = 0: a single-row angular bearing needs an axial load to carry the radial "
                         f"load {f[:2].tolist()} N (it sits at a locating position: give it the shaft's Fz)")
    res = bearing_stiffness(choice.designation, t * f, model=choice.model,
                            fixed_tilt=(0.0, 0.0) if hold_tilt else None)
    tt = np.append(t, 1.0)
    k = tt[:, None] * res.K * tt[None, :]
    return PositionResult(position=choice.position, choice=choice, K=k, C=None, load=tt * res.load,
                          displacement=tt * res.displacement, mirrored=bool(mirrored), detail=res)


def _fluid_film_result(choice: BearingChoice, f: np.ndarray, speeds_rpm, model: str) -> PositionResult:
    from housingfe.bearings.fluid_film import journal_bearing_coefficients, short_bearing_coefficients

    shaft = SHAFT[choice.position]
    if not isinstance(speeds_rpm, dict) or shaft not in speeds_rpm:
        raise InputError(f"speeds_rpm: need {{'pinion': n1, 'wheel': n2}} in rev/min for the fluid film "
                         f"(got {speeds_rpm!r})")
    n = float(speeds_rpm[shaft])
    if not (math.isfinite(n) and n != 0.0):
        raise InputError(f"speeds_rpm[{shaft!r}]={n}: a plain bearing needs rotation (n != 0)")
    if f[2] != 0.0:
        raise InputError(f"Fz={f[2]} N: the fluid-film configuration is the double helical set without axial "
                         "load; the thrust bearings are only represented by the axial stand-in")
    if np.any(f[3:5] != 0.0):
        raise InputError(f"Mx={f[3]}, My={f[4]} N m: the journal is taken as aligned (no misaligned "
                         "equilibrium); give zero moments")
    reverse = n < 0.0
    w = f[:2] * (MIRROR_Y[:2] if reverse else 1.0)
    omega = abs(n) * 2.0 * math.pi / 60.0
    journal = choice.journal
    if model == "reynolds":
        res = journal_bearing_coefficients(journal, omega, w)
        k, c = res.K.copy(), res.C.copy()
    else:
        res = short_bearing_coefficients(journal, omega, w)
        k, c = res.K.copy(), res.C.copy()
        for m in (k, c):
            m[3:5, 3:5] = journal.length**2 / 12.0 * np.array([[m[1, 1], -m[1, 0]], [-m[0, 1], m[0, 0]]])
    t = MIRROR_Y if reverse else np.ones(6)
    k = t[:, None] * k * t[None, :]
    c = t[:, None] * c * t[None, :]
    load = np.zeros(6)
    load[:2] = f[:2]
    return PositionResult(position=choice.position, choice=choice, K=k, C=c, load=load,
                          displacement=t * res.displacement, mirrored=reverse, detail=res)


def _axial_stand_in(position: str, f: np.ndarray, label: str) -> float:
    """Mean radial stiffness (k_xx + k_yy)/2 of the NJ 316 / NU 2219 at the position's radial load."""
    from housingfe.bearings import bearing_stiffness

    designation = "SKF NJ316" if SHAFT[position] == "pinion" else "SKF NU2219"
    try:
        k = bearing_stiffness(designation, (f[0], f[1], 0.0, 0.0, 0.0), model="sliced-roller",
                              fixed_tilt=(0.0, 0.0)).K
    except InputError as err:
        raise InputError(f"{label}: axial stand-in from {designation}: {err}") from None
    return 0.5 * (k[0, 0] + k[1, 1])


def diagonal_table(results: dict[str, dict[str, PositionResult]]) -> str:
    """Markdown table of the diagonal stiffnesses {configuration: evaluate(...)} (for the docs)."""
    head = "| configuration | position | bearing | k_xx [N/m] | k_yy [N/m] | k_zz [N/m] | k_θxθx [N m/rad] | " \
           "k_θyθy [N m/rad] |"
    lines = [head, "|" + "---|" * 8]
    for name, per_position in results.items():
        for p, r in per_position.items():
            d = np.diag(r.K)
            bearing = r.choice.designation or "journal (Sec. 3.5)"
            if r.mirrored:
                bearing += " (mirrored)"
            lines.append(f"| {name} | {p} | {bearing} | " + " | ".join(f"{v:.3g}" for v in d[:5]) + " |")
    return "\n".join(lines)


def main() -> None:
    """Print the diagonal table of every configuration at the representative load (docs/bearings.md)."""
    results = {name: evaluate(name, representative_loads(c.gear_set), REPRESENTATIVE_SPEEDS_RPM)
               for name, c in configurations().items()}
    print(diagonal_table(results))


if __name__ == "__main__":
    main()
