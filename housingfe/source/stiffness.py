"""Analytic tooth stiffness and load distribution (van Roosmalen 1994, Sec. 2.2-2.4, Appendix A).

The part of every contact line inside the path of contact is discretised into points (segment middles).
The compliance between two points i, j (normal deflection at i per unit normal force at j) is

    c_ij = [tooth plate, same tooth pair only]  sum_g G_g(w_i, w_j) g_g(i) g_g(j)       (eq. 2.31-2.32)
         + [Hertz, i = j]                        delta_Hertz(F_i) / F_i                 (eq. 2.40, secant)
         + [shaft bending, both gears]           cos^2(beta_b) a_g(z_i, z_j)            (Euler beams)
         + [wheel body torsion, both gears]      cos^2(beta_b) r_b^2 L_k / (G I_p)       (eq. 2.49-2.52)

G_g is the Green's function of Schmidt's cantilever-plate edge equation
S1 f'''' - S2 f'' + S3 f = P delta(x - xi) with free ends (eq. 2.7-2.29), solved exactly with the
four exponential roots (both root cases of Appendix A are covered by complex arithmetic; the 8x8
system is assembled here rather than copied from the OCR'd Appendix A, whose entries did not survive
legibly).  g = sqrt(f_tot(y)/f_etot) uses the Weber-Banaschek deflection of the tooth (eq. 2.36) and
root (eq. 2.39) of the virtual spur gear in the normal section.  The load distribution follows Sec. 2.3:
equal approach delta at all loaded points, points that would carry tension are released, iteration on
the non-linear Hertz term.  The mesh stiffness per unit width is s = (dF/B) / d(delta) (eq. 2.55).

Conventions: forces and deflections are NORMAL to the flank (the plane of action), in N and m; the
mesh stiffness S_t(t) is the normal stiffness used in Appendix C's matrix.  Position on the path of
contact s is measured along the transverse line of action from the pinion's tangent point T1.
Assumptions where the thesis' figures are missing are listed in docs/source.md.
"""
from __future__ import annotations

import collections
import functools
import math
from dataclasses import dataclass, field

import numpy as np

from housingfe.errors import InputError, SolverError
from housingfe.source.gears import GearPair, tooth_profile


# Schmidt's plate factor alpha = 12 / (1 + 2 nu)^2 (eq. 2.11 as printed).
def _plate_alpha(nu: float) -> float:
    return 12.0 / (1.0 + 2.0 * nu) ** 2


# ----------------------------------------------------------------------------- inputs
@dataclass(frozen=True)
class ShaftBending:
    """Euler-beam model of one gear shaft (Fig. 2.6): bearings as simple supports (infinitely stiff
    radially, no moment stiffness), shaft diameter `shaft_diameter` [m] over `left_span` and
    `right_span` [m] between the bearings and the gear faces; the gear body is a solid cylinder of the
    root diameter over the face width."""

    left_span: float
    right_span: float
    shaft_diameter: float


@dataclass(frozen=True)
class Corrections:
    """Flank corrections as the gap they open along the flank normal (m).

    tip_relief: (pinion, wheel) amount at the tip [m]; tip_relief_length: (pinion, wheel) length along
    the transverse line of action [m], linear ramp.  width_relief on the pinion: amount [m] over
    `width_relief_length` [m] from the face w = 0, linear.  triangular=True turns the tip reliefs into
    the 3-D triangular correction D of Fig. F.1: relief = amount * max(0, 1 - l/L - w'/W) with l the
    distance from the tip along the line of action and w' the distance from the corner Q (pinion:
    face w = 0, wheel: face w = b), W = triangle_width (pinion, wheel) [m]."""

    tip_relief: tuple[float, float] = (0.0, 0.0)
    tip_relief_length: tuple[float, float] = (0.0, 0.0)
    width_relief: float = 0.0
    width_relief_length: float = 0.0
    triangular: bool = False
    triangle_width: tuple[float, float] = (0.0, 0.0)

    @classmethod
    def from_table(cls, t: dict, where: str = "corrections") -> "Corrections":
        """From Appendix F style keys in um / mm: pinion_um, pinion_mm, wheel_um, wheel_mm,
        pinion_width_relief_um, pinion_width_relief_mm, kind = "3-D triangular", pinion_width_mm,
        wheel_width_mm."""
        known = {"pinion_um", "pinion_mm", "wheel_um", "wheel_mm", "pinion_width_relief_um",
                 "pinion_width_relief_mm", "kind", "pinion_width_mm", "wheel_width_mm"}
        unknown = set(t) - known
        if unknown:
            raise InputError(f"{where}: unknown key {sorted(unknown)[0]!r}")
        vals = {k: v for k, v in t.items() if k != "kind"}
        if any((not isinstance(v, (int, float))) or v < 0 for v in vals.values()):
            raise InputError(f"{where}: amounts and lengths must be numbers >= 0")
        kind = t.get("kind", "tip relief")
        if kind not in ("tip relief", "3-D triangular"):
            raise InputError(f"{where}: kind: {kind!r} is not 'tip relief' or '3-D triangular'")
        triangular = kind == "3-D triangular"
        c = cls(
            tip_relief=(t.get("pinion_um", 0) * 1e-6, t.get("wheel_um", 0) * 1e-6),
            tip_relief_length=(t.get("pinion_mm", 0) * 1e-3, t.get("wheel_mm", 0) * 1e-3),
            width_relief=t.get("pinion_width_relief_um", 0) * 1e-6,
            width_relief_length=t.get("pinion_width_relief_mm", 0) * 1e-3,
            triangular=triangular,
            triangle_width=(t.get("pinion_width_mm", 0) * 1e-3, t.get("wheel_width_mm", 0) * 1e-3),
        )
        for g in (0, 1):
            if (c.tip_relief[g] > 0) != (c.tip_relief_length[g] > 0):
                raise InputError(f"{where}: a tip relief needs both an amount and a length > 0")
            if triangular and c.tip_relief[g] > 0 and c.triangle_width[g] <= 0:
                raise InputError(f"{where}: a 3-D triangular correction needs pinion_width_mm/wheel_width_mm")
        return c


# ----------------------------------------------------------------------------- Weber-Banaschek
@dataclass
class _ToothFlex:
    """Weber-Banaschek flexibility of one gear's tooth (virtual spur gear in the normal section) as
    functions of the transverse roll distance rho_t = sqrt(r^2 - r_b^2) of the contact point."""

    rho_t: np.ndarray            # m, grid along the flank
    c_tooth: np.ndarray          # m^2/N: delta_t * B / F (rigid root), eq. 2.36
    c_root: np.ndarray           # m^2/N: delta_r * B / F, eq. 2.39
    t_hertz: np.ndarray          # m: distance contact point -> tooth centre line along the load line
    rho_n: np.ndarray            # m: normal radius of curvature of the flank
    tip_height: float            # m: plate height h_p (root to tip along the centre line)


