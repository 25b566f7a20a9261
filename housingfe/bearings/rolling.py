"""Rolling-element bearing stiffness matrices after Lim (van Roosmalen 1994, Sec. 3.2, 3.3, Appendix D).

Axis convention (the same for every model and for the 6x6 results):
  z is the shaft (bearing) axis, x and y are radial; DOF order (dx, dy, dz, bx, by, bz).
  `load` = (Fx, Fy, Fz, Mx, My) is the mean force [N] and moment [N m] the shaft applies to the inner ring;
  `displacement` is the rigid-body motion of the inner ring relative to the outer ring [m, rad];
  K = d(load)/d(displacement) [N/m, N/rad (= N m/m), N m/rad], symmetric, torsional row/column bz zero.
  Rolling element j sits at psi_j = 2 pi j / Z from the x-axis (thesis Fig. 3.1).

Models:
  "lim-ball"      Eqs. (3.1)-(3.12), Appendix D (C-1): ball on raceway groove curvature centres, n = 3/2,
                  K_n from Hertz point contact (hertz.ball_effective_stiffness).
  "lim-roller"    Eqs. (3.13)-(3.14), (C-2): fixed contact angle, n = 10/9, K_n from Palmgren's line contact.
                  Tilt stiffness is zero for alpha0 = 0 (the defect Sec. 3.3.2 points out).
  "sliced-roller" Sec. 3.3.2: every roller cut into slices along its length, each slice with the
                  Weber–Banaschek law Eq. (3.17); the approach of slice a is delta_j - a * gamma_j (rigid rings).
  "self-aligning" Double-row spherical roller bearing: two rows of Lim rollers at +-alpha0 whose contact
                  normals pass through the centre of the spherical outer raceway, so a tilt loads no element
                  and the moment rows/columns of K are zero by construction (as the thesis did, Sec. 5.8).

The mean displacement is solved by Newton–Raphson (Eqs. (3.11)-(3.12)) with the analytic Jacobian.  The
bearing is conservative and its elastic energy is convex in the displacement, so Newton's step is
safeguarded by a line search on the potential energy U(q) - f.q; a load the bearing cannot carry
makes that energy unbounded below and is reported as InputError.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize

from housingfe.bearings import hertz
from housingfe.errors import InputError

DOF_NAMES = ("x", "y", "z", "theta_x", "theta_y", "theta_z")
ROLLER_PROFILES = ("straight", "logarithmic")


# Bearing steel (through-hardened 100Cr6 / AISI 52100): E = 208 GPa, nu = 0.3.  Handbook values for this steel
# lie between about 200 and 210 GPa; a ball contact's stiffness goes with E^(2/3), so that spread moves K by
# under 3 %.  The same names as the scenes' [material] tables.
BEARING_STEEL_YOUNGS_MODULUS = 208e9
BEARING_STEEL_POISSON_RATIO = 0.3


@dataclass(frozen=True)
class RollingBearing:
    """Geometry of a rolling-element bearing (SI units: m, rad, Pa).

    kind: "ball", "cylindrical_roller", "tapered_roller" or "spherical_roller" (double-row self-aligning).
    n_elements: Z per row; element_diameter: D_w [m]; pitch_diameter: d_pw [m] (required, although they
    follow bore, outer_diameter and width positionally for backwards compatibility).
    bore, outer_diameter, width [m]: boundary dimensions, optional (no model uses them; when given they are
    checked against the internal geometry).
    contact_angle: unloaded contact angle alpha0 [rad] (ball: 0 for deep groove; the clearance is radial_clearance).
    radial_clearance: Lim's r_L [m], the radial play of the unloaded, centred rings (half the diametral one).
    groove_inner/groove_outer: groove conformities f_i = r_i / D_w, f_o = r_o / D_w [-], > 0.5 (balls only).
    roller_length: effective contact length of one roller [m] (rollers only).
    roller_profile: "straight" (full line contact, the thesis' rollers; default) or "logarithmic" (the
    ISO/TS 16281 crowned profile, hertz.logarithmic_profile_drop; rollers cut into `profile_slices` laminae).
    youngs_modulus [Pa], poisson_ratio [-]: rings and elements (default bearing steel, 208 GPa, 0.3).
    estimated: {field name: estimation rule} for every value that is not public catalogue data.
    """
    designation: str
    kind: str
    bore: float | None = None
    outer_diameter: float | None = None
    width: float | None = None
    n_elements: int | None = None
    element_diameter: float | None = None
    pitch_diameter: float | None = None
    contact_angle: float = 0.0
    radial_clearance: float = 0.0
    groove_inner: float = 0.52
    groove_outer: float = 0.53
    roller_length: float = 0.0
    rows: int = 1
    roller_profile: str = "straight"
    profile_slices: int = 20
    youngs_modulus: float = BEARING_STEEL_YOUNGS_MODULUS
    poisson_ratio: float = BEARING_STEEL_POISSON_RATIO
    estimated: dict = field(default_factory=dict, compare=False, hash=False)

    def __post_init__(self):
        name = self.designation or "bearing"
        if self.kind not in ("ball", "cylindrical_roller", "tapered_roller", "spherical_roller"):
            raise InputError(f"{name}: kind={self.kind!r}: must be ball, cylindrical_roller, "
                             "tapered_roller or spherical_roller")
        for key in ("n_elements", "element_diameter", "pitch_diameter"):
            if getattr(self, key) is None:
                raise InputError(f"{name}: {key}: missing (the internal geometry Z, D_w, d_pw is required)")
        positive = {"element_diameter": self.element_diameter, "pitch_diameter": self.pitch_diameter}
        positive.update({k: getattr(self, k) for k in ("bore", "outer_diameter", "width")
                         if getattr(self, k) is not None})
        for key, value in positive.items():
            if not (isinstance(value, (int, float)) and value > 0 and math.isfinite(value)):
                raise InputError(f"{name}: {key}={value}: must be a positive length in m")
        if isinstance(self.n_elements, bool) or not isinstance(self.n_elements, int) or self.n_elements < 3:
            raise InputError(f"{name}: n_elements={self.n_elements}: need a whole number >= 3 of rolling elements")
        if self.element_diameter >= self.pitch_diameter:
            raise InputError(f"{name}: element_diameter={self.element_diameter} m: must be smaller than the pitch "
                             f"diameter {self.pitch_diameter} m")
        if self.bore is not None and self.outer_diameter is not None:
            if not (self.bore < self.pitch_diameter < self.outer_diameter):
                raise InputError(f"{name}: pitch_diameter={self.pitch_diameter} m: must lie between bore and "
                                 "outside diameter")
            if self.element_diameter >= (self.outer_diameter - self.bore) / 2:
                raise InputError(f"{name}: element_diameter={self.element_diameter} m: larger than the ring "
                                 "section")
        if not (0.0 <= self.contact_angle < math.pi / 2):
            raise InputError(f"{name}: contact_angle={self.contact_angle} rad: must be in [0, pi/2)")
        if not math.isfinite(self.radial_clearance) or self.radial_clearance < -0.01 * self.element_diameter:
            raise InputError(f"{name}: radial_clearance={self.radial_clearance} m: non-physical interference")
        if self.kind != "ball" and not self.roller_length > 0:
            raise InputError(f"{name}: roller_length={self.roller_length} m: rollers need a positive length")
        if self.kind == "ball" and not (self.groove_inner > 0.5 and self.groove_outer > 0.5):
            raise InputError(f"{name}: groove conformities f_i, f_o must be > 0.5 "
                             f"(got {self.groove_inner}, {self.groove_outer})")
        if self.kind == "ball" and max(self.groove_inner, self.groove_outer) >= 1.0:
            raise InputError(f"{name}: groove conformities f_i, f_o must be < 1 (got {self.groove_inner}, "
                             f"{self.groove_outer}): a groove radius of a whole ball diameter or more")
        if self.roller_profile not in ROLLER_PROFILES:
            raise InputError(f"{name}: roller_profile={self.roller_profile!r}: must be one of "
                             f"{', '.join(ROLLER_PROFILES)}")
        if self.kind == "ball" and self.roller_profile != "straight":
            raise InputError(f"{name}: roller_profile={self.roller_profile!r}: balls have no roller profile")
        if isinstance(self.profile_slices, bool) or not isinstance(self.profile_slices, int) \
                or self.profile_slices < 2:
            raise InputError(f"{name}: profile_slices={self.profile_slices}: need a whole number >= 2")
        if self.rows not in (1, 2):
            raise InputError(f"{name}: rows={self.rows}: must be 1 or 2")
        if not (self.youngs_modulus > 0 and math.isfinite(self.youngs_modulus)):
            raise InputError(f"{name}: youngs_modulus={self.youngs_modulus} Pa: must be > 0")
        if not (0.0 <= self.poisson_ratio < 0.5):
            raise InputError(f"{name}: poisson_ratio={self.poisson_ratio}: must be in [0, 0.5)")


@dataclass
class BearingResult:
    """Mean operating point and 6x6 stiffness of one bearing (axis convention: module docstring).

    K [N/m, N/rad, N m/rad]; displacement (dx, dy, dz, bx, by, bz) [m, rad]; element_loads [N] per rolling
    element (row-major for two rows), element_angles psi_j [rad]; contact_angles [rad] (loaded, balls).
    """
    designation: str
    model: str
    load: np.ndarray
    K: np.ndarray
    displacement: np.ndarray
    element_loads: np.ndarray
    element_angles: np.ndarray
    contact_angles: np.ndarray
    iterations: int
    residual: float

    def secant_stiffness(self) -> list[float | None]:
        """Secant stiffness F_i / delta_i per DOF (x, y, z, theta_x, theta_y) [N/m, N m/rad]: the load divided by
        the deflection it causes (from the equilibrium solve).  None where the DOF carries no load or does not
        move.  Not a matrix, and not K: the tangent K = dF/d(delta) is larger (1.5 F/delta for a pure Hertz ball
        contact), so delta = F/K underestimates the deflection under the load."""
        out = []
        for i in range(5):
            f, d = float(self.load[i]), float(self.displacement[i])
            out.append(f / d if f != 0.0 and d != 0.0 and f / d > 0 else None)
        return out

    def as_dict(self) -> dict:
        """JSON-ready dict: K, displacement, element_loads (SI units) and the operating point.
        "displacement" is the deflection under the load (equilibrium solve) [m, rad]; "K" the tangent stiffness
        dF/d(delta) at that point; "secant_stiffness" the per-DOF F_i / delta_i (None where undefined)."""
        return {"designation": self.designation, "model": self.model, "load": self.load.tolist(),
                "K": self.K.tolist(), "K_is": "tangent stiffness dF/d(delta) at the operating point",
                "displacement": self.displacement.tolist(),
                "displacement_is": "deflection under the load, from the equilibrium solve [m, rad]",
                "secant_stiffness": self.secant_stiffness(),
                "secant_stiffness_is": "F_i / delta_i per DOF x, y, z, theta_x, theta_y [N/m, N m/rad]",
                "element_loads": self.element_loads.tolist(),
                "element_angles_deg": np.degrees(self.element_angles).tolist(),
                "contact_angles_deg": np.degrees(self.contact_angles).tolist(),
                "iterations": self.iterations}


# ----------------------------------------------------------------------------------------------- user geometry
GEOMETRY_KEYS = {
    # TOML key: (RollingBearing field, help) -- all SI (m, Pa) except the angle in degrees
    "designation": ("designation", "a name for the reports"),
    "kind": ("kind", "ball (default), cylindrical_roller, tapered_roller or spherical_roller"),
    "elements": ("n_elements", "number of rolling elements Z per row"),
    "element_diameter": ("element_diameter", "ball (roller) diameter D_w [m]"),
    "pitch_diameter": ("pitch_diameter", "pitch diameter d_pw [m]"),
    "conformity_inner": ("groove_inner", "inner groove conformity f_i = r_i / D_w [-], > 0.5 (default 0.52)"),
    "conformity_outer": ("groove_outer", "outer groove conformity f_o = r_o / D_w [-], > 0.5 (default 0.53)"),
    "radial_clearance": ("radial_clearance", "radial play of the centred rings = half the diametral clearance "
                                             "[m] (default 0)"),
    "contact_angle_deg": ("contact_angle", "unloaded contact angle [deg] (default 0)"),
    "roller_length": ("roller_length", "effective roller length [m] (rollers only)"),
    "rows": ("rows", "1 or 2"),
    "roller_profile": ("roller_profile", "straight (default: full line contact) or logarithmic (ISO/TS 16281 "
                                         "crowned rollers)"),
    "bore": ("bore", "bore d [m], optional"),
    "outer_diameter": ("outer_diameter", "outside diameter D [m], optional"),
    "width": ("width", "width B [m], optional"),
    "youngs_modulus": ("youngs_modulus", "[Pa] (default 208e9, bearing steel)"),
    "poisson_ratio": ("poisson_ratio", "[-] (default 0.3)"),
}


def bearing_from_table(table: dict, where: str = "bearing", key_names: dict | None = None) -> RollingBearing:
    """RollingBearing from a table of internal geometry (the [bearing] table of `housingfe bearing --geometry`).

    Keys (SI, angle in degrees): see GEOMETRY_KEYS; elements, element_diameter and pitch_diameter are
    required.  Unknown keys, wrong types and non-physical values raise InputError("<where>: <key>: ...").
    Defaults that stand in for unknown data are listed in the result's `estimated`.  Values far outside any real
    bearing (a 25 m ball: millimetres given for metres) are refused, naming the key as `key_names` spells it
    (e.g. the command-line flag) and the unit they look like."""
    if not isinstance(table, dict):
        raise InputError(f"{where}: need a table of bearing geometry")
    for key in table:
        if key not in GEOMETRY_KEYS:
            raise InputError(f"{where}: {key}: unknown key (known: {', '.join(GEOMETRY_KEYS)})")
    for key in ("elements", "element_diameter", "pitch_diameter"):
        if key not in table:
            raise InputError(f"{where}: {key}: missing ({GEOMETRY_KEYS[key][1]})")
    kwargs: dict = {"designation": "user bearing", "kind": "ball"}
    for key, value in table.items():
        name = GEOMETRY_KEYS[key][0]
        if key in ("designation", "kind", "roller_profile"):
            if not isinstance(value, str):
                raise InputError(f"{where}: {key}: need a string, got {value!r}")
        elif key in ("elements", "rows"):
            if isinstance(value, bool) or not isinstance(value, int):
                raise InputError(f"{where}: {key}: need a whole number, got {value!r}")
        elif isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise InputError(f"{where}: {key}: need a number, got {value!r}")
        if key == "roller_profile" and value not in ROLLER_PROFILES:
            raise InputError(f"{where}: {(key_names or {}).get(key, key)}: {value!r}: must be one of "
                             f"{', '.join(ROLLER_PROFILES)}")
        if key == "contact_angle_deg":
            if not 0.0 <= value < 90.0:
                raise InputError(f"{where}: {key}: {value} deg must lie in [0, 90)")
            value = math.radians(value)
        elif key in ("element_diameter", "pitch_diameter", "bore", "outer_diameter", "width") and not value > 0:
            raise InputError(f"{where}: {key}: {value} m must be > 0")
        elif key in ("conformity_inner", "conformity_outer") and not value > 0.5:
            raise InputError(f"{where}: {key}: {value} must be > 0.5 (groove radius larger than the ball's)")
        elif key == "roller_length" and not value > 0:
            raise InputError(f"{where}: {key}: {value} m must be > 0")
        kwargs[name] = float(value) if isinstance(value, (int, float)) and key not in ("elements", "rows") \
            else value
    _check_units(table, where, key_names or {})
    estimated = {}
    if kwargs["kind"] == "ball":
        for key, rule in (("conformity_inner", "0.52 (Harris typical)"), ("conformity_outer", "0.53 (Harris typical)")):
            if key not in table:
                estimated[GEOMETRY_KEYS[key][0]] = f"default {rule}"
    if "youngs_modulus" not in table:
        estimated["youngs_modulus"] = "default 208 GPa (bearing steel)"
    try:
        bearing = RollingBearing(**kwargs, estimated=estimated)
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None
    # (RollingBearing itself allows overfull rings: analytic studies use them, e.g. Stribeck's limit Z -> inf)
    z, dw, dpw = bearing.n_elements, bearing.element_diameter, bearing.pitch_diameter
    if z * dw >= math.pi * dpw:
        raise InputError(f"{where}: elements: {z} elements of {dw} m do not fit on the pitch circle ({dpw} m)")
    return bearing


# Largest plausible values (SI) of the internal geometry: a value above is taken for a unit typo, not a bearing.
# The largest rolling elements in catalogues are about 0.15 m (slewing rings, mill bearings), the largest
# bearings about 5 m across; radial clearances are a fraction of a percent of the element diameter.
_LENGTH_LIMITS_M = {"element_diameter": 0.3, "pitch_diameter": 5.0, "bore": 5.0, "outer_diameter": 6.0,
                    "width": 1.0, "roller_length": 0.5}
_YOUNGS_MODULUS_RANGE_PA = (50e9, 500e9)     # bearing steels ~208 GPa, silicon nitride ~310 GPa


def _check_units(table: dict, where: str, key_names: dict) -> None:
    """InputError naming the key when a value of `table` lies far outside any real rolling bearing and looks
    like a value in another unit (mm for m, GPa or MPa for Pa)."""
    for key, limit in _LENGTH_LIMITS_M.items():
        value = table.get(key)
        if value is not None and value > limit:
            raise InputError(f"{where}: {key_names.get(key, key)}: {value:g} m is implausible for a rolling bearing "
                             f"(at most {limit:g} m): it looks like millimetres ({value:g} mm = {value / 1e3:g} m); "
                             "lengths are in m")
    clearance, dw = table.get("radial_clearance"), table.get("element_diameter")
    if clearance is not None and dw is not None and clearance > 0.1 * dw:
        raise InputError(f"{where}: {key_names.get('radial_clearance', 'radial_clearance')}: {clearance:g} m is "
                         f"{clearance / dw:.0%} of the element diameter ({dw:g} m): it looks like millimetres or "
                         f"micrometres; lengths are in m (a clearance of 20 um is 2e-05)")
    modulus = table.get("youngs_modulus")
    low, high = _YOUNGS_MODULUS_RANGE_PA
    if modulus is not None and not low <= modulus <= high:
        unit = ": it looks like GPa" if modulus < 1e4 else ": it looks like MPa" if modulus < 1e7 else ""
        raise InputError(f"{where}: {key_names.get('youngs_modulus', 'youngs_modulus')}: {modulus:g} Pa is outside "
                         f"the range of bearing materials ({low:g} to {high:g} Pa){unit}; give Pa (208e9 for "
                         "bearing steel)")


# ----------------------------------------------------------------------------------------------- models
# Registry of the bearing models by name: a model is a _Model subclass decorated with @register_bearing_model;
# `make_model`, the `housingfe bearing` CLI and the scene schema (housingfe.drivetrain.interior.BearingSpec.model)
# all take their names from here.
BEARING_MODELS: dict[str, type] = {}


def register_bearing_model(cls):
    """Class decorator: add a bearing model (a _Model subclass with `name` and the bearing `kinds` it fits) to
    BEARING_MODELS."""
    if not cls.name or cls.name in BEARING_MODELS:
        raise ValueError(f"bearing model {cls.name!r}: needs a new, non-empty name")
    BEARING_MODELS[cls.name] = cls
    return cls


def check_bearing_model(name: str) -> str:
    """`name` if it is a registered bearing model, else ValueError "'<name>' is not a bearing model; known: ..."."""
    if name not in BEARING_MODELS:
        raise ValueError(f"{name!r} is not a bearing model; known: {', '.join(BEARING_MODELS)}")
    return name


class _Model:
    """One bearing model: energy, load vector and analytic Jacobian as functions of the 5 mean DOFs.
    kinds: the RollingBearing kinds the model fits."""
    name = ""
    kinds: tuple[str, ...] = ()
    exponent = 1.5
    carries_moments = True

    def __init__(self, bearing: RollingBearing):
        self.bearing = bearing
        z = bearing.n_elements
        self.psi = 2.0 * np.pi * np.arange(z) / z
        self.cos, self.sin = np.cos(self.psi), np.sin(self.psi)

    def radial_direction(self) -> np.ndarray:
        """d(delta_r,j)/dq, one row per element (Eq. (3.5))."""
        u = np.zeros((len(self.psi), 5))
        u[:, 0], u[:, 1] = self.cos, self.sin
        return u

    def axial_direction(self, radius: float) -> np.ndarray:
        """d(delta_z,j)/dq = (0, 0, 1, r sin psi, -r cos psi) (Eq. (3.5))."""
        u = np.zeros((len(self.psi), 5))
        u[:, 2] = 1.0
        u[:, 3], u[:, 4] = radius * self.sin, -radius * self.cos
        return u

    def reference_deflection(self, load: np.ndarray) -> float:
        """Typical element deflection [m] for this load: scales the Newton iteration."""
        force = max(np.linalg.norm(load[:3]), np.linalg.norm(load[3:]) / self.moment_arm(), 1.0)
        return (force / (len(self.psi) * self.k_n)) ** (1.0 / self.exponent)     # psi: every element, all rows

    def moment_arm(self) -> float:
        return self.bearing.pitch_diameter / 2.0

    def evaluate(self, q: np.ndarray):
        """(energy [J], load vector F(q) (5,), Jacobian dF/dq (5, 5), element loads [N], contact angles [rad])
        at the mean displacement q = (dx, dy, dz, bx, by[, bz]) [m, rad]."""
        return self._evaluate(np.asarray(q, float)[:5])

    def _evaluate(self, q: np.ndarray):
        raise NotImplementedError


@register_bearing_model
class LimBall(_Model):
    """Lim's ball bearing, Eqs. (3.1)-(3.9); Jacobian = Appendix D (C-1a..p) in vector form."""
    name = "lim-ball"
    kinds = ("ball",)
    exponent = 1.5

    def __init__(self, bearing: RollingBearing):
        super().__init__(bearing)
        b = bearing
        self.k_n = hertz.ball_effective_stiffness(b.element_diameter, b.pitch_diameter, b.contact_angle,
                                                  b.groove_inner, b.groove_outer, b.youngs_modulus, b.poisson_ratio)
        self.a0 = (b.groove_inner + b.groove_outer - 1.0) * b.element_diameter       # Eq. (3.2), A_0
        # r_j: radius of the inner raceway groove curvature centre (Eq. (3.5))
        self.r_j = b.pitch_diameter / 2.0 + (b.groove_inner - 0.5) * b.element_diameter * math.cos(b.contact_angle)
        self.u_r = self.radial_direction()
        self.u_z = self.axial_direction(self.r_j)

    def _evaluate(self, q):
        b, n = self.bearing, self.exponent
        s_r = self.a0 * math.cos(b.contact_angle) + self.u_r @ q - b.radial_clearance   # (delta*)_rj, (3.4)
        s_z = self.a0 * math.sin(b.contact_angle) + self.u_z @ q                         # (delta*)_zj, (3.3)
        a = np.hypot(s_r, s_z)                                                            # A_j, (3.2)
        d = np.maximum(a - self.a0, 0.0)                                                  # delta_j, (3.1)
        if b.contact_angle > 0:
            # an angular contact ring has a shoulder on one side only: a ball pushed past the groove
            # bottom (loaded contact angle < 0) leaves its raceway instead of contacting the other side
            d = np.where(s_z > 0, d, 0.0)
        q_j = self.k_n * d**n                                                             # (3.6)
        v = (s_r[:, None] * self.u_r + s_z[:, None] * self.u_z) / a[:, None]              # unit "normal"
        force = q_j @ v                                                                    # (3.8)
        on = d > 0
        w_geo = np.where(on, q_j / a, 0.0)
        w_dir = np.where(on, n * self.k_n * d ** (n - 1.0), 0.0) - w_geo
        jac = (self.u_r.T * w_geo) @ self.u_r + (self.u_z.T * w_geo) @ self.u_z + (v.T * w_dir) @ v
        energy = self.k_n / (n + 1.0) * np.sum(d ** (n + 1.0))
        return energy, force, jac, q_j, np.arctan2(s_z, s_r)

    def moment_arm(self):
        return self.r_j


