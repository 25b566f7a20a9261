"""The bearings van Roosmalen (1994) uses, from their boundary dimensions.

Public catalogue data: bore d, outside diameter D, width B (SKF), the contact angle of the 7xxx B series (40 deg)
and, for SKF 6312 / 6215, the number and diameter of the balls printed in thesis Sec. 4.6.  Everything else is
internal geometry that SKF does not publish; it is estimated by the rules below and listed in each entry's
`estimated` dict (field -> rule), so every result can say which inputs are guesses.

Estimation rules (stated before any result was computed, not tuned to any published stiffness):
  pitch diameter      d_m = (d + D) / 2.
  ball diameter       D_w = 0.3175 (D - d), rounded to the nearest 1/32 inch (ratio of the two bearings whose
                      balls the thesis prints: 22.22/70 = 0.3174, 17.46/55 = 0.3175).
  number of balls     Z = round(0.596 pi d_m / D_w) for deep groove bearings (fill factor of the two printed
                      bearings: 0.596 both); 0.70 for angular contact bearings (filled from one side, more balls).
  groove curvature    f_i = 0.52, f_o = 0.53 (Harris' typical values for deep groove and angular contact).
  radial clearance    deep groove: half the mid-range ISO 5753-1 Group N (CN) diametral clearance;
                      angular contact (adjusted in pairs): 0; roller bearings: half the mid-range CN value.
  cylindrical rollers D_w = 0.26 (D - d), effective length 0.6 B, Z = round(0.80 pi d_m / D_w).
  spherical rollers   two rows, D_w = 0.22 (D - d), length per row 0.4 B, Z per row = round(0.80 pi d_m / D_w),
                      contact angle 9 deg (from a typical SKF calculation factor e = 1.5 tan(alpha) ~ 0.24).
  tapered rollers     (SKF 30316 J2, 30219 J2: not named by the thesis, which only says "taper roller bearings",
                      Sec. 5.8; chosen as the single-row series with the same d, D and cone width B as the
                      6316 / 6219 and 7316 B / 7219 B they replace, see _TAPERED.)  Cup contact angle from the
                      catalogue calculation factor e = 1.5 tan(alpha); mean roller diameter D_w = 0.22 (D - d)
                      (the spherical-roller ratio: the raceways are inclined and the cone carries a large rib),
                      effective length 0.6 B and Z = round(0.80 pi d_m / D_w) as for cylindrical rollers;
                      one contact angle for both raceways (the rollers taken as cylinders, thesis Sec. 3.3.2);
                      radial clearance 0 (adjusted against the ball bearing at the other end of the shaft, like
                      the angular contact bearings).
  material            bearing steel youngs_modulus = 208 GPa, poisson_ratio = 0.3 (rolling.BEARING_STEEL_*).
"""
from __future__ import annotations

import contextvars
import math
from contextlib import contextmanager
from typing import TYPE_CHECKING

from housingfe.errors import InputError

if TYPE_CHECKING:
    from housingfe.bearings.rolling import RollingBearing

_INCH = 25.4e-3
_MM = 1e-3
_UM = 1e-6

# designation: kind, d, D, B [mm], contact angle [deg], published (Z, D_w [mm]) or None, CN diametral
# clearance range [um] (ISO 5753-1 Group N, estimated)
_BOUNDARY = {
    "6312": ("ball", 60, 130, 31, 0.0, (8, 22.22), (11, 28)),
    "6215": ("ball", 75, 130, 25, 0.0, (11, 17.46), (12, 36)),
    "6316": ("ball", 80, 170, 39, 0.0, None, (12, 36)),
    "6219": ("ball", 95, 170, 32, 0.0, None, (18, 43)),
    "7316B": ("ball", 80, 170, 39, 40.0, None, None),
    "7219B": ("ball", 95, 170, 32, 40.0, None, None),
    "21316CC": ("spherical_roller", 80, 170, 39, None, None, (55, 75)),
    "22219CC": ("spherical_roller", 95, 170, 43, None, None, (65, 90)),
    "NJ316": ("cylindrical_roller", 80, 170, 39, 0.0, None, (40, 70)),
    "NU2219": ("cylindrical_roller", 95, 170, 43, 0.0, None, (45, 75)),
    "30316J2": ("tapered_roller", 80, 170, 39, None, None, None),
    "30219J2": ("tapered_roller", 95, 170, 32, None, None, None),
}

