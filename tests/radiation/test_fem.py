"""Exterior Helmholtz FE (dolfinx, complex PETSc in a subprocess) against analytic radiators.

Acceptance (issue 6): analytic sigma within 0.5 dB for ka from 0.1 to 5.  The meshes here are the
coarse end of `housingfe bench radiation` so that each test takes a few seconds."""
import numpy as np
import pytest

from housingfe.errors import InputError
from housingfe.radiation import analytic, fem

C = analytic.SPEED_OF_SOUND
KA = np.array([0.1, 0.5, 1.0, 2.0, 3.0, 5.0])
A = 0.1  # m, radius of sphere and piston


def _frequencies(ka):
    return ka * C / (2 * np.pi * A)


def _db_error(results, reference):
    sigma = np.array([r.sigma for r in results])
    return 10 * np.log10(sigma / reference)


def test_pulsating_sphere_within_half_db():
    sweep = fem.helmholtz_fem_radiation(fem.sphere_geometry(A, h_m=0.03, h_surface_m=0.025), _frequencies(KA))
    err = _db_error(sweep.results, analytic.sphere_sigma(KA))
    assert np.all(abs(err) < 0.5), err
    assert np.all(abs(err) < 0.05), err  # measured: < 0.01 dB on this mesh
    # power in W against eq. 4.6 (the FE's default velocity 1 m/s is a peak phasor), not only the ratio
    p = np.array([r.power_w for r in sweep.results])
    assert p == pytest.approx(analytic.sphere_power(A, _frequencies(KA), velocity_peak_m_s=1.0), rel=0.01)


def test_rms_velocity_is_accepted_explicitly():
    # velocity_is_rms: 1 m/s rms carries the power of sqrt(2) m/s peak (eq. 4.6 with v_rms)
    f = _frequencies(np.array([1.0]))
    sweep = fem.helmholtz_fem_radiation(fem.sphere_geometry(A, h_m=0.03, h_surface_m=0.025), f, 1.0,
                                        velocity_is_rms=True)
    assert sweep.results[0].power_w == pytest.approx(analytic.sphere_power(A, f, velocity_rms_m_s=1.0)[0],
                                                     rel=0.01)
    assert sweep.results[0].mean_square_velocity == pytest.approx(1.0, rel=1e-6)


def _fibonacci_sphere(n, radius):
    i = np.arange(n) + 0.5
    z = 1 - 2 * i / n
    phi = np.pi * (1 + 5**0.5) * i
    r = np.sqrt(1 - z**2)
    return radius * np.column_stack([r * np.cos(phi), r * np.sin(phi), z])


def test_oscillating_sphere_from_sampled_velocity_within_half_db():
    # rigid sphere oscillating along z: v_n = U cos(theta), sigma = (ka)^4 / (4 + (ka)^4) (dipole);
    # the velocity enters as point samples, as the housing's surface field will.
    ka = np.array([0.5, 1.0, 2.0, 5.0])
    pts = _fibonacci_sphere(6000, A)
    v = (1e-3 + 0j) * pts[:, 2] / A
    sweep = fem.helmholtz_fem_radiation(fem.sphere_geometry(A, h_m=0.03, h_surface_m=0.02), _frequencies(ka),
                                        velocity=(pts, v))
    err = _db_error(sweep.results, ka**4 / (4 + ka**4))
    assert np.all(abs(err) < 0.5), err
    assert sweep.results[0].mean_square_velocity == pytest.approx(1e-6 / 6, rel=0.02)  # <cos^2>/2 = 1/6


def test_baffled_piston_within_half_db():
    sweep = fem.helmholtz_fem_radiation(fem.baffled_piston_geometry(A, h_m=0.035, h_surface_m=0.015),
                                        _frequencies(KA))
    err = _db_error(sweep.results, analytic.piston_sigma(KA))
    assert np.all(abs(err) < 0.5), err
    assert sweep.ndofs > 0 and all(r.seconds > 0 for r in sweep.results)


def test_bad_fem_input():
    with pytest.raises(InputError, match="truncation"):
        fem.helmholtz_fem_radiation(fem.sphere_geometry(A, 0.03), [100.0], truncation="abc")
    with pytest.raises(InputError, match="outer_radius"):
        fem.helmholtz_fem_radiation(fem.sphere_geometry(A, 0.03, outer_radius_m=0.05), [100.0])
    with pytest.raises(InputError, match="frequencies"):
        fem.helmholtz_fem_radiation(fem.sphere_geometry(A, 0.03), [-1.0])


def test_user_msh_file_gives_the_same_power(tmp_path):
    # the path the housing will take: a gmsh file with physical groups air = 1, vibrating = 10
    msh = tmp_path / "sphere.msh"
    geometry = fem.sphere_geometry(A, h_m=0.04, h_surface_m=0.03)
    f = _frequencies(np.array([0.5, 2.0]))
    built = fem.helmholtz_fem_radiation(geometry, f, save_msh=str(msh))
    loaded = fem.helmholtz_fem_radiation(fem.FemGeometry("msh", outer_radius=1.5 * A, h=0.04, path=str(msh)), f)
    assert [r.power_w for r in loaded.results] == pytest.approx([r.power_w for r in built.results], rel=1e-9)
    assert loaded.ndofs == built.ndofs


def test_breathing_box_tends_to_monopole_at_low_frequency():
    # a closed body with uniform normal velocity is a monopole of volume velocity v S when kL << 1:
    # P = rho c k^2 (v S)^2 / (8 pi), so sigma -> k^2 S / (4 pi)  (box of Sec. 4.2: 325 x 225 x 125 mm)
    edges = (0.325, 0.225, 0.125)
    S = 2 * (edges[0] * edges[1] + edges[0] * edges[2] + edges[1] * edges[2])
    f = np.array([20.0, 50.0])
    sweep = fem.helmholtz_fem_radiation(fem.box_geometry(edges, h_m=0.06, h_surface_m=0.04), f)
    k = 2 * np.pi * f / C
    err = _db_error(sweep.results, k**2 * S / (4 * np.pi))
    assert abs(err[0]) < 0.05 and abs(err[1]) < 0.15, err
    assert sweep.results[0].area_m2 == pytest.approx(S, rel=1e-9)


def test_vibrating_cap_on_sphere_against_series_within_half_db():
    # one 'plate' of a closed body: a 60 degree polar cap vibrates, the rest of the sphere is at rest;
    # many spherical harmonics, so the BGT2 truncation is not exact here (measured <= 0.07 dB)
    ka = np.array([0.1, 1.0, 2.0, 5.0])
    pts = _fibonacci_sphere(20000, A)
    v = (pts[:, 2] / A > np.cos(np.pi / 3)).astype(complex)
    sweep = fem.helmholtz_fem_radiation(fem.sphere_geometry(A, h_m=0.03, h_surface_m=0.02), _frequencies(ka),
                                        velocity=(pts, v))
    err = _db_error(sweep.results, analytic.sphere_cap_sigma(ka, np.pi / 3))
    assert np.all(abs(err) < 0.5), err
    assert np.all(abs(err) < 0.15), err
