"""Responses of the housing: surface-averaged mean-square normal velocity (exact area integral and
area-weighted sample points, eq. 5.4), transfer functions, band levels and receptances.

Conventions: loads and responses are rms phasors; <v^2>(f) = omega^2 u^H W u / S with
W = int_S (u.n)(v.n) dS, the exact area integral over the radiating surface S.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np
import ufl
from dolfinx import fem, geometry
from dolfinx import mesh as dmesh
from dolfinx.cpp import mesh as _cpp_mesh
from dolfinx.fem.petsc import assemble_matrix
from mpi4py import MPI

from housingfe import levels
from housingfe.errors import InputError
from housingfe.solvers import blocks


# ------------------------------------------------------------------------------ sample points
@dataclass
class SamplePoints:
    """N points on the radiating surface with outward normals and area weights (m^2, summing to S)."""

    points: np.ndarray
    normals: np.ndarray
    weights: np.ndarray


def _surface_facet_data(housing, surface: str):
    """Owned facets of a surface: midpoints, unit outward normals, areas, atomic group tag (all ranks)."""
    mesh = housing.mesh
    fdim = mesh.topology.dim - 1
    n_owned = mesh.topology.index_map(fdim).size_local
    mids, normals, areas, groups = [], [], [], []
    mesh.topology.create_connectivity(fdim, mesh.topology.dim)
    f2c = mesh.topology.connectivity(fdim, mesh.topology.dim)
    for value in housing.facet_tag_values(surface):
        facets = housing.facet_tags.find(value)
        facets = facets[facets < n_owned]
        if not len(facets):
            continue
        geom = _cpp_mesh.entities_to_geometry(mesh._mesh, fdim, facets, False)
        x = mesh.geometry.x[geom]
        if geom.shape[1] == 4:   # quadrilateral (dolfinx vertex order 0,1,2,3 = tensor product)
            cross = np.cross(x[:, 3] - x[:, 0], x[:, 2] - x[:, 1])
        else:
            cross = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
            cross *= 1.0
        area = np.linalg.norm(cross, axis=1) * (0.5 if geom.shape[1] in (3, 4) else 1.0)
        n = cross / np.linalg.norm(cross, axis=1)[:, None]
        mid = dmesh.compute_midpoints(mesh, fdim, facets)
        cells = np.array([f2c.links(f)[0] for f in facets])
        centroid = dmesh.compute_midpoints(mesh, mesh.topology.dim, cells)
        sign = np.sign(np.einsum("ij,ij->i", mid - centroid, n))
        mids.append(mid), normals.append(n * sign[:, None]), areas.append(area)
        groups.append(np.full(len(facets), value))
    data = [np.concatenate(a) if a else np.zeros((0, 3) if k < 2 else 0) for k, a in
            enumerate((mids, normals, areas, groups))]
    gathered = mesh.comm.allgather(data)
    out = [np.concatenate([g[k] for g in gathered]) for k in range(4)]
    # the gathered order depends on the partition: sort by position so that sample points (k-means from a
    # seeded random start) are the same on any number of ranks
    key = np.round(out[0], 9)
    order = np.lexsort((key[:, 2], key[:, 1], key[:, 0]))
    return [a[order] for a in out]


def facet_points(housing, surface: str) -> tuple[SamplePoints, np.ndarray]:
    """Every facet of a surface as a point (midpoint, outward normal, area weight), with its atomic
    group tag (one id per plate); identical on every rank."""
    mids, normals, areas, groups = _surface_facet_data(housing, surface)
    return SamplePoints(mids, normals, areas), groups


def surface_outline(housing, surface: str) -> tuple[np.ndarray, np.ndarray]:
    """The surface as a triangulation (vertices m, triangles) with shared vertices merged, all ranks."""
    mesh = housing.mesh
    fdim = mesh.topology.dim - 1
    n_owned = mesh.topology.index_map(fdim).size_local
    tris = []
    for value in housing.facet_tag_values(surface):
        facets = housing.facet_tags.find(value)
        facets = facets[facets < n_owned]
        if not len(facets):
            continue
        x = mesh.geometry.x[_cpp_mesh.entities_to_geometry(mesh._mesh, fdim, facets, False)]
        if x.shape[1] == 4:   # tensor-product quad 0-1-3-2 -> two triangles
            tris += [x[:, [0, 1, 3]], x[:, [0, 3, 2]]]
        else:
            tris.append(x[:, :3])
    local = np.concatenate(tris) if tris else np.zeros((0, 3, 3))
    corners = np.concatenate(mesh.comm.allgather(local)).reshape(-1, 3)
    vertices, index = np.unique(np.round(corners, 9), axis=0, return_inverse=True)
    return vertices, index.reshape(-1, 3)


def sample_points(housing, surface: str, count: int, seed: int = 0,
                  key: str = "analysis.harmonic.sample_points") -> SamplePoints:
    """`count` area-weighted sample points on `surface`: points are shared out among the surface's atomic
    groups (plates) in proportion to area; inside a group, area-weighted k-means on the facet midpoints
    gives clusters; each point is the facet midpoint nearest its cluster centre and carries the cluster's
    area.  Deterministic (fixed seed) and identical on every rank.  `key`: the input named when count exceeds
    the surface's facets."""
    mids, normals, areas, groups = _surface_facet_data(housing, surface)
    if count > len(areas):
        raise InputError(f"{key}: {count} points asked for, but surface {surface!r} has "
                         f"only {len(areas)} facets (one point per facet at most)")
    total = areas.sum()
    tags = np.unique(groups)
    share = np.array([areas[groups == t].sum() for t in tags]) / total * count
    alloc = np.floor(share).astype(int)
    for i in np.argsort(share - alloc)[::-1][:count - alloc.sum()]:
        alloc[i] += 1
    rng = np.random.default_rng(seed)
    pts, nrm, w = [], [], []
    for t, k in zip(tags, alloc):
        sel = np.flatnonzero(groups == t)
        k = min(k, len(sel))
        if k == 0:
            continue
        labels = _weighted_kmeans(mids[sel], areas[sel], k, rng)
        for c in range(k):
            members = sel[labels == c]
            if not len(members):
                continue
            centre = np.average(mids[members], axis=0, weights=areas[members])
            rep = members[np.argmin(np.linalg.norm(mids[members] - centre, axis=1))]
            pts.append(mids[rep]), nrm.append(normals[rep]), w.append(areas[members].sum())
    return SamplePoints(np.array(pts), np.array(nrm), np.array(w))


