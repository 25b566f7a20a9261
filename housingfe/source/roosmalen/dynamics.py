"""Lumped dynamics of the gearbox interior (van Roosmalen 1994, Sec. 2.5-2.7, Appendix C).

15 degrees of freedom (Fig. 2.10, numbering of Appendix C, 1-based there, 0-based here):
  0-5   pinion with its shaft: x, y, z, theta_x, theta_y, theta_z
  6-11  wheel with its shaft:  x, y, z, theta_x, theta_y, theta_z
  12    coupling between shaft 2 (pinion - coupling) and shaft 1 (coupling - far end)
  13    coupling between shaft 3 (wheel - coupling) and shaft 4 (coupling - ground)
  14    far end of shaft 1: angle held constant so that shaft 1 carries the torque (preload)
Translations in m, rotations in rad; x, y in the transverse plane (y along the line of action for
alpha'_t = 0), z axial.  DOF 14 is eliminated: the dynamic model has 14 DOFs and the preload enters as
the constant force k1 * theta_15 on DOF 12.

The mesh couples the gears through S(t) h h^T with the normal mesh stiffness S(t) (Appendix C, with
the operating transverse pressure angle alpha'_t and the base helix angle beta_b) and the engagement
shock force F_e(t) (eq. 2.62) acts along h.  Damping: modal viscous damping with zeta = eta / 2 for
every mode of the mean system (loss factor eta = 0.1, Sec. 2.5).

The periodic steady state is found by harmonic balance, which for this LINEAR periodic system is an
exact Fourier (Hill) expansion: the only coupling between harmonics is the scalar mesh deflection
d = h^T q, so the (2H+1) x (2H+1) Toeplitz system for d is solved directly; no iteration, no transient.
`time_integration` is the slow reference (implicit Radau to steady state).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from housingfe.errors import InputError, SolverError
from housingfe.levels import OMEGA0, band_sum, level, third_octave_bands
from housingfe.source.gears import GearPair
from housingfe.source.stiffness import Corrections, flank_gaps

# the engagement shock models (`engagement` of source and run-up scenes): the thesis' two-dimensional Eq. 2.62, the
# same shock per face-width slice of the contact lines (a helical tooth enters and leaves gradually), and the envelope
# bound of the latter near an integer overlap ratio (a bound, not a model: docs/source.md)
ENGAGEMENT_MODELS = ("face-width", "thesis-2d", "envelope-bound")
DEFAULT_ENGAGEMENT = "face-width"

# positions per base pitch at which the source samples the mesh stiffness (stiffness_curve; linearly interpolated
# onto the 256 instants of S(t)): the harmonic balance and the run-up take S's harmonics, and the shuttling moment's
# arm, up to the run-up's H = 30 lines; a harmonic n of the linear interpolant is the true one times sinc^2(n / P)
# plus images of n' = P +- n.  Chosen for <= 0.5 dB error of the run-up's total L_WA at every speed >= 250 rev/min
# against 512 positions (32: 3.3 dB at 250 rpm, 64: 0.9 dB, 128: 0.3 dB; sets A and uncorrected at 2000 N m:
# benchmarks/experiments/stiffness_positions)
DEFAULT_STIFFNESS_POSITIONS = 128

N_DOF = 14       # after eliminating the prescribed far-end angle (DOF 15 of the thesis)
WHEEL_THETA_Z = 11
BEARING_DOFS = {"pinion": [0, 1, 2, 3, 4], "wheel": [6, 7, 8, 9, 10]}


# ------------------------------------------------------------------------------------ parameters
@dataclass(frozen=True)
class LumpedInterior:
    """Parameters of the lumped model (SI).  Masses [kg], inertias [kg m^2] (axial = polar about the
    shaft axis, diametral = about a transverse axis through the gear centre), torsional shaft
    stiffnesses [N m/rad], bearing stiffness diagonals [N/m, N/m, N/m, N m/rad, N m/rad] for x, y, z,
    theta_x, theta_y of each shaft (Appendix C), loss factor eta [-]."""

    pinion_mass: float
    pinion_inertia_axial: float
    pinion_inertia_diametral: float
    wheel_mass: float
    wheel_inertia_axial: float
    wheel_inertia_diametral: float
    coupling_inertia: tuple[float, float]          # DOF 13, 14
    torsion_stiffness: tuple[float, float, float, float]   # shafts 1, 2, 3, 4
    pinion_bearings: tuple[float, float, float, float, float]
    wheel_bearings: tuple[float, float, float, float, float]
    loss_factor: float = 0.1

    def __post_init__(self):
        values = [self.pinion_mass, self.pinion_inertia_axial, self.pinion_inertia_diametral, self.wheel_mass,
                  self.wheel_inertia_axial, self.wheel_inertia_diametral, *self.coupling_inertia,
                  *self.torsion_stiffness, *self.pinion_bearings, *self.wheel_bearings]
        if not all(np.isfinite(values)) or min(values) <= 0:
            raise InputError("interior: masses, inertias and stiffnesses must be finite and > 0")
        if not 0 < self.loss_factor < 2:
            raise InputError(f"interior: loss_factor: {self.loss_factor} is outside (0, 2)")


@dataclass(frozen=True)
class ShaftGeometry:
    """Geometry from which `derive_interior` builds the lumped parameters (all m): bearing spans from
    the gear faces, diameter of the shaft between the bearings, and for the torsion shafts outside the
    gearbox (Appendix C: pi G d^4 / (32 l)) diameters and lengths of shafts 1-4."""

    pinion_spans: tuple[float, float] = (0.06, 0.06)
    pinion_shaft_diameter: float = 0.080
    wheel_spans: tuple[float, float] = (0.06, 0.06)
    wheel_shaft_diameter: float = 0.095
    torsion_diameters: tuple[float, float, float, float] = (0.040, 0.060, 0.075, 0.055)
    torsion_lengths: tuple[float, float, float, float] = (1.5, 0.25, 0.25, 1.5)
    coupling_inertia: tuple[float, float] = (0.02, 0.05)


# Appendix C's printed bearing stiffness diagonal (the only parameters that survived in the text).
APPENDIX_C_BEARINGS = {
    "pinion": (5.3e8, 7.3e8, 1.6e8, 5.2e6, 3.8e6),
    "wheel": (5.3e8, 5.7e8, 1.3e8, 3.7e6, 3.4e6),
}


def _cylinder(density: float, diameter: float, length: float) -> tuple[float, float, float]:
    """Mass [kg], polar and diametral (about its own centre) inertia [kg m^2] of a solid cylinder."""
    m = density * math.pi * diameter**2 / 4 * length
    r2 = diameter**2 / 4
    return m, m * r2 / 2, m * (3 * r2 + length**2) / 12


def derive_interior(pair: GearPair, geometry: ShaftGeometry = ShaftGeometry(), loss_factor: float = 0.1,
                    bearings: dict | None = None) -> LumpedInterior:
    """Lumped parameters from gear and shaft geometry (Appendix C's table did not survive): each gear
    is a solid cylinder of the mean of tip and root diameter over its face width, plus its shaft
    between the bearings (solid, `*_shaft_diameter`); diametral inertia about the gear centre by the
    parallel-axis theorem; torsion shafts k = pi G d^4 / (32 l)."""
    rho, E, nu = pair.density, pair.youngs_modulus, pair.poisson_ratio
    G = E / (2 * (1 + nu))
    out = {}
    for g, name, spans, dshaft in ((0, "pinion", geometry.pinion_spans, geometry.pinion_shaft_diameter),
                                   (1, "wheel", geometry.wheel_spans, geometry.wheel_shaft_diameter)):
        width = pair.face_width[g] * (2 if pair.kind == "double_helical" else 1) + (
            pair.helix_gap if pair.kind == "double_helical" else 0.0)
        dg = 0.5 * float(pair.tip_diameter[g] + pair.root_diameter[g])
        m, jp, jd = _cylinder(rho, dg, width)
        for span, sign in ((spans[0], -1), (spans[1], 1)):
            ms, jps, jds = _cylinder(rho, dshaft, span)
            arm = 0.5 * width + 0.5 * span
            m, jp, jd = m + ms, jp + jps, jd + jds + ms * arm**2
        out[name] = (m, jp, jd)
    k = tuple(math.pi * G * d**4 / (32 * l) for d, l in zip(geometry.torsion_diameters, geometry.torsion_lengths))
    b = bearings or APPENDIX_C_BEARINGS
    return LumpedInterior(*out["pinion"], *out["wheel"], coupling_inertia=geometry.coupling_inertia,
                    torsion_stiffness=k, pinion_bearings=tuple(b["pinion"]), wheel_bearings=tuple(b["wheel"]),
                    loss_factor=loss_factor)


# ------------------------------------------------------------------------------------ matrices
@dataclass
class Matrices:
    """M, K0 (everything except the mesh), mesh direction h, modal damping D, preload force per N m of
    torque in shaft 1 (f_unit), all for the 14 free DOFs."""

    M: np.ndarray
    K0: np.ndarray
    h: np.ndarray
    D: np.ndarray
    preload: np.ndarray
    mean_mesh_stiffness: float


def mesh_direction(pair: GearPair, axial_moment: bool = True) -> np.ndarray:
    """h (14,) with d = h^T q the mesh compression along the flank normal [m] (Appendix C: k_ij = S h_i h_j).
    Positive rotations of both gears close the mesh (theta_z of the wheel counts the other way).  The
    centre line is the x axis (wheel at +x) and the contact is taken at the operating pitch point, mid
    face.  axial_moment=True adds the tilt coupling theta_y: the axial force component F sin(beta_b)
    acts at the operating pitch radius r_w (h_4 = r_w1 sin(beta_b), h_10 = r_w2 sin(beta_b)); Appendix C
    lists only the x, y, z, theta_z terms, which leaves the bearing moments unexcited.

    Double helical pair: the two helices have opposite hands, normals n_+- = cos(beta_b) l +- sin(beta_b) z, and
    carry half the normal force each (S/2 each), so d = h^T q is the mean of the two helices' normal compressions
    and F h the resultant of the normal force F: no axial component, no tilt term, the transverse part
    cos(beta_b) l kept (h_3 = h_9 = h_5 = h_11 = 0).  Along the transverse line of action the mesh is then the
    stiffness S cos^2(beta_b) and carries F cos(beta_b) = T1 / r_b1 (docs/drivetrain.md).  The axial stiffness
    S sin^2(beta_b) of the halves against each other (relative axial motion compresses one, unloads the other) is
    not in h h^T: it positions a floating wheel and is not excited by the mesh (no mean or periodic axial load)."""
    a, bb = pair.operating_pressure_angle, pair.base_helix_angle
    rb1, rb2 = pair.base_diameter / 2
    h = np.zeros(N_DOF)
    axial = 0.0 if pair.kind == "double_helical" else -math.sin(bb)     # the halves' axial parts cancel
    h[0:3] = [math.sin(a) * math.cos(bb), math.cos(a) * math.cos(bb), axial]
    h[5] = rb1 * math.cos(bb)
    h[6:9] = -h[0:3]
    h[11] = rb2 * math.cos(bb)
    if axial_moment and pair.kind == "single_helical":     # double helical: the two helices' moments cancel
        rw1 = rb1 / math.cos(a)
        rw2 = rb2 / math.cos(a)
        h[4] = rw1 * math.sin(bb)
        h[10] = rw2 * math.sin(bb)
    return h


def assemble(pair: GearPair, interior: LumpedInterior, mean_mesh_stiffness: float, axial_moment: bool = True) -> Matrices:
    """Mass, stiffness and damping matrices of the 14-DOF model (mean mesh stiffness for the modes)."""
    it = interior
    M = np.diag([it.pinion_mass] * 3 + [it.pinion_inertia_diametral] * 2 + [it.pinion_inertia_axial]
                + [it.wheel_mass] * 3 + [it.wheel_inertia_diametral] * 2 + [it.wheel_inertia_axial]
                + list(it.coupling_inertia))
    K0 = np.zeros((N_DOF, N_DOF))
    K0[np.arange(5), np.arange(5)] = it.pinion_bearings
    K0[np.arange(6, 11), np.arange(6, 11)] = it.wheel_bearings
    k1, k2, k3, k4 = it.torsion_stiffness

    def spring(i, j, k):
        K0[i, i] += k
        K0[j, j] += k
        K0[i, j] -= k
        K0[j, i] -= k

    spring(5, 12, k2)
    spring(11, 13, k3)
    K0[12, 12] += k1          # to the held far end (DOF 15)
    K0[13, 13] += k4          # to the loading gearbox, torsionally held
    h = mesh_direction(pair, axial_moment)
    K = K0 + mean_mesh_stiffness * np.outer(h, h)
    w2, phi = sla.eigh(K, M)
    if w2.min() <= 0:
        raise SolverError("dynamics: the mean system is not positive definite")
    zeta = it.loss_factor / 2
    Mphi = M @ phi
    D = Mphi @ np.diag(2 * zeta * np.sqrt(w2)) @ Mphi.T
    preload = np.zeros(N_DOF)
    preload[12] = 1.0          # the held angle acts as k1 * theta_15 on DOF 12
    return Matrices(M=M, K0=K0, h=h, D=D, preload=preload, mean_mesh_stiffness=mean_mesh_stiffness)


def natural_frequencies(mats: Matrices) -> np.ndarray:
    """Undamped natural frequencies [Hz] of the mean system."""
    w2 = sla.eigh(mats.K0 + mats.mean_mesh_stiffness * np.outer(mats.h, mats.h), mats.M, eigvals_only=True)
    return np.sqrt(np.abs(w2)) / (2 * math.pi)


def preload_force(mats: Matrices, torque: float) -> np.ndarray:
    """Constant force vector [N, N m] that makes shaft 1 carry `torque` [N m] in the static mean system
    (Sec. 2.5: theta_15 is found from the static solution of eq. 2.56)."""
    K = mats.K0 + mats.mean_mesh_stiffness * np.outer(mats.h, mats.h)
    q = np.linalg.solve(K, mats.preload)          # response to a unit force k1 theta_15 = 1
    k1 = mats.K0[12, 12] - (-mats.K0[12, 5])      # k1 = K0[12,12] - k2
    torque_per_unit = 1.0 - k1 * q[12]            # torque in shaft 1 = k1 (theta15 - theta13)
    return mats.preload * torque / torque_per_unit


# ------------------------------------------------------------------------------------ excitation
def engagement_force(pair: GearPair, corrections: Corrections, stiffness: np.ndarray, normal_force: float,
                     n_samples: int | None = None, contact_ratio: float | None = None) -> np.ndarray:
    """Engagement/disengagement shock force F_e [N] over one mesh period (eq. 2.62, Fig. 2.14/2.16),
    sampled at the positions of `stiffness` (S(t) [N/m], one period, uniformly spaced).

    Our reading of eq. 2.62: the tooth pairs are springs spaced one transverse pitch apart on a contact
    length eps_tot * p; every pair in contact is asked for the deflection delta_i = max(delta - e(s_i), 0)
    with delta = F / S(t) and e the tip relief of the wheel (at the start, length l_2) and the pinion (at
    the end, length l_1); F_e = S(t) (sum_i delta_i - mean) / eps_tot.  For the 3-D correction D the
    relief ramps are those of Fig. F.1's profile direction (amount, length).  contact_ratio: eps_tot by default
    (the thesis treats a helical pair as a spur pair with the total contact ratio); eps_alpha gives the shock
    of the transverse section."""
    S = np.asarray(stiffness, dtype=float)
    n = S.size if n_samples is None else n_samples
    t = np.arange(n) / n
    if n != S.size:
        S = np.interp(t, np.arange(S.size) / S.size, S, period=1.0)
    pitch = pair.transverse_base_pitch
    eps = pair.total_contact_ratio if contact_ratio is None else contact_ratio
    length = eps * pitch
    delta = normal_force / S
    total = np.zeros(n)
    for k in range(int(math.ceil(eps)) + 1):
        s = (t + k) * pitch                           # position of pair k on the contact length
        inside = s < length
        e = np.zeros(n)
        ca1, l1 = corrections.tip_relief[0], corrections.tip_relief_length[0]
        ca2, l2 = corrections.tip_relief[1], corrections.tip_relief_length[1]
        if ca2 > 0:
            e += ca2 * np.clip((l2 - s) / l2, 0, 1)
        if ca1 > 0:
            e += ca1 * np.clip((s - (length - l1)) / l1, 0, 1)
        total += np.where(inside, np.maximum(delta - e, 0.0), 0.0)
    return S * (total - total.mean()) / eps


def engagement_force_face_width(pair: GearPair, corrections: Corrections, stiffness: np.ndarray,
                                normal_force: float, load_share: np.ndarray | None = None,
                                n_slices: int = 256, n_samples: int | None = None,
                                origin: float = 0.0, helix_stagger: bool = True,
                                exact_edges: bool = True) -> np.ndarray:
    """Engagement/disengagement shock force F_e [N] over one mesh period, distributed over the face width:
    Eq. 2.62 applied per face-width slice of the contact lines, sampled like `engagement_force`.

    Every helix is cut into `n_slices` slices of width b / n_slices at offsets o_j from its leading face; slice j
    of tooth pair k sits at the roll position s = origin + (t + k) p_bt + o_j tan(beta_b) [m from T1] (origin = 0:
    the convention of MeshModel.contact_points, so F_e is in phase with the stiffness curve; origin = A puts
    pair 0's leading face at the start of contact at t = 0, as `engagement_force` does) and is in contact for
    A <= s < E.  Its required deflection is max(delta - e, 0), delta = F / S(t), e the gap of the corrections at
    (s, w) (`flank_gaps`: tip reliefs, the 3-D triangular correction, width relief).  The slices are springs of
    stiffness S(t) phi_j / (eps_alpha n_slices n_helices), phi_j = `load_share` (helices, m) resampled to the
    slices (how the mesh stiffness is distributed across the face, mean 1; None: uniform):
    F_e = S(t) (D(t) - mean D), D = sum over slices in contact of phi_j max(delta - e, 0) / (eps_alpha n_slices
    n_helices).  A slice's share of the load is thus its stiffness times its deflection compatibility, and a
    helical tooth enters over eps_beta mesh periods instead of at once.

    Limits (tests/source/roosmalen/test_dynamics.py): spur gears (eps_beta = 0) with origin = A give exactly
    `engagement_force`; for a uniform load and constant S the harmonics are those of the transverse-section
    shock (Eq. 2.62 with eps_alpha) times the slices' array factor, |sinc(n eps_beta)| for many slices.

    helix_stagger = False drops the o_j tan(beta_b) term: every slice of a contact line at the same roll position
    (the pair's transverse, spur-equivalent shock with the same load share and flank gaps; the reference of the
    envelope bound in housingfe.source.roosmalen.overlap and `engagement_force_envelope_bound`).

    exact_edges = True (default): a staggered slice covers the roll positions s +- (b / n_slices) tan(beta_b) / 2, and
    where the start A or the end E of the path of contact cuts it, it counts with the fraction inside and its gap is
    taken at the middle of that part: the contact edges move continuously with t instead of jumping from slice to
    slice.  Near an integer eps_beta the helix cancels the edges' steps to a residual ~|sinc(n eps_beta)| of them, a
    window of (eps_beta - 1) p_bt only a few slices wide, which midpoint slices (exact_edges = False, before) resolve
    badly (benchmarks/experiments/excitation_convergence)."""
    S = np.asarray(stiffness, dtype=float)
    n = S.size if n_samples is None else n_samples
    t = np.arange(n) / n
    if n != S.size:
        S = np.interp(t, np.arange(S.size) / S.size, S, period=1.0)
    if n_slices < 1:
        raise InputError(f"dynamics: n_slices: need at least 1 slice, got {n_slices}")
    p = pair.transverse_base_pitch
    A, E_ = pair.path_of_contact
    b = pair.contact_width
    tb = math.tan(pair.base_helix_angle)
    helices = 2 if pair.kind == "double_helical" else 1
    offset = (np.arange(n_slices) + 0.5) / n_slices * b
    if load_share is None:
        share = np.ones((helices, n_slices))
    else:
        ls = np.atleast_2d(np.asarray(load_share, dtype=float))
        if ls.shape[0] != helices or not np.all(np.isfinite(ls)) or ls.min() < 0:
            raise InputError(f"dynamics: load_share: need ({helices}, m) finite values >= 0, got shape {ls.shape}")
        centres = (np.arange(ls.shape[1]) + 0.5) / ls.shape[1] * b
        share = np.array([np.interp(np.where(hx == 0, offset, b - offset), centres, ls[hx]) for hx in range(helices)])
        share /= share.mean()
    delta = (normal_force / S)[:, None]
    k_lo = math.floor((A - origin - b * tb) / p) - 1
    k_hi = math.ceil((E_ - origin) / p) + 1
    # half a slice's extent along s (0: no stagger, a line's slices share one s and its edges are sharp anyway)
    half = 0.5 * b / n_slices * tb if (exact_edges and helix_stagger and tb > 0) else 0.0
    total = np.zeros(n)
    for hx in range(helices):
        w_local = offset if hx == 0 else b - offset           # helix 1 has the opposite hand
        w = w_local + hx * (b + pair.helix_gap)
        for k in range(k_lo, k_hi + 1):
            s = origin + (t[:, None] + k) * p + (offset[None, :] * tb if helix_stagger else 0.0 * offset[None, :])
            if half > 0:
                lo, hi = np.maximum(s - half, A), np.minimum(s + half, E_)
                inside = np.clip((hi - lo) / (2 * half), 0.0, 1.0)
                if not inside.any():
                    continue
                s_mid = np.where(inside > 0, 0.5 * (lo + hi), s)          # the middle of the part in contact
                wl = offset[None, :] + (s_mid - s) / tb
                wl = wl if hx == 0 else b - wl
                e = flank_gaps(pair, corrections, s_mid, wl, wl + hx * (b + pair.helix_gap), hx)
            else:
                inside = ((s >= A) & (s < E_)).astype(float)
                if not inside.any():
                    continue
                e = flank_gaps(pair, corrections, s, w_local[None, :], w[None, :], hx)
            total += (inside * np.maximum(delta - e, 0.0) * share[hx][None, :]).sum(axis=1)
    total /= pair.transverse_contact_ratio * n_slices * helices
    return S * (total - total.mean())


def envelope_factor(n, eps_beta: float) -> np.ndarray:
    """min(1, 1 / (pi n eps_beta)) [-] per harmonic n >= 1: the envelope of |sinc(n eps_beta)|; 1 for eps_beta = 0."""
    n = np.asarray(n, dtype=float)
    if eps_beta <= 0.0:
        return np.ones_like(n)
    return np.minimum(1.0, 1.0 / (math.pi * n * eps_beta))


def engagement_force_envelope_bound(pair: GearPair, corrections: Corrections, stiffness: np.ndarray,
                                    normal_force: float, load_share: np.ndarray | None = None,
                                    n_slices: int = 256) -> np.ndarray:
    """F_e [N] over one mesh period (samples of `stiffness` S(t) [N/m]) whose quasi-static excitation is the envelope
    bound of housingfe.source.roosmalen.overlap: engagement "envelope-bound", a bound and a sensitivity, not a model.

    Start: the face-width slice model with every slice of a contact line in phase (`engagement_force_face_width`
    with helix_stagger=False, the same load share and flank gaps: the shock without the helix's cancellation) and its
    quasi-static mesh compression d_ip = (F - F_e,ip) / S(t).  The scaled quantity is that compression (so the
    excitation k_m (d - mean d) = k_m x TE), not the shock: each harmonic n >= 1 of d_ip is multiplied by
    min(1, 1 / (pi n eps_beta)) (`envelope_factor`; phase and the mean kept), d_b = inverse FFT, and
    F_e = F - S(t) d_b, whose quasi-static compression is d_b exactly.  (Scaling F_e,ip itself would leave the
    stiffness term F / S(t) unscaled and miss the documented bound.)  Spur gears (eps_beta = 0): the factor is 1
    and F_e is the face-width shock (to rounding)."""
    S = np.asarray(stiffness, dtype=float)
    flat = engagement_force_face_width(pair, corrections, S, normal_force, load_share=load_share, n_slices=n_slices,
                                       helix_stagger=False)
    d = quasi_static_compression(S, flat, normal_force)
    coefficients = np.fft.rfft(d - d.mean())
    coefficients[1:] *= envelope_factor(np.arange(1, coefficients.size), pair.overlap_ratio)
    return normal_force - S * (d.mean() + np.fft.irfft(coefficients, S.size))


def engagement_force_from_transmission_error(stiffness: np.ndarray, normal_force: float,
                                            transmission_error: np.ndarray) -> np.ndarray:
    """F_e [N] over one mesh period (samples of `stiffness` S(t) [N/m]) whose quasi-static mesh compression
    (F - F_e) / S is mean(F / S) + e(t), e = `transmission_error` [m] (samples of the same instants): a TE the user
    brings (housingfe.source.transmission_error) instead of an engagement model, on the model's own S(t).  The
    quasi-static excitation k_m (d - mean d) is then k_m e(t) exactly; the constant mean(F / S) (the stiffness-only
    compression) only sets the static state, which no harmonic sees."""
    S = np.asarray(stiffness, dtype=float)
    e = np.asarray(transmission_error, dtype=float)
    return normal_force - S * (np.mean(normal_force / S) + e)


def engagement_shock(model: str, pair: GearPair, corrections: Corrections, stiffness: np.ndarray,
                     normal_force: float, load_share: np.ndarray | None = None) -> np.ndarray:
    """F_e [N] of the engagement model `model` (ENGAGEMENT_MODELS): "thesis-2d" = `engagement_force` (Eq. 2.62,
    the replica of the thesis), "face-width" = `engagement_force_face_width` with the given load share,
    "envelope-bound" = `engagement_force_envelope_bound` (the face-width excitation's envelope bound, not a model)."""
    if model == "thesis-2d":
        return engagement_force(pair, corrections, stiffness, normal_force)
    if model == "face-width":
        return engagement_force_face_width(pair, corrections, stiffness, normal_force, load_share=load_share)
    if model == "envelope-bound":
        return engagement_force_envelope_bound(pair, corrections, stiffness, normal_force, load_share=load_share)
    raise InputError(f"engagement: {model!r} is not one of {', '.join(ENGAGEMENT_MODELS)}")


# ------------------------------------------------------------------------------------ harmonic balance
@dataclass
class SteadyState:
    """Periodic steady state: q(t) = sum_n Q[n] exp(i n Omega t), n = -H..H (two-sided coefficients).
    tooth_frequency [Hz]; Q (2H+1, 14) [m, rad]; mesh_force (2H+1,) [N] (S(t) d(t) + F_e(t))."""

    tooth_frequency: float
    harmonics: np.ndarray
    Q: np.ndarray
    mesh_force: np.ndarray

    def one_sided(self, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Frequencies n f_tooth [Hz] (n >= 1) and one-sided complex amplitudes 2 X_n."""
        pos = self.harmonics >= 1
        return self.harmonics[pos] * self.tooth_frequency, 2 * values[pos]

    def wheel_angular_velocity(self) -> tuple[np.ndarray, np.ndarray]:
        """(f [Hz], one-sided complex amplitude of the wheel's angular velocity [rad/s])."""
        omega = 2 * math.pi * self.tooth_frequency
        return self.one_sided(1j * self.harmonics * omega * self.Q[:, WHEEL_THETA_Z])

    def wheel_velocity_mean_square(self) -> tuple[np.ndarray, np.ndarray]:
        """(f [Hz], mean square of each harmonic line of the wheel angular velocity [(rad/s)^2])."""
        f, a = self.wheel_angular_velocity()
        return f, 0.5 * np.abs(a) ** 2


@dataclass
class ContactCheck:
    """Whether the teeth stay in contact over one period of a steady state (contact_check).  min_force_N, mean_force_N:
    the smallest and the mean total mesh force S(t) d(t) + F_e(t) [N]; lost: min_force_N < 0 (the teeth separate
    and the linear model, which lets the mesh pull, is invalid there); message: "contact loss at ... N m, ... rpm"
    (when torque and speed were given) or ""."""

    min_force_N: float
    mean_force_N: float
    lost: bool
    message: str


def contact_check(state: SteadyState, torque: float | None = None, speed_rpm: float | None = None,
                  n_samples: int = 1024) -> ContactCheck:
    """Check a harmonic-balance steady state for contact loss: the mesh force of `state` sampled over one tooth
    period.  The linear model holds while it is positive; where the dynamic part exceeds the mean (the dynamic mesh
    deflection exceeds the static one) the real teeth separate and the levels are not what the model says.
    torque [N m] and speed_rpm [rev/min] only label the message."""
    t = np.arange(n_samples) / n_samples
    force = np.real(np.exp(2j * math.pi * np.outer(t, state.harmonics)) @ state.mesh_force)
    mean = float(np.real(state.mesh_force[state.harmonics == 0][0]))
    low = float(force.min())
    lost = low < 0.0
    where = " at " + ", ".join(x for x in (f"{torque:g} N m" if torque is not None else "",
                                          f"{speed_rpm:g} rpm" if speed_rpm is not None else "") if x)
    message = (f"contact loss{where if where != ' at ' else ''}: the mesh force falls to {low:.4g} N (mean "
               f"{mean:.4g} N); the teeth separate and the linear harmonic balance is invalid there") if lost else ""
    return ContactCheck(low, mean, lost, message)


def _fourier_coefficients(samples: np.ndarray, H: int) -> np.ndarray:
    """Two-sided coefficients c_n, n = -2H..2H, of a periodic real signal sampled uniformly (zero beyond
    the Nyquist limit)."""
    N = samples.size
    X = np.fft.fft(samples) / N
    out = np.zeros(4 * H + 1, dtype=complex)
    for n in range(-2 * H, 2 * H + 1):
        if abs(n) < N / 2:
            out[n + 2 * H] = X[n % N]
    return out


def harmonic_balance(mats: Matrices, stiffness: np.ndarray, shock: np.ndarray, preload: np.ndarray,
                     tooth_frequency: float, H: int = 40) -> SteadyState:
    """Periodic steady state of M q'' + D q' + (K0 + S(t) h h^T) q = f0 - F_e(t) h (Hill expansion with
    harmonics -H..H of the tooth frequency [Hz]).  stiffness, shock: one period, uniformly sampled [N/m, N]."""
    if tooth_frequency <= 0:
        raise InputError(f"dynamics: tooth frequency must be > 0 Hz, got {tooth_frequency}")
    Om = 2 * math.pi * tooth_frequency
    n = np.arange(-H, H + 1)
    Xs = _fourier_coefficients(np.asarray(stiffness, float), H)      # index k + 2H
    Es = _fourier_coefficients(np.asarray(shock, float), H)[H:3 * H + 1]
    h = mats.h
    g = np.empty(n.size, dtype=complex)
    b = np.zeros(n.size, dtype=complex)
    Zh = np.empty((n.size, N_DOF), dtype=complex)
    Zf0 = None
    for i, nn in enumerate(n):
        Z = mats.K0 - (nn * Om) ** 2 * mats.M + 1j * nn * Om * mats.D
        sol = np.linalg.solve(Z, np.column_stack([h, preload]) if nn == 0 else h[:, None])
        Zh[i] = sol[:, 0]
        g[i] = h @ sol[:, 0]
        if nn == 0:
            Zf0 = sol[:, 1]
            b[i] = h @ Zf0
    T = Xs[(n[:, None] - n[None, :]) + 2 * H]                          # Toeplitz X_{n-m}
    A = np.eye(n.size) + g[:, None] * T
    d = np.linalg.solve(A, b - g * Es)
    mesh = T @ d + Es                                                  # S(t) d(t) + F_e(t), harmonics
    Q = -Zh * mesh[:, None]
    Q[H] += Zf0
    return SteadyState(tooth_frequency=tooth_frequency, harmonics=n, Q=Q, mesh_force=mesh)


# ------------------------------------------------------------------------------------ harmonic balance on a receptance
@dataclass
class MeshSteadyState:
    """Periodic steady state of the mesh alone (two-sided harmonics n = -H..H of the tooth frequency [Hz]):
    compression d [m] (the dynamic transmission error d = h^T q), mesh_force W = S(t) d(t) + F_e(t) [N] and the
    excitation W - k_ref d [N] that the structure holding the reference stiffness k_ref [N/m] is loaded with."""

    tooth_frequency: float
    harmonics: np.ndarray
    compression: np.ndarray
    mesh_force: np.ndarray
    excitation: np.ndarray
    reference_stiffness: float

    def one_sided(self, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Frequencies n f_tooth [Hz] (n >= 1) and one-sided complex amplitudes 2 X_n."""
        pos = self.harmonics >= 1
        return self.harmonics[pos] * self.tooth_frequency, 2 * values[pos]


def quasi_static_compression(stiffness: np.ndarray, shock: np.ndarray, mean_force: float) -> np.ndarray:
    """d_qs(t) = (F - F_e(t)) / S(t) [m]: the mesh compression at zero speed, where the mesh force S d + F_e equals
    the transmitted normal force F [N] at every instant (samples of one period, as stiffness and shock)."""
    return (mean_force - np.asarray(shock, float)) / np.asarray(stiffness, float)


def mesh_harmonic_balance(receptance: np.ndarray, static_compression: float, stiffness: np.ndarray,
                          shock: np.ndarray, reference_stiffness: float, tooth_frequency: float = float("nan"),
                          first_order: bool = False) -> MeshSteadyState:
    """Periodic steady state of the time-varying mesh S(t) on ANY linear structure, from the structure's receptance
    at the mesh coordinate alone (the rank-one Hill expansion of `harmonic_balance`, generalised).

    The structure (the rigid-bore lumped interior, or the coupled gearbox: housing, bearings, shafts, gear bodies)
    holds the constant mesh stiffness k_ref = reference_stiffness [N/m]; receptance[n] = g(n Omega) = h^T H(n Omega) h
    [m/N], n = 0..H (H = len - 1; g(-w) = conj g(w)), its compression under a unit compressive mesh-force pair;
    static_compression b_0 [m] its static mesh compression under the external mean loads (the torque).  The mesh
    adds (S(t) - k_ref) d + F_e(t), so per harmonic

        d_n = b_0 delta_n0 - g_n (sum_m (S - k_ref)_{n-m} d_m + E_n),      n = -H..H,

    a (2H+1)^2 Toeplitz solve: exact for the linear periodic system as H grows (what Perret-Liaudet's spectral
    iterative method converges to).  With receptance of the rigid-bore model this is `harmonic_balance`.

    first_order=True: the mean-stiffness solve (Velex; Eritenel): the structure holding k_ref is loaded by the
    quasi-static transmission error, W_n - k_ref d_n = -k_ref d_qs,n (n != 0, `quasi_static_compression` with
    F = k_ref b_0): exact at zero speed, it neglects the parametric feedback of the dynamic compression on the
    ripple S - k_ref.  stiffness, shock: one period, uniformly sampled [N/m, N]."""
    g1 = np.asarray(receptance, complex)
    H = g1.size - 1
    if H < 1:
        raise InputError("dynamics: receptance: need g at n = 0..H with H >= 1")
    n = np.arange(-H, H + 1)
    g = np.where(n >= 0, g1[np.abs(n)], np.conj(g1[np.abs(n)]))
    Xs = _fourier_coefficients(np.asarray(stiffness, float), H)
    Es = _fourier_coefficients(np.asarray(shock, float), H)[H:3 * H + 1]
    k = float(reference_stiffness)
    b = np.zeros(n.size, complex)
    b[H] = static_compression
    T = Xs[(n[:, None] - n[None, :]) + 2 * H]
    dT = T - k * np.eye(n.size)
    if first_order:
        F = k * float(static_compression)
        qs = _fourier_coefficients(quasi_static_compression(stiffness, shock, F), H)[H:3 * H + 1]
        exc = -k * qs
        exc[H] = 0.0                           # the mean: the mean system's static state, W_0 = k_ref b_0
        d = b - g * exc
    else:
        d = np.linalg.solve(np.eye(n.size) + g[:, None] * dT, b - g * Es)
        exc = dT @ d + Es
    return MeshSteadyState(tooth_frequency=float(tooth_frequency), harmonics=n, compression=d,
                           mesh_force=exc + k * d, excitation=exc, reference_stiffness=k)


def lumped_receptance(mats: Matrices, preload: np.ndarray, tooth_frequency: float, H: int,
                      reference_stiffness: float) -> tuple[np.ndarray, float]:
    """(g(n Omega) n = 0..H [m/N], static compression b_0 [m]) of the rigid-bore lumped model holding the mesh
    stiffness reference_stiffness [N/m]: the inputs of `mesh_harmonic_balance` that make it `harmonic_balance`."""
    Om = 2 * math.pi * tooth_frequency
    h = mats.h
    K = mats.K0 + reference_stiffness * np.outer(h, h)
    g = np.empty(H + 1, complex)
    for nn in range(H + 1):
        g[nn] = h @ np.linalg.solve(K - (nn * Om) ** 2 * mats.M + 1j * nn * Om * mats.D, h)
    return g, float(h @ np.linalg.solve(K, preload))


def time_integration(mats: Matrices, stiffness: np.ndarray, shock: np.ndarray, preload: np.ndarray,
                     tooth_frequency: float, periods: int, samples_per_period: int = 64,
                     rtol: float = 1e-8, method: str = "Radau") -> tuple[np.ndarray, np.ndarray]:
    """Slow reference: integrate from the static mean solution over `periods` mesh periods with scipy's
    solve_ivp (S(t), F_e(t) as trigonometric interpolants, eq. 2.60).  Returns the last period's time
    samples [s] and states q (samples, 14)."""
    from scipy.integrate import solve_ivp

    T = 1.0 / tooth_frequency
    # trigonometric interpolants without the Nyquist term, as in `harmonic_balance`
    n_s = len(stiffness)
    Xs = np.fft.rfft(np.asarray(stiffness, float))[: (n_s + 1) // 2] / n_s
    Es = np.fft.rfft(np.asarray(shock, float))[: (n_s + 1) // 2] / n_s
    if len(shock) != n_s:
        raise InputError("dynamics: stiffness and shock must be sampled at the same points")
    ks = np.arange(Xs.size)

    def trig(c, t):
        ph = np.exp(2j * math.pi * ks * t / T)
        w = np.where(ks == 0, 1.0, 2.0)
        return float(np.real(np.sum(w * c * ph)))

    Minv = np.linalg.inv(mats.M)
    h = mats.h

    def rhs(t, y):
        q, v = y[:N_DOF], y[N_DOF:]
        force = preload - mats.K0 @ q - trig(Xs, t) * h * (h @ q) - trig(Es, t) * h - mats.D @ v
        return np.concatenate([v, Minv @ force])

    def jac(t, y):
        K = mats.K0 + trig(Xs, t) * np.outer(h, h)
        J = np.zeros((2 * N_DOF, 2 * N_DOF))
        J[:N_DOF, N_DOF:] = np.eye(N_DOF)
        J[N_DOF:, :N_DOF] = -Minv @ K
        J[N_DOF:, N_DOF:] = -Minv @ mats.D
        return J

    q0 = np.linalg.solve(mats.K0 + np.real(Xs[0]) * np.outer(h, h), preload)
    t_eval = (periods - 1) * T + np.arange(samples_per_period) * T / samples_per_period
    kw = {"jac": jac} if method in ("Radau", "BDF", "LSODA") else {}
    sol = solve_ivp(rhs, (0, periods * T), np.concatenate([q0, np.zeros(N_DOF)]), method=method,
                    t_eval=t_eval, rtol=rtol, atol=1e-14, **kw)
    if not sol.success:
        raise SolverError(f"dynamics: time integration failed: {sol.message}")
    return sol.t, sol.y[:N_DOF].T


# ------------------------------------------------------------------------------------ levels
def wheel_levels(state: SteadyState, f_max: float | None = None) -> dict[str, np.ndarray]:
    """L_omega of the wheel (eq. 2.61, omega0 = 5e-8 rad/s): narrow-band lines (f, dB) and 1/3-octave
    bands (centre, dB) up to f_max [Hz]."""
    f, ms = state.wheel_velocity_mean_square()
    if f_max is not None:
        keep = f <= f_max
        f, ms = f[keep], ms[keep]
    bands = third_octave_bands(max(10.0, f.min() / 1.2), f.max() * 1.1)
    banded = band_sum(f, ms, bands)
    return {"f": f, "L_omega": level(ms, OMEGA0), "band_center": bands.center, "band_nominal": bands.nominal,
            "band_L_omega": level(banded, OMEGA0)}


def tooth_band_level(state: SteadyState) -> float:
    """L_omega [dB] in the 1/3-octave band that contains the tooth frequency."""
    f, ms = state.wheel_velocity_mean_square()
    bands = third_octave_bands(state.tooth_frequency / 1.3, state.tooth_frequency * 1.3)
    banded = band_sum(f, ms, bands)
    inside = (bands.lower <= state.tooth_frequency) & (state.tooth_frequency < bands.upper)
    return float(level(banded[inside].sum(), OMEGA0))


# ------------------------------------------------------------------------------------ bearing spectra
@dataclass
class BearingSpectra:
    """Harmonic bearing loads for the housing model at one operating point.

    frequency [Hz] (n f_tooth, n = 1..H); bearing names and axial positions z [m] (from the gear
    centre plane, along the shaft); loads (n_bearings, 6, n_freq) complex one-sided amplitudes of
    [F_x, F_y, F_z (N), M_x, M_y, M_z (N m)] that the SHAFT exerts on the housing at the bearing,
    load(t) = Re(sum A exp(i 2 pi f t)); axes as in the lumped model (z along the shafts).
    The lumped model has one 5-DOF spring per shaft (Appendix C); its reaction is split over the two
    bearings of the shaft by statics (radial forces by the lever rule, the tilt moment as a force
    couple, the axial force to the bearing at z < 0, the locating bearing)."""

    speed_rpm: float
    torque_Nm: float
    frequency: np.ndarray
    names: list[str]
    z: np.ndarray
    loads: np.ndarray
    lumped: np.ndarray | None = None      # (2, 5, n_freq): unsplit [Fx, Fy, Fz, Mx, My] per shaft at the gear centre


def bearing_spectra(state: SteadyState, mats: Matrices, interior: LumpedInterior, geometry: ShaftGeometry,
                    pair: GearPair, speed_rpm: float, torque: float) -> BearingSpectra:
    """Bearing loads of both shafts from the steady state (see `BearingSpectra`)."""
    pos = state.harmonics >= 1
    names, zs, loads, lumped = [], [], [], []
    for g, shaft, spans, kb in ((0, "pinion", geometry.pinion_spans, interior.pinion_bearings),
                                (1, "wheel", geometry.wheel_spans, interior.wheel_bearings)):
        dofs = BEARING_DOFS[shaft]
        react = 2 * (np.asarray(kb)[:, None] * state.Q[pos][:, dofs].T)        # (5, H): Fx Fy Fz Mx My
        lumped.append(react)
        half = 0.5 * pair.face_width[g]
        zl, zr = -(half + spans[0]), half + spans[1]
        L = zr - zl
        wl, wr = zr / L, -zl / L                       # lever rule for a force at z = 0
        Fx, Fy, Fz, Mx, My = react
        # a moment M_y about the centre = force couple F_x = -M_y / L at zl, + M_y / L at zr (and M_x ~ F_y)
        left = np.array([wl * Fx - My / L, wl * Fy + Mx / L, Fz, 0 * Fz, 0 * Fz, 0 * Fz])
        right = np.array([wr * Fx + My / L, wr * Fy - Mx / L, 0 * Fz, 0 * Fz, 0 * Fz, 0 * Fz])
        names += [f"{shaft}_left", f"{shaft}_right"]
        zs += [zl, zr]
        loads += [left, right]
    f = state.harmonics[pos] * state.tooth_frequency
    return BearingSpectra(speed_rpm=speed_rpm, torque_Nm=torque, frequency=f, names=names, z=np.array(zs),
                          loads=np.array(loads), lumped=np.array(lumped))
