"""Response points (points.csv), operating deflection shapes and band tables: the point FRF against the
rigid-body mass line of a free plate and the static deflection of a cantilever, modal against direct,
mobility/accelerance against i omega H and -omega^2 H, the ODS scaled by the load amplitude, no NaN in any
table, 1 and 2 MPI ranks."""

import csv
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest

from housingfe.errors import InputError
from housingfe.response.forced import POINT_COLUMNS, point_rows
from housingfe.response.forced import run as run_forced
from housingfe.response.observers import (
    RESPONSE_POINTS,
    PointEvaluator,
    closest_point_on_triangles,
    response_point_samples,
)
from housingfe.scene import build_model_from_scene
from tests.conftest import load_scene, mumps_solve
from tests.response.test_forced import LOADS, PLATE

A, B, H = 0.3, 0.2, 0.005          # the plate of tests.response.test_forced, x in [0, A], y in [0, B], z in [0, H]


def plate(*extra):
    return load_scene("nafems-fv12", *PLATE, LOADS, "damping.loss_factor=0.01", *extra)


def test_closest_point_on_triangles_matches_a_dense_sampling():
    rng = np.random.default_rng(3)
    tri = rng.normal(size=(1, 3, 3))
    u, v = np.meshgrid(np.linspace(0, 1, 301), np.linspace(0, 1, 301))
    inside = u + v <= 1
    dense = tri[0, 0] + np.outer(u[inside], tri[0, 1] - tri[0, 0]) + np.outer(v[inside], tri[0, 2] - tri[0, 0])
    for _ in range(100):
        p = 2 * rng.normal(size=3)
        q, d = closest_point_on_triangles(p, tri)
        best = np.linalg.norm(dense - p, axis=1).min()
        assert d[0] == pytest.approx(np.linalg.norm(q[0] - p), abs=1e-12)
        assert best - 1e-2 <= d[0] <= best + 1e-12


@pytest.fixture(scope="module")
def free_plate(comm):
    """Free plate, both solvers, lines 2-1202 Hz (the first elastic modes); the force p1 of amplitude 2.5 N."""
    scene = plate("analysis.harmonic.f_min=2.0", "analysis.harmonic.f_max=1202.0", "analysis.harmonic.df=6.0",
                  'analysis.harmonic.solver="both"', "analysis.harmonic.sample_points=[1, 8]",
                  "analysis.harmonic.deflection_shapes_hz=[4.0, 700.0]",
                  'analysis.harmonic.points=[{name="drive", point=[0.07, 0.05, 0.006], direction=[0, 0, -1]}, '
                  '{name="corner", point=[0.29, 0.19, 0.005], direction="normal"}, {name="edge", point=[0.3, 0.1, 0.0025]}]',
                  LOADS.replace("radius=0.01}", "radius=0.01, amplitude=2.5}", 1))
    model = build_model_from_scene(scene, comm)
    return model, run_forced(model, scene.analysis.harmonic, scene.loads, scene.damping)


def _H(forced, solver, load, row):
    return forced.responses[solver][load].extras["point_values"][RESPONSE_POINTS][row]


@pytest.mark.slow
def test_points_are_snapped_to_the_surface(free_plate):
    _, forced = free_plate
    drive, corner, edge = forced.response_points
    assert drive.distance == pytest.approx(0.001, rel=1e-9)          # 1 mm above the top face
    assert np.allclose(drive.point, [0.07, 0.05, H])
    assert np.allclose(corner.directions, [[0, 0, 1]])                # outward normal of the top face
    assert edge.labels == ["x", "y", "z"] and np.allclose(edge.normal, [1, 0, 0])


