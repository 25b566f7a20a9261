"""The test gearbox housing on an elastic frame: `supports` kind "elastic" on foot_bottom (springs per unit area,
housingfe.fe.model.foundation_forms) as the run-up's `housing.set` gives it (docs/runup.md, "The gearbox on a
frame").  On soft springs the housing moves as a rigid body: its six lowest modes are those of a rigid block on a
uniform spring bed, with no zero modes left."""
import numpy as np
import pytest
from scipy.linalg import eigh

from housingfe.scene import build_model_from_scene, load_housing_scene
from housingfe.solvers import blocks, modal

FOOT_X = (-0.245, 0.245)                  # m: the two feet run the housing's full length 0.490 m
FOOT_Y = ((-0.150, -0.075), (0.075, 0.150))  # m: 0.075 m wide, inner edge on the inner wall face (width 0.170, 10 mm)
K_V = 1e6                                 # N/m in total: rigid-body modes 6-16 Hz, far below the first elastic ~450 Hz


def spring_bed_stiffness(k_n: float, k_t: float) -> np.ndarray:
    """6x6 stiffness (N/m, N, N m) of uniform springs k_n (normal, z) and k_t (x, y) per unit area (N/m^3) on the
    feet rectangles in the plane z = 0, for the rigid motion (t_x, t_y, t_z, theta_x, theta_y, theta_z) about the
    origin: u_x = t_x - theta_z y, u_y = t_y + theta_z x, u_z = t_z + theta_x y - theta_y x.  Two-point Gauss
    rules per direction: exact for the quadratic integrands."""
    g, w = np.polynomial.legendre.leggauss(2)
    K = np.zeros((6, 6))
    for y0, y1 in FOOT_Y:
        for x, wx in zip((FOOT_X[0] + FOOT_X[1]) / 2 + (FOOT_X[1] - FOOT_X[0]) / 2 * g, w * (FOOT_X[1] - FOOT_X[0]) / 2):
            for y, wy in zip((y0 + y1) / 2 + (y1 - y0) / 2 * g, w * (y1 - y0) / 2):
                gx = np.array([1, 0, 0, 0, 0, -y])
                gy = np.array([0, 1, 0, 0, 0, x])
                gz = np.array([0, 0, 1, y, -x, 0])
                K += wx * wy * (k_t * (np.outer(gx, gx) + np.outer(gy, gy)) + k_n * np.outer(gz, gz))
    return K


@pytest.fixture(scope="module")
def soft_mount(comm):
    area = (FOOT_X[1] - FOOT_X[0]) * sum(b - a for a, b in FOOT_Y)
    k_n = K_V / area
    scene, _ = load_housing_scene("test-gearbox", [
        "mesh.size=0.06", "supports.0.kind=elastic", f"supports.0.normal_stiffness={k_n!r}",
        f"supports.0.tangential_stiffness={k_n / 3!r}"])
    model = build_model_from_scene(scene, comm)
    return model, k_n


def test_soft_mount_modes_are_the_rigid_block_on_springs(soft_mount):
    """The six lowest modes within 0.2 % of the rigid block on the spring bed (Rayleigh-Ritz on the six exact rigid
    motions: the analytic spring-bed stiffness against the housing's rigid-body mass matrix R^T M R); an elastic
    mode's flexibility lowers them by ~(16 / 450)^2 ~ 0.1 % (measured: 0.005-0.04 %).  No zero mode: the springs hold all six motions.  A
    spring bed on the wrong faces, k_n and k_t swapped (measured: -30 ... +43 %) or a missing area factor moves them by
    far more."""
    model, k_n = soft_mount
    assert model.expected_zero_modes is None       # a supported housing: no rigid-body modes expected
    R = blocks.columns(model.rigid_body_vectors())
    M_rb = R.T @ blocks.mat_block(model.M, R)
    M_rb = (M_rb + M_rb.T) / 2
    # `housingfe describe test-gearbox`: 0.01409 m^3 of steel; the 60 mm mesh's polygonal 170 mm bores cut ~2 % less
    assert M_rb[0, 0] == pytest.approx(0.01409 * 7850.0, rel=0.03)
    w2 = eigh(spring_bed_stiffness(k_n, k_n / 3), M_rb, eigvals_only=True)
    expected = np.sqrt(w2) / (2 * np.pi)
    result = modal.solve_modes(model.K, model.M, 1.5 * expected.max())
    assert result.rigid_count == 0
    fe = result.frequencies_hz
    assert len(fe) >= 6
    assert fe[0] > 3.0                              # 6 Hz: no zero mode
    assert np.allclose(fe[:6], expected, rtol=2e-3), (fe[:6], expected)
    # the bounce alone (a rigid block on springs K_V): sqrt(K_V / m) / 2 pi lies among them within the rocking's
    # coupling (the centre of gravity is 8 mm off the feet's centre along x)
    bounce = np.sqrt(K_V / M_rb[0, 0]) / (2 * np.pi)
    assert np.min(np.abs(fe[:6] / bounce - 1)) < 0.02