def profile_drops(bearing: RollingBearing, slice_centres: np.ndarray) -> np.ndarray:
    """Approach lost to the roller profile at each lamina centre [m]: 2 P(x_k) (inner and outer contact, ISO/TS
    16281) for roller_profile "logarithmic", zeros for "straight"."""
    if bearing.roller_profile == "straight":
        return np.zeros(len(slice_centres))
    return 2.0 * hertz.logarithmic_profile_drop(slice_centres, bearing.element_diameter, bearing.roller_length,
                                                bearing.kind)


@register_bearing_model
class LimRoller(_Model):
    """Lim's roller bearing, Eqs. (3.13)-(3.14), (C-2): fixed contact angle, n = 10/9, uniform load per roller.

    roller_profile "logarithmic": every roller is cut into `profile_slices` laminae of Palmgren's law with
    k_n / slices each (so that a straight roller gives Lim's law exactly), lamina k approached by
    delta_j - 2 P(x_k) (ISO/TS 16281); the ring tilt does not enter (as in Lim's model)."""
    name = "lim-roller"
    kinds = ("cylindrical_roller", "tapered_roller")
    exponent = 10.0 / 9.0

    def __init__(self, bearing: RollingBearing):
        super().__init__(bearing)
        b = bearing
        self.k_n = hertz.roller_effective_stiffness(b.roller_length, b.youngs_modulus, b.poisson_ratio)
        self.r_j = b.pitch_diameter / 2.0
        a = b.contact_angle
        self.g = math.cos(a) * self.radial_direction() + math.sin(a) * self.axial_direction(self.r_j)
        self.gap = b.radial_clearance * math.cos(a)
        self._slice_for_profile()

    def _slice_for_profile(self):
        """Rows of laminae for a crowned roller (see the class docstring); nothing for a straight one."""
        b = self.bearing
        self.laminae = 1
        self.k_row = self.k_n
        self.g_row, self.gap_row = self.g, self.gap
        if b.roller_profile == "straight":
            return
        ns = b.profile_slices
        x = (np.arange(ns) + 0.5) * b.roller_length / ns - b.roller_length / 2.0
        self.laminae = ns
        self.k_row = self.k_n / ns
        self.g_row = np.repeat(self.g, ns, axis=0)                                  # row j*ns + k
        self.gap_row = self.gap + np.tile(profile_drops(b, x), self.g.shape[0])

    def _evaluate(self, q):
        n, k = self.exponent, self.k_row
        d = np.maximum(self.g_row @ q - self.gap_row, 0.0)               # Eq. (3.13) (per lamina if crowned)
        q_j = k * d**n
        force = q_j @ self.g_row                                         # Eq. (3.14)
        jac = (self.g_row.T * (n * k * d ** (n - 1.0))) @ self.g_row     # (C-2)
        energy = k / (n + 1.0) * np.sum(d ** (n + 1.0))
        per_roller = q_j.reshape(self.g.shape[0], self.laminae).sum(axis=1)
        return energy, force, jac, per_roller, np.full(self.g.shape[0], self.bearing.contact_angle)