@pytest.mark.slow
def test_low_frequency_accelerance_is_the_rigid_body_mass_line(free_plate):
    """Below the first elastic mode a free plate moves as a rigid body: accelerance = d . (F/m + alpha x r)
    with m and J of the rectangular plate (analytic), alpha = J^-1 (r_F x F).  At 2 and 8 Hz the elastic
    modes (the first one near 300 Hz) add about (8/300)^2 ~ 7e-4."""
    model, forced = free_plate
    rho = model.material.density
    m = rho * A * B * H
    J = m / 12 * np.diag([B**2 + H**2, A**2 + H**2, A**2 + B**2])
    c = np.array([A / 2, B / 2, H / 2])
    F = np.array([0.0, 0.0, -1.0])                       # unit force of load p1 (direction [0, 0, -1])
    alpha = np.linalg.solve(J, np.cross(forced.loads[0].centre - c, F))
    row = 0
    for rp in forced.response_points:
        acc = F / m + np.cross(alpha, rp.point - c)
        for d in rp.directions:
            expected = acc @ d
            for solver in ("modal+residual", "direct"):
                f = forced.responses[solver][0].frequencies[:2]
                acc_fe = -(2 * np.pi * f) ** 2 * _H(forced, solver, 0, row)[:2]
                scale = np.linalg.norm(F / m)
                assert np.max(np.abs(acc_fe - expected)) < 2e-3 * scale, (rp.name, d, solver)
            row += 1


@pytest.mark.slow
def test_point_frf_modal_matches_direct(free_plate):
    """Modal superposition + residual (basis to 1.5 f_max) against the direct solver at the response points,
    on every line: the difference is below 2 % of the largest response of the point set at that line up to
    2/3 f_max and below 15 % up to f_max (a component that is ~0, e.g. in-plane motion under a normal force,
    is compared with the rest)."""
    _, forced = free_plate
    for load in range(2):
        hm = forced.responses["modal+residual"][load].extras["point_values"][RESPONSE_POINTS]
        hd = forced.responses["direct"][load].extras["point_values"][RESPONSE_POINTS]
        err = np.max(np.abs(hm - hd), axis=0) / np.max(np.abs(hd), axis=0)
        f = forced.spec.frequencies
        # measured: 1.3 % below 2/3 f_max; near f_max 3.6 % (p1) and 11 % (p2, with an in-plane component) with
        # f_max = 1500 Hz: modes above 1.5 f_max enter only statically, near f_max their amplification shows
        assert np.max(err[f < 2 / 3 * f[-1]]) < 2e-2, load
        assert np.max(err) < 0.15, load


@pytest.mark.slow
def test_points_csv_columns_obey_their_definitions(free_plate):
    """mobility = i omega H, accelerance = -omega^2 H, magnitude and phase of each, and the physical rms
    response = |H| x the load's rms amplitude (2.5 N for p1)."""
    _, forced = free_plate
    rows = point_rows(forced)
    assert len(rows) == len(forced.responses) * 2 * 5 * len(forced.spec.frequencies)
    col = {c: i for i, c in enumerate(POINT_COLUMNS)}
    for r in rows[::97]:
        w = 2 * np.pi * r[col["frequency_hz"]]
        h = complex(r[col["receptance_re"]], r[col["receptance_im"]])
        y = complex(r[col["mobility_re"]], r[col["mobility_im"]])
        a = complex(r[col["accelerance_re"]], r[col["accelerance_im"]])
        assert y == pytest.approx(1j * w * h, rel=1e-12)
        assert a == pytest.approx(-w * w * h, rel=1e-12)
        for q, z in (("receptance", h), ("mobility", y), ("accelerance", a)):
            assert r[col[f"{q}_abs"]] == pytest.approx(abs(z), rel=1e-12)
            assert np.exp(1j * np.radians(r[col[f"{q}_phase_deg"]])) == pytest.approx(z / abs(z), abs=1e-9)
        amp = 2.5 if r[col["load_case"]] == "p1" else 1.0
        assert r[col["load_rms"]] == amp
        assert r[col["velocity_rms_m_s"]] == pytest.approx(abs(y) * amp, rel=1e-12)
        assert r[col["load_unit"]] == "N"
    assert all(np.isfinite(v) for r in rows for v in r if isinstance(v, float))


