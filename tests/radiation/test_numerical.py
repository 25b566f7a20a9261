"""Rayleigh-integral radiation efficiency against the analytic baffled piston and Wallace's plate mode."""
import numpy as np
import pytest

from housingfe.errors import InputError
from housingfe.radiation import analytic, numerical

C = analytic.SPEED_OF_SOUND


@pytest.mark.parametrize("ka", [0.1, 0.5, 1.0, 2.0, 3.0, 5.0])
def test_rayleigh_piston_matches_analytic(ka):
    a = 0.1
    pts, nrm, w = numerical.disc_quadrature(a, 12, 36)
    res = numerical.rayleigh_radiated_power(pts, nrm, w, np.full(len(w), 2e-3 + 1e-3j),
                                            ka * C / (2 * np.pi * a))
    assert 10 * np.log10(res.sigma / analytic.piston_sigma(ka)) == pytest.approx(0.0, abs=0.01)
    assert res.area_m2 == pytest.approx(np.pi * a**2, rel=1e-12)
    assert res.mean_square_velocity == pytest.approx(abs(2e-3 + 1e-3j) ** 2 / 2)


def _plate_grid(lx, ly, n):
    """Midpoint rule on an n x n grid of a plate in z = 0 (like facet data from an FE mesh)."""
    x = (np.arange(n) + 0.5) * lx / n
    y = (np.arange(n) + 0.5) * ly / n
    X, Y = np.meshgrid(x, y, indexing="ij")
    pts = np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)])
    return pts, np.tile([0.0, 0.0, 1.0], (X.size, 1)), np.full(X.size, lx * ly / n**2)


def test_rayleigh_simply_supported_plate_mode_11_low_frequency_wallace():
    # Wallace (1972): sigma_11 ~ 32 k^2 a b / pi^5 * [1 - k^2 a b / 12 ((1 - 8/pi^2) (a/b + b/a))]
    lx, ly = 0.4, 0.3
    pts, nrm, w = _plate_grid(lx, ly, 40)
    v = np.sin(np.pi * pts[:, 0] / lx) * np.sin(np.pi * pts[:, 1] / ly)
    k = 0.5 / lx
    res = numerical.rayleigh_radiated_power(pts, nrm, w, v, k * C / (2 * np.pi))
    kab = k**2 * lx * ly
    expected = 32 * kab / np.pi**5 * (1 - kab / 12 * (1 - 8 / np.pi**2) * (lx / ly + ly / lx))
    assert res.sigma == pytest.approx(expected, rel=0.01)


def test_plates_far_apart_add_their_powers():
    pts, nrm, w = numerical.disc_quadrature(0.05, 8, 24)
    pts2 = pts + [0.0, 0.0, 0.2]
    f = 1000.0
    one = numerical.rayleigh_radiated_power(pts, nrm, w, np.ones(len(w)), f)
    both = numerical.baffled_plates_radiated_power(
        np.vstack([pts, pts2]), np.vstack([nrm, nrm]), np.concatenate([w, w]), np.ones(2 * len(w)),
        np.repeat([1, 2], len(w)), f)
    assert both.power_w == pytest.approx(2 * one.power_w, rel=1e-12)
    assert both.sigma == pytest.approx(one.sigma, rel=1e-12)


def test_non_planar_data_rejected_by_rayleigh():
    pts, nrm, w = numerical.disc_quadrature(0.05, 4, 8)
    pts[0, 2] = 0.01
    with pytest.raises(InputError, match="plane"):
        numerical.rayleigh_radiated_power(pts, nrm, w, np.ones(len(w)), 100.0)


@pytest.mark.parametrize("change", ["weights", "normals", "shape"])
def test_bad_surface_data_raises_input_error(change):
    pts, nrm, w = numerical.disc_quadrature(0.05, 4, 8)
    v = np.ones(len(w))
    if change == "weights":
        w[0] = -1.0
    elif change == "normals":
        nrm = 2 * nrm
    else:
        v = v[:-1]
    with pytest.raises(InputError):
        numerical.rayleigh_radiated_power(pts, nrm, w, v, 100.0)


def test_rms_velocity_input_doubles_power_keeps_sigma():
    # the same phasor read as rms carries twice the mean square, hence twice the power
    pts, nrm, w = numerical.disc_quadrature(0.1, 8, 24)
    v = np.full(len(w), 1e-3 + 0j)
    peak = numerical.rayleigh_radiated_power(pts, nrm, w, v, 500.0)
    rms = numerical.rayleigh_radiated_power(pts, nrm, w, v, 500.0, velocity_is_rms=True)
    assert rms.power_w == pytest.approx(2 * peak.power_w, rel=1e-12)
    assert rms.mean_square_velocity == pytest.approx(1e-6, rel=1e-12)
    assert rms.sigma == pytest.approx(peak.sigma, rel=1e-12)