# single-row tapered roller bearings: total width T, cup width C [mm], calculation factors e, Y (SKF catalogue
# values as recalled, NOT checked against the catalogue: the search found SKF tables of the same series for
# small bores only, e.g. 30204 J2: e = 0.35, Y = 1.7).  d, D, B are in _BOUNDARY; alpha = atan(e / 1.5).
# Why not the steep 31316 J2 (e = 0.83, Y = 0.72): at the test gearbox load (Fr = 21.2 kN per bearing,
# Fa = 8272 N) a single bearing needs Fa >= 0.5 Fr / Y, i.e. 6.2 kN (30316 J2), 7.6 kN (30219 J2) but 14.7 kN
# (31316 J2): the steep bearing cannot run alone at the locating position.
_TAPERED = {
    "30316J2": {"T": 42.5, "C": 33.0, "e": 0.35, "Y": 1.7},
    "30219J2": {"T": 34.5, "C": 27.0, "e": 0.43, "Y": 1.4},
}

_SPHERICAL_CONTACT_ANGLE_DEG = 9.0

# the estimated internals in effect (`estimated_internals`); None: the rules of the module docstring
_INTERNALS: contextvars.ContextVar = contextvars.ContextVar("bearing_internals", default=None)
INTERNAL_KEYS = ("clearance_position", "groove_inner", "groove_outer", "spherical_contact_angle_deg",
                 "tapered_e_scale", "roller_profile")


@contextmanager
def estimated_internals(**values):
    """Within the block, `lookup` builds bearings with other values of the ESTIMATED internals (uncertainty studies,
    housingfe.studies.uncertainty); published data (d, D, B, the 7xxx B contact angle, the printed ball sets) stay.

    clearance_position: where in the ISO 5753-1 Group N diametral clearance range [0 = lowest, 1 = highest] the
    radial clearance (half the diametral) sits (the rule: 0.5, mid-range; bearings adjusted to 0 stay at 0);
    groove_inner, groove_outer: groove curvature ratios f_i, f_o (rule 0.52, 0.53); spherical_contact_angle_deg
    (rule 9 deg); tapered_e_scale: factor on the recalled calculation factor e of the tapered rollers (rule 1);
    roller_profile: "straight" (rule: full line contact, as the thesis) or "logarithmic" (ISO/TS 16281 crown) for
    every roller bearing.  Unknown keys -> InputError."""
    unknown = sorted(set(values) - set(INTERNAL_KEYS))
    if unknown:
        raise InputError(f"estimated_internals: {', '.join(unknown)} unknown (known: {', '.join(INTERNAL_KEYS)})")
    token = _INTERNALS.set(dict(values))
    try:
        yield
    finally:
        _INTERNALS.reset(token)


def internals_in_effect() -> tuple:
    """The estimated internals `estimated_internals` sets here, as a hashable key ((name, value), ... sorted; () for
    the rules): what a cache of results of the bearing models must hold beside the loads."""
    values = _INTERNALS.get()
    return () if values is None else tuple(sorted(values.items()))


def _internal(key: str, rule: float) -> float:
    values = _INTERNALS.get()
    return rule if values is None else float(values.get(key, rule))


def _roller_profile(est: dict) -> str:
    """The roller profile in effect (rule: straight), noted in `est`."""
    values = _INTERNALS.get()
    profile = "straight" if values is None else str(values.get("roller_profile", "straight"))
    est["roller_profile"] = ("straight: full line contact (the thesis' rollers; SKF publishes no profile)"
                             if profile == "straight" else
                             f"{profile}: ISO/TS 16281 default crown (the real profile is not published)")
    return profile


def normalise(designation: str) -> str:
    """'SKF 7316 B' -> '7316B' (upper case, no spaces, no 'SKF' prefix)."""
    key = designation.upper().replace(" ", "").replace("-", "")
    return key.removeprefix("SKF")


def designations() -> list[str]:
    """The catalogue's designations (SKF spelling without spaces)."""
    return list(_BOUNDARY)


def _ball_diameter(d: float, outer: float) -> float:
    return round(0.3175 * (outer - d) / (_INCH / 32.0)) * _INCH / 32.0


