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
  (see tests/drivetrain/test_coupling.py and docs/coupling.md for how the answer depends on k).

Extra nodes (masters, shaft nodes) carry 6 DOFs each and are appended after the FE DOFs.  A torsion node (e.g.
the coupling of a drive line: a polar inertia between two torsion springs) has ONE independent DOF, its rotation
phi (rad) about a unit axis a: its six DOFs are u = 0, theta = a phi, constraints of the same u_full = P q kind
(its translations are rows of P without entries, its rotations refer to the one kept rotation component, the one
of largest |a_k|: theta_j = (a_j / a_k) theta_k).  So a node that only a torsion spring and a polar inertia
touch gets no penalty springs and no arbitrary diagonal values for the DOFs nothing holds.  The whole coupled
model is the transformation u_full = P q from the independent DOFs q, with K_c = P^T K_full P (likewise M, C):
no constraint rows are kept, so there are no spurious eigenvalues from constrained DOFs (the usual trouble
with MPC/penalty diagonals in eigenproblems) and the modal (SLEPc, inertia-counted) and harmonic solvers
work on (K_c, M_c) unchanged.

MPI: everything is PETSc, on any number of ranks, with the same answer (to round-off) on each.
* Full layout (u_full): every rank owns its FE DOFs in dolfinx's global numbering (index_map.local_range * bs,
  the numbering of model.K); the last rank also owns the 6 DOFs of every extra node, after its FE DOFs (global
  index n_fe + 6 i for node i).  K_full, M_full are MPIAIJ from the local CSR rows of the FE matrices padded with
  the extra rows, plus the element / star-rod triplets sent to the ranks owning their rows.  K_full and M_full
  get one sparsity pattern (an explicit zero in one wherever the other has an entry).
* q layout: every rank owns its independent (not eliminated) FE DOFs in order; the last rank then also the
  independent extra DOFs.  P is MPIAIJ (rows: full layout, columns: q layout).  RBE2 rows (bore FE DOFs, on
  their owners) refer to the master's columns (last rank); RBE3 rows (master DOFs, last rank) refer to the bore
  DOFs on any rank: bore coordinates, area weights and q indices of the owned bore nodes are gathered on the
  last rank, which forms R.
* K_c = P^T K_full P by MatPtAP (C_c likewise); M_c re-runs K_c's product on M_full's values (MAT_REUSE_MATRIX:
  numeric phase only), so K_c and M_c share one sparsity pattern by construction (checked after the products:
  the solvers add them with SAME_NONZERO_PATTERN).  On one rank MatPtAP uses the "rap" algorithm (4x faster
  here) unless -matptap_via is set.
1, 2 and 3 ranks agree to ~1e-10 (frequencies, static solutions; tests/drivetrain/test_coupling.py, docs/coupling.md).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from petsc4py import PETSc

