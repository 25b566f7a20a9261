"""Gears as made: tooth-to-tooth deviations within an ISO 1328-1 accuracy grade and their first-order loaded
transmission error over the hunting period (issue 28, benchmarks/experiments/as_made).  An experiment's tools, not
part of the default chain: nothing in the source model calls this module.

First-order loaded TE.  At a mesh position the load distribution of the existing 3-D mesh model
(`stiffness.MeshModel`, Sec. 2.3) solves (C + H) F = delta - e over the contact points in contact, sum F = F_tot
(C: tooth, plate, shaft and body compliances; H: the Hertzian approach; e: the flank gaps).  A small extra gap
de_i at the points (material missing on a flank, along the mesh normal) changes the approach by

    d delta = sum_i k_i de_i / sum_i k_i,    k = (C + H_t)^-1 1 over the points in contact,

k_i the points' stiffnesses (the row sums of the stiffness matrix, H_t the tangent Hertz compliance; sum k_i is the
mesh stiffness dF/d delta at that position).  This holds while the deviations are small against the deflection
(about 40 um at set A's 2000 N m) and change no point's contact state; the as-made deviations of an ISO grade 5
gear are 6-9 um.  The deviation of a flank point is the sum of the pinion's and the wheel's gaps there."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from housingfe.errors import InputError
from housingfe.source.gears import GearPair
from housingfe.source.stiffness import MeshModel

# ISO 1328-1:1995 Sec. 5.2.4: a formula takes the geometric mean of the limits of the range its parameter lies in
_MODULE_RANGES_MM = (0.5, 2.0, 3.5, 6.0, 10.0, 16.0, 25.0, 40.0, 70.0)
_DIAMETER_RANGES_MM = (5.0, 20.0, 50.0, 125.0, 280.0, 560.0, 1000.0, 1600.0, 2500.0, 4000.0, 6000.0, 8000.0, 10000.0)
_WIDTH_RANGES_MM = (4.0, 10.0, 20.0, 40.0, 80.0, 160.0, 250.0, 400.0, 650.0, 1000.0)

DEVIATION_KINDS = ("pitch", "profile_slope", "profile_form", "helix_slope", "twist")

# the shape of the pitch deviations' order spectrum (draw_deviations, deviation_statistics): "independent" = single
# pitch deviations drawn independently per tooth (a nearly white spectrum: sidebands at every shaft order, the upper
# bound of the high-order sideband energy); "runout" = the tooth positions one order-1 sinusoid per gear, each tooth
# carrying its displacement unchanged through the mesh (sidebands only at the tooth orders +- 1 shaft order of that
# gear); "none" = no pitch deviations, which is also the first-order limit of a pure eccentricity: the contact
# normals of an involute pair are all parallel (the plane of action), so a translated gear opens every contact
# point by the same gap, and the first-order TE sum k_i e_i / sum k_i is that gap, one order-1 line below every
# tooth band (its sidebands come only from the stiffness ripple k(t) e(t), a second-order term this module drops).
# The flank deviations stay independent per tooth in all three.
PITCH_MODELS = ("independent", "runout", "none")
DEFAULT_PITCH_MODEL = "independent"


def check_pitch_model(value) -> str:
    """The pitch model (PITCH_MODELS) or InputError "as_made_pitch: ..."."""
    if isinstance(value, str) and value in PITCH_MODELS:
        return value
    raise InputError(f"as_made_pitch: {value!r} is not a pitch-deviation model; choose from "
                     + ", ".join(f'"{m}"' for m in PITCH_MODELS))


def runout_amplitude(teeth: int, tolerances: dict) -> float:
    """Largest amplitude [m, along the reference circle in the transverse plane] of the "runout" pitch model's
    order-1 sinusoid of the tooth positions, x_t = A cos(2 pi t / z + phi): F_p / 2, so that its cumulative pitch
    deviation (range of the positions, <= 2 A) stays within ISO 1328-1 F_p (Sec. 6.3), capped where few teeth
    would take a single pitch step 2 A sin(pi / z) beyond f_pt (z < ~10 at grade 5; never on set A).  A pure
    eccentricity e shifts the flanks by e / cos(alpha) along the reference circle, so this is e <= F_p cos(alpha) / 2;
    ISO 1328-2's radial runout tolerance F_r (2 e with a ball probe) is quoted as about 0.8 F_p for the same
    grade (not read from the standard's text here), i.e. about 0.85 of this amplitude (-1.4 dB)."""
    amplitude = tolerances["F_p"] / 2
    if tolerances["f_pt"] > 0 and teeth > 1:
        amplitude = min(amplitude, tolerances["f_pt"] / (2 * math.sin(math.pi / teeth)))
    return amplitude


def _range_mean(value: float, limits: tuple[float, ...], name: str) -> float:
    for lo, hi in zip(limits[:-1], limits[1:]):
        if lo <= value <= hi:
            return math.sqrt(lo * hi)
    raise InputError(f"as_made: {name} {value:g} mm lies outside the ISO 1328-1 range {limits[0]:g}-{limits[-1]:g} mm")


def _iso_round(x: float) -> float:
    """ISO 1328-1:1995 Sec. 5.2.3: > 10 um to whole um, 5-10 um to 0.5 um, < 5 um to 0.1 um."""
    if x > 10.0:
        return float(round(x))
    if x >= 5.0:
        return round(2.0 * x) / 2.0
    return round(x, 1)


def iso1328_tolerances(normal_module: float, reference_diameter: float, face_width: float, grade: int = 5) -> dict:
    """Allowable values [m] of ISO 1328-1:1995 for one gear (module, reference diameter and face width in m):
    single pitch f_pt (Sec. 6.1), total cumulative pitch F_p (6.3), profile form f_falpha and slope f_Halpha (Annex B,
    +- for the slopes), helix slope f_Hbeta (Annex B).  Grade-5 formulas in um with the geometric means m, d, b of
    their ranges, times 2^((grade - 5)/2), rounded as Sec. 5.2.3."""
    m = _range_mean(normal_module * 1e3, _MODULE_RANGES_MM, "normal module")
    d = _range_mean(reference_diameter * 1e3, _DIAMETER_RANGES_MM, "reference diameter")
    b = _range_mean(face_width * 1e3, _WIDTH_RANGES_MM, "face width")
    step = 2.0 ** ((grade - 5) / 2.0)
    um = {"f_pt": 0.3 * (m + 0.4 * math.sqrt(d)) + 4.0,
          "F_p": 0.3 * m + 1.25 * math.sqrt(d) + 7.0,
          "f_falpha": 2.5 * math.sqrt(m) + 0.17 * math.sqrt(d) + 0.5,
          "f_Halpha": 2.0 * math.sqrt(m) + 0.14 * math.sqrt(d) + 0.5,
          "f_Hbeta": 0.07 * math.sqrt(d) + 0.45 * math.sqrt(b) + 3.0}
    return {k: _iso_round(v * step) * 1e-6 for k, v in um.items()}


@dataclass
class ContactWeights:
    """First-order sensitivities of the mesh approach to flank gaps at n_positions mesh positions over one base pitch
    (u = p / n_positions * p_bt, the convention of MeshModel.contact_points).  Per position p: the points in contact
    with roll position s [m from T1], axial position w_local [m] in their helix, tooth-pair index `pair` and
    weight k_i / sum k [-] (sums to 1); stiffness [N/m] = sum k_i."""

    s: list
    w_local: list
    pair: list
    weight: list
    stiffness: np.ndarray

    @property
    def n_positions(self) -> int:
        return len(self.s)


def contact_weights(model: MeshModel, total_force: float, n_positions: int = 32, rel_step: float = 1e-4) -> \
        ContactWeights:
    """The points in contact and their stiffness weights k_i / sum k (module docstring) at `total_force` [N]."""
    pbt = model.pair.transverse_base_pitch
    out = {k: [] for k in ("s", "w_local", "pair", "weight")}
    stiffness = []
    for p in range(n_positions):
        pts, F, _ = model.load_distribution(p / n_positions * pbt, total_force)
        idx = np.flatnonzero(F > 0)
        sub = {k: v[idx] for k, v in pts.items()}
        C = model.compliance(sub)
        Fa = F[idx]
        h_tangent = (model.hertz(sub, Fa * (1 + rel_step)) - model.hertz(sub, Fa * (1 - rel_step))) / (
            2 * rel_step * Fa)
        k = np.linalg.solve(C + np.diag(h_tangent), np.ones(idx.size))
        stiffness.append(k.sum())
        out["s"].append(sub["s"])
        out["w_local"].append(sub["w_local"])
        out["pair"].append(sub["pair"].astype(int))
        out["weight"].append(k / k.sum())
    return ContactWeights(**out, stiffness=np.array(stiffness))


@dataclass
class ToothDeviations:
    """Deviations of every tooth of one gear [m, along the mesh normal, a gap: material missing], (z,) arrays:
    position (the tooth's displacement, from the pitch deviations), profile_slope (the gap's rise over the profile
    evaluation range), helix_slope (over the face width), twist (profile slope at the far face minus at the near
    face) and form (z, 3): coefficients of the Legendre polynomials P2-P4 over the profile evaluation range."""

    position: np.ndarray
    profile_slope: np.ndarray
    helix_slope: np.ndarray
    twist: np.ndarray
    form: np.ndarray

    @classmethod
    def zeros(cls, teeth: int) -> "ToothDeviations":
        z = np.zeros(teeth)
        return cls(z.copy(), z.copy(), z.copy(), z.copy(), np.zeros((teeth, 3)))

    def gap(self, tooth: np.ndarray, xi: np.ndarray, eta: np.ndarray) -> np.ndarray:
        """Gap [m] at normalised profile position xi and face position eta (both in [-1/2, 1/2]) of `tooth`."""
        x = 2 * xi
        legendre = np.stack([(3 * x**2 - 1) / 2, (5 * x**3 - 3 * x) / 2, (35 * x**4 - 30 * x**2 + 3) / 8], axis=-1)
        return (self.position[tooth] + self.profile_slope[tooth] * xi + self.helix_slope[tooth] * eta
                + self.twist[tooth] * xi * eta + np.sum(self.form[tooth] * legendre, axis=-1))


def hunting_mesh_periods(pair: GearPair) -> int:
    """Mesh periods until every pinion tooth has met every wheel tooth it can meet: lcm(z1, z2)."""
    return math.lcm(*pair.teeth)


def first_order_te(pair: GearPair, weights: ContactWeights, pinion: ToothDeviations, wheel: ToothDeviations,
                   periods: int | None = None, with_spread: bool = False):
    """First-order loaded TE [m] (the change of the mesh approach) of the deviations over `periods` mesh periods
    (default: the hunting period), weights.n_positions samples per period.  Pair k at mesh period m is pinion tooth
    (m + k) mod z1 and wheel tooth (m + k) mod z2; the profile coordinate runs over the path of contact A..E (the
    wheel's the other way round), the face coordinate over the contact width.  with_spread: also return the largest
    range (max - min) [m] of the deviations over the points in contact at one instant (the first-order validity:
    it must stay small against the mesh deflection)."""
    te_pinion, te_wheel, spread = _te_terms(pair, weights, pinion, wheel, periods)
    te = te_pinion + te_wheel
    return (te, spread) if with_spread else te


def _te_terms(pair: GearPair, weights: ContactWeights, pinion: ToothDeviations, wheel: ToothDeviations,
              periods: int | None = None) -> tuple[np.ndarray, np.ndarray, float]:
    """`first_order_te`'s two terms apart, the pinion's deviations' and the wheel's [m] (the TE is their sum), and
    the largest spread of the deviations in contact [m]."""
    z1, z2 = (int(z) for z in pair.teeth)
    periods = hunting_mesh_periods(pair) if periods is None else periods
    A, E = pair.path_of_contact
    b = pair.contact_width
    n_pos = weights.n_positions
    te = np.zeros((2, periods, n_pos))
    spread = 0.0
    m = np.arange(periods)[:, None]
    for p in range(n_pos):
        xi = (weights.s[p] - 0.5 * (A + E)) / (E - A)
        eta = weights.w_local[p] / b - 0.5
        k = weights.pair[p][None, :]
        e_pinion = pinion.gap((m + k) % z1, xi[None, :], eta[None, :])
        e_wheel = wheel.gap((m + k) % z2, -xi[None, :], eta[None, :])
        te[0, :, p] = e_pinion @ weights.weight[p]
        te[1, :, p] = e_wheel @ weights.weight[p]
        spread = max(spread, float(np.max(np.ptp(e_pinion + e_wheel, axis=1))))
    return te[0].ravel(), te[1].ravel(), spread


def exact_deviation_te(model: MeshModel, total_force: float, pinion: ToothDeviations, wheel: ToothDeviations,
                       n_positions: int, periods: int | None = None) -> np.ndarray:
    """The same TE change as `first_order_te` from the full (nonlinear) load distribution: at every mesh position of
    `periods` mesh periods (default: the hunting period) the deviations are added to the flank gaps and the approach
    solved again (contact loss, Hertz and all), minus the aligned approach at that position [m].  The first-order
    check: about 10 ms per position."""
    pair = model.pair
    z1, z2 = (int(z) for z in pair.teeth)
    periods = hunting_mesh_periods(pair) if periods is None else periods
    A, E = pair.path_of_contact
    b = pair.contact_width
    pbt = pair.transverse_base_pitch
    out = np.zeros((periods, n_positions))
    for p in range(n_positions):
        u = p / n_positions * pbt
        cache: dict = {}
        _, _, delta0 = model.load_distribution(u, total_force, _cache=cache)
        pts, e_aligned = cache["pts"], cache["e"].copy()
        xi = (pts["s"] - 0.5 * (A + E)) / (E - A)
        eta = pts["w_local"] / b - 0.5
        k = pts["pair"].astype(int)
        for m in range(periods):
            cache["e"] = e_aligned + pinion.gap((m + k) % z1, xi, eta) + wheel.gap((m + k) % z2, -xi, eta)
            out[m, p] = model.load_distribution(u, total_force, _cache=cache)[2] - delta0
    return out.ravel()


def draw_deviations(rng: np.random.Generator, teeth: int, tolerances: dict, kinds, pitch_factor: float,
                    flank_factor: float, max_tries: int = 200000,
                    pitch_model: str = DEFAULT_PITCH_MODEL) -> ToothDeviations:
    """Random deviations of every tooth of one gear within the tolerances (iso1328_tolerances, [m]) for the
    deviation kinds asked (DEVIATION_KINDS), converted to the mesh normal: pitch_factor (cos alpha_t cos beta_b)
    for the pitch, measured along the reference circle in the transverse plane; flank_factor (cos beta_b) for the
    profile and helix deviations, measured in the transverse plane along the base tangent (the transverse line of
    action):

    - pitch, pitch_model "independent" (PITCH_MODELS): single pitch deviations uniform in +-f_pt, closed around
      the gear (sum zero), redrawn until the total cumulative pitch deviation (range of the tooth positions) is
      within F_p; "runout": the positions A cos(2 pi t / z + phi), phi uniform in [0, 2 pi), A uniform in
      [0, runout_amplitude] (F_p / 2); "none": none (PITCH_MODELS);
    - profile_slope: uniform in +-f_Halpha per tooth; helix_slope: uniform in +-f_Hbeta per tooth;
    - profile_form: P2-P4 with normal random weights, scaled to a range over the profile of U(0, 1) f_falpha;
    - twist: uniform in +-f_Halpha per tooth (the profile slope at either face +-half of it from the middle's)."""
    dev = ToothDeviations.zeros(teeth)
    kinds = set(kinds)
    unknown = kinds - set(DEVIATION_KINDS)
    if unknown:
        raise InputError(f"as_made: unknown deviation kinds {sorted(unknown)}; choose from {DEVIATION_KINDS}")
    check_pitch_model(pitch_model)
    if "pitch" in kinds and pitch_model == "runout":
        amplitude = rng.uniform(0, 1) * runout_amplitude(teeth, tolerances)
        phase = rng.uniform(0, 2 * math.pi)
        dev.position = amplitude * np.cos(2 * math.pi * np.arange(teeth) / teeth + phase) * pitch_factor
    elif "pitch" in kinds and pitch_model == "independent":
        for _ in range(max_tries):
            steps = rng.uniform(-1, 1, teeth) * tolerances["f_pt"]
            steps -= steps.mean()
            if np.abs(steps).max() > tolerances["f_pt"]:
                continue
            pos = np.cumsum(steps)
            if np.ptp(pos) <= tolerances["F_p"]:
                dev.position = (pos - pos.mean()) * pitch_factor
                break
        else:
            raise InputError("as_made: no pitch draw within f_pt and F_p")
    if "profile_slope" in kinds:
        dev.profile_slope = rng.uniform(-1, 1, teeth) * tolerances["f_Halpha"] * flank_factor
    if "helix_slope" in kinds:
        dev.helix_slope = rng.uniform(-1, 1, teeth) * tolerances["f_Hbeta"] * flank_factor
    if "twist" in kinds:
        dev.twist = rng.uniform(-1, 1, teeth) * tolerances["f_Halpha"] * flank_factor
    if "profile_form" in kinds:
        xi = np.linspace(-0.5, 0.5, 201)
        probe = ToothDeviations.zeros(1)
        for t in range(teeth):
            c = rng.normal(size=3)
            probe.form[0] = c
            shape = probe.gap(np.zeros(xi.size, int), xi, np.zeros_like(xi))
            dev.form[t] = c / np.ptp(shape) * rng.uniform(0, 1) * tolerances["f_falpha"] * flank_factor
    return dev


def order_lines(signal: np.ndarray, revolutions_per_record: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """One-sided complex amplitudes of a periodic record (one full period of N samples): orders [cycles per record /
    revolutions] and c_q with x[n] = Re sum_q c_q exp(2 pi i q n / N) (order 0: the mean; the Nyquist line of an
    even N not doubled), same unit as the signal."""
    x = np.asarray(signal, float)
    c = 2 * np.fft.rfft(x) / x.size
    c[0] /= 2
    if x.size % 2 == 0:
        c[-1] /= 2                  # the Nyquist line is a cosine sampled at its extremes
    return np.arange(c.size) / revolutions_per_record, c


def order_amplitudes(signal: np.ndarray, revolutions_per_record: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """One-sided amplitudes |c_q| of a periodic record (`order_lines`): orders and amplitudes (order 0: |mean|).
    Parseval: mean(x^2) = a_0^2 + sum_{0 < q < N/2} a_q^2 / 2 (+ a_{N/2}^2 for an even length N)."""
    orders, c = order_lines(signal, revolutions_per_record)
    return orders, np.abs(c)


# ------------------------------------------------------------------------------------------------ pinion re-indexed
def turned(deviations: ToothDeviations, shift: int) -> ToothDeviations:
    """The same gear re-assembled turned by `shift` teeth against its mate: the tooth that meets the mate's
    tooth m + k at mesh period m (first_order_te's indexing, tooth m + k before) is now tooth m + k + shift, so
    the deviations seen at mesh index t are those of physical tooth (t + shift) mod z.  Every deviation stays on
    its tooth (a runout turns with the gear: it belongs to the gear on its shaft)."""
    z = deviations.position.size
    idx = (np.arange(z) + int(shift)) % z
    return ToothDeviations(deviations.position[idx], deviations.profile_slope[idx], deviations.helix_slope[idx],
                           deviations.twist[idx], deviations.form[idx])


def reindexed_order_lines(pair: GearPair, weights: ContactWeights, pinion: ToothDeviations, wheel: ToothDeviations,
                          shift: int, aligned_te: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Wheel orders and complex one-sided amplitudes c_q [m] (`order_lines`) of the loaded TE over one hunting period
    with the pinion turned by `shift` teeth against the wheel (`turned`; the thesis' Sec. 5.6 test: 8 and 16 of
    24): the first-order TE of the deviations (`first_order_te`) plus the aligned pair's periodic TE (aligned_te: one
    mesh period of weights.n_positions samples [m], or None).  The TE is linear in the deviations, so turning the
    pinion multiplies its share at wheel order q = (z2/z1) j by exp(2 pi i j shift / z1) and leaves the wheel's and
    the aligned share: a line's power changes only at the orders both gears reach, and never at the tooth
    harmonics (j = 0 mod z1)."""
    periods = hunting_mesh_periods(pair)
    te = first_order_te(pair, weights, turned(pinion, shift), wheel, periods)
    if aligned_te is not None:
        te = te + _aligned_record(aligned_te, weights.n_positions, periods)
    return order_lines(te, periods // int(pair.teeth[1]))


def turned_pinion_lines(pair: GearPair, weights: ContactWeights, pinion: ToothDeviations, wheel: ToothDeviations,
                        shifts, aligned_te: np.ndarray | None = None) -> tuple[np.ndarray, list[np.ndarray]]:
    """`reindexed_order_lines` for several shifts from one evaluation of the deviations: wheel orders and, per shift,
    the complex one-sided amplitudes c_q [m].  Turning the pinion by s teeth shows at mesh period m the deviations
    it showed at period m + s, so its share of the hunting record (`_te_terms`) is the unturned one advanced by s
    mesh periods (a circular shift: the hunting period is a multiple of z1); the wheel's and the aligned share stay.
    Equal to `reindexed_order_lines` shift by shift to rounding (tests/source/test_as_made.py), a third of its cost
    for three shifts."""
    periods = hunting_mesh_periods(pair)
    te_pinion, te_wheel, _ = _te_terms(pair, weights, pinion, wheel, periods)
    if aligned_te is not None:
        te_wheel = te_wheel + _aligned_record(aligned_te, weights.n_positions, periods)
    per_wheel_revolution = periods // int(pair.teeth[1])
    lines = [order_lines(np.roll(te_pinion, -int(s) * weights.n_positions) + te_wheel, per_wheel_revolution)
             for s in shifts]
    if not lines:
        raise ValueError("turned_pinion_lines: no shifts")
    return lines[0][0], [c for _, c in lines]


def _aligned_record(aligned_te, positions: int, periods: int) -> np.ndarray:
    """The aligned pair's TE of one mesh period (`positions` samples [m]) repeated over `periods` mesh periods."""
    d = np.asarray(aligned_te, float)
    if d.size != positions:
        raise InputError(f"as_made: the aligned TE needs {positions} samples per mesh period, got {d.size}")
    return np.tile(d, periods)


def band_rms_amplitude(frequencies: np.ndarray, amplitudes: np.ndarray, lower: float, upper: float) -> float:
    """Amplitude [same unit] of the single line with the energy of all lines with lower <= f < upper."""
    sel = (frequencies >= lower) & (frequencies < upper)
    return float(np.sqrt(np.sum(amplitudes[sel] ** 2)))


# ------------------------------------------------------------------------------------------------ expected spectrum
# the per-tooth flank parameters drawn independently for every tooth (draw_deviations), in the order of the
# covariance matrix of DeviationStatistics: profile slope, helix slope, twist, the form's Legendre P2, P3, P4
FLANK_PARAMETERS = ("profile_slope", "helix_slope", "twist", "P2", "P3", "P4")


def _flank_basis(xi: np.ndarray, eta: np.ndarray) -> np.ndarray:
    """(..., 6): the gap per unit of each FLANK_PARAMETERS entry at profile position xi and face position eta."""
    x = 2 * xi
    return np.stack([xi, eta, xi * eta, (3 * x**2 - 1) / 2, (5 * x**3 - 3 * x) / 2,
                     (35 * x**4 - 30 * x**2 + 3) / 8], axis=-1)


def _form_shape_covariance(n_theta: int = 96, n_phi: int = 192) -> np.ndarray:
    """E[c c^T / ptp(shape c)^2] (3x3) for c ~ N(0, I_3): the ratio does not depend on |c|, so it is the mean over
    the unit sphere of u u^T / ptp(shape u)^2 (Gauss-Legendre in cos(theta) x uniform in phi; ptp on the 201-point
    profile grid of draw_deviations)."""
    mu, wmu = np.polynomial.legendre.leggauss(n_theta)
    phi = (np.arange(n_phi) + 0.5) * 2 * math.pi / n_phi
    st = np.sqrt(1 - mu**2)
    u = np.stack([np.outer(st, np.cos(phi)), np.outer(st, np.sin(phi)), np.outer(mu, np.ones(n_phi))], -1).reshape(
        -1, 3)
    w = np.repeat(wmu, n_phi) / (2 * n_phi)               # sums to 1
    xi = np.linspace(-0.5, 0.5, 201)
    legendre = _flank_basis(xi, np.zeros_like(xi))[:, 3:]  # (201, 3)
    ptp = np.ptp(u @ legendre.T, axis=1)
    return np.einsum("n,ni,nj->ij", w / ptp**2, u, u)


@dataclass
class DeviationStatistics:
    """Second moments of one gear's random deviations as `draw_deviations` draws them (all zero-mean: every draw
    and its negative are equally likely).  pitch_spectrum (z,) [m^2]: E|P_j|^2 of the DFT P_j = sum_t x_t
    exp(-2 pi i j t / z) of the tooth positions x_t (the covariance of the positions is circulant: a cyclic shift of
    the steps shifts the positions and keeps both acceptance tests, so the P_j are uncorrelated); flank_covariance
    (6, 6) [m^2]: covariance of one tooth's FLANK_PARAMETERS, independent from tooth to tooth and of the pitch."""

    teeth: int
    pitch_spectrum: np.ndarray
    flank_covariance: np.ndarray


def deviation_statistics(teeth: int, tolerances: dict, kinds, pitch_factor: float, flank_factor: float, *,
                         pitch_samples: int = 20000, seed: int = 28, batch: int = 50000,
                         pitch_model: str = DEFAULT_PITCH_MODEL) -> DeviationStatistics:
    """The second moments (DeviationStatistics) of `draw_deviations(rng, teeth, tolerances, kinds, pitch_factor,
    flank_factor)`, without drawing flanks:

    - profile slope, helix slope, twist: uniform in +-a, variance a^2 / 3 (a = f_Halpha, f_Hbeta, f_Halpha times
      flank_factor);
    - profile form: c / ptp(shape c) U f_falpha flank_factor with c ~ N(0, I_3), U ~ U(0, 1): covariance
      E[U^2] f^2 E[c c^T / ptp^2] = f^2 / 3 x the sphere mean of `_form_shape_covariance` (a quadrature, no draws);
    - pitch: the steps are uniform in +-f_pt, mean-removed, and accepted only when every step stays within f_pt and
      the positions' range within F_p.  Without the acceptance the positions are a closed random walk with
      E|P_j|^2 = z (f_pt^2 / 3) / (4 sin^2(pi j / z)) (j != 0; P_0 = 0); the acceptance on F_p (about 29 % of the
      tries for set A's pinion, 5 % for its wheel) cuts the low orders and has no closed form, so the spectrum is the
      mean of |P_j|^2 over `pitch_samples` accepted position draws (seeded; the positions alone, vectorised, about
      1 s; relative sampling error about 1/sqrt(pitch_samples) per order, 0.7 % at 20000);
    - pitch, pitch_model "runout": x_t = A cos(2 pi t / z + phi) has P_1 = conj(P_{z-1}) = (z / 2) A exp(i phi) and
      no other order, so E|P_1|^2 = E|P_{z-1}|^2 = z^2 E[A^2] / 4 = z^2 A_max^2 / 12 (A uniform in [0, A_max],
      A_max = runout_amplitude), closed form, no draws; the covariance R(d) = E[A^2] / 2 cos(2 pi d / z) is
      circulant as the one above, so the same spectrum machinery takes it; "none": zero."""
    kinds = set(kinds)
    unknown = kinds - set(DEVIATION_KINDS)
    if unknown:
        raise InputError(f"as_made: unknown deviation kinds {sorted(unknown)}; choose from {DEVIATION_KINDS}")
    check_pitch_model(pitch_model)
    z = int(teeth)
    spectrum = np.zeros(z)
    if "pitch" in kinds and pitch_model == "runout":
        if z > 1:                           # E[A^2] = A_max^2 / 3; at z = 2 orders 1 and z - 1 coincide and add
            mean_square = runout_amplitude(z, tolerances) ** 2 / 3 * pitch_factor**2
            spectrum[1] += z**2 * mean_square / 4
            spectrum[z - 1] += z**2 * mean_square / 4
    elif "pitch" in kinds and pitch_model == "independent" and tolerances["f_pt"] > 0:
        rng = np.random.default_rng(seed)
        f_pt, F_p = tolerances["f_pt"], tolerances["F_p"]
        accepted, total = 0, np.zeros(z)
        for _ in range(10000):
            steps = rng.uniform(-1, 1, (batch, z)) * f_pt
            steps -= steps.mean(axis=1, keepdims=True)
            pos = np.cumsum(steps, axis=1)
            ok = (np.abs(steps).max(axis=1) <= f_pt) & (np.ptp(pos, axis=1) <= F_p)
            pos = pos[ok][: pitch_samples - accepted]
            pos -= pos.mean(axis=1, keepdims=True)
            total += np.sum(np.abs(np.fft.fft(pos, axis=1)) ** 2, axis=0)
            accepted += pos.shape[0]
            if accepted >= pitch_samples:
                break
        else:
            raise InputError("as_made: no pitch draw within f_pt and F_p")
        spectrum = total / accepted * pitch_factor**2
    cov = np.zeros((6, 6))
    var = {"profile_slope": tolerances["f_Halpha"], "helix_slope": tolerances["f_Hbeta"],
           "twist": tolerances["f_Halpha"]}
    for i, name in enumerate(FLANK_PARAMETERS[:3]):
        if name in kinds:
            cov[i, i] = (var[name] * flank_factor) ** 2 / 3
    if "profile_form" in kinds:
        cov[3:, 3:] = (tolerances["f_falpha"] * flank_factor) ** 2 / 3 * _form_shape_covariance()
    return DeviationStatistics(z, spectrum, cov)


@dataclass
class ExpectedOrderSpectrum:
    """Expected one-sided power per order of the loaded TE over the hunting period (`expected_order_spectrum`):
    orders [wheel orders], aligned [m^2]: a_q^2 of the aligned pair's periodic TE (its tooth harmonics, the mean's
    line), deviations [m^2]: E a_q^2 of the deviations' first-order TE; total = aligned + deviations (order 0 the
    mean: a_0 = |mean|, as order_amplitudes)."""

    orders: np.ndarray
    aligned: np.ndarray
    deviations: np.ndarray

    @property
    def total(self) -> np.ndarray:
        return self.aligned + self.deviations

    def band(self, frequencies: np.ndarray, lower: float, upper: float, which: str = "total") -> float:
        """sqrt(E sum a_q^2) [m] over the lines with lower <= f < upper (frequencies [Hz] per order): the amplitude
        of the single line with the band's expected energy (band_rms_amplitude of the expectation)."""
        sel = (np.asarray(frequencies) >= lower) & (np.asarray(frequencies) < upper)
        return float(np.sqrt(np.sum(getattr(self, which)[sel])))


def _order_transfer(pair: GearPair, weights: ContactWeights, gear: int, q: np.ndarray, periods: int) -> np.ndarray:
    """T_b(q) (len(q), 7) of gear `gear` (0 pinion, 1 wheel) for the per-tooth parameters b = (position,
    FLANK_PARAMETERS): sum_p exp(-2 pi i q p / N) sum_k c_b[p, k] exp(2 pi i j k / z), j = q / r mod z (see
    `expected_order_spectrum`)."""
    z = int(pair.teeth[gear])
    A, E = pair.path_of_contact
    b = pair.contact_width
    P = weights.n_positions
    N = periods * P
    r = periods // z
    j = (q // r) % z
    T = np.zeros((q.size, 7), complex)
    for p in range(P):
        xi = (weights.s[p] - 0.5 * (A + E)) / (E - A)
        xi = -xi if gear == 1 else xi            # the wheel's profile runs the other way (first_order_te)
        eta = weights.w_local[p] / b - 0.5
        basis = np.concatenate([np.ones((xi.size, 1)), _flank_basis(xi, eta)], axis=1)     # (points, 7)
        c = weights.weight[p][:, None] * basis
        phase = np.exp(2j * math.pi * np.outer(j, weights.pair[p]) / z)                    # (q, points)
        T += np.exp(-2j * math.pi * q * p / N)[:, None] * (phase @ c)
    return T


def expected_order_spectrum(pair: GearPair, weights: ContactWeights, pinion: DeviationStatistics,
                            wheel: DeviationStatistics, aligned_te: np.ndarray | None = None,
                            periods: int | None = None) -> ExpectedOrderSpectrum:
    """E a_q^2 at every order of the record of `first_order_te` (default: the hunting period, M = lcm(z1, z2) mesh
    periods of P = weights.n_positions samples, N = M P), analytically: no draws of the TE.

    Derivation.  The first-order TE is linear in the per-tooth parameters theta_{g,b,t} (gear g, parameter b =
    position or FLANK_PARAMETERS, tooth t): x[m, p] = sum_g sum_b sum_k c_{g,b}[p, k] theta_{g,b,(m + k) mod z_g},
    c_{g,b}[p, k] = sum over the contact points i of pair k at position p of w_{p,i} phi_b(+-xi_i, eta_i) (the
    weights of `contact_weights`, phi_b the gap per unit parameter, xi negated on the wheel).  With
    theta_t = (1/z) sum_j Theta_j exp(2 pi i j t / z) and r_g = M / z_g, the DFT X_q = (1/N) sum x[m, p]
    exp(-2 pi i q (m P + p) / N) sums over m to M where q = r_g j (mod M), else 0:

        X_q = 1/(P z_g) sum_b Theta_{g,b,j} T_{g,b}(q),   j = q / r_g mod z_g (q a multiple of r_g; else no share)
        T_{g,b}(q) = sum_p exp(-2 pi i q p / N) sum_k c_{g,b}[p, k] exp(2 pi i j k / z_g)

    (a gear's deviations reach only its own rotation orders).  The deviations are zero-mean and independent between
    the gears, between the pitch and the flanks, and the flanks from tooth to tooth (E Theta_b Theta_b'^* =
    z Sigma_bb', Sigma = DeviationStatistics.flank_covariance); the pitch positions have E|Theta_pos,j|^2 =
    pitch_spectrum[j] and no correlation between orders.  Hence, summed over the gears that reach q,

        E|X_q|^2 = 1/(P z)^2 [ pitch_spectrum[j] |T_pos(q)|^2 + z T_fl(q)^H Sigma T_fl(q) ],

    and with the aligned pair's periodic TE D (aligned_te: one mesh period of P samples, lines at q = n M) the
    expected total E|D_q + X_q|^2 = |D_q|^2 + E|X_q|^2 (the cross term has zero mean): the mean's line plus the
    variance.  One-sided as order_amplitudes: E a_q^2 = 4 E|X_q|^2 for 0 < q < N/2, E|X_q|^2 at 0 and N/2.  Orders in
    wheel orders q / (M / z2)."""
    z1, z2 = (int(z) for z in pair.teeth)
    periods = hunting_mesh_periods(pair) if periods is None else int(periods)
    P = weights.n_positions
    N = periods * P
    q_all = np.arange(N // 2 + 1)
    one_sided = np.where((q_all == 0) | (2 * q_all == N), 1.0, 4.0)
    dev = np.zeros(q_all.size)
    for g, stats in enumerate((pinion, wheel)):
        z = (z1, z2)[g]
        if stats.teeth != z:
            raise InputError(f"as_made: statistics of {stats.teeth} teeth for a gear of {z}")
        if periods % z:
            raise InputError(f"as_made: {periods} mesh periods are not whole revolutions of a {z}-tooth gear")
        r = periods // z
        q = q_all[q_all % r == 0]
        j = (q // r) % z
        T = _order_transfer(pair, weights, g, q, periods)
        power = stats.pitch_spectrum[j] * np.abs(T[:, 0]) ** 2
        power += z * np.real(np.einsum("qa,ab,qb->q", T[:, 1:].conj(), stats.flank_covariance, T[:, 1:]))
        dev[q] += power / (P * z) ** 2
    aligned = np.zeros(q_all.size)
    if aligned_te is not None:
        aligned = order_amplitudes(_aligned_record(aligned_te, P, periods))[1] ** 2
    return ExpectedOrderSpectrum(q_all / (periods // z2), aligned, dev * one_sided)
