"""Benchmark `stability`: the hard cases where FE codes silently go wrong, each with its risk, its reference
(analytic or converged) and what the package gives, with the error and the cost (issue 30).

Cases (every one small: seconds each):

- thin plates (t/L = 1/1000) per element family against Kirchhoff's free square plate: shear locking;
- a thinner plate (t/L = 1/10 000), where the model's eigenvalues span more than double precision resolves:
  the solver must refuse with a clear message, not count wrong;
- repeated eigenvalues of a free cube: the whole multiplicity, M-orthonormal;
- an eigenvalue exactly at f_max (and 1e-9 either side): the inertia count and the eigensolve agree;
- two free bodies in one model (12 zero modes): counted and never reported as elastic;
- the same cube in SI, in mm-t-s and 100x larger: the same (scaled) frequencies;
- forced response with eta = 1e-6 exactly at a resonance: finite and equal to the single-mode amplitude;
- P2 tetrahedra on the thin plate at t/L = 1/200 (against Kirchhoff), and at 1/1000 with FV12's element size:
  refused by the quality check with a message naming mesh.size;
- a nu = 0.499 gasket bonded between steel blocks: volumetric locking of Q2 against a converged Q3 (fixed: selective
  reduced integration of the volumetric term in nearly incompressible cells, housingfe.solvers.elasticity);
- stiffness contrast: a soft layer with E ratio 1e6 and 1e9 (zero modes, count, backward error, sqrt(E) scaling)
  and a 1e11 N/m bearing on a 0.05 kg node (against scipy's dense eigh);
- a rigid rotor on two short journal bearings through the onset of oil whirl (against Lund's threshold), and the
  projected forced-response solver flagging the unstable point;
- the gear source at a load and speed where the teeth separate: flagged (housingfe.source.roosmalen.dynamics.contact_check);
- a P2 tetrahedral cube with a sliver: refused/warned by the quality check, its effect on the frequencies measured.

`housingfe bench stability [--quick]` prints the table and writes stability.csv, stability.md and stability.png
(error against cost).  The test suite (tests/benchmarks/test_stability.py) asserts the same cases.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from housingfe.outputs import atomic_output_dir, format_table, write_csv

# Free square plate, nu = 0.3, Kirchhoff theory: lambda^2 = omega a^2 sqrt(rho h / D) of the first six elastic
# modes (NAFEMS FV12's reference 1.622, 2.360, 2.922, 4.233, 4.233, 7.416 Hz for the 10 m x 50 mm plate divided
# by 1/(2 pi a^2) sqrt(D / rho h) = 0.12043 Hz).
FREE_PLATE_LAMBDA2 = np.array([1.622, 2.360, 2.922, 4.233, 4.233, 7.416]) / 0.120433

STEEL = dict(youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)


@dataclass
class CaseResult:
    """One row of the table: the case, the risk it tests, the reference, what the package gives, the error and
    the cost (s).  `ok`: the package met the reference within the case's stated tolerance (or refused cleanly
    where refusing is the right answer)."""

    case: str
    risk: str
    reference: str
    ours: str
    error: float | None
    cost_s: float
    ok: bool
    details: dict = field(default_factory=dict)

    def row(self) -> list:
        err = "-" if self.error is None else f"{self.error:.2e}"
        return [self.case, self.risk, self.reference, self.ours, err, f"{self.cost_s:.2f}", "yes" if self.ok else "NO"]


HEADER = ["case", "risk", "reference", "ours", "error", "cost s", "ok"]


# ------------------------------------------------------------------------------------------ model builders
def free_plate_model(h: float, family: str, size: float = 0.625, a: float = 10.0, f_max: float | None = None):
    """The NAFEMS FV12 plate (a x a x h m, steel-like E = 200 GPa, rho = 8000) as a free HousingModel, one layer
    through the thickness; family: "Q1", "Q2", "Q3" or "S2R" (20-node brick, reduced integration)."""
    from mpi4py import MPI

    from housingfe.fe.model import build_model
    from housingfe.geometry.plate import PlateGeometry
    from housingfe.materials import Material
    from housingfe.scene import MeshSpec

    specs = {"Q1": dict(element="hex", degree=1), "Q2": dict(element="hex", degree=2),
             "P2": dict(element="tet", degree=2),
             "Q3": dict(element="hex", degree=3),
             "S2R": dict(element="hex", degree=2, family="serendipity", integration="reduced")}
    material = Material(name="fv12", youngs_modulus=200e9, poisson_ratio=0.3, density=8000.0)
    f_ref = kirchhoff_free_plate_hz(a, h, 200e9, 0.3, 8000.0)
    return (build_model(PlateGeometry(kind="plate", a=a, b=a, h=h), material, MeshSpec(size=size, **specs[family]),
                        f_max or 1.3 * f_ref[-1], MPI.COMM_WORLD), f_ref)


def kirchhoff_free_plate_hz(a: float, h: float, E: float, nu: float, rho: float) -> np.ndarray:
    """The first six elastic frequencies (Hz) of a free square Kirchhoff plate, side a and thickness h (m)."""
    D = E * h ** 3 / (12 * (1 - nu ** 2))
    return FREE_PLATE_LAMBDA2 / (2 * math.pi * a * a) * math.sqrt(D / (rho * h))


def cube_matrices(n: int = 3, side: float = 0.1, length_unit: float = 1.0, stress_unit: float = 1.0,
                  density_unit: float = 1.0, bodies: int = 1, degree: int = 2, comm=None):
    """K and M (PETSc) of free steel cubes of `side` m meshed with n^3 Q`degree` hexahedra, expressed in other units:
    lengths divided by length_unit (m), stresses by stress_unit (Pa), densities by density_unit (kg/m^3) —
    mm-t-s is (1e-3, 1e6, 1e12).  bodies = 2: a second, disjoint cube beside the first (12 zero modes).
    Returns (K, M, V)."""
    import ufl
    from dolfinx import fem, mesh
    from dolfinx.fem.petsc import assemble_matrix
    from mpi4py import MPI

    comm = comm or MPI.COMM_WORLD
    L = side / length_unit
    if bodies == 1:
        domain = mesh.create_box(comm, [np.zeros(3), np.full(3, L)], [n, n, n], mesh.CellType.hexahedron)
    else:
        domain = _disjoint_cubes(comm, L, n, bodies)
    V = fem.VectorFunctionSpace(domain, ("Lagrange", degree))
    E, nu, rho = STEEL["youngs_modulus"] / stress_unit, STEEL["poisson_ratio"], STEEL["density"] / density_unit
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    eps = lambda w: ufl.sym(ufl.grad(w))
    a = ufl.inner(2 * mu * eps(u) + lam * ufl.tr(eps(u)) * ufl.Identity(3), eps(v)) * ufl.dx
    m = rho * ufl.inner(u, v) * ufl.dx
    K = assemble_matrix(fem.form(a))
    K.assemble()
    M = assemble_matrix(fem.form(m))
    M.assemble()
    from petsc4py import PETSc

    for A in (K, M):
        A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    return K, M, V


def _disjoint_cubes(comm, L: float, n: int, bodies: int):
    """`bodies` cubes of side L side by side with a gap of L/2 between them, one mesh (gmsh, rank 0)."""
    import gmsh
    from dolfinx.io import gmshio

    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("cubes")
        tags = [gmsh.model.occ.addBox(1.5 * L * i, 0, 0, L, L, L) for i in range(bodies)]
        gmsh.model.occ.synchronize()
        gmsh.option.setNumber("Mesh.RecombineAll", 1)
        gmsh.option.setNumber("Mesh.Recombine3DAll", 1)
        for dim, tag in gmsh.model.getEntities(1):
            gmsh.model.mesh.setTransfiniteCurve(tag, n + 1)
        for dim, tag in gmsh.model.getEntities(2):
            gmsh.model.mesh.setTransfiniteSurface(tag)
            gmsh.model.mesh.setRecombine(2, tag)
        for tag in tags:
            gmsh.model.mesh.setTransfiniteVolume(tag)
        gmsh.model.addPhysicalGroup(3, tags, 1)
        gmsh.model.mesh.generate(3)
    domain, _, _ = gmshio.model_to_mesh(gmsh.model, comm, 0, gdim=3)
    if comm.rank == 0:
        gmsh.option.setNumber("Mesh.RecombineAll", 0)
        gmsh.option.setNumber("Mesh.Recombine3DAll", 0)
        gmsh.finalize()
    return domain


def _timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0


# ------------------------------------------------------------------------------------------ the cases
def thin_plate(family: str, h: float = 0.01, size: float = 0.625) -> CaseResult:
    """The free 10 m plate, t/L = h/10, one element layer, family Q1/Q2/Q3/S2R, against Kirchhoff: the largest
    relative error of the three lowest elastic frequencies (all six must be found).  ok: < 1 % (Q1 is expected to lock: reported, and ok
    means "locks as expected" there)."""
    from housingfe.solvers.modal import modes

    (model, f_ref), t_build = _timed(lambda: free_plate_model(h, family, size))
    basis, t_solve = _timed(lambda: modes(model, 1.3 * f_ref[-1]))
    f = basis.frequencies_hz[basis.rigid_count:]
    n = min(len(f), len(f_ref))
    # the three lowest: FV12's published 4.233 Hz pair and 7.416 Hz mode sit 0.8-1.0 % above every converged
    # solid result of the package at any thickness (docs/verification.md; Q3 at t/L = 1/1000 gives 4.188 Hz
    # scaled), the three lowest agree with it to 0.03 %: they measure locking without the reference's own error
    err = float(np.max(np.abs(f[:3] / f_ref[:3] - 1))) if n == len(f_ref) else float("inf")
    locks = family == "Q1"
    ok = (err > 0.03) if locks else err < 0.01
    return CaseResult(f"thin plate t/L=1/{10 / h:.0f}, {family}, {model.dofs} DOFs", "shear locking",
                      "Kirchhoff free square plate (FV12 lambda^2)",
                      f"{n} of 6 elastic modes, f1 {f[0]:.4g} Hz" if n else "no elastic mode",
                      err, t_build + t_solve, ok, {"frequencies_hz": f[:6].tolist(), "reference_hz": f_ref.tolist(),
                                                   "expected_to_lock": locks})


def thinner_than_double(family: str = "S2R", h: float = 0.001) -> CaseResult:
    """t/L = 1/10 000 with elements 625 thicknesses wide: f_max's eigenvalue lies at ~3e-15 of the mesh's highest,
    where double precision no longer separates the six rigid motions from the lowest elastic ones (with the floor
    switched off the solve finds 11 near-zero modes).  ok: a SolverError that says why (modal.PRECISION_FLOOR)."""
    from housingfe.errors import SolverError
    from housingfe.solvers.modal import modes

    t0 = time.perf_counter()
    model, f_ref = free_plate_model(h, family)
    try:
        basis = modes(model, 1.3 * f_ref[-1])
        f = basis.frequencies_hz[basis.rigid_count:]
        ours, ok, message = f"answered: {len(f)} elastic modes", False, ""
    except SolverError as exc:
        message = str(exc)
        ours, ok = "refused: " + message[:60] + "...", "double precision" in message
    return CaseResult(f"plate t/L=1/{10 / h:.0f}, {family}, {model.dofs} DOFs", "count/solve beyond double precision",
                      "a clear refusal", ours, None, time.perf_counter() - t0, ok, {"message": message})


def thin_plate_indefinite_workspace(family: str = "S2R", h: float = 0.003) -> CaseResult:
    """t/L = 1/3333 with elements 208 thicknesses wide (f_max at 3.5e-13 of the highest eigenvalue): the LDL^T of
    K - sigma M needs more delayed pivots than MUMPS' analysis plans for (INFOG(1) = -9).  Until 2026-11-26 PETSc
    kept that failed factor silently and its partial inertia (0 of 16) was read as "beyond double precision";
    the workspace is now grown (housingfe.solvers.mumps) and the plate is solved.  ok: 6 rigid modes and the six
    lowest elastic ones within 2 % of the Kirchhoff reference."""
    from housingfe.solvers.modal import modes

    t0 = time.perf_counter()
    model, f_ref = free_plate_model(h, family)
    basis = modes(model, 1.3 * f_ref[-1])
    f = basis.frequencies_hz[basis.rigid_count:]
    n = min(len(f), len(f_ref))
    err = float(np.max(np.abs(f[:n] / np.asarray(f_ref)[:n] - 1))) if n else math.inf
    ok = basis.rigid_count == 6 and n == len(f_ref) and err < 0.02
    return CaseResult(f"plate t/L=1/{10 / h:.0f}, {family}, {model.dofs} DOFs",
                      "MUMPS workspace short for the delayed pivots (INFOG -9)",
                      "Kirchhoff free square plate (FV12 lambda^2)",
                      f"{basis.rigid_count} rigid, {len(f)} elastic, f1 {f[0]:.4g} Hz" if len(f) else "no elastic mode",
                      err, time.perf_counter() - t0, ok,
                      {"frequencies_hz": f[:6].tolist(), "reference_hz": list(map(float, f_ref))})


def repeated_eigenvalues(n: int = 3) -> CaseResult:
    """A free steel cube (0.1 m, n^3 Q2): its elastic spectrum has multiplicities 2 and 3 from the cube's
    symmetry.  Every cluster returned whole (the count proves it), M-orthonormal to 1e-10, residuals < 1e-8."""
    from housingfe.solvers.modal import solve_modes

    (K, M, V), t_build = _timed(lambda: cube_matrices(n))
    f_max = 45000.0
    res, t_solve = _timed(lambda: solve_modes(K, M, f_max))
    lam = res.eigenvalues[res.rigid_count:]
    clusters = _clusters(lam, 1e-7)
    ortho = _m_orthogonality(M, res.vectors)
    ok = res.complete and ortho < 1e-10 and float(np.max(res.residuals)) < 1e-8 and max(clusters) >= 3
    return CaseResult(f"free cube, {K.getSize()[0]} DOFs", "repeated eigenvalues (symmetry)",
                      "inertia count; M-orthonormality", f"{len(lam)} elastic, multiplicities {sorted(set(clusters))}, "
                      f"|V'MV-I| {ortho:.1e}", ortho, t_build + t_solve, ok,
                      {"clusters": clusters, "residual_max": float(np.max(res.residuals))})


def _clusters(lam: np.ndarray, rel: float) -> list[int]:
    """Sizes of the groups of eigenvalues within `rel` of each other (ascending order)."""
    sizes, start = [], 0
    for i in range(1, len(lam) + 1):
        if i == len(lam) or lam[i] - lam[i - 1] > rel * abs(lam[i]):
            sizes.append(i - start)
            start = i
    return sizes


def _m_orthogonality(M, vectors) -> float:
    """max |V^T M V - I| of PETSc vectors."""
    MV = [M.createVecLeft() for _ in vectors]
    for x, y in zip(vectors, MV):
        M.mult(x, y)
    G = np.array([[x.dot(y) for y in MV] for x in vectors])
    return float(np.max(np.abs(G - np.eye(len(vectors)))))


def eigenvalue_at_cutoff(offsets=(-1e-9, 0.0, 1e-9)) -> CaseResult:
    """f_max placed on a computed eigenfrequency of the cube (and 1e-9 relative either side): the inertia count
    and the eigensolve must agree (or the solver refuses a singular shift clearly).  ok: every placement either
    complete or a SolverError naming f_max."""
    from housingfe.errors import SolverError
    from housingfe.solvers.modal import solve_modes

    K, M, _ = cube_matrices(3)
    t0 = time.perf_counter()
    ref = solve_modes(K, M, 30000.0)
    f = ref.frequencies_hz
    target = f[ref.rigid_count + 4]          # an elastic frequency inside a multiplet or beside one
    outcomes, ok = [], True
    for off in offsets:
        try:
            r = solve_modes(K, M, target * (1 + off))
            outcomes.append(f"{off:+.0e}: {len(r.eigenvalues)}/{r.expected_count}")
            ok &= r.complete
        except SolverError as exc:
            outcomes.append(f"{off:+.0e}: refused")
            ok &= "f_max" in str(exc)
    return CaseResult("f_max on an eigenfrequency (+-1e-9)", "count and solve disagree at the cut-off",
                      "returned = inertia count", "; ".join(outcomes), None, time.perf_counter() - t0, ok)


def free_bodies() -> CaseResult:
    """Two disjoint free cubes in one model: 12 zero modes.  With the six global rigid motions deflated (what a
    free housing hands the solver), the other six must still come out as zero modes, never as elastic."""
    from housingfe.solvers import elasticity
    from housingfe.solvers.modal import solve_modes

    (K, M, V), t_build = _timed(lambda: cube_matrices(2, bodies=2))
    t0 = time.perf_counter()
    plain = solve_modes(K, M, 30000.0)
    deflated = solve_modes(K, M, 30000.0, null_space=elasticity.rigid_body_vectors(V), method="block")
    cost = t_build + time.perf_counter() - t0
    K1, M1, _ = cube_matrices(2)
    one = solve_modes(K1, M1, 30000.0)
    # the elastic spectrum of two identical cubes is the single cube's, every eigenvalue twice
    f_one = one.frequencies_hz[one.rigid_count:]
    f_two = deflated.frequencies_hz[deflated.rigid_count:]
    err = float(np.max(np.abs(f_two[::2][:len(f_one)] / f_one[:len(f_two[::2])] - 1))) if len(f_two) else None
    ok = plain.rigid_count == 12 and deflated.rigid_count == 12 and err is not None and err < 1e-8
    return CaseResult("two free cubes in one model", "mechanisms counted as elastic modes",
                      "12 zero modes; each elastic mode of one cube twice",
                      f"zero modes {plain.rigid_count} (plain), {deflated.rigid_count} (6 deflated)", err, cost, ok)


def unit_systems() -> CaseResult:
    """The same cube in SI (m, Pa, kg/m^3), in mm-t-s (mm, MPa, t/mm^3) and 100x larger in SI: the frequencies
    equal (the larger one / 100) and six zero modes each; no threshold may depend on units or size."""
    from housingfe.solvers.modal import solve_modes

    t0 = time.perf_counter()
    f_max = 40000.0
    cases = {"SI": (dict(), 1.0), "mm-t-s": (dict(length_unit=1e-3, stress_unit=1e6, density_unit=1e12), 1.0),
             "SI x100": (dict(side=10.0), 100.0)}
    freqs, rigid = {}, {}
    for name, (kw, scale) in cases.items():
        K, M, _ = cube_matrices(3, **kw)
        r = solve_modes(K, M, f_max / scale)
        freqs[name] = r.frequencies_hz[r.rigid_count:] * scale
        rigid[name] = r.rigid_count
    n = min(len(v) for v in freqs.values())
    err = max(float(np.max(np.abs(freqs[k][:n] / freqs["SI"][:n] - 1))) for k in freqs)
    ok = all(v == 6 for v in rigid.values()) and all(len(v) == len(freqs["SI"]) for v in freqs.values()) and err < 1e-8
    return CaseResult("cube in SI, mm-t-s, 100x size", "thresholds that depend on units or size",
                      "identical (scaled) frequencies, 6 zero modes",
                      f"{n} elastic each, zero modes {list(rigid.values())}", err, time.perf_counter() - t0, ok)


def resonance_light_damping(eta: float = 1e-6) -> CaseResult:
    """A point force on the free cube at exactly an elastic eigenfrequency with loss factor 1e-6: the response
    must be finite and equal the resonant mode's own term (phi' f)^2 / (i eta lambda) to the other modes'
    share (< 1e-3 relative at this damping), on the modal and the direct solvers."""
    from housingfe.solvers import harmonic
    from housingfe.solvers.modal import solve_modes

    K, M, V = cube_matrices(3)
    t0 = time.perf_counter()
    res = solve_modes(K, M, 30000.0)
    k = res.rigid_count
    lam, phi = res.eigenvalues[k], res.vectors[k]
    # every mode of the resonant eigenvalue's multiplet responds alike: the reference sums them
    multiplet = [j for j in range(k, len(res.eigenvalues)) if abs(res.eigenvalues[j] - lam) < 1e-7 * lam]
    f = K.createVecLeft()
    f.getArray()[:] = 0.0
    idx = int(np.argmax(np.abs(phi.getArray())))
    f.getArray()[idx] = 1.0                  # 1 N on the DOF where the mode moves most
    f_res = math.sqrt(lam) / (2 * math.pi)
    # phi_j (phi_j' f) / (lambda (1 + i eta) - omega^2) at omega^2 = lambda, observed at the loaded DOF
    exact = sum(res.vectors[j].dot(f) ** 2 for j in multiplet) / (1j * eta * lam)
    damping = harmonic.Damping(eta=lambda f: np.full(np.shape(f), eta))
    out = {}
    for name, run in (("modal", lambda: harmonic.modal_superposition(K, M, res, [_Load(f)], [f_res], damping,
                                                                       _reduce_dot(f))),
                      ("direct", lambda: harmonic.direct(K, M, [_Load(f)], [f_res], damping, _reduce_dot(f)))):
        try:
            out[name] = complex(_value(run()))
        except Exception as exc:  # noqa: BLE001 - reported as the case's outcome
            out[name] = exc
    errs = [abs(v / exact - 1) for v in out.values() if isinstance(v, complex)]
    err = max(errs) if len(errs) == len(out) else None
    ok = err is not None and all(np.isfinite(complex(v)) for v in out.values()) and err < 1e-3
    return CaseResult(f"eta = {eta:g} at resonance ({f_res:.0f} Hz)", "singular or overflowing response",
                      "single-mode amplitude (phi'f)^2/(i eta lambda)",
                      ", ".join(f"{k} {abs(v):.3e} m/N" if isinstance(v, complex) else f"{k} failed: {v}"
                                for k, v in out.items()), err, time.perf_counter() - t0, ok)


class _Load:
    """The minimum the raw harmonic solvers need of a load: its vector."""

    def __init__(self, vector):
        self.vector = vector
        self.name = "f"


def _reduce_dot(f):
    """A reduction that keeps the response at the loaded DOF: w^T x for each kept vector x (w = the load's
    indicator)."""
    def reduce(vectors):
        return np.array([[x.dot(f)] for x in vectors])
    return reduce


def _value(result) -> complex:
    """The response at the loaded DOF from a HarmonicResult of one load and one line."""
    block = result.blocks[0][0]
    reduced = np.asarray(block.reduced)            # (vectors, kept outputs): here one output, the loaded DOF
    return complex(np.asarray(block.coeffs)[:, 0] @ reduced[:, 0])


# ------------------------------------------------------------------------------------------ issue 30, second part
def thin_plate_tet(h: float = 0.05, size: float = 0.3) -> CaseResult:
    """P2 tetrahedra (mesh.element = "tet") on the free 10 m plate, t/L = h/10, against Kirchhoff: the largest
    relative error of the three lowest elastic frequencies.  ok: < 0.5 %."""
    from housingfe.solvers.modal import modes

    t0 = time.perf_counter()
    model, f_ref = free_plate_model(h, "P2", size)
    basis = modes(model, 1.3 * f_ref[-1])
    f = basis.frequencies_hz[basis.rigid_count:]
    err = float(np.max(np.abs(f[:3] / f_ref[:3] - 1))) if len(f) >= 3 else float("inf")
    return CaseResult(f"thin plate t/L=1/{10 / h:.0f}, P2 tets, {model.dofs} DOFs", "shear locking (tets)",
                      "Kirchhoff free square plate (FV12 lambda^2)",
                      f"{len(f)} elastic modes, f1 {f[0]:.4g} Hz, worst tet {model.housing.quality['min']:.3f}",
                      err, time.perf_counter() - t0, err < 0.005,
                      {"frequencies_hz": f[:6].tolist(), "reference_hz": f_ref.tolist(),
                       "quality": model.housing.quality["min"]})


def thin_plate_tet_refused(h: float = 0.01, size: float = 0.625) -> CaseResult:
    """P2 tetrahedra 62 thicknesses wide (t/L = 1/1000 at FV12's element size): the flat tets are refused before
    any solve, with an InputError naming mesh.size and why.  ok: refused with that message."""
    from housingfe.errors import InputError

    t0 = time.perf_counter()
    try:
        model, _ = free_plate_model(h, "P2", size, f_max=1.0)
        ours, ok, message = f"meshed: {model.dofs} DOFs", False, ""
    except InputError as exc:
        message = str(exc)
        ours, ok = "refused: " + message[:70] + "...", message.startswith("mesh.size:") and "flat" in message
    return CaseResult(f"plate t/L=1/{10 / h:.0f}, P2 tets {size / h:.0f} t wide", "flat tets (quality ~0.01)",
                      "a clear refusal naming mesh.size", ours, None, time.perf_counter() - t0, ok,
                      {"message": message})


def layered_block_matrices(n: int, layers_per_10mm: int, degree: int, gasket_E: float, gasket_nu: float,
                           integration: str = "full", selective: bool = True):
    """A 100 x 100 mm stack, steel block 40 mm / gasket layer 10 mm / steel block 40 mm, bonded, free, meshed with
    n x n x 9 layers_per_10mm Q`degree` bricks; the gasket (E, nu as given, 1200 kg/m^3) as a material region, K
    and M from the package's own assembly (housingfe.solvers.elasticity: selective reduced integration of the
    volumetric term where nu > 0.49, unless selective=False).  Returns (K, M, V)."""
    from dolfinx import mesh
    from mpi4py import MPI

    from housingfe.materials import Material
    from housingfe.solvers import elasticity

    domain = mesh.create_box(MPI.COMM_WORLD, [np.zeros(3), np.array([0.1, 0.1, 0.09])],
                             [n, n, 9 * layers_per_10mm], mesh.CellType.hexahedron)
    tdim = domain.topology.dim
    gasket_cells = mesh.locate_entities(domain, tdim, lambda x: (x[2] > 0.04 - 1e-9) & (x[2] < 0.05 + 1e-9))
    cells_all = np.arange(domain.topology.index_map(tdim).size_local + domain.topology.index_map(tdim).num_ghosts)
    # locate_entities keeps cells with all vertices inside: exactly the gasket layer's cells
    markers = np.where(np.isin(cells_all, gasket_cells), 2, 1).astype(np.int32)
    tags = mesh.meshtags(domain, tdim, cells_all, markers)
    steel = Material(name="steel", **STEEL)
    gasket = Material(name="gasket", youngs_modulus=gasket_E, poisson_ratio=gasket_nu, density=1200.0)
    V = elasticity.displacement_space(domain, degree)
    materials = elasticity.MaterialField(domain, steel, tags, {2: gasket})
    K, M = elasticity.assemble_stiffness_mass(V, materials, [], reduced=integration == "reduced", selective=selective)
    return K, M, V


def gasket_locking(nu: float = 0.499) -> CaseResult:
    """A rubber layer (E = 10 MPa, nu = 0.499) bonded between two steel blocks, one Q2 brick through it (what a
    scene's `layers = 1` gives): the rocking and bounce modes (4-6) against Q3, 3 x 3 x 9 bricks (within 0.25 % of
    Q3 with 4 x 4 x 18: 862.2 against 860.2 Hz).  Before the fix (full integration) Q2 gave 2016 Hz against 860 Hz (2.3x:
    volumetric locking); the package now integrates the volumetric term of nu > 0.49 cells at reduced order.
    ok: < 2 %, and full integration locking (> 1.5x) as it did."""
    from housingfe.solvers.modal import solve_modes

    t0 = time.perf_counter()
    out = {}
    # the reference fully integrated (no fix in it); "Q2 full" is the package before the fix
    for name, args, selective in (("Q2", (4, 1, 2), True), ("Q2 full", (4, 1, 2), False),
                                  ("reference Q3", (3, 1, 3), False)):
        K, M, _ = layered_block_matrices(*args, gasket_E=10e6, gasket_nu=nu, selective=selective)
        r = solve_modes(K, M, 3000.0)
        out[name] = r.frequencies_hz[r.rigid_count:][:6]
    err = float(np.max(np.abs(out["Q2"] / out["reference Q3"] - 1)))
    locked = float(np.max(out["Q2 full"][3:6] / out["reference Q3"][3:6]))
    return CaseResult(f"gasket nu={nu} between steel blocks, Q2 1 layer", "volumetric locking",
                      "Q3 (converged to 0.25 %)", f"modes 4-6: {', '.join(f'{x:.0f}' for x in out['Q2'][3:6])} Hz "
                      f"(ref {', '.join(f'{x:.0f}' for x in out['reference Q3'][3:6])}; full integration "
                      f"x{locked:.2f})", err,
                      time.perf_counter() - t0, err < 0.02 and locked > 1.5,
                      {**{k: v.tolist() for k, v in out.items()}, "locking_factor_full": locked})


def stiffness_contrast(ratios=(1e6, 1e9)) -> CaseResult:
    """Steel blocks on a soft layer (nu = 0.3) with E_steel / E_gasket = 1e6 and 1e9: six zero modes (the soft
    modes must not be counted as rigid), complete, residuals < 1e-8, and the soft modes' frequencies scaling as
    sqrt(E_gasket) between the two (the steel is rigid to 1e-6 against the layer: the reference)."""
    from housingfe.solvers.modal import solve_modes

    t0 = time.perf_counter()
    soft, facts = {}, []
    for ratio in ratios:
        E_g = STEEL["youngs_modulus"] / ratio
        K, M, _ = layered_block_matrices(3, 1, 2, gasket_E=E_g, gasket_nu=0.3)
        # the soft modes: about sqrt(E_g / E_steel) of the blocks' own; 6 of them (the two blocks' relative motion)
        f_max = 300.0 * math.sqrt(E_g / 1e6)
        r = solve_modes(K, M, f_max)
        soft[ratio] = r.frequencies_hz[r.rigid_count:] / math.sqrt(E_g)
        # ModalResult.residuals (||Kx - lambda Mx|| / ||Kx||) grows as the contrast (2e-6 at 1e6, 3e-4 at 1e9)
        # because ||Kx|| of a soft mode is tiny against ||K|| ||x||; the normwise backward error is the measure
        facts.append((ratio, r.rigid_count, r.complete, _backward_error(K, M, r), len(soft[ratio])))
    a, b = soft[ratios[0]], soft[ratios[1]]
    n = min(len(a), len(b))
    err = float(np.max(np.abs(b[:n] / a[:n] - 1))) if n else float("inf")
    ok = n >= 6 and len(a) == len(b) and all(rc == 6 and c and res < 1e-12 for _, rc, c, res, _ in facts) and err < 1e-4
    return CaseResult("soft layer, E ratio 1e6 / 1e9", "stiffness contrast: zero modes, count, residuals",
                      "6 zero modes; f ~ sqrt(E_gasket) (rigid blocks)",
                      "; ".join(f"{r:.0e}: {rc} zero, {m} soft, bwd err {res:.0e}" for r, rc, _, res, m in facts),
                      err, time.perf_counter() - t0, ok, {"facts": facts})


def stiff_bearing_light_node(k_bearing: float = 1e11, journal_mass: float = 0.05) -> CaseResult:
    """A free steel cube (Q2, 375 DOFs) with a 0.05 kg journal node on a 1e11 N/m spring (x, y, z) at a corner:
    max K_ii / M_ii (eigenvalue_scale) rises with the spring; the zero modes (6), the count and the frequencies
    must not move.  Reference: scipy's dense eigh of the same matrices (another solver).  ok: 6 zero modes,
    complete, < 1e-8."""
    import scipy.linalg
    from petsc4py import PETSc

    from housingfe.solvers.modal import eigenvalue_scale, solve_modes

    t0 = time.perf_counter()
    K, M, V = cube_matrices(2)
    k, m = _dense(K), _dense(M)
    n = len(k)
    corner = int(np.argmin(np.linalg.norm(V.tabulate_dof_coordinates(), axis=1)))     # block index of (0, 0, 0)
    K2, M2 = np.zeros((n + 3, n + 3)), np.zeros((n + 3, n + 3))
    K2[:n, :n], M2[:n, :n] = k, m
    for c in range(3):
        i, j = 3 * corner + c, n + c
        K2[i, i] += k_bearing
        K2[j, j] += k_bearing
        K2[i, j] -= k_bearing
        K2[j, i] -= k_bearing
        M2[j, j] = journal_mass
    ref = np.sqrt(np.abs(scipy.linalg.eigh(K2, M2, eigvals_only=True))) / (2 * math.pi)
    Kp, Mp = (PETSc.Mat().createAIJ(A.shape, csr=_csr(A), comm=PETSc.COMM_SELF) for A in (K2, M2))
    for A in (Kp, Mp):
        A.assemble()
        A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    f_max = 1.2 * ref[ref < 60000.0].max()
    r = solve_modes(Kp, Mp, f_max)
    f = r.frequencies_hz
    want = ref[ref < f_max]
    err = float(np.max(np.abs(f[6:] / want[6:len(f)] - 1))) if len(f) == len(want) else float("inf")
    scale_ratio = eigenvalue_scale(Kp, Mp) / eigenvalue_scale(K, M)
    ok = r.rigid_count == 6 and r.complete and err < 1e-8 and float(np.max(r.residuals)) < 1e-8
    return CaseResult(f"1e11 N/m bearing on a {journal_mass} kg node", "stiff spring, light node: scale/classification",
                      "dense eigh (scipy) of the same matrices",
                      f"{r.rigid_count} zero, {len(f) - r.rigid_count} elastic of {len(want) - 6}, scale x{scale_ratio:.0f}",
                      err, time.perf_counter() - t0, ok, {"scale_ratio": scale_ratio})


def _backward_error(K, M, r) -> float:
    """max over the elastic modes of ||K x - lambda M x|| / ((||K||_inf + |lambda| ||M||_inf) ||x||) (Higham)."""
    nk, nm = K.norm(_norm_inf()), M.norm(_norm_inf())
    worst = 0.0
    for lam, x in zip(r.eigenvalues[r.rigid_count:], r.vectors[r.rigid_count:]):
        y = K.createVecLeft()
        K.mult(x, y)
        z = M.createVecLeft()
        M.mult(x, z)
        y.axpy(-lam, z)
        worst = max(worst, y.norm() / ((nk + abs(lam) * nm) * x.norm()))
    return worst


def _norm_inf():
    from petsc4py import PETSc

    return PETSc.NormType.INFINITY


def _dense(A) -> np.ndarray:
    indptr, indices, data = A.getValuesCSR()
    import scipy.sparse

    return scipy.sparse.csr_matrix((data, indices, indptr), shape=A.getSize()).toarray()


def _csr(A: np.ndarray):
    import scipy.sparse

    c = scipy.sparse.csr_matrix(A)
    return c.indptr.astype(np.int32), c.indices.astype(np.int32), c.data


def oil_whirl() -> CaseResult:
    """A rigid rotor (100 kg per bearing, its weight as load) on two short plain bearings (D 100 mm, L 30 mm,
    C 100 um, 0.02 Pa s) swept 300-30 000 rpm: the complex eigenvalues of M q'' + C q' + K q = 0 with the films'
    non-symmetric K cross to Re s > 0 at the onset of oil whirl.  Reference: Lund's Routh-Hurwitz stability
    threshold (critical mass) from the same coefficients, without eigenvalues.  And the forced-response path
    (harmonic.projected, the solver of non-symmetric stiffness) flags the unstable operating point.
    Second reference: the same sweep with the finite-bearing Reynolds solver (L/D = 0.3, Reynolds cavitation):
    7642 rpm against the short bearing's 7617.
    ok: onsets within 1e-6, whirl ratio 0.4-0.55 (half-frequency whirl), projected flags above, not below, the
    finite bearing within 2 %."""
    from scipy.optimize import brentq

    from housingfe.bearings.fluid_film import (
        JournalBearing,
        lund_critical_mass,
        short_bearing_coefficients,
        whirl_onset,
    )

    t0 = time.perf_counter()
    bearing = JournalBearing(diameter=0.1, length=0.03, clearance=100e-6, viscosity=0.02)
    mass, load = 100.0, (0.0, -100.0 * 9.81)
    res = whirl_onset(bearing, mass, load, np.geomspace(300.0, 30000.0, 15))

    def margin(rpm):
        c = short_bearing_coefficients(bearing, rpm * 2 * math.pi / 60, load)
        return lund_critical_mass(c.K, c.C)[0] - mass

    ref = brentq(margin, 300.0, 30000.0, xtol=1e-6)
    err = abs(res.onset_rpm / ref - 1) if res.onset_rpm else float("inf")
    flags = {rpm: _projected_flags(bearing, mass, load, rpm) for rpm in (0.8 * ref, 1.2 * ref)}
    # another film model: the finite bearing (L/D = 0.3) by the Reynolds solver with Reynolds cavitation
    finite = whirl_onset(bearing, mass, load, np.geomspace(1000.0, 30000.0, 6), model="reynolds")
    finite_gap = abs(finite.onset_rpm / res.onset_rpm - 1) if finite.onset_rpm else float("inf")
    ok = (err < 1e-6 and 0.4 < res.whirl_ratio < 0.55 and not flags[0.8 * ref] and bool(flags[1.2 * ref])
          and finite_gap < 0.02)
    return CaseResult("rotor on 2 short journal bearings", "non-symmetric K: instability (oil whirl)",
                      f"Lund threshold {ref:.0f} rpm; finite bearing {finite.onset_rpm:.0f}", f"unstable (oil whirl) above {res.onset_rpm:.0f} rpm, whirl "
                      f"{res.whirl_ratio:.3f} x speed; projected solver flags: "
                      + ("yes" if flags[1.2 * ref] and not flags[0.8 * ref] else "NO"), err, time.perf_counter() - t0, ok,
                      {"message": res.message, "lund_rpm": ref, "whirl_ratio": res.whirl_ratio,
                       "finite_bearing": finite.message, "finite_bearing_gap": finite_gap,
                       "flags": {f"{k:.0f}": v for k, v in flags.items()}})


def _projected_flags(bearing, mass, load, rpm) -> list:
    """harmonic.projected's self-excited modes for the 2-DOF rotor on one film at `rpm` (a forced response)."""
    from petsc4py import PETSc

    from housingfe.bearings.fluid_film import short_bearing_coefficients
    from housingfe.solvers import harmonic
    from housingfe.solvers.modal import solve_modes

    c = short_bearing_coefficients(bearing, rpm * 2 * math.pi / 60, load)
    k2, c2 = c.K[:2, :2], c.C[:2, :2]
    mats = []
    for A in (k2, mass * np.eye(2), c2, 0.5 * (k2 + k2.T)):
        P = PETSc.Mat().createAIJ((2, 2), csr=_csr(A), comm=PETSc.COMM_SELF)
        P.assemble()
        mats.append(P)
    K, M, C, K_sym = mats
    for A in (M, K_sym):
        A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    modal = solve_modes(K_sym, M, 2000.0)
    f = K.createVecLeft()
    f.set(0.0)
    f.setValue(1, 1.0)
    f.assemble()
    damping = harmonic.Damping(eta=lambda fr: np.zeros(np.shape(fr)))
    out = harmonic.projected(K, M, modal, [_Load(f)], [10.0, 50.0], damping, _reduce_dot(f), C=C, K_sym=K_sym)
    return out.unstable