def _virtual_spur(pair: GearPair) -> GearPair:
    """The virtual spur gear pair of the normal section: z_n = z / (cos^2(beta_b) cos(beta)), same
    normal module, pressure angle, profile shifts and racks; tip diameters d_an = d_n + d_a - d (ISO 6336-3),
    so the virtual teeth have the real ones' addendum whatever set the real tips."""
    bb, b = pair.base_helix_angle, pair.helix_angle
    zn = tuple(z / (math.cos(bb) ** 2 * math.cos(b)) for z in pair.teeth)
    dn = pair.module * np.array(zn)
    tips = dn + pair.tip_diameter - pair.pitch_diameter
    return GearPair(module=pair.module, teeth=zn, pressure_angle=pair.pressure_angle, helix_angle=0.0,
                    profile_shift=pair.profile_shift, face_width=pair.face_width,
                    addendum_coefficient=pair.addendum_coefficient,
                    dedendum_coefficient=pair.dedendum_coefficient,
                    rack_tip_radius_factor=pair.rack_tip_radius_factor, kind="spur",
                    youngs_modulus=pair.youngs_modulus, poisson_ratio=pair.poisson_ratio,
                    blank_tip_diameter=(float(tips[0]), float(tips[1])))


@functools.lru_cache(maxsize=32)   # GearPair is frozen (hashable); the profile generation takes ~0.5 s
def weber_banaschek(pair: GearPair, gear: int, n: int = 80) -> _ToothFlex:
    """Tooth and root flexibility of gear 0/1 after Weber & Banaschek (eq. 2.34-2.39), Hertz distance
    t and normal curvature radius, tabulated over the active flank.  Units: see `_ToothFlex`."""
    E, nu = pair.youngs_modulus, pair.poisson_ratio
    vp = _virtual_spur(pair)
    prof = tooth_profile(vp, gear, n_radii=160)
    R, psi = prof["radius"], prof["half_angle"]
    y_prof, x_prof = R * np.cos(psi), R * np.sin(psi)
    y0 = y_prof[0]                                   # root: where the fillet meets the root circle
    root_thickness = 2 * x_prof[0]
    rbv = float(vp.base_diameter[gear]) / 2
    rav = float(vp.tip_diameter[gear]) / 2
    r_lo = max(prof["form_radius"], rbv * 1.0001)
    rv = np.linspace(r_lo, rav, n)
    psi_v = np.interp(rv, R, psi)
    alpha_load = np.arccos(rbv / rv) - psi_v          # angle of the load with the normal to the centre line
    # load height above the root (clipped: a load line meeting the centre line below the root adds no arm)
    yp = np.maximum(rv * np.cos(psi_v) - rv * np.sin(psi_v) * np.tan(alpha_load) - y0, 1e-6 * pair.module)
    t_h = rv * np.sin(psi_v) / np.cos(alpha_load)
    rho_n = np.sqrt(rv**2 - rbv**2)
    c_t = np.empty(n)
    for i in range(n):
        ys = np.linspace(0.0, yp[i], 200)
        half = np.interp(ys + y0, y_prof, x_prof)     # half thickness along the centre line
        bending = 12 * (1 - nu**2) * np.trapz((yp[i] - ys) ** 2 / (2 * half) ** 3, ys)
        shear = (2.4 * (1 + nu) + (1 - nu**2) * np.tan(alpha_load[i]) ** 2) * np.trapz(1 / (2 * half), ys)
        c_t[i] = np.cos(alpha_load[i]) ** 2 / E * (bending + shear)
    ratio = yp / root_thickness
    c_r = np.cos(alpha_load) ** 2 / E * (
        18 * (1 - nu**2) / math.pi * ratio**2 + 2 * (1 + nu) * (1 - 2 * nu) * ratio
        + 4.8 / math.pi * (1 - nu**2) * (1 + (1 - nu) / 2.4 * np.tan(alpha_load) ** 2))
    # transverse roll distance of the real gear belonging to each virtual radius
    rho_t = rho_n * math.cos(pair.base_helix_angle)
    return _ToothFlex(rho_t=rho_t, c_tooth=c_t, c_root=c_r, t_hertz=t_h, rho_n=rho_n,
                      tip_height=float(rav * math.cos(psi_v[-1]) - y0))


# ----------------------------------------------------------------------------- Schmidt plate
def plate_green_matrix(length: float, S1: float, S2: float, S3: float, xi, x) -> np.ndarray:
    """Edge deflections G[i, j] [m] at x_i of Schmidt's cantilever plate of width `length` [m] for a
    unit point force [N] at xi_j: S1 f'''' - S2 f'' + S3 f = delta(x - xi), free ends f'' = 0 and
    f''' - (S2/S1) f' = 0 (eq. 2.7, 2.22-2.29).  S1 [N m^2], S2 [N], S3 [N/m^2].  One 8x8 system per
    load point (Appendix A), assembled from the exact exponential solution; complex roots cover both of
    Appendix A's cases."""
    xi = np.atleast_1d(np.asarray(xi, dtype=float))
    x = np.atleast_1d(np.asarray(x, dtype=float))
    return _plate_evaluate(*_plate_solution(length, S1, S2, S3, xi), xi, x)


def plate_green_blocks(length: float, S1: float, S2: float, S3: float, lines) -> list[np.ndarray]:
    """`plate_green_matrix(length, S1, S2, S3, w, w)` [m/N] for each array w [m] of `lines` (the points of one
    contact line each), with the 8x8 systems of all lines solved in one batch: the same numbers, fewer calls."""
    lines = [np.atleast_1d(np.asarray(w, dtype=float)) for w in lines]
    lam, ref_l, ref_r, coef = _plate_solution(length, S1, S2, S3, np.concatenate(lines))
    out, start = [], 0
    for w in lines:
        part = slice(start, start + w.size)
        out.append(_plate_evaluate(lam, ref_l[part], ref_r[part], coef[part], w, w))
        start += w.size
    return out


def _plate_solution(length: float, S1: float, S2: float, S3: float, xi: np.ndarray):
    """(roots lam (4,), references ref_l, ref_r (n, 4) [m], coefficients (n, 8)) of `plate_green_matrix` for unit
    loads at xi [m]: column j's edge deflection is sum_k coef[j, k] exp(lam_k (x - ref_l[j, k])) left of xi_j and
    sum_k coef[j, 4 + k] exp(lam_k (x - ref_r[j, k])) right of it."""
    a, b = S2 / S1, S3 / S1
    disc = np.sqrt(complex(a * a / 4 - b))
    lam = np.array([np.sqrt(a / 2 + disc), -np.sqrt(a / 2 + disc), np.sqrt(a / 2 - disc), -np.sqrt(a / 2 - disc)])
    grow = lam.real > 0
    n = xi.size
    # basis exp(lam (x - ref)) with ref chosen so that no basis function exceeds 1 in its region
    ref_l = np.where(grow[None, :], xi[:, None], 0.0)             # (n, 4)
    ref_r = np.where(grow[None, :], length, xi[:, None])

    # the row of derivative order k is lam**k * exp(lam (pt - ref)): one exponential per point set, reused for
    # every order (the same floating-point operations as evaluating each row on its own)
    power = [lam**order for order in range(4)]
    zero, ell = np.zeros(n), np.full(n, length)
    e_0l = np.exp(lam * (zero[:, None] - ref_l))                  # (n, 4)
    e_lr = np.exp(lam * (ell[:, None] - ref_r))
    e_xl = np.exp(lam * (xi[:, None] - ref_l))
    e_xr = np.exp(lam * (xi[:, None] - ref_r))
    A = np.zeros((n, 8, 8), dtype=complex)
    A[:, 0, :4] = power[2] * e_0l
    A[:, 1, :4] = power[3] * e_0l - a * (power[1] * e_0l)
    A[:, 2, 4:] = power[2] * e_lr
    A[:, 3, 4:] = power[3] * e_lr - a * (power[1] * e_lr)
    for k in range(3):                                             # continuity of f, f', f'' at xi
        A[:, 4 + k, :4] = power[k] * e_xl
        A[:, 4 + k, 4:] = -(power[k] * e_xr)
    A[:, 7, :4] = -(power[3] * e_xl)                               # jump of f''' = P / S1
    A[:, 7, 4:] = power[3] * e_xr
    rhs = np.zeros((n, 8, 1), dtype=complex)
    rhs[:, 7, 0] = 1.0 / S1
    coef = np.linalg.solve(A, rhs)[..., 0]                         # (n, 8)
    return lam, ref_l, ref_r, coef


