"""A bore master on the bore's axis: the least-squares cylinder through the bore surface's mesh vertices (SI units).

A bearing bore's master node (housingfe.drivetrain.coupling, `[coupling.bores]` without a `centre`) belongs on the
bore's axis, mid-length.  The centre of the bounding box of the surface's nodes is there only for a complete,
evenly meshed bore: the faceted bores of the test gearbox put it 0.29-0.42 mm off the shaft line at 60 mm elements,
a half bore (split housing) puts it r/2 off, and any bore whose vertices do not reach its extremes evenly
(an uneven mesh, a partial or notched bore) moves it.  The rule
(`fit_bore`), on the surface's mesh vertices (which the mesher puts on the CAD surface; `surface_geometry`):

* The vertices' P1 nodal normals m_i = int phi_i n dA give the normal tensor T = sum m_i m_i^T / |m_i| (trace 1,
  eigenvalues l1 <= l2 <= l3).  **Flat** (l2 < FLAT_NORMAL_SPREAD l3: every normal within ~2 deg of one
  direction, e.g. a box housing's flat bearing seat or bolt patch): there is no axis to fit; the master goes to
  the area-weighted centroid sum w_i x_i / sum w_i (w_i = int phi_i dA: the exact centre of area of the faceted
  surface), `axis` is the face normal.
* **Curved**: a circular cylinder (unit axis a, a point p on it, radius R) fitted by area-weighted least squares,
  min sum w_i (d_i - R)^2 with d_i the distance of vertex i from the axis (scipy.optimize.least_squares, started
  from the normal tensor's axis (l1's eigenvector) and a weighted algebraic circle fit across it).  The master
  goes to the axis point at the middle of the surface's extent along the axis.  A fit whose area-weighted rms
  distance from the cylinder exceeds MAX_RELATIVE_RMS of R is not a bore (a bore surface with its shoulder face,
  a cone, a sphere): InputError naming the surface, the cylinder found and its deviation.  A meshed cylinder
  fits to round-off (its vertices lie on it).
* An explicit `centre` in the scene is used as given (no fit).
* The coupling (housingfe.drivetrain.interior.bore_fits) compares the fitted axis with the axis of every bearing
  the bore carries (and with the bore's own `axis` where the scene gives one): more than MAX_TILT_DEG apart is
  an InputError naming the bore, both axes and the angle.
* The run-up's bore matching (housingfe.drivetrain.bore_matching.bore_shape: which bore carries which bearing)
  reads the same fit (`surface_geometry` + `fit_points`): the package's one cylinder fit of a bore surface.

MPI: the vertices of the surface (each owned by one rank), their weights and normals are gathered on every rank
and sorted by coordinate, so every rank fits the same numbers in the same order and 1 and 2 ranks give the same
bore (to the round-off of the assembled weights).  Cost: ~6 ms per bore on the test gearbox (two surface
assemblies and the fit; the first call of a process ~30 ms more for the function space; `BoreFit.time_s`).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from housingfe.errors import InputError

FLAT_NORMAL_SPREAD = 1e-3   # l2 / l3 of the normal tensor below which a surface is flat (normals within ~2 deg)
MAX_RELATIVE_RMS = 0.05     # rms distance from the fitted cylinder / R above which a surface is not a bore
MAX_TILT_DEG = 1.0          # a bore's fitted axis vs its bearing's axis (deg); also the run-up's bore matching's


@dataclass(frozen=True)
class BoreFit:
    """A bore surface as the coupling sees it (m): kind "cylinder" or "flat" (see the module docstring), the
    master's centre, the unit axis (cylinder: the bore axis; flat: the face normal; largest component positive),
    radius (nan when flat), length (extent along the axis; 0 when flat), rms (area-weighted rms distance of
    the nodes from the cylinder / plane), box_centre (the bounding-box centre of the nodes, the old master
    position), nodes (the surface's node count), time_s (the fit's wall time on this rank, s)."""

    surface: str
    kind: str
    centre: np.ndarray
    axis: np.ndarray
    radius: float
    length: float
    rms: float
    box_centre: np.ndarray
    nodes: int
    time_s: float = 0.0

    def summary(self) -> dict:
        """JSON-able record (m, s)."""
        return {"surface": self.surface, "kind": self.kind, "centre_m": [float(x) for x in self.centre],
                "axis": [float(x) for x in self.axis], "radius_m": None if math.isnan(self.radius) else self.radius,
                "length_m": self.length, "rms_deviation_m": self.rms,
                "box_centre_m": [float(x) for x in self.box_centre], "fit_s": self.time_s}

    def tilt_deg(self, axis) -> float:
        """Angle (deg, 0..90) between this bore's axis and `axis` (any length, either sense)."""
        a = np.asarray(axis, float) / np.linalg.norm(axis)
        return math.degrees(math.acos(min(1.0, abs(float(self.axis @ a)))))