@register_bearing_model
class SelfAligningRoller(LimRoller):
    """Double-row spherical roller bearing: rows at +-alpha0, contact normals through the sphere centre, so a
    tilt of the inner ring compresses no roller and the moment stiffness is zero by construction."""
    name = "self-aligning"
    kinds = ("spherical_roller",)
    carries_moments = False

    def __init__(self, bearing: RollingBearing):
        _Model.__init__(self, bearing)
        b = bearing
        self.k_n = hertz.roller_effective_stiffness(b.roller_length, b.youngs_modulus, b.poisson_ratio)
        self.r_j = b.pitch_diameter / 2.0
        a = b.contact_angle
        rad = self.radial_direction()
        ax = np.zeros_like(rad)
        ax[:, 2] = 1.0                       # no r*beta term: the outer raceway is a sphere about the centre
        self.g = np.vstack([math.cos(a) * rad + math.sin(a) * ax, math.cos(a) * rad - math.sin(a) * ax])
        self.psi = np.concatenate([self.psi, self.psi])
        self.gap = b.radial_clearance * math.cos(a)
        self._slice_for_profile()


@register_bearing_model
class SphericalPointContact(SelfAligningRoller):
    """Double-row spherical roller bearing with Hertz point contacts (n = 3/2): the self-aligning kinematics, each
    roller pressed between two elliptical contacts of osculation 0.97 (hertz.spherical_roller_effective_stiffness,
    the ISO/TS 16281 treatment of spherical rollers).  A crowned alternative to the line-contact "self-aligning"."""
    name = "spherical-point-contact"
    exponent = 1.5

    def __init__(self, bearing: RollingBearing):
        if bearing.roller_profile != "straight":
            raise InputError(f"{bearing.designation}: model 'spherical-point-contact' has its crown from the "
                             "osculation; roller_profile must be 'straight'")
        super().__init__(bearing)
        b = bearing
        self.k_n = self.k_row = hertz.spherical_roller_effective_stiffness(
            b.element_diameter, b.pitch_diameter, b.contact_angle, b.youngs_modulus, b.poisson_ratio)


