"""FE coupling (housingfe.drivetrain.coupling) against analytic answers: a stiff block on a 6x6 spring (rigid-body
spring-mass eigenproblem), RBE3 adds no stiffness, star rods -> RBE2, a pinned-pinned Timoshenko shaft on
bearings, two gears on a mesh spring, the direct harmonic solver with non-symmetric bearing matrices, the
total mass from the rigid-body vectors, and 1 against 2 MPI ranks."""
import json
import math
import re
import shutil
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.linalg as sl
from scipy.optimize import brentq

from housingfe.drivetrain import coupling as cp
from housingfe.drivetrain import interior
from housingfe.drivetrain.shafts import CircularSection, RigidDisc, Shaft
from housingfe.errors import InputError
from housingfe.scene import build_model_from_scene
from housingfe.solvers import elasticity, harmonic, modal
from tests.conftest import load_scene, mumps_solve
from tests.two_ranks import module_result

A, B, H, RHO = 0.2, 0.1, 0.05, 7850.0            # block (m, kg/m^3)
K_SPRING = np.diag([1e6, 2e6, 3e6, 1e4, 2e4, 0.5e4])   # N/m, N m/rad: rigid-body modes 55..190 Hz
BOTTOM_CENTRE = (A / 2, B / 2, 0.0)


def block_scene(E, *extra, rho=RHO):
    return load_scene("nafems-fv12", f"geometry.a={A}", f"geometry.b={B}", f"geometry.h={H}", "mesh.size=0.05",
                      f"material.youngs_modulus={E}", f"material.density={rho}", "analysis.modal.f_max=200.0",
                      *extra)


@pytest.fixture(scope="module")
def stiff_block(comm):
    """A block 100x stiffer than steel: its first elastic mode is far above the spring modes."""
    return build_model_from_scene(block_scene(2.1e13), comm)


@pytest.fixture(scope="module")
def steel_block(comm):
    return build_model_from_scene(block_scene(2.1e11), comm)


def rigid_block_frequencies(k6, master):
    """Exact 6-DOF spring-mass frequencies (Hz) of the block on a spring at `master` (DOFs at the master)."""
    mass = RHO * A * B * H
    mc = np.zeros((6, 6))
    mc[:3, :3] = mass * np.eye(3)
    mc[3:, 3:] = mass / 12 * np.diag([B**2 + H**2, A**2 + H**2, A**2 + B**2])
    t = np.zeros((6, 6))
    t[:3] = cp.rigid_arm(np.array([A / 2, B / 2, H / 2]) - np.asarray(master))
    t[3:, 3:] = np.eye(3)
    return np.sqrt(sl.eigh(k6, t.T @ mc @ t, eigvals_only=True)) / (2 * math.pi)


def coupled_frequencies(model, kind, f_max=200.0, **kw):
    con = cp.BoreConnection("bore", "bottom", BOTTOM_CENTRE, (0, 0, 1), kind, **kw)
    system = cp.couple(model, [con], [cp.spring("bore", None, K_SPRING)])
    return modal.solve_modes(system.K, system.M, f_max).frequencies_hz


@pytest.mark.parametrize("kind", ["rbe2", "rbe3"])
def test_rigid_block_on_spring_has_analytic_frequencies(stiff_block, kind):
    exact = rigid_block_frequencies(K_SPRING, BOTTOM_CENTRE)
    f = coupled_frequencies(stiff_block, kind)
    assert len(f) == 6          # complete by the inertia count, no rigid or spurious modes
    assert np.max(np.abs(f / exact - 1)) < 1e-5


