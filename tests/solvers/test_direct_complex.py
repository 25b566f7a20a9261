"""The complex-worker direct solver (housingfe.solvers._complex_worker) against the real 2x2 block form in this
process: same solutions to 1e-9 relative, for a hysteretic loss factor, a non-proportional damping matrix D and a
non-symmetric viscous C (the LU path), with one worker or several sharing the lines; a singular undamped line is
reported as in the block form."""
import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

from housingfe.errors import SolverError
from housingfe.fe.loads import assemble_load
from housingfe.scene import build_model_from_scene
from housingfe.solvers import _complex_worker, harmonic, modal
from tests.conftest import load_scene

pytestmark = pytest.mark.skipif(not _complex_worker.available(), reason="complex PETSc build not installed")

LOADS = ('loads=[{name="p1", kind="force", surface="top", point=[0.07, 0.05, 0.005], direction=[0,0,-1], '
         'radius=0.01}, {name="p2", kind="force", surface="top", point=[0.21, 0.13, 0.005], '
         'direction=[0,0.3,-1], radius=0.01}]')
# A thick plate (a block): on a 5 mm plate the bending-dominated system is so ill-conditioned that either form
# carries ~1e-8 relative round-off (measured: residuals 6e-9 for both at 37 Hz), which says nothing of the method.
FREQS = np.array([37.0, 410.0, 1333.0, 1990.0])


@pytest.fixture(scope="module")
def plate(comm):
    if comm.size > 1:
        pytest.skip("the complex worker is a one-rank path (the block form serves several ranks)")
    scene = load_scene("nafems-fv12", "geometry.a=0.3", "geometry.b=0.2", "geometry.h=0.04", "mesh.size=0.04",
                       LOADS.replace("0.005]", "0.04]"))
    model = build_model_from_scene(scene, comm)
    loads = [assemble_load(spec, model.housing, model.V, model.bcs) for spec in scene.loads]
    return model, loads


def _solutions(res):
    """(loads, lines, n) complex displacements from the blocks of a direct result (reduce = copies)."""
    out = []
    for blocks in res.blocks:
        lines = sorted(blocks, key=lambda b: b.index[0])
        out.append([b.reduced[0].getArray() + 1j * b.reduced[1].getArray() for b in lines])
    return np.array(out)


def _compare(model, loads, damping, C=None, freqs=FREQS):
    copies = lambda vecs: [v.copy() for v in vecs]   # noqa: E731
    new = harmonic.direct(model.K, model.M, loads, freqs, damping, copies, C=C, method="complex")
    old = harmonic.direct(model.K, model.M, loads, freqs, damping, copies, C=C, method="block")
    u_new, u_old = _solutions(new), _solutions(old)
    assert u_new.shape == (len(loads), len(freqs), model.K.getSize()[0])
    scale = np.abs(u_old).max(axis=2, keepdims=True)
    assert np.max(np.abs(u_new - u_old) / scale) < 1e-9
    return u_new


def test_hysteretic_loss_factor_equals_block_form(plate):
    model, loads = plate
    u = _compare(model, loads, harmonic.Damping(lambda f: np.full(np.shape(f), 0.02)))
    # the damping acts (the first lines are mass-line dominated: rigid-body motion carries no damping)
    assert np.all(np.abs(u[:, -1].imag).max(axis=1) > 0.05 * np.abs(u[:, -1].real).max(axis=1))


def test_damping_matrix_and_nonsymmetric_viscous_matrix_equal_block_form(plate):
    model, loads = plate
    D = model.K.copy()
    D.scale(0.01)
    D.axpy(0.01 * (2 * np.pi * 800.0) ** 2, model.M, structure=modal.axpy_structure(D, model.M))
    _compare(model, loads, harmonic.Damping(lambda f: np.zeros(np.shape(f)), D=D))
    C = model.M.copy()                      # same pattern, lower triangle scaled: non-symmetric -> LU
    indptr, indices, data = C.getValuesCSR()
    rows = np.repeat(np.arange(len(indptr) - 1), np.diff(indptr))
    C.setValuesCSR(indptr, indices, 200.0 * data * np.where(indices < rows, 1.3, 1.0))
    C.assemble()
    # LU: at 37 Hz the block form's LU is itself 6e-9 off an independent SuperLU solve (the complex LU 6e-11), so the
    # forms are compared from 410 Hz and the complex one against SuperLU at 37 Hz
    eta = harmonic.Damping(lambda f: np.full(np.shape(f), 0.01))
    _compare(model, loads, eta, C=C, freqs=FREQS[1:])
    u = harmonic.direct(model.K, model.M, loads, FREQS[:1], eta, lambda v: [x.copy() for x in v], C=C)
    w = 2 * np.pi * FREQS[0]
    A = _csr(model.K) * (1 + 0.01j) + 1j * w * _csr(C) - w * w * _csr(model.M)
    for j, load in enumerate(loads):
        ref = spsolve(A.tocsc(), load.vector.getArray().astype(complex))
        assert np.abs(_solutions(u)[j, 0] - ref).max() < 1e-9 * np.abs(ref).max()


def _csr(A):
    indptr, indices, data = A.getValuesCSR()
    return sp.csr_matrix((data, indices, indptr), shape=A.getSize())


def test_undamped_eigenfrequency_is_singular(plate):
    model, loads = plate
    modes = modal.solve_modes(model.K, model.M, 8000.0)
    f_hit = np.array([modes.frequencies_hz[modes.rigid_count]])
    undamped = harmonic.Damping(lambda f: np.zeros(np.shape(f)))
    with pytest.raises(SolverError, match="eigenfrequency"):
        harmonic.direct(model.K, model.M, loads, f_hit, undamped, lambda v: v, method="complex")