@register_bearing_model
class SlicedRoller(_Model):
    """Thesis Sec. 3.3.2: rollers sliced along their length, non-uniform load, Weber–Banaschek per slice.

    Slice k of roller j at a_k (from the roller centre along its axis, -l/2..l/2) is compressed by
    delta_j - a_k gamma_j with delta_j of Eq. (3.13) and gamma_j = bx sin psi - by cos psi (Eq. (3.15)); this is
    the exact small-rotation approach of two rigid rings.  The slice forces act along the contact normal,
    so F = sum F_jk g_jk and K = sum dF_jk/d(delta) g_jk g_jk^T with g_jk = d(approach)/dq (virtual work).
    """
    name = "sliced-roller"
    kinds = ("cylindrical_roller", "tapered_roller")
    exponent = 10.0 / 9.0
    tilt_factor = 1.0       # approach of slice a: delta_j - tilt_factor * a * gamma_j

    def __init__(self, bearing: RollingBearing, slices: int = 20):
        if slices < 2:
            raise InputError(f"{bearing.designation}: slices={slices}: need at least 2 slices per roller")
        super().__init__(bearing)
        b = bearing
        self.slices = slices
        self.k_n = hertz.roller_effective_stiffness(b.roller_length, b.youngs_modulus, b.poisson_ratio)   # only for scaling
        self.r_j = b.pitch_diameter / 2.0
        dl = b.roller_length / slices
        self.a = (np.arange(slices) + 0.5) * dl - b.roller_length / 2.0
        alpha = b.contact_angle
        g_centre = math.cos(alpha) * self.radial_direction() + math.sin(alpha) * self.axial_direction(self.r_j)
        tilt = np.zeros_like(g_centre)
        tilt[:, 3], tilt[:, 4] = self.sin, -self.cos                                # d(gamma_j)/dq
        # (Z, slices, 5) -> (Z*slices, 5)
        arm = self.tilt_factor * self.a
        self.g = (g_centre[:, None, :] - arm[None, :, None] * tilt[:, None, :]).reshape(-1, 5)
        # a crowned roller: lamina k starts 2 P(a_k) further from contact (ISO/TS 16281)
        self.gap = b.radial_clearance * math.cos(alpha) + np.tile(profile_drops(b, self.a), len(self.psi))
        inner_race = b.pitch_diameter / 2.0 - b.element_diameter / 2.0
        outer_race = b.pitch_diameter / 2.0 + b.element_diameter / 2.0
        self.law = hertz.LineContactSlices(b.element_diameter, inner_race, outer_race, dl, b.youngs_modulus, b.poisson_ratio)

    def _evaluate(self, q):
        approach = self.g @ q - self.gap
        f, k = self.law.force_and_stiffness(approach)
        force = f @ self.g
        jac = (self.g.T * k) @ self.g
        energy = float(np.sum(self.law.energy(approach)))
        per_roller = f.reshape(len(self.psi), self.slices).sum(axis=1)
        return energy, force, jac, per_roller, np.full(len(self.psi), self.bearing.contact_angle)