def _weighted_kmeans(x: np.ndarray, w: np.ndarray, k: int, rng, iterations: int = 30) -> np.ndarray:
    centres = x[rng.choice(len(x), size=k, replace=False)]
    labels = np.zeros(len(x), dtype=int)
    for _ in range(iterations):
        labels = np.argmin(((x[:, None, :] - centres[None]) ** 2).sum(-1), axis=1)
        for c in range(k):
            m = labels == c
            if m.any():
                centres[c] = np.average(x[m], axis=0, weights=w[m])
    return labels


class PointEvaluator:
    """Normal displacement of a field at sample points (each point evaluated on one owning rank)."""

    def __init__(self, V, samples: SamplePoints):
        mesh = V.mesh
        self.V, self.samples = V, samples
        tree = geometry.BoundingBoxTree(mesh, mesh.topology.dim)
        candidates = geometry.compute_collisions(tree, samples.points)
        colliding = geometry.compute_colliding_cells(mesh, candidates, samples.points)
        n_owned = mesh.topology.index_map(mesh.topology.dim).size_local
        rank = mesh.comm.rank
        mine = np.full(len(samples.points), -1)
        for i in range(len(samples.points)):
            cells = [c for c in colliding.links(i) if c < n_owned]
            if cells:
                mine[i] = cells[0]
        # each point evaluated once, by the lowest rank that owns a cell containing it (buffer Allreduce: the
        # pickled allreduce cannot take MPI.MIN of arrays)
        mine_rank = np.where(mine >= 0, rank, mesh.comm.size).astype(np.int64)
        owner = np.empty_like(mine_rank)
        mesh.comm.Allreduce(mine_rank, owner, op=MPI.MIN)
        if np.any(owner == mesh.comm.size):
            bad = samples.points[np.flatnonzero(owner == mesh.comm.size)[0]]
            raise InputError(f"analysis.harmonic: point {np.round(bad, 6).tolist()} lies outside the mesh")
        self.local = np.flatnonzero(owner == rank)
        self.cells = mine[self.local]
        self.u = fem.Function(V)

    def normal_values(self, vec) -> np.ndarray:
        """u . n at every sample point (m per unit of the vector), on all ranks."""
        vec.copy(self.u.vector)
        self.u.x.scatter_forward()
        out = np.zeros(len(self.samples.points))
        if len(self.local):
            # dolfinx 0.5.2 returns shape (3,) instead of (1, 3) for a single point: reshape
            vals = self.u.eval(self.samples.points[self.local], self.cells).reshape(len(self.local), -1)
            out[self.local] = np.einsum("ij,ij->i", vals, self.samples.normals[self.local])
        total = np.empty_like(out)
        self.V.mesh.comm.Allreduce(out, total, op=MPI.SUM)
        return total


