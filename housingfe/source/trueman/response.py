"""Trueman (1974): branched multi-mesh torsional drive excited by transmission-error (TE) harmonics.

Model (thesis Sec. 5.2-5.4, Appendices A-I; data Appendix B, see `housingfe.source.trueman.data`): torsion only, rigid
bearings, viscous damping, teeth always in contact, only the once-per-drawroll-revolution TE harmonic.
All rotations are drawroll-referred; speeds are DRAWROLL r.p.m.; omega = 2 pi rpm / 60.

What differs from the thesis's program (on purpose):
- The whole machine is one global complex dynamic stiffness Z(omega) = K + j omega C - omega^2 M.  Each TE
  theta_E at mesh m (between gear DOFs a, b, mesh stiffness k_m + j omega c_m) is replaced by the
  equivalent equal-and-opposite torque pair +-(k_m + j omega c_m) theta_E on a and b; all meshes are solved
  together and the mesh torque is T = (k_m + j omega c_m)(theta_a - theta_b - theta_E).  The thesis
  propagates "theta = T_D / K4" from the source box by box, which is not the physical gear displacement
  (shown on a two-inertia case in tests/source/trueman/test_trueman.py).
- A machine's random TE set is drawn ONCE and kept over the whole speed sweep (the thesis re-draws at every
  speed card); the generator is numpy's PCG64 with an explicit seed.

Public API: `critical_speeds`, `mesh_transfer`, `mesh_torques`, `random_te`, `mesh_load_envelopes`,
`mesh_torque_from_receptances`, `shaft_end_stiffness`; the scene runner (`run_scene`, `bench_rows`) is
housingfe.source.trueman.run.
"""
from __future__ import annotations

import math

import numpy as np
import scipy.linalg as sl
import scipy.optimize as so
import scipy.sparse.linalg as sla

from housingfe.errors import InputError, SolverError
from housingfe.source.trueman import data
from housingfe.source.trueman.model import DriveConfig, DriveModel, build_drive, vs_drive_ratios

__all__ = [
    "DriveConfig",
    "DriveModel",
    "build_drive",
    "critical_speeds",
    "mesh_load_envelopes",
    "mesh_torque_from_receptances",
    "mesh_torques",
    "mesh_transfer",
    "random_te",
    "rpm_to_omega",
    "shaft_end_stiffness",
    "thesis_propagation_factors",
    "thesis_style_transfer",
    "vs_drive_ratios",
]


def rpm_to_omega(rpm):
    """Drawroll speed [r.p.m.] -> excitation circular frequency of the once-per-rev TE [rad/s]."""
    return 2.0 * np.pi * np.asarray(rpm, dtype=float) / 60.0


# ----------------------------------------------------------------------------------- natural frequencies
def natural_frequencies(model: DriveModel, count: int) -> np.ndarray:
    """Lowest `count` non-zero undamped natural frequencies [rad/s] of an assembled model.

    The drive line is free-free (headstock inertia, free tail), so one rigid-body mode at 0 is dropped.
    Shift-invert Lanczos about a small negative shift keeps K - sigma M regular."""
    if model.n_dof <= 200:   # small systems (tests, single boxes): dense solver, all modes
        lam = sl.eigh(model.K.toarray(), model.M.toarray(), eigvals_only=True)
    else:
        try:
            lam = sla.eigsh(model.K.tocsc(), k=count + 1, M=model.M.tocsc(), sigma=-1.0, which="LM",
                            return_eigenvectors=False)
        except sla.ArpackError as exc:  # pragma: no cover - numerical failure path
            raise SolverError(f"eigen-solution of the torsional drive failed: {exc}") from None
    omega = np.sqrt(np.abs(np.sort(lam)))
    omega = omega[omega > 1e-3 * max(omega.max(), 1.0)]
    return omega[:count]