def test_rbe2_bore_follows_master_in_fe_vector(stiff_block):
    """Map back to the FE model: on the bore, the housing displacement of a mode is u_m + theta_m x r."""
    con = cp.BoreConnection("bore", "bottom", BOTTOM_CENTRE, (0, 0, 1), "rbe2")
    system = cp.couple(stiff_block, [con], [cp.spring("bore", None, K_SPRING)])
    q = modal.solve_modes(system.K, system.M, 200.0).vectors[2]
    u = system.fe_vector(q, stiff_block.V).getArray().reshape(-1, 3)
    um = system.node_displacement(q, "bore")
    nodes, _ = cp.surface_nodes(stiff_block, "bottom")
    x = stiff_block.V.tabulate_dof_coordinates()[nodes]
    expected = um[:3] + np.cross(um[3:], x - np.asarray(BOTTOM_CENTRE))
    assert np.allclose(u[nodes], expected, rtol=0, atol=1e-12 * np.abs(expected).max())


def test_rbe3_reproduces_rigid_motions_exactly():
    rng = np.random.default_rng(1)
    r, w = rng.normal(size=(12, 3)), rng.uniform(0.1, 1.0, 12)
    R = cp.rbe3_matrix(r, w)
    arms = np.concatenate([cp.rigid_arm(ri) for ri in r])
    assert np.allclose(R @ arms, np.eye(6), atol=1e-12)
    # translation part of a pure translation field = area-weighted mean
    u = rng.normal(size=3)
    assert np.allclose(R[:3] @ np.tile(u, 12), u)


BOX_F_MAX = 1500.0      # Hz: six rigid + a few elastic modes of the coarse free box, keeps the tests fast


@pytest.fixture(scope="module")
def bare_box(coarse_box_model):
    return modal.solve_modes(coarse_box_model.K, coarse_box_model.M, BOX_F_MAX)


def test_rbe3_adds_no_stiffness_rbe2_stiffens(coarse_box_model, bare_box):
    m, bare, f_max = coarse_box_model, bare_box, BOX_F_MAX
    point = (0.0, 0.0, 0.125)
    for kind in ("rbe3", "rbe2"):
        system = cp.couple(m, [cp.BoreConnection("top", "outer_top", point, (0, 0, 1), kind)])
        r = modal.solve_modes(system.K, system.M, f_max)
        assert r.rigid_count == 6, kind
        el, el0 = r.frequencies_hz[6:], bare.frequencies_hz[6:]
        if kind == "rbe3":
            assert len(el) == len(el0)
            assert np.max(np.abs(el / el0 - 1)) < 1e-8
        else:   # a rigid top plate: stiffer, every frequency up (fewer modes below f_max)
            assert len(el) <= len(el0) and np.all(el >= el0[:len(el)] * (1 - 1e-9))
            assert el[0] > 1.01 * el0[0]


def test_rbe3_master_mass_no_spurious_modes(coarse_box_model, bare_box):
    """A mass on an RBE3 master: still six rigid modes, the total mass moves with them, frequencies drop."""
    m, bare, f_max = coarse_box_model, bare_box, BOX_F_MAX
    system = cp.couple(m, [cp.BoreConnection("top", "outer_top", (0.0, 0.0, 0.125), (0, 0, 1), "rbe3")],
                       [cp.point_mass("top", np.diag([2.0, 2.0, 2.0, 1e-3, 1e-3, 1e-3]))])
    r = modal.solve_modes(system.K, system.M, f_max)
    assert r.rigid_count == 6 and r.complete
    assert np.all(r.frequencies_hz[6:len(bare.eigenvalues)] <= bare.frequencies_hz[6:len(r.eigenvalues)] + 1e-9)
    # a rigid x-translation of the housing carries the master along exactly: mass = box + 2 kg
    q = system.K.createVecRight()
    q.set(0.0)
    q.getArray()[:system.n_fe:3] = 1.0
    Mq = system.M.createVecLeft()
    system.M.mult(q, Mq)
    mass_box = m.housing.volume * m.material.density
    assert abs(q.dot(Mq) - (mass_box + 2.0)) < 1e-3 * mass_box
    assert np.allclose(system.node_displacement(q, "top"), [1, 0, 0, 0, 0, 0], atol=1e-12)


