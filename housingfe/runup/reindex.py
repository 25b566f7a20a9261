"""The pinion turned against the wheel: the thesis' re-indexing test (Sec. 5.6, Fig. 5.12; issue 28).

Gear set A (z = 24 / 72, ratio exactly 3) at 2000 N m: the pinion was removed and re-assembled turned by 8 and 16
teeth against the wheel; the sound power level changed by 0.3 dB mean, 0.8 dB standard deviation over the run-up's
speeds.  Here, per pitch model (`housingfe.source.as_made.PITCH_MODELS`) and seeded draw of ISO 1328-1 grade-5
deviations of all kinds on both gears, the loaded TE's wheel-order lines over one hunting period with the pinion
turned by 0 and by each shift (`as_made.turned_pinion_lines`, the same draw, the aligned pair's d_qs included) go
through the rigid-bore lumped source's receptance R_TE(f) (`runup.as_made.te_receptance_rigid_bores`) at every
speed 50..1500 rpm (50 rpm steps, the run-up's); per draw L(s) - L(0) per speed, its mean and standard deviation over
the speeds (the shifts pooled: the thesis quotes one mean and one s.d.).  The levels (`KINDS`): the wheel's L_omega
in the tooth band, over the 1/3-octave bands of harmonics 1..8 (each order once), and the same A-weighted line by
line (the L_omega analogue of an L_WA).  What differs from the measurement (L_omega, not L_W; first order on the
mean-stiffness system; the deviations travel with the pinion's teeth): benchmarks/experiments/reindex/README.md,
docs/source.md "The pinion turned against the wheel".
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from housingfe import levels
from housingfe.errors import InputError
from housingfe.runup.as_made import band_of, te_receptance_rigid_bores

SCENE = "gearset-A"
TORQUE_NM = 2000.0
SHIFTS = (8, 16)                     # pinion teeth turned against the wheel (1/3 and 2/3 of a pinion revolution)
SPEEDS_RPM = np.arange(50.0, 1501.0, 50.0)
HARMONICS = range(1, 9)
KINDS = ("tooth", "bands 1-8", "bands 1-8, A")
# the experiment's defaults (benchmarks/experiments/reindex): draws per pitch model, seed, mesh positions per pitch
DRAWS = 50
SEED = 56
POSITIONS = 32
GRADE = 5                            # ISO 1328-1:1995 grade standing in for the thesis' DIN 5


@dataclass
class SetA:
    """Gear set A at a pinion torque (scene `gearset-A`, rigid-bore lumped source, face-width engagement): the pair,
    its mesh model, operating point (op.mats: the mean system), normal force [N], the aligned pair's quasi-static TE
    d_qs at `positions` samples per mesh period [m], the contact weights, the ISO 1328-1 grade-GRADE tolerances per gear
    [m] and the factors of pitch and flank deviations to the mesh normal [-]."""

    pair: object
    model: object
    op: object
    normal_force: float
    aligned_te: np.ndarray
    weights: object
    tolerances: list
    pitch_factor: float
    flank_factor: float


def set_a(positions: int = POSITIONS, torque_nm: float = TORQUE_NM, scene: str = SCENE) -> SetA:
    """`SetA` of the built-in scene at `torque_nm` [N m] with `positions` mesh positions per base pitch (a divisor of
    the source's stiffness positions; InputError otherwise)."""
    from housingfe.scenefile import read_scene_dict
    from housingfe.source import as_made as am
    from housingfe.source.roosmalen import dynamics as dyn
    from housingfe.source.roosmalen import run as rs

    data, path = read_scene_dict(scene)
    table = rs.parse(data, str(path))
    pair, corr, _, interior, model = rs.build(table, str(path))
    op = rs.OperatingPoint(pair, corr, interior, model, torque_nm, positions, engagement="face-width")
    force = op.normal_force
    d_qs = dyn.quasi_static_compression(op.S, op.shock, force)
    step = d_qs.size // positions
    if positions < 1 or step * positions != d_qs.size:
        raise InputError(f"positions: {positions} must divide the source's {d_qs.size} stiffness positions")
    beta_b = pair.base_helix_angle
    tolerances = [am.iso1328_tolerances(pair.module, pair.pitch_diameter[g], pair.face_width[g], GRADE)
                  for g in range(2)]
    return SetA(pair, model, op, force, d_qs[::step], am.contact_weights(model, force, positions), tolerances,
                math.cos(pair.transverse_pressure_angle) * math.cos(beta_b), math.cos(beta_b))


def weights_per_speed(orders: np.ndarray, f_tooth_per_rpm: float, z2: int, receptance,
                      speeds_rpm: np.ndarray = SPEEDS_RPM, harmonics=HARMONICS) -> np.ndarray:
    """(KINDS, speed, order) weights: the mean square of L_omega per unit a_q^2 [1/s^2 per m^2] of the wheel-order
    lines each level sums at each pinion speed [rpm] (receptance: f [Hz] -> |Omega_wheel / e| [(rad/s)/m];
    A-weighting line by line on the last), so that L = 10 lg(W @ |c|^2 / omega_0^2)."""
    W = np.zeros((len(KINDS), speeds_rpm.size, orders.size))
    for i, v in enumerate(speeds_rpm):
        f_t = f_tooth_per_rpm * v
        f = orders * f_t / z2
        lo, hi = band_of(f_t)
        tooth = (f >= lo) & (f < hi)
        bands = np.zeros(f.size, bool)
        for n in harmonics:
            lo, hi = band_of(n * f_t)
            bands |= (f >= lo) & (f < hi)
        bands &= orders > 0
        r2 = np.zeros(f.size)
        r2[bands | tooth] = receptance(f[bands | tooth]) ** 2 / 2
        W[0, i] = r2 * tooth
        W[1, i] = r2 * bands
        W[2, i] = r2 * bands * 10 ** (levels.a_weighting_db(np.maximum(f, 1e-9)) / 10)
    return W


@dataclass
class TurnedPinion:
    """Per pitch model: per draw the mean and the s.d. (ddof 1) over the speeds of L(turned) - L(0) [dB], the shifts
    pooled, for the level `kind` (KINDS) on the rigid-bore route; the draws' seed, the shifts, the speeds [rpm]."""

    pitch_model: str
    kind: str
    mean_db: np.ndarray
    sd_db: np.ndarray
    seed: int
    shifts: tuple
    speeds_rpm: np.ndarray

    @property
    def draws(self) -> int:
        return int(self.mean_db.size)


def turned_pinion(draws: int = DRAWS, seed: int = SEED, positions: int = POSITIONS, kind: str = "bands 1-8, A",
                  shifts=SHIFTS, pitch_models=None) -> tuple[dict[str, TurnedPinion], float]:
    """({pitch model: TurnedPinion}, seconds) of set A at TORQUE_NM on the rigid-bore route: `draws` seeded draws per
    pitch model (numpy default_rng([seed, index of the model in as_made.PITCH_MODELS]), pinion then wheel, as the
    experiment draws them: the same numbers as benchmarks/experiments/reindex's rigid rows for the same seed)."""
    from housingfe.source import as_made as am

    if kind not in KINDS:
        raise InputError(f"turned pinion: kind {kind!r} is not one of {KINDS}")
    if draws < 1 or not shifts:
        raise InputError(f"turned pinion: draws: {draws}, shifts: {tuple(shifts)} (at least one of each)")
    t0 = time.perf_counter()
    models = am.PITCH_MODELS if pitch_models is None else tuple(am.check_pitch_model(m) for m in pitch_models)
    a = set_a(positions)
    z1, z2 = (int(z) for z in a.pair.teeth)
    zero = (am.ToothDeviations.zeros(z1), am.ToothDeviations.zeros(z2))
    orders, _ = am.turned_pinion_lines(a.pair, a.weights, *zero, (0,), a.aligned_te)
    W = weights_per_speed(orders, a.pair.tooth_frequency(1.0), z2,
                          lambda f: te_receptance_rigid_bores(a.op.mats, f))[KINDS.index(kind)]
    out = {}
    for model in models:
        rng = np.random.default_rng([seed, am.PITCH_MODELS.index(model)])
        mean, sd = np.zeros(draws), np.zeros(draws)
        for d in range(draws):
            pin, whl = (am.draw_deviations(rng, z, a.tolerances[g], am.DEVIATION_KINDS, a.pitch_factor,
                                           a.flank_factor, pitch_model=model) for g, z in enumerate((z1, z2)))
            _, lines = am.turned_pinion_lines(a.pair, a.weights, pin, whl, (0,) + tuple(shifts), a.aligned_te)
            L = [10 * np.log10(W @ np.abs(c) ** 2 / levels.OMEGA0**2) for c in lines]      # per speed
            diffs = np.ravel([x - L[0] for x in L[1:]])
            mean[d], sd[d] = diffs.mean(), diffs.std(ddof=1)
        out[model] = TurnedPinion(model, kind, mean, sd, seed, tuple(shifts), SPEEDS_RPM.copy())
    return out, time.perf_counter() - t0