# ------------------------------------------------------------------------------ response points
RESPONSE_POINTS = "response points"


@dataclass
class ResponsePoint:
    """A named response point snapped to the surface: requested and snapped position (m), snapping distance
    (m), outward unit normal there, and the unit directions (rows) with their labels ("x", "y", "z", "normal",
    or "given")."""

    name: str
    requested: np.ndarray
    point: np.ndarray
    distance: float
    normal: np.ndarray
    surface: str
    directions: np.ndarray
    labels: list


def _surface_triangles(housing, names) -> tuple[np.ndarray, np.ndarray]:
    """The facets of the named surfaces as straight triangles (T, 3, 3) with outward unit normals (T, 3),
    gathered on every rank (owned facets only, so each once)."""
    mesh = housing.mesh
    tdim = mesh.topology.dim
    fdim = tdim - 1
    n_owned = mesh.topology.index_map(fdim).size_local
    mesh.topology.create_connectivity(fdim, tdim)
    f2c = mesh.topology.connectivity(fdim, tdim)
    values = sorted({v for name in names for v in housing.facet_tag_values(name)})
    quads = mesh.topology.cell_type == dmesh.CellType.hexahedron
    tris, normals = [], []
    for value in values:
        facets = housing.facet_tags.find(value)
        facets = facets[facets < n_owned]
        if not len(facets):
            continue
        x = mesh.geometry.x[_cpp_mesh.entities_to_geometry(mesh._mesh, fdim, facets, False)]
        # the first 3 (4) geometry nodes are the corners; tensor-product quad 0-1-3-2 -> two triangles
        parts = [x[:, [0, 1, 3]], x[:, [0, 3, 2]]] if quads else [x[:, :3]]
        mid = dmesh.compute_midpoints(mesh, fdim, facets)
        cells = np.array([f2c.links(f)[0] for f in facets])
        inward = dmesh.compute_midpoints(mesh, tdim, cells) - mid
        for t in parts:
            n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
            n /= np.linalg.norm(n, axis=1)[:, None]
            n *= -np.sign(np.einsum("ij,ij->i", n, inward))[:, None]
            tris.append(t), normals.append(n)
    local = (np.concatenate(tris) if tris else np.zeros((0, 3, 3)),
             np.concatenate(normals) if normals else np.zeros((0, 3)))
    gathered = mesh.comm.allgather(local)
    return np.concatenate([g[0] for g in gathered]), np.concatenate([g[1] for g in gathered])


