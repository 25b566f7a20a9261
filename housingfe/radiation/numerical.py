"""Numerical radiated power and radiation efficiency from a surface normal-velocity field.

Convention: velocities are complex *peak* phasors v_hat (m/s) of a harmonic motion at frequency f
(pass `velocity_is_rms=True` for rms phasors, as the housing's forced response uses: they are scaled by sqrt(2)).
The time-averaged power is P = 1/2 Re integral(p_hat conj(v_hat)) dS (W) and the radiation efficiency is

    sigma = P / (rho c S <v~^2>),   <v~^2> = integral(|v_hat|^2 / 2) dS / S   (eq. 4.8, rms^2 average).

Two methods:
- `rayleigh_radiated_power`: the Rayleigh integral for a plane radiator in an infinite rigid baffle,
  evaluated as P = 1/2 v^H R v with the real radiation-resistance matrix
  R_ij = rho c k^2 w_i w_j sin(k r_ij) / (2 pi k r_ij) (baffled half-space).  The kernel is smooth, so the
  result converges with the surface quadrature alone; exact for the baffled piston.
  `baffled_plates_radiated_power` applies it plate by plate (each plate baffled, plates uncorrelated):
  the cheap check of the box approximation on a housing.
- `helmholtz_fem_radiation` (closed bodies): an exterior Helmholtz FE model in dolfinx (complex PETSc,
  run in a subprocess) with a spherical perfectly matched layer, see `housingfe.radiation.fem`.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy.spatial.distance import cdist

from housingfe.errors import InputError
from housingfe.radiation.analytic import AIR_DENSITY, SPEED_OF_SOUND
from housingfe.radiation.registry import Radiator, register_radiator

_BLOCK_ENTRIES = 4_000_000  # entries of the resistance matrix built at once (~32 MB per temporary array)


@dataclass(frozen=True)
class RadiationResult:
    """Radiated power (W), radiation efficiency (-), area S (m^2), surface-averaged mean-square
    velocity <v~^2> (m^2/s^2) and wall time (s) of one frequency (Hz)."""

    frequency_hz: float
    power_w: float
    sigma: float
    area_m2: float
    mean_square_velocity: float
    seconds: float

    @property
    def radiation_index_db(self) -> float:
        """10 lg sigma in dB."""
        return float(10.0 * np.log10(self.sigma)) if self.sigma > 0 else float("-inf")


def check_surface_data(points, normals, weights, velocity):
    """Validate surface quadrature data: points (n,3) m, outward unit normals (n,3), area weights (n,)
    m^2 and complex normal velocity (n,) m/s.  Returns them as arrays; raises InputError."""
    x = np.asarray(points, dtype=float)
    n = np.asarray(normals, dtype=float)
    w = np.asarray(weights, dtype=float)
    v = np.asarray(velocity, dtype=complex)
    if x.ndim != 2 or x.shape[1] != 3 or x.shape[0] == 0:
        raise InputError("points: need an (n, 3) array of coordinates in m")
    if n.shape != x.shape:
        raise InputError("normals: need an (n, 3) array like points")
    if w.shape != (x.shape[0],) or v.shape != (x.shape[0],):
        raise InputError("weights/velocity: need one value per point")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(n)) and np.all(np.isfinite(w))
            and np.all(np.isfinite(v))):
        raise InputError("surface data: must be finite")
    if np.any(w <= 0):
        raise InputError("weights: area weights must be positive (m^2)")
    if np.any(abs(np.linalg.norm(n, axis=1) - 1.0) > 1e-6):
        raise InputError("normals: must be unit vectors")
    return x, n, w, v


def _check_frequency(frequency_hz, rho, c):
    if not np.isfinite(frequency_hz) or frequency_hz <= 0:
        raise InputError(f"frequency_hz: must be positive, got {frequency_hz!r}")
    if not (np.isfinite(rho) and rho > 0 and np.isfinite(c) and c > 0):
        raise InputError("rho, c: must be positive")


def _check_planar(points, normals, where: str, tol: float = 1e-6):
    n0 = normals[0]
    if np.any(np.linalg.norm(np.cross(normals, n0), axis=1) > tol):
        raise InputError(f"{where}: the Rayleigh integral needs a plane radiator (all normals parallel)")
    size = np.ptp(points, axis=0).max()
    if np.any(abs((points - points[0]) @ n0) > tol * max(size, 1e-12) + 1e-9):
        raise InputError(f"{where}: the Rayleigh integral needs a plane radiator (points off the plane)")


def rayleigh_power_w(points, weights, velocity, frequency_hz: float,
                     rho: float = AIR_DENSITY, c: float = SPEED_OF_SOUND) -> float:
    """Power (W) radiated into a half-space by a plane baffled radiator: 1/2 v^H R v with
    R_ij = rho c k^2 w_i w_j sinc(k r_ij) / (2 pi).  No input checks (see `rayleigh_radiated_power`)."""
    k = 2.0 * np.pi * frequency_hz / c
    q = weights * velocity  # volume velocity per point, m^3/s
    total = 0.0
    rows = max(1, _BLOCK_ENTRIES // len(points))
    for start in range(0, len(points), rows):
        block = slice(start, start + rows)
        kr = cdist(points[block], points) * k
        total += np.real(np.conj(q[block]) @ (np.sinc(kr / np.pi) @ q))
    return float(0.5 * rho * c * k**2 / (2.0 * np.pi) * total)


def _result(frequency_hz, power, weights, velocity, rho, c, seconds) -> RadiationResult:
    area = float(weights.sum())
    mean_square = float(np.sum(weights * abs(velocity) ** 2) / (2.0 * area))
    denominator = rho * c * area * mean_square
    sigma = power / denominator if denominator > 0 else float("nan")
    return RadiationResult(float(frequency_hz), power, sigma, area, mean_square, seconds)


def _as_peak(velocity, velocity_is_rms: bool):
    return velocity * np.sqrt(2.0) if velocity_is_rms else velocity


def rayleigh_radiated_power(points, normals, weights, velocity, frequency_hz: float,
                            rho: float = AIR_DENSITY, c: float = SPEED_OF_SOUND,
                            velocity_is_rms: bool = False) -> RadiationResult:
    """Radiated power and radiation efficiency of a *plane* radiator in an infinite rigid baffle
    (Rayleigh integral).  points (n,3) m, unit normals (n,3) pointing into the fluid, area weights (n,)
    m^2, complex peak (or, with velocity_is_rms, rms) normal velocity (n,) m/s, frequency in Hz, rho in
    kg/m^3, c in m/s."""
    x, n, w, v = check_surface_data(points, normals, weights, velocity)
    v = _as_peak(v, velocity_is_rms)
    _check_frequency(frequency_hz, rho, c)
    _check_planar(x, n, "points")
    t0 = time.perf_counter()
    power = rayleigh_power_w(x, w, v, frequency_hz, rho, c)
    return _result(frequency_hz, power, w, v, rho, c, time.perf_counter() - t0)


def baffled_plates_radiated_power(points, normals, weights, velocity, plate_ids, frequency_hz: float,
                                  rho: float = AIR_DENSITY, c: float = SPEED_OF_SOUND,
                                  velocity_is_rms: bool = False) -> RadiationResult:
    """Housing estimate: every plate (points sharing a plate id) radiates as if set in its own infinite
    rigid baffle and the plates are uncorrelated, so their powers add.  Inputs as in
    `rayleigh_radiated_power` plus `plate_ids` (n,) (e.g. the facet tags of the lead's housing mesh).
    This is the check of Föller's box approximation against the computed surface velocity."""
    x, n, w, v = check_surface_data(points, normals, weights, velocity)
    v = _as_peak(v, velocity_is_rms)
    _check_frequency(frequency_hz, rho, c)
    ids = np.asarray(plate_ids)
    if ids.shape != w.shape:
        raise InputError("plate_ids: need one id per point")
    t0 = time.perf_counter()
    power = 0.0
    for plate in np.unique(ids):
        sel = ids == plate
        _check_planar(x[sel], n[sel], f"plate {plate}")
        power += rayleigh_power_w(x[sel], w[sel], v[sel], frequency_hz, rho, c)
    return _result(frequency_hz, power, w, v, rho, c, time.perf_counter() - t0)


def disc_quadrature(radius_m: float, n_radial: int = 16, n_angular: int = 48, center=(0.0, 0.0, 0.0)):
    """Gauss-Legendre (radius) x trapezoidal (angle) quadrature of a disc in the plane z = center_z,
    normal +z.  Returns points (n,3) m, normals (n,3), weights (n,) m^2; the weights sum to pi a^2."""
    if radius_m <= 0 or n_radial < 1 or n_angular < 3:
        raise InputError("disc_quadrature: radius_m > 0, n_radial >= 1, n_angular >= 3 required")
    t, wt = np.polynomial.legendre.leggauss(n_radial)
    r = 0.5 * radius_m * (t + 1.0)
    wr = 0.5 * radius_m * wt * r
    theta = 2.0 * np.pi * np.arange(n_angular) / n_angular
    R, TH = np.meshgrid(r, theta, indexing="ij")
    W = np.repeat(wr[:, None], n_angular, axis=1) * (2.0 * np.pi / n_angular)
    pts = np.column_stack([R.ravel() * np.cos(TH.ravel()), R.ravel() * np.sin(TH.ravel()),
                           np.zeros(R.size)]) + np.asarray(center, dtype=float)
    normals = np.tile([0.0, 0.0, 1.0], (R.size, 1))
    return pts, normals, W.ravel()


# ------------------------------------------------------------------ as a radiation model of a housing
RADIATION_POINTS = "radiation"     # the observer's point set of the numerical radiator


def housing_plate_points(housing, surfaces):
    """Facet points (midpoint, outward normal, area weight) of the listed surfaces of a HousingMesh, and one plate
    id per point: a listed surface may fold (a flange top and its rim), so each plane part of a surface is a
    plate of its own, radiating in its own baffle.  Identical on every rank."""
    from housingfe.response.observers import SamplePoints, facet_points

    pts, nrm, w, keys = [], [], [], []
    for i, surface in enumerate(surfaces):
        sp, _ = facet_points(housing, surface)
        pts.append(sp.points), nrm.append(sp.normals), w.append(sp.weights)
        keys.append(np.column_stack([np.full(len(sp.weights), i), np.round(sp.normals, 3)]))
    _, ids = np.unique(np.concatenate(keys), axis=0, return_inverse=True)
    return SamplePoints(np.concatenate(pts), np.concatenate(nrm), np.concatenate(w)), ids.ravel()


@register_radiator("numerical")
class NumericalRadiator(Radiator):
    """The Rayleigh integral plate by plate (`baffled_plates_radiated_power`) over the computed velocity at the
    facet midpoints of the listed surfaces: L_sigma = 10 lg(P / (rho c S <v~^2>)) per line."""

    def __init__(self, surfaces, points=None, plate_ids=None):
        self.surfaces = tuple(surfaces)
        self.points, self.plate_ids = points, plate_ids

    @classmethod
    def from_spec(cls, spec, housing, material) -> NumericalRadiator:
        return cls([p.surface for p in spec.plates])

    def extra_points(self, structure) -> dict:
        """{RADIATION_POINTS: the facet points of the surfaces} on structure.housing (computed once)."""
        if self.points is None:
            self.points, self.plate_ids = housing_plate_points(structure.housing, self.surfaces)
        return {RADIATION_POINTS: self.points}

    def radiation_index_db(self, response) -> np.ndarray:
        """From the displacement per unit load at the points (response.extras["point_values"][RADIATION_POINTS],
        present when extra_points was given to the forced response) times the load amplitude (rms)."""
        if self.points is None:
            raise InputError("radiation: the numerical model needs the response at its points: pass "
                             "radiator.extra_points(structure) to the forced response")
        disp = response.extras["point_values"][RADIATION_POINTS]
        out = np.empty(len(response.frequencies))
        for k, f in enumerate(response.frequencies):
            v = 1j * 2 * np.pi * f * disp[:, k] * response.amplitude[k]
            r = baffled_plates_radiated_power(self.points.points, self.points.normals, self.points.weights, v,
                                              self.plate_ids, f, velocity_is_rms=True)
            out[k] = 10 * np.log10(max(r.sigma, 1e-30))
        return out