@register_bearing_model
class SlicedRollerThesis(SlicedRoller):
    """The sliced roller with the thesis' own Eq. (3.16): slice a moves by delta_j - a sin(gamma_j/2), i.e. half
    the ring tilt (the roller's rotation) instead of the approach of the two rings.  For comparison with the
    thesis' numbers only; its tilt stiffness from the slicing is 1/4 of "sliced-roller"."""
    name = "sliced-roller-thesis"
    tilt_factor = 0.5


def default_model(bearing: RollingBearing) -> str:
    """The thesis' model for each kind: Lim for balls, the Sec. 3.3.2 improvement for rollers."""
    return {"ball": "lim-ball", "cylindrical_roller": "sliced-roller", "tapered_roller": "sliced-roller",
            "spherical_roller": "self-aligning"}[bearing.kind]


def make_model(bearing: RollingBearing, model: str | None = None) -> _Model:
    """Instantiate a model by name (None: default_model); checks that model and kind match."""
    name = model or default_model(bearing)
    if name not in BEARING_MODELS:
        raise InputError(f"{bearing.designation}: model={name!r}: must be one of {sorted(BEARING_MODELS)}")
    cls = BEARING_MODELS[name]
    if bearing.kind not in cls.kinds:
        # spherical roller bearings carry no moment: only a self-aligning model fits them
        hint = (" (spherical roller bearings use 'self-aligning')"
                if "spherical_roller" in (bearing.kind, *cls.kinds) and "ball" not in (bearing.kind, *cls.kinds)
                else "")
        raise InputError(f"{bearing.designation}: model {name!r} does not fit a {bearing.kind} bearing{hint}")
    return cls(bearing)