def critical_speeds(cfg: DriveConfig, count: int = 5, max_rpm: float = 6000.0,
                    scan_step_rpm: float = 25.0) -> list[float]:
    """Critical drawroll speeds [r.p.m.] of a configuration: speeds at which the once-per-revolution
    excitation frequency equals an undamped natural frequency (the zeros of the total dynamic stiffness,
    thesis Sec. 5.4).  For a speed-independent model these are the natural frequencies themselves; for the
    rig's variable-speed drive (ratios depend on speed) each crossing omega_i(rpm) = 2 pi rpm/60 is
    bracketed on a scan and refined with Brent's method.  Returns at most `count` values below `max_rpm`."""
    if not cfg.speed_dependent:
        omega = natural_frequencies(build_drive(cfg), count)
        rpm = omega * 60.0 / (2.0 * np.pi)
        return [float(r) for r in rpm if r <= max_rpm]

    def mismatch(rpm: float, i: int) -> float:
        omega = natural_frequencies(build_drive(cfg, rpm), i + 1)
        return float(omega[i] * 60.0 / (2.0 * np.pi) - rpm)

    grid = np.arange(scan_step_rpm, max_rpm + scan_step_rpm, scan_step_rpm)
    n_modes = count + 4   # a few spare modes: higher modes may cross below max_rpm too
    table = np.array([natural_frequencies(build_drive(cfg, r), n_modes) * 60.0 / (2.0 * np.pi)
                      for r in grid])
    found = []
    for i in range(n_modes):
        diff = table[:, i] - grid
        for j in np.nonzero(np.sign(diff[:-1]) != np.sign(diff[1:]))[0]:
            found.append(so.brentq(mismatch, grid[j], grid[j + 1], args=(i,), xtol=1e-3))
    return sorted(found)[:count]


# ----------------------------------------------------------------------------------- forced response
def _solve(model: DriveModel, omega: float, rhs: np.ndarray) -> np.ndarray:
    try:
        return sla.splu(model.dynamic_stiffness(omega)).solve(rhs)
    except RuntimeError as exc:  # exactly singular (undamped at a natural frequency)
        raise SolverError(f"dynamic stiffness singular at omega = {omega:.6g} rad/s: {exc}") from None


def mesh_transfer(model: DriveModel, omega: float) -> np.ndarray:
    """Mesh-torque transfer matrix H [N m/rad] at circular frequency omega [rad/s]:
    H[i, j] = complex torque at mesh i per unit TE (1 rad, drawroll-referred) at mesh j, all other TE zero.
    Sign convention T = k_m (theta_bronze - theta_steel - theta_E): a rigidly held pair gives H = -k_m."""
    a, b = model.mesh_dofs[:, 0], model.mesh_dofs[:, 1]
    km = model.mesh_stiffness + 1j * omega * model.mesh_damping
    n_mesh = len(a)
    rhs = np.zeros((model.n_dof, n_mesh), dtype=complex)
    cols = np.arange(n_mesh)
    rhs[a, cols] = km
    rhs[b, cols] = -km
    x = _solve(model, omega, rhs)
    return km[:, None] * (x[a, :] - x[b, :]) - np.diag(km)


def mesh_torques(cfg: DriveConfig, rpm, te: np.ndarray) -> np.ndarray:
    """Complex dynamic mesh torques [N m] over drawroll speeds `rpm` for TE phasors `te`
    (shape (n_machines, n_mesh) [rad]); returns shape (n_speeds, n_machines, n_mesh)."""
    rpm = np.atleast_1d(np.asarray(rpm, dtype=float))
    te = np.atleast_2d(te)
    model = None if cfg.speed_dependent else build_drive(cfg)
    out = np.empty((len(rpm), te.shape[0], te.shape[1]), dtype=complex)
    for s, r in enumerate(rpm):
        m = build_drive(cfg, r) if cfg.speed_dependent else model
        out[s] = te @ mesh_transfer(m, float(rpm_to_omega(r))).T
    return out


def random_te(n_machines: int, n_mesh: int, err: float = data.TE_AMPLITUDE_MAX_RAD,
              seed: int = 1974) -> np.ndarray:
    """Random fundamental TE phasors [rad] (thesis eq. 5.9): amplitude ERR*A and phase 2 pi B with A, B
    independent uniform on [0, 1), one pair per mesh and machine.  Reproducible: numpy PCG64 seeded with
    `seed`; row i is machine i (the first draw is all amplitudes, then all phases)."""
    if n_machines < 1 or n_mesh < 1:
        raise InputError(f"random_te: need n_machines >= 1 and n_mesh >= 1, got {n_machines}, {n_mesh}")
    if not err > 0:
        raise InputError(f"random_te: err: must be > 0, got {err}")
    rng = np.random.Generator(np.random.PCG64(seed))
    amplitude = err * rng.random((n_machines, n_mesh))
    phase = 2.0 * np.pi * rng.random((n_machines, n_mesh))
    return amplitude * np.exp(1j * phase)