def test_star_rods_converge_to_rbe2(steel_block):
    """Star rods are a penalty: the frequencies rise monotonically towards RBE2 with an error ~ 1/k."""
    exact_rigid = rigid_block_frequencies(K_SPRING, BOTTOM_CENTRE)
    rbe2 = coupled_frequencies(steel_block, "rbe2")
    errors = []
    for k in (1e6, 1e8, 1e10):
        f = coupled_frequencies(steel_block, "star", rod_stiffness=k)
        assert np.all(f <= rbe2 * (1 + 1e-9))
        errors.append(np.max(np.abs(f / rbe2 - 1)))
    assert errors[0] > 1e-3                       # soft rods: a visible error
    assert errors[2] < 2e-5
    assert 50 < errors[1] / errors[2] < 200       # ~ 1/k
    assert np.max(np.abs(rbe2 / exact_rigid - 1)) < 1e-4   # the steel block is nearly rigid


def test_pinned_shaft_on_bearings_matches_timoshenko(comm):
    """A shaft on two bearing springs (stiff radially/axially, free in tilt and spin) to masters tied by RBE2
    to a free block of 10^6 kg (rigid up to ~10 kHz): the pinned-pinned Timoshenko bending frequency; seven
    rigid modes (the block's six and the shaft's spin)."""
    model = build_model_from_scene(block_scene(2.1e16, rho=1e9), comm)
    L, d = 0.5, 0.02
    shaft = Shaft.stepped([(L / 2, d), (L / 2, d)], origin=(A / 2, B / 2, 0.0), axis=(1, 0, 0),
                          elements_per_segment=10)
    k = np.diag([1e12, 1e12, 1e12, 0.0, 0.0, 0.0])
    cons = [cp.BoreConnection("b1", "bottom", (A / 2, B / 2, 0.0), (1, 0, 0)),
            cp.BoreConnection("b2", "top", (A / 2 + L, B / 2, 0.0), (1, 0, 0))]
    system = cp.couple(model, cons, [cp.spring("s:0", "b1", k), cp.spring("s:20", "b2", k)],
                       shafts={"s": shaft})
    r = modal.solve_modes(system.K, system.M, 2000.0)
    assert r.rigid_count == 7
    sec, mat = CircularSection(d), shaft.material
    kn = math.pi / L
    EI, rA, rI, kGA = mat.youngs_modulus * sec.second_moment, mat.density * sec.area, mat.density * sec.second_moment, \
        sec.shear_factor(mat.poisson_ratio) * mat.shear_modulus * sec.area
    # Timoshenko, simply supported, mode 1: rI rA/kGA w^4 - (rA + rI k^2 + EI rA k^2/kGA) w^2 + EI k^4 = 0
    w2 = min(np.roots([rI * rA / kGA, -(rA + rI * kn**2 + EI * rA * kn**2 / kGA), EI * kn**4]).real)
    f1 = math.sqrt(w2) / (2 * math.pi)
    bending = r.frequencies_hz[7:9]              # the two planes
    assert np.max(np.abs(bending / f1 - 1)) < 1e-4


