"""Fukuma, Furukawa & Aida (1973): coupled circumferential / radial / axial vibration of a spur gear on a
flexible shaft between two bearings (Bull. JSME 16(97), 6th report).  SI units throughout.

Model (the paper's Sec. 2):
- Shaft of length l between two identical bearings of radial stiffness K_p; "degree of fixity" lambda: the
  influence functions are the blend G = (1 - lambda) G_hinged + lambda G_fixed of a shaft simply supported
  on the two springs and one whose ends are clamped against rotation but translate on the springs.  Shaft
  bending stiffness from K_s = 6 E pi (r_o^4 - r_i^4) / l^3 = 24 E I / l^3.
- The static influence functions are exact cubic pieces (Euler-Bernoulli, point force and moment at the gear
  position z = gear distance / l); they are computed with two Hermite beam elements (nodes 0, z, 1), which
  reproduce them exactly, and checked against the paper's closed forms in the tests.
- Influence coefficients alpha = G_uu(z,z), beta = G_u0(z,z), gamma = G_00(z,z), Lambda = alpha gamma - beta^2
  (eq. 2); shaft mass folded into the gear by the static deflection shapes (eq. 3, 8, 9): equivalent mass m,
  diametral inertia I and dynamic coupling C (2T = m y'^2 + I phi'^2 - 2 C y' phi') - plus the gear itself.
- Identical driving and driven systems (eq. 12', 14): DOFs q = [x, y_V, y_H, phi_V, phi_H], x the sum of
  both gears' base-circle displacements, y the radial displacement of one gear (positive away from the
  mesh), phi its tilt; mesh force W_d = K (x - 2 y_V cos a - 2 y_H sin a) - F, mesh moment
  M_d = K b^2 (phi_V cos a + phi_H sin a)/6 - K b^2 phi_g / 12; damping of eq. 14 with zeta (paper: 0.07).
  Gyroscopic terms are neglected (the paper finds +-0.5 dB).  Linear, steady-state harmonic response.

Inputs NOT in the paper and assumed here (stated in docs/fukuma.md): Young's modulus and density of the shaft
(steel 206 GPa, 7850 kg/m^3), the shaft cross-section carrying the mass (the equivalent radius of Table 1),
the gear blank (solid steel disc of pitch radius and face width b with a bore of the shaft radius), the mesh
stiffness K (2.0e8 N/m, 20 N/(mm um) over b = 10 mm), the accelerometer radius (base radius) and the gear
positions of Fig. 5 (figure missing; only A1 = mid-span, zl = 110 mm, is stated).

Public API: `ShaftBearing`, `GearBody`, `FukumaPair`, `influence_coefficients`, `equivalent_inertia`,
`harmonic_response`, `conversion_ratios`, `bearing_load_spectra`; the scene runner (`run_scene`,
`bench_rows`) is housingfe.source.fukuma.run.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from housingfe.errors import InputError

KGF = 9.80665                     # N per kgf (Table 1 is in kg/mm = kgf/mm)
KGF_PER_MM = KGF / 1e-3           # N/m per kgf/mm


# ------------------------------------------------------------------------------------------ data types
@dataclass(frozen=True)
class ShaftBearing:
    """Shaft between two identical bearings (one direction V or H may have its own K_p).

    length: bearing span l [m]
    shaft_stiffness: K_s = 24 E I / l^3 [N/m] (Table 1)
    bearing_stiffness_v, bearing_stiffness_h: K_p in the vertical / horizontal direction [N/m]
    fixity: lambda, degree of built-in support of both bearings [-] (0 hinged ... 1 clamped)
    mass_radius_outer, mass_radius_inner: cross-section that carries the shaft's mass [m]
    density: shaft density [kg/m^3]
    """

    length: float
    shaft_stiffness: float
    bearing_stiffness_v: float
    bearing_stiffness_h: float
    fixity: float
    mass_radius_outer: float
    mass_radius_inner: float = 0.0
    density: float = 7850.0

    def __post_init__(self):
        for key in ("length", "shaft_stiffness", "bearing_stiffness_v", "bearing_stiffness_h",
                    "mass_radius_outer", "density"):
            if not getattr(self, key) > 0:
                raise InputError(f"shaft: {key}: must be > 0, got {getattr(self, key)}")
        if not 0.0 <= self.fixity <= 1.0:
            raise InputError(f"shaft: fixity: lambda must lie in [0, 1], got {self.fixity}")
        if not 0.0 <= self.mass_radius_inner < self.mass_radius_outer:
            raise InputError("shaft: mass_radius_inner: must lie in [0, mass_radius_outer)")

    @property
    def bending_stiffness(self) -> float:
        """E I = K_s l^3 / 24 [N m^2]."""
        return self.shaft_stiffness * self.length**3 / 24.0

    @property
    def area(self) -> float:
        """Cross-section area S [m^2]."""
        return math.pi * (self.mass_radius_outer**2 - self.mass_radius_inner**2)

    @property
    def polar_area_moment(self) -> float:
        """Polar second moment of area Z = pi (r_o^4 - r_i^4) / 2 [m^4]."""
        return math.pi * (self.mass_radius_outer**4 - self.mass_radius_inner**4) / 2.0


def shaft_stiffness_from_radius(youngs_modulus: float, length: float, r_outer: float, r_inner: float = 0.0):
    """Fukuma's K_s = 6 E pi (r_o^4 - r_i^4) / l^3 [N/m] (SI inputs)."""
    return 6.0 * youngs_modulus * math.pi * (r_outer**4 - r_inner**4) / length**3


