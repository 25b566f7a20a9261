"""Block Krylov–Schur (housingfe.solvers.block_eigen): against dense LAPACK, against SLEPc, a double
eigenvalue, the scalar-mass products and their fall-back, and its limits."""
import math

import numpy as np
import pytest
from petsc4py import PETSc

from housingfe.errors import SolverError
from housingfe.scene import build_model_from_scene
from housingfe.solvers import block_eigen, modal, mumps
from tests.conftest import load_scene


def _dense(A):
    return A.copy().convert("dense").getDenseArray().copy()


def test_block_matches_dense_lapack_eigenpairs(comm):
    """Every eigenvalue below f_max within the accuracy of dense LAPACK (backward stable: |error| <~ eps
    lambda_max, 5e-5 rad^2/s^2 on this thin plate, i.e. 1e-7 of its lowest eigenvalue) and to 1e-10 of
    SLEPc's shift-and-invert; eigenvectors M-orthonormal (a small plate: 1 rank, dense matrices)."""
    import scipy.linalg

    if comm.size > 1:
        pytest.skip("dense comparison on one rank")
    model = build_model_from_scene(load_scene("nafems-fv12", "mesh.size=1.25", "mesh.degree=2"), comm)
    K, M = _dense(model.K), _dense(model.M)
    f_max = 20.0
    lam = scipy.linalg.eigh(K, M, eigvals_only=True)
    lapack_accuracy = 100 * np.finfo(float).eps * lam[-1]
    exact = lam[lam < (2 * math.pi * f_max) ** 2]
    assert len(exact) >= 20 and model.dofs >= 1000
    result = modal.solve_modes(model.K, model.M, f_max, method="block")
    assert result.eigensolver == "block" and result.complete
    elastic = exact > 1.0
    assert np.allclose(result.eigenvalues[elastic], exact[elastic], rtol=0, atol=lapack_accuracy)
    slepc = modal.solve_modes(model.K, model.M, f_max, method="slepc")
    # on the same transformed problem (SLEPc's shift, 1 % of f_max below zero) the two solvers agree to 1e-10;
    # the default block path factorises at f_max instead and agrees within the problem's own accuracy (above)
    same_shift = modal.solve_modes(model.K, model.M, f_max, method="block", shift_hz=0.01 * f_max)
    assert np.allclose(same_shift.eigenvalues[elastic], slepc.eigenvalues[elastic], rtol=1e-10, atol=0)
    assert np.allclose(result.eigenvalues[elastic], slepc.eigenvalues[elastic], rtol=0, atol=lapack_accuracy)
    assert result.rigid_count == int(np.sum(~elastic)) == 6
    X = np.column_stack([x.getArray() for x in result.vectors])
    assert np.allclose(X.T @ M @ X, np.eye(X.shape[1]), atol=1e-9)
    # ||K x - lambda M x|| / ||K x|| on a thin plate (SLEPc's own: up to 4e-6 here)
    assert np.max(result.residuals) < 1e-6


def test_block_and_slepc_agree_on_the_box_and_auto_picks_block(coarse_box_model):
    """The free box (15 k DOFs, 6 rigid + 14 elastic modes to 2.5 kHz): the two eigensolvers agree to 1e-10
    in every frequency and their modes pair one to one (|x_slepc^T M x_block| = 1 to 1e-8)."""
    K, M = coarse_box_model.K, coarse_box_model.M
    assert K.getSize()[0] >= modal.BLOCK_MIN_DOFS
    auto = modal.solve_modes(K, M, 2500.0)
    slepc = modal.solve_modes(K, M, 2500.0, method="slepc")
    assert auto.eigensolver == "block" and slepc.eigensolver == "slepc"
    assert auto.rigid_count == slepc.rigid_count == 6
    k = auto.rigid_count
    assert np.allclose(auto.eigenvalues[k:], slepc.eigenvalues[k:], rtol=1e-10, atol=0)
    overlap = [abs(x.dot(modal._mult(M, y))) for x, y in zip(auto.vectors[k:], slepc.vectors[k:])]
    assert min(overlap) > 1 - 1e-8
    assert auto.timings["eigensolve_block_solves"] > 0