# ----------------------------------------------------------------------------------------------- solver
def _load_vector(load, preload_axial: float, name: str) -> np.ndarray:
    f = np.asarray(load, dtype=float).ravel()
    if f.size not in (5, 6):
        raise InputError(f"{name}: load: need 5 values (Fx Fy Fz Mx My) [N, N m], got {f.size}")
    if not np.all(np.isfinite(f)):
        raise InputError(f"{name}: load: non-finite value in {f.tolist()}")
    if f.size == 6 and f[5] != 0.0:
        raise InputError(f"{name}: load: Mz={f[5]} N m: a bearing transmits no torque about its axis")
    f = f[:5].copy()
    f[2] += preload_axial
    return f


class _Unbounded(Exception):
    """The iterate left the physical range: the energy has no minimum (load cannot be carried)."""


def solve_mean_displacement(model: _Model, f: np.ndarray, tol: float = 1e-10, max_iter: int = 200,
                            fixed_tilt: tuple[float, float] | None = None):
    """Mean displacement q with F(q) = f (Eqs. (3.11)-(3.12)).

    The Newton–Raphson iteration of the thesis (analytic Jacobian = [K]) is globalised as a trust-region
    Newton method (scipy 'trust-exact') on the potential energy U(q) - f.q, which is convex for every model
    here: this converges from q = 0 even while no element is loaded (singular K).
    fixed_tilt: prescribe (bx, by) [rad] instead of solving for them (the moments Mx, My in f are then
    ignored and follow from the solution).  Returns (q (5,), iterations, scaled residual).
    Raises InputError when no equilibrium exists (energy unbounded below) or Newton fails."""
    b = model.bearing
    r = model.moment_arm()
    d_ref = model.reference_deflection(f)
    k_ref = model.k_n * d_ref ** (model.exponent - 1.0) * len(model.psi)
    scale_q = np.array([d_ref, d_ref, d_ref, d_ref / r, d_ref / r])     # DOF scaling: rotations as r*beta
    f_ref = k_ref * d_ref
    scale_f = scale_q * k_ref
    q0 = np.zeros(5)
    free = np.ones(5, bool)
    if fixed_tilt is not None:
        free[3:] = False
        q0[3:] = fixed_tilt
    elif not model.carries_moments:
        if np.any(np.abs(f[3:]) > 1e-9 * f_ref * r):
            raise InputError(f"{b.designation}: load: Mx={f[3]}, My={f[4]} N m: a self-aligning bearing "
                             "carries no moment")
        free[3:] = False        # tilts are free and load nothing: keep them at zero
    sq = scale_q[free]
    # 100x any real contact deflection plus room for the axial play: beyond this there is no equilibrium
    limit = (0.02 * b.element_diameter + 20.0 * abs(b.radial_clearance)) / d_ref
    cache = {}

    def state(x):
        key = x.tobytes()
        if key not in cache:
            if np.max(np.abs(x)) > limit:
                raise _Unbounded
            q = q0.copy()
            q[free] = x * sq
            cache.clear()
            cache[key] = model.evaluate(q)
        return cache[key]

    def potential(x):
        return (state(x)[0] - f[free] @ (x * sq)) / (f_ref * d_ref)

    def gradient(x):
        return (state(x)[1][free] - f[free]) * sq / (f_ref * d_ref)

    def hessian(x):
        return state(x)[2][np.ix_(free, free)] * sq[:, None] * sq[None, :] / (f_ref * d_ref) \
            + 1e-12 * np.eye(len(sq))

    try:
        sol = minimize(potential, np.zeros(len(sq)), jac=gradient, hess=hessian, method="trust-exact",
                       options={"gtol": tol, "maxiter": max_iter, "initial_trust_radius": 1.0})
    except _Unbounded:
        raise InputError(f"{b.designation}: load {f.tolist()} N, N m: the bearing cannot carry it "
                         "(displacement grows without bound)") from None
    q = q0.copy()
    q[free] = sol.x * sq
    residual = float(np.max(np.abs((f - model.evaluate(q)[1])[free] / scale_f[free])))
    iterations = int(sol.nit)
    # the trust region may stop a little early where the Jacobian is not Lipschitz (n = 10/9 contacts);
    # finish with plain Newton–Raphson steps, Eq. (3.12), while they reduce the residual
    for _ in range(10):
        if residual < tol:
            break
        _, force, jac, *_ = model.evaluate(q)
        trial = q.copy()
        trial[free] += np.linalg.lstsq(jac[np.ix_(free, free)], (f - force)[free], rcond=1e-14)[0]
        new_residual = float(np.max(np.abs((f - model.evaluate(trial)[1])[free] / scale_f[free])))
        if new_residual >= residual:
            break
        q, residual, iterations = trial, new_residual, iterations + 1
    if residual > 1e3 * tol:
        raise InputError(f"{b.designation}: load {f.tolist()} N, N m: Newton did not converge in {iterations} "
                         f"iterations (residual {residual:.2e}); the bearing cannot carry this load")
    return q, iterations, residual


