"""Gears as made (housingfe.source.as_made, issue 28): ISO 1328-1 grade-5 tolerances, the first-order loaded TE of
tooth deviations over the hunting period, its spectrum in shaft orders."""
import math
from dataclasses import replace

import numpy as np
import pytest

from housingfe.errors import InputError
from housingfe.source import as_made as am
from housingfe.source.gears import GearPair
from housingfe.source.stiffness import Corrections, MeshModel
from tests.source.thesis_gears import SYMMETRIC_SHAFTS

FORCE = 40e3


@pytest.fixture(scope="module")
def spur():
    # set A's module and tooth numbers as a spur pair at its standard centre distance (eps_alpha 1.71, eps_beta 0)
    pair = GearPair.from_table(dict(module_mm=4.0, teeth=[24, 72], pressure_angle_deg=20.0, helix_angle_deg=0.0,
                                    addendum_modification=[0.0, 0.0], face_width_mm=[40.0, 40.0],
                                    centre_distance_mm=192.0, kind="spur"))
    model = MeshModel(pair, shafts=SYMMETRIC_SHAFTS, corrections=Corrections(), n_slices=6)
    return pair, model, am.contact_weights(model, FORCE, n_positions=8)


def test_iso1328_grade5_tolerances_of_set_a():
    """ISO 1328-1:1995 formulas with the geometric means of the ranges (m 3.5-6 mm: 4.583; d 50-125 mm: 79.06,
    280-560 mm: 396.0; b 40-80 mm: 56.57), rounded per Sec. 5.2.3. Pinion: f_pt = 0.3 (4.583 + 0.4 * 8.891) + 4 =
    6.44 -> 6.5; F_p = 1.375 + 11.11 + 7 = 19.5 -> 19 (hand: 19.49); f_Halpha = 4.282 + 1.245 + 0.5 = 6.03 -> 6.0;
    f_falpha = 5.352 + 1.511 + 0.5 = 7.36 -> 7.5; f_Hbeta = 0.622 + 3.385 + 3 = 7.01 -> 7.0.  Wheel: 7.76 -> 8.0,
    33.25 -> 33, 7.57 -> 7.5, 9.24 -> 9.0, 7.78 -> 8.0."""
    d1, d2 = 24 * 4.0 / math.cos(math.radians(12)), 72 * 4.0 / math.cos(math.radians(12))
    pin = am.iso1328_tolerances(0.004, d1 * 1e-3, 0.066)
    whl = am.iso1328_tolerances(0.004, d2 * 1e-3, 0.062)
    um = lambda t: {k: round(v * 1e6, 6) for k, v in t.items()}       # noqa: E731
    assert um(pin) == {"f_pt": 6.5, "F_p": 19.0, "f_falpha": 7.5, "f_Halpha": 6.0, "f_Hbeta": 7.0}
    assert um(whl) == {"f_pt": 8.0, "F_p": 33.0, "f_falpha": 9.0, "f_Halpha": 7.5, "f_Hbeta": 8.0}
    # one grade coarser: sqrt(2) before rounding (f_pt 6.44 * 1.414 = 9.11 -> 9.0)
    assert am.iso1328_tolerances(0.004, d1 * 1e-3, 0.066, grade=6)["f_pt"] == pytest.approx(9.0e-6)
    with pytest.raises(InputError, match="module"):
        am.iso1328_tolerances(0.1, 0.1, 0.05)


def test_weights_sum_to_the_mesh_stiffness_and_are_the_approachs_first_order_sensitivity(spur):
    """sum k_i is dF/d delta of the load distribution, and a small gap on one tooth pair's points moves the
    approach by its weight share (finite difference of the nonlinear load distribution)."""
    pair, model, w = spur
    pbt = pair.transverse_base_pitch
    for p in (0, 5):
        u = p / 8 * pbt
        assert w.stiffness[p] == pytest.approx(model.stiffness_at(u, FORCE)["stiffness"], rel=2e-3)
        _, _, d0 = model.load_distribution(u, FORCE)
        k = int(w.pair[p][0])
        e0 = 0.2e-6

        class Perturbed(MeshModel):
            def gaps(self, pts):
                return super().gaps(pts) + np.where(pts["pair"] == k, e0, 0.0)

        perturbed = Perturbed(**{f: getattr(model, f) for f in ("pair", "shafts", "corrections", "n_slices")})
        _, _, d1 = perturbed.load_distribution(u, FORCE)
        share = w.weight[p][w.pair[p] == k].sum()
        assert 0.05 < share < 0.95
        assert (d1 - d0) / e0 == pytest.approx(share, rel=5e-3)