def contact_loss() -> CaseResult:
    """Gear set D (thesis) at 10 N m near its mesh resonance (7750 rpm, tooth frequency 3.1 kHz): the dynamic
    mesh force exceeds the mean, the teeth separate.  The steady state must be flagged by
    housingfe.source.roosmalen.dynamics.contact_check ("contact loss at 10 N m, 7750 rpm"), and the nominal point
    (2000 N m, 1500 rpm) must not be.  Reference: a contact force cannot be negative."""
    import tomllib

    from housingfe.scenefile import SCENE_DIR
    from housingfe.source.roosmalen import dynamics as dyn
    from housingfe.source.roosmalen import run as roosmalen

    t0 = time.perf_counter()
    path = SCENE_DIR / "gearset-D.toml"
    table = roosmalen.parse(tomllib.loads(path.read_text()), str(path))
    pair, corr, _, interior, model = roosmalen.build(table)
    checks = {}
    for torque, rpm in ((10.0, 7750.0), (2000.0, 1500.0)):
        op = roosmalen.OperatingPoint(pair, corr, interior, model, torque, 16)
        checks[(torque, rpm)] = dyn.contact_check(op.steady_state(pair, rpm, 30), torque, rpm)
    low, nominal = checks[(10.0, 7750.0)], checks[(2000.0, 1500.0)]
    ok = low.lost and "contact loss at 10 N m, 7750 rpm" in low.message and not nominal.lost
    return CaseResult("gear set D, 10 N m at 7750 rpm", "teeth separate: linear HB invalid",
                      "contact force >= 0", f"min/mean mesh force {low.min_force_N / low.mean_force_N:.2f} "
                      f"(flagged: {low.lost}); nominal {nominal.min_force_N / nominal.mean_force_N:.2f}", None,
                      time.perf_counter() - t0, ok, {"message": low.message})