def format_vector(v) -> str:
    """(x, y, z) with 4 significant digits, for messages; components below 1e-9 of the largest print as 0."""
    v = np.asarray(v, float)
    v = np.where(np.abs(v) < 1e-9 * np.abs(v).max(initial=0.0), 0.0, v)
    return "(" + ", ".join(f"{float(x) + 0.0:.4g}" for x in v) + ")"


def _positive(a: np.ndarray) -> np.ndarray:
    """The sense of a unit vector with its largest component positive (eigh's sign is arbitrary)."""
    return a if a[np.argmax(np.abs(a))] > 0 else -a


def fit_points(x: np.ndarray, w: np.ndarray, m: np.ndarray, surface: str = "surface") -> BoreFit:
    """The BoreFit (module docstring) of a surface given by all its nodes (m; (N, 3)), their area weights
    w = int N_i dA (m^2; (N,)) and nodal normals m = int N_i n dA (m^2; (N, 3)).  Nodes of zero weight (P2
    triangle vertices) count for the axial extent and the bounding box only.  InputError when not a bore."""
    x, w, m = np.asarray(x, float), np.clip(np.asarray(w, float), 0.0, None), np.asarray(m, float)
    box_centre = (x.min(axis=0) + x.max(axis=0)) / 2
    size = np.linalg.norm(m, axis=1)
    if len(x) < 3 or w.sum() <= 0 or size.sum() <= 0:
        raise InputError(f"surface {surface!r}: fewer than three nodes or no area")
    T = np.einsum("i,ij,ik->jk", 1.0 / np.where(size > 0, size, 1.0), m, m) / size.sum()
    lam, vec = np.linalg.eigh(T)
    W = w.sum()
    if lam[1] < FLAT_NORMAL_SPREAD * lam[2]:
        normal = _positive(vec[:, 2])
        centre = w @ x / W
        rms = math.sqrt(float(w @ ((x - centre) @ normal) ** 2) / W)
        return BoreFit(surface, "flat", centre, normal, math.nan, 0.0, rms, box_centre, len(x))
    used = w > 1e-12 * w.max()
    xu, wu = x[used], w[used] / W
    axis0, e1 = vec[:, 0], vec[:, 1]
    e2 = np.cross(axis0, e1)
    c = wu @ xu
    u, v = (xu - c) @ e1, (xu - c) @ e2
    # algebraic circle (Kasa), weighted: u^2 + v^2 = 2 a u + 2 b v + d, R^2 = d + a^2 + b^2
    A = np.column_stack([2 * u, 2 * v, np.ones_like(u)]) * np.sqrt(wu)[:, None]
    (a, b, d), *_ = np.linalg.lstsq(A, (u**2 + v**2) * np.sqrt(wu), rcond=None)
    radius0 = math.sqrt(max(d + a * a + b * b, 1e-300))
    c0 = c + a * e1 + b * e2
    sw = np.sqrt(wu)

    def geometry(z):
        ax = axis0 + z[0] * e1 + z[1] * e2
        return ax / np.linalg.norm(ax), c0 + z[2] * e1 + z[3] * e2

    def residuals(z):
        ax, p = geometry(z)
        dx = xu - p
        return sw * (np.linalg.norm(dx - np.outer(dx @ ax, ax), axis=1) - z[4])

    from scipy.optimize import least_squares

    fit = least_squares(residuals, np.array([0.0, 0.0, 0.0, 0.0, radius0]),
                        x_scale=np.array([1.0, 1.0, radius0, radius0, radius0]), ftol=1e-15, xtol=1e-15, gtol=1e-15)
    axis, point = geometry(fit.x)
    axis, radius = _positive(axis), abs(float(fit.x[4]))
    rms = float(np.linalg.norm(fit.fun))              # the residuals carry sqrt(w_i / W)
    s = (x - point) @ axis
    centre = point + 0.5 * (s.min() + s.max()) * axis
    if rms > MAX_RELATIVE_RMS * radius:
        raise InputError(f"surface {surface!r} is not a cylindrical bore: the best cylinder (radius "
                         f"{radius * 1e3:.4g} mm, axis {format_vector(axis)}, through {format_vector(centre)} m) leaves an rms "
                         f"deviation of {rms * 1e3:.3g} mm, {rms / radius:.1%} of the radius (at most "
                         f"{MAX_RELATIVE_RMS:.0%}); a flat seat is taken as it is, a curved one must be a cylinder")
    return BoreFit(surface, "cylinder", centre, axis, radius, float(s.max() - s.min()), rms, box_centre, len(x))


