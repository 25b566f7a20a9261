"""Coupling the FE housing with bearings, shafts and gears: bore master nodes, springs, beams (SI units).

Every bearing bore gets a 6-DOF master node (u_x, u_y, u_z, theta_x, theta_y, theta_z in global axes; m, rad)
on its axis at the bearing centre, tied to the nodes of the bore surface in one of three ways:

* ``rbe2`` — rigid spider, exact: every bore node follows the rigid motion of the master,
  u_s = u_m + theta_m x r_s (r_s = x_s - x_m).  The bore nodes are eliminated (master–slave elimination).
* ``rbe3`` — distributing (interpolation) element, exact, adds no stiffness: the master moves with the
  weighted least-squares rigid-body fit of the bore nodes' displacements,
  u_m = R u_s, R = (A^T W A)^-1 A^T W, A_s = [I, -[r_s]x], W = the consistent surface weights int N_s dA
  (area weights).  The fit reproduces any rigid motion exactly; for a master at the weighted centroid its
  translation is the area-weighted mean.  The master DOFs are eliminated, so a spring K_b between a shaft node
  and the master becomes [R, -I]^T K_b [R, -I] among bore and shaft DOFs.
* ``star`` — the thesis' "stiff massless rods in a star": each bore node is joined to a rigid arm of the
  master by an isotropic link of stiffness ``rod_stiffness`` (N/m per rod, axial and lateral alike),
  energy 1/2 k |u_s - (u_m + theta_m x r_s)|^2.  A penalty: it tends to rbe2 as k -> infinity
  (see tests/test_coupling.py and docs/coupling.md for how the answer depends on k).

Extra nodes (masters, shaft nodes) carry 6 DOFs each and are appended after the FE DOFs.  The whole coupled
model is the transformation u_full = P q from the independent DOFs q, with K_c = P^T K_full P (likewise M, C):
no constraint rows are kept, so there are no spurious eigenvalues from constrained DOFs (the usual trouble
with MPC/penalty diagonals in eigenproblems) and the modal (SLEPc, inertia-counted) and harmonic solvers
work on (K_c, M_c) unchanged.  K_c and M_c share one sparsity pattern (the solvers add them with
SAME_NONZERO_PATTERN).

Serial only (for now): the FE matrices are gathered into scipy (a one-rank PETSc AIJ is read directly), the triple
product is done there and the result is handed back as PETSc AIJ.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from petsc4py import PETSc

from housingfe.errors import InputError

KINDS = ("rbe2", "rbe3", "star")


# ------------------------------------------------------------------------------------------------- inputs
@dataclass
class BoreConnection:
    """A bore (surface `surface` of the housing mesh) tied to a master node `name` at `centre` (m).

    axis: the bore / shaft axis (any length); `frame()` gives a rotation whose third column is the axis, for
    `housingfe.bearings.transform_stiffness`.  kind: rbe2 | rbe3 | star; rod_stiffness (N/m per rod) for star.
    """

    name: str
    surface: str
    centre: tuple
    axis: tuple = (0.0, 0.0, 1.0)
    kind: str = "rbe2"
    rod_stiffness: float | None = None

    def __post_init__(self):
        if self.kind not in KINDS:
            raise InputError(f"connection {self.name}: kind {self.kind!r} is not one of {', '.join(KINDS)}")
        if self.kind == "star" and not (self.rod_stiffness and self.rod_stiffness > 0):
            raise InputError(f"connection {self.name}: kind 'star' needs rod_stiffness > 0 (N/m)")
        if np.linalg.norm(self.axis) == 0:
            raise InputError(f"connection {self.name}: axis is the zero vector")

    def frame(self) -> np.ndarray:
        """3x3 rotation, columns = local x, y, z (z = bore axis) in global coordinates."""
        return axis_frame(self.axis)


@dataclass
class Element:
    """A lumped element among extra nodes: `nodes` names (None = ground, which is then dropped), K, M, C of size
    6 len(nodes) in global axes (N/m, N/rad, N m/rad; kg, kg m, kg m^2; N s/m ...).  K and C may be
    non-symmetric (fluid films); M must be symmetric."""

    nodes: tuple
    K: np.ndarray | None = None
    M: np.ndarray | None = None
    C: np.ndarray | None = None


@dataclass
class GearMesh:
    """Gear mesh stiffness k (N/m) along the line of action `direction` through the contact `point` (m) between
    shaft nodes a and b: the spring acts on the relative displacement of the two tooth flanks,
    delta = n . (u_a + theta_a x r_a) - n . (u_b + theta_b x r_b), r = point - node position.  C optional (N s/m)."""

    a: str
    b: str
    stiffness: float
    point: tuple
    direction: tuple
    damping: float = 0.0


@dataclass
class TieRod:
    """A Timoshenko beam between two extra nodes a and b (e.g. the thesis' tie rod between the shafts);
    section: housingfe.shafts.CircularSection, material: housingfe.shafts.Material."""

    a: str
    b: str
    section: object
    material: object = None


def spring(a: str, b: str | None, K6, C6=None) -> Element:
    """A 6x6 spring (bearing) between nodes a and b (b None: ground), K6 in global axes; C6 optional damping.
    Forces on a: -K6 (u_a - u_b)."""
    K6 = _check6(K6, f"spring {a}-{b}: K")
    C6 = None if C6 is None else _check6(C6, f"spring {a}-{b}: C")
    if b is None:
        return Element((a,), K6, None, C6)
    rel = np.hstack([np.eye(6), -np.eye(6)])
    return Element((a, b), rel.T @ K6 @ rel, None, None if C6 is None else rel.T @ C6 @ rel)


def bearing(shaft_node: str, master: str | None, K_local, axis, C_local=None) -> Element:
    """A bearing between a shaft node and a bore master (or ground): the 6x6 K (and fluid-film C) in the
    bearing frame (z = shaft axis, as housingfe.bearings returns them), rotated to global axes with
    `axis_frame(axis)`.  Rotation about the shaft axis stays free: its local row and column are zeroed."""
    from housingfe.bearings import transform_stiffness

    free_spin = np.ones(6)
    free_spin[5] = 0.0
    frame = axis_frame(axis)

    def glob(a):
        a = _check6(a, f"bearing {shaft_node}-{master}") * np.outer(free_spin, free_spin)
        return transform_stiffness(a, frame)

    return spring(shaft_node, master, glob(K_local), None if C_local is None else glob(C_local))


def point_mass(node: str, M6) -> Element:
    """A 6x6 mass matrix (kg, kg m^2) lumped on a node, e.g. RigidDisc.mass_matrix(axis)."""
    return Element((node,), None, _check6(M6, f"mass on {node}"), None)


def axis_frame(axis) -> np.ndarray:
    """Orthonormal 3x3 with third column along `axis` (columns = local x, y, z in global coordinates)."""
    z = np.asarray(axis, float) / np.linalg.norm(axis)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = helper - (helper @ z) * z
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _check6(a, what: str) -> np.ndarray:
    a = np.asarray(a, float)
    if a.shape != (6, 6) or not np.all(np.isfinite(a)):
        raise InputError(f"{what}: need a finite 6x6 matrix")
    return a


def skew(r) -> np.ndarray:
    """[r]x: skew(r) @ v = r x v."""
    x, y, z = r
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def rigid_arm(r) -> np.ndarray:
    """3x6 map from master (u, theta) to the displacement of a point at offset r (m): u + theta x r."""
    return np.hstack([np.eye(3), -skew(r)])


# ------------------------------------------------------------------------------------------------ result
@dataclass
class CoupledSystem:
    """The coupled model in its independent DOFs q (FE DOFs not eliminated, then the extra nodes' DOFs).

    K, M (PETSc AIJ, same sparsity pattern; K non-symmetric only if a non-symmetric spring was given), C
    (PETSc AIJ or None, viscous damping from the springs, N s/m).  P: scipy CSR map u_full = P q, u_full =
    [FE DOFs, 6 DOFs per extra node].  nodes: extra node name -> (position (m), full-vector offset).
    """

    K: PETSc.Mat
    M: PETSc.Mat
    C: PETSc.Mat | None
    P: sp.csr_matrix
    n_fe: int
    nodes: dict
    symmetric: bool
    timings: dict = field(default_factory=dict)

    @property
    def size(self) -> int:
        return self.P.shape[1]

    def expand(self, q: PETSc.Vec) -> np.ndarray:
        """The full displacement [FE DOFs, extra DOFs] of a reduced vector q."""
        return self.P @ q.getArray(readonly=True)

    def fe_vector(self, q: PETSc.Vec, V) -> PETSc.Vec:
        """The housing displacement of q as a PETSc Vec on the FE space V (map back to the FE model)."""
        from dolfinx import la

        out = la.create_petsc_vector(V.dofmap.index_map, V.dofmap.index_map_bs)
        out.getArray()[:] = self.expand(q)[: self.n_fe]
        return out

    def node_displacement(self, q: PETSc.Vec, name: str) -> np.ndarray:
        """(u_x, u_y, u_z, theta_x, theta_y, theta_z) (m, rad) of an extra node (master or shaft node)."""
        _, off = self.nodes[name]
        return self.P[off:off + 6] @ q.getArray(readonly=True)

    def load(self, fe_load: PETSc.Vec | None = None, node_loads: dict | None = None) -> PETSc.Vec:
        """Reduced load q-vector P^T f for an FE load vector (N) and/or 6-component loads (N, N m) on extra nodes."""
        f = np.zeros(self.P.shape[0])
        if fe_load is not None:
            f[: self.n_fe] = fe_load.getArray(readonly=True)
        for name, value in (node_loads or {}).items():
            if name not in self.nodes:
                raise InputError(f"load on unknown node {name!r} (known: {', '.join(self.nodes)})")
            off = self.nodes[name][1]
            f[off:off + 6] += np.asarray(value, float)
        out = self.K.createVecRight()
        out.getArray()[:] = self.P.T @ f
        return out


# ------------------------------------------------------------------------------------------------ coupling
def couple(model, connections=(), elements=(), shafts=None, gear_meshes=(), tie_rods=(),
           extra_nodes=None) -> CoupledSystem:
    """Couple a HousingModel with bore masters, shafts and lumped elements.

    connections: BoreConnection list (a master node per bore, named by the connection).
    shafts: {name: housingfe.shafts.Shaft}; node i of shaft `name` is called "name:i" (its discs and supports
    are included through Shaft.matrices()).
    extra_nodes: {name: position} free 6-DOF nodes without stiffness of their own (e.g. a ground-less hub).
    elements: Element list (springs, bearings, point masses) among any named nodes; gear_meshes: GearMesh
    list; tie_rods: TieRod list (beams between named nodes).
    """
    if model.V.mesh.comm.size > 1:
        raise InputError("coupling: serial only (run without mpirun)")
    t0 = time.perf_counter()
    K_fe, M_fe = _to_scipy(model.K), _to_scipy(model.M)
    n_fe = K_fe.shape[0]
    nodes = _register_nodes(n_fe, connections, shafts, extra_nodes)
    n_full = n_fe + 6 * len(nodes)
    Kx, Mx, Cx = _extra_matrices(nodes, shafts, list(elements) + [_gear_element(g, nodes) for g in gear_meshes]
                                 + [_tie_rod(t, nodes) for t in tie_rods])
    t1 = time.perf_counter()
    P, eliminated = _transformation(model, connections, nodes, n_full, Kx)

    # K and M in one complex product, Z = K + i M: P is real, so P^T Z P = K_c + i M_c, and K_c, M_c come
    # out on one sparsity pattern, which the solvers need (they add K and M with SAME_NONZERO_PATTERN).
    # Pt as CSR and products grouped as Pt @ (Z @ P): all CSR, no CSC conversion of the big matrix.
    Pt = P.T.tocsr()
    if eliminated[:n_fe].any():
        Zc = Pt @ (_pad(_complex(K_fe, M_fe), n_full) @ P)
    else:   # P is the identity on the FE DOFs (rbe3, star): the FE block passes through untouched
        Zc = _pad(_complex(K_fe, M_fe), P.shape[1])
    if Kx or Mx:
        Zc = Zc + Pt @ ((Kx.matrix(n_full) + 1j * Mx.matrix(n_full)) @ P)
    Zc.sort_indices()
    Cc = (Pt @ (Cx.matrix(n_full) @ P)).tocsr() if Cx else None
    t2 = time.perf_counter()
    K, M = _petsc(Zc, Zc.data.real), _petsc(Zc, Zc.data.imag)
    C = None
    if Cc is not None:
        Cc.sort_indices()
        C = _petsc(Cc, Cc.data)
    symmetric = Kx.symmetric()          # the FE K is symmetric; only springs (fluid films) can break it
    K.setOption(PETSc.Mat.Option.SYMMETRIC, symmetric)
    M.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    t3 = time.perf_counter()
    return CoupledSystem(K, M, C, P, n_fe, nodes, symmetric,
                         {"couple_s": t3 - t0, "extra_assembly_s": t1 - t0, "transform_s": t2 - t1,
                          "to_petsc_s": t3 - t2})


def _register_nodes(n_fe: int, connections, shafts, extra_nodes) -> dict:
    """name -> (position (m), offset of its 6 DOFs in the full vector): masters, shaft nodes, free nodes."""
    nodes = {}
    named = [(c.name, c.centre) for c in connections]
    for sname, shaft in (shafts or {}).items():
        named += [(f"{sname}:{i}", x) for i, x in enumerate(shaft.nodes)]
    named += list((extra_nodes or {}).items())
    for name, position in named:
        if name in nodes:
            raise InputError(f"coupling: node name {name!r} used twice")
        nodes[name] = (np.asarray(position, float), n_fe + 6 * len(nodes))
    return nodes


def _extra_matrices(nodes: dict, shafts, elements) -> tuple:
    """Stiffness, mass and damping of the shafts and lumped elements in the full space (COO triplets)."""
    Kx, Mx, Cx = _Triplets(), _Triplets(), _Triplets()
    for sname, shaft in (shafts or {}).items():
        ks, ms = shaft.matrices()
        idx = np.concatenate([_node_dofs(nodes, f"{sname}:{i}") for i in range(len(shaft.nodes))])
        Kx.add(idx, idx, ks)
        Mx.add(idx, idx, ms)
    for e in elements:
        idx = _element_dofs(e, nodes)
        # ground ends (None) carry no DOFs: keep the rows/columns of the real nodes only
        keep = np.concatenate([np.arange(6 * j, 6 * j + 6) for j, n in enumerate(e.nodes) if n is not None])
        for trip, mat in ((Kx, e.K), (Mx, e.M), (Cx, e.C)):
            if mat is not None:
                mat = np.asarray(mat, float)
                trip.add(idx, idx, mat[np.ix_(keep, keep)] if mat.shape[0] == 6 * len(e.nodes) else mat)
    return Kx, Mx, Cx


def _transformation(model, connections, nodes: dict, n_full: int, Kx) -> tuple[sp.csr_matrix, np.ndarray]:
    """P (u_full = P q) from the bore connections and the mask of eliminated full DOFs; star rods go into Kx."""
    n_fe = model.K.getSize()[0]
    constrained = _dirichlet_dofs(model)
    coords = model.V.tabulate_dof_coordinates()          # one row per FE node (blocked DOF index)
    rows, cols, vals = [], [], []
    eliminated = np.zeros(n_full, bool)
    slaves_used = np.zeros(n_fe, bool)
    for c in connections:
        node_ids, w = surface_nodes(model, c.surface)
        dofs = (3 * node_ids[:, None] + np.arange(3)[None, :]).ravel()
        if np.any(constrained[dofs]):
            raise InputError(f"connection {c.name}: surface {c.surface!r} has Dirichlet-constrained DOFs")
        if np.any(slaves_used[dofs]):
            raise InputError(f"connection {c.name}: surface {c.surface!r} shares nodes with another connection")
        slaves_used[dofs] = True
        r = coords[node_ids] - np.asarray(c.centre, float)
        mdofs = _node_dofs(nodes, c.name)
        if c.kind == "rbe2":          # slave rows: u_s = [I, -[r]x] (u_m, theta_m)
            arms = np.stack([rigid_arm(ri) for ri in r])                        # (N, 3, 6)
            rows.append(np.repeat(dofs, 6))
            cols.append(np.tile(mdofs, len(dofs)))
            vals.append(arms.reshape(-1, 6).ravel())
            eliminated[dofs] = True
        elif c.kind == "rbe3":        # master rows: (u_m, theta_m) = R u_s
            # nodes of zero weight (P2 triangle vertices) have zero columns in R: leaving them out keeps
            # explicit zeros out of P and of the (dense, rank-6) coupling block of the spring
            used = np.abs(w) > 1e-12 * np.abs(w).max()
            R = rbe3_matrix(r[used], w[used])                                     # (6, 3N)
            used_dofs = dofs.reshape(-1, 3)[used].ravel()
            rows.append(np.repeat(mdofs, len(used_dofs)))
            cols.append(np.tile(used_dofs, 6))
            vals.append(R.ravel())
            eliminated[mdofs] = True
        else:
            _star_rods(Kx, dofs, mdofs[0], r, c.rod_stiffness)
    independent = np.flatnonzero(~eliminated)
    col_of = np.full(n_full, -1)
    col_of[independent] = np.arange(len(independent))
    r_all = np.concatenate(rows + [independent])
    c_all = np.concatenate(cols + [independent])
    v_all = np.concatenate(vals + [np.ones(len(independent))])
    if np.any(col_of[c_all] < 0):
        raise InputError("coupling: a constraint refers to an eliminated DOF (chained constraints)")
    return sp.csr_matrix((v_all, (r_all, col_of[c_all])), shape=(n_full, len(independent))), eliminated


def rbe3_matrix(r: np.ndarray, w: np.ndarray) -> np.ndarray:
    """6 x 3N matrix R of the weighted least-squares rigid-body fit: (u_m, theta_m) = R u_s.

    r: (N, 3) node offsets from the master (m); w: (N,) weights (m^2, consistent surface areas).  Exact for
    rigid motions: R A = I, A_s = [I, -[r_s]x]."""
    A = np.concatenate([rigid_arm(ri) for ri in r])                      # (3N, 6)
    Wd = np.repeat(w, 3)
    AtW = A.T * Wd[None, :]
    G = AtW @ A
    if np.linalg.cond(G) > 1e12:
        raise InputError("rbe3: bore nodes do not determine a rigid motion (collinear or too few)")
    return np.linalg.solve(G, AtW)


def _star_rods(Kx, dofs, moff, r, k) -> None:
    """Isotropic links of stiffness k (N/m) between each bore node and the master's rigid arm."""
    mdofs = np.arange(moff, moff + 6)
    for i, ri in enumerate(r):
        B = np.hstack([np.eye(3), -rigid_arm(ri)])                        # relative displacement, 3 x 9
        idx = np.concatenate([dofs[3 * i:3 * i + 3], mdofs])
        Kx.add(idx, idx, k * B.T @ B)


def _gear_element(g: GearMesh, nodes) -> Element:
    n = np.asarray(g.direction, float)
    n /= np.linalg.norm(n)
    x = np.asarray(g.point, float)
    ga = n @ rigid_arm(x - _node(nodes, g.a)[0])
    gb = n @ rigid_arm(x - _node(nodes, g.b)[0])
    gvec = np.concatenate([ga, -gb])
    K = g.stiffness * np.outer(gvec, gvec)
    C = g.damping * np.outer(gvec, gvec) if g.damping else None
    return Element((g.a, g.b), K, None, C)


def _tie_rod(t: TieRod, nodes) -> Element:
    from housingfe.shafts import STEEL, beam_element_matrices

    k, m = beam_element_matrices(_node(nodes, t.a)[0], _node(nodes, t.b)[0], t.section, t.material or STEEL)
    return Element((t.a, t.b), k, m, None)


def _node(nodes, name):
    if name not in nodes:
        raise InputError(f"coupling: unknown node {name!r} (known: {', '.join(nodes) or 'none'})")
    return nodes[name]


def _node_dofs(nodes, name) -> np.ndarray:
    off = _node(nodes, name)[1]
    return np.arange(off, off + 6)


def _element_dofs(e: Element, nodes) -> np.ndarray:
    return np.concatenate([_node_dofs(nodes, n) for n in e.nodes if n is not None])


class _Triplets:
    """COO accumulator of dense element blocks."""

    def __init__(self):
        self.r, self.c, self.v, self.blocks = [], [], [], []

    def __bool__(self):
        return bool(self.v)

    def symmetric(self) -> bool:
        """True if every block added was symmetric (blocks are square, on the same DOFs both ways)."""
        return all(np.allclose(b, b.T, rtol=1e-12, atol=1e-12 * np.abs(b).max(initial=0.0)) for b in self.blocks)

    def add(self, ri, ci, block):
        block = np.asarray(block, float)
        self.blocks.append(block)
        self.r.append(np.repeat(ri, len(ci)))
        self.c.append(np.tile(ci, len(ri)))
        self.v.append(block.ravel())

    def matrix(self, n) -> sp.csr_matrix:
        if not self.v:
            return sp.csr_matrix((n, n))
        return sp.csr_matrix((np.concatenate(self.v), (np.concatenate(self.r), np.concatenate(self.c))),
                             shape=(n, n))


# ---------------------------------------------------------------------------------------- FE-side helpers
def _to_scipy(A: PETSc.Mat) -> sp.csr_matrix:
    indptr, indices, data = A.getValuesCSR()
    return sp.csr_matrix((data, indices, indptr), shape=A.getSize())


def _complex(K: sp.csr_matrix, M: sp.csr_matrix) -> sp.csr_matrix:
    """K + i M; without a sparse addition when both share one pattern (dolfinx assembles them so)."""
    if np.array_equal(K.indptr, M.indptr) and np.array_equal(K.indices, M.indices):
        return sp.csr_matrix((K.data + 1j * M.data, K.indices, K.indptr), shape=K.shape)
    return K + 1j * M


def _pad(A: sp.csr_matrix, n: int) -> sp.csr_matrix:
    """A in the top-left corner of an n x n matrix (extra DOFs appended)."""
    m = A.shape[0]
    indptr = np.concatenate([A.indptr, np.full(n - m, A.indptr[-1])])
    return sp.csr_matrix((A.data, A.indices, indptr), shape=(n, n))


def _dirichlet_dofs(model) -> np.ndarray:
    """Boolean mask of Dirichlet-constrained FE DOFs (unrolled indices)."""
    n = model.V.dofmap.index_map.size_local * model.V.dofmap.index_map_bs
    mask = np.zeros(n, bool)
    for bc in model.bcs:
        idx, _ = bc.dof_indices()
        mask[idx[idx < n]] = True
    return mask


def surface_nodes(model, surface: str) -> tuple[np.ndarray, np.ndarray]:
    """Nodes (blocked DOF indices) of a surface and their consistent area weights int N_i dA (m^2)."""
    import ufl
    from dolfinx import fem
    from dolfinx.fem.petsc import assemble_vector

    housing, V = model.housing, model.V
    facets = housing.facets(surface)
    nodes = fem.locate_dofs_topological(V, housing.mesh.topology.dim - 1, facets)
    ds = ufl.Measure("ds", domain=housing.mesh, subdomain_data=housing.facet_tags)
    v = ufl.TestFunction(V)
    one = fem.Constant(housing.mesh, np.array([1.0, 0.0, 0.0], dtype=PETSc.ScalarType))
    # int N_i dA: the x-component of the load vector of a unit x-traction (P2 triangle vertices get 0)
    b = assemble_vector(fem.form(ufl.inner(one, v) * ds(housing.facet_tag_values(surface))))
    w = b.getArray(readonly=True)[3 * nodes].copy()
    b.destroy()
    if len(nodes) < 3:
        raise InputError(f"surface {surface!r}: fewer than three nodes")
    return np.asarray(nodes), w


def _petsc(pattern: sp.csr_matrix, values: np.ndarray) -> PETSc.Mat:
    """A sequential PETSc AIJ with the (sorted) CSR structure of `pattern` and the given values."""
    n = pattern.shape[0]
    # WithArrays: PETSc takes the arrays as they are (no row-by-row insertion); petsc4py keeps them alive.
    A = PETSc.Mat().createAIJWithArrays(size=(n, n), csr=(pattern.indptr.astype(PETSc.IntType),
                                                          pattern.indices.astype(PETSc.IntType),
                                                          np.ascontiguousarray(values)), comm=PETSc.COMM_SELF)
    A.assemble()
    return A


def surface_centre(model, surface: str) -> np.ndarray:
    """Centre (m) of the bounding box of a surface's nodes (a bore: on the axis, mid-plate)."""
    nodes, _ = surface_nodes(model, surface)
    x = model.V.tabulate_dof_coordinates()[nodes]
    return (x.min(axis=0) + x.max(axis=0)) / 2