def test_gear_mesh_torsion(comm):
    """Two gears (rigid discs) on stiff supports, coupled by a mesh spring on the line of action:
    one rigid mode (the train turns) and omega^2 = k (r1^2/J1 + r2^2/J2)."""
    model = build_model_from_scene(block_scene(2.1e13, 'geometry.edges={x0="clamped", x1="clamped", y0="free", y1="free"}'),
                        comm)
    r1, r2, k_mesh = 0.05, 0.08, 1e7
    g1, g2 = RigidDisc.cylinder(2 * r1, 0.02), RigidDisc.cylinder(2 * r2, 0.02)
    nodes = {"g1": (0.0, 0.0, 0.5), "g2": (r1 + r2, 0.0, 0.5)}
    # a bearing matrix with a (wrong) spin stiffness: cp.bearing must free the rotation about the shaft axis
    local = np.diag([1e15, 1e15, 1e15, 1e12, 1e12, 1e9])
    elements = [cp.point_mass("g1", g1.mass_matrix((0, 0, 1))), cp.point_mass("g2", g2.mass_matrix((0, 0, 1))),
                cp.bearing("g1", None, local, (0, 0, 1)), cp.bearing("g2", None, local, (0, 0, 1))]
    mesh = cp.GearMesh("g1", "g2", k_mesh, point=(r1, 0.0, 0.5), direction=(0.0, 1.0, 0.0))
    system = cp.couple(model, [], elements, gear_meshes=[mesh], extra_nodes=nodes)
    res = modal.solve_modes(system.K, system.M, 2000.0)
    exact = math.sqrt(k_mesh * (r1**2 / g1.polar_inertia + r2**2 / g2.polar_inertia)) / (2 * math.pi)
    assert res.rigid_count == 1
    assert abs(res.frequencies_hz[1] / exact - 1) < 1e-5


def test_tie_rod_axial_mode(stiff_block):
    """A tie rod (beam) from a grounded node to a 10 kg mass free only along the rod: the rod-with-tip-mass
    frequency beta c / L, beta tan beta = m_rod / m_tip (Rayleigh: one element is within ~1e-4)."""
    L, d, m_tip = 0.3, 0.02, 10.0
    sec = CircularSection(d)
    ground = np.diag([1e14] * 6)
    slide = np.diag([0.0] + [1e14] * 5)                    # free along x only
    system = cp.couple(stiff_block, [], [cp.spring("a", None, ground), cp.spring("b", None, slide),
                                         cp.point_mass("b", np.diag([m_tip] * 3 + [0.0] * 3))],
                       tie_rods=[cp.TieRod("a", "b", sec)], extra_nodes={"a": (0.0, 0.0, 0.3), "b": (L, 0.0, 0.3)})
    res = modal.solve_modes(system.K, system.M, 1000.0)
    steel = Shaft.stepped([(L, d)]).material
    ratio = steel.density * sec.area * L / m_tip
    beta = brentq(lambda b: b * math.tan(b) - ratio, 1e-6, 1.0)
    exact = beta * math.sqrt(steel.youngs_modulus / steel.density) / L / (2 * math.pi)
    assert res.rigid_count == 6 and len(res.eigenvalues) == 7      # the free block's six + the rod
    assert abs(res.frequencies_hz[6] / exact - 1) < 1e-3


def test_harmonic_solvers_on_coupled_system(stiff_block):
    """Harmonic solvers unchanged on (K_c, M_c): a force on the master of the block on its spring gives the static
    deflection K_spring^-1 F at 0.1 Hz (inertia ~ (0.1/55)^2 ~ 3e-6), and modal superposition + residual equals
    the direct solution on the spring modes."""
    con = cp.BoreConnection("bore", "bottom", BOTTOM_CENTRE, (0, 0, 1), "rbe3")
    system = cp.couple(stiff_block, [con], [cp.spring("bore", None, K_SPRING)])
    force = np.array([100.0, -50.0, 30.0, 2.0, -1.0, 0.5])           # N, N m
    load = SimpleNamespace(vector=system.load(node_loads={"bore": force}))
    damping = harmonic.Damping(eta=lambda f: np.full(np.shape(f), 0.01))

    def reduce(vecs):
        return np.array([system.node_displacement(v, "bore") for v in vecs])

    def master(res, k):
        blk = next(b for b in res.blocks[0] if k in b.index)
        return blk.reduced.T @ blk.coeffs[:, list(blk.index).index(k)]

    freqs = np.array([0.1, 70.0, 150.0])
    direct = harmonic.direct(system.K, system.M, [load], freqs, damping, reduce)
    static = np.linalg.solve(K_SPRING, force)
    u0 = master(direct, 0)
    assert np.linalg.norm(u0 - static / (1 + 0.01j)) < 1e-5 * np.linalg.norm(static)   # hysteretic: K (1 + i eta)
    modes = modal.solve_modes(system.K, system.M, 2000.0)
    sup = harmonic.modal_superposition(system.K, system.M, modes, [load], freqs, damping, reduce)
    for k in range(len(freqs)):
        d, m = master(direct, k), master(sup, k)
        assert np.linalg.norm(m - d) < 1e-6 * np.linalg.norm(d)