@pytest.mark.parametrize("workers", [1, 3])
def test_a_dense_sweep_equals_block_form(plate, workers):
    """Twenty lines 5 Hz apart on one symbolic factorisation per worker: the answers stay those of the block form to
    1e-9, line by line in order, also when three workers share the lines (line k on worker k mod 3)."""
    model, loads = plate
    freqs = np.arange(1300.0, 1400.0, 5.0)
    damping = harmonic.Damping(lambda f: np.full(np.shape(f), 0.02))
    copies = lambda vecs: [v.copy() for v in vecs]   # noqa: E731
    new = harmonic.direct(model.K, model.M, loads, freqs, damping, copies, method="complex", workers=workers)
    old = harmonic.direct(model.K, model.M, loads, freqs, damping, copies, method="block")
    u_new, u_old = _solutions(new), _solutions(old)
    assert np.max(np.abs(u_new - u_old) / np.abs(u_old).max(axis=2, keepdims=True)) < 1e-9
    assert new.timings["direct_factorisations"] == len(freqs) and new.timings["direct_workers"] == workers
    assert [b.index[0] for b in new.blocks[0]] == list(range(len(freqs)))


def test_backward_error_is_reported_and_a_poor_line_is_refactorised_with_scaling(plate, tmp_path):
    """The worker checks each line's normwise backward error: the plate's lines are at round-off (< 1e-13) without
    MUMPS' scaling; a line above the tolerance (forced here: tolerance 0) is factorised again with scaling, and the
    answer is the same."""
    import subprocess
    import sys

    model, loads = plate
    damping = harmonic.Damping(lambda f: np.full(np.shape(f), 0.02))
    copies = lambda vecs: [v.copy() for v in vecs]   # noqa: E731
    res = harmonic.direct(model.K, model.M, loads, FREQS, damping, copies, method="complex", workers=1)
    assert 0 < res.timings["direct_backward_error"] < 1e-13
    assert res.timings["direct_factorisations"] == len(FREQS)
    n = model.K.getSize()[0]
    job = {"loads": np.array([ld.vector.getArray() for ld in loads]), "omega": 2 * np.pi * FREQS,
           "eta": np.full(len(FREQS), 0.02), "use_D": False, "symmetric": True, "block_size": 3}
    for name, A in (("K", model.K), ("M", model.M)):
        indptr, indices, data = A.getValuesCSR()
        job.update({f"{name}_indptr": indptr, f"{name}_indices": indices, f"{name}_data": data})
    np.savez(tmp_path / "job.npz", **job)
    driver = ("import sys; from housingfe.solvers import _complex_worker as w; w.BACKWARD_ERROR_TOL = 0.0; "
              f"raise SystemExit(w.run({str(tmp_path / 'job.npz')!r}, sys.stdout.buffer))")
    out = subprocess.run([sys.executable, "-c", driver], capture_output=True, env=_complex_worker.complex_env(),
                         check=True).stdout
    line_bytes = _complex_worker.HEAD_BYTES + 16 * len(loads) * n
    assert len(out) == len(FREQS) * line_bytes
    u_ref = _solutions(res)
    for k in range(len(FREQS)):
        raw = out[k * line_bytes:(k + 1) * line_bytes]
        head = np.frombuffer(raw[:_complex_worker.HEAD_BYTES])
        assert head[1] == (2 if k == 0 else 1)   # scaling stays on once switched on
        assert head[2] < 1e-13
        sol = np.frombuffer(raw[_complex_worker.HEAD_BYTES:], np.complex128).reshape(len(loads), n)
        assert np.abs(sol - u_ref[:, k]).max() < 1e-9 * np.abs(u_ref[:, k]).max()


def test_a_short_mumps_workspace_is_grown_in_the_worker(tmp_path):
    """The saddle point [[0, B], [B^T, 0]] (order 3000, see tests/solvers/test_mumps.py) at ICNTL(14) = 0: MUMPS
    stops with INFOG(1) = -9 in the worker's complex LDL^T, which the worker reported as a singular line; now it
    factorises again with more workspace and the solution satisfies A x = f to round-off."""
    import os
    import subprocess
    import sys

    n = 1500
    B = sp.random(n, n, density=4 / n, random_state=1, format="csr") + sp.eye(n)
    K = sp.bmat([[None, B], [B.T, None]], format="csr")
    K.sort_indices()
    M = sp.eye(2 * n, format="csr")
    f = np.random.default_rng(9).standard_normal((1, 2 * n))
    job = {"loads": f, "omega": np.array([0.0]), "eta": np.array([0.0]), "use_D": False, "symmetric": True,
           "block_size": 1}
    for name, A in (("K", K), ("M", M)):
        job.update({f"{name}_indptr": A.indptr, f"{name}_indices": A.indices, f"{name}_data": A.data})
    np.savez(tmp_path / "job.npz", **job)
    env = _complex_worker.complex_env()
    env["PETSC_OPTIONS"] = (os.environ.get("PETSC_OPTIONS", "") + " -direct_mat_mumps_icntl_14 0").strip()
    driver = ("import sys; from housingfe.solvers import _complex_worker as w; "
              f"raise SystemExit(w.run({str(tmp_path / 'job.npz')!r}, sys.stdout.buffer))")
    proc = subprocess.run([sys.executable, "-c", driver], capture_output=True, env=env)
    assert proc.returncode == 0, proc.stderr.decode()
    x = np.frombuffer(proc.stdout[_complex_worker.HEAD_BYTES:], np.complex128)
    assert np.linalg.norm(K @ x - f[0]) < 1e-10 * np.linalg.norm(f)