@pytest.mark.slow
def test_deflection_shapes_are_the_point_frf_times_the_load_amplitude(free_plate):
    """The ODS field evaluated at the response points equals H x amplitude at the same line (direct: re-solved
    at that line, modal: from the basis)."""
    model, forced = free_plate
    evaluator = PointEvaluator(model.V, response_point_samples(forced.response_points))
    assert {d.solver for d in forced.deflection_shapes} == {"direct"}
    freqs = forced.spec.frequencies
    for ds in forced.deflection_shapes:
        j = [lc.name for lc in forced.loads].index(ds.load)
        k = int(np.argmin(abs(freqs - ds.frequency)))
        assert ds.frequency == freqs[k]
        u = evaluator.normal_values(ds.real) + 1j * evaluator.normal_values(ds.imag)
        amp = 2.5 if ds.load == "p1" else 1.0
        expected = forced.responses["direct"][j].extras["point_values"][RESPONSE_POINTS][:, k] * amp
        assert np.max(np.abs(u - expected)) <= 1e-9 * np.max(np.abs(expected))


@pytest.mark.slow
def test_modal_deflection_shapes_and_xdmf_time_axis(free_plate, tmp_path, comm):
    """Without the direct solver the ODS come from the modal basis; the XDMF file has one time step per line,
    time = frequency (Hz)."""
    from housingfe.report import write_deflection_shapes
    from housingfe.response.forced import deflection_shapes

    model, forced = free_plate
    modal_only = {k: v for k, v in forced.results.items() if k != "direct"}
    view = type(forced)(**{**forced.__dict__, "results": modal_only})
    shapes = deflection_shapes(view, model.K, model.M, None)
    assert {d.solver for d in shapes} == {"modal+residual"}
    evaluator = PointEvaluator(model.V, response_point_samples(forced.response_points))
    for ds, ref in zip(shapes, forced.deflection_shapes):
        u = evaluator.normal_values(ds.real) + 1j * evaluator.normal_values(ds.imag)
        u_ref = evaluator.normal_values(ref.real) + 1j * evaluator.normal_values(ref.imag)
        assert np.max(np.abs(u - u_ref)) < 1e-2 * np.max(np.abs(u_ref))
    view.deflection_shapes = shapes
    folder = comm.bcast(str(tmp_path), root=0)
    files = write_deflection_shapes(__import__("pathlib").Path(folder), model, view, comm)
    text = (tmp_path / files["p1"]).read_text()
    times = sorted({float(t) for t in re.findall(r'Time Value="([^"]+)"', text)})
    assert times == pytest.approx(sorted({d.frequency for d in shapes}))
    assert {"displacement_re", "displacement_im", "displacement_abs"} <= set(re.findall(r'Attribute Name="([^"]+)"', text))