def mesh_load_envelopes(cfg: DriveConfig, rpm, te: np.ndarray) -> dict[str, np.ndarray]:
    """Monte-Carlo envelopes of |dynamic mesh torque| [N m] over machines (thesis HISTOLIMITPLUS):
    "min", "mean", "max" of shape (n_speeds, n_mesh); "rpm" echoes the speeds."""
    rpm = np.atleast_1d(np.asarray(rpm, dtype=float))
    te = np.atleast_2d(te)
    model = None if cfg.speed_dependent else build_drive(cfg)
    out = {k: np.empty((len(rpm), te.shape[1])) for k in ("min", "mean", "max")}
    for s, r in enumerate(rpm):
        m = build_drive(cfg, r) if cfg.speed_dependent else model
        mag = np.abs(te @ mesh_transfer(m, float(rpm_to_omega(r))).T)
        out["min"][s], out["mean"][s], out["max"][s] = mag.min(0), mag.mean(0), mag.max(0)
    out["rpm"] = rpm
    return out


# ----------------------------------------------------------------------------------- analytic pieces
def mesh_torque_from_receptances(te, h_aa, h_bb, k_mesh, c_mesh, omega, h_ab=0.0):
    """Mesh torque [N m] from a TE theta_E [rad] by the receptance form of the thesis's eq. 5.6a.

    h_aa, h_bb: driving-point receptances [rad/(N m)] of the two gear DOFs of the system WITHOUT this mesh
    (everything attached to each gear), h_ab their cross receptance (0 for a tree-like drive);
    k_mesh [N m/rad], c_mesh [N m s/rad], omega [rad/s].  With T = k(theta_a - theta_b - theta_E), torque -T
    on gear a and +T on gear b:  T = -theta_E / (1/(k + j omega c) + h_aa + h_bb - 2 h_ab)."""
    k_bar = k_mesh + 1j * omega * c_mesh
    return -np.asarray(te) / (1.0 / k_bar + h_aa + h_bb - 2.0 * h_ab)


def shaft_end_stiffness(k_far, omega, length, diameter, shear_modulus, density):
    """Exact dynamic stiffness [N m/rad] at the near end of a uniform solid shaft whose far end carries a
    dynamic stiffness `k_far` [N m/rad] (thesis Sec. 5.2.2 after Chenea 1953):
    K_in = (K_L - Z tan(omega L / c)) / (1 + (K_L / Z) tan(omega L / c)),
    Z = omega J_p sqrt(G rho), c = sqrt(G / rho), J_p = pi d^4 / 32.  SI inputs (m, Pa, kg/m^3, rad/s)."""
    polar = math.pi * diameter**4 / 32.0
    z = omega * polar * math.sqrt(shear_modulus * density)
    t = np.tan(omega * length / math.sqrt(shear_modulus / density))
    return (k_far - z * t) / (1.0 + k_far / z * t)


def thesis_propagation_factors(model: DriveModel, omega: float) -> np.ndarray:
    """K_B / K_4 per mesh (complex) at circular frequency omega [rad/s]: the factor by which the thesis's
    program (Appendix C) scales every INDUCED mesh torque relative to a physically consistent solution.

    The program injects theta = T_D / K_4 at the bronze gear (K_4: mesh in series with the steel-gear side,
    eq. 5.1) where the true bronze displacement is T_D / K_B (K_B: the bronze gear's own side - crossed mesh,
    layshaft, bronze gear and its drawshaft - without the mesh).  Everything the bronze gear drives responds
    in proportion to its displacement, so every remote contribution of that source is scaled by K_B / K_4.
    Both stiffnesses are driving-point values of the global model with the mesh removed."""
    z_full = model.dynamic_stiffness(omega)
    out = np.empty(len(model.mesh_dofs), dtype=complex)
    for j, (a, b) in enumerate(model.mesh_dofs):
        kbar = model.mesh_stiffness[j] + 1j * omega * model.mesh_damping[j]
        z = z_full.tolil()
        z[a, a] -= kbar
        z[b, b] -= kbar
        z[a, b] += kbar
        z[b, a] += kbar
        rhs = np.zeros((model.n_dof, 2), dtype=complex)
        rhs[a, 0] = rhs[b, 1] = 1.0
        x = sla.splu(z.tocsc()).solve(rhs)
        k_b = 1.0 / x[a, 0]
        k_4 = 1.0 / (1.0 / kbar + x[b, 1])
        out[j] = k_b / k_4
    return out


def thesis_style_transfer(model: DriveModel, omega: float) -> np.ndarray:
    """Emulation of the thesis's superposition (NOT physical; for explaining its published loads): the
    mesh-torque transfer matrix with each source's direct term exact (eq. 5.6a) and its induced terms
    scaled by K_B / K_4 (`thesis_propagation_factors`).  Same shape and convention as `mesh_transfer`."""
    h = mesh_transfer(model, omega)
    scaled = h * thesis_propagation_factors(model, omega)[None, :]
    np.fill_diagonal(scaled, np.diag(h))
    return scaled