def test_direct_harmonic_with_nonsymmetric_bearing(stiff_block):
    """A journal bearing (Ocvirk short bearing: non-symmetric K, cross-coupled C) plus K_SPRING on the master:
    the direct solver (LU via its options prefix) agrees with a dense complex solve of (K + i w C - w^2 M) q = f."""

    from housingfe.bearings import JournalBearing, short_bearing_coefficients

    film = short_bearing_coefficients(JournalBearing(0.05, 0.025, 50e-6, 0.02), 300.0, (0.0, -1000.0))
    con = cp.BoreConnection("bore", "bottom", BOTTOM_CENTRE, (0, 0, 1), "rbe3")
    system = cp.couple(stiff_block, [con], [cp.bearing("bore", None, K_SPRING + film.K, (0, 0, 1), film.C)])
    assert not system.symmetric
    f = system.load(node_loads={"bore": [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]})
    freqs = np.array([60.0, 90.0])
    # the direct solver sees the non-symmetric matrices and factorises with LU by itself
    res = harmonic.direct(system.K, system.M, [SimpleNamespace(vector=f)], freqs,
                          harmonic.Damping(eta=lambda x: np.zeros_like(x)),
                          lambda vecs: np.array([v.getArray().copy() for v in vecs]), C=system.C)
    n = system.size
    dense = [system.K.getValues(range(n), range(n)), system.M.getValues(range(n), range(n)),
             system.C.getValues(range(n), range(n))]
    for blk in res.blocks[0]:
        w = 2 * math.pi * freqs[blk.index[0]]
        u = (blk.reduced.T @ blk.coeffs)[:, 0]
        ref = np.linalg.solve(dense[0] + 1j * w * dense[2] - w * w * dense[1], f.getArray())
        assert np.linalg.norm(u - ref) < 1e-6 * np.linalg.norm(ref)   # cond(K) ~ 1e11 (stiff block)


def test_bad_input():
    with pytest.raises(InputError):
        cp.BoreConnection("b", "bottom", (0, 0, 0), kind="rbe4")
    with pytest.raises(InputError):
        cp.BoreConnection("b", "bottom", (0, 0, 0), kind="star")
    with pytest.raises(InputError):
        cp.spring("a", None, np.eye(5))


def test_gearbox_with_real_bores(comm):
    """The benchmark's gearbox: four round bores RBE2-tied, shafts on SKF bearings, gears on a mesh spring.
    Free-free: the housing's six rigid modes plus the turning gear train, no others; every mode below f_max
    found (inertia count)."""
    from housingfe.benchmarks.coupling import gearbox_parts

    model = build_model_from_scene(load_scene("gearbox-model", "mesh.size=0.04", "analysis.modal.f_max=600.0"), comm)
    system = cp.couple(model, **gearbox_parts(model, "rbe2"))
    res = modal.solve_modes(system.K, system.M, 600.0)
    assert res.rigid_count == 7 and res.complete
    assert system.symmetric


SPEC = """
[[bores]]
name = "bore"
surface = "bottom"
axis = [0.0, 0.0, 1.0]
kind = "rbe3"

[[bearings]]
shaft_node = "bore"          # the master itself, to ground
axis = [0.0, 0.0, 1.0]
stiffness = [1e6, 2e6, 3e6, 1e4, 2e4, 0.5e4]

[[shafts]]
name = "s"
origin = [0.1, 0.05, -0.3]
axis = [0.0, 0.0, 1.0]
segments = [[0.1, 0.02], [0.1, 0.02]]
elements_per_segment = 2
discs = [{ node = 2, outer_diameter = 0.05, width = 0.01 }]

[[bearings]]
shaft_node = "s:0"
designation = "SKF 6312"
load = [5000.0, 0.0, 0.0, 0.0, 0.0]

[[tie_rods]]
a = "s:4"
b = "bore"
diameter = 0.01
"""