def _plate_evaluate(lam, ref_l, ref_r, coef, xi: np.ndarray, x: np.ndarray) -> np.ndarray:
    """G[i, j] [m/N] at x_i for the loads xi_j of a `_plate_solution`."""
    # each x_i lies left or right of the load xi_j: evaluate only that side's solution (one exponential per entry)
    left_side = (x[:, None] <= xi[None, :])[..., None]                         # (nx, n, 1)
    ref = np.where(left_side, ref_l[None, :, :], ref_r[None, :, :])             # (nx, n, 4)
    c = np.where(left_side, coef[None, :, :4], coef[None, :, 4:])
    e = np.exp(lam[None, None, :] * (x[:, None, None] - ref))
    return np.einsum("ijk,ijk->ij", e, c).real


def plate_green(length: float, S1: float, S2: float, S3: float, xi: float, x) -> np.ndarray:
    """Edge deflection f(x) [m] for a unit force [N] at xi (one column of `plate_green_matrix`)."""
    return plate_green_matrix(length, S1, S2, S3, [xi], x)[:, 0]


def plate_coefficients(flex: _ToothFlex, nu: float) -> tuple[float, float, float]:
    """(S1, S2, S3) of eq. 2.8-2.10 for one tooth.  The equivalent plate has the tooth height h_p and
    a flexural rigidity N chosen so that its cantilever compliance h_p^3/(3N) equals the
    Weber-Banaschek rigid-root compliance at the tip; then S3 = gamma 3N/h_p^3 = 1/f_etot (per unit
    width), so a uniformly loaded long tooth deflects exactly as Weber-Banaschek predicts."""
    f_e = flex.c_tooth[-1]
    f_etot = flex.c_tooth[-1] + flex.c_root[-1]
    hp = flex.tip_height
    N = hp**3 / (3 * f_e)
    gamma = f_e / f_etot
    alpha = _plate_alpha(nu)
    return hp * N / alpha, 2 * (1 - nu) * N / hp, gamma * 3 * N / hp**3


# ----------------------------------------------------------------------------- shafts and torsion
def beam_influence(z: np.ndarray, shaft: ShaftBending, gear_diameter: float, face_width: float,
                   gear_offset: float, E: float, n_grid: int = 1500) -> np.ndarray:
    """Deflection at axial positions z_i [m] (measured from the gear's first face) per unit transverse
    force at z_j, of a simply supported stepped Euler beam (unit-load method) [m/N].

    The unit-load integral sum_k w_k m_i(z_k) m_j(z_k) over the grid z_k (weights w_k = dz / EI, bending moment
    m_i(z) = z (L - z_i) / L left of z_i, z_i (L - z) / L right of it) is split where z_k passes min(z_i, z_j) and
    max(z_i, z_j); on each part the moments factor, so the sum is three prefix sums over the grid times factors
    of z_i, z_j: the same quadrature as the (n, n_grid) moment matrix product, summed in another order (equal to
    ~1e-15 relative), at O(n^2 + n_grid) instead of O(n^2 n_grid)."""
    L, zz, lower2, middle, upper2 = _beam_grid(shaft, gear_diameter, face_width, E, n_grid)
    zp = shaft.left_span + gear_offset + np.atleast_1d(np.asarray(z, dtype=float))
    count = np.searchsorted(zz, zp, side="right")            # grid points with z_k <= z_i (left of the load)
    a, b = np.minimum.outer(zp, zp), np.maximum.outer(zp, zp)
    ca, cb = np.minimum.outer(count, count), np.maximum.outer(count, count)   # count grows with z
    return ((L - a) * (L - b) * lower2[ca] + a * (L - b) * (middle[cb] - middle[ca]) + a * b * upper2[cb]) / L**2


@functools.lru_cache(maxsize=64)   # the same shafts for every mesh position: grid and weights once
def _beam_grid(shaft: ShaftBending, gear_diameter: float, face_width: float, E: float, n_grid: int):
    """(length L [m], grid z [m], and over the grid with weights w = dz / EI [1/(N m)]: the prefix sums
    sum_{k<c} w z^2 and sum_{k<c} w z (L - z), the suffix sum sum_{k>=c} w (L - z)^2 for c = 0..n_grid [m^3/N])
    of `beam_influence` (read-only arrays)."""
    L = shaft.left_span + face_width + shaft.right_span
    zz = np.linspace(0.0, L, n_grid)
    in_gear = (zz >= shaft.left_span) & (zz <= shaft.left_span + face_width)
    d = np.where(in_gear, gear_diameter, shaft.shaft_diameter)
    EI = E * math.pi * d**4 / 64
    w = np.gradient(zz) / EI
    lower2 = np.concatenate([[0.0], np.cumsum(w * zz**2)])
    middle = np.concatenate([[0.0], np.cumsum(w * zz * (L - zz))])
    upper2 = np.concatenate([np.cumsum((w * (L - zz) ** 2)[::-1])[::-1], [0.0]])
    for arr in (zz, lower2, middle, upper2):
        arr.flags.writeable = False
    return L, zz, lower2, middle, upper2


# ----------------------------------------------------------------------------- flank gaps
def flank_gaps(pair: GearPair, corrections: Corrections, s, w_local, w, helix) -> np.ndarray:
    """Initial gap [m] along the flank normal that the corrections open at contact points: roll position s [m]
    along the transverse line of action from T1, axial position w_local [m] within its helix and w [m] over
    the gear, helix index (0/1; helix 1 of a double helical gear has the opposite hand).  Arrays broadcast.
    Tip reliefs ramp linearly from the tip (pinion: from E, wheel: from A) over their length along the line of
    action; the 3-D triangular correction D also runs out over triangle_width from its corner Q; the pinion's
    width relief ramps from the face w = 0."""
    c = corrections
    A, E_ = pair.path_of_contact
    s, w_local, w, helix = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (s, w_local, w, helix)))
    b = pair.contact_width
    # the corner Q where a helix' contact starts/ends depends on the helix hand
    w_from_pinion_corner = np.where(helix == 0, w_local, b - w_local)
    gap = np.zeros(s.shape)
    for g, dist in ((0, E_ - s), (1, s - A)):
        amt, length = c.tip_relief[g], c.tip_relief_length[g]
        if amt <= 0:
            continue
        if c.triangular:
            wq = w_from_pinion_corner if g == 0 else b - w_from_pinion_corner
            gap += amt * np.maximum(0.0, 1 - dist / length - wq / c.triangle_width[g])
        else:
            gap += amt * np.maximum(0.0, 1 - dist / length)
    if c.width_relief > 0:
        gap += c.width_relief * np.maximum(0.0, 1 - w / c.width_relief_length)
    return gap