@dataclass(frozen=True)
class GearBody:
    """Rigid gear: mass [kg], diametral (tilting) and polar moments of inertia [kg m^2], base radius r_g [m],
    face width b [m]."""

    mass: float
    diametral_inertia: float
    polar_inertia: float
    base_radius: float
    face_width: float

    @classmethod
    def solid_disc(cls, outer_radius, bore_radius, width, base_radius, density=7850.0) -> GearBody:
        """A steel disc (ring) of `outer_radius`, `bore_radius`, `width` [m] - the assumed gear blank."""
        mass = density * math.pi * (outer_radius**2 - bore_radius**2) * width
        polar = 0.5 * mass * (outer_radius**2 + bore_radius**2)
        diametral = 0.25 * mass * (outer_radius**2 + bore_radius**2) + mass * width**2 / 12.0
        return cls(mass, diametral, polar, base_radius, width)


@dataclass(frozen=True)
class FukumaPair:
    """Identical driving and driven gear-shaft systems (the paper's test rig).

    mesh_stiffness K [N/m], pressure_angle alpha_b [rad] (working pressure angle), zeta: fraction of critical
    damping of every damper of eq. 14 [-], teeth: tooth number z (for the mesh frequency)."""

    shaft: ShaftBearing
    gear: GearBody
    mesh_stiffness: float
    pressure_angle: float
    zeta: float = 0.07
    teeth: int = 36

    def __post_init__(self):
        if not self.mesh_stiffness > 0:
            raise InputError(f"gear: mesh_stiffness: must be > 0, got {self.mesh_stiffness}")
        if not 0 < self.pressure_angle < math.pi / 4:
            raise InputError("gear: pressure_angle: must lie in (0, 45) deg")
        if self.zeta < 0:
            raise InputError("gear: zeta: must be >= 0")


# ------------------------------------------------------------------------------- static influence functions
def _beam_element(ei: float, le: float) -> np.ndarray:
    return ei / le**3 * np.array([[12, 6 * le, -12, 6 * le], [6 * le, 4 * le**2, -6 * le, 2 * le**2],
                                  [-12, -6 * le, 12, -6 * le], [6 * le, 2 * le**2, -6 * le, 4 * le**2]])


def _static_solution(shaft: ShaftBearing, kp: float, z: float, clamped: bool) -> np.ndarray:
    """Nodal displacements [w0, t0, wz, tz, w1, t1] (w [m], t = dw/ds [rad]) for a unit force (column 0)
    and a unit moment (column 1) at s = z l.  Two Hermite elements: exact for point loads."""
    length, ei = shaft.length, shaft.bending_stiffness
    k = np.zeros((6, 6))
    for e, le in enumerate((z * length, (1.0 - z) * length)):
        idx = slice(2 * e, 2 * e + 4)
        k[idx, idx] += _beam_element(ei, le)
    k[0, 0] += kp
    k[4, 4] += kp
    free = [0, 2, 3, 4] if clamped else [0, 1, 2, 3, 4, 5]
    f = np.zeros((6, 2))
    f[2, 0] = 1.0
    f[3, 1] = 1.0
    u = np.zeros((6, 2))
    u[np.ix_(free, [0, 1])] = np.linalg.solve(k[np.ix_(free, free)], f[free])
    return u


