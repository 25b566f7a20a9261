"""Lumped interior model (van Roosmalen 1994 Sec. 2.5-2.7): statics, energy balance, harmonic balance
against time integration and exact frequency response, engagement shock, published trends."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import housingfe
from housingfe.data import thesis
from housingfe.levels import OMEGA0
from housingfe.source.gears import GearPair
from housingfe.source.roosmalen import dynamics as dyn
from housingfe.source.stiffness import (
    Corrections,
    MeshModel,
    ShaftBending,
    normal_force_from_torque,
    stiffness_curve,
)
from tests.source.thesis_gears import spur_pair

REF = thesis()["gears"]
PAIR = GearPair.from_table(REF["single_helical"])
GEOMETRY = dyn.ShaftGeometry()
SHAFTS = (ShaftBending(*GEOMETRY.pinion_spans, GEOMETRY.pinion_shaft_diameter),
          ShaftBending(*GEOMETRY.wheel_spans, GEOMETRY.wheel_shaft_diameter))
K_MEAN = 1.1e9      # N/m, about the analytic mean mesh stiffness of the test gears


def _matrices(loss_factor=0.1):
    return dyn.assemble(PAIR, dyn.derive_interior(PAIR, GEOMETRY, loss_factor), K_MEAN)


def _stiffness_wave(n=64, rel_amp=0.05):
    t = np.arange(n) / n
    return K_MEAN * (1 + rel_amp * np.cos(2 * math.pi * t) + 0.3 * rel_amp * np.sin(4 * math.pi * t))


def test_static_preload_gives_the_torque_and_the_mesh_force():
    mats = _matrices()
    torque = 2000.0
    f0 = dyn.preload_force(mats, torque)
    q = np.linalg.solve(mats.K0 + K_MEAN * np.outer(mats.h, mats.h), f0)
    k1 = dyn.derive_interior(PAIR, GEOMETRY).torsion_stiffness[0]
    theta15 = f0[12] / k1
    assert k1 * (theta15 - q[12]) == pytest.approx(torque, rel=1e-10)               # shaft 1 carries T
    # pinion moment balance: the normal mesh force times r_b1 cos(beta_b) equals T
    assert K_MEAN * (mats.h @ q) == pytest.approx(normal_force_from_torque(PAIR, torque), rel=1e-10)


def test_energy_balance_without_excitation():
    mats = _matrices(loss_factor=0.1)
    K = mats.K0 + K_MEAN * np.outer(mats.h, mats.h)
    assert np.allclose(mats.D, mats.D.T) and np.linalg.eigvalsh(mats.D).min() > -1e-9 * np.abs(mats.D).max()
    Minv = np.linalg.inv(mats.M)
    n = dyn.N_DOF

    def rhs(t, y):
        q, v = y[:n], y[n:2 * n]
        a = Minv @ (-K @ q - mats.D @ v)
        return np.concatenate([v, a, [v @ mats.D @ v]])          # last state: dissipated energy

    rng = np.random.default_rng(1)
    y0 = np.concatenate([rng.normal(size=n) * 1e-6, rng.normal(size=n) * 1e-3, [0.0]])
    sol = solve_ivp(rhs, (0, 0.02), y0, method="DOP853", rtol=1e-10, atol=1e-16)

    def energy(y):
        q, v = y[:n], y[n:2 * n]
        return 0.5 * v @ mats.M @ v + 0.5 * q @ K @ q

    e0, e1, lost = energy(sol.y[:, 0]), energy(sol.y[:, -1]), sol.y[-1, -1]
    assert e1 < 0.5 * e0                                       # damping does take energy out
    assert e0 - e1 == pytest.approx(lost, rel=1e-6)            # and exactly as much as D dissipates


def test_harmonic_balance_equals_exact_frf_for_constant_stiffness():
    mats = _matrices()
    n = 64
    t = np.arange(n) / n
    shock = 1000 * np.cos(2 * math.pi * t) + 300 * np.sin(6 * math.pi * t)
    f_tooth = 400.0
    st = dyn.harmonic_balance(mats, np.full(n, K_MEAN), shock, np.zeros(dyn.N_DOF), f_tooth, H=8)
    for harmonic, coeff in ((1, 500.0), (3, -150j)):
        w = 2 * math.pi * f_tooth * harmonic
        Z = mats.K0 + K_MEAN * np.outer(mats.h, mats.h) - w**2 * mats.M + 1j * w * mats.D
        exact = np.linalg.solve(Z, -coeff * mats.h)
        assert np.allclose(st.Q[8 + harmonic], exact, rtol=1e-9, atol=1e-9 * np.abs(exact).max())


def test_harmonic_balance_equals_time_integration_with_varying_stiffness():
    # heavy damping (eta = 1) so that a short explicit integration reaches the periodic state
    mats = _matrices(loss_factor=1.0)
    S = _stiffness_wave()
    t = np.arange(S.size) / S.size
    shock = 2000 * np.sign(np.sin(2 * math.pi * t))
    f0 = dyn.preload_force(mats, 1500.0)
    st = dyn.harmonic_balance(mats, S, shock, f0, 500.0, H=31)
    times, q = dyn.time_integration(mats, S, shock, f0, 500.0, periods=40, samples_per_period=64,
                                    rtol=1e-9, method="DOP853")
    hb = np.real(np.exp(2j * math.pi * 500.0 * np.outer(times, st.harmonics)) @ st.Q)
    wheel = dyn.WHEEL_THETA_Z
    ours, ref = hb[:, wheel], q[:, wheel]
    # the static wind-up (~0.1 rad) agrees to the integrator's relative tolerance, the ripple to 1e-4
    assert ours.mean() == pytest.approx(ref.mean(), rel=1e-7)
    assert np.max(np.abs((ours - ours.mean()) - (ref - ref.mean()))) < 1e-4 * np.ptp(ref)


def test_engagement_shock_of_uncorrected_gears_jumps_by_F_over_eps():
    S = np.full(512, K_MEAN)
    force = 40e3
    fe = dyn.engagement_force(PAIR, Corrections(), S, force)
    assert abs(fe.mean()) < 1e-9 * force
    # the number of pairs in contact changes by one: F_e steps by S * (F/S) / eps_tot = F / eps_tot
    assert np.ptp(fe) == pytest.approx(force / PAIR.total_contact_ratio, rel=1e-9)
    # a tip relief as large as the deflection over a long ramp removes most of the step
    delta = force / K_MEAN
    relief = Corrections(tip_relief=(delta, delta), tip_relief_length=(5e-3, 5e-3))
    assert np.max(np.abs(np.diff(dyn.engagement_force(PAIR, relief, S, force)))) < 0.1 * np.max(np.abs(np.diff(fe)))


def test_level_of_a_line():
    mats = _matrices()
    st = dyn.harmonic_balance(mats, np.full(16, K_MEAN), 1000 * np.cos(2 * math.pi * np.arange(16) / 16),
                              np.zeros(dyn.N_DOF), 300.0, H=4)
    f, a = st.wheel_angular_velocity()
    lv = dyn.wheel_levels(st)
    assert f[0] == pytest.approx(300.0)
    assert lv["L_omega"][0] == pytest.approx(10 * math.log10(abs(a[0]) ** 2 / 2 / OMEGA0**2), abs=1e-9)
    assert dyn.tooth_band_level(st) == pytest.approx(lv["L_omega"][0], abs=1e-9)   # only line in its band


def test_correction_ranking_at_2000Nm_follows_the_thesis():
    # Sec. 2.7 / 5.7 (calc. at 2000 N m): uncorrected +3.5 dB and D -5.1 dB relative to correction A
    interior = dyn.derive_interior(PAIR, GEOMETRY)
    force = normal_force_from_torque(PAIR, 2000.0)
    levels = {}
    for name in ("uncorrected", "A", "D"):
        corr = Corrections.from_table(REF["profile_corrections"][name])
        curve = stiffness_curve(MeshModel(PAIR, shafts=SHAFTS, corrections=corr, n_slices=12), force, 16)
        S = np.interp(np.arange(128) / 128, curve.position, curve.stiffness, period=1.0)
        mats = dyn.assemble(PAIR, interior, curve.mean)
        f0 = dyn.preload_force(mats, 2000.0)
        shock = dyn.engagement_force(PAIR, corr, S, force)
        levels[name] = np.mean([dyn.tooth_band_level(dyn.harmonic_balance(mats, S, shock, f0,
                                                                          PAIR.tooth_frequency(rpm), 20))
                                for rpm in (800, 1000, 1200, 1400)])
    assert levels["uncorrected"] > levels["A"] > levels["D"]


def test_bearing_split_preserves_the_lumped_reaction():
    # the four bearing forces must add up to the lumped shaft reaction and reproduce its moments
    mats = _matrices()
    interior = dyn.derive_interior(PAIR, GEOMETRY)
    n = 32
    shock = 1000 * np.cos(2 * math.pi * np.arange(n) / n)
    st = dyn.harmonic_balance(mats, np.full(n, K_MEAN), shock, np.zeros(dyn.N_DOF), 400.0, H=4)
    bs = dyn.bearing_spectra(st, mats, interior, GEOMETRY, PAIR, 1000.0, 0.0)
    for shaft, (i, j) in enumerate(((0, 1), (2, 3))):
        Fx, Fy, Fz, Mx, My = bs.lumped[shaft]
        left, right = bs.loads[i], bs.loads[j]
        assert np.allclose(left[0] + right[0], Fx) and np.allclose(left[1] + right[1], Fy)
        assert np.allclose(left[2] + right[2], Fz)
        # moments about the gear centre (M = r x F): M_y = sum z F_x, M_x = -sum z F_y
        tol = 1e-9 * np.abs(bs.loads).max()
        assert np.allclose(bs.z[i] * left[0] + bs.z[j] * right[0], My, atol=tol)
        assert np.allclose(-(bs.z[i] * left[1] + bs.z[j] * right[1]), Mx, atol=tol)
        assert np.abs(My).max() > 1e-3 * np.abs(Fx).max()     # the helical mesh tilts the shafts


def test_static_tilt_moment_is_axial_force_times_pitch_radius():
    # helical mesh: the axial tooth force F_n sin(beta_b) acts at the operating pitch radius, so the
    # pinion bearings carry the moment F_n sin(beta_b) r_w1 about y, and the wheel's r_w2 in turn
    mats = _matrices()
    torque = 2000.0
    q = np.linalg.solve(mats.K0 + K_MEAN * np.outer(mats.h, mats.h), dyn.preload_force(mats, torque))
    interior = dyn.derive_interior(PAIR, GEOMETRY)
    fn = normal_force_from_torque(PAIR, torque)
    rw1, rw2 = PAIR.base_diameter / 2 / math.cos(PAIR.operating_pressure_angle)
    sb = math.sin(PAIR.base_helix_angle)
    assert interior.pinion_bearings[4] * q[4] == pytest.approx(-fn * sb * rw1, rel=1e-9)
    assert interior.wheel_bearings[4] * q[10] == pytest.approx(-fn * sb * rw2, rel=1e-9)
    assert interior.pinion_bearings[2] * q[2] == pytest.approx(fn * sb, rel=1e-9)    # axial force on the pinion


PAIR_DH = GearPair.from_table(REF["double_helical"])


def test_single_helical_mesh_direction_is_the_appendix_c_normal():
    """Bit for bit the single helical normal (sin a cos bb, cos a cos bb, -sin bb) with r_b cos bb and the tilt terms
    r_w sin bb: the double helical change leaves it alone."""
    a, bb = PAIR.operating_pressure_angle, PAIR.base_helix_angle
    rb1, rb2 = PAIR.base_diameter / 2
    h = np.zeros(dyn.N_DOF)
    h[0:3] = [math.sin(a) * math.cos(bb), math.cos(a) * math.cos(bb), -math.sin(bb)]
    h[5], h[6:9], h[11] = rb1 * math.cos(bb), -h[0:3], rb2 * math.cos(bb)
    h[4], h[10] = rb1 / math.cos(a) * math.sin(bb), rb2 / math.cos(a) * math.sin(bb)
    assert np.array_equal(dyn.mesh_direction(PAIR), h)


def test_double_helical_mesh_puts_no_axial_force_or_moment_on_the_shafts():
    """Double helical: the halves' axial forces are equal and opposite at the same radius, so the static mesh load
    on each shaft is transverse, T / r_b1 along the line of action (torque balance: the normal force F_n =
    T / (r_b1 cos bb) has the transverse resultant F_n cos bb), and the bearings carry no axial force and no
    moment; the transverse mesh stiffness is S cos^2(beta_b)."""
    interior = dyn.derive_interior(PAIR_DH, GEOMETRY)
    mats = dyn.assemble(PAIR_DH, interior, K_MEAN)
    h = mats.h
    assert h[2] == 0.0 and h[8] == 0.0 and h[4] == 0.0 and h[10] == 0.0 and h[3] == 0.0 and h[9] == 0.0
    cb = math.cos(PAIR_DH.base_helix_angle)
    assert K_MEAN * (h[0] ** 2 + h[1] ** 2) == pytest.approx(K_MEAN * cb**2, rel=1e-14)
    torque = 2000.0
    q = np.linalg.solve(mats.K0 + K_MEAN * np.outer(h, h), dyn.preload_force(mats, torque))
    mesh = -K_MEAN * (h @ q) * h                   # generalized mesh force on the 14 DOFs
    rb1 = PAIR_DH.base_diameter[0] / 2
    for shaft in (slice(0, 6), slice(6, 12)):
        f = mesh[shaft]
        assert f[2] == 0.0 and f[3] == 0.0 and f[4] == 0.0          # no axial force, no tilting moment
        assert math.hypot(f[0], f[1]) == pytest.approx(torque / rb1, rel=1e-10)
    assert K_MEAN * (h @ q) == pytest.approx(normal_force_from_torque(PAIR_DH, torque), rel=1e-10)
    reaction = mats.K0[:5, :5] @ q[:5]             # the pinion bearings: transverse only
    assert abs(reaction[2]) < 1e-12 * torque / rb1 and np.abs(reaction[3:5]).max() < 1e-12 * torque
    assert math.hypot(reaction[0], reaction[1]) == pytest.approx(torque / rb1, rel=1e-10)


# ------------------------------------------------------------------ engagement over the face width
SET_A = Corrections.from_table(REF["profile_corrections"]["A"])


@pytest.mark.parametrize("corrections", [Corrections(), SET_A])
def test_face_width_shock_of_a_spur_pair_is_the_thesis_shock(corrections):
    """eps_beta = 0: every slice of a contact line enters and leaves at once, so the face-width shock is Eq. 2.62
    sample by sample (time-varying S, any load share across the face: a spur line's slices sum to one pair)."""
    spur = spur_pair()
    assert spur.overlap_ratio == 0.0
    S = _stiffness_wave(n=256, rel_amp=0.2)
    force = 40e3
    ref = dyn.engagement_force(spur, corrections, S, force)
    A = spur.path_of_contact[0]
    share = np.linspace(0.7, 1.3, 24)[None, :]           # a skewed load across the face changes nothing
    for load_share in (None, share):
        ours = dyn.engagement_force_face_width(spur, corrections, S, force, load_share=load_share, n_slices=16,
                                               origin=A)
        np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-9 * np.ptp(ref))