def sliver(target_quality: float = 0.004) -> CaseResult:
    """A free steel cube of P2 tetrahedra (4^3 x 6) with one interior node pushed towards the opposite face of one
    of its tetrahedra until that tet is a sliver of `target_quality`: the package's quality check warns (between
    0.05 and 0.08) or refuses (below), and the frequencies move by the measured amount (reference: the same mesh
    without the sliver).  ok: complete, 6 zero modes, all frequencies within 0.5 %, warning/refusal as stated."""
    from housingfe.errors import InputError
    from housingfe.fe.model import check_element_quality
    from housingfe.solvers.modal import solve_modes

    t0 = time.perf_counter()
    K0, M0, q0 = _sliver_cube(0.0)
    r0 = solve_modes(K0, M0, 40000.0)
    f0 = r0.frequencies_hz[r0.rigid_count:]
    # the push s (fraction of the node's distance to the opposite face) that gives the target quality: q ~ (1 - s) q0
    s = 1.0 - target_quality / 0.84
    K, M, q = _sliver_cube(s)
    r = solve_modes(K, M, 40000.0)
    f = r.frequencies_hz[r.rigid_count:]
    err = float(np.max(np.abs(f[:len(f0)] / f0[:len(f)] - 1))) if len(f) == len(f0) else float("inf")
    try:
        verdict = check_element_quality({"min": q, "measure": "tet"}, 0.025, None, "tet") or "no warning"
    except InputError as exc:
        verdict = str(exc)
    expected = ("refused" if q < 0.05 else "warned" if q < 0.08 else "passed")
    flagged = (verdict.startswith("mesh.size:") if expected == "refused" else
               verdict.startswith("mesh: element quality") if expected == "warned" else verdict == "no warning")
    ok = r.complete and r.rigid_count == 6 and err < 5e-3 and flagged
    return CaseResult(f"P2 tet cube with a sliver q={q:.3f}", "slivers (as from CAD)",
                      "same mesh without the sliver", f"{expected} by the quality check; {len(f)} elastic, complete",
                      err, time.perf_counter() - t0, ok, {"quality": q, "verdict": verdict})


