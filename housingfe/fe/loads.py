"""Load cases as FE load vectors: forces and couples spread over small surface patches, pressures.

Each load vector is assembled for a unit amplitude (1 N, 1 N m, 1 Pa); amplitudes and spectra scale it per
frequency.  Responses per unit load are transfer functions directly (F0 = 1 N, l0 = 1 m).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import ufl
from dolfinx import fem
from dolfinx import mesh as dmesh
from dolfinx.fem.petsc import assemble_vector
from mpi4py import MPI
from petsc4py import PETSc

from housingfe.errors import InputError


@dataclass
class LoadCase:
    """A load vector for unit amplitude, with its spectrum.

    vector: PETSc Vec (N per unit load); kind: force | moment | pressure; amplitude(f): rms load (N, N m
    or Pa) at frequencies f (Hz); patch_area: loaded area (m^2); centre: patch centroid (m)."""

    name: str
    kind: str
    vector: PETSc.Vec
    spec: object
    patch_area: float
    centre: np.ndarray

    def amplitude(self, frequencies) -> np.ndarray:
        """rms load amplitude at the given frequencies (N, N m or Pa)."""
        f = np.asarray(frequencies, dtype=float)
        scale = self.spec.amplitude
        if self.spec.spectrum is None:
            return np.full(f.shape, scale)
        table = self.spec.spectrum
        return scale * np.interp(np.log(f), np.log(table.frequencies), table.values)


def assemble_load(spec, housing, V, bcs) -> LoadCase:
    """The load vector of one scene load (unit amplitude); Dirichlet rows are zeroed."""
    from dolfinx.fem.petsc import set_bc

    if spec.surface not in housing.facet_groups:
        raise InputError(f"loads.{spec.name}.surface: no surface {spec.surface!r} "
                         f"(known: {', '.join(sorted(housing.facet_groups))})")
    facets = housing.facets(spec.surface)
    v = ufl.TestFunction(V)
    mesh = V.mesh
    x = ufl.SpatialCoordinate(mesh)
    if spec.kind == "pressure":
        ds = ufl.Measure("ds", domain=mesh, subdomain_data=housing.facet_tags)(housing.facet_tag_values(spec.surface))
        form = -ufl.inner(ufl.FacetNormal(mesh), v) * ds
        area, first, _ = _moments(x, ds, mesh.comm)
        centre = first / area
    else:
        point = np.asarray(spec.point, dtype=float)
        _check_point_on_surface(mesh, facets, point, spec)
        patch = _patch(mesh, facets, point, spec.radius)
        ds = ufl.Measure("ds", domain=mesh, subdomain_data=patch)(1)
        area, first, second = _moments(x, ds, mesh.comm)
        centre = first / area
        direction = np.asarray(spec.direction, dtype=float)
        direction = direction / np.linalg.norm(direction)
        if spec.kind == "force":
            traction = fem.Constant(mesh, PETSc.ScalarType(direction / area))
        else:
            # area inertia tensor about the centroid: J = int (|r|^2 I - r r^T), r = x - c
            rr = second - area * np.outer(centre, centre)
            J = np.trace(rr) * np.eye(3) - rr
            theta = np.linalg.solve(J, direction)      # rotation-like field carrying a unit couple
            traction = ufl.cross(fem.Constant(mesh, PETSc.ScalarType(theta)),
                                 x - fem.Constant(mesh, PETSc.ScalarType(centre)))
        form = ufl.inner(traction, v) * ds
    vec = assemble_vector(fem.form(form))
    vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    set_bc(vec, bcs)
    return LoadCase(spec.name, spec.kind, vec, spec, area, centre)


# Floor of the on-surface tolerance (m): scene coordinates are usually given to the millimetre.
POINT_TOLERANCE_FLOOR = 1e-3


def point_tolerance(spec) -> float:
    """How far (m) a force's or moment's point may lie from its surface: the load's own `radius`, at least
    1 mm.  The patch is by definition the surface within `radius` of the point, so a point farther away than
    that has no patch of its own; the fallback to the nearest facets in `_patch` is for coarse meshes only
    (a facet's midpoint can lie beyond `radius` though the surface passes through the point)."""
    return max(float(spec.radius), POINT_TOLERANCE_FLOOR)


def surface_distance_bound(mesh, facets: np.ndarray, point: np.ndarray) -> float:
    """A lower bound of the distance (m) from `point` to the union of `facets` (all ranks): the minimum over
    the facets of |point - midpoint| minus the facet's largest midpoint-to-node distance.  It is <= 0 for a
    point on the surface however coarse the mesh, and within a facet size of the true distance otherwise."""
    fdim = mesh.topology.dim - 1
    bound = np.inf
    if len(facets):
        from dolfinx.cpp.mesh import entities_to_geometry

        mids = dmesh.compute_midpoints(mesh, fdim, facets)
        cpp_mesh = getattr(mesh, "_mesh", mesh)  # dolfinx 0.5.2's Python Mesh wraps the C++ one
        nodes = entities_to_geometry(cpp_mesh, fdim, np.ascontiguousarray(facets, dtype=np.int32), False)
        reach = np.linalg.norm(mesh.geometry.x[nodes] - mids[:, None, :], axis=2).max(axis=1)
        bound = float(np.min(np.linalg.norm(mids - point, axis=1) - reach))
    return mesh.comm.allreduce(bound, op=MPI.MIN)


def _check_point_on_surface(mesh, facets, point, spec) -> None:
    """InputError naming loads.<name>.point when the point lies farther than `point_tolerance` from the
    load's surface (before, the load silently moved to the nearest facets, metres away)."""
    distance = surface_distance_bound(mesh, facets, point)
    tol = point_tolerance(spec)
    if distance > tol:
        raise InputError(f"loads.{spec.name}.point: {list(spec.point)} lies at least {distance * 1e3:.0f} mm "
                         f"from surface {spec.surface!r} (allowed: the load radius, {tol * 1e3:.0f} mm); "
                         "put the point on the surface")


def _integrate(expr, comm) -> float:
    return comm.allreduce(fem.assemble_scalar(fem.form(expr)), op=MPI.SUM)


def _moments(x, ds, comm):
    """Area (m^2), first moments int x (m^3) and second moments int x x^T (m^4) over ds.  The forms hold
    no numbers, so they are compiled once and reused for every patch."""
    area = _integrate(1.0 * ds, comm)
    first = np.array([_integrate(x[i] * ds, comm) for i in range(3)])
    second = np.array([[_integrate(x[i] * x[j] * ds, comm) for j in range(3)] for i in range(3)])
    return area, first, second


def _patch(mesh, facets: np.ndarray, point: np.ndarray, radius: float):
    """MeshTags (value 1) of the surface facets whose midpoints lie within `radius` of `point`; if none
    does (coarse mesh), the facets nearest to the point."""
    fdim = mesh.topology.dim - 1
    mids = dmesh.compute_midpoints(mesh, fdim, facets) if len(facets) else np.zeros((0, 3))
    dist = np.linalg.norm(mids - point, axis=1)
    chosen = facets[dist <= radius]
    if mesh.comm.allreduce(len(chosen), op=MPI.SUM) == 0:
        nearest = mesh.comm.allreduce(float(dist.min()) if len(dist) else np.inf, op=MPI.MIN)
        if not np.isfinite(nearest):
            raise InputError("loads: the load surface has no facets")
        chosen = facets[dist <= nearest * (1 + 1e-9) + 1e-12]
    chosen = np.unique(chosen).astype(np.int32)
    return dmesh.meshtags(mesh, fdim, chosen, np.ones(len(chosen), dtype=np.int32))