from housingfe.errors import InputError, SolverError

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
    section: housingfe.drivetrain.shafts.CircularSection, material: housingfe.drivetrain.shafts.Material."""

    a: str
    b: str
    section: object
    material: object = None


def spring(a: str, b: str | None, K6, C6=None, offset=None) -> Element:
    """A 6x6 spring (bearing) between nodes a and b (b None: ground), K6 in global axes; C6 optional damping.
    Forces on a: -K6 (u_a - u_b).  offset: position of a minus position of b (m) when the two nodes are not at
    one point (a shaft node on the nominal shaft line, a bore master at the centre measured on the mesh): b's
    side then reaches a's point through a rigid arm, u_b + theta_b x offset, so that a rigid motion of the whole
    model strains no spring (a zero-length spring between points 0.3-0.4 mm apart held the free test gearbox's
    rotations at 0.04-0.19 Hz, found as a rigid-body mode that was not one: docs/stability.md)."""
    K6 = _check6(K6, f"spring {a}-{b}: K")
    C6 = None if C6 is None else _check6(C6, f"spring {a}-{b}: C")
    if b is None:
        return Element((a,), K6, None, C6)
    arm = np.eye(6)
    if offset is not None:
        arm[:3] = rigid_arm(np.asarray(offset, float))
    rel = np.hstack([np.eye(6), -arm])
    return Element((a, b), rel.T @ K6 @ rel, None, None if C6 is None else rel.T @ C6 @ rel)


def bearing(shaft_node: str, master: str | None, K_local, axis, C_local=None, offset=None) -> Element:
    """A bearing between a shaft node and a bore master (or ground): the 6x6 K (and fluid-film C) in the
    bearing frame (z = shaft axis, as housingfe.bearings returns them), rotated to global axes with
    `axis_frame(axis)`.  Rotation about the shaft axis stays free: its local row and column are zeroed.
    offset: shaft node position minus master position (m); the bearing acts at the shaft node, the master
    reaches it by a rigid arm (`spring`)."""
    from housingfe.bearings import transform_stiffness

    free_spin = np.ones(6)
    free_spin[5] = 0.0
    frame = axis_frame(axis)

    def glob(a):
        a = _check6(a, f"bearing {shaft_node}-{master}") * np.outer(free_spin, free_spin)
        return transform_stiffness(a, frame)

    return spring(shaft_node, master, glob(K_local), None if C_local is None else glob(C_local),
                  offset=None if master is None else offset)


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

    K, M (PETSc AIJ on the q layout, same sparsity pattern; K non-symmetric only if a non-symmetric spring was
    given), C (PETSc AIJ or None, viscous damping from the springs, N s/m).  P: PETSc AIJ, u_full = P q
    (rows: the full layout [FE DOFs, 6 DOFs per extra node], columns: q; see the module docstring for the
    parallel layouts).  n_fe: global number of FE DOFs.  nodes: extra node name -> (position (m), global offset
    in the full vector).  size: global number of q DOFs.  independent: this rank's full-layout rows that are its
    q entries, in order.  timings (s): extra_assembly_s (lumped parts, bore nodes, star rods), to_petsc_s
    (K_full, M_full, C_full), transform_s (P, the triple products, the pattern check), couple_s (all).  All
    methods are collective (call them on every rank) and give the same answer on any number of ranks.
    """

    K: PETSc.Mat
    M: PETSc.Mat
    C: PETSc.Mat | None
    P: PETSc.Mat
    n_fe: int
    nodes: dict
    symmetric: bool
    timings: dict = field(default_factory=dict)
    independent: np.ndarray | None = field(default=None, repr=False)   # local full rows that are the local q

    @property
    def size(self) -> int:
        return self.P.getSize()[1]

    @property
    def _comm(self):
        return self.P.getComm().tompi4py()

    def _full_range(self) -> tuple[int, int, int]:
        """(first global full row of this rank, its number of FE rows, its number of full rows)."""
        lo, hi = self.P.getOwnershipRange()
        return lo, min(hi, self.n_fe) - lo, hi - lo

    def expand(self, q: PETSc.Vec) -> PETSc.Vec:
        """The full displacement u_full = P q (a PETSc Vec in the full layout: on every rank its FE DOFs, on the
        last rank then the extra DOFs, 6 per node at the offsets of `nodes`)."""
        u = self.P.createVecLeft()
        self.P.mult(q, u)
        return u

    def restrict(self, full: PETSc.Vec) -> PETSc.Vec:
        """The q vector of a full-layout vector: its independent entries (exact, restrict(expand(q)) = q, for
        vectors that satisfy the constraints, e.g. rigid-body fields)."""
        q = self.P.createVecRight()
        q.getArray()[:] = full.getArray(readonly=True)[self.independent]
        return q

    def fe_vector(self, q: PETSc.Vec, V) -> PETSc.Vec:
        """The housing displacement of q as a PETSc Vec on the FE space V, ghosts updated (map back to the FE
        model)."""
        from dolfinx import la

        u = self.expand(q)
        out = la.create_petsc_vector(V.dofmap.index_map, V.dofmap.index_map_bs)
        # the housing vectors dropped since the last call (release_fe_garbage): cleaned here, while `out` keeps
        # their communicator alive
        release_petsc_garbage(out.getComm())
        _, n_loc_fe, _ = self._full_range()
        out.getArray()[:] = u.getArray(readonly=True)[:n_loc_fe]
        out.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        u.destroy()
        return out

    def node_displacement(self, q: PETSc.Vec, name: str) -> np.ndarray:
        """(u_x, u_y, u_z, theta_x, theta_y, theta_z) (m, rad) of an extra node (master or shaft node), the same
        numpy (6,) array on every rank."""
        off = _node(self.nodes, name)[1]
        u = self.expand(q)
        comm = self._comm
        value = None
        if comm.rank == comm.size - 1:
            lo = self._full_range()[0]
            value = u.getArray(readonly=True)[off - lo:off - lo + 6].copy()
        u.destroy()
        return comm.bcast(value, root=comm.size - 1)

    def load(self, fe_load: PETSc.Vec | None = None, node_loads: dict | None = None) -> PETSc.Vec:
        """Reduced load q-vector P^T f for an FE load vector (N; a PETSc Vec on the FE space, owned entries
        complete) and/or 6-component loads (N, N m) on extra nodes (given alike on every rank, added once)."""
        loads = {}
        for name, value in (node_loads or {}).items():
            if name not in self.nodes:
                raise InputError(f"load on unknown node {name!r} (known: {', '.join(self.nodes)})")
            value = np.asarray(value, float)
            if value.shape != (6,):
                raise InputError(f"load on node {name!r}: need 6 components (F_x, F_y, F_z, M_x, M_y, M_z)")
            loads[name] = value
        comm = self._comm
        lo, n_loc_fe, _ = self._full_range()
        f = self.P.createVecLeft()
        f.set(0.0)
        arr = f.getArray()
        if fe_load is not None:
            fe = fe_load.getArray(readonly=True)
            if comm.allreduce(len(fe) != n_loc_fe):
                raise InputError("coupling: the FE load vector is not on the coupled model's FE space")
            arr[:n_loc_fe] = fe
        if comm.rank == comm.size - 1:
            for name, value in loads.items():
                off = self.nodes[name][1] - lo
                arr[off:off + 6] += value
        out = self.P.createVecRight()
        self.P.multTranspose(f, out)
        f.destroy()
        return out

    def rigid_body_vectors(self, V) -> list[PETSc.Vec]:
        """Six q vectors: unit translations x, y, z and unit rotations about the global x, y, z axes through the
        origin of the whole coupled system (every FE node, every extra node: u = theta x r, rotation DOFs =
        theta).  With the rigid modes of (K, M): housingfe.solvers.modal.rigid_body_mass_properties(M, modes,
        system.rigid_body_vectors(V)) gives the total mass and centre of gravity.  A torsion node keeps only its
        rotation about its axis (its constraints hold no rigid translation; it carries no translational mass)."""
        lo, n_loc_fe, _ = self._full_range()
        bs = V.dofmap.index_map_bs
        x = V.tabulate_dof_coordinates()[:n_loc_fe // bs]
        out = []
        for i in range(6):
            full = self.P.createVecLeft()
            arr = full.getArray()
            arr[:] = 0.0
            axis = np.eye(3)[i % 3]
            fe = np.zeros((len(x), bs))
            fe[:, :3] = axis if i < 3 else np.cross(axis, x)
            arr[:n_loc_fe] = fe.ravel()
            for position, off in self.nodes.values():
                if lo <= off < lo + len(arr):
                    arr[off - lo:off - lo + 6] = (np.concatenate([axis, np.zeros(3)]) if i < 3
                                                  else np.concatenate([np.cross(axis, position), axis]))
            out.append(self.restrict(full))
            full.destroy()
        return out


# ------------------------------------------------------------------------------------------------ coupling
def couple(model, connections=(), elements=(), shafts=None, gear_meshes=(), tie_rods=(),
           extra_nodes=None, torsion_nodes=None) -> CoupledSystem:
    """Couple a HousingModel with bore masters, shafts and lumped elements (collective: call on every rank).

    connections: BoreConnection list (a master node per bore, named by the connection).
    shafts: {name: housingfe.drivetrain.shafts.Shaft}; node i of shaft `name` is called "name:i" (its discs and supports
    are included through Shaft.matrices()).
    extra_nodes: {name: position} free 6-DOF nodes without stiffness of their own (e.g. a ground-less hub).
    torsion_nodes: {name: (position, axis)} nodes with one DOF, the rotation about `axis` (module docstring):
    elements on them act through u = 0, theta = axis phi.
    elements: Element list (springs, bearings, point masses) among any named nodes; gear_meshes: GearMesh
    list; tie_rods: TieRod list (beams between named nodes).
    """
    t0 = time.perf_counter()
    release_petsc_garbage(model.K.getComm())
    n_fe = model.K.getSize()[0]
    torsion_nodes = {name: (position, _unit(axis, f"torsion node {name}"))
                     for name, (position, axis) in (torsion_nodes or {}).items()}
    nodes = _register_nodes(n_fe, connections, shafts, {**(extra_nodes or {}),
                                                       **{n: x for n, (x, _) in torsion_nodes.items()}})
    lay = _Layout(model, 6 * len(nodes))
    # the lumped parts are small: every rank builds them (same checks, same symmetry flag), the last adds them
    Kx, Mx, Cx = _extra_matrices(nodes, shafts, list(elements) + [_gear_element(g, nodes) for g in gear_meshes]
                                 + [_tie_rod(t, nodes) for t in tie_rods])
    symmetric = Kx.symmetric()          # the FE K is symmetric; only springs (fluid films) can break it
    bores = _bores(model, lay, connections)
    stars = _Triplets()
    for c, b in zip(connections, bores):
        if c.kind == "star":
            _star_rods(stars, lay.fe_start + b.dofs, nodes[c.name][1], b.r, c.rod_stiffness)
    t1 = time.perf_counter()

    K_full, M_full = _full_matrices(model, lay, Kx, Mx, stars)
    C_full = _full_damping(lay, Cx) if lay.comm.allreduce(bool(Cx)) else None
    t2 = time.perf_counter()

    P, independent = _transformation(lay, connections, bores, nodes, torsion_nodes)
    K, M = _triple_products(K_full, M_full, P)
    C = _ptap(C_full, P) if C_full is not None else None
    for A in (K_full, M_full, C_full):
        if A is not None:
            A.destroy()
    _check_same_pattern(lay.comm, K, M)
    K.setOption(PETSc.Mat.Option.SYMMETRIC, symmetric)
    M.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    t3 = time.perf_counter()
    return CoupledSystem(K, M, C, P, n_fe, nodes, symmetric,
                         {"couple_s": t3 - t0, "extra_assembly_s": t1 - t0, "to_petsc_s": t2 - t1,
                          "transform_s": t3 - t2}, independent)


def release_petsc_garbage(comm) -> None:
    """Free the PETSc objects of `comm` that Python has dropped (collective: call on every rank of comm).

    petsc4py 3.18 does not destroy a Mat/Vec/KSP when its Python object dies: it parks it in a per-communicator
    garbage list (PetscObjectDelayedDestroy, on one rank too) until PETSc.garbage_cleanup(comm) runs.  Nothing
    else calls it, so every coupled system (K, M, P: ~55 MB on the 60 mm test gearbox mesh) and whatever a
    re-analysis dropped stayed in the process for good.  A re-analysis couples again, so cleaning here bounds
    the garbage to what was dropped since the last coupling."""
    PETSc.garbage_cleanup(comm)


def hold_petsc_comm(comm):
    """A one-entry-per-rank PETSc vector on `comm` (collective): while it lives, so does PETSc's communicator, and
    release_petsc_garbage(probe.getComm()) is safe however often it runs; destroy() it after (at once, not parked).

    A handle from obj.getComm() does not keep the communicator: once a garbage cleanup has freed the last object on
    it PETSc frees the communicator too, and cleaning through the handle again segfaulted (petsc4py 3.18)."""
    return PETSc.Vec().createMPI((1, PETSc.DECIDE), comm=comm)


def release_fe_garbage(V) -> None:
    """Free the dropped PETSc vectors of the FE space V (dolfinx la.create_petsc_vector, fem.Function.vector;
    collective on V's mesh).

    dolfinx 0.5.2 creates them on the communicator of V's IndexMap, which it duplicates from the mesh's: neither
    the matrices' communicator (release_petsc_garbage in `couple`) nor the mesh's reaches their garbage list, so
    every housing field dropped stayed (the 40-90 housing fields of each coupled basis' Ritz vectors: ~6 MB on the
    80 mm test gearbox mesh, per basis built).  That communicator is PETSc's while an object lives on it and is
    not exposed by dolfinx, so a probe vector holds it for the cleanup (a held handle dangles once its last object
    is gone: cleaning through it later segfaulted)."""
    from dolfinx import la

    probe = la.create_petsc_vector(V.dofmap.index_map, V.dofmap.index_map_bs)
    PETSc.garbage_cleanup(probe.getComm())
    probe.destroy()


class _Layout:
    """Ownership of the full layout: rank r owns FE rows [fe_start, fe_end) (dolfinx's numbering), the last rank
    also the n_x extra rows [n_fe, n_fe + n_x)."""

    def __init__(self, model, n_x: int):
        self.comm = model.V.mesh.comm
        self.n_fe = model.K.getSize()[0]
        self.n_x = n_x
        self.fe_start, self.fe_end = model.K.getOwnershipRange()
        self.last = self.comm.rank == self.comm.size - 1
        index_map, bs = model.V.dofmap.index_map, model.V.dofmap.index_map_bs
        wrong = ((self.fe_start, self.fe_end) != tuple(bs * r for r in index_map.local_range)
                 or (self.last and self.fe_end != self.n_fe))
        if self.comm.allreduce(wrong):
            raise SolverError("coupling: the rows of model.K are not dolfinx's rank-by-rank numbering of model.V")
        self.starts = np.array(self.comm.allgather(self.fe_start) + [self.n_fe + n_x])   # full-layout row owners
        self.n_fe_local = self.fe_end - self.fe_start
        self.n_local = self.n_fe_local + (n_x if self.last else 0)
        self.n_full = self.n_fe + n_x

    def local(self, rows) -> np.ndarray:
        """Local full-layout row of global full rows owned by this rank."""
        return np.asarray(rows) - self.fe_start


def _collective_check(comm, bad: bool, message: str) -> None:
    """Raise InputError on every rank if `bad` on any (so that no rank waits in a collective call)."""
    if comm.allreduce(bool(bad)):
        raise InputError(message)


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


@dataclass
class _Bore:
    """The owned nodes of a bore surface on this rank: dofs (local unrolled FE indices, (N, 3)), r (N, 3)
    offsets from the master (m), w (N,) area weights (m^2)."""

    dofs: np.ndarray
    r: np.ndarray
    w: np.ndarray


def _bores(model, lay: _Layout, connections) -> list[_Bore]:
    """Owned bore nodes of every connection; Dirichlet DOFs on a bore and nodes shared by two bores are errors."""
    constrained = _dirichlet_dofs(model)
    coords = model.V.tabulate_dof_coordinates()          # one row per FE node (blocked DOF index)
    used = np.zeros(lay.n_fe_local, bool)
    out = []
    for c in connections:
        node_ids, w = surface_nodes(model, c.surface)
        dofs = 3 * node_ids[:, None] + np.arange(3)[None, :]
        _collective_check(lay.comm, np.any(constrained[dofs]),
                          f"connection {c.name}: surface {c.surface!r} has Dirichlet-constrained DOFs")
        _collective_check(lay.comm, np.any(used[dofs]),
                          f"connection {c.name}: surface {c.surface!r} shares nodes with another connection")
        used[dofs] = True
        out.append(_Bore(dofs, coords[node_ids] - np.asarray(c.centre, float), w))
    return out


def torsion_dof(axis) -> int:
    """The rotation component (0, 1, 2 = theta_x, theta_y, theta_z) a torsion node keeps: that of the largest
    |axis_k| (the others follow as theta_j = axis_j / axis_k theta_k)."""
    return int(np.argmax(np.abs(np.asarray(axis, float))))


def _unit(axis, what: str) -> np.ndarray:
    a = np.asarray(axis, float)
    if a.shape != (3,) or not np.all(np.isfinite(a)) or np.linalg.norm(a) == 0:
        raise InputError(f"{what}: axis must be a finite non-zero 3-vector")
    return a / np.linalg.norm(a)


def _transformation(lay: _Layout, connections, bores, nodes: dict,
                    torsion_nodes: dict | None = None) -> tuple[PETSc.Mat, np.ndarray]:
    """P (u_full = P q, MPIAIJ) and the local full rows that are q entries (the independent DOFs)."""
    comm, last = lay.comm, lay.comm.size - 1
    torsion_nodes = torsion_nodes or {}
    eliminated = np.zeros(lay.n_local, bool)            # local full rows
    extra_eliminated = np.zeros(lay.n_x, bool)          # every extra DOF, on every rank
    for c, b in zip(connections, bores):
        if c.kind == "rbe2":
            eliminated[b.dofs.ravel()] = True
        elif c.kind == "rbe3":
            extra_eliminated[nodes[c.name][1] - lay.n_fe + np.arange(6)] = True
    for name, (_, axis) in torsion_nodes.items():       # all but the kept rotation component
        kept = np.arange(6) != 3 + torsion_dof(axis)
        extra_eliminated[nodes[name][1] - lay.n_fe + np.flatnonzero(kept)] = True
    if lay.last:
        eliminated[lay.n_fe_local:] = extra_eliminated
    independent = np.flatnonzero(~eliminated)
    counts = np.array(comm.allgather(len(independent)))
    q_start, n_q = int(counts[:comm.rank].sum()), int(counts.sum())
    q_local = np.full(lay.n_local, -1)
    q_local[independent] = q_start + np.arange(len(independent))
    # q column of every extra DOF: the independent ones close the last rank's block
    q_extra = np.full(lay.n_x, -1)
    q_extra[~extra_eliminated] = n_q - np.count_nonzero(~extra_eliminated) + np.arange(np.count_nonzero(~extra_eliminated))

    rows, cols, vals = [independent], [q_local[independent]], [np.ones(len(independent))]
    for c, b in zip(connections, bores):
        mx = nodes[c.name][1] - lay.n_fe + np.arange(6)         # master DOFs among the extras
        if c.kind == "rbe2":          # slave rows: u_s = [I, -[r]x] (u_m, theta_m)
            arms = np.stack([rigid_arm(ri) for ri in b.r]) if len(b.r) else np.zeros((0, 3, 6))   # (N, 3, 6)
            rows.append(np.repeat(b.dofs.ravel(), 6))
            cols.append(np.tile(q_extra[mx], b.dofs.size))
            vals.append(arms.reshape(-1))
        elif c.kind == "rbe3":        # master rows: (u_m, theta_m) = R u_s, from the bore nodes of every rank
            parts = comm.gather((b.r, b.w, q_local[b.dofs]), root=last)
            error, block = None, None
            if lay.last:
                r = np.concatenate([p[0] for p in parts])
                w = np.concatenate([p[1] for p in parts])
                qs = np.concatenate([p[2] for p in parts])
                # nodes of zero weight (P2 triangle vertices) have zero columns in R: leaving them out keeps
                # explicit zeros out of P and of the (dense, rank-6) coupling block of the spring
                keep = np.abs(w) > 1e-12 * np.abs(w).max()
                try:
                    R = rbe3_matrix(r[keep], w[keep])                              # (6, 3N)
                except InputError as exc:
                    error = f"connection {c.name}: {exc}"
                else:
                    q_used = qs[keep].ravel()
                    block = (np.repeat(lay.n_fe_local + mx, len(q_used)), np.tile(q_used, 6), R.ravel())
            error = comm.bcast(error, root=last)
            if error:
                raise InputError(error)
            if block is not None:
                rows.append(block[0])
                cols.append(block[1])
                vals.append(block[2])
    if lay.last:
        for name, (_, axis) in torsion_nodes.items():   # theta_j = a_j / a_k theta_k; translations: no entries
            k = torsion_dof(axis)
            mx = nodes[name][1] - lay.n_fe + np.arange(6)
            others = [j for j in range(3) if j != k]
            rows.append(lay.n_fe_local + mx[[3 + j for j in others]])
            cols.append(np.full(2, q_extra[mx[3 + k]]))
            vals.append(np.array([axis[j] / axis[k] for j in others]))
    r_all, c_all, v_all = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
    _collective_check(comm, np.any(c_all < 0), "coupling: a constraint refers to an eliminated DOF (chained "
                                               "constraints)")
    Pl = sp.csr_matrix((v_all, (r_all, c_all)), shape=(lay.n_local, n_q))
    Pl.eliminate_zeros()            # zero arm components: no structural entries in P, nor in K_c
    P = _aij(comm, Pl, (lay.n_local, lay.n_full), (len(independent), n_q), Pl.data)
    return P, independent


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


def _star_rods(trip, dofs, moff, r, k) -> None:
    """Isotropic links of stiffness k (N/m) between each bore node (global DOFs (N, 3)) and the master's rigid
    arm: blocks k B^T B, B = [I, -I, [r]x] (relative displacement, 3 x 9)."""
    n = len(r)
    if n == 0:
        return
    B = np.zeros((n, 3, 9))
    B[:, :, :3] = np.eye(3)
    B[:, :, 3:6] = -np.eye(3)
    B[:, :, 6:] = np.stack([skew(ri) for ri in r])
    blocks = k * np.einsum("nai,naj->nij", B, B)
    idx = np.concatenate([dofs, np.broadcast_to(np.arange(moff, moff + 6), (n, 6))], axis=1)     # (N, 9)
    trip.r.append(np.repeat(idx, 9, axis=1).ravel())
    trip.c.append(np.tile(idx, (1, 9)).ravel())
    trip.v.append(blocks.ravel())


def _gear_element(g: GearMesh, nodes) -> Element:
    return gear_mesh_element(g, _node(nodes, g.a)[0], _node(nodes, g.b)[0])


def gear_mesh_element(g: GearMesh, position_a, position_b) -> Element:
    """The 12x12 Element of a gear mesh between nodes at position_a and position_b (m): stiffness (and damping)
    on the relative flank displacement along the contact normal (see GearMesh)."""
    n = np.asarray(g.direction, float)
    n /= np.linalg.norm(n)
    x = np.asarray(g.point, float)
    gvec = np.concatenate([n @ rigid_arm(x - np.asarray(position_a, float)),
                           -(n @ rigid_arm(x - np.asarray(position_b, float)))])
    K = g.stiffness * np.outer(gvec, gvec)
    C = g.damping * np.outer(gvec, gvec) if g.damping else None
    return Element((g.a, g.b), K, None, C)


def _tie_rod(t: TieRod, nodes) -> Element:
    from housingfe.drivetrain.shafts import STEEL, beam_element_matrices

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
    """COO accumulator of dense element blocks (global full-layout indices)."""

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

    def arrays(self, scale=1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if not self.v:
            return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
        return (np.concatenate(self.r).astype(np.int64), np.concatenate(self.c).astype(np.int64),
                scale * np.concatenate(self.v))


# ---------------------------------------------------------------------------------------- full matrices
def _route(lay: _Layout, rows, cols, vals) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Send triplets (global full-layout rows) to the ranks that own their rows; returns this rank's."""
    comm = lay.comm
    if comm.size == 1:
        return rows, cols, vals
    owner = np.searchsorted(lay.starts, rows, side="right") - 1
    order = np.argsort(owner, kind="stable")
    splits = np.cumsum(np.bincount(owner, minlength=comm.size))[:-1]
    send = list(zip(*(np.split(a[order], splits) for a in (rows, cols, vals))))
    got = comm.alltoall(send)
    return tuple(np.concatenate([g[i] for g in got]) for i in range(3))


def _full_matrices(model, lay: _Layout, Kx, Mx, stars) -> tuple[PETSc.Mat, PETSc.Mat]:
    """K_full and M_full (MPIAIJ, full layout, one sparsity pattern): the FE rows of this rank padded with the
    extra rows (last rank), plus the lumped parts (last rank) and the star rods (rank of the bore node)."""
    ptr, idx, kv = model.K.getValuesCSR()
    mptr, midx, mv = model.M.getValuesCSR()
    if not (np.array_equal(ptr, mptr) and np.array_equal(idx, midx)):    # dolfinx assembles them on one pattern
        ptr, idx, (kv, mv) = _add_to_csr(ptr, idx, (kv, np.zeros(len(kv))), _row_of(mptr), midx,
                                         (np.zeros(len(mv)), mv))
    ptr = np.concatenate([ptr, np.full(lay.n_local - lay.n_fe_local, ptr[-1])])
    # triplets (global rows) with a K and an M value each: explicit zeros where only one of them has a value
    trip = [stars.arrays() + (None,)]
    if lay.last:
        trip += [Kx.arrays() + (None,), Mx.arrays() + ("M",)]
    rows = np.concatenate([t[0] for t in trip])
    cols = np.concatenate([t[1] for t in trip])
    vk = np.concatenate([t[2] if t[3] is None else np.zeros(len(t[2])) for t in trip])
    vm = np.concatenate([t[2] if t[3] == "M" else np.zeros(len(t[2])) for t in trip])
    nonzero = (vk != 0) | (vm != 0)             # zero entries of the blocks (e.g. of a rod's k B^T B) stay out
    rows, cols, vals = _route(lay, rows[nonzero], cols[nonzero], np.stack([vk, vm], axis=1)[nonzero])
    ptr, idx, (kv, mv) = _add_to_csr(ptr, idx, (kv, mv), lay.local(rows), cols, vals.T)
    sizes = (lay.n_local, lay.n_full)
    return (_aij(lay.comm, (ptr, idx), sizes, sizes, kv), _aij(lay.comm, (ptr, idx), sizes, sizes, mv))


def _row_of(ptr) -> np.ndarray:
    """The row of every entry of a CSR matrix."""
    return np.repeat(np.arange(len(ptr) - 1), np.diff(ptr))


def _add_to_csr(ptr, idx, values, rows, cols, add_values):
    """CSR (ptr, idx, [value arrays], sorted columns) plus triplets (local rows, global columns, [value arrays]):
    the union pattern (sorted, duplicates summed, explicit zeros kept).  Only the rows the triplets touch are
    rebuilt; the others are moved as blocks."""
    if len(rows) == 0:
        return ptr, idx, list(values)
    n, n_cols = len(ptr) - 1, int(max(idx.max(initial=0), cols.max())) + 1
    counts = np.diff(ptr)
    touched = np.unique(rows)
    # the existing entries of the touched rows and the new ones, sorted by (row, column), duplicates summed
    lengths = counts[touched]
    sel = np.repeat(ptr[touched] - np.r_[0, np.cumsum(lengths)[:-1]], lengths) + np.arange(lengths.sum())
    r_all = np.concatenate([np.repeat(touched, lengths), rows]).astype(np.int64)
    c_all = np.concatenate([idx[sel], cols]).astype(np.int64)
    key = r_all * n_cols + c_all
    ukey, inverse = np.unique(key, return_inverse=True)
    merged = []
    for old, new in zip(values, add_values):
        merged.append(np.bincount(inverse, np.concatenate([old[sel], new]), minlength=len(ukey)))
    u_rows, u_cols = ukey // n_cols, ukey % n_cols
    new_counts = counts.copy()
    new_counts[touched] = np.bincount(u_rows, minlength=n)[touched]
    new_ptr = np.concatenate([[0], np.cumsum(new_counts)])
    out_idx = np.empty(new_ptr[-1], dtype=idx.dtype)
    out_vals = [np.empty(new_ptr[-1]) for _ in values]
    # untouched rows: the runs between touched rows move as blocks
    edges = np.concatenate([[-1], touched, [n]])
    for lo, hi in zip(edges[:-1] + 1, edges[1:]):
        if hi > lo:
            s0, s1, d0 = ptr[lo], ptr[hi], new_ptr[lo]
            out_idx[d0:d0 + s1 - s0] = idx[s0:s1]
            for o, v in zip(out_vals, values):
                o[d0:d0 + s1 - s0] = v[s0:s1]
    # touched rows: the merged entries, in order (ukey is sorted by row, then column)
    dst = new_ptr[u_rows] + np.arange(len(ukey)) - np.searchsorted(u_rows, u_rows)
    out_idx[dst] = u_cols
    for o, v in zip(out_vals, merged):
        o[dst] = v
    return new_ptr, out_idx, out_vals


def _full_damping(lay: _Layout, Cx) -> PETSc.Mat:
    """C_full (MPIAIJ, full layout): the lumped dampers, on the last rank."""
    r, c, v = Cx.arrays() if lay.last else _Triplets().arrays()
    C = sp.csr_matrix((v, (lay.local(r), c)), shape=(lay.n_local, lay.n_full))
    C.sum_duplicates()
    sizes = (lay.n_local, lay.n_full)
    return _aij(lay.comm, C, sizes, sizes, C.data)


def _aij(comm, pattern, rows: tuple, cols: tuple, values) -> PETSc.Mat:
    """A PETSc AIJ from this rank's rows: pattern a scipy CSR or (indptr, indices) with global, sorted column
    indices; rows/cols = (local, global) sizes."""
    if isinstance(pattern, sp.csr_matrix):
        pattern = (pattern.indptr, pattern.indices)
    ptr, idx = (np.ascontiguousarray(a, dtype=PETSc.IntType) for a in pattern)
    A = PETSc.Mat().createAIJWithArrays(size=(rows, cols), csr=(ptr, idx, np.ascontiguousarray(values, float)),
                                        comm=comm)
    A.assemble()
    return A


def _ptap(A: PETSc.Mat, P: PETSc.Mat, result: PETSc.Mat | None = None) -> PETSc.Mat:
    """P^T A P (MatPtAP).  On one rank with the "rap" algorithm (P^T formed, then P^T (A P)): for a P that is
    mostly identity it is ~4x faster than the default there (0.05 s against 0.21 s on 39 k DOFs, 2.6 M
    non-zeros); left alone if the user set -matptap_via."""
    opts = PETSc.Options()
    choose = A.getComm().getSize() == 1 and result is None and not opts.hasName("matptap_via")
    if choose:
        opts["matptap_via"] = "rap"
    try:
        return A.PtAP(P, result)
    finally:
        if choose:
            opts.delValue("matptap_via")


def _triple_products(K_full: PETSc.Mat, M_full: PETSc.Mat, P: PETSc.Mat) -> tuple[PETSc.Mat, PETSc.Mat]:
    """K_c = P^T K_full P and M_c = P^T M_full P.  K_full and M_full share one pattern, so M_c reuses the
    symbolic product of K_c (MatPtAP with MAT_REUSE_MATRIX on M's values): half the cost, one pattern."""
    product = _ptap(K_full, P)
    K = product.copy()
    M_full.copy(K_full, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)     # M's values into K_full
    _ptap(K_full, P, product)
    M = product.copy()
    product.destroy()             # with its intermediate data (P^T, A P)
    return K, M


def _check_same_pattern(comm, K: PETSc.Mat, M: PETSc.Mat) -> None:
    """The solvers add K and M with SAME_NONZERO_PATTERN: K_c and M_c must have identical local CSR patterns."""
    ik, jk, _ = K.getValuesCSR()
    im, jm, _ = M.getValuesCSR()
    if not comm.allreduce(np.array_equal(ik, im) and np.array_equal(jk, jm), op=_land()):
        raise SolverError("coupling: K_c and M_c came out with different sparsity patterns (the solvers add "
                          "them with SAME_NONZERO_PATTERN)")


def _land():
    from mpi4py import MPI

    return MPI.LAND


# ---------------------------------------------------------------------------------------- FE-side helpers
def _dirichlet_dofs(model) -> np.ndarray:
    """Boolean mask of the owned Dirichlet-constrained FE DOFs (local unrolled indices)."""
    n = model.V.dofmap.index_map.size_local * model.V.dofmap.index_map_bs
    mask = np.zeros(n, bool)
    for bc in model.bcs:
        idx, _ = bc.dof_indices()
        mask[idx[idx < n]] = True
    return mask


def surface_nodes(model, surface: str) -> tuple[np.ndarray, np.ndarray]:
    """Owned nodes (local blocked DOF indices < index_map.size_local) of a surface and their consistent area
    weights int N_i dA (m^2).  Collective; every node of the surface is returned on exactly one rank."""
    import ufl
    from dolfinx import fem
    from dolfinx.fem.petsc import assemble_vector

    housing, V = model.housing, model.V
    facets = housing.facets(surface)
    nodes = fem.locate_dofs_topological(V, housing.mesh.topology.dim - 1, facets)   # owned and ghost nodes
    nodes = np.asarray(nodes[nodes < V.dofmap.index_map.size_local])
    ds = ufl.Measure("ds", domain=housing.mesh, subdomain_data=housing.facet_tags)
    v = ufl.TestFunction(V)
    one = fem.Constant(housing.mesh, np.array([1.0, 0.0, 0.0], dtype=PETSc.ScalarType))
    # int N_i dA: the x-component of the load vector of a unit x-traction (P2 triangle vertices get 0)
    b = assemble_vector(fem.form(ufl.inner(one, v) * ds(housing.facet_tag_values(surface))))
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)   # ghost contributions to owners
    w = b.getArray(readonly=True)[3 * nodes].copy()
    b.destroy()
    if housing.mesh.comm.allreduce(len(nodes)) < 3:
        raise InputError(f"surface {surface!r}: fewer than three nodes")
    return nodes, w


def surface_centre(model, surface: str) -> np.ndarray:
    """Centre (m) of the bounding box of a surface's nodes; the same on every rank.  On the axis of a complete,
    evenly meshed bore only: bore masters go where housingfe.drivetrain.bore_axis.fit_bore puts them."""
    from mpi4py import MPI

    nodes, _ = surface_nodes(model, surface)
    x = model.V.tabulate_dof_coordinates()[nodes]
    lo = x.min(axis=0) if len(x) else np.full(3, np.inf)
    hi = x.max(axis=0) if len(x) else np.full(3, -np.inf)
    comm = model.V.mesh.comm
    comm.Allreduce(MPI.IN_PLACE, lo, op=MPI.MIN)
    comm.Allreduce(MPI.IN_PLACE, hi, op=MPI.MAX)
    return (lo + hi) / 2