def test_scene_section(stiff_block):
    """The [coupling] section: the block part of the model gives the spring-mass answer (bottom-face centre from
    the surface's bounding box; the bearing() frame frees the spin, so one rigid mode), shafts, bearings from the
    catalogue and tie rods are built; unknown keys are errors that name the key."""
    import tomllib

    spec = tomllib.loads(SPEC)
    only_block = {"bores": spec["bores"], "bearings": spec["bearings"][:1]}
    system = interior.couple_from_spec(stiff_block, only_block)
    assert np.allclose(system.nodes["bore"][0], BOTTOM_CENTRE)
    res = modal.solve_modes(system.K, system.M, 200.0)
    f = res.frequencies_hz
    k6 = K_SPRING.copy()
    k6[5, 5] = 0.0
    exact = rigid_block_frequencies(k6 + 1e-9 * np.eye(6), BOTTOM_CENTRE)
    assert res.rigid_count == 1 and np.max(np.abs(f[1:] / exact[1:] - 1)) < 1e-5
    full = interior.couple_from_spec(stiff_block, spec)
    assert {"s:0", "s:4"} <= set(full.nodes) and full.size == system.size + 30
    bad = dict(spec, bores=[dict(spec["bores"][0], kindd="rbe2")])
    with pytest.raises(InputError, match="kindd"):
        interior.couple_from_spec(stiff_block, bad)


def test_rigid_body_vectors_give_total_mass_and_centre(coarse_box_model, bare_box):
    """rigid_body_vectors + the coupled rigid modes (the free box's six and the shaft's spin): the mass is the box's
    plus the shaft's and the disc's, the centre of gravity their weighted mean; expand/restrict round trip."""
    m = coarse_box_model
    top = cp.surface_centre(m, "outer_top")
    L, d = 0.2, 0.03
    shaft = Shaft.stepped([(L, d)], origin=top, axis=(0, 0, 1), elements_per_segment=4)
    disc = RigidDisc.cylinder(0.1, 0.02)
    shaft.add_disc(4, disc)
    system = cp.couple(m, [cp.BoreConnection("top", "outer_top", tuple(top), (0, 0, 1), "rbe2")],
                       [cp.bearing("s:0", "top", np.diag([1e9, 1e9, 1e9, 1e6, 1e6, 0.0]), (0, 0, 1))],
                       shafts={"s": shaft})
    res = modal.solve_modes(system.K, system.M, 50.0)        # below the first elastic mode: the rigid ones
    assert res.rigid_count == 7 and len(res.eigenvalues) == 7
    rigid = system.rigid_body_vectors(m.V)
    props = modal.rigid_body_mass_properties(system.M, res.vectors, rigid)
    box = modal.rigid_body_mass_properties(m.M, bare_box.vectors[:6], elasticity.rigid_body_vectors(m.V))
    m_shaft = shaft.material.density * CircularSection(d).area * L
    total = box["mass_kg"] + m_shaft + disc.mass
    centre = (box["mass_kg"] * box["centre_of_gravity_m"] + m_shaft * (top + [0, 0, L / 2])
              + disc.mass * shaft.nodes[4]) / total
    assert abs(props["mass_kg"] / total - 1) < 1e-8
    assert np.allclose(props["centre_of_gravity_m"], centre, rtol=0, atol=1e-8)
    assert props["projection_defect"] < 1e-6
    # the rigid fields satisfy the constraints: expand then restrict gives them back; the master moves rigidly
    for i, q in enumerate(rigid):
        back = system.restrict(system.expand(q))
        back.axpy(-1.0, q)
        assert back.norm() == 0.0
        expected = np.eye(6)[i] if i < 3 else np.r_[np.cross(np.eye(3)[i - 3], top), np.eye(3)[i - 3]]
        assert np.allclose(system.node_displacement(q, "top"), expected, rtol=0, atol=1e-12)


