"""Modal solver: verification against NAFEMS FV12 and plate theory, completeness, rigid-body checks."""
import math

import numpy as np
import pytest

from housingfe.errors import SolverError
from housingfe.scene import build_model_from_scene
from housingfe.solvers import elasticity, modal
from tests.conftest import load_scene


def test_nafems_fv12_free_square_plate(comm):
    """NAFEMS FV12 thin-plate reference values within 1.5 %, the 4.233 Hz pair resolved as a pair.

    The structured square hex mesh keeps the plate's 90-degree symmetry, so the pair cannot split."""
    scene = load_scene("nafems-fv12")
    model = build_model_from_scene(scene, comm)
    result = modal.solve_modes(model.K, model.M, scene.analysis.modal.f_max)
    f = result.frequencies_hz[6:]
    reference = np.array([1.622, 2.360, 2.922, 4.233, 4.233, 7.416])
    assert np.all(np.abs(f[:6] / reference - 1) < 0.015), f[:6]
    assert abs(f[4] - f[3]) / f[3] < 1e-6


def test_simply_supported_square_plate_matches_kirchhoff(comm):
    """Simply supported thin plate: f_11 = (pi/2) (2/a^2) sqrt(D / (rho h)) within 1 %."""
    a, h = 1.0, 0.01
    scene = load_scene("nafems-fv12", f"geometry.a={a}", f"geometry.b={a}", f"geometry.h={h}",
                       "mesh.size=0.0625", "analysis.modal.f_max=130.0",
                       'geometry.edges={x0="simply_supported",x1="simply_supported",'
                       'y0="simply_supported",y1="simply_supported"}')
    model = build_model_from_scene(scene, comm)
    m = model.material
    D = m.youngs_modulus * h**3 / (12 * (1 - m.poisson_ratio**2))
    f11 = math.pi / 2 * (2 / a**2) * math.sqrt(D / (m.density * h))
    result = modal.solve_modes(model.K, model.M, 1.2 * f11)
    # w = 0 on the edges leaves the three in-plane rigid motions free: a true mechanism, found as such
    assert result.rigid_count == 3
    assert len(result.eigenvalues) == 4
    assert result.frequencies_hz[3] == pytest.approx(f11, rel=0.01)


def test_inertia_count_equals_dense_eigenvalue_count(comm):
    """Sylvester count of K - sigma M agrees with a dense generalized eigen-solution (tiny plate)."""
    import scipy.linalg

    if comm.size > 1:
        pytest.skip("dense comparison on one rank")
    scene = load_scene("nafems-fv12", "mesh.size=2.5", "mesh.degree=2")
    model = build_model_from_scene(scene, comm)
    K = model.K.copy().convert("dense").getDenseArray()
    M = model.M.copy().convert("dense").getDenseArray()
    lam = scipy.linalg.eigh(K, M, eigvals_only=True)
    for f in (1.0, 3.0, 8.0, 20.0):
        sigma = (2 * math.pi * f) ** 2
        assert modal.count_eigenvalues_below(model.K, model.M, sigma) == int(np.sum(lam < sigma))


def test_free_box_rigid_modes_carry_mass_and_centre_of_gravity(coarse_box_model):
    model = coarse_box_model
    result = modal.solve_modes(model.K, model.M, 2500.0)
    f = result.frequencies_hz
    assert result.complete
    assert np.all(f[:6] < 1e-3 * f[6])          # six rigid-body modes, clearly separated
    props = modal.rigid_body_mass_properties(model.M, result.vectors[:6], elasticity.rigid_body_vectors(model.V))
    mass = model.material.density * model.housing.volume
    assert mass == pytest.approx(24.4048, rel=1e-4)          # rho * exact volume of the reconstruction
    assert props["mass_kg"] == pytest.approx(mass, rel=1e-8)
    assert np.allclose(props["centre_of_gravity_m"], model.housing.centroid, atol=1e-8)
    assert np.max(result.residuals[6:]) < 1e-8


