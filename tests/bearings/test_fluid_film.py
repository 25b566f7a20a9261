"""Fluid-film journal bearings: the Reynolds solver against Raimondi–Boyd and the Ocvirk short bearing, and the
thesis' Sec. 3.5 operating points."""
import math

import numpy as np
import pytest

from housingfe.bearings.fluid_film import (
    JournalBearing,
    ReynoldsSolver,
    journal_bearing_coefficients,
    short_bearing_coefficients,
    short_bearing_film_force,
    short_bearing_load,
)
from housingfe.data import thesis
from housingfe.errors import InputError

REF = thesis()


def thesis_bearing(name):
    d = REF["fluid_film_bearings"][name]
    return (JournalBearing(d["D_mm"] * 1e-3, d["L_mm"] * 1e-3, d["radial_clearance_um"] * 1e-6,
                           d["viscosity_Pa_s"]), d["omega_rad_per_s"], d["F_N"], d["eccentricity_ratio"])


def test_short_bearing_force_integral_equals_closed_form():
    b = JournalBearing(0.08, 0.02, 1e-4, 0.04)
    for eps in (0.2, 0.6, 0.9):
        f = short_bearing_film_force(b, 150.0, (eps * 1e-4, 0.0))
        assert np.hypot(*f) == pytest.approx(short_bearing_load(b, 150.0, eps), rel=1e-6)
        # Ocvirk attitude angle: tan(phi) = pi sqrt(1 - eps^2) / (4 eps)
        assert abs(math.atan2(f[1], f[0]) - math.pi) % (2 * math.pi) == pytest.approx(
            math.atan(math.pi * math.sqrt(1 - eps**2) / (4 * eps)), abs=1e-6)


@pytest.mark.parametrize("eps,s_rb,phi_rb", [(0.6, 0.121, 50.58), (0.8, 0.0446, 36.24), (0.9, 0.0188, 26.45)])
def test_finite_bearing_matches_raimondi_boyd(eps, s_rb, phi_rb):
    # Raimondi & Boyd (1958), full journal bearing, L/D = 1, Reynolds condition: Sommerfeld number and
    # attitude angle (as tabulated in Shigley's Mechanical Engineering Design)
    b = JournalBearing(0.1, 0.1, 1e-4, 0.05)
    omega = 100.0
    f = ReynoldsSolver(b, 90, 24, "reynolds").film_load((eps, 0.0, 0.0, 0.0))
    load = np.hypot(*f[:2]) * b.viscosity * omega * 0.05**4 / 1e-4**2
    s = b.viscosity * omega / (2 * math.pi) * 0.1 * 0.1 / load * (0.05 / 1e-4) ** 2
    assert s == pytest.approx(s_rb, rel=0.02)
    assert abs(math.degrees(math.atan2(f[1], f[0]) - math.pi)) == pytest.approx(phi_rb, abs=1.5)


def test_finite_solver_tends_to_short_bearing_coefficients():
    # L/D = 0.1 with the half-Sommerfeld condition: the Ocvirk assumptions hold up to O((L/D)^2)
    b = JournalBearing(0.1, 0.01, 1e-4, 0.05)
    omega = 100.0
    load = (0.0, -short_bearing_load(b, omega, 0.6))
    short = short_bearing_coefficients(b, omega, load)
    assert short.eccentricity_ratio == pytest.approx(0.6, abs=1e-9)
    finite = journal_bearing_coefficients(b, omega, load, cavitation="gumbel", n_theta=180, n_z=16)
    assert finite.eccentricity_ratio == pytest.approx(0.6, abs=0.01)
    assert finite.K[:2, :2] == pytest.approx(short.K[:2, :2], rel=0.05)
    assert finite.C[:2, :2] == pytest.approx(short.C[:2, :2], rel=0.05)


