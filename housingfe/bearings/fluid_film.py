"""Plain cylindrical fluid-film journal bearings: eccentricity, stiffness K and damping C (thesis Sec. 3.5).

The thesis reads its coefficients from graphs: Lund (/3.9/) for the 2x2 force coefficients, Kikuchi (/3.2/)
and Mukherjee & Rao (/3.3/) for the moment (tilt) coefficients.  Those graphs are not in the text, so here
both come from one model that contains them: the isoviscous, incompressible Reynolds equation for a finite
bearing, solved by finite volumes on the unwrapped film (theta, z),

    d/dtheta(H^3 dP/dtheta) + d/dZ(H^3 dP/dZ) = 6 dH/dtheta + 12 dH/dtau,
    H = h/C = 1 - X(z) cos(theta) - Y(z) sin(theta),  X(z) = X + beta_y z,  Y(z) = Y - beta_x z,
    P = p C^2 / (eta omega R^2),  Z = z / R,  tau = omega t,

with p = 0 at both bearing ends and a cavitation condition: "reynolds" (Swift–Stieber, p >= 0 as a
complementarity problem, primal-dual active set) or "gumbel" (half-Sommerfeld: the full-film solution with
negative pressures dropped, the assumption behind the short-bearing (Ocvirk) closed forms).  The closed-form
short-bearing load is available too (`short_bearing_load`), as the check of the solver.

Axis convention as for the rolling bearings: z = shaft axis, DOF order (x, y, z, theta_x, theta_y, theta_z),
the journal (shaft) moves by q relative to the bearing, the shaft rotates at +omega about +z.
K_ij = -d(F_film,i)/d(q_j), C_ij = -d(F_film,i)/d(dq_j/dt), F_film = film force and moment on the journal, so
K and C are the matrices that go into M q'' + C q' + K q = f on the shaft side.  Both are NOT symmetric.
The film carries no axial force and no torque: rows/columns z and theta_z are zero.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp
from scipy.optimize import brentq
from scipy.sparse.linalg import splu

from housingfe.errors import InputError, SolverError

DOFS_4 = (0, 1, 3, 4)       # x, y, theta_x, theta_y inside the 6x6 convention


@dataclass(frozen=True)
class JournalBearing:
    """Plain journal bearing: diameter D [m], length L [m], radial clearance C [m], viscosity eta [Pa s]."""
    diameter: float
    length: float
    clearance: float
    viscosity: float

    def __post_init__(self):
        for key in ("diameter", "length", "clearance", "viscosity"):
            value = getattr(self, key)
            if not (value > 0 and math.isfinite(value)):
                raise InputError(f"journal bearing: {key}={value}: must be positive (SI units)")
        if self.clearance >= 0.05 * self.diameter:
            raise InputError(f"journal bearing: clearance={self.clearance} m: not small against D={self.diameter} m")


@dataclass
class FluidFilmResult:
    """Operating point and dynamic coefficients of a journal bearing.

    eccentricity_ratio [-], attitude_angle [rad] (between load line and line of centres), min_film [m],
    displacement (6,) [m, rad] of the journal centre, K (6x6) [N/m, N/rad, N m/m, N m/rad], C (6x6) [N s/m, ...],
    sommerfeld = eta N L D / W (R/C)^2 [-] with N in rev/s."""
    eccentricity_ratio: float
    attitude_angle: float
    min_film: float
    displacement: np.ndarray
    K: np.ndarray
    C: np.ndarray
    sommerfeld: float
    load: np.ndarray


# ------------------------------------------------------------------------------------------ analytic
def short_bearing_load_factor(eps: float) -> float:
    """Ocvirk short bearing: W / (eta omega R L^3 / C^2) = eps sqrt(pi^2 (1 - eps^2) + 16 eps^2) / (4 (1-eps^2)^2)."""
    return eps * math.sqrt(math.pi**2 * (1 - eps**2) + 16 * eps**2) / (4 * (1 - eps**2) ** 2)


def short_bearing_load(bearing: JournalBearing, omega: float, eps: float) -> float:
    """Load capacity W [N] of the short (Ocvirk, half-Sommerfeld) bearing at eccentricity ratio eps."""
    r = bearing.diameter / 2
    return bearing.viscosity * omega * r * bearing.length**3 / bearing.clearance**2 * short_bearing_load_factor(eps)


def short_bearing_eccentricity(bearing: JournalBearing, omega: float, load: float) -> float:
    """Eccentricity ratio [-] at which the Ocvirk short bearing carries `load` [N]."""
    _check_operating(omega, load)
    return brentq(lambda e: short_bearing_load(bearing, omega, e) - load, 1e-9, 1 - 1e-9, xtol=1e-14)


def short_bearing_film_force(bearing: JournalBearing, omega: float, pos, vel=(0.0, 0.0),
                             n_points: int = 20000) -> np.ndarray:
    """Film force (Fx, Fy) [N] on the journal of a short (Ocvirk) bearing, half-Sommerfeld condition:
    F = -(eta R L^3 / 2) int max(-G, 0) / h^3 (cos, sin) dtheta, G = omega dh/dtheta + 2 dh/dt,
    h = C - x cos(theta) - y sin(theta); pos = (x, y) [m], vel = (dx/dt, dy/dt) [m/s]."""
    x, y = pos
    xd, yd = vel
    th = (np.arange(n_points) + 0.5) * (2 * math.pi / n_points)
    c, s = np.cos(th), np.sin(th)
    h = bearing.clearance - x * c - y * s
    if h.min() <= 0:
        raise InputError("journal bearing: the journal touches the bearing (film thickness <= 0)")
    g = omega * (x * s - y * c) + 2.0 * (-xd * c - yd * s)
    weight = np.maximum(-g, 0.0) / h**3
    scale = -bearing.viscosity * bearing.diameter / 2 * bearing.length**3 / 2 * (2 * math.pi / n_points)
    return scale * np.array([np.sum(weight * c), np.sum(weight * s)])


def short_bearing_coefficients(bearing: JournalBearing, omega: float, load, rel_step: float = 1e-5
                               ) -> FluidFilmResult:
    """Ocvirk short bearing: eccentricity from the closed-form load, K and C (6x6, only the x/y block is
    non-zero: the short-bearing force model has no tilt coefficients) by central differences of
    short_bearing_film_force.  load = (Wx, Wy) [N] on the journal."""
    w = np.asarray(load, float).ravel()
    magnitude = float(np.hypot(*w))
    _check_operating(omega, magnitude)
    eps = short_bearing_eccentricity(bearing, omega, magnitude)
    c = bearing.clearance
    f0 = short_bearing_film_force(bearing, omega, (eps * c, 0.0))
    angle = math.atan2(-w[1], -w[0]) - math.atan2(f0[1], f0[0])
    rot = _rotation(angle)[:2, :2]
    pos0 = np.array([eps * c, 0.0])
    k2, c2 = np.zeros((2, 2)), np.zeros((2, 2))
    h = rel_step * c
    for j in range(2):
        d = np.zeros(2)
        d[j] = h
        k2[:, j] = -(short_bearing_film_force(bearing, omega, pos0 + d)
                     - short_bearing_film_force(bearing, omega, pos0 - d)) / (2 * h)
        v = d * omega
        c2[:, j] = -(short_bearing_film_force(bearing, omega, pos0, v)
                     - short_bearing_film_force(bearing, omega, pos0, -v)) / (2 * h * omega)
    k6, c6 = np.zeros((6, 6)), np.zeros((6, 6))
    k6[:2, :2] = rot @ k2 @ rot.T
    c6[:2, :2] = rot @ c2 @ rot.T
    disp = np.zeros(6)
    disp[:2] = rot @ pos0
    r = bearing.diameter / 2
    sommerfeld = bearing.viscosity * omega / (2 * math.pi) * bearing.length * bearing.diameter / magnitude \
        * (r / c) ** 2
    attitude = abs(math.atan2(f0[1], f0[0]) - math.pi)
    return FluidFilmResult(eccentricity_ratio=eps, attitude_angle=min(attitude, 2 * math.pi - attitude),
                           min_film=c * (1 - eps), displacement=disp, K=k6, C=c6, sommerfeld=sommerfeld, load=w)


def _check_operating(omega: float, load: float) -> None:
    if not (omega > 0 and math.isfinite(omega)):
        raise InputError(f"journal bearing: omega={omega} rad/s: must be > 0 (a plain bearing needs rotation)")
    if not (load > 0 and math.isfinite(load)):
        raise InputError(f"journal bearing: load={load} N: must be > 0")


# ------------------------------------------------------------------------------------------ Reynolds FV
class ReynoldsSolver:
    """Finite-volume Reynolds solver on n_theta x n_z cells; dimensionless (see module docstring)."""

    def __init__(self, bearing: JournalBearing, n_theta: int = 90, n_z: int = 24, cavitation: str = "reynolds"):
        if cavitation not in ("reynolds", "gumbel"):
            raise InputError(f"journal bearing: cavitation={cavitation!r}: must be 'reynolds' or 'gumbel'")
        self.bearing = bearing
        self.cavitation = cavitation
        self.nt, self.nz = n_theta, n_z
        self.dt = 2 * math.pi / n_theta
        half = bearing.length / bearing.diameter        # L/2 / R
        self.dz = 2 * half / n_z
        self.theta = (np.arange(n_theta) + 0.5) * self.dt
        self.z = -half + (np.arange(n_z) + 0.5) * self.dz

    def _film(self, theta, z, q):
        x, y, bx, by = q
        return 1.0 - (x + by * z) * np.cos(theta) - (y - bx * z) * np.sin(theta)

    def pressure(self, q, qdot=(0.0, 0.0, 0.0, 0.0)) -> np.ndarray:
        """Dimensionless pressure P[n_theta, n_z] for dimensionless journal position q = (X, Y, bx, by)/C
        (tilts times R/C) and velocity qdot = dq/dtau."""
        nt, nz, dt, dz = self.nt, self.nz, self.dt, self.dz
        th, zz = np.meshgrid(self.theta, self.z, indexing="ij")
        h_e = self._film(th + dt / 2, zz, q)                 # east faces (theta + dt/2)
        h_w = self._film(th - dt / 2, zz, q)
        h_n = self._film(th, zz + dz / 2, q)
        h_s = self._film(th, zz - dz / 2, q)
        if min(h_e.min(), h_w.min(), h_n.min(), h_s.min()) <= 0:
            raise InputError("journal bearing: the journal touches the bearing (film thickness <= 0)")
        ce, cw = h_e**3 / dt**2, h_w**3 / dt**2
        cn, cs = h_n**3 / dz**2, h_s**3 / dz**2
        # the ends z = +-L/2 lie half a cell beyond the outer nodes: p = 0 there (factor 2 on the face)
        cn[:, -1] *= 2.0
        cs[:, 0] *= 2.0
        xd, yd, bxd, byd = qdot
        hdot = -(xd + byd * zz) * np.cos(th) - (yd - bxd * zz) * np.sin(th)
        rhs = 6.0 * (h_e - h_w) / dt + 12.0 * hdot           # = div(H^3 grad P)
        idx = np.arange(nt * nz).reshape(nt, nz)
        rows, cols, vals = [idx.ravel()], [idx.ravel()], [(ce + cw + cn + cs).ravel()]
        for coef, other in ((ce, np.roll(idx, -1, axis=0)), (cw, np.roll(idx, 1, axis=0))):
            rows.append(idx.ravel()), cols.append(other.ravel()), vals.append(-coef.ravel())
        rows += [idx[:, :-1].ravel(), idx[:, 1:].ravel()]
        cols += [idx[:, 1:].ravel(), idx[:, :-1].ravel()]
        vals += [-cn[:, :-1].ravel(), -cs[:, 1:].ravel()]
        a = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(nt * nz, nt * nz))
        g = -rhs.ravel()                                     # A p = g with A = -div(H^3 grad) (an M-matrix)
        if self.cavitation == "gumbel":
            p = splu(a.tocsc()).solve(g)
            return np.maximum(p, 0.0).reshape(nt, nz)
        p, self._cavitated = self._obstacle(a, g, getattr(self, "_cavitated", None))
        return p.reshape(nt, nz)

    @staticmethod
    def _obstacle(a, g, start=None) -> tuple[np.ndarray, np.ndarray]:
        """p >= 0, A p - g >= 0, p (A p - g) = 0 by a primal-dual active set (finite for M-matrices),
        warm-started from the previous cavitated set (neighbouring operating points differ little)."""
        n = len(g)
        cav = np.zeros(n, bool) if start is None or len(start) != n else start.copy()
        c = float(a.diagonal().mean())
        for _ in range(100):
            p = np.zeros(n)
            free = ~cav
            if free.any():
                p[free] = splu(a[free][:, free].tocsc()).solve(g[free])
            lam = a @ p - g
            new = lam - c * p > 1e-12 * c
            if np.array_equal(new, cav):
                return p, cav
            cav = new
        raise SolverError("journal bearing: cavitation active set did not settle in 100 iterations")

    def film_load(self, q, qdot=(0.0, 0.0, 0.0, 0.0)) -> np.ndarray:
        """Dimensionless film force and moment on the journal (Fx, Fy, Mx, My) / (eta omega R^4 / C^2) (moments
        additionally / R)."""
        p = self.pressure(q, qdot)
        w = self.dt * self.dz
        th, zz = np.meshgrid(self.theta, self.z, indexing="ij")
        fx = -np.sum(p * np.cos(th)) * w
        fy = -np.sum(p * np.sin(th)) * w
        mx = np.sum(p * np.sin(th) * zz) * w                 # Mx = -int z dFy
        my = -np.sum(p * np.cos(th) * zz) * w                # My = +int z dFx
        return np.array([fx, fy, mx, my])


def _rotation(angle: float) -> np.ndarray:
    """4x4 rotation about z acting on (x, y, theta_x, theta_y)."""
    c, s = math.cos(angle), math.sin(angle)
    r2 = np.array([[c, -s], [s, c]])
    out = np.zeros((4, 4))
    out[:2, :2] = r2
    out[2:, 2:] = r2
    return out


# the last results of journal_bearing_coefficients by their exact inputs: a run-up following its speed
# (housingfe.runup.chain.follow_speeds) asks for both bearings of a shaft at the same load and speed (the double
# helical set loads them alike), each a ~0.3 s Reynolds solve with a root search
_COEFFICIENTS: dict = {}
COEFFICIENT_MEMO = 512          # ~1 kB each; a run-up asks for 2 shafts x its speeds per torque


def journal_bearing_coefficients(bearing: JournalBearing, omega: float, load, *, n_theta: int = 90,
                                 n_z: int = 24, cavitation: str = "reynolds",
                                 rel_step: float = 1e-4) -> FluidFilmResult:
    """Static equilibrium and linearised K, C (6x6, non-symmetric) of a journal bearing.

    omega [rad/s] > 0 shaft speed about +z; load (Wx, Wy) [N] applied by the shaft to the journal (e.g.
    (0, -20763)).  Eccentricity from the load (the Sommerfeld number), then central differences of the film
    force and moment with respect to journal displacement, tilt and their velocities.  The same inputs again give
    a copy of the remembered result (the last COEFFICIENT_MEMO)."""
    w = np.asarray(load, float).ravel()
    key = (bearing, float(omega), tuple(w.tolist()), n_theta, n_z, cavitation, rel_step)
    if key not in _COEFFICIENTS:
        res = _coefficients(bearing, omega, w, n_theta, n_z, cavitation, rel_step)
        while len(_COEFFICIENTS) >= COEFFICIENT_MEMO:
            _COEFFICIENTS.pop(next(iter(_COEFFICIENTS)))
        _COEFFICIENTS[key] = res
    res = _COEFFICIENTS[key]
    return replace(res, displacement=res.displacement.copy(), K=res.K.copy(), C=res.C.copy(), load=res.load.copy())


def _coefficients(bearing: JournalBearing, omega: float, w: np.ndarray, n_theta: int, n_z: int, cavitation: str,
                  rel_step: float) -> FluidFilmResult:
    if w.size != 2:
        raise InputError(f"journal bearing: load: need (Wx, Wy) in N, got {w.tolist()}")
    magnitude = float(np.hypot(*w))
    _check_operating(omega, magnitude)
    solver = ReynoldsSolver(bearing, n_theta, n_z, cavitation)
    r, c, eta = bearing.diameter / 2, bearing.clearance, bearing.viscosity
    force_scale = eta * omega * r**4 / c**2
    target = magnitude / force_scale

    def load_at(eps):                  # journal displaced along +x by eps; film force magnitude
        return float(np.hypot(*solver.film_load((eps, 0.0, 0.0, 0.0))[:2]))

    if load_at(0.98) < target:
        raise InputError(f"journal bearing: load {magnitude:.6g} N needs an eccentricity ratio above 0.98 "
                         "(film thinner than 2 % of the clearance); not carried")
    eps = brentq(lambda e: load_at(e) - target, 1e-6, 0.98, xtol=1e-10)
    f0 = solver.film_load((eps, 0.0, 0.0, 0.0))
    # in this frame the film force points along f0; the applied load points opposite; rotate the frame
    # so that the film force balances the given load: R f0 = -w
    angle = math.atan2(-w[1], -w[0]) - math.atan2(f0[1], f0[0])
    attitude = math.atan2(f0[1], f0[0]) - math.pi      # from the load line (-f0) to the line of centres (+x)
    q0 = np.array([eps, 0.0, 0.0, 0.0])
    k4 = np.zeros((4, 4))
    c4 = np.zeros((4, 4))
    for j in range(4):
        dq = np.zeros(4)
        dq[j] = rel_step
        k4[:, j] = -(solver.film_load(q0 + dq) - solver.film_load(q0 - dq)) / (2 * rel_step)
        c4[:, j] = -(solver.film_load(q0, dq) - solver.film_load(q0, -dq)) / (2 * rel_step)
    # back to SI: forces / displacement C; tilts are b = beta R / C; moments carry one more R
    unit_q = np.array([c, c, c / r, c / r])
    unit_f = np.array([force_scale, force_scale, force_scale * r, force_scale * r])
    rot = _rotation(angle)
    k_si = rot @ (k4 * unit_f[:, None] / unit_q[None, :]) @ rot.T
    c_si = rot @ (c4 * unit_f[:, None] / (unit_q[None, :] * omega)) @ rot.T
    k6, c6 = np.zeros((6, 6)), np.zeros((6, 6))
    k6[np.ix_(DOFS_4, DOFS_4)] = k_si
    c6[np.ix_(DOFS_4, DOFS_4)] = c_si
    disp = np.zeros(6)
    disp[[0, 1]] = rot[:2, :2] @ np.array([eps * c, 0.0])
    n_rev = omega / (2 * math.pi)
    sommerfeld = eta * n_rev * bearing.length * bearing.diameter / magnitude * (r / c) ** 2
    return FluidFilmResult(eccentricity_ratio=eps, attitude_angle=abs(attitude) if abs(attitude) <= math.pi
                           else 2 * math.pi - abs(attitude), min_film=c * (1 - eps), displacement=disp,
                           K=k6, C=c6, sommerfeld=sommerfeld, load=w)


# ------------------------------------------------------------------------------------------ stability (oil whirl)
def rotor_eigenvalues(mass: float, K: np.ndarray, C: np.ndarray) -> np.ndarray:
    """Eigenvalues s [1/s] of a rigid rotor's translation on its film, mass q'' + C q' + K q = 0 (q = x, y of the
    journal; mass [kg] carried by this bearing; K, C the 2x2 (or the x/y block of the 6x6) film coefficients).
    K is not symmetric: s is complex, and Re(s) > 0 is a growing whirl (the film feeds energy in through the
    cross-coupled stiffness K_xy - K_yx faster than C takes it out)."""
    k, c = np.asarray(K, float)[:2, :2], np.asarray(C, float)[:2, :2]
    a = np.block([[np.zeros((2, 2)), np.eye(2)], [-k / mass, -c / mass]])
    return np.linalg.eigvals(a)


def lund_critical_mass(K: np.ndarray, C: np.ndarray) -> tuple[float, float]:
    """(critical mass [kg], whirl frequency [rad/s]) of a rigid rotor on a film with coefficients K, C (x/y block):
    the Routh-Hurwitz boundary of rotor_eigenvalues in Lund's form (Lund 1966; Childs, Turbomachinery
    Rotordynamics, 1993, Sec. 3): K_eq = (Kxx Cyy + Kyy Cxx - Kxy Cyx - Kyx Cxy) / (Cxx + Cyy),
    w^2 = ((Kxx - K_eq)(Kyy - K_eq) - Kxy Kyx) / (Cxx Cyy - Cxy Cyx); stable iff mass < K_eq / w^2.  An
    eigenvalue-free check of the growth rates (infinite critical mass where w^2 <= 0: no whirl possible)."""
    k, c = np.asarray(K, float)[:2, :2], np.asarray(C, float)[:2, :2]
    k_eq = (k[0, 0] * c[1, 1] + k[1, 1] * c[0, 0] - k[0, 1] * c[1, 0] - k[1, 0] * c[0, 1]) / (c[0, 0] + c[1, 1])
    w2 = ((k[0, 0] - k_eq) * (k[1, 1] - k_eq) - k[0, 1] * k[1, 0]) / (c[0, 0] * c[1, 1] - c[0, 1] * c[1, 0])
    if w2 <= 0:
        return math.inf, 0.0
    return k_eq / w2, math.sqrt(w2)


@dataclass
class WhirlOnset:
    """Speed sweep of a rigid rotor on fluid films.  onset_rpm: the lowest speed [rev/min] above which a mode
    grows (None: stable over the sweep); whirl_ratio: that mode's frequency / shaft speed at the onset (~0.5:
    half-frequency oil whirl); speeds_rpm, growth_rate [1/s] (max Re s per speed), whirl_hz (its Im s / 2 pi);
    message: "unstable (oil whirl) above N rpm ..." or "stable up to N rpm"."""
    onset_rpm: float | None
    whirl_ratio: float | None
    eccentricity_ratio: float | None
    speeds_rpm: np.ndarray
    growth_rate: np.ndarray
    whirl_hz: np.ndarray
    message: str


def whirl_onset(bearing: JournalBearing, mass: float, load, speeds_rpm, model: str = "short") -> WhirlOnset:
    """Where a rigid rotor of `mass` [kg] per bearing, loaded by `load` = (Wx, Wy) [N] per bearing, starts to
    whirl on its plain journal bearing: the eigenvalues of rotor_eigenvalues at each speed of `speeds_rpm`
    [rev/min, ascending], then the crossing Re s = 0 between the last stable and the first unstable speed by
    bisection (brentq).  model: "short" (Ocvirk, fast) or "reynolds" (finite bearing, Reynolds cavitation)."""
    speeds = np.asarray(speeds_rpm, float)
    if speeds.ndim != 1 or len(speeds) < 2 or np.any(np.diff(speeds) <= 0) or speeds[0] <= 0:
        raise InputError(f"whirl_onset: speeds_rpm: need >= 2 ascending positive speeds, got {speeds.tolist()}")
    if not (mass > 0 and math.isfinite(mass)):
        raise InputError(f"whirl_onset: mass={mass} kg: must be positive")
    coefficients = {"short": short_bearing_coefficients, "reynolds": journal_bearing_coefficients}[model]

    def state(rpm):
        res = coefficients(bearing, rpm * 2 * math.pi / 60, load)
        s = rotor_eigenvalues(mass, res.K, res.C)
        top = int(np.argmax(s.real))
        return float(s[top].real), abs(float(s[top].imag)), res.eccentricity_ratio

    rows = np.array([state(n) for n in speeds])
    growth, whirl = rows[:, 0], rows[:, 1] / (2 * math.pi)
    # the film's own scale: Re s is round-off below 1e-9 of |s|
    unstable = growth > 1e-9 * np.abs(rows[:, 1] + 1.0)
    if not unstable.any():
        return WhirlOnset(None, None, None, speeds, growth, whirl, f"stable up to {speeds[-1]:.6g} rpm")
    i = int(np.argmax(unstable))
    if i == 0:
        return WhirlOnset(speeds[0], rows[0, 1] / (speeds[0] * 2 * math.pi / 60), rows[0, 2], speeds, growth, whirl,
                          f"unstable (oil whirl) at {speeds[0]:.6g} rpm already (the lowest speed swept)")
    onset = brentq(lambda n: state(n)[0], speeds[i - 1], speeds[i], xtol=1e-9 * speeds[i], rtol=1e-12)
    _, w, eps = state(onset)
    ratio = w / (onset * 2 * math.pi / 60)
    return WhirlOnset(onset, ratio, eps, speeds, growth, whirl,
                      f"unstable (oil whirl) above {onset:.6g} rpm (whirl at {ratio:.3f} x shaft speed, "
                      f"eccentricity ratio {eps:.3f})")