def test_spur_single_deviating_tooth_gives_its_deviation_times_its_load_share(spur):
    """A spur pair (eps_beta = 0), one pinion tooth displaced by e0 (the same over its flank): the first-order TE at
    every instant is e0 times that tooth's share of the mesh stiffness, which on uncorrected flanks is its share of
    the load F_tooth / F (to the Hertz tangent/secant difference, < 3 %), and zero while the tooth is out of mesh."""
    pair, model, w = spur
    z1, z2 = pair.teeth
    e0 = 1e-6
    pin, whl = am.ToothDeviations.zeros(z1), am.ToothDeviations.zeros(z2)
    pin.position[0] = e0
    te = am.first_order_te(pair, w, pin, whl).reshape(-1, w.n_positions)
    assert te.shape == (math.lcm(z1, z2), 8)
    pbt = pair.transverse_base_pitch
    compared = 0
    for m in range(te.shape[0]):
        for p in range(w.n_positions):
            ks = w.pair[p]
            on = ((m + ks) % z1) == 0
            if not on.any():
                assert te[m, p] == 0.0
                continue
            pts, F, _ = model.load_distribution(p / 8 * pbt, FORCE) if m < 3 else (None, None, None)
            stiffness_share = w.weight[p][on].sum()
            assert te[m, p] == pytest.approx(e0 * stiffness_share, rel=1e-12)
            if pts is not None:
                load_share = F[pts["pair"] == ks[on][0]].sum() / FORCE
                assert stiffness_share == pytest.approx(load_share, rel=0.03)
                compared += 1
    assert compared >= 4 and np.count_nonzero(te) > 0


