"""Radiated power of closed (or baffled) bodies from an exterior Helmholtz FE model (dolfinx, complex).

The solve runs in a subprocess with the complex PETSc/SLEPc build (`housingfe.radiation._fem_worker`);
this module prepares the job and reads the result, so it is safe to call from a real-build process.

Model: air between the vibrating surface and a sphere of radius `outer_radius` about the origin,
Lagrange elements of `degree` on second-order (curved) tetrahedra, closed by
- "bgt2" (default): the second-order Bayliss-Gunzburger-Turkel absorbing condition on the sphere
  (exact for monopole and dipole fields; its error falls as the sphere grows), or
- "bgt1": the first-order condition dp/dr = -(1/R + i k) p (exact only for a monopole), or
- "pml": a spherical perfectly matched layer of `pml_thickness` beyond `outer_radius` (measured: poor
  at kR < 1, where the near field dominates; kept for comparison).
A plane z = 0 outside the body is a rigid baffle when the mesh is a half-space (baffled piston).

Velocity convention as in `housingfe.radiation.numerical` (docs/radiation.md, "Conventions"): the velocity
field is a complex *peak* phasor (m/s), P = 1/2 Re int p v_n* dS, sigma = P / (rho c S <v~^2>),
<v~^2> = int |v_n|^2 / 2 dS / S; rms phasors (the housing's forced response, the scenes' loads) are accepted
explicitly with `velocity_is_rms=True`.  rho and c default to `housingfe.levels` (1.2 kg/m^3, 344 m/s).
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from housingfe.errors import InputError, SolverError
from housingfe.radiation.analytic import AIR_DENSITY, SPEED_OF_SOUND
from housingfe.radiation.numerical import RadiationResult

COMPLEX_PETSC_DIR = "/usr/lib/petscdir/petsc3.18/x86_64-linux-gnu-complex"
COMPLEX_SLEPC_DIR = "/usr/lib/slepcdir/slepc3.18/x86_64-linux-gnu-complex"
TRUNCATIONS = ("bgt2", "bgt1", "pml")


@dataclass(frozen=True)
class FemGeometry:
    """Air-domain geometry for the FE model (lengths in m).

    kind: "sphere" (pulsating sphere of `radius`), "baffled_piston" (disc of `radius` on z = 0 in a
    rigid baffle, half-space z > 0), "box" (a closed box of edge lengths `box` centred at the origin, all
    faces vibrating) or "msh" (a gmsh file `path` with physical volume 1 = air, surface
    10 = vibrating, outer boundary the sphere r = outer_radius about the origin).  h: element size in the
    air, h_surface: element size on the vibrating surface."""

    kind: str
    outer_radius: float
    h: float
    radius: float = 0.0
    h_surface: float | None = None
    pml_thickness: float = 0.0
    path: str | None = None
    box: tuple | None = None

    def to_json(self) -> dict:
        data = {"kind": self.kind, "outer_radius": self.outer_radius, "h": self.h, "radius": self.radius,
                "h_surface": self.h_surface or self.h, "pml_thickness": self.pml_thickness}
        if self.path:
            data["path"] = str(self.path)
        if self.box:
            data["box"] = [float(v) for v in self.box]
        return data


def sphere_geometry(radius_m: float, h_m: float, outer_radius_m: float | None = None,
                    h_surface_m: float | None = None, pml_thickness_m: float = 0.0) -> FemGeometry:
    """A pulsating sphere of radius_m in air up to outer_radius_m (default 1.5 radius), sizes in m."""
    return FemGeometry("sphere", outer_radius_m or 1.5 * radius_m, h_m, radius_m, h_surface_m,
                       pml_thickness_m)


def baffled_piston_geometry(radius_m: float, h_m: float, outer_radius_m: float | None = None,
                            h_surface_m: float | None = None, pml_thickness_m: float = 0.0) -> FemGeometry:
    """A circular piston of radius_m in a rigid baffle z = 0, air up to outer_radius_m (default
    2 radius), sizes in m."""
    return FemGeometry("baffled_piston", outer_radius_m or 2.0 * radius_m, h_m, radius_m, h_surface_m,
                       pml_thickness_m)


def box_geometry(edges_m, h_m: float, outer_radius_m: float | None = None,
                 h_surface_m: float | None = None) -> FemGeometry:
    """A closed box (lx, ly, lz in m) centred at the origin with all faces vibrating, air up to
    outer_radius_m (default 1.5 half-diagonal); element sizes in m.  The velocity is best given as
    samples (points, values) on the faces."""
    edges = tuple(float(e) for e in edges_m)
    if len(edges) != 3 or min(edges) <= 0:
        raise InputError("box: need three positive edge lengths (m)")
    half_diagonal = 0.5 * float(np.linalg.norm(edges))
    return FemGeometry("box", outer_radius_m or 1.5 * half_diagonal, h_m, half_diagonal, h_surface_m, 0.0,
                       None, edges)


@dataclass(frozen=True)
class FemSweep:
    """Results of one FE sweep: per-frequency `RadiationResult`s (their `seconds` is assembly + solve
    of that frequency), the number of DOFs and cells, and the one-off mesh and setup times (s)."""

    results: list
    ndofs: int
    ncells: int
    mesh_seconds: float
    setup_seconds: float
    total_seconds: float = field(default=0.0)


def _check(geometry: FemGeometry, truncation: str, degree: int, frequencies: np.ndarray):
    if geometry.kind not in ("sphere", "baffled_piston", "box", "msh"):
        raise InputError(f"geometry.kind: unknown {geometry.kind!r}")
    if truncation not in TRUNCATIONS:
        raise InputError(f"truncation: choose one of {', '.join(TRUNCATIONS)}, got {truncation!r}")
    if truncation == "pml" and geometry.pml_thickness <= 0:
        raise InputError("pml_thickness: must be positive with truncation 'pml'")
    if degree not in (1, 2, 3):
        raise InputError(f"degree: 1, 2 or 3, got {degree!r}")
    if geometry.h <= 0 or (geometry.h_surface is not None and geometry.h_surface <= 0):
        raise InputError("h: element sizes must be positive")
    if geometry.kind != "msh" and not 0 < geometry.radius < geometry.outer_radius:
        raise InputError("outer_radius: must exceed the radiator radius (box: its half-diagonal)")
    if geometry.kind == "msh" and not (geometry.path and Path(geometry.path).is_file()):
        raise InputError(f"path: mesh file not found: {geometry.path!r}")
    if frequencies.ndim != 1 or frequencies.size == 0 or np.any(~np.isfinite(frequencies)) \
            or np.any(frequencies <= 0):
        raise InputError("frequencies_hz: need positive frequencies")


def complex_env() -> dict:
    """Environment selecting the complex PETSc/SLEPc build (both variables, see STACK-NOTES)."""
    env = dict(os.environ)
    env["PETSC_DIR"] = COMPLEX_PETSC_DIR
    env["SLEPC_DIR"] = COMPLEX_SLEPC_DIR
    env.setdefault("OPENBLAS_NUM_THREADS", "1")  # the machine is shared; MUMPS gains little here
    return env


def helmholtz_fem_radiation(geometry: FemGeometry, frequencies_hz, velocity=1.0, truncation: str = "bgt2",
                            degree: int = 2, rho: float = AIR_DENSITY, c: float = SPEED_OF_SOUND,
                            save_msh: str | None = None, timeout_s: float = 3600.0, *,
                            velocity_is_rms: bool = False) -> FemSweep:
    """Radiated power (W) and radiation efficiency per frequency (Hz) from an exterior Helmholtz FE model.

    velocity: a complex *peak* normal velocity phasor (m/s) uniform over the vibrating surface, or a pair
    (points (n,3) m, values (n,) complex m/s) sampled on it (nearest sample per surface DOF).
    velocity_is_rms=True (keyword only): the values are rms phasors (scaled by sqrt(2) to peak); the power
    is then twice that of the same numbers read as peak, sigma is the same.
    One mesh and one form compilation serve the whole sweep; each frequency is one sparse LU (MUMPS)."""
    scale = np.sqrt(2.0) if velocity_is_rms else 1.0
    f = np.atleast_1d(np.asarray(frequencies_hz, dtype=float))
    _check(geometry, truncation, degree, f)
    if not (rho > 0 and c > 0):
        raise InputError("rho, c: must be positive")
    with tempfile.TemporaryDirectory(prefix="housingfe-fem-") as tmp:
        tmp = Path(tmp)
        if not isinstance(velocity, (tuple, list)):
            v = complex(velocity) * scale
            velocity_spec = {"uniform": [v.real, v.imag]}
        else:
            if len(velocity) != 2:
                raise InputError("velocity: need (points (n,3), values (n,))")
            points, values = velocity
            points = np.asarray(points, dtype=float)
            values = np.asarray(values, dtype=complex) * scale
            if points.ndim != 2 or points.shape[1] != 3 or values.shape != (points.shape[0],):
                raise InputError("velocity: need (points (n,3), values (n,))")
            np.savez(tmp / "velocity.npz", points=points, values=values)
            velocity_spec = {"npz": str(tmp / "velocity.npz")}
        job = {"geometry": geometry.to_json(), "frequencies_hz": f.tolist(), "rho": rho, "c": c,
               "velocity": velocity_spec, "truncation": truncation, "degree": degree}
        if save_msh:
            job["save_msh"] = str(save_msh)
        (tmp / "job.json").write_text(json.dumps(job))
        cmd = [sys.executable, "-m", "housingfe.radiation._fem_worker", str(tmp / "job.json"),
               str(tmp / "result.json")]
        proc = subprocess.run(cmd, env=complex_env(), capture_output=True, text=True, timeout=timeout_s,
                              check=False)  # a failure is reported below with the worker's stderr
        if proc.returncode != 0:
            tail = (proc.stderr or proc.stdout).strip().splitlines()[-5:]
            raise SolverError("exterior Helmholtz FE solve failed: " + " | ".join(tail))
        out = json.loads((tmp / "result.json").read_text())
    results = [RadiationResult(r["frequency_hz"], r["power_w"], r["sigma"], r["area_m2"],
                               r["mean_square_velocity"], r["seconds"]) for r in out["results"]]
    return FemSweep(results, out["ndofs"], out["ncells"], out["mesh_seconds"], out["setup_seconds"],
                    out["mesh_seconds"] + out["setup_seconds"] + sum(r.seconds for r in results))