@pytest.mark.parametrize("face_mm", [25.0, 66.0])
def test_uniform_face_width_shock_is_the_transverse_shock_times_sinc(face_mm):
    """Uniform load along the line and constant S: slice j is the transverse-section shock (Eq. 2.62 with
    eps_alpha) delayed by o_j tan(beta_b) / p_bt, so harmonic n is multiplied by the slices' array factor
    sin(pi n eps_beta) / (J sin(pi n eps_beta / J)) -> sinc(n eps_beta) for many slices (notes §5.2)."""
    from dataclasses import replace

    pair = replace(PAIR, face_width=(face_mm * 1e-3, face_mm * 1e-3))
    eps_b = pair.overlap_ratio
    S = np.full(2048, K_MEAN)
    force = 40e3
    A = pair.path_of_contact[0]
    transverse = dyn.engagement_force(pair, SET_A, S, force, contact_ratio=pair.transverse_contact_ratio)
    sliced = dyn.engagement_force_face_width(pair, SET_A, S, force, n_slices=600, origin=A)
    n = np.arange(1, 16)
    amp = lambda x: 2 * np.abs(np.fft.rfft(x)[1:16]) / x.size     # noqa: E731
    expected = amp(transverse) * np.abs(np.sinc(n * eps_b))
    np.testing.assert_allclose(amp(sliced), expected, rtol=0, atol=2e-3 * amp(transverse)[0])
    # the tolerance is far below the reduction the slices make (the test can tell sinc from no smoothing)
    assert np.max(amp(transverse) - expected) > 50 * 2e-3 * amp(transverse)[0]