def test_cantilever_point_frf_at_low_frequency_is_the_static_tip_deflection(comm):
    """Plate clamped at x = 0, unit force spread over the free edge x = A: at 0.2 Hz (first mode ~45 Hz, dynamic
    amplification (0.2/45)^2 = 2e-5) the point receptance at the middle of the tip edge times (1 + i eta) is the static deflection, computed here by
    an independent static solve; and it lies between beam theory F L^3 / (3 E I) (narrow) and the cylindrical
    bending value (1 - nu^2) F L^3 / (3 E I) (wide plate)."""
    from dolfinx import fem, geometry

    from housingfe.fe.loads import assemble_load

    scene = plate('geometry.edges={x0="clamped"}', "analysis.modal.f_max=400.0",
                  "analysis.harmonic.f_min=0.2", "analysis.harmonic.f_max=0.2", 'analysis.harmonic.solver="both"',
                  'loads=[{name="tip", kind="force", surface="edge_x1", point=[0.3, 0.1, 0.0025], '
                  'direction=[0, 0, 1], radius=0.2}]',
                  'analysis.harmonic.points=[{name="tip", point=[0.3, 0.1, 0.0025], direction=[0, 0, 1]}]')
    model = build_model_from_scene(scene, comm)
    forced = run_forced(model, scene.analysis.harmonic, scene.loads, scene.damping)
    load = assemble_load(scene.loads[0], model.housing, model.V, model.bcs)
    u = fem.Function(model.V)
    mumps_solve(model.K, load.vector, u.vector, factor="cholesky")
    u.x.scatter_forward()
    mesh = model.V.mesh
    x = np.array([[A, B / 2, H / 2]])
    cells = geometry.compute_colliding_cells(mesh, geometry.compute_collisions(
        geometry.BoundingBoxTree(mesh, mesh.topology.dim), x), x).links(0)
    n_owned = mesh.topology.index_map(mesh.topology.dim).size_local
    mine = [c for c in cells if c < n_owned][:1]
    local = float(u.eval(x, mine).reshape(-1)[2]) if mine else 0.0
    has = comm.allgather(bool(mine))
    static = comm.bcast(local, root=has.index(True))
    for solver in ("modal+residual", "direct"):
        h = _H(forced, solver, 0, 0)[0]
        assert h * (1 + 0.01j) == pytest.approx(static, rel=1e-4), solver
    E, nu = model.material.youngs_modulus, model.material.poisson_ratio
    beam = A**3 / (3 * E * B * H**3 / 12)
    print(f"static {static:.5e} m, beam {beam:.5e} m, ratio {static / beam:.4f}, 1 - nu^2 = {1 - nu**2:.3f}")
    assert (1 - nu**2) * beam * 0.99 < static < beam * 1.01


@pytest.mark.slow
def test_sample_points_one_and_too_many(free_plate, comm):
    """sample_points = [1] gives one point (it crashed in the evaluator's reshape); more points than facets is
    an InputError naming the key."""
    from housingfe.response.observers import SurfaceObserver

    model, forced = free_plate
    r = forced.responses["direct"][0]
    assert np.all(np.isfinite(r.point_mean_square_velocity[1])) and np.all(r.point_mean_square_velocity[1] > 0)
    with pytest.raises(InputError, match="analysis.harmonic.sample_points"):
        SurfaceObserver(model, "top", [10**6], forced.loads)


@pytest.mark.slow
def test_point_far_from_the_surface_is_an_input_error(free_plate):
    from housingfe.response.observers import locate_response_points
    from housingfe.scene import ResponsePointSpec

    model, _ = free_plate
    far = ResponsePointSpec(name="far", point=[0.1, 0.1, 0.5])
    with pytest.raises(InputError, match=r"points.0 \(far\).point: .* lies 0.495 m"):
        locate_response_points(model.housing, [far])
    ok = ResponsePointSpec(name="far", point=[0.1, 0.1, 0.5], tolerance=1.0)
    assert locate_response_points(model.housing, [ok])[0].distance == pytest.approx(0.495)
    with pytest.raises(InputError, match="surface: no surface 'lid'"):
        locate_response_points(model.housing, [ResponsePointSpec(name="p", point=[0, 0, 0], surface="lid")])


def _housingfe(*args, ranks=None):
    cmd = [sys.executable, "-m", "housingfe", *args]
    if ranks:
        cmd = [shutil.which("mpirun"), "-n", str(ranks), *cmd]
    env = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1", "OPENBLAS_NUM_THREADS": "1"}
    import os

    return subprocess.run(cmd, capture_output=True, text=True, env={**os.environ, **env}, timeout=300)


CLI = ["nafems-fv12", *[a for s in PLATE for a in ("--set", s)], "--set", LOADS,
       "--set", "analysis.harmonic.f_min=4.88", "--set", "analysis.harmonic.df=4.88",
       "--set", "analysis.harmonic.f_max=300.0", "--set", "output.pictures=false", "--set", "damping.loss_factor=0.01",
       "--set", "analysis.harmonic.sample_points=[1, 4]", "--set", "analysis.harmonic.deflection_shapes_hz=[250.0]",
       "--set", 'analysis.harmonic.points=[{name="a", point=[0.2, 0.1, 0.005], direction="normal"}]']