def mpi_case(model) -> dict:
    """What the 1-against-2-rank test compares, on the steel block (a condition number ~100x below the stiff
    block's, so round-off stays far below 1e-8): the block on its spring through rbe2 and rbe3, and through star
    rods with a shaft (disc, bearing to the master, a soft spin spring); for the last, a static solve of an FE
    load plus node loads, mapped back with expand, fe_vector, node_displacement, and the mass of its rigid-body
    vectors."""
    from petsc4py import PETSc

    comm = model.V.mesh.comm
    out = {"ranks": comm.size, "bore_nodes": comm.allgather(len(cp.surface_nodes(model, "bottom")[0]))}
    for kind in ("rbe2", "rbe3"):
        out[kind] = coupled_frequencies(model, kind).tolist()
    shaft = Shaft.stepped([(0.1, 0.03)], origin=(A / 2, B / 2, -0.15), axis=(0, 0, 1), elements_per_segment=2)
    shaft.add_disc(0, RigidDisc.cylinder(0.08, 0.02))
    con = cp.BoreConnection("bore", "bottom", BOTTOM_CENTRE, (0, 0, 1), "star", rod_stiffness=1e10)
    elements = [cp.spring("bore", None, K_SPRING),
                cp.bearing("s:2", "bore", np.diag([1e7, 1e7, 1e7, 1e4, 1e4, 0.0]), (0, 0, 1)),
                cp.spring("s:0", None, np.diag([0.0, 0.0, 0.0, 0.0, 0.0, 1e3]))]
    system = cp.couple(model, [con], elements, shafts={"s": shaft})
    out["star"] = modal.solve_modes(system.K, system.M, 600.0).frequencies_hz.tolist()

    f = system.load(elasticity.rigid_body_vectors(model.V)[2],             # 1 N along z on every FE node
                    {"s:0": [0.0, 100.0, 0.0, 0.0, 0.0, 5.0], "bore": [0.0, 0.0, 0.0, 1.0, 0.0, 0.0]})
    q = mumps_solve(system.K, f)
    u = system.expand(q)
    back = system.restrict(u)
    back.axpy(-1.0, q)
    out["restrict_error"] = back.norm(PETSc.NormType.INFINITY) / q.norm(PETSc.NormType.INFINITY)
    out["compliance"] = f.dot(q)
    out["u_norm"] = u.norm()
    out["fe_norm"] = system.fe_vector(q, model.V).norm()
    for name in ("bore", "s:0"):
        value = system.node_displacement(q, name)
        out["same_on_all_ranks_" + name] = all(np.array_equal(v, value) for v in comm.allgather(value))
        out[name] = value.tolist()
    tx = system.rigid_body_vectors(model.V)[0]
    Mt = system.M.createVecLeft()
    system.M.mult(tx, Mt)
    out["mass"] = tx.dot(Mt)
    out["size"] = system.size
    return out


@pytest.mark.mpi
def garbage_entries(comm, capfd) -> int:
    """Number of PETSc objects parked in comm's garbage list (petsc4py 3.18: what Python dropped, not yet freed)."""
    from petsc4py import PETSc

    capfd.readouterr()
    PETSc.garbage_view(comm)
    out = capfd.readouterr().out
    return int(re.search(r"Total entries: (\d+)", out).group(1))