# ----------------------------------------------------------------------------- mesh model
_PLATE_MEMO_SIZE = 64     # plate matrices a MeshModel keeps (each <= 30 kB at 60 points per contact line)


@dataclass
class MeshModel:
    """Everything that does not change with mesh position: flexibilities, plate Green's functions,
    shaft and torsion influence matrices over the face-width slices.

    torque_configuration 1 or 2 (Fig. 2.7): 1 = both torques enter at face w = 0, 2 = the wheel torque
    leaves at the opposite face.  n_slices: points per contact line (on the part in contact).

    lead_gap: misalignment of the mesh under load as a linear gap [m per m of w] along the flank normal over the
    gear's axial position w (housingfe.source.misalignment: sign conventions): gap = lead_gap * w for
    lead_gap >= 0 (the face w = 0 carries most), lead_gap * (w - total width) otherwise (the far face carries
    most), added to the gaps of the corrections.  0: perfectly aligned gears (the thesis' Sec. 2.3).
    include_body_torsion: wheel-body torsion of Sec. 2.2.4 (False only for analytic checks).

    edge_refinement: segments cut into this many equal parts where a contact line's loaded contact edge lies
    (`load_distribution`; 1: uniform points only)."""

    pair: GearPair
    shafts: tuple[ShaftBending, ShaftBending] | None = None
    corrections: Corrections = field(default_factory=Corrections)
    n_slices: int = 24
    torque_configuration: int = 2
    include_plate_coupling: bool = True
    lead_gap: float = 0.0
    include_body_torsion: bool = True
    edge_refinement: int = 8

    def __post_init__(self):
        if self.torque_configuration not in (1, 2):
            raise InputError(f"stiffness: torque_configuration: must be 1 or 2, got {self.torque_configuration}")
        if self.n_slices < 2:
            raise InputError("stiffness: n_slices: need at least 2 points per contact line")
        if self.edge_refinement < 1:
            raise InputError(f"stiffness: edge_refinement: need at least 1, got {self.edge_refinement}")
        if not math.isfinite(self.lead_gap):
            raise InputError(f"stiffness: lead_gap: {self.lead_gap} must be a finite slope (m/m)")
        p = self.pair
        nu, E = p.poisson_ratio, p.youngs_modulus
        self.G_shear = E / (2 * (1 + nu))
        self.flex = [weber_banaschek(p, 0), weber_banaschek(p, 1)]
        self.helices = 2 if p.kind == "double_helical" else 1
        self.plate = [plate_coefficients(f, nu) for f in self.flex]
        self.f_etot = [f.c_tooth[-1] + f.c_root[-1] for f in self.flex]
        self.total_width = self.helices * p.contact_width + (self.helices - 1) * p.helix_gap
        # constants of the per-point interpolation (`_flex_at`), evaluated once rather than at every iteration
        self._line_of_action = p.line_of_action_length
        self._flex_total = [f.c_tooth + f.c_root for f in self.flex]
        # recent plate matrices of `compliance`, by (gear, w_local bytes), least recently used first
        self._plate_memo: collections.OrderedDict = collections.OrderedDict()

    # -------------------------------------------------------------- contact points
    def contact_points(self, u: float) -> dict[str, np.ndarray]:
        """Contact points at mesh position u [m] (along the transverse line of action).  The part of
        every contact line inside the path of contact A <= s <= E is cut exactly and divided into
        `n_slices` equal segments; a point sits at each segment's middle.  Returns per point: position
        s [m], axial position within its helix w_local [m] and over the gear w [m], segment width
        [m] (axial), helix and tooth-pair index."""
        p = self.pair
        A, E_ = p.path_of_contact
        pbt = p.transverse_base_pitch
        tb = math.tan(p.base_helix_angle)
        b = p.contact_width
        n = self.n_slices
        out = {k: [] for k in ("s", "w_local", "w", "width", "helix", "pair")}
        k_lo = math.floor((A - u - b * tb) / pbt) - 1
        k_hi = math.ceil((E_ - u) / pbt) + 1
        for hx in range(self.helices):
            for k in range(k_lo, k_hi + 1):
                s0 = u + k * pbt                       # s at the helix' leading face (offset 0)
                if tb > 0:
                    # offset o = distance from the face where s = s0, o in [0, b]: s = s0 + o tan(beta_b)
                    o_a, o_b = max(0.0, (A - s0) / tb), min(b, (E_ - s0) / tb)
                else:
                    o_a, o_b = (0.0, b) if A <= s0 <= E_ else (1.0, 0.0)
                if o_b - o_a <= 1e-12 * b:
                    continue
                width = (o_b - o_a) / n
                o = o_a + (np.arange(n) + 0.5) * width
                w_local = o if hx == 0 else b - o      # helix 1 has the opposite hand
                out["s"].append(s0 + o * tb)
                out["w_local"].append(w_local)
                out["w"].append(w_local + hx * (b + p.helix_gap))
                out["width"].append(np.full(n, width))
                out["helix"].append(np.full(n, hx))
                out["pair"].append(np.full(n, k))
        if not out["s"]:
            return {k: np.zeros(0) for k in out}
        return {k: np.concatenate(v) for k, v in out.items()}

    def split_segments(self, pts: dict[str, np.ndarray], split: np.ndarray) -> dict[str, np.ndarray]:
        """The contact points `pts` (`contact_points`) with every segment where `split` (bool per point) is true cut
        into `edge_refinement` equal segments along its contact line, each with a point at its middle, in place (a
        line's points stay in order of the offset o).  Adds "parent": the index in `pts` each point comes from."""
        r = self.edge_refinement
        count = np.where(split, r, 1)
        parent = np.repeat(np.arange(split.size), count)
        # offset of each new point from its parent's middle along the contact line, in units of the parent's width
        first = np.cumsum(count) - count
        k = np.arange(parent.size) - first[parent]
        frac = np.where(split[parent], (k + 0.5) / r - 0.5, 0.0)
        do = frac * pts["width"][parent]
        sign = np.where(pts["helix"][parent] == 0, 1.0, -1.0)          # helix 1 has the opposite hand
        out = {key: v[parent] for key, v in pts.items()}
        out["s"] = out["s"] + do * math.tan(self.pair.base_helix_angle)
        out["w_local"] = out["w_local"] + sign * do
        out["w"] = out["w"] + sign * do
        out["width"] = np.where(split[parent], out["width"] / r, out["width"])
        out["parent"] = parent
        return out

    def _flex_at(self, s: np.ndarray) -> dict[str, np.ndarray]:
        rho_t = [s, self._line_of_action - s]
        out = {}
        for g in (0, 1):
            f = self.flex[g]
            r = np.minimum(np.maximum(rho_t[g], f.rho_t[0]), f.rho_t[-1])     # np.clip, without its overhead
            out[f"c{g}"] = np.interp(r, f.rho_t, self._flex_total[g])
            out[f"t{g}"] = np.interp(r, f.rho_t, f.t_hertz)
            out[f"rho{g}"] = np.interp(r, f.rho_t, f.rho_n)
        return out

    def gaps(self, pts: dict[str, np.ndarray]) -> np.ndarray:
        """Initial gap [m] along the normal at each contact point from the flank corrections and the lead gap of
        the misalignment (`lead_gap`)."""
        gap = flank_gaps(self.pair, self.corrections, pts["s"], pts["w_local"], pts["w"], pts["helix"])
        return gap + self.misalignment_gap(pts["w"])

    def misalignment_gap(self, w) -> np.ndarray:
        """The linear gap [m] of `lead_gap` at axial positions w [m] over the gear, >= 0 (zero at the face that
        carries most)."""
        w = np.asarray(w, dtype=float)
        if self.lead_gap >= 0:
            return self.lead_gap * w
        return self.lead_gap * (w - self.total_width)

    def body_compliance(self, w: np.ndarray) -> np.ndarray:
        """Compliance [m/N] between axial positions w through shaft bending and wheel-body torsion of
        both gears, projected on the flank normal (cos^2(beta_b))."""
        p = self.pair
        cb2 = math.cos(p.base_helix_angle) ** 2
        rb = p.base_diameter / 2
        w = np.asarray(w, dtype=float)
        nearer, farther = np.minimum.outer(w, w), np.maximum.outer(w, w)
        body = np.zeros_like(nearer)
        for g in (0, 1):
            Ip = math.pi * (float(p.pitch_diameter[g]) / 2) ** 4 / 2
            if g == 1 and self.torque_configuration == 2:
                twist_length = self.total_width - farther
            else:
                twist_length = nearer
            if self.include_body_torsion:
                body += cb2 * rb[g] ** 2 * twist_length / (self.G_shear * Ip)
            if self.shafts is not None:
                body += cb2 * beam_influence(w, self.shafts[g], float(p.root_diameter[g]), self.total_width,
                                             0.0, p.youngs_modulus, n_grid=600)
        return body

    def compliance(self, pts: dict[str, np.ndarray]) -> np.ndarray:
        """Linear part of the compliance matrix [m/N] between the contact points (no Hertz)."""
        pr, hx, wl = pts["pair"], pts["helix"], pts["w_local"]
        fl = self._flex_at(pts["s"])
        C = self.body_compliance(pts["w"])
        b = self.pair.contact_width
        gg = [np.sqrt(fl[f"c{g}"] / self.f_etot[g]) for g in (0, 1)]
        # A contact line's plate matrix depends only on its points' w_local: the solve on edge-refined points
        # (`_refine_edges`) takes the matrices of the lines it did not cut from the solve before it, and a line that
        # lies wholly inside the path of contact has the same points at every mesh position
        memo = self._plate_memo
        lines = [np.flatnonzero((pr == key[0]) & (hx == key[1]))                 # one plate per tooth pair and helix
                 for key in set(zip(pr.tolist(), hx.tolist()))]
        plates = [{}, {}]
        for g in (0, 1):
            if not self.include_plate_coupling:
                continue
            S1, S2, S3 = self.plate[g]
            missing = []
            for idx in lines:
                memo_key = (g, wl[idx].tobytes())
                if memo_key in memo:
                    memo.move_to_end(memo_key)
                    plates[g][memo_key] = memo[memo_key]
                else:
                    missing.append((memo_key, idx))
            if missing:
                for (memo_key, _), plate in zip(missing, plate_green_blocks(b, S1, S2, S3,
                                                                            [wl[idx] for _, idx in missing])):
                    plates[g][memo_key] = memo[memo_key] = plate
            while len(memo) > _PLATE_MEMO_SIZE:
                memo.popitem(last=False)
        for idx in lines:
            block = np.ix_(idx, idx)
            for g in (0, 1):
                if self.include_plate_coupling:
                    plate = plates[g][(g, wl[idx].tobytes())]
                else:                                   # independent slices (no plate coupling)
                    plate = np.diag(1.0 / (self.plate[g][2] * pts["width"][idx]))
                C[block] += plate * np.outer(gg[g][idx], gg[g][idx])
        return C

    def hertz(self, pts, forces: np.ndarray) -> np.ndarray:
        """Hertzian approach [m] of each contact point under its normal force [N] (eq. 2.40), with the
        contact-line length of its segment width / cos(beta_b)."""
        return self._hertz_of(self._hertz_factors(pts), forces)

    def _hertz_factors(self, pts) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The load-independent factors of `hertz` at the points: t0 t1 pi E L [N m], 2 rho_v (1 - nu^2)
        [m] and pi E L [N/m] (the same products, in the same order, as `hertz` evaluates them)."""
        p = self.pair
        fl = self._flex_at(pts["s"])
        E, nu = p.youngs_modulus, p.poisson_ratio
        L = pts["width"] / math.cos(p.base_helix_angle)
        rho_v = fl["rho0"] * fl["rho1"] / (fl["rho0"] + fl["rho1"])
        return fl["t0"] * fl["t1"] * math.pi * E * L, 2 * rho_v * (1 - nu**2), math.pi * E * L

    def _hertz_of(self, factors, forces: np.ndarray) -> np.ndarray:
        """`hertz` [m] from its load-independent `factors` (`_hertz_factors`) and the forces [N]."""
        numerator, denominator, pi_E_L = factors
        nu = self.pair.poisson_ratio
        F = np.maximum(forces, 1e-9)
        arg = numerator / (denominator * F)
        # arg = (2 t0 / a)(2 t1 / a) with a the Hertzian half-width: Weber's formula holds for a well below the
        # tooth thicknesses.  Its approach F (ln(arg) - nu/(1-nu)) peaks where ln(arg) = 1 + nu/(1-nu) and beyond
        # (larger line loads, a approaching t) falls, then turns negative: an approach that shrinks as the load grows
        # gave a segment of a vanishing contact line (width -> 0 at the path's ends) a vanishing compliance, so a
        # 0.05 mm line of the double helical set took 5 % of the mesh force on one point (spikes of +14 % in the
        # stiffness curve; earlier, the negative part made the iteration cycle).  Past the peak the bracket is held
        # at its peak value 1: the approach grows on as 2 F (1 - nu^2) / (pi E L), so a segment's compliance grows
        # as 1/L and a contact line of length -> 0 carries a load -> 0 at a given approach.  Loads of the
        # contact lines inside the path (arg ~ 1e2) are untouched
        bracket = np.maximum(np.log(arg), 1.0 + nu / (1 - nu)) - nu / (1 - nu)
        return 2 * F * (1 - nu**2) / pi_E_L * bracket

    # -------------------------------------------------------------- load distribution
    def load_distribution(self, u: float, total_force: float, tol: float = 1e-10, max_iter: int = 60,
                          _cache: dict | None = None):
        """Force distribution [N] and mean approach [m] at mesh position u for a total normal force
        [N] (Sec. 2.3).  Returns (points, forces, delta)."""
        if _cache is not None and _cache.get("u") == u:
            pts, C, e = _cache["pts"], _cache["C"], _cache["e"]
            return (pts, *self._solve(pts, C, e, u, total_force, tol, max_iter))
        pts = self.contact_points(u)
        if pts["s"].size == 0:
            raise SolverError(f"stiffness: no contact at mesh position {u}")
        C, e = self.compliance(pts), self.gaps(pts)
        F, delta = self._solve(pts, C, e, u, total_force, tol, max_iter)
        if self.edge_refinement > 1:
            pts, C, e, F, delta = self._refine_edges(pts, C, e, F, delta, u, total_force, tol, max_iter)
        if _cache is not None:
            _cache.update(u=u, pts=pts, C=C, e=e)
        return pts, F, delta

    def _refine_edges(self, coarse, C, e, F, delta, u, total_force, tol, max_iter, max_rounds: int = 6):
        """Resolve the loaded contact edges (`load_distribution`): cut the segments on both sides of every change
        between a point in contact and one out of contact along a contact line (a relief's or a misalignment's
        edge) into `edge_refinement` parts and solve again, until every such change lies inside cut segments.

        Why: a point stands for its whole segment, in contact or not; with equal segments the edge, which moves
        continuously with the mesh position, jumps by a segment whenever it crosses a point, and the stiffness curve
        carries these steps as wiggles whose harmonics converge slowly with the points per line
        (benchmarks/experiments/contact_edge).  Cut segments make the steps edge_refinement times finer at the
        cost of a few points per edge, where the smooth rest of the line needs none."""
        split = np.zeros(coarse["s"].size, dtype=bool)
        pts, parent = coarse, np.arange(coarse["s"].size)
        line = coarse["pair"] * 2 + coarse["helix"]
        for _ in range(max_rounds):
            inside = F > 0
            lp = line[parent]
            change = np.flatnonzero((lp[1:] == lp[:-1]) & (inside[1:] != inside[:-1]))
            need = np.zeros_like(split)
            need[parent[change]] = True
            need[parent[change + 1]] = True
            if not (need & ~split).any():
                break
            split |= need
            coarse_force = np.bincount(parent, weights=F, minlength=split.size)
            pts = self.split_segments(coarse, split)
            parent = pts.pop("parent")
            C, e = self.compliance(pts), self.gaps(pts)
            # start from the last solution, a segment's force shared among its parts (fewer iterations)
            start = coarse_force[parent] / np.bincount(parent, minlength=split.size)[parent]
            F, delta = self._solve(pts, C, e, u, total_force, tol, max_iter, start)
        return pts, C, e, F, delta

    def _solve(self, pts, C, e, u, total_force, tol, max_iter, start=None):
        """(forces [N], approach [m]) of the active-set iteration of `load_distribution` on given points,
        compliance C [m/N] and gaps e [m]; start: initial forces [N] (None: the total spread evenly), points with
        none start out of contact."""
        n = pts["s"].size
        if start is None:
            active = np.ones(n, dtype=bool)
            F = np.full(n, total_force / n)
        else:
            active = start > 0
            F = np.where(active, start, 0.0)
        hertz_factors = self._hertz_factors(pts)                   # the points do not change in the iteration
        for _ in range(max_iter):
            h = self._hertz_of(hertz_factors, F) / np.maximum(F, 1e-9)      # secant Hertz compliance
            idx = np.flatnonzero(active)
            m = idx.size
            K = np.empty((m + 1, m + 1))
            K[:m, :m] = C.take(idx, axis=0).take(idx, axis=1)
            K.ravel()[: m * (m + 2): m + 2] += h[idx]                 # the diagonal of the active block
            K[:m, m] = -1.0
            K[m, :m] = 1.0
            K[m, m] = 0.0
            rhs = np.concatenate([-e[idx], [total_force]])
            sol = np.linalg.solve(K, rhs)
            F_new = np.zeros(n)
            F_new[idx] = sol[:m]
            delta = sol[m]
            neg = F_new < 0
            if neg.any():                                          # release points that pull
                active &= ~neg
                F = np.where(active, np.maximum(F_new, total_force * 1e-6), 0.0)
                continue
            # re-admit points that the approach would push into the mating flank
            approach = C @ F_new + e
            penetrating = (~active) & (approach < delta - 1e-12)
            change = np.max(np.abs(F_new - F)) / total_force
            F = F_new
            if penetrating.any():
                active |= penetrating
                continue
            if change < tol:
                return F, delta
        raise SolverError(f"stiffness: load distribution did not converge at u = {u:.3e} m")

    def stiffness_at(self, u: float, total_force: float, rel_step: float = 1e-3) -> dict[str, float]:
        """Mean approach delta [m] and mesh stiffness [N/m] (dF / d delta, eq. 2.55) at position u; also the
        centre of pressure of the load distribution at total_force (`load_centre`): axial_centre w_c and
        line_centre s_c [m]."""
        cache: dict = {}      # the compliance matrix does not depend on the load
        pts, F, d0 = self.load_distribution(u, total_force, _cache=cache)
        _, _, d1 = self.load_distribution(u, total_force * (1 + rel_step), _cache=cache)
        k = total_force * rel_step / (d1 - d0)
        _, w_c, s_c = load_centre(pts, F)
        return {"delta": d0, "stiffness": k, "n_points": int(np.count_nonzero(F > 0)), "axial_centre": w_c,
                "line_centre": s_c, "unit_friction": friction_resultants(self.pair, pts, F, self.total_width)}


def load_centre(points: dict[str, np.ndarray], forces: np.ndarray) -> tuple[float, float, float]:
    """(total force [N], axial centre w_c [m], centre along the line of action s_c [m]) of a load distribution
    over contact points (`MeshModel.contact_points`): the centre of pressure sum F_i x_i / sum F_i, with w the
    axial position over the gear (MeshModel's w, from its face w = 0) and s measured from T1."""
    forces = np.asarray(forces, float)
    total = float(forces.sum())
    if not total > 0:
        raise SolverError("stiffness: a centre of pressure needs a positive total force")
    return total, float(forces @ points["w"]) / total, float(forces @ points["s"]) / total


FRICTION_RESULTANTS = ("force", "pinion_torque", "wheel_torque", "tilt_moment")


def friction_resultants(pair: GearPair, points: dict[str, np.ndarray], forces: np.ndarray, total_width: float,
                        mu: float = 1.0) -> dict[str, float]:
    """Resultants of Coulomb sliding friction mu F_i at the contact points of a load distribution (normal forces
    F_i [N] at `MeshModel.contact_points`; mu [-]), pinion driving.

    Parallel axes: the flanks' relative motion is a rotation about the pitch line (the line through the pitch point
    C parallel to the axes), so the sliding velocity of the pinion on the wheel at a point s [m] from T1 is
    (omega_1 + omega_2)(s - s_P) along -e_f, with s_P = r_b1 tan(alpha_wt) the pitch point and e_f the unit vector
    from the pinion centre to T1 (in the transverse plane, normal to the plane of action: tangent to the flank of a
    helical gear too; e_f = d x e_1, d from T1 to T2, e_1 the pinion's rotation vector).  The friction on the pinion
    is +mu F_i sgn(s_i - s_P) e_f, on the wheel the opposite; its sign flips at the pitch point.  Returns

      force:         mu sum F_i sgn(s_i - s_P) [N], the friction force on the pinion along e_f;
      pinion_torque: -mu sum F_i s_i sgn(s_i - s_P) [N m] about the pinion's rotation vector (lever s_i from T1;
                     negative brakes: recess);
      wheel_torque:  +mu sum F_i (L - s_i) sgn(s_i - s_P) [N m] about the wheel's rotation vector (lever L - s_i
                     from T2, L = T1T2);
      tilt_moment:   mu sum F_i sgn(s_i - s_P) (w_i - total_width/2) [N m]: the friction force's moment about the
                     gear middle, vector tilt_moment (e_w x e_f) on the pinion and the opposite on the wheel (e_w the
                     direction in which w grows).

    Their power is -mu (omega_1 + omega_2) sum F_i |s_i - s_P| <= 0 (dissipation).

    A point stands for its segment of contact line (`MeshModel.contact_points`: axial width, s = s0 + o tan(beta_b)),
    over which its force is spread evenly: a segment that straddles the pitch point is split there, each part with
    its own share of F_i and its own centroid (s, w), so the sign flips exactly at s_P, not at a segment's middle."""
    forces = np.asarray(forces, float)
    s = np.asarray(points["s"], float)
    w = np.asarray(points["w"], float)
    s_pitch = float(pair.base_diameter[0]) / 2 * math.tan(pair.operating_pressure_angle)
    tan_bb = math.tan(pair.base_helix_angle)
    half = 0.5 * np.asarray(points["width"], float) * tan_bb           # half the segment's extent along s [m]
    spread = half > 0
    safe = np.where(spread, half, 1.0)
    above = np.where(spread, np.clip((s + half - s_pitch) / (2 * safe), 0.0, 1.0), 0.5 * (1 + np.sign(s - s_pitch)))
    below = np.where(spread, 1.0 - above, 0.5 * (1 - np.sign(s - s_pitch)))
    s_above = np.where(spread, 0.5 * (np.maximum(s_pitch, s - half) + s + half), s)
    s_below = np.where(spread, 0.5 * (s - half + np.minimum(s_pitch, s + half)), s)
    # w along a segment: w_local = o on helix 0, b - o on helix 1 (the opposite hand), s grows with o
    dw_ds = np.where(np.asarray(points["helix"]) == 0, 1.0, -1.0) / tan_bb if tan_bb > 0 else np.zeros_like(s)
    mid = 0.5 * total_width
    F = float(mu) * forces
    signed = F * (above - below)
    line = F * (above * s_above - below * s_below)
    tilt = F * (above * (w + (s_above - s) * dw_ds - mid) - below * (w + (s_below - s) * dw_ds - mid))
    return {"force": float(signed.sum()), "pinion_torque": float(-line.sum()),
            "wheel_torque": float(pair.line_of_action_length * signed.sum() - line.sum()),
            "tilt_moment": float(tilt.sum())}


@dataclass
class StiffnessCurve:
    """Mesh stiffness over one mesh period.  position: u / p_bt in [0, 1); stiffness: normal mesh
    stiffness [N/m]; per_width: s = stiffness / total face width [N/m^2] (1 N/(mm um) = 1e9 N/m^2);
    deflection: mean normal approach [m] at the given load; axial_centre, line_centre: the centre of
    pressure w_c, s_c [m] of the load distribution at each position (`load_centre`; the shuttling moment's
    arm, housingfe.source.mesh_moments); unit_friction: {name: (n_positions,)} the sliding-friction resultants per
    unit friction coefficient at each position (`friction_resultants` with mu = 1: N, N m)."""

    position: np.ndarray
    stiffness: np.ndarray
    per_width: np.ndarray
    deflection: np.ndarray
    total_force: float
    axial_centre: np.ndarray | None = None
    line_centre: np.ndarray | None = None
    unit_friction: dict | None = None

    @property
    def mean(self) -> float:
        """Mean normal mesh stiffness [N/m]."""
        return float(self.stiffness.mean())

    @property
    def amplitude(self) -> float:
        """Peak-to-peak stiffness / 2 [N/m]."""
        return float(0.5 * (self.stiffness.max() - self.stiffness.min()))

    def fourier(self) -> np.ndarray:
        """Complex Fourier coefficients X_k (eq. 2.58) of the stiffness, k = 0..N-1 [N/m]."""
        return np.fft.fft(self.stiffness) / self.stiffness.size


def check_tooth_force(pair: GearPair, total_force: float) -> None:
    """InputError unless a total normal tooth force [N] is > 0 and within the teeth's strength (the pinion torque
    T1 = F_bn r_b1 cos(beta_b) checked by GearPair.torque_problem): beyond it the teeth of any steel gear break,
    Weber's Hertzian approach loses its validity (contact half-widths of the order of the tooth thickness) and the
    load distribution has no physical answer.  Callers that know the scene key or option check the torque first."""
    if not total_force > 0:
        raise InputError(f"stiffness: total force must be > 0 N, got {total_force}")
    torque = total_force * float(pair.base_diameter[0]) / 2 * math.cos(pair.base_helix_angle)
    problem = pair.torque_problem(torque)
    if problem is not None:
        raise InputError(f"stiffness: normal tooth force {total_force:.4g} N, pinion torque {problem}")


def stiffness_curve(model: MeshModel, total_force: float, n_positions: int = 32) -> StiffnessCurve:
    """Mesh stiffness over one mesh period at a total normal tooth force [N] (Sec. 2.4)."""
    check_tooth_force(model.pair, total_force)
    pbt = model.pair.transverse_base_pitch
    pos = np.arange(n_positions) / n_positions
    out = [model.stiffness_at(x * pbt, total_force) for x in pos]
    k = np.array([o["stiffness"] for o in out])
    return StiffnessCurve(position=pos, stiffness=k, per_width=k / model.pair.total_contact_width,
                          deflection=np.array([o["delta"] for o in out]), total_force=total_force,
                          axial_centre=np.array([o["axial_centre"] for o in out]),
                          line_centre=np.array([o["line_centre"] for o in out]),
                          unit_friction={k: np.array([o["unit_friction"][k] for o in out])
                                         for k in FRICTION_RESULTANTS})


def face_load_share(model: MeshModel, total_force: float, n_bins: int | None = None,
                    n_positions: int = 8, lead_gap: float | None = None) -> np.ndarray:
    """Relative mesh stiffness per unit face width over the face, (helices, n_bins), mean 1 [-]: bin j of helix
    hx covers w_local in [j, j + 1) * b / n_bins.

    A contact point's share of the load is its stiffness times its deflection compatibility (Sec. 2.3); on the
    UNCORRECTED flanks every point has the same approach delta, so its stiffness is F_i / delta.  Summed per
    bin of the face width and averaged over `n_positions` mesh positions of one base pitch at `total_force`
    [N], this is how the mesh stiffness is distributed across the face: shaft bending, wheel-body torsion and
    the plate coupling of the teeth make it non-uniform (the profile direction averages out over the pitch).

    lead_gap [m/m]: the misalignment under load (MeshModel.lead_gap; None: the model's own).  The uncorrected
    flanks then carry the linear gap, and F_i / delta (delta: the approach of the face that carries most) is the
    point's stiffness times its compatibility (delta - gap) / delta: the share is the LOAD share of the misaligned
    mesh, zero where the gap exceeds the approach (contact loss: `contact_loss_fraction`)."""
    check_tooth_force(model.pair, total_force)
    bare = MeshModel(model.pair, shafts=model.shafts, corrections=Corrections(), n_slices=model.n_slices,
                     torque_configuration=model.torque_configuration,
                     include_plate_coupling=model.include_plate_coupling,
                     lead_gap=model.lead_gap if lead_gap is None else float(lead_gap),
                     include_body_torsion=model.include_body_torsion, edge_refinement=model.edge_refinement)
    n_bins = n_bins or model.n_slices
    b = model.pair.contact_width
    acc = np.zeros((bare.helices, n_bins))
    count = np.zeros((bare.helices, n_bins))
    pbt = model.pair.transverse_base_pitch
    centres = (np.arange(n_bins) + 0.5) / n_bins * b
    for x in np.arange(n_positions) / n_positions:
        pts, F, delta = bare.load_distribution(x * pbt, total_force)
        density = F / (delta * pts["width"])            # stiffness x compatibility per unit face width [N/m^2]
        for key in set(zip(pts["pair"].tolist(), pts["helix"].tolist())):     # one contact line at a time
            idx = np.flatnonzero((pts["pair"] == key[0]) & (pts["helix"] == key[1]))
            idx = idx[np.argsort(pts["w_local"][idx])]
            w, half = pts["w_local"][idx], 0.5 * pts["width"][idx]
            covered = (centres >= w[0] - half[0]) & (centres <= w[-1] + half[-1])
            acc[key[1]] += np.where(covered, np.interp(centres, w, density[idx]), 0.0)
            count[key[1]] += covered
    # per contact line covering a bin, not per position: with a few positions the number of lines over a bin
    # jumps between floor and ceil of eps_alpha * n_positions, which is sampling, not stiffness
    share = acc / np.maximum(count, 1)
    return share / share.mean()


def contact_loss_fraction(share: np.ndarray, threshold: float = 1e-3) -> float:
    """Fraction [-] of the face (bins of a `face_load_share`) that carries less than `threshold` of the mean load:
    where a misalignment's gap exceeds the approach, the flanks separate."""
    share = np.asarray(share, dtype=float)
    return float(np.mean(share < threshold))


def normal_force_from_torque(pair: GearPair, pinion_torque: float) -> float:
    """Total normal tooth force F_bn = T1 / (r_b1 cos(beta_b)) [N] for a pinion torque [N m]."""
    return pinion_torque / (float(pair.base_diameter[0]) / 2 * math.cos(pair.base_helix_angle))


# ----------------------------------------------------------------------------- ISO 6336-1
def iso6336_blank_factor(web_thickness: float | None, face_width: float, rim_thickness: float | None,
                         module: float) -> float:
    """Gear blank factor C_R of ISO 6336-1 (method B) [-].

    web_thickness b_s [m] (None: solid disc, C_R = 1), face_width b [m], rim_thickness s_R [m], normal
    module m_n [m].  C_R = 1 + ln(b_s / b) / (5 exp(s_R / (5 m_n))), with b_s/b limited to [0.2, 1.2] and
    s_R/m_n to >= 1 as the standard prescribes.  For a pair whose two blanks differ, pass the C_R of the more
    flexible (webbed) blank."""
    if web_thickness is None:
        return 1.0
    if not (face_width > 0 and module > 0 and web_thickness > 0 and rim_thickness is not None
            and rim_thickness > 0):
        raise InputError("iso6336_blank_factor: web_thickness, face_width, rim_thickness and module must be > 0 m")
    bs_b = min(max(web_thickness / face_width, 0.2), 1.2)
    sr_m = max(rim_thickness / module, 1.0)
    return 1.0 + math.log(bs_b) / (5.0 * math.exp(sr_m / 5.0))


def iso6336_stiffness(pair: GearPair, load_per_width: float | None = None, blank_factor: float = 1.0,
                      correction_factor: float = 0.8) -> dict[str, float]:
    """Single stiffness c' and mesh stiffness c_gamma of ISO 6336-1 method B, in the standard's units
    N/(mm um) (= 1e9 N/m per m of face width).

    c'_th = 1 / q' with q' from the standard's polynomial in z_n1, z_n2, x1, x2 [mm um / N];
    c' = c'_th C_M C_R C_B cos(beta), C_M = correction_factor (0.8 for solid discs), C_R = blank_factor
    (1 for solid discs; see `iso6336_blank_factor`), C_B = (C_B1 + C_B2) / 2 with
    C_Bi = [1 + 0.5 (1.2 - h_fP,i / m_n)] [1 - 0.02 (20 deg - alpha_n)] from each gear's basic rack
    (pair.dedendum_coefficient); load_per_width = F_t K_A / b [N/m]: below 100 N/mm c' is multiplied by
    (F_t K_A / b / 100 N/mm)^0.25.  c_gamma_alpha = c' (0.75 eps_alpha + 0.25), c_gamma_beta = 0.85
    c_gamma_alpha.

    Keys: c_th_N_per_mm_um, c_prime_N_per_mm_um, c_gamma_alpha_N_per_mm_um, c_gamma_beta_N_per_mm_um, the SI
    twins *_N_per_m2 (N/m per m of face width), the factors C_M, C_R, C_B, and q_prime_mm_um_per_N."""
    if not blank_factor > 0 or not correction_factor > 0:
        raise InputError("iso6336_stiffness: blank_factor and correction_factor must be > 0")
    bb, b = pair.base_helix_angle, pair.helix_angle
    zn1, zn2 = (z / (math.cos(bb) ** 2 * math.cos(b)) for z in pair.teeth)
    x1, x2 = pair.profile_shift
    q = (0.04723 + 0.15551 / zn1 + 0.25791 / zn2 - 0.00635 * x1 - 0.11654 * x1 / zn1
         - 0.00193 * x2 - 0.24188 * x2 / zn2 + 0.00529 * x1**2 + 0.00182 * x2**2)   # mm um / N
    c_th = 1.0 / q                                                                   # N/(mm um)
    alpha_term = 1 - 0.02 * (20 - math.degrees(pair.pressure_angle))
    c_b = 0.5 * sum((1 + 0.5 * (1.2 - h_f)) * alpha_term for h_f in pair.dedendum_coefficient)
    c_prime = c_th * correction_factor * blank_factor * c_b * math.cos(b)
    if load_per_width is not None and load_per_width < 100e3:
        c_prime *= (load_per_width / 1e3) ** 0.25 / 100 ** 0.25
    eps_a = pair.transverse_contact_ratio
    c_gamma_alpha = c_prime * (0.75 * eps_a + 0.25)
    out = {"c_th_N_per_mm_um": c_th, "c_prime_N_per_mm_um": c_prime,
           "c_gamma_alpha_N_per_mm_um": c_gamma_alpha, "c_gamma_beta_N_per_mm_um": 0.85 * c_gamma_alpha}
    out.update({k.replace("_N_per_mm_um", "_N_per_m2"): v * 1e9 for k, v in list(out.items())})
    out.update({"C_M": correction_factor, "C_R": blank_factor, "C_B": c_b, "q_prime_mm_um_per_N": q})
    return out