def test_incomplete_solution_is_detected(coarse_box_model):
    """Asking SLEPc for too few modes must be caught by the inertia count, not pass silently."""
    model = coarse_box_model
    with pytest.raises(SolverError, match="incomplete"):
        modal.solve_modes(model.K, model.M, 2500.0, nev=8)
    partial = modal.solve_modes(model.K, model.M, 2500.0, nev=8, require_complete=False)
    assert not partial.complete
    assert partial.expected_count > 8


def test_close_modes_are_m_orthogonal(coarse_box_model):
    """Close/repeated eigenvalues come back as distinct, M-orthonormal vectors."""
    model = coarse_box_model
    result = modal.solve_modes(model.K, model.M, 2500.0)
    X = result.vectors
    G = np.array([[X[i].dot(_mult(model.M, X[j])) for j in range(len(X))] for i in range(len(X))])
    assert np.allclose(G, np.eye(len(X)), atol=1e-8)


def _mult(M, x):
    y = M.createVecLeft()
    M.mult(x, y)
    return y


SIMPLY_SUPPORTED = ('geometry.edges={x0="simply_supported",x1="simply_supported",'
                    'y0="simply_supported",y1="simply_supported"}')


@pytest.mark.parametrize("f_max", [3.7, 8.0])
def test_rigid_count_does_not_depend_on_f_max(comm, f_max):
    """Issue 12 item 4: FV12's plate simply supported (w = 0 on the edges) keeps its three in-plane rigid
    motions, counted as three whatever f_max; its first elastic mode is Kirchhoff's f_11 = 2.377 Hz."""
    scene = load_scene("nafems-fv12", SIMPLY_SUPPORTED)
    model = build_model_from_scene(scene, comm)
    result = modal.solve_modes(model.K, model.M, f_max)
    assert result.rigid_count == 3
    m = model.material
    D = m.youngs_modulus * 0.05**3 / (12 * (1 - m.poisson_ratio**2))
    f11 = math.pi / 2 * (2 / 10.0**2) * math.sqrt(D / (m.density * 0.05))
    assert result.frequencies_hz[3] == pytest.approx(f11, rel=0.01)


def test_free_plate_has_six_rigid_modes_below_a_low_f_max(comm):
    """The free FV12 plate solved only to 3 Hz (f_max close to its 1.622 Hz first mode) still has six."""
    scene = load_scene("nafems-fv12")
    model = build_model_from_scene(scene, comm)
    result = modal.solve_modes(model.K, model.M, 3.0)
    assert result.rigid_count == 6
    assert result.frequencies_hz[6] == pytest.approx(1.622, rel=0.015)


def test_simply_supported_plate_harmonic_basis_counts_rigid_modes(comm):
    """harmonic.json's facts for the issue's plate: a basis to 3.7 Hz = three rigid modes, one elastic mode."""
    from housingfe.response import forced as forced_response

    scene = load_scene("nafems-fv12", SIMPLY_SUPPORTED,
                       "analysis.harmonic={f_min=0.5, f_max=2.4666667, df=0.5, surface=\"top\", "
                       "modal_basis_factor=1.5}",
                       "loads=[{name=\"top\", kind=\"force\", surface=\"top\", point=[3.1, 2.7, 0.05], "
                       "direction=[0.0, 0.0, -1.0], radius=0.2}]",
                       "damping={loss_factor=0.01}")
    forced = forced_response.run(build_model_from_scene(scene, comm), scene.analysis.harmonic, scene.loads, scene.damping)
    assert forced.facts["basis_f_max_hz"] == pytest.approx(3.7)
    assert forced.facts["rigid_modes"] == 3
    assert forced.facts["modes_in_basis"] == 1