def _hermite(u: np.ndarray, z: float, length: float, s: np.ndarray):
    """Deflection w and slope dw/ds at positions s [m] from nodal solutions u (6 x n_load)."""
    w = np.empty((len(s), u.shape[1]))
    t = np.empty_like(w)
    for e, (a, le) in enumerate(((0.0, z * length), (z * length, (1.0 - z) * length))):
        mask = (s >= a - 1e-15) & (s <= a + le + 1e-15)
        xi = (s[mask] - a) / le
        n = np.stack([1 - 3 * xi**2 + 2 * xi**3, le * (xi - 2 * xi**2 + xi**3), 3 * xi**2 - 2 * xi**3,
                      le * (-xi**2 + xi**3)], axis=1)
        dn = np.stack([(-6 * xi + 6 * xi**2) / le, 1 - 4 * xi + 3 * xi**2, (6 * xi - 6 * xi**2) / le,
                       -2 * xi + 3 * xi**2], axis=1)
        ue = u[2 * e:2 * e + 4]
        w[mask] = n @ ue
        t[mask] = dn @ ue
    return w, t


def _check_position(z: float):
    if not 0.0 < z < 1.0:
        raise InputError(f"gear position: z = {z} must lie strictly between the bearings (0 < z < 1)")


def influence_field(shaft: ShaftBearing, kp: float, z: float, s: np.ndarray):
    """Blended influence functions at shaft positions s [m] for loads at the gear position z [-]:
    returns (w, t) each of shape (len(s), 2): column 0 per unit force [m/N, rad/N], column 1 per unit
    moment [m/(N m), rad/(N m)].  G = (1 - lambda) G_hinged + lambda G_fixed."""
    _check_position(z)
    lam = shaft.fixity
    w_h, t_h = _hermite(_static_solution(shaft, kp, z, False), z, shaft.length, s)
    w_f, t_f = _hermite(_static_solution(shaft, kp, z, True), z, shaft.length, s)
    return (1 - lam) * w_h + lam * w_f, (1 - lam) * t_h + lam * t_f


def influence_coefficients(shaft: ShaftBearing, kp: float, z: float) -> dict[str, float]:
    """alpha [m/N], beta [1/N], gamma [1/(N m)], Lambda = alpha gamma - beta^2 at gear position z [-]."""
    w, t = influence_field(shaft, kp, z, np.array([z * shaft.length]))
    alpha, beta, gamma = w[0, 0], w[0, 1], t[0, 1]
    return {"alpha": alpha, "beta": beta, "gamma": gamma, "Lambda": alpha * gamma - beta**2}


def _gauss_points(z: float, length: float, n: int = 6):
    x, wt = np.polynomial.legendre.leggauss(n)
    pts, weights = [], []
    for a, b in ((0.0, z * length), (z * length, length)):
        pts.append(0.5 * (b - a) * x + 0.5 * (a + b))
        weights.append(0.5 * (b - a) * wt)
    return np.concatenate(pts), np.concatenate(weights)


def equivalent_inertia(shaft: ShaftBearing, kp: float, z: float, gear: GearBody | None = None) -> dict:
    """Equivalent mass m [kg], diametral inertia I [kg m^2] and dynamic coupling C [kg m] of eq. (9) at gear
    position z [-] (shaft mass through the static shapes of eq. 3), plus the gear body if given.
    Also returns J [kg m^2] (gear + whole shaft in rigid rotation, eq. 6)."""
    coef = influence_coefficients(shaft, kp, z)
    flex = np.array([[coef["alpha"], coef["beta"]], [coef["beta"], coef["gamma"]]])
    s, wt = _gauss_points(z, shaft.length)
    w, t = influence_field(shaft, kp, z, s)
    shape_y = w @ np.linalg.inv(flex)          # y(s) = shape_y . [y(z), phi(z)]
    shape_p = t @ np.linalg.inv(flex)
    rho, area, diam = shaft.density, shaft.area, shaft.polar_area_moment / 2.0
    mass = rho * (area * (shape_y.T * wt) @ shape_y + diam * (shape_p.T * wt) @ shape_p)
    out = {"m": mass[0, 0], "I": mass[1, 1], "C": -mass[0, 1],
           "J": rho * shaft.polar_area_moment * shaft.length}
    if gear is not None:
        out["m"] += gear.mass
        out["I"] += gear.diametral_inertia
        out["J"] += gear.polar_inertia
    return out