def _excitation_amplitudes(S, shock, force, harmonics=15):
    x = np.mean(S) * dyn.quasi_static_compression(S, shock, force)
    return 2 * np.abs(np.fft.rfft(x - x.mean())[1:harmonics + 1]) / x.size


def test_face_width_excitation_near_an_integer_overlap_ratio_is_the_analytic_edge_residual():
    """Set A's geometry (eps_beta = 1.026, eps_alpha = 1.441), no corrections, uniform load, constant S: the
    quasi-static excitation is what the helix leaves of the two contact-edge steps (entry at A, exit at E),
    k_m (d - mean d)_n = 2 F |sin(pi n eps_alpha)| |sinc(n eps_beta)| / (pi n eps_alpha): 1/n times the edges'
    interference (near-zeros at n = 7, 9).  The scene default 256 slices x 256 samples gives it within 1e-3 of the
    tooth line with the contact edges cut exactly; with the edges at the slice midpoints (before) the residual window
    (eps_beta - 1) p_bt is only ~7 slices wide and harmonic 7 came out 2.4 times too large (the plateau of the
    check 28.excitation.envelope)."""
    S = np.full(256, K_MEAN)
    force = 41.5e3
    n = np.arange(1, 16)
    ea, eb = PAIR.transverse_contact_ratio, PAIR.overlap_ratio
    analytic = 2 * force * np.abs(np.sin(math.pi * n * ea)) * np.abs(np.sinc(n * eb)) / (math.pi * n * ea)
    exact = _excitation_amplitudes(S, dyn.engagement_force_face_width(PAIR, Corrections(), S, force), force)
    np.testing.assert_allclose(exact, analytic, rtol=0, atol=1e-3 * analytic[0])
    midpoint = _excitation_amplitudes(S, dyn.engagement_force_face_width(PAIR, Corrections(), S, force,
                                                                         exact_edges=False), force)
    assert np.max(np.abs(midpoint - analytic)[4:12]) > 20 * 1e-3 * analytic[0]      # the test can tell