def test_below_the_shift_gives_every_eigenpair_under_it_from_the_counts_factor(comm):
    """side="below" with nev = the inertia count of K - sigma M returns exactly the eigenvalues below sigma
    (sigma mid-spectrum, wanted and unwanted interleaved in |theta|), against dense LAPACK, on the very
    factorisation that counted them; a wrong side or ordering returns eigenvalues above sigma and fails."""
    import scipy.linalg

    if comm.size > 1:
        pytest.skip("dense comparison on one rank")
    model = build_model_from_scene(load_scene("nafems-fv12", "mesh.size=1.25", "mesh.degree=2"), comm)
    lam = scipy.linalg.eigh(_dense(model.K), _dense(model.M), eigvals_only=True)
    sigma = (2 * math.pi * 12.0) ** 2
    A = model.K.copy()
    A.axpy(-sigma, model.M)
    factor = mumps.ldlt(A)
    factor.factorise(A)
    count, null = factor.inertia()
    exact = lam[lam < sigma]
    assert null == 0 and count == len(exact) >= 15
    result = block_eigen.block_krylov_schur(factor, model.M, sigma, count, side="below")
    factor.destroy()
    assert np.all(result.eigenvalues < sigma) and np.all(np.diff(result.eigenvalues) >= 0)
    elastic = exact > 1.0
    # eigenvalue accuracy sigma + 1/theta: the tolerance times |lambda - sigma| <= sigma, plus LAPACK's own
    assert np.allclose(result.eigenvalues[elastic], exact[elastic], rtol=0,
                       atol=1e-9 * sigma + 100 * np.finfo(float).eps * lam[-1])
    with pytest.raises(ValueError, match="side must be one of"):
        block_eigen.block_krylov_schur(None, model.M, sigma, count, side="left")


def test_default_block_solve_uses_the_counts_factorisation_and_keeps_the_residuals(coarse_box_model):
    """solve_modes without nev, shift or kept solver factorises once (at f_max: no factorisation at a shift),
    finds what a shift below zero finds (to 1e-10, Rayleigh quotients) with residuals as small (< 1e-8)."""
    K, M = coarse_box_model.K, coarse_box_model.M
    one = modal.solve_modes(K, M, 2500.0, method="block")
    two = modal.solve_modes(K, M, 2500.0, method="block", shift_hz=25.0)
    assert one.timings["eigensolve_factor_s"] == 0.0 < two.timings["eigensolve_factor_s"]
    k = one.rigid_count
    assert k == two.rigid_count == 6
    assert np.allclose(one.eigenvalues[k:], two.eigenvalues[k:], rtol=1e-10, atol=0)
    assert np.max(one.residuals[k:]) < 1e-8 and np.max(two.residuals[k:]) < 1e-8


def test_rigid_body_motions_deflated_give_the_same_elastic_modes_with_fewer_solves(coarse_box_model):
    """The free box with its six exact rigid-body motions as null_space: they come back as the six zero modes
    (M-orthonormal, residuals no larger than the solved rigid modes'), the elastic eigenvalues equal the undeflated solve's to 1e-10 with
    residuals < 1e-8 and M-orthogonal to the rigid motions, with fewer block solves."""
    model = coarse_box_model
    K, M = model.K, model.M
    plain = modal.solve_modes(K, M, 2500.0, method="block")
    deflated = modal.solve_modes(K, M, 2500.0, method="block", null_space=model.rigid_body_vectors())
    assert deflated.timings["eigensolve_deflated"] == 6 and plain.timings["eigensolve_deflated"] == 0
    assert deflated.rigid_count == plain.rigid_count == 6 and deflated.complete
    assert np.allclose(deflated.eigenvalues[6:], plain.eigenvalues[6:], rtol=1e-10, atol=0)
    assert np.max(deflated.residuals[:6]) <= np.max(plain.residuals[:6]) and np.max(deflated.residuals[6:]) < 1e-8
    X = deflated.vectors
    G = np.array([[X[i].dot(modal._mult(M, X[j])) for j in range(len(X))] for i in range(len(X))])
    assert np.allclose(G, np.eye(len(X)), atol=1e-8)
    assert deflated.timings["eigensolve_block_solves"] < plain.timings["eigensolve_block_solves"]


def test_vectors_that_are_not_null_are_not_deflated(coarse_box_model):
    """A null_space that K does not annihilate (a rigid motion plus a bending-like perturbation) is refused by
    null_space_basis and the solve is the undeflated one: deflating it would drop a wrong vector's direction."""
    model = coarse_box_model
    K, M = model.K, model.M
    vectors = model.rigid_body_vectors()
    bent = vectors[0].copy()
    bent.getArray()[::7] += 1e-6
    assert modal.null_space_basis(K, M, vectors) is not None
    assert modal.null_space_basis(K, M, vectors[:5] + [bent]) is None
    result = modal.solve_modes(K, M, 2500.0, method="block", null_space=vectors[:5] + [bent])
    assert result.timings["eigensolve_deflated"] == 0 and result.rigid_count == 6 and result.complete