# ------------------------------------------------------------------------------------------ dynamics
def system_matrices(pair: FukumaPair, z: float):
    """Mass, damping and stiffness matrices (5 x 5) of eq. (14) for DOFs [x, y_V, y_H, phi_V, phi_H], the
    mesh row vector n (delta = n q) and the per-direction coefficients."""
    a = pair.pressure_angle
    ca, sa = math.cos(a), math.sin(a)
    K, b, zeta = pair.mesh_stiffness, pair.gear.face_width, pair.zeta
    dirs = {}
    for name, kp in (("V", pair.shaft.bearing_stiffness_v), ("H", pair.shaft.bearing_stiffness_h)):
        dirs[name] = {**influence_coefficients(pair.shaft, kp, z),
                      **equivalent_inertia(pair.shaft, kp, z, pair.gear)}
    J = dirs["V"]["J"]
    Mx = 0.5 * J / pair.gear.base_radius**2        # M = M1 M2 / (M1 + M2) with M1 = M2 = J / r_g^2
    n = np.array([1.0, -2 * ca, -2 * sa, 0.0, 0.0])
    km = K * b**2 / 6.0
    M = np.zeros((5, 5))
    C = np.zeros((5, 5))
    Kmat = np.zeros((5, 5))
    M[0, 0] = Mx
    D = 2 * zeta * math.sqrt(Mx * K)
    Kmat[0] += K * n
    C[0] += D * n
    tilt = np.array([0.0, 0.0, 0.0, ca, sa])
    iv, ih = dirs["V"]["I"], dirs["H"]["I"]
    d_tilt = 2 * zeta * math.sqrt(iv * ih / (iv * sa**2 + ih * ca**2) * km)
    for (iy, ip, proj), name in zip(((1, 3, ca), (2, 4, sa)), ("V", "H")):
        c = dirs[name]
        al, be, ga, la = c["alpha"], c["beta"], c["gamma"], c["Lambda"]
        M[iy, iy], M[ip, ip] = c["m"], c["I"]
        M[iy, ip] = M[ip, iy] = -c["C"]
        # shaft-bearing stiffness = inverse of the flexibility [[alpha, beta], [beta, gamma]]
        Kmat[iy, iy] += ga / la
        Kmat[iy, ip] += -be / la
        Kmat[ip, ip] += al / la
        Kmat[ip, iy] += -be / la
        d_y = 2 * zeta * math.sqrt(c["m"] / al)
        d_p = 2 * zeta * math.sqrt(c["I"] * al / la)
        C[iy, iy] += d_y + d_p * be**2 / al
        C[iy, ip] += -d_p * be
        C[ip, ip] += d_p * al
        C[ip, iy] += -d_p * be
        # radial rows: -(W_d) proj moves to the left-hand side (W_d = K n q + D n q' - F)
        Kmat[iy] -= proj * K * n
        C[iy] -= proj * D * n
        # tilt rows: + M_d proj
        Kmat[ip] += proj * km * tilt
        C[ip] += proj * d_tilt * tilt
    return M, C, Kmat, dirs


def harmonic_response(pair: FukumaPair, z: float, omega: float, force: complex = 1.0,
                      angle_error: complex = 0.0) -> np.ndarray:
    """Complex steady-state amplitudes q = [x, y_V, y_H, phi_V, phi_H] [m, rad] at circular frequency omega
    [rad/s] for a disturbing mesh force F = `force` [N] (profile error, eq. 12) and an angular error
    phi_g = `angle_error` [rad] (lead / parallelism)."""
    M, C, K, _ = system_matrices(pair, z)
    a = pair.pressure_angle
    km12 = pair.mesh_stiffness * pair.gear.face_width**2 / 12.0
    f = np.array([force, -force * math.cos(a), -force * math.sin(a),
                  km12 * angle_error * math.cos(a), km12 * angle_error * math.sin(a)], dtype=complex)
    return np.linalg.solve(K + 1j * omega * C - omega**2 * M, f)


def conversion_ratios(pair: FukumaPair, z: float, omega: float, sensor_radius: float | None = None) -> dict:
    """Radial and axial conversion ratios K_r = a_r / a_t and K_z = a_z / a_t (Sec. 4.2-4.3) of the linear
    harmonic response at omega [rad/s].  a_t: circumferential acceleration of one gear at `sensor_radius`
    (default: base radius), a_r: radial, a_z: axial acceleration at the same radius from the tilt, all
    as RMS seen by gear-fixed accelerometers (rotation-averaged V and H).  K_z does not depend on the
    sensor radius; K_r does (as 1 / radius)."""
    r = pair.gear.base_radius if sensor_radius is None else sensor_radius
    q = harmonic_response(pair, z, omega) * omega**2
    a_t = abs(q[0]) * r / (2.0 * pair.gear.base_radius)
    a_r = math.sqrt((abs(q[1]) ** 2 + abs(q[2]) ** 2) / 2.0)
    a_z = r * math.sqrt((abs(q[3]) ** 2 + abs(q[4]) ** 2) / 2.0)
    return {"K_r": a_r / a_t, "K_z": a_z / a_t, "a_t": a_t / math.sqrt(2.0)}


def mesh_frequency(pair: FukumaPair, rpm: float) -> float:
    """Tooth-meshing frequency [rad/s] at shaft speed rpm."""
    return 2.0 * math.pi * rpm / 60.0 * pair.teeth