def test_dropped_coupled_systems_are_freed(stiff_block, capfd):
    """petsc4py 3.18 does not destroy a Mat whose Python object dies; it parks it until PETSc.garbage_cleanup.
    couple() cleans up first, so repeated re-analyses hold at most one dropped system: before, every coupled
    K, M, P stayed (~55 MB per build_interior on the 60 mm test gearbox mesh)."""
    con = cp.BoreConnection("bore", "bottom", BOTTOM_CENTRE, (0, 0, 1), "rbe3")
    comm = stiff_block.K.getComm()
    counts = []
    for _ in range(4):
        cp.couple(stiff_block, [con], [cp.spring("bore", None, K_SPRING)])     # dropped at once
        counts.append(garbage_entries(comm, capfd))
    assert counts[0] >= 3                   # K, M, P of the dropped system are parked, not freed ...
    assert counts == [counts[0]] * 4        # ... until the next coupling frees them: no growth per call


def test_dropped_housing_fields_are_freed(stiff_block, capfd):
    """dolfinx 0.5.2 makes a housing field (fe_vector) on its IndexMap's own duplicated communicator, not the
    matrices' one that couple() cleans: every field dropped stayed parked (each coupled basis maps its 40-90 Ritz
    vectors to the housing: ~6 MB per basis on the 80 mm test gearbox mesh, ~12 MB per rebuilt base with the
    modes').  fe_vector now frees the ones dropped before it, release_fe_garbage the last ones."""
    from dolfinx import la

    con = cp.BoreConnection("bore", "bottom", BOTTOM_CENTRE, (0, 0, 1), "rbe2")
    system = cp.couple(stiff_block, [con], [cp.spring("bore", None, K_SPRING)])
    q = system.K.createVecRight()
    q.set(1.0)
    V = stiff_block.V
    held = la.create_petsc_vector(V.dofmap.index_map, V.dofmap.index_map_bs)     # holds their communicator
    comm = held.getComm()
    counts = []
    for _ in range(5):
        system.fe_vector(q, V)                                                   # dropped at once
        counts.append(garbage_entries(comm, capfd))
    assert counts == [1] * 5                  # the last one parked, the earlier ones freed: no growth per field
    cp.release_fe_garbage(V)
    assert garbage_entries(comm, capfd) == 0
    held.destroy()


def test_two_ranks_give_the_serial_answer(steel_block):
    """rbe2, rbe3, star rods + shaft: frequencies, a static solve mapped back, node displacements (the same on every
    rank) and the coupled mass agree between 1 rank (here) and 2 ranks (mpirun, below)."""
    one = mpi_case(steel_block)
    mass = RHO * A * B * H + Shaft.stepped([(0.1, 0.03)]).material.density * CircularSection(0.03).area * 0.1 \
        + RigidDisc.cylinder(0.08, 0.02).mass
    assert abs(one["mass"] / mass - 1) < 1e-10 and one["restrict_error"] < 1e-14
    if not shutil.which("mpirun"):
        pytest.skip("mpirun not installed")
    two = module_result("tests.drivetrain.test_coupling")
    assert two["ranks"] == 2 and min(two["bore_nodes"]) > 0        # the bore is split between the ranks
    assert sum(two["bore_nodes"]) == one["bore_nodes"][0] and two["size"] == one["size"]
    for kind in ("rbe2", "rbe3", "star"):
        assert len(two[kind]) == len(one[kind])
        assert np.max(np.abs(np.divide(two[kind], one[kind]) - 1)) < 1e-8, kind
    for key in ("compliance", "u_norm", "fe_norm", "mass"):
        assert abs(two[key] / one[key] - 1) < 1e-8, key
    for name in ("bore", "s:0"):
        assert two["same_on_all_ranks_" + name]
        assert np.linalg.norm(np.subtract(two[name], one[name])) < 1e-8 * np.linalg.norm(one[name]), name
    assert two["restrict_error"] < 1e-14


if __name__ == "__main__":       # mpirun -n 2 python -m tests.drivetrain.test_coupling: the 2-rank half of the test above
    from mpi4py import MPI

    result = mpi_case(build_model_from_scene(block_scene(2.1e11), MPI.COMM_WORLD))
    if MPI.COMM_WORLD.rank == 0:
        print(json.dumps(result))