def test_modes_of_a_free_structure_deflate_its_rigid_motions(coarse_box_model):
    """modal.modes passes a free structure's rigid-body motions (expected_zero_modes 6) to the eigensolve."""
    basis = modal.modes(coarse_box_model, 2500.0)
    assert basis.timings["eigensolve_deflated"] == 6 and basis.rigid_count == 6 and basis.complete


def test_double_eigenvalue_is_resolved_as_a_pair(comm):
    """NAFEMS FV12's 4.233 Hz pair (square plate, symmetric mesh): both members found, equal to 1e-8 and
    M-orthogonal — a block method must not lose one of a multiple eigenvalue."""
    scene = load_scene("nafems-fv12")
    model = build_model_from_scene(scene, comm)
    result = modal.solve_modes(model.K, model.M, scene.analysis.modal.f_max, method="block")
    f = result.frequencies_hz[6:]
    assert f[3] == pytest.approx(4.233, rel=0.015) and abs(f[4] / f[3] - 1) < 1e-8
    assert abs(result.vectors[9].dot(modal._mult(model.M, result.vectors[10]))) < 1e-8


def test_mass_products_run_on_the_scalar_mass_and_equal_m_times_x(coarse_box_model):
    """The elastic mass is m ⊗ I3: the products use m (9x fewer entries) and equal M X to round-off."""
    M = coarse_box_model.M
    products = block_eigen.MassProducts(M)
    assert products.scalar is not None
    assert products.scalar.getSize()[0] * 3 == M.getSize()[0]
    X = np.random.default_rng(0).standard_normal((M.getLocalSize()[0], 5))
    reference = np.column_stack([_mult_array(M, X[:, j]) for j in range(5)])
    assert np.allclose(products(X), reference, rtol=0, atol=1e-13 * np.abs(reference).max())
    products.destroy()


def test_mass_products_fall_back_when_components_couple(coarse_box_model):
    """A mass that couples the components (one off-diagonal component entry) is not m ⊗ I: the full matrix is
    used, and the products are still M X."""
    M = coarse_box_model.M.copy()
    r0, _ = M.getOwnershipRange()
    M.setValue(r0, r0 + 1, 1e-3, addv=PETSc.InsertMode.ADD_VALUES)
    M.setValue(r0 + 1, r0, 1e-3, addv=PETSc.InsertMode.ADD_VALUES)
    M.assemble()
    products = block_eigen.MassProducts(M)
    assert products.scalar is None
    X = np.random.default_rng(1).standard_normal((M.getLocalSize()[0], 3))
    reference = np.column_stack([_mult_array(M, X[:, j]) for j in range(3)])
    assert np.allclose(products(X), reference, rtol=0, atol=1e-13 * np.abs(reference).max())


def test_too_small_a_model_is_refused_by_block_and_solved_by_auto(comm):
    """A basis larger than the model is a SolverError of the block method; method="auto" uses SLEPc below
    BLOCK_MIN_DOFS."""
    model = build_model_from_scene(load_scene("nafems-fv12", "mesh.size=2.5", "mesh.degree=1"), comm)
    n = model.dofs
    assert n < modal.BLOCK_MIN_DOFS
    P = model.K.copy()
    P.axpy(1.0, model.M)
    ksp = mumps.mumps_cholesky(P, "small_")
    ksp.setUp()
    with pytest.raises(SolverError, match=f"basis of {n + 8} vectors for {n} DOFs"):
        block_eigen.block_krylov_schur(ksp.getPC().getFactorMatrix(), model.M, -1.0, 10, max_basis=n)
    result = modal.solve_modes(model.K, model.M, 8.0)
    assert result.eigensolver == "slepc" and result.complete


def test_unknown_eigensolver_is_named():
    with pytest.raises(ValueError, match="unknown eigensolver 'lanczos'"):
        modal.solve_modes(None, None, 100.0, method="lanczos")


def _mult_array(M, x):
    v = M.createVecRight()
    v.getArray()[:] = x
    return modal._mult(M, v).getArray().copy()