def _bearing_reactions(pair: FukumaPair, kp: float, z: float, load: np.ndarray):
    """Forces [N] and moments [N m] the shaft exerts on its two bearings for gear loads (P, M) on the shaft
    (force along w, moment conjugate to the slope dw/ds)."""
    lam, length = pair.shaft.fixity, pair.shaft.length
    out_f, out_m = [], []
    for end, node in ((0, 0), (1, 4)):
        u_h = _static_solution(pair.shaft, kp, z, False)
        u_f = _static_solution(pair.shaft, kp, z, True)
        w = (1 - lam) * u_h[node] + lam * u_f[node]
        out_f.append(kp * (w @ load))
        # clamped-end moment reaction of the fixed model: from element equilibrium at the end node
        ei = pair.shaft.bending_stiffness
        if end == 0:
            ke = _beam_element(ei, z * length)
            moment = ke[1] @ u_f[0:4]
        else:
            ke = _beam_element(ei, (1 - z) * length)
            moment = ke[3] @ u_f[2:6]
        # the support's moment on the shaft is `moment`; the shaft's moment on the bearing is its negative
        out_m.append(-lam * (moment @ load))
    return out_f, out_m


def bearing_load_spectra(pair: FukumaPair, z: float, rpm: float, te_harmonics_m, torque_Nm: float = 0.0):
    """Bearing force and moment spectra of the driving and driven shafts for a static transmission error
    with harmonic amplitudes `te_harmonics_m` [m] at 1, 2, ... times the mesh frequency (disturbing force
    F = K e, eq. 12) at shaft speed `rpm` and gear position z [-].

    Returns the housing chain's structure `housingfe.source.roosmalen.dynamics.BearingSpectra` (issue 7):
    frequency [Hz], names, z [m] (bearing positions along the shaft from the gear centre plane: -z l and
    (1 - z) l), loads (4, 6, n_freq) complex one-sided amplitudes of [F_x, F_y, F_z, M_x, M_y, M_z] that
    each SHAFT exerts on the housing at the bearing, load(t) = Re(A exp(i 2 pi f t)); x = horizontal H,
    y = vertical V (the line of action for alpha_b = 0), z along the shaft (right-handed).  The driven
    gear's radial displacement away from the mesh is +y / +x; the driving shaft's loads are the same with
    opposite sign (both gears are pushed apart symmetrically).  Spur gears: F_z = M_z = 0.  `torque_Nm` is
    only recorded (the model is linear; the mean load does not enter).

    The gear loads on the shaft are P = (gamma y - beta phi)/Lambda, M = (alpha phi - beta y)/Lambda
    (eq. 2); bearing forces K_p y_bearing follow from the blended influence functions, bearing moments are
    lambda times the clamped-end moments."""
    from housingfe.source.roosmalen.dynamics import BearingSpectra

    te = np.atleast_1d(np.asarray(te_harmonics_m, dtype=complex))
    omega0 = mesh_frequency(pair, rpm)
    freqs = np.arange(1, len(te) + 1) * omega0 / (2 * math.pi)
    loads = np.zeros((4, 6, len(te)), dtype=complex)
    for h, e in enumerate(te):
        q = harmonic_response(pair, z, (h + 1) * omega0, force=pair.mesh_stiffness * e)
        # V plane (y, z): the slope dy/dz is a rotation about -x, so Mx = -M(V plane);
        # H plane (x, z): dx/dz is a rotation about +y, so My = +M(H plane)
        for (iy, ip, fdof, mdof, msign), kp in (((1, 3, 1, 3, -1.0), pair.shaft.bearing_stiffness_v),
                                                ((2, 4, 0, 4, 1.0), pair.shaft.bearing_stiffness_h)):
            c = influence_coefficients(pair.shaft, kp, z)
            y, p = q[iy], q[ip]
            load = np.array([(c["gamma"] * y - c["beta"] * p) / c["Lambda"],
                             (c["alpha"] * p - c["beta"] * y) / c["Lambda"]])
            forces, moments = _bearing_reactions(pair, kp, z, load)
            for j in range(2):
                loads[2 + j, fdof, h] = forces[j]
                loads[2 + j, mdof, h] = msign * moments[j]
    loads[0:2] = -loads[2:4]
    length = pair.shaft.length
    return BearingSpectra(speed_rpm=rpm, torque_Nm=torque_Nm, frequency=freqs,
                          names=["driving_left", "driving_right", "driven_left", "driven_right"],
                          z=np.array([-z * length, (1 - z) * length] * 2), loads=loads)