def test_residual_vectors_reuse_the_eigensolve_factorisation(coarse_box_model):
    """solve_modes(keep_solver=True) hands its factorisation of K - shift M to the modal sweep's residual vectors:
    the same vectors as a new factorisation at that shift, only for the matrices it was built from, and freed."""
    from types import SimpleNamespace

    from housingfe.solvers import harmonic

    K, M = coarse_box_model.K, coarse_box_model.M
    kept = modal.solve_modes(K, M, 2500.0, method="block", keep_solver=True)
    plain = modal.solve_modes(K, M, 2500.0, method="block")
    solver = kept.shifted_solver
    assert plain.shifted_solver is None and solver is not None
    assert solver.shift < 0 and solver.matches(K, M)
    other = K.copy()
    assert not solver.matches(other, M)
    other.destroy()
    f = K.createVecRight()
    start, end = f.getOwnershipRange()
    f.getArray()[:] = np.random.default_rng(1).standard_normal(K.getSize()[0])[start:end]
    loads = [SimpleNamespace(vector=f)]
    copies = lambda vecs: [v.copy() for v in vecs]   # noqa: E731
    damping = harmonic.Damping(lambda fr: np.full(np.shape(fr), 0.02))
    freqs = np.array([300.0, 1200.0])
    reused = harmonic.modal_superposition(K, M, kept, loads, freqs, damping, copies)
    fresh = harmonic.modal_superposition(K, M, plain, loads, freqs, damping, copies, shift=solver.shift)
    r_reused = reused.blocks[0][0].reduced[-1].getArray()
    r_fresh = fresh.blocks[0][0].reduced[-1].getArray()
    scale = max(comm_max(np.abs(r_fresh), K), 1e-300)
    assert comm_max(np.abs(r_reused - r_fresh), K) < 1e-9 * scale
    assert comm_max(np.abs(r_fresh), K) > 0
    kept.release_solver()
    assert kept.shifted_solver is None


def comm_max(values: np.ndarray, A) -> float:
    from mpi4py import MPI

    return A.getComm().tompi4py().allreduce(float(values.max(initial=0.0)), op=MPI.MAX)


def _with_extra_slot(A):
    """A copy of A with one more stored entry (an explicit 0.0 outside A's pattern in each rank's first row):
    the same operator, another sparsity pattern."""
    from petsc4py import PETSc

    ia, ja, va = A.getValuesCSR()
    start, _ = A.getOwnershipRange()
    row = ja[ia[0]:ia[1]]
    free = next(c for c in range(A.getSize()[1]) if c not in set(row.tolist()))
    at = ia[0] + int(np.searchsorted(row, free))
    ja = np.insert(ja, at, free)
    va = np.insert(va, at, 0.0)
    ia = ia.copy()
    ia[1:] += 1
    B = PETSc.Mat().createAIJ(A.getSizes(), csr=(ia, ja, va), comm=A.getComm())
    B.setBlockSizes(*A.getBlockSizes())
    assert B.getInfo()["nz_used"] == A.getInfo()["nz_used"] + A.getComm().getSize()   # one per rank
    return B


def test_matrices_of_different_patterns_give_the_same_modes(comm):
    """K - s M is formed with PETSc's fast same-pattern update only when K and M share their pattern (on one rank
    and in parallel): the same update on another pattern would silently give a wrong matrix."""
    from petsc4py import PETSc

    scene = load_scene("nafems-fv12")
    model = build_model_from_scene(scene, comm)
    K, M = model.K, model.M
    M_other = _with_extra_slot(M)
    assert modal.axpy_structure(K, M) == PETSc.Mat.Structure.SAME_NONZERO_PATTERN
    assert modal.axpy_structure(K, M_other) == PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN
    f_max = scene.analysis.modal.f_max
    for method in ("block", "slepc"):
        same = modal.solve_modes(K, M, f_max, method=method)
        other = modal.solve_modes(K, M_other, f_max, method=method)
        assert len(other.eigenvalues) == len(same.eigenvalues) == same.expected_count
        elastic = slice(6, None)
        np.testing.assert_allclose(other.frequencies_hz[elastic], same.frequencies_hz[elastic], rtol=1e-8)
    M_other.destroy()
