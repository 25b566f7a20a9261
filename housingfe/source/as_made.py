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
    z1, z2 = (int(z) for z in pair.teeth)
    periods = hunting_mesh_periods(pair) if periods is None else periods
    A, E = pair.path_of_contact
    b = pair.contact_width
    n_pos = weights.n_positions
    te = np.zeros((periods, n_pos))
    spread = 0.0
    m = np.arange(periods)[:, None]
    for p in range(n_pos):
        xi = (weights.s[p] - 0.5 * (A + E)) / (E - A)
        eta = weights.w_local[p] / b - 0.5
        k = weights.pair[p][None, :]
        e = pinion.gap((m + k) % z1, xi[None, :], eta[None, :]) + wheel.gap((m + k) % z2, -xi[None, :], eta[None, :])
        te[:, p] = e @ weights.weight[p]
        spread = max(spread, float(np.max(np.ptp(e, axis=1))))
    return (te.ravel(), spread) if with_spread else te.ravel()


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
                    flank_factor: float, max_tries: int = 200000) -> ToothDeviations:
    """Random deviations of every tooth of one gear within the tolerances (iso1328_tolerances, [m]) for the
    deviation kinds asked (DEVIATION_KINDS), converted to the mesh normal: pitch_factor (cos alpha_t cos beta_b)
    for the pitch, measured along the reference circle in the transverse plane; flank_factor (cos beta_b) for the
    profile and helix deviations, measured in the transverse plane along the base tangent (the transverse line of
    action):

    - pitch: single pitch deviations uniform in +-f_pt, closed around the gear (sum zero), redrawn until the total
      cumulative pitch deviation (range of the tooth positions) is within F_p;
    - profile_slope: uniform in +-f_Halpha per tooth; helix_slope: uniform in +-f_Hbeta per tooth;
    - profile_form: P2-P4 with normal random weights, scaled to a range over the profile of U(0, 1) f_falpha;
    - twist: uniform in +-f_Halpha per tooth (the profile slope at either face +-half of it from the middle's)."""
    dev = ToothDeviations.zeros(teeth)
    kinds = set(kinds)
    unknown = kinds - set(DEVIATION_KINDS)
    if unknown:
        raise InputError(f"as_made: unknown deviation kinds {sorted(unknown)}; choose from {DEVIATION_KINDS}")
    if "pitch" in kinds:
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


def order_amplitudes(signal: np.ndarray, revolutions_per_record: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """One-sided amplitudes of a periodic record (one full period): orders [cycles per record / revolutions] and
    amplitudes (order 0: the mean).  Parseval: mean(x^2) = a_0^2 + sum_{0 < q < N/2} a_q^2 / 2 (+ a_{N/2}^2 for an
    even length N: the Nyquist line is a cosine sampled at its extremes)."""
    x = np.asarray(signal, float)
    c = np.fft.rfft(x) / x.size
    a = 2 * np.abs(c)
    a[0] = abs(c[0])
    if x.size % 2 == 0:
        a[-1] = abs(c[-1])          # the Nyquist line is not doubled
    return np.arange(a.size) / revolutions_per_record, a


def band_rms_amplitude(frequencies: np.ndarray, amplitudes: np.ndarray, lower: float, upper: float) -> float:
    """Amplitude [same unit] of the single line with the energy of all lines with lower <= f < upper."""
    sel = (frequencies >= lower) & (frequencies < upper)
    return float(np.sqrt(np.sum(amplitudes[sel] ** 2)))