@pytest.mark.parametrize("corrections", [Corrections(), SET_A])
def test_face_width_excitation_is_converged_in_slices_and_samples_at_the_default(corrections):
    """A time-varying S and a skewed load across the face: the quasi-static excitation's harmonics 1-15 at the
    default 256 slices x 256 samples lie within 2e-3 of the tooth line of 2048 slices x 1024 samples (the converged
    reference, benchmarks/experiments/excitation_convergence; errors 1e-4 / 2e-4 of it, midpoint edges 3e-2 / 1e-2)."""
    force = 41.5e3
    share = np.linspace(0.9, 1.15, 24)[None, :]
    coarse_S = _stiffness_wave(n=32, rel_amp=0.02)
    amps = []
    for samples, slices in ((256, 256), (1024, 2048)):
        S = np.interp(np.arange(samples) / samples, np.arange(32) / 32, coarse_S, period=1.0)
        shock = dyn.engagement_force_face_width(PAIR, corrections, S, force, load_share=share, n_slices=slices)
        amps.append(_excitation_amplitudes(S, shock, force))
    default, reference = amps
    np.testing.assert_allclose(default, reference, rtol=0, atol=2e-3 * reference[0])


def test_face_width_is_the_default_engagement_and_thesis_2d_the_replica():
    force = 40e3
    S = np.full(256, K_MEAN)
    assert dyn.DEFAULT_ENGAGEMENT == "face-width"
    np.testing.assert_array_equal(dyn.engagement_shock("thesis-2d", PAIR, SET_A, S, force),
                                  dyn.engagement_force(PAIR, SET_A, S, force))
    np.testing.assert_array_equal(dyn.engagement_shock("face-width", PAIR, SET_A, S, force),
                                  dyn.engagement_force_face_width(PAIR, SET_A, S, force))
    with pytest.raises(housingfe.errors.InputError, match="engagement"):
        dyn.engagement_shock("3d", PAIR, SET_A, S, force)


