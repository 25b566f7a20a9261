"""Sound power levels (eq. 4.16), bands and A-weighting."""
import numpy as np
import pytest

from housingfe import levels
from housingfe.errors import InputError
from housingfe.radiation import analytic, power


@pytest.mark.parametrize("f, expected", [(100.0, -19.1), (1000.0, 0.0), (4000.0, 1.0)])
def test_a_weighting_iec_61672_table_values(f, expected):
    assert power.a_weighted([f], [0.0])[0] == pytest.approx(expected, abs=0.05)


def test_eq_4_16_and_its_inverse():
    L_v, S, L_sigma = np.array([80.0, 90.0]), 0.408, np.array([-15.2, 0.0])
    L_W = power.sound_power_level(L_v, S, L_sigma)
    # Sec. 4.7: "total area 0.408 m^2 so that L_S = -3.9 dB"
    assert power.area_level_db(S) == pytest.approx(-3.9, abs=0.05)
    assert L_W == pytest.approx(L_v - 3.894 + L_sigma, abs=1e-3)
    assert power.radiation_index_from_levels(L_W, L_v, S) == pytest.approx(L_sigma)


def test_eq_4_16_equals_physical_power_up_to_rho_c_over_400():
    # L_W = L_v + L_S + L_sigma holds exactly for rho c = P0/(S0 v0^2) = 400 kg/(m^2 s); with the
    # physical rho c the power level is higher by 10 lg(rho c / 400).
    rho, c, S, v2, sigma = 1.21, 344.0, 0.7, 1e-6, 0.5
    P = rho * c * S * v2 * sigma
    L_exact = power.power_level_db(P)
    L_eq = power.sound_power_level(levels.level(v2, levels.V0), S, 10 * np.log10(sigma))
    assert L_exact - L_eq == pytest.approx(10 * np.log10(rho * c / 400.0), abs=1e-9)


def test_band_sum_two_equal_lines_add_3_db_and_a_weighted_total():
    f = np.array([990.0, 1010.0, 3990.0])
    L = np.array([60.0, 60.0, 50.0])
    bands = levels.third_octave_bands(900.0, 4100.0)
    band_L = power.band_power_levels(f, L, bands)
    i1k = int(np.argmin(abs(bands.nominal - 1000)))
    i4k = int(np.argmin(abs(bands.nominal - 4000)))
    assert band_L[i1k] == pytest.approx(63.01, abs=0.01)
    assert band_L[i4k] == pytest.approx(50.0, abs=1e-9)
    assert np.isneginf(band_L[[i for i in range(len(band_L)) if i not in (i1k, i4k)]]).all()
    total_A = power.energy_total_db(power.a_weighted(f, L))
    expected = 10 * np.log10(2 * 10**(60.0 / 10 + levels.a_weighting_db(1000.0) / 10)
                             + 10**((50.0 + levels.a_weighting_db(3990.0)) / 10))
    assert total_A == pytest.approx(expected, abs=0.05)
    # by hand with A(1 kHz) = 0 dB, A(4 kHz) = +1.0 dB: 10 lg(2e6 + 10^5.1) = 63.27 dB
    assert total_A == pytest.approx(63.27, abs=0.03)


def test_sound_power_spectrum_from_erp():
    # sigma = 1 (ERP): the power in W from eq. 4.16 equals rho c S v^2 * 400/(rho c)
    f = np.arange(100.0, 2001.0, 10.0)
    L_v = np.full(f.shape, 70.0)
    spec = power.sound_power_spectrum(f, L_v, 1.0, 0.0)
    assert spec.L_W_db == pytest.approx(70.0)
    assert spec.total_L_W_db == pytest.approx(70.0 + 10 * np.log10(f.size))
    assert spec.total_L_WA_db < spec.total_L_W_db
    # every line lands in exactly one band: band energies add up to the total
    assert power.energy_total_db(spec.band_L_W_db) == pytest.approx(spec.total_L_W_db, abs=1e-9)


def test_erp_level_of_unit_sigma():
    P = analytic.equivalent_radiated_power(levels.V0**2, 1.0, rho=1.0, c=400.0)
    assert power.power_level_db(P) == pytest.approx(0.0, abs=1e-12)


def test_bad_input():
    with pytest.raises(InputError, match="area_m2"):
        power.sound_power_level(70.0, 0.0, 0.0)
    with pytest.raises(InputError, match="velocity_level_db"):
        power.sound_power_level(np.nan, 1.0, 0.0)