def _sliver_cube(push: float, n: int = 4):
    """K, M (P2, steel) of a free 0.1 m cube of n^3 x 6 tetrahedra whose node nearest the centre is moved by `push`
    times its distance towards the opposite face of one of its tetrahedra; returns (K, M, worst quality)."""
    import ufl
    from dolfinx import fem, mesh
    from dolfinx.fem.petsc import assemble_matrix
    from mpi4py import MPI

    from housingfe.geometry.blocks import tet_quality

    domain = mesh.create_box(MPI.COMM_WORLD, [np.zeros(3), np.full(3, 0.1)], [n] * 3, mesh.CellType.tetrahedron)
    x = domain.geometry.x
    cells = domain.geometry.dofmap.array.reshape(-1, 4)
    node = int(np.argmin(np.linalg.norm(x - 0.05, axis=1)))
    cell = cells[np.any(cells == node, axis=1)][0]
    face = x[[j for j in cell if j != node]]
    normal = np.cross(face[1] - face[0], face[2] - face[0])
    normal /= np.linalg.norm(normal)
    x[node] -= push * ((x[node] - face[0]) @ normal) * normal
    quality = float(tet_quality(x[cells]).min())
    V = fem.VectorFunctionSpace(domain, ("Lagrange", 2))
    E, nu, rho = STEEL["youngs_modulus"], STEEL["poisson_ratio"], STEEL["density"]
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    eps = lambda w: ufl.sym(ufl.grad(w))
    K = assemble_matrix(fem.form(ufl.inner(2 * mu * eps(u) + lam * ufl.tr(eps(u)) * ufl.Identity(3), eps(v)) * ufl.dx))
    K.assemble()
    M = assemble_matrix(fem.form(rho * ufl.inner(u, v) * ufl.dx))
    M.assemble()
    return K, M, quality