def test_thesis_2d_shock_reproduces_fig_2_20_correction_length_of_set_d():
    """Fig. 2.20 (Sec. 2.7; set D, delta = 40 um on both gears, n = 1500 rev/min, L_omega at the tooth frequency):
    "The uncorrected gears are represented by l = 0 and they show the highest levels" and "When the gears should be
    operated at a torque load of 2000 Nm, a correction length of 5.5 mm appears to be the best choice".  The thesis'
    2-D shock (engagement thesis-2d, the replica) with D's geometry: l = 0 the loudest, and among 0 / 2 / 4 / 5 / 5.5 /
    6 / 7 mm the quietest at 2000 N m is 5.5 mm (82.5 dB against 89.4 at 6 mm and 95.9 at 5 mm when written)."""
    from dataclasses import replace

    from housingfe.scenefile import read_scene_dict
    from housingfe.source.roosmalen import run as rs

    data, path = read_scene_dict("gearset-D")
    table = rs.parse(data, str(path))
    pair, corr, _, interior, model = rs.build(table, str(path))
    levels = {}
    for length_mm in (0.0, 2.0, 4.0, 5.0, 5.5, 6.0, 7.0):
        relief = 40e-6 if length_mm else 0.0
        c = replace(corr, tip_relief=(relief, relief), tip_relief_length=(length_mm * 1e-3,) * 2)
        op = rs.OperatingPoint(pair, c, interior, replace(model, corrections=c), 2000.0, table.stiffness_positions,
                               engagement="thesis-2d")
        levels[length_mm] = dyn.tooth_band_level(op.steady_state(pair, 1500.0, 20))
    assert max(levels, key=levels.get) == 0.0
    assert min(levels, key=levels.get) == 5.5
