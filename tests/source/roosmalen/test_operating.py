"""The source stage (housingfe.source.roosmalen.operating): SourceModel.operating_point gives what `housingfe source` computes,
its mesh force and transmission error obey F = S(t) d(t) + F_e(t), its bearing loads balance the lumped reactions,
and bad operating points are input errors."""
import math

import numpy as np
import pytest

from housingfe.errors import InputError
from housingfe.levels import OMEGA0, level
from housingfe.scenefile import read_scene_dict
from housingfe.source.roosmalen import dynamics as dyn
from housingfe.source.roosmalen import run as roosmalen
from housingfe.source.roosmalen.operating import SourceModel


@pytest.fixture(scope="module")
def model():
    return SourceModel.from_scene("gearset-A")


def test_tooth_band_levels_are_those_of_the_source_command(model):
    """The path of `housingfe source gearset-A` (roosmalen.run_scene: build, OperatingPoint at the scene torque,
    harmonic balance with the scene's harmonics, tooth_band_level) at the measured speeds of Sec. 5.3."""
    data, path = read_scene_dict("gearset-A")
    table = roosmalen.parse(data, str(path))
    pair, corr, _, interior, mesh_model = roosmalen.build(table, str(path))
    op = roosmalen.OperatingPoint(pair, corr, interior, mesh_model, table.torque_Nm, table.stiffness_positions)
    for rpm in (500.0, 1000.0, 1500.0):
        ref = dyn.tooth_band_level(op.steady_state(pair, rpm, table.harmonics))
        ex = model.operating_point(rpm, 2000.0)
        assert ex.L_omega_tooth_band == pytest.approx(ref, abs=1e-9)
        assert ex.tooth_frequency_hz == pytest.approx(0.4 * rpm, rel=1e-12)       # 24 teeth
        np.testing.assert_allclose(ex.frequency_hz, ex.harmonic * 0.4 * rpm, rtol=1e-12)
    # numpy scalars are numbers too
    assert model.operating_point(np.int64(500), np.float64(2000.0)).L_omega_tooth_band == pytest.approx(
        model.operating_point(500.0, 2000.0).L_omega_tooth_band, abs=1e-12)
    # and the description of the test gearbox gives the same model
    from housingfe.drivetrain.description import test_gearbox

    ex2 = test_gearbox("A").source_model(harmonics=table.harmonics, stiffness_positions=table.stiffness_positions
                                         ).operating_point(1000.0, 2000.0)
    assert ex2.L_omega_tooth_band == pytest.approx(model.operating_point(1000.0, 2000.0).L_omega_tooth_band,
                                                   abs=1e-9)


@pytest.mark.parametrize("rpm", [50.0, 1000.0])
def test_mesh_force_is_stiffness_times_transmission_error_plus_shock(model, rpm):
    """F(t) = S(t) d(t) + F_e(t) harmonic by harmonic: F_n = sum_m S_{n-m} d_m + E_n with the Fourier coefficients
    of the sampled S and F_e, d from the excitation's mean compression and transmission error."""
    ex = model.operating_point(rpm, 2000.0)
    S, Fe = model.mesh_stiffness(2000.0)
    N, H = S.size, ex.harmonic.size
    c, E = np.fft.fft(S) / N, np.fft.fft(Fe) / N
    d = np.zeros(2 * H + 1, complex)                  # two-sided, index m + H
    d[H] = ex.mean_compression
    d[H + 1:] = ex.transmission_error / 2
    d[:H] = np.conj(ex.transmission_error[::-1]) / 2
    m = np.arange(-H, H + 1)
    F = np.array([c[(n - m) % N] @ d + E[n % N] for n in range(0, H + 1)])
    assert F[0].real == pytest.approx(ex.mean_mesh_force, rel=1e-10)
    np.testing.assert_allclose(2 * F[1:], ex.mesh_force, atol=1e-9 * np.abs(ex.mesh_force).max())
    # the mean force carries the torque: 2000 N m on the pinion base radius (normal force, helix included)
    pair = model.pair
    assert ex.mean_mesh_force == pytest.approx(
        2000.0 / (pair.base_diameter[0] / 2 * math.cos(pair.base_helix_angle)), rel=2e-3)