def test_a_total_stiffness_in_newtons_per_metre_is_spread_over_the_feet(comm):
    """`total_normal_stiffness` / `total_tangential_stiffness` (N/m, a frame's data) on the feet: the model spreads
    them over foot_bottom's area measured on the mesh, so the six modes are the rigid block on the analytic spring
    bed K_V / A with the feet's drawn area A = 0.49 m x 2 x 0.075 m = 0.0735 m^2 (a wrong area, e.g. the housing's
    whole bottom, moves them by the square root of the area ratio, >= 10 %)."""
    from housingfe.fe.model import surface_area

    area = (FOOT_X[1] - FOOT_X[0]) * sum(b - a for a, b in FOOT_Y)
    scene, _ = load_housing_scene("test-gearbox", [
        "mesh.size=0.06", "supports.0.kind=elastic", f"supports.0.total_normal_stiffness={K_V!r}",
        f"supports.0.total_tangential_stiffness={K_V / 3!r}"])
    model = build_model_from_scene(scene, comm)
    assert surface_area(model.housing, "foot_bottom") == pytest.approx(area, rel=1e-9)
    R = blocks.columns(model.rigid_body_vectors())
    M_rb = R.T @ blocks.mat_block(model.M, R)
    M_rb = (M_rb + M_rb.T) / 2
    k_n = K_V / area
    expected = np.sqrt(eigh(spring_bed_stiffness(k_n, k_n / 3), M_rb, eigvals_only=True)) / (2 * np.pi)
    fe = modal.solve_modes(model.K, model.M, 1.5 * expected.max()).frequencies_hz
    assert np.allclose(fe[:6], expected, rtol=2e-3), (fe[:6], expected)


@pytest.mark.parametrize("sets, key", [
    (["supports.0.kind=elastic"], "normal_stiffness"),
    (["supports.0.kind=elastic", "supports.0.normal_stiffness=1e10", "supports.0.total_normal_stiffness=1e9"],
     "normal_stiffness"),
    (["supports.0.kind=elastic", "supports.0.total_normal_stiffness=1e9", "supports.0.tangential_stiffness=1e9",
      "supports.0.total_tangential_stiffness=1e8"], "tangential_stiffness"),
    (["supports.0.total_normal_stiffness=1e9"], "total_normal_stiffness"),
    (["supports.0.kind=elastic", "supports.0.total_normal_stiffness=-1e9"], "total_normal_stiffness"),
])
def test_an_elastic_support_given_twice_or_not_at_all_is_one_error_naming_the_key(sets, key, tmp_path):
    """Neither or both of the per-area and the total normal stiffness, both tangential stiffnesses, a stiffness on a
    fixed support (it would be ignored silently), a negative total: one line naming the key, exit 2, nothing
    written."""
    import os
    import subprocess
    import sys

    cmd = [sys.executable, "-m", "housingfe", "run", "test-gearbox", "--out", str(tmp_path / "out")]
    for s in sets:
        cmd += ["--set", s]
    proc = subprocess.run(cmd, capture_output=True, text=True, env={**os.environ, "OPENBLAS_NUM_THREADS": "1"},
                          cwd=tmp_path, timeout=300)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert key in proc.stderr, proc.stderr
    assert not (tmp_path / "out").exists()