def embed_6x6(jac5: np.ndarray) -> np.ndarray:
    """5x5 (dx, dy, dz, bx, by) -> 6x6 with a zero torsional row/column (Eq. (C-1p))."""
    k = np.zeros((6, 6))
    k[:5, :5] = 0.5 * (jac5 + jac5.T)    # symmetric analytically; remove round-off asymmetry
    return k


def stiffness_at(model: _Model, q: np.ndarray) -> np.ndarray:
    """Analytic 6x6 stiffness [N/m, N/rad, N m/rad] at mean displacement q (5 or 6 values)."""
    return embed_6x6(model.evaluate(np.asarray(q, float)[:5])[2])


def finite_difference_stiffness(model: _Model, q: np.ndarray, rel_step: float = 1e-6) -> np.ndarray:
    """Central-difference 6x6 stiffness of the load vector around q (for checking the analytic one)."""
    q = np.asarray(q, float)[:5]
    r = model.moment_arm()
    size = max(np.max(np.abs(q[:3])), np.max(np.abs(q[3:])) * r, 1e-9)
    k = np.zeros((6, 6))
    for i in range(5):
        h = rel_step * size / (r if i >= 3 else 1.0)
        dq = np.zeros(5)
        dq[i] = h
        k[:5, i] = (model.evaluate(q + dq)[1] - model.evaluate(q - dq)[1]) / (2 * h)
    return k