def test_bearing_loads_and_levels(model):
    ex = model.operating_point(1500.0, 2000.0)
    b = ex.bearings
    assert b.names == ["pinion_left", "pinion_right", "wheel_left", "wheel_right"]
    assert ex.bearing_forces.shape == (4, 3, ex.harmonic.size)
    # each shaft's two bearings carry its lumped reaction k_b q (forces; moments as force couples)
    Q = ex.state.Q[ex.state.harmonics >= 1]
    for i, (shaft, kb) in enumerate((("pinion", model.interior.pinion_bearings),
                                     ("wheel", model.interior.wheel_bearings))):
        react = 2 * np.asarray(kb)[:, None] * Q[:, dyn.BEARING_DOFS[shaft]].T
        np.testing.assert_allclose(ex.bearing_forces[2 * i] + ex.bearing_forces[2 * i + 1], react[:3],
                                   atol=1e-9 * np.abs(react).max())
    # L_omega per line: the wheel's angular velocity i n Omega theta_z (rms), re 5e-8 rad/s
    omega = 1j * 2 * math.pi * ex.frequency_hz * 2 * Q[:, dyn.WHEEL_THETA_Z]
    np.testing.assert_allclose(ex.L_omega, level(0.5 * np.abs(omega) ** 2, OMEGA0), atol=1e-9)
    assert ex.L_omega_tooth_band >= ex.L_omega[0] - 1e-9           # the band holds the first line


@pytest.mark.parametrize("speed, torque, key", [(-100.0, 2000.0, "speed_rpm"), (0.0, 2000.0, "speed_rpm"),
                                                (3000.0, 2000.0, "speed_rpm"), (float("nan"), 2000.0, "speed_rpm"),
                                                ("fast", 2000.0, "speed_rpm"), (1000.0, 0.0, "torque_nm"),
                                                (1000.0, -500.0, "torque_nm")])
def test_bad_operating_points_are_input_errors(model, speed, torque, key):
    with pytest.raises(InputError, match=key):
        model.operating_point(speed, torque)


def test_default_stiffness_positions_do_not_alias_the_harmonics_the_balance_uses():
    """The source samples S(t) (and the shuttling moment's arm, the load's centre) at `stiffness_positions` per base
    pitch and interpolates them linearly onto 256 instants (OperatingPoint, mesh_moments.one_sided_harmonics); the
    run-up takes harmonics n = 1..H of that.  A harmonic of the interpolant is the true one times sinc^2(n / P) plus
    images of P -+ n: at 32 positions every n >= 16 is an image and n >= 9 is aliased, which cost up to 3.3 dB of
    the run-up's L_WA at 250 rev/min (benchmarks/experiments/stiffness_positions).  Analytic curve with a slope jump
    at any point of the period, f(u) = ((u - u0) mod 1 - 1/2)^2, harmonics exactly 1 / (pi^2 n^2): at the default
    positions every line n <= H lies below the positions' Nyquist limit, n <= H/2 comes within 1 dB and n <= H within
    3 dB for every u0 (128 positions: 0.5 / 2.1 dB; 32: 20 / 56 dB; 64: 2.4 / 13 dB; 96: 1.1 / 5.2 dB)."""
    import inspect

    from housingfe.source.mesh_moments import one_sided_harmonics

    defaults = inspect.signature(SourceModel).parameters
    positions, H = defaults["stiffness_positions"].default, defaults["harmonics"].default
    assert roosmalen.SourceTable.model_fields["stiffness_positions"].default == positions
    assert positions > 2 * H                      # every line of the balance below the Nyquist limit P / 2
    n = np.arange(1, H + 1)
    exact = 1.0 / (np.pi**2 * n**2)
    u = np.arange(positions) / positions
    worst = np.zeros(H)
    for u0 in np.linspace(0.0, 1.0, 41)[:-1] + 0.0031:      # the kink between the positions, anywhere
        amp = np.abs(one_sided_harmonics(u, ((u - u0) % 1.0 - 0.5) ** 2, H))
        worst = np.maximum(worst, np.abs(20 * np.log10(amp / exact)))
    assert worst[:H // 2].max() < 1.0
    assert worst.max() < 3.0
