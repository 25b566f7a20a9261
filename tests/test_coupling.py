"""FE coupling (housingfe.coupling) against analytic answers: a stiff block on a 6x6 spring (rigid-body
spring-mass eigenproblem), RBE3 adds no stiffness, star rods -> RBE2, a pinned-pinned Timoshenko shaft on
bearings, two gears on a mesh spring, and the direct harmonic solver with non-symmetric bearing matrices."""
import math
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.linalg as sl
from scipy.optimize import brentq

from housingfe import coupling as cp
from housingfe import interior
from housingfe.errors import InputError
from housingfe.model import build_model
from housingfe.shafts import CircularSection, RigidDisc, Shaft
from housingfe.solvers import harmonic, modal
from tests.conftest import load_scene

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
    return build_model(block_scene(2.1e13), comm)


@pytest.fixture(scope="module")
def steel_block(comm):
    return build_model(block_scene(2.1e11), comm)


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
    model = build_model(block_scene(2.1e16, rho=1e9), comm)
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
    EI, rA, rI, kGA = mat.E * sec.second_moment, mat.rho * sec.area, mat.rho * sec.second_moment, \
        sec.shear_factor(mat.nu) * mat.G * sec.area
    # Timoshenko, simply supported, mode 1: rI rA/kGA w^4 - (rA + rI k^2 + EI rA k^2/kGA) w^2 + EI k^4 = 0
    w2 = min(np.roots([rI * rA / kGA, -(rA + rI * kn**2 + EI * rA * kn**2 / kGA), EI * kn**4]).real)
    f1 = math.sqrt(w2) / (2 * math.pi)
    bending = r.frequencies_hz[7:9]              # the two planes
    assert np.max(np.abs(bending / f1 - 1)) < 1e-4


def test_gear_mesh_torsion(comm):
    """Two gears (rigid discs) on stiff supports, coupled by a mesh spring on the line of action:
    one rigid mode (the train turns) and omega^2 = k (r1^2/J1 + r2^2/J2)."""
    model = build_model(block_scene(2.1e13, 'geometry.edges={x0="clamped", x1="clamped", y0="free", y1="free"}'),
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
    ratio = steel.rho * sec.area * L / m_tip
    beta = brentq(lambda b: b * math.tan(b) - ratio, 1e-6, 1.0)
    exact = beta * math.sqrt(steel.E / steel.rho) / L / (2 * math.pi)
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

    model = build_model(load_scene("gearbox-model", "mesh.size=0.04", "analysis.modal.f_max=600.0"), comm)
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