def transform_stiffness(k_local: np.ndarray, rotation) -> np.ndarray:
    """6x6 matrix from the bearing frame to global axes: T K T^T with T = diag(R, R).

    rotation: 3x3 whose COLUMNS are the bearing's local x, y, z axes (z = shaft axis) in global coordinates.
    Works for K and for the fluid-film C alike (units unchanged)."""
    r = np.asarray(rotation, float)
    if r.shape != (3, 3) or not np.allclose(r.T @ r, np.eye(3), atol=1e-9):
        raise InputError("bearing rotation: need an orthonormal 3x3 matrix (columns = local x, y, z)")
    t = np.kron(np.eye(2), r)
    return t @ np.asarray(k_local, float) @ t.T


def rolling_bearing_stiffness(bearing: RollingBearing, load, *, model: str | None = None,
                              preload_axial: float = 0.0,
                              fixed_tilt: tuple[float, float] | None = None) -> BearingResult:
    """Mean displacement and 6x6 stiffness of a rolling bearing under the mean load (Fx, Fy, Fz, Mx, My).

    load [N, N m] acts on the inner ring; preload_axial [N] is added to Fz.  fixed_tilt=(bx, by) [rad]
    prescribes the tilt (e.g. (0, 0) for a bearing on a stiff shaft held by a second bearing) instead of the
    moments; the returned load then holds the moments that tilt needs.  Raises InputError if the bearing
    cannot carry the load (no equilibrium, or every element unloaded at equilibrium)."""
    m = make_model(bearing, model)
    f = _load_vector(load, preload_axial, bearing.designation)
    q, iterations, residual = solve_mean_displacement(m, f, fixed_tilt=fixed_tilt)
    _, force, jac, loads, angles = m.evaluate(q)
    if fixed_tilt is not None:
        f[3:] = force[3:]
    if not np.any(loads > 0):
        raise InputError(f"{bearing.designation}: load {f.tolist()} N, N m: every rolling element is unloaded "
                         "(zero stiffness); apply a load or preload")
    return BearingResult(designation=bearing.designation, model=m.name, load=np.append(f, 0.0),
                         K=embed_6x6(jac), displacement=np.append(q, 0.0), element_loads=loads,
                         element_angles=m.psi.copy(), contact_angles=angles, iterations=iterations,
                         residual=residual)