def surface_geometry(model, surface: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every mesh vertex of a surface (coordinates (N, 3), m), its P1 area weight int phi_i dA (m^2) and its P1
    nodal normal int phi_i n dA (m^2, (N, 3)), the same arrays in the same order on every rank (collective;
    gathered, sorted by coordinate).  Vertices, not the displacement space's nodes: the mesher puts the vertices
    on the CAD surface, while the mid-edge nodes of P2 elements on a linear (faceted) geometry lie inside a bore
    by the sagitta of their edge; fitted with their (P2) weights they moved the test gearbox's bore axes 0.24-0.75
    mm off the shaft line and tilted one by 1.0 deg at 60 mm elements (docs/drivetrain.md, "Bore centres")."""
    import ufl
    from dolfinx import fem
    from dolfinx import mesh as dmesh
    from dolfinx.fem.petsc import assemble_vector
    from petsc4py import PETSc

    housing = model.housing
    mesh = housing.mesh
    V1 = fem.VectorFunctionSpace(mesh, ("CG", 1))
    facets = housing.facets(surface)
    nodes = fem.locate_dofs_topological(V1, mesh.topology.dim - 1, facets)      # owned and ghost vertices
    nodes = np.asarray(nodes[nodes < V1.dofmap.index_map.size_local])
    # the surface's facets as tag 1 of their own: one compiled form for every surface (the JIT compiles a form per
    # set of tag values, ~0.3 s each the first time)
    marked = dmesh.meshtags(mesh, mesh.topology.dim - 1, np.asarray(facets, np.int32),
                            np.ones(len(facets), np.int32))
    ds = ufl.Measure("ds", domain=mesh, subdomain_data=marked)(1)
    v = ufl.TestFunction(V1)
    unit_x = fem.Constant(mesh, np.array([1.0, 0.0, 0.0], dtype=PETSc.ScalarType))
    out = []
    for integrand in (ufl.inner(unit_x, v), ufl.inner(ufl.FacetNormal(mesh), v)):
        b = assemble_vector(fem.form(integrand * ds))
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)   # ghost parts to owners
        out.append(b.getArray(readonly=True).reshape(-1, 3)[nodes].copy())
        b.destroy()
    x, w, m = V1.tabulate_dof_coordinates()[nodes], out[0][:, 0], out[1]
    comm = mesh.comm
    if comm.size > 1:
        x, w, m = (np.concatenate(comm.allgather(a)) for a in (x, w, m))
    if len(x) < 3:
        raise InputError(f"surface {surface!r}: fewer than three mesh vertices")
    order = np.lexsort(x.T[::-1])
    return x[order], w[order], m[order]


def fit_bore(model, surface: str) -> BoreFit:
    """The BoreFit of a housing surface (collective; the same on every rank): see the module docstring."""
    t0 = time.perf_counter()
    x, w, m = surface_geometry(model, surface)
    fit = fit_points(x, w, m, surface)
    return BoreFit(**{**fit.__dict__, "time_s": time.perf_counter() - t0})