def lookup(designation: str) -> RollingBearing:
    """RollingBearing for a catalogue designation (e.g. 'SKF 6312'); unknown -> InputError."""
    from housingfe.bearings.rolling import RollingBearing  # scipy-heavy: keep `housingfe --help` fast

    key = normalise(designation)
    if key not in _BOUNDARY:
        raise InputError(f"bearing designation {designation!r}: not in the catalogue "
                         f"(known: {', '.join(_BOUNDARY)})")
    kind, d, outer, width, alpha_deg, published, clearance = _BOUNDARY[key]
    if kind == "tapered_roller":
        return _tapered(key, d, outer, width)
    d, outer, width = d * _MM, outer * _MM, width * _MM
    pitch = (d + outer) / 2.0
    est = {"pitch_diameter": "(d + D) / 2", "youngs_modulus": "bearing steel 208 GPa", "poisson_ratio": "0.3"}
    name = f"SKF {key}"
    position = _internal("clearance_position", 0.5)
    radial_clearance = 0.0 if clearance is None else \
        0.5 * (clearance[0] + position * (clearance[1] - clearance[0])) * _UM
    if clearance is not None:
        est["radial_clearance"] = f"half of the mid-range ISO 5753-1 Group N diametral clearance {clearance} um"
    else:
        est["radial_clearance"] = "0 (angular contact, adjusted against its partner)"
    if kind == "ball":
        if published:
            z, dw = published[0], published[1] * _MM
        else:
            dw = _ball_diameter(d, outer)
            fill = 0.596 if alpha_deg == 0 else 0.70
            z = round(fill * math.pi * pitch / dw)
            est["element_diameter"] = "0.3175 (D - d), nearest 1/32 inch"
            est["n_elements"] = f"round({fill} pi d_m / D_w)"
        est["groove_inner"] = "0.52 (Harris typical)"
        est["groove_outer"] = "0.53 (Harris typical)"
        return RollingBearing(designation=name, kind=kind, bore=d, outer_diameter=outer, width=width,
                              n_elements=z, element_diameter=dw, pitch_diameter=pitch,
                              contact_angle=math.radians(alpha_deg), radial_clearance=radial_clearance,
                              groove_inner=_internal("groove_inner", 0.52),
                              groove_outer=_internal("groove_outer", 0.53), estimated=est)
    if kind == "cylindrical_roller":
        dw = 0.26 * (outer - d)
        z = round(0.80 * math.pi * pitch / dw)
        est.update(element_diameter="0.26 (D - d)", roller_length="0.6 B", n_elements="round(0.80 pi d_m / D_w)")
        return RollingBearing(designation=name, kind=kind, bore=d, outer_diameter=outer, width=width,
                              n_elements=z, element_diameter=dw, pitch_diameter=pitch, contact_angle=0.0,
                              radial_clearance=radial_clearance, roller_length=0.6 * width,
                              roller_profile=_roller_profile(est), estimated=est)
    dw = 0.22 * (outer - d)
    z = round(0.80 * math.pi * pitch / dw)
    est.update(element_diameter="0.22 (D - d)", roller_length="0.4 B per row",
               n_elements="round(0.80 pi d_m / D_w) per row",
               contact_angle=f"{_SPHERICAL_CONTACT_ANGLE_DEG} deg (e = 1.5 tan(alpha) ~ 0.24)")
    return RollingBearing(designation=name, kind=kind, bore=d, outer_diameter=outer, width=width, n_elements=z,
                          element_diameter=dw, pitch_diameter=pitch,
                          contact_angle=math.radians(_internal("spherical_contact_angle_deg",
                                                               _SPHERICAL_CONTACT_ANGLE_DEG)),
                          radial_clearance=radial_clearance, roller_length=0.4 * width, rows=2,
                          roller_profile=_roller_profile(est), estimated=est)


def _tapered(key: str, d: float, outer: float, width: float) -> RollingBearing:
    from housingfe.bearings.rolling import RollingBearing

    data = _TAPERED[key]
    d, outer, width = d * _MM, outer * _MM, width * _MM
    pitch = (d + outer) / 2.0
    dw = 0.22 * (outer - d)
    z = round(0.80 * math.pi * pitch / dw)
    alpha = math.atan(data["e"] * _internal("tapered_e_scale", 1.0) / 1.5)
    est = {"pitch_diameter": "(d + D) / 2", "youngs_modulus": "bearing steel 208 GPa", "poisson_ratio": "0.3",
           "element_diameter": "0.22 (D - d) (mean roller diameter)", "roller_length": "0.6 B",
           "n_elements": "round(0.80 pi d_m / D_w)",
           "contact_angle": f"atan(e / 1.5) with e = {data['e']} (SKF value recalled, not checked); one angle "
                            "for both raceways (rollers as cylinders, thesis Sec. 3.3.2)",
           "radial_clearance": "0 (adjusted against the ball bearing at the other end of the shaft)"}
    return RollingBearing(designation=f"SKF {key[:-2]} {key[-2:]}", kind="tapered_roller", bore=d,
                          outer_diameter=outer, width=width, n_elements=z, element_diameter=dw,
                          pitch_diameter=pitch, contact_angle=alpha, radial_clearance=0.0,
                          roller_length=0.6 * width, roller_profile=_roller_profile(est), estimated=est)


def tapered_data(designation: str) -> dict:
    """Total width T and cup width C [mm] and the calculation factors e, Y of a catalogue tapered roller
    bearing (the values the entry's contact angle comes from)."""
    key = normalise(designation)
    if key not in _TAPERED:
        raise InputError(f"bearing designation {designation!r}: not a tapered roller bearing of the catalogue "
                         f"(known: {', '.join(_TAPERED)})")
    return dict(_TAPERED[key])