def closest_point_on_triangles(p: np.ndarray, tris: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Closest point (m) of each triangle (T, 3, 3) to the point p (3,) and its distance (m) (Ericson,
    Real-Time Collision Detection, 5.1.5: Voronoi regions of vertices, edges and face)."""
    a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = np.einsum("ij,ij->i", ab, ap), np.einsum("ij,ij->i", ac, ap)
    bp, cp = p - b, p - c
    d3, d4 = np.einsum("ij,ij->i", ab, bp), np.einsum("ij,ij->i", ac, bp)
    d5, d6 = np.einsum("ij,ij->i", ab, cp), np.einsum("ij,ij->i", ac, cp)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = va + vb + vc
        v, w = vb / denom, vc / denom
        out = a + ab * v[:, None] + ac * w[:, None]                      # inside the face
        t_ab = d1 / (d1 - d3)
        t_ac = d2 / (d2 - d6)
        t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
    # Ericson tests a, b, ab, c, ac, bc with early returns: applied here in reverse, so the earlier test wins
    cases = [
        ((va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0), b + (c - b) * t_bc[:, None]),   # edge bc
        ((vb <= 0) & (d2 >= 0) & (d6 <= 0), a + ac * t_ac[:, None]),     # edge ac
        ((d6 >= 0) & (d5 <= d6), c),                                     # vertex c
        ((vc <= 0) & (d1 >= 0) & (d3 <= 0), a + ab * t_ab[:, None]),     # edge ab
        ((d3 >= 0) & (d4 <= d3), b),                                     # vertex b
        ((d1 <= 0) & (d2 <= 0), a),                                      # vertex a
    ]
    for mask, q in cases:
        out = np.where(mask[:, None], q, out)
    return out, np.linalg.norm(out - p, axis=1)


def locate_response_points(housing, specs) -> list[ResponsePoint]:
    """Snap every ResponsePointSpec to its surface (see the spec); InputError naming the point when it lies
    farther than its tolerance from the surface or names an unknown surface.  Identical on every rank."""
    out = []
    for i, spec in enumerate(specs):
        key = f"analysis.harmonic.points.{i} ({spec.name})"
        names = [spec.surface] if spec.surface is not None else sorted(housing.facet_groups)
        for name in names:
            if name not in housing.facet_groups:
                raise InputError(f"{key}.surface: no surface {name!r} (known: {', '.join(sorted(housing.facet_groups))})")
        tris, normals = _surface_triangles(housing, names)
        p = np.asarray(spec.point, float)
        q, dist = closest_point_on_triangles(p, tris)
        k = int(np.argmin(dist))
        tol = spec.tolerance if spec.tolerance is not None else housing.element_size
        if dist[k] > tol:
            where = f"surface {spec.surface!r}" if spec.surface else "the housing's surface"
            raise InputError(f"{key}.point: {list(spec.point)} lies {dist[k]:.4g} m from {where} (more than the "
                             f"tolerance {tol:.4g} m, one element size unless given; set tolerance to accept it)")
        # the outward normal at the snapped point: mean of the triangles touching it (an edge or corner of the
        # housing has several)
        touching = dist <= dist[k] + 1e-9 * max(housing.element_size, 1e-12)
        normal = normals[touching].mean(axis=0)
        normal /= max(np.linalg.norm(normal), 1e-300)
        if spec.direction is None:
            dirs, labels = np.eye(3), ["x", "y", "z"]
        elif spec.direction == "normal":
            dirs, labels = normal[None, :], ["normal"]
        else:
            d = np.asarray(spec.direction, float)
            dirs, labels = (d / np.linalg.norm(d))[None, :], ["given"]
        out.append(ResponsePoint(spec.name, p, q[k], float(dist[k]), normal,
                                 spec.surface or "any", dirs, labels))
    return out


def response_point_samples(points: list[ResponsePoint]) -> SamplePoints:
    """One evaluation row per (point, direction), as a point set of the observer: `normals` holds the
    directions, so the kept values are the displacement along each direction (m per unit load)."""
    rows = [(rp.point, d) for rp in points for d in rp.directions]
    return SamplePoints(np.array([r[0] for r in rows]).reshape(-1, 3), np.array([r[1] for r in rows]).reshape(-1, 3),
                        np.ones(len(rows)))


# ----------------------------------------------------------------------------------- observers
@dataclass
class Reduced:
    """What the responses need of a set of vectors Psi: G = Psi^T W Psi, point values per sample set,
    projections on the load vectors (for receptances)."""

    gram: np.ndarray
    points: dict
    loads: np.ndarray


class SurfaceObserver:
    """The radiating surface (W, S), the sample-point sets and the load vectors of a model."""

    def __init__(self, model, surface: str, sample_counts, load_cases, extra_points: dict | None = None):
        housing, V = model.housing, model.V
        if surface not in housing.facet_groups:
            raise InputError(f"analysis.harmonic.surface: no surface {surface!r} "
                             f"(known: {', '.join(sorted(housing.facet_groups))})")
        ds = ufl.Measure("ds", domain=housing.mesh, subdomain_data=housing.facet_tags)(
            housing.facet_tag_values(surface))
        n = ufl.FacetNormal(housing.mesh)
        u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
        self.W = assemble_matrix(fem.form(ufl.dot(u, n) * ufl.dot(v, n) * ds))
        self.W.assemble()
        self.area = housing.mesh.comm.allreduce(fem.assemble_scalar(fem.form(1.0 * ds)), op=MPI.SUM)
        self.samples = {N: sample_points(housing, surface, N) for N in sample_counts}
        # named point sets whose complex values are kept per line (e.g. the facets of radiating plates)
        self.extra_samples = dict(extra_points or {})
        self.evaluators = {N: PointEvaluator(V, s) for N, s in {**self.samples, **self.extra_samples}.items()}
        self.load_vectors = [lc.vector for lc in load_cases]

    def reduce(self, vectors, housing_vectors=None) -> Reduced:
        """Project a list of PETSc vectors (see Reduced).  housing_vectors: the same vectors on the housing's
        FE space when `vectors` live in other DOFs (a coupled model); the load projections use `vectors`."""
        n = len(vectors)     # may be 0: a modal basis without modes below its limit and without residual
        loads = np.array([[f.dot(x) for x in vectors] for f in self.load_vectors]).reshape(len(self.load_vectors), n)
        vectors = vectors if housing_vectors is None else housing_vectors
        if n:           # the Gram matrix X^T W X as one block product (n^2 dot products took 0.3 s at n = 91)
            X = blocks.columns(vectors)
            gram = blocks.gram(X, blocks.mat_block(self.W, X), self.W.getComm())
        else:
            gram = np.zeros((0, 0))
        points = {N: np.array([ev.normal_values(x) for x in vectors]).reshape(n, len(ev.samples.points)).T
                  for N, ev in self.evaluators.items()}
        return Reduced(gram, points, loads)


class CoupledObserver(SurfaceObserver):
    """The observer of a housing coupled with its interior (housingfe.drivetrain.interior.CoupledInterior): solution vectors are
    in the coupled DOFs q; the surface quantities come from their housing part, the load projections from q,
    and `nodes` (interior node names) keep their six displacement components (m, rad) per unit load as
    extra point sets named "node <name>"."""

    def __init__(self, interior, surface: str, sample_counts, load_cases, extra_points: dict | None = None,
                 nodes=()):
        super().__init__(interior.model, surface, sample_counts, load_cases, extra_points)
        self.interior = interior
        self.nodes = {node_key(n): n for n in nodes}
        for key in self.nodes:
            self.extra_samples[key] = SimpleNamespace(weights=np.ones(6))

    def reduce(self, vectors) -> Reduced:
        red = super().reduce(vectors, [self.interior.fe_vector(q) for q in vectors])
        for key, name in self.nodes.items():
            red.points[key] = np.array([self.interior.system.node_displacement(q, name) for q in vectors]).reshape(len(vectors), 6).T
        return red


def node_key(name: str) -> str:
    """The point-set name under which a CoupledObserver keeps an interior node's values."""
    return f"node {name}"


# ----------------------------------------------------------------------------------- responses
@dataclass
class LoadResponse:
    """Per unit load, on the frequency grid: exact surface-averaged <v^2> (m^2/s^2 per unit^2), the same
    from each sample-point set, and receptances to every load case (m per N or rad-ish per N m)."""

    name: str
    kind: str
    frequencies: np.ndarray
    mean_square_velocity: np.ndarray
    point_mean_square_velocity: dict
    receptance: np.ndarray
    amplitude: np.ndarray
    extras: dict = field(default_factory=dict)

    @property
    def transfer_db(self) -> np.ndarray:
        """TF = L_v - L_load in dB (TF_F re v0/F0, TF_M re v0/(F0 l0), pressure re v0/(1 Pa))."""
        return levels.level(self.mean_square_velocity, levels.V0)

    @property
    def velocity_level_db(self) -> np.ndarray:
        """L_v (dB re 5e-8 m/s) for the scene's load amplitude and spectrum."""
        return levels.level(self.mean_square_velocity * self.amplitude**2, levels.V0)


def responses(result, observer: SurfaceObserver, load_cases) -> list[LoadResponse]:
    """Evaluate a HarmonicResult on the observer: surface <v^2>, point <v^2>, receptances."""
    f = result.frequencies
    w2 = (2 * math.pi * f) ** 2
    out = []
    for j, lc in enumerate(load_cases):
        ms = np.zeros(len(f))
        pms = {N: np.zeros(len(f)) for N in observer.samples}
        kept = {name: np.zeros((len(s.weights), len(f)), dtype=complex) for name, s in observer.extra_samples.items()}
        rec = np.zeros((len(load_cases), len(f)), dtype=complex)
        for block in result.blocks[j]:
            c = block.coeffs
            r = block.reduced
            ms[block.index] = np.real(np.einsum("kf,kl,lf->f", c.conj(), r.gram, c)) * w2[block.index] / observer.area
            for N, P in r.points.items():
                vals = P @ c
                if N in kept:
                    kept[N][:, block.index] = vals
                    continue
                wts = observer.samples[N].weights
                pms[N][block.index] = (wts @ np.abs(vals) ** 2) / wts.sum() * w2[block.index]
            rec[:, block.index] = r.loads @ c
        out.append(LoadResponse(lc.name, lc.kind, f, ms, pms, rec, lc.amplitude(f), {"point_values": kept}))
    return out


def band_line_counts(freqs: np.ndarray, bands) -> np.ndarray:
    """Number of lines in each band (lower <= f < upper).  A band with none has no level: the writers leave
    it out (a grid with df wider than the band, or lines below the lowest band)."""
    return levels.band_sum(freqs, np.ones_like(np.asarray(freqs, float)), bands).astype(int)


def band_levels(freqs: np.ndarray, mean_square: np.ndarray, f_lo: float, f_hi: float, reference: float):
    """1/3-octave band levels (dB) of a narrow-band mean-square spectrum: energy sum of the lines in each
    band (IEC 61260 base-10 edges).  Returns (bands, levels); bands with no line get nan here (one index per
    band for the callers) and are left out of every table written (see band_line_counts)."""
    bands = levels.third_octave_bands(f_lo, f_hi)
    sums = levels.band_sum(freqs, mean_square, bands)
    counts = levels.band_sum(freqs, np.ones_like(freqs), bands)
    with np.errstate(divide="ignore", invalid="ignore"):
        return bands, np.where(counts > 0, levels.level(sums, reference), np.nan)


def transfer_band_levels(resp: LoadResponse, f_lo: float, f_hi: float):
    """Band TF (dB): band L_v of the response minus band level of the load (both energy sums), so a
    flat unit spectrum gives the band of the unit-load transfer function."""
    f = resp.frequencies
    bands, lv = band_levels(f, resp.mean_square_velocity * resp.amplitude**2, f_lo, f_hi, levels.V0)
    _, lf = band_levels(f, resp.amplitude**2, f_lo, f_hi, 1.0)
    return bands, lv, lv - lf