CASES = {
    "thin-Q2": lambda: thin_plate("Q2"), "thin-Q3": lambda: thin_plate("Q3"), "thin-S2R": lambda: thin_plate("S2R"),
    "thin-Q1": lambda: thin_plate("Q1"), "thinner-than-double": thinner_than_double,
    "workspace-S2R": thin_plate_indefinite_workspace,
    "repeated": repeated_eigenvalues, "cutoff": eigenvalue_at_cutoff, "free-bodies": free_bodies,
    "units": unit_systems, "resonance": resonance_light_damping,
    "thin-P2": thin_plate_tet, "thin-P2-refused": thin_plate_tet_refused, "gasket": gasket_locking,
    "contrast": stiffness_contrast, "stiff-bearing": stiff_bearing_light_node, "oil-whirl": oil_whirl,
    "contact-loss": contact_loss, "sliver": sliver,
}
QUICK = ("thin-S2R", "repeated", "cutoff", "units", "stiff-bearing", "oil-whirl")


def main(out_dir: Path, quick: bool = False) -> None:
    """Run the cases, print the table, write stability.csv / stability.md / stability.png atomically."""
    rows = []
    for name in (QUICK if quick else CASES):
        rows.append(CASES[name]())
        print(f"  {name}: {'ok' if rows[-1].ok else 'NOT OK'} ({rows[-1].cost_s:.1f} s)", flush=True)
    table = [r.row() for r in rows]
    print(format_table(HEADER, table))
    with atomic_output_dir(out_dir) as tmp:
        write_csv(tmp / "stability.csv", HEADER, table)
        (tmp / "stability.md").write_text("| " + " | ".join(HEADER) + " |\n|" + "---|" * len(HEADER) + "\n"
                                          + "".join("| " + " | ".join(map(str, r)) + " |\n" for r in table))
        _plot(rows, tmp / "stability.png")
    print(f"results: {out_dir}/")