@pytest.mark.parametrize("name", ["pinion", "wheel"])
def test_thesis_section_3_5_eccentricity(name):
    # the thesis reads 0.82 (pinion) and 0.83 (wheel) from short-bearing graphs (Lund); the closed-form
    # Ocvirk bearing gives 0.804 and 0.786, the finite-length Reynolds solution (L/D = 0.70, 0.74) 0.888, 0.877
    bearing, omega, force, eps_thesis = thesis_bearing(name)
    short = short_bearing_coefficients(bearing, omega, (0.0, -force))
    assert short.eccentricity_ratio == pytest.approx(eps_thesis, abs=0.05)
    finite = journal_bearing_coefficients(bearing, omega, (0.0, -force))
    assert eps_thesis < finite.eccentricity_ratio < 0.9
    assert finite.eccentricity_ratio > short.eccentricity_ratio      # the finite film carries less


def test_coefficient_structure():
    bearing, omega, force, _ = thesis_bearing("pinion")
    res = journal_bearing_coefficients(bearing, omega, (0.0, -force))
    k, c = res.K, res.C
    assert res.displacement[1] < 0                  # the journal sinks under a downward load...
    assert abs(res.displacement[0]) > 0             # ...and moves sideways (attitude angle)
    assert abs(k[0, 1] - k[1, 0]) > 0.1 * abs(k[0, 1])                   # cross-coupled, non-symmetric K
    assert c[0, 1] == pytest.approx(c[1, 0], rel=1e-3)                  # Reynolds condition: symmetric C
    assert k[3, 3] > 0 and k[4, 4] > 0 and c[3, 3] > 0 and c[4, 4] > 0   # tilt (moment) coefficients
    assert np.all(k[2] == 0) and np.all(k[5] == 0) and np.all(c[:, 5] == 0)
    # force and tilt blocks decouple for a centred, symmetric film
    assert np.max(np.abs(k[:2, 3:5])) < 1e-6 * np.max(np.abs(k[:2, :2])) / bearing.length


def test_bad_operating_points():
    bearing, omega, force, _ = thesis_bearing("wheel")
    with pytest.raises(InputError, match="omega"):
        journal_bearing_coefficients(bearing, 0.0, (0.0, -force))
    with pytest.raises(InputError, match="eccentricity"):
        journal_bearing_coefficients(bearing, omega, (0.0, -100 * force))
    with pytest.raises(InputError, match="clearance"):
        JournalBearing(0.08, 0.05, -1e-4, 0.05)


@pytest.mark.parametrize("eps", [0.3, 0.6, 0.85])
def test_short_bearing_coefficients_match_closed_forms(eps):
    # Friswell, Penny, Garvey & Lees, Dynamics of Rotating Machines (2010), short-bearing coefficients,
    # load along -y, rotation from x to y: K = (F/C) a, C = (F/(C omega)) b, h0 = (pi^2 (1-e^2) + 16 e^2)^(-3/2)
    e = eps
    h0 = 1 / (math.pi**2 * (1 - e * e) + 16 * e * e) ** 1.5
    s = math.sqrt(1 - e * e)
    a = h0 * np.array([
        [4 * (math.pi**2 * (2 - e * e) + 16 * e * e), math.pi * (math.pi**2 * (1 - e * e) ** 2 - 16 * e**4) / (e * s)],
        [-math.pi * (math.pi**2 * (1 - e * e) * (1 + 2 * e * e) + 32 * e * e * (1 + e * e)) / (e * s),
         4 * (math.pi**2 * (1 + 2 * e * e) + 32 * e * e * (1 + e * e) / (1 - e * e))]])
    bxy = -8 * (math.pi**2 * (1 + 2 * e * e) - 16 * e * e)
    b = h0 * np.array([[2 * math.pi * s * (math.pi**2 * (1 + 2 * e * e) - 16 * e * e) / e, bxy],
                       [bxy, 2 * math.pi * (math.pi**2 * (1 - e * e) ** 2 + 48 * e * e) / (e * s)]])
    bearing = JournalBearing(0.1, 0.02, 1e-4, 0.05)
    omega = 100.0
    w = short_bearing_load(bearing, omega, eps)
    res = short_bearing_coefficients(bearing, omega, (0.0, -w))
    assert res.K[:2, :2] * bearing.clearance / w == pytest.approx(a, rel=1e-5, abs=1e-6)
    assert res.C[:2, :2] * bearing.clearance * omega / w == pytest.approx(b, rel=1e-5, abs=1e-6)