def _table(path):
    with open(path) as fh:
        return list(csv.reader(fh))


@pytest.mark.slow
def test_cli_tables_have_no_nan_and_two_ranks_agree(tmp_path):
    """4.88 Hz lines: the 12.5 Hz band holds none and the 4.88 Hz line lies below the 10 Hz band; bands.csv
    leaves the band out and says so in the summary, no table holds NaN or inf; points.csv and the ODS file
    exist; 2 MPI ranks give the same points.csv and bands.csv."""
    one = _housingfe("run", *CLI, "--out", str(tmp_path / "one"))
    assert one.returncode == 0, one.stderr
    out = tmp_path / "one"
    for name in ("frf.csv", "bands.csv", "octave_bands.csv", "receptance.csv", "points.csv"):
        text = (out / name).read_text().lower()
        assert "nan" not in text and "inf" not in text, name
    bands = _table(out / "bands.csv")
    col = bands[0].index("lines")
    nominal = [float(r[1]) for r in bands[1:] if r[0] == "p1"]
    assert 12.5 not in nominal and 10.0 in nominal and 16.0 in nominal
    assert all(int(r[col]) >= 1 for r in bands[1:])
    assert "12.5 Hz hold no line" in one.stdout and "4.88 Hz) lie below the lowest band" in one.stdout
    assert (out / "ods_p1.xdmf").exists() and (out / "ods_p2.xdmf").exists()
    if not shutil.which("mpirun"):
        pytest.skip("mpirun not installed")
    two = _housingfe("run", *CLI, "--out", str(tmp_path / "two"), ranks=2)
    assert two.returncode == 0, two.stderr
    for name, first in (("points.csv", 7), ("bands.csv", 1)):
        a, b = _table(out / name), _table(tmp_path / "two" / name)
        assert a[0] == b[0] and len(a) == len(b)
        for ra, rb in zip(a[1:], b[1:]):
            for x, y in zip(ra[first:], rb[first:]):
                try:
                    fx, fy = float(x), float(y)
                except ValueError:
                    assert x == y
                    continue
                assert fy == pytest.approx(fx, rel=1e-6, abs=1e-6 * abs(fx) + 1e-300), (name, ra[:4])


def test_cli_far_point_exits_2_with_one_line(tmp_path):
    bad = _housingfe("run", *CLI, "--set", 'analysis.harmonic.points=[{name="far", point=[0.2, 0.1, 1.0]}]',
                     "--out", str(tmp_path / "bad"))
    assert bad.returncode == 2
    assert len(bad.stderr.strip().splitlines()) == 1 and "analysis.harmonic.points.0 (far).point" in bad.stderr
    assert not (tmp_path / "bad").exists()


def test_cli_lines_below_10_hz_say_why_the_band_tables_are_empty(tmp_path):
    """All lines below the 10 Hz band: bands.csv has its header only and the summary says why; the run with
    both solvers and a deflection shape still completes (it crashed on the empty band plot)."""
    args = [a if a != "analysis.harmonic.f_max=300.0" else "analysis.harmonic.f_max=8.0" for a in CLI]
    res = _housingfe("run", *args, "--set", "analysis.harmonic.f_min=2.0", "--set", "analysis.harmonic.df=2.0",
                     "--set", 'analysis.harmonic.solver="both"', "--set", "output.pictures=true",
                     "--set", "analysis.harmonic.deflection_shapes_hz=[4.0]", "--out", str(tmp_path / "low"))
    assert res.returncode == 0, res.stderr
    assert len(_table(tmp_path / "low" / "bands.csv")) == 1
    assert "no 1/3-octave band: bands start at 10 Hz" in res.stdout
    assert len(_table(tmp_path / "low" / "points.csv")) == 1 + 3 * 2 * 4     # solvers x loads x lines, 1 direction