def _plot(rows: list[CaseResult], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for r in rows:
        if r.error is not None and r.error > 0:
            ax.loglog(r.cost_s, r.error, "o" if r.ok else "x", color="tab:blue" if r.ok else "tab:red")
            ax.annotate(r.case.split(",")[0][:28], (r.cost_s, r.error), fontsize=7)
    ax.set_xlabel("cost (s, one core)")
    ax.set_ylabel("error against the reference (relative)")
    ax.set_title("housingfe bench stability: hard cases, error against cost")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


# ------------------------------------------------------------------------------------------ rank independence
def cube_multiplet_projections(n: int = 3, f_max: float = 30000.0) -> list[dict]:
    """The free cube's eigen-subspaces in a form that does not depend on the MPI partition: for each cluster of
    equal eigenvalues, the M-products of its (M-orthonormal) vectors with fixed probe fields P_ij = phi_i' M p_j
    (p_j: smooth analytic fields interpolated into the space).  Two runs span the same subspace iff the row
    spaces of their P agree (principal angles ~ 0), whatever basis each picked inside a multiplet.  Rank 0
    returns [{"frequency_hz", "size", "P"}], the other ranks []."""
    from dolfinx import fem

    from housingfe.solvers.modal import solve_modes

    K, M, V = cube_matrices(n)
    res = solve_modes(K, M, f_max)
    probes = []
    for j in range(12):
        p = fem.Function(V)
        a, b, c = 1 + j % 3, 1 + (j // 3) % 2, 1 + j // 6
        p.interpolate(lambda x, a=a, b=b, c=c: np.vstack([np.sin(a * 31 * x[0] + b * 17 * x[1]) * np.cos(c * 23 * x[2]),
                                                          np.cos(b * 29 * x[0] + c * 13 * x[2]) * x[1] * 10,
                                                          np.sin(c * 19 * x[1] + a * 11 * x[2]) + x[0] * b * 7]))
        Mp = M.createVecLeft()
        M.mult(p.vector, Mp)
        probes.append(Mp)
    lam = res.eigenvalues[res.rigid_count:]
    vectors = res.vectors[res.rigid_count:]
    out, start = [], 0
    for size in _clusters(lam, 1e-7):
        block = vectors[start:start + size]
        P = np.array([[x.dot(q) for q in probes] for x in block])
        out.append({"frequency_hz": float(np.sqrt(lam[start]) / (2 * np.pi)), "size": size, "P": P.tolist()})
        start += size
    return out if V.mesh.comm.rank == 0 else []


def principal_angles(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Principal angles (rad) between the row spaces of A and B (each rows x probes)."""
    import scipy.linalg

    return scipy.linalg.subspace_angles(np.asarray(A).T, np.asarray(B).T)


if __name__ == "__main__":   # `mpirun -n 2 python -m housingfe.benchmarks.stability --projections FILE`
    import json
    import sys

    if len(sys.argv) == 3 and sys.argv[1] == "--projections":
        data = cube_multiplet_projections()
        if data:
            Path(sys.argv[2]).write_text(json.dumps(data))