def test_identical_teeth_give_only_tooth_harmonics_and_random_ones_spread_over_shaft_orders(spur):
    """The same deviations on every tooth make the TE periodic in the mesh period: lines only at multiples of the
    tooth order (z2 wheel orders).  Deviations on the pinion alone repeat every pinion revolution: lines only at
    multiples of z2/z1 wheel orders.  Random ones on both spread energy over all shaft orders, and Parseval holds."""
    pair, model, w = spur
    z1, z2 = pair.teeth
    rng = np.random.default_rng(3)
    tol = {"f_pt": 6e-6, "F_p": 1.0, "f_falpha": 7e-6, "f_Halpha": 6e-6, "f_Hbeta": 7e-6}

    same = [am.ToothDeviations.zeros(z) for z in (z1, z2)]
    for d in same:
        d.profile_slope[:] = 5e-6
        d.helix_slope[:] = -3e-6
        d.twist[:] = 4e-6
        d.form[:] = [1e-6, -0.5e-6, 0.2e-6]
    te = am.first_order_te(pair, w, *same)
    orders, a = am.order_amplitudes(te)
    assert np.max(a[1:]) > 1e-7
    off_tooth = (np.arange(a.size) % z2) != 0
    assert np.max(a[off_tooth]) < 1e-12 * np.max(a[1:])

    pin = am.draw_deviations(rng, z1, tol, am.DEVIATION_KINDS, 0.9, 1.0)
    te = am.first_order_te(pair, w, pin, am.ToothDeviations.zeros(z2))
    _, a = am.order_amplitudes(te)
    not_pinion = (np.arange(a.size) % (z2 // z1)) != 0
    assert np.max(a[not_pinion]) < 1e-12 * np.max(a)

    whl = am.draw_deviations(rng, z2, tol, am.DEVIATION_KINDS, 0.9, 1.0)
    te = am.first_order_te(pair, w, pin, whl)
    orders, a = am.order_amplitudes(te)
    side = (orders > 0) & off_tooth
    assert np.sum(a[side] ** 2) > 0.5 * np.sum(a[1:] ** 2)        # most of the energy off the tooth harmonics
    assert np.count_nonzero(a[side] > 1e-3 * a.max()) > z2 // 2
    n = te.size
    parseval = a[0] ** 2 + np.sum(a[1:n // 2] ** 2) / 2 + a[n // 2] ** 2
    assert parseval == pytest.approx(np.mean(te**2), rel=1e-12)


def test_draws_stay_within_the_tolerances():
    rng = np.random.default_rng(7)
    tol = am.iso1328_tolerances(0.004, 0.2944, 0.062)
    for _ in range(5):
        d = am.draw_deviations(rng, 72, tol, am.DEVIATION_KINDS, 1.0, 1.0)
        steps = np.diff(np.concatenate([d.position, d.position[:1]]))
        assert np.abs(steps).max() <= tol["f_pt"] * (1 + 1e-12)
        assert np.ptp(d.position) <= tol["F_p"] * (1 + 1e-12)
        assert np.abs(d.profile_slope).max() <= tol["f_Halpha"]
        assert np.abs(d.helix_slope).max() <= tol["f_Hbeta"]
        xi = np.linspace(-0.5, 0.5, 401)
        for t in range(72):
            only_form = replace(am.ToothDeviations.zeros(1), form=d.form[t:t + 1])
            assert np.ptp(only_form.gap(np.zeros(xi.size, int), xi, 0 * xi)) <= tol["f_falpha"] * (1 + 1e-9)
    with pytest.raises(InputError, match="unknown"):
        am.draw_deviations(rng, 10, tol, ["runout"], 1.0, 1.0)


def test_first_order_te_is_the_limit_of_the_full_load_distribution(spur):
    """Deviations 1 % of grade 5 (~0.07 um against a ~30 um deflection): the full load distribution with the
    deviations in the flank gaps changes the approach as the first-order sum k_i e_i / sum k_i, to 1 % of its range."""
    pair, model, w = spur
    z1, z2 = pair.teeth
    rng = np.random.default_rng(11)
    tol = {k: v * 0.01 for k, v in am.iso1328_tolerances(0.004, 0.096, 0.040).items()}
    pin, whl = (am.draw_deviations(rng, z, tol, am.DEVIATION_KINDS, 0.9, 1.0) for z in (z1, z2))
    first = am.first_order_te(pair, w, pin, whl, periods=4)
    exact = am.exact_deviation_te(model, FORCE, pin, whl, w.n_positions, periods=4)
    assert np.ptp(first) > 0.02e-6
    assert np.max(np.abs(exact - first)) < 0.01 * np.ptp(first)


def test_expected_order_spectrum_is_the_mean_of_the_draws(spur):
    """The analytic E a_q^2 (expected_order_spectrum, deviation_statistics) against the mean of 400 seeded draws'
    a_q^2 (first_order_te, draw_deviations as the experiment draws them, all kinds, ISO grade 5) at every order of
    the hunting period.  Per order the sample mean of 400 has the standard error s_q / sqrt(400) (s_q the draws' own
    standard deviation at that order, ~ the mean for a sum of several independent terms): every order lies within
    5 standard errors (at 577 orders a false alarm has probability ~ 3e-4; the pitch spectrum's own sampling error,
    ~0.7 %, is far below the 400-draw tolerance of ~25 %), and the band energy around the tooth order (the many
    orders together) within 4 %."""
    pair, model, w = spur
    z1, z2 = pair.teeth
    tol = [am.iso1328_tolerances(0.004, d, 0.040) for d in pair.pitch_diameter]
    stats = [am.deviation_statistics(z, t, am.DEVIATION_KINDS, 0.94, 1.0) for z, t in zip((z1, z2), tol)]
    expected = am.expected_order_spectrum(pair, w, *stats)
    rng = np.random.default_rng(2028)
    draws = 400
    power = np.array([am.order_amplitudes(am.first_order_te(pair, w, *(
        am.draw_deviations(rng, z, t, am.DEVIATION_KINDS, 0.94, 1.0) for z, t in zip((z1, z2), tol))))[1] ** 2
        for _ in range(draws)])
    mean, err = power.mean(axis=0), power.std(axis=0) / math.sqrt(draws)
    assert expected.deviations.shape == mean.shape
    assert np.all(np.abs(mean - expected.deviations) <= 5 * err + 1e-30)
    assert np.count_nonzero(expected.deviations > 1e-3 * expected.deviations.max()) > z2   # all shaft orders
    band = (expected.orders >= 0.89 * z2) & (expected.orders < 1.12 * z2)
    assert np.sum(mean[band]) == pytest.approx(np.sum(expected.deviations[band]), rel=0.04)


def test_expected_order_spectrum_without_deviations_is_the_aligned_pairs_tooth_lines_and_keeps_parseval(spur):
    """Zero tolerances: only the aligned pair's tooth harmonics (orders n z2), exactly its a_n^2.  Parseval on the
    expectation: sum of the expected line powers = the expected mean square of the record, computed in time from
    the positions' circulant covariance R(d) = 1/z^2 sum_j S_j exp(2 pi i j d / z) and the flank covariance."""
    pair, model, w = spur
    z1, z2 = pair.teeth
    aligned = 0.3e-6 * np.cos(2 * math.pi * np.arange(8) / 8) + 0.1e-6 * np.sin(4 * math.pi * np.arange(8) / 8) + 1e-6
    zero = {k: 0.0 for k in ("f_pt", "F_p", "f_falpha", "f_Halpha", "f_Hbeta")}
    none = [am.deviation_statistics(z, zero, am.DEVIATION_KINDS, 0.94, 1.0) for z in (z1, z2)]
    spec = am.expected_order_spectrum(pair, w, *none, aligned_te=aligned)
    assert np.max(spec.deviations) == 0.0
    _, a = am.order_amplitudes(np.tile(aligned, am.hunting_mesh_periods(pair)))
    assert np.allclose(spec.total, a**2, rtol=0, atol=1e-30)
    on = spec.orders % z2 == 0
    assert np.max(spec.total[~on]) < 1e-12 * np.max(spec.total)
    assert np.sqrt(spec.total[z2]) == pytest.approx(0.3e-6, rel=1e-12)

    tol = [am.iso1328_tolerances(0.004, d, 0.040) for d in pair.pitch_diameter]
    stats = [am.deviation_statistics(z, t, am.DEVIATION_KINDS, 0.94, 1.0) for z, t in zip((z1, z2), tol)]
    spec = am.expected_order_spectrum(pair, w, *stats)
    n = 2 * (spec.orders.size - 1)
    parseval = spec.deviations[0] + np.sum(spec.deviations[1:-1]) / 2 + spec.deviations[-1]
    A, E = pair.path_of_contact
    mean_square = 0.0
    for p in range(w.n_positions):
        xi = (w.s[p] - 0.5 * (A + E)) / (E - A)
        eta = w.pair[p] * 0.0 + w.w_local[p] / pair.contact_width - 0.5
        for g, (z, st) in enumerate(zip((z1, z2), stats)):
            d = np.arange(z)
            R = np.real(np.exp(2j * math.pi * np.outer(d, d) / z) @ st.pitch_spectrum) / z**2
            k = w.pair[p]
            c = w.weight[p]
            mean_square += c @ R[(k[:, None] - k[None, :]) % z] @ c
            basis = am._flank_basis(-xi if g else xi, eta) * c[:, None]
            same = (k[:, None] - k[None, :]) % z == 0
            mean_square += np.sum(same * (basis @ st.flank_covariance @ basis.T))
    assert parseval == pytest.approx(mean_square / w.n_positions, rel=1e-10)
    assert n == am.hunting_mesh_periods(pair) * w.n_positions


def test_pitch_spectrum_without_the_range_test_is_the_closed_random_walk():
    """F_p out of reach: only the per-step test |step| <= f_pt (after removing the mean) is left, which a step
    fails rarely for many teeth; the sampled spectrum then approaches z (f_pt^2 / 3) / (4 sin^2(pi j / z)) of the
    closed random walk (j != 0; P_0 = 0).  The F_p test of set A's wheel cuts the lowest orders."""
    z, f_pt = 200, 8e-6
    st = am.deviation_statistics(z, {"f_pt": f_pt, "F_p": 1.0, "f_falpha": 0, "f_Halpha": 0, "f_Hbeta": 0},
                                 ["pitch"], 1.0, 1.0, pitch_samples=4000)
    j = np.arange(1, z)
    closed = z * f_pt**2 / 3 / (4 * np.sin(math.pi * j / z) ** 2)
    assert st.pitch_spectrum[0] == pytest.approx(0.0, abs=1e-30)
    assert np.mean(st.pitch_spectrum[1:] / closed) == pytest.approx(1.0, abs=0.03)
    wheel = am.deviation_statistics(72, am.iso1328_tolerances(0.004, 0.2944, 0.062), ["pitch"], 1.0, 1.0)
    free = 72 * (8e-6) ** 2 / 3 / (4 * math.sin(math.pi / 72) ** 2)
    assert wheel.pitch_spectrum[1] < 0.5 * free


def test_runout_pitch_gives_lines_only_at_tooth_orders_plus_minus_one_shaft_order(spur):
    """pitch_model "runout": each gear's tooth positions are one order-1 sinusoid A cos(2 pi t / z + phi), A within
    F_p / 2.  Its first-order TE is the mesh-periodic weights modulated once per revolution of that gear, so its
    lines lie only at n z_g +- 1 orders of that gear (n >= 0): wheel orders 72 n +- 1 for the wheel's, 72 n +- 3
    (pinion orders 24 n +- 1) for the pinion's.  Each line's power is |Theta_1|^2 |T_pos(q)|^2 / (P z)^2 with
    |Theta_1|^2 = z^2 A^2 / 4 whatever the phase: a draw's spectrum is the expectation times A^2 / E[A^2]
    (E[A^2] = A_max^2 / 3) to rounding, and the mean of seeded draws is the expectation within 5 standard errors."""
    pair, model, w = spur
    z1, z2 = pair.teeth
    r1 = z2 // z1
    tol = [am.iso1328_tolerances(0.004, d, 0.040) for d in pair.pitch_diameter]
    stats = [am.deviation_statistics(z, t, ["pitch"], 0.94, 1.0, pitch_model="runout") for z, t in zip((z1, z2), tol)]
    for z, t, st in zip((z1, z2), tol, stats):
        a_max = am.runout_amplitude(z, t)
        assert a_max == pytest.approx(t["F_p"] / 2, rel=1e-12)               # F_p / 2, not capped by f_pt here
        assert np.count_nonzero(st.pitch_spectrum) == 2
        assert st.pitch_spectrum[1] == pytest.approx(z**2 * (0.94 * a_max) ** 2 / 12, rel=1e-12)
    expected = am.expected_order_spectrum(pair, w, *stats).deviations
    zero = am.ToothDeviations.zeros
    q = np.arange(expected.size)
    at_wheel = np.minimum(q % z2, (-q) % z2) == 1
    at_pinion = np.minimum(q % z2, (-q) % z2) == r1
    assert np.max(expected[~(at_wheel | at_pinion)]) == 0.0
    assert np.min(expected[at_wheel | at_pinion][: 2 * 4]) > 0.0            # n = 0..3 of both gears carry power

    rng = np.random.default_rng(1328)
    silent = [replace(st, pitch_spectrum=0 * st.pitch_spectrum) for st in stats]
    only = {0: am.expected_order_spectrum(pair, w, stats[0], silent[1]),
            1: am.expected_order_spectrum(pair, w, silent[0], stats[1])}
    for g, lines in ((0, at_pinion), (1, at_wheel)):
        z = (z1, z2)[g]
        dev = am.draw_deviations(rng, z, tol[g], ["pitch"], 0.94, 1.0, pitch_model="runout")
        steps = np.diff(np.concatenate([dev.position, dev.position[:1]]))
        assert np.ptp(dev.position) <= 0.94 * tol[g]["F_p"] and np.abs(steps).max() <= 0.94 * tol[g]["f_pt"]
        te = am.first_order_te(pair, w, *((dev, zero(z2)) if g == 0 else (zero(z1), dev)))
        _, a = am.order_amplitudes(te)
        assert np.max(a[~lines] ** 2) < 1e-24 * np.max(a**2)
        amplitude_sq = 2 * np.mean(dev.position**2) / 0.94**2          # A^2 of this draw
        scale = amplitude_sq / (am.runout_amplitude(z, tol[g]) ** 2 / 3)
        assert np.allclose(a**2, only[g].deviations * scale, rtol=1e-9, atol=1e-12 * np.max(a**2))

    draws = 300
    power = np.array([am.order_amplitudes(am.first_order_te(pair, w, *(
        am.draw_deviations(rng, z, t, ["pitch"], 0.94, 1.0, pitch_model="runout") for z, t in zip((z1, z2), tol))))[1]
        ** 2 for _ in range(draws)])
    mean, err = power.mean(axis=0), power.std(axis=0) / math.sqrt(draws)
    assert np.all(np.abs(mean - expected) <= 5 * err + 1e-30)
    band = (q >= 0.89 * z2) & (q < 1.12 * z2)
    assert np.sum(mean[band]) == pytest.approx(np.sum(expected[band]), rel=0.15)


def test_pitch_model_is_checked_and_independent_stays_the_default():
    tol = am.iso1328_tolerances(0.004, 0.2944, 0.062)
    default = am.deviation_statistics(72, tol, ["pitch"], 1.0, 1.0, pitch_samples=500)
    named = am.deviation_statistics(72, tol, ["pitch"], 1.0, 1.0, pitch_samples=500, pitch_model="independent")
    assert np.array_equal(default.pitch_spectrum, named.pitch_spectrum)
    d0 = am.draw_deviations(np.random.default_rng(5), 72, tol, am.DEVIATION_KINDS, 1.0, 1.0)
    d1 = am.draw_deviations(np.random.default_rng(5), 72, tol, am.DEVIATION_KINDS, 1.0, 1.0, pitch_model="independent")
    assert np.array_equal(d0.position, d1.position) and np.array_equal(d0.form, d1.form)
    for bad in ("eccentric", 1, None):
        with pytest.raises(InputError, match="as_made_pitch: .* choose from \"independent\", \"runout\", \"none\""):
            am.deviation_statistics(72, tol, ["pitch"], 1.0, 1.0, pitch_model=bad)
    # few teeth: the single pitch step 2 A sin(pi / z) would exceed f_pt at A = F_p / 2, so A is capped
    assert am.runout_amplitude(6, {"f_pt": 5e-6, "F_p": 20e-6}) == pytest.approx(5e-6 / (2 * math.sin(math.pi / 6)))
    # "none": no pitch deviations drawn or counted, the flanks as with the other models
    assert not np.any(am.deviation_statistics(72, tol, am.DEVIATION_KINDS, 1.0, 1.0, pitch_model="none").pitch_spectrum)
    d2 = am.draw_deviations(np.random.default_rng(5), 72, tol, am.DEVIATION_KINDS, 1.0, 1.0, pitch_model="none")
    assert not np.any(d2.position) and np.any(d2.profile_slope)


# ------------------------------------------------------------------------ pinion re-indexed (thesis Sec. 5.6)
def _draw_pair(rng, pair, kinds, pitch_model):
    tol = [am.iso1328_tolerances(0.004, d, 0.040) for d in pair.pitch_diameter]
    return [am.draw_deviations(rng, int(z), t, kinds, 0.94, 1.0, pitch_model=pitch_model)
            for z, t in zip(pair.teeth, tol)]


def test_turning_the_pinion_moves_only_the_lines_both_gears_reach(spur):
    """The first-order TE is linear in the deviations, so turning the pinion by s teeth against the wheel multiplies
    the pinion's share at wheel order q = 3 j by exp(2 pi i j s / 24): a full pinion revolution (s = 24, 48) is the
    identity; the tooth harmonics (q = 72 n, j = 0 mod 24) do not move; the pinion's own spectrum keeps its
    magnitudes and Parseval; the orders only the wheel reaches (q not a multiple of 3) keep theirs; and the whole
    spectrum's energy changes only by the cross terms at the shared orders."""
    pair, model, w = spur
    z1, z2 = (int(z) for z in pair.teeth)
    rng = np.random.default_rng(56)
    pin, whl = _draw_pair(rng, pair, am.DEVIATION_KINDS, "independent")
    aligned = 1e-6 * np.cos(2 * math.pi * np.arange(w.n_positions) / w.n_positions) + 0.3e-6
    orders, c0 = am.reindexed_order_lines(pair, w, pin, whl, 0, aligned)
    q = np.arange(orders.size)
    assert np.array_equal(orders, q)                               # one wheel revolution per hunting period
    for s in (24, 48, -24):
        assert np.allclose(am.reindexed_order_lines(pair, w, pin, whl, s, aligned)[1], c0, rtol=0, atol=1e-18)
    zero = (am.ToothDeviations.zeros(z1), am.ToothDeviations.zeros(z2))
    _, p0 = am.reindexed_order_lines(pair, w, pin, zero[1], 0)
    _, w0 = am.reindexed_order_lines(pair, w, zero[0], whl, 0, aligned)
    assert np.allclose(p0 + w0, c0, rtol=0, atol=1e-18)            # linear: pinion share + wheel share
    tooth = q % z2 == 0
    shared = (q % (z2 // z1) == 0) & ~tooth
    assert np.max(np.abs(p0[q % (z2 // z1) != 0])) < 1e-12 * np.max(np.abs(p0))
    for s in (8, 16, 5):
        _, cs = am.reindexed_order_lines(pair, w, pin, whl, s, aligned)
        _, ps = am.reindexed_order_lines(pair, w, pin, zero[1], s)
        assert np.allclose(cs[tooth], c0[tooth], rtol=0, atol=1e-18)
        assert np.allclose(np.abs(cs[~shared]), np.abs(c0[~shared]), rtol=0, atol=1e-18)
        assert np.allclose(np.abs(ps), np.abs(p0), rtol=0, atol=1e-18)
        assert np.sum(np.abs(ps) ** 2) == pytest.approx(np.sum(np.abs(p0) ** 2), rel=1e-12)
        j = q[shared] // (z2 // z1)
        assert np.allclose(ps[shared], p0[shared] * np.exp(2j * math.pi * j * s / z1), rtol=0, atol=1e-18)
        cross = 2 * np.real(w0[shared] * np.conj(ps[shared] - p0[shared]))
        assert np.sum(np.abs(cs) ** 2 - np.abs(c0) ** 2) == pytest.approx(np.sum(cross), rel=1e-9)
        assert abs(np.sum(cross)) > 1e-6 * np.sum(np.abs(c0[1:]) ** 2)      # the shared lines do move


def test_runout_pitch_alone_keeps_every_lines_magnitude_when_the_pinion_turns(spur):
    """"runout" pitch without flank deviations: the pinion's lines lie at 72 n +- 3, the wheel's at 72 n +- 1 and
    the aligned pair's at 72 n; no order is shared, so no line's magnitude can change whatever the shift."""
    pair, model, w = spur
    rng = np.random.default_rng(57)
    pin, whl = _draw_pair(rng, pair, ["pitch"], "runout")
    aligned = 1e-6 * np.cos(2 * math.pi * np.arange(w.n_positions) / w.n_positions)
    _, c0 = am.reindexed_order_lines(pair, w, pin, whl, 0, aligned)
    for s in (8, 16, 3):
        _, cs = am.reindexed_order_lines(pair, w, pin, whl, s, aligned)
        assert np.allclose(np.abs(cs), np.abs(c0), rtol=1e-9, atol=1e-15 * np.max(np.abs(c0)))
        assert not np.allclose(cs, c0, rtol=0, atol=1e-3 * np.max(np.abs(c0[1:])))   # the phases do move


def test_one_displaced_pinion_tooth_and_one_wheel_tooth_interfere_at_the_shared_orders():
    """Analytic case.  One contact point per mesh position, weight 1 (one tooth pair carries the load), pinion
    tooth t_p displaced by d1, wheel tooth t_w by d2: TE[m, p] = d1 [(m + s) = t_p mod 24] + d2 [m = t_w mod 72]
    over M = 72 mesh periods of P samples.  Its line at wheel order q (N = M P, G(q) = (2/N) sum_p exp(-2 pi i q p /
    N)) is G(q) [d1 sum_{m = t_p - s mod 24} exp(-2 pi i q m / M) + d2 exp(-2 pi i q t_w / M)], the first sum
    3 exp(-2 pi i q (t_p - s) / M) at q = 0 mod 3 and 0 elsewhere, so
    |c_q|^2 = |G|^2 [9 d1^2 + d2^2 + 6 d1 d2 cos(2 pi q (t_p - s - t_w) / M)] at q = 0 mod 3: turning the pinion by s
    moves the cross term's phase by 2 pi q s / 72 = 2 pi j s / 24."""
    pair = GearPair.from_table(dict(module_mm=4.0, teeth=[24, 72], pressure_angle_deg=20.0, helix_angle_deg=0.0,
                                    addendum_modification=[0.0, 0.0], face_width_mm=[40.0, 40.0],
                                    centre_distance_mm=192.0, kind="spur"))
    P, M = 4, 72
    one = [np.zeros(1)] * P
    w = am.ContactWeights(s=one, w_local=one, pair=[np.zeros(1, int)] * P, weight=[np.ones(1)] * P,
                          stiffness=np.ones(P))
    d1, d2, tp, tw = 3e-6, 2e-6, 5, 40
    pin, whl = am.ToothDeviations.zeros(24), am.ToothDeviations.zeros(72)
    pin.position[tp], whl.position[tw] = d1, d2
    N = M * P
    q = np.arange(N // 2 + 1)
    G = 2 / N * np.sum(np.exp(-2j * math.pi * np.outer(q, np.arange(P)) / N), axis=1)
    G[0] /= 2
    G[-1] /= 2
    for s in (0, 8, 16):
        _, c = am.reindexed_order_lines(pair, w, pin, whl, s)
        expected = G * (d1 * np.where(q % 3 == 0, 3.0, 0.0) * np.exp(-2j * math.pi * q * (tp - s) / M)
                        + d2 * np.exp(-2j * math.pi * q * tw / M))
        assert np.allclose(c, expected, rtol=0, atol=1e-15)
        shared = q % 3 == 0
        power = np.abs(G[shared]) ** 2 * (9 * d1**2 + d2**2 + 6 * d1 * d2 * np.cos(
            2 * math.pi * q[shared] * (tp - s - tw) / M))
        assert np.allclose(np.abs(c[shared]) ** 2, power, rtol=1e-9, atol=1e-30)


def test_turned_pinion_lines_are_reindexed_order_lines_from_one_evaluation(spur):
    """The fast path (the pinion's share of the hunting record advanced by s mesh periods) gives, shift by shift,
    the lines of re-assembling the gears with the pinion turned (`reindexed_order_lines`, via `turned`), negative and
    full-revolution shifts included; and first_order_te is still the sum of the two gears' terms."""
    pair, model, w = spur
    rng = np.random.default_rng(7)
    pin, whl = _draw_pair(rng, pair, am.DEVIATION_KINDS, "independent")
    aligned = 0.5e-6 * np.sin(2 * math.pi * np.arange(w.n_positions) / w.n_positions)
    shifts = (0, 8, 16, 5, -3, 24)
    orders, lines = am.turned_pinion_lines(pair, w, pin, whl, shifts, aligned)
    scale = np.max(np.abs(lines[0]))
    for s, c in zip(shifts, lines):
        ref_orders, ref = am.reindexed_order_lines(pair, w, pin, whl, s, aligned)
        assert np.array_equal(orders, ref_orders)
        assert np.max(np.abs(c - ref)) < 1e-12 * scale, s
    assert np.max(np.abs(lines[1] - lines[0])) > 1e-3 * scale          # a turn does move the shared orders
    with pytest.raises(ValueError, match="no shifts"):
        am.turned_pinion_lines(pair, w, pin, whl, ())
