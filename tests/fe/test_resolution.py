"""The mesh's resolution of f_max (issue 27, item 2) and the traps of item 3 it came with: a mesh far too coarse
for f_max stops before meshing (one line, exit 2) unless mesh.allow_coarse; every run reports elements per
bending wavelength and an error estimate next to "complete"; the estimate bounds the error of a simply supported
plate against Kirchhoff's (Navier's) frequencies; a run with no elastic mode below f_max ends cleanly; modes.json
is strict JSON (null, never NaN)."""
from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from housingfe.fe import resolution
from housingfe.geometry.mesh import bending_wavelength
from tests.conftest import load_scene

# the trap: 150 mm quadratic bricks on 6 mm walls at 2 kHz (about one element per bending wavelength)
COARSE = ["--set", "geometry.wall_thickness=0.006", "--set", "mesh.size=0.15", "--set", "mesh.degree=2",
          "--set", "mesh.grading=1", "--set", "analysis.modal.f_max=2000", "--set", "output.pictures=false"]
# the other trap: a plate with an explicit size asked for everything below 1 MHz
MEGAHERTZ_PLATE = ["--set", "geometry.a=0.3", "--set", "geometry.b=0.2", "--set", "geometry.h=0.005",
                   "--set", "mesh.size=0.05", "--set", "analysis.modal.f_max=1e6", "--set", "output.pictures=false"]


def housingfe(*args, cwd):
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    return subprocess.run([sys.executable, "-m", "housingfe", *args], capture_output=True, text=True, cwd=cwd,
                          env=env, timeout=300)


def strict_json(path):
    """modes.json read as strict JSON: NaN / Infinity are errors."""
    def refuse(token):
        raise ValueError(f"not JSON: {token}")

    return json.loads(path.read_text(), parse_constant=refuse)


def test_calibration_constants_are_the_fit_of_the_data():
    """ERROR_MODEL is what fit_calibration makes of housingfe/data/benchmarks/resolution_calibration.csv (so the
    constants cannot drift from the data), and every calibration point lies on or under its family's bound."""
    fitted = resolution.fit_calibration()
    assert fitted == resolution.ERROR_MODEL
    for family, points in resolution.calibration_points().items():
        typical, bound = zip(*(resolution.error_at(family, x) for x, _ in points))
        errors = np.array([e for _, e in points])
        inside = errors <= resolution.FIT_ERROR_CEILING
        assert np.all(errors[inside] <= np.array(bound)[inside] * (1 + 1e-3)), family
        # the typical curve is typical: between a fifth and four fifths of the fitted points lie above it
        fit = inside & (errors >= resolution.FIT_ERROR_FLOOR)
        above = np.mean(errors[fit] > np.array(typical)[fit])
        assert 0.2 < above < 0.8, (family, above)


@pytest.mark.parametrize("size", [0.05, 0.025])
def test_estimate_bounds_the_error_against_kirchhoff(size, comm):
    """A simply supported 300 x 200 x 5 mm steel plate, Q2 bricks at 50 and 25 mm: each bending mode below
    2.5 kHz is within the estimated bound of Navier's thin-plate frequency (plus 0.3 % for what a 3-D solid adds
    to Kirchhoff's plate: shear and rotary inertia, (k h)^2-small here), and the typical estimate is within a
    factor 3 of the highest modes' error."""
    from housingfe.scene import build_model_from_scene
    from housingfe.solvers import modal

    a, b, t, f_max = 0.3, 0.2, 0.005, 2500.0
    scene = load_scene("nafems-fv12", f"geometry.a={a}", f"geometry.b={b}", f"geometry.h={t}",
                       'geometry.edges={x0="simply_supported", x1="simply_supported", y0="simply_supported", '
                       'y1="simply_supported"}', f"mesh.size={size}", "mesh.degree=2",
                       f"analysis.modal.f_max={f_max}")
    model = build_model_from_scene(scene, comm)
    mat = model.material
    D = mat.youngs_modulus * t**3 / (12 * (1 - mat.poisson_ratio**2))
    navier = sorted(math.pi / 2 * (m**2 / a**2 + n**2 / b**2) * math.sqrt(D / (mat.density * t))
                    for m in range(1, 12) for n in range(1, 12))
    navier = np.array([f for f in navier if f < f_max])
    result = modal.solve_modes(model.K, model.M, 2 * f_max)
    f = result.frequencies_hz
    f = f[f > 10.0][:len(navier)]        # the three in-plane rigid motions the edge supports leave free
    h = resolution.largest_cell_edge(model.housing.mesh)
    x = h / np.array([bending_wavelength(fi, t, mat.youngs_modulus, mat.poisson_ratio, mat.density)
                      for fi in navier])
    typical, bound = (np.array(v) for v in zip(*(resolution.error_at("Q2", xi) for xi in x)))
    error = np.abs(f / navier - 1)
    assert np.all(error <= bound + 0.003), np.c_[navier, error, bound]
    # not a wild overestimate: the highest modes' error is within a factor 3 of the typical estimate
    assert typical[-1] / 3 - 0.003 <= error[-3:].max() <= 3 * typical[-1] + 0.003, (error[-3:], typical[-1])
    # and the model reports that estimate for f_max
    lam = bending_wavelength(f_max, t, mat.youngs_modulus, mat.poisson_ratio, mat.density)
    assert model.resolution.estimated_error == pytest.approx(resolution.error_at("Q2", h / lam)[0])
    assert model.resolution.error_bound == pytest.approx(resolution.error_at("Q2", h / lam)[1])


def test_coarse_mesh_is_refused_before_meshing_in_one_line(tmp_path):
    """150 mm bricks on 6 mm walls at 2 kHz: exit 2, one line naming mesh.size, the numbers and the way out."""
    out = tmp_path / "out"
    proc = housingfe("run", "box-free", *COARSE, "--out", str(out), cwd=tmp_path)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2, proc.stderr
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert "mesh.size" in lines[0] and "mesh.allow_coarse" in lines[0] and "2000 Hz" in lines[0], lines[0]
    assert "per bending wavelength" in lines[0]
    assert not out.exists()


def test_megahertz_plate_is_refused(tmp_path):
    out = tmp_path / "out"
    proc = housingfe("run", "nafems-fv12", *MEGAHERTZ_PLATE, "--out", str(out), cwd=tmp_path)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr
    assert "mesh.size" in lines[0] and "far too coarse" in lines[0], lines[0]
    assert not out.exists()


def test_megahertz_plate_run_anyway_says_its_modes_are_the_mesh_s(tmp_path):
    """Run anyway, the 1 MHz plate's ~900 modes on ~1000 DOFs are "complete" only for the discrete model: the
    summary says so and warns that f_max is in the top of the discrete spectrum and that the wall is no thin
    plate at that frequency."""
    out = tmp_path / "out"
    proc = housingfe("run", "nafems-fv12", *MEGAHERTZ_PLATE, "--set", "mesh.allow_coarse=true", "--out", str(out),
                     cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    summary = (out / "summary.txt").read_text()
    assert "complete (of the discrete model): True" in summary and "error near f_max > 100 %" in summary
    warnings = strict_json(out / "modes.json")["resolution"]["warnings"]
    assert any("top of the discrete spectrum" in w for w in warnings)
    assert any("no thin plate" in w for w in warnings)


def test_allow_coarse_runs_and_warns_in_summary_and_json(tmp_path):
    """With mesh.allow_coarse the coarse run goes ahead, and both summary.txt and modes.json say how coarse it
    is: the estimated error stands next to "complete"."""
    out = tmp_path / "out"
    proc = housingfe("run", "box-free", *COARSE, "--set", "mesh.allow_coarse=true", "--out", str(out),
                     cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    summary = (out / "summary.txt").read_text()
    complete_line = next(line for line in summary.splitlines() if "complete" in line)
    assert "of the discrete model" in complete_line and "estimated discretisation error" in complete_line
    assert "WARNING: mesh too coarse for f_max = 2000 Hz" in summary
    data = strict_json(out / "modes.json")
    res = data["resolution"]
    assert res["status"] == "far too coarse" and res["worst_wall"] == "walls"
    assert res["estimated_error_near_f_max"] > resolution.REFUSE_ERROR
    assert res["error_bound_near_f_max"] > res["estimated_error_near_f_max"]
    walls = {w["name"]: w for w in res["walls"]}
    # the longest cell edge of the mesh: at most the 150 mm asked for (the edges are split into equal parts)
    assert 0.1 < res["element_size_m"] <= 0.15 + 1e-9
    assert walls["walls"]["bending_wavelength_m"] == pytest.approx(
        bending_wavelength(2000.0, 0.006, 210e9, 0.3, 7850.0), rel=0.02)
    assert walls["walls"]["elements_per_wavelength"] < 1.3 and walls["flange"]["elements_per_wavelength"] < 2
    assert any("mesh too coarse" in w for w in res["warnings"])


def test_no_elastic_mode_below_f_max_ends_cleanly_with_strict_json(tmp_path):
    """box-free (published first mode 641 Hz) asked for modes below 500 Hz: no IndexError; the published rows
    that have no counterpart carry null, and modes.json is strict JSON."""
    out = tmp_path / "out"
    proc = housingfe("run", "box-free", "--set", "analysis.modal.f_max=500", "--set", "output.pictures=false",
                     "--out", str(out), cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    data = strict_json(out / "modes.json")
    assert data["frequencies_hz"] == []
    first = next(r for r in data["published"] if r["quantity"].startswith("first elastic mode"))
    assert first["ours"] is None and "not computed" in first["note"]


def test_fewer_modes_than_published_gives_null_not_nan(tmp_path):
    """NAFEMS FV12 lists six modes; below 3 Hz there are three: the other three are null in modes.json."""
    out = tmp_path / "out"
    proc = housingfe("run", "nafems-fv12", "--set", "analysis.modal.f_max=3.0", "--set", "output.pictures=false",
                     "--out", str(out), cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "NaN" not in (out / "modes.json").read_text()
    rows = strict_json(out / "modes.json")["published"]
    ours = [r["ours"] for r in rows if r["quantity"].startswith("elastic mode")]
    assert len(ours) == 6 and all(v is not None for v in ours[:3]) and ours[3:] == [None, None, None]


def test_write_json_is_strict(tmp_path):
    from housingfe.outputs import write_json

    write_json(tmp_path / "x.json", {"a": float("nan"), "b": [np.inf, np.float64(1.5)], "c": np.array([-np.inf])})
    assert strict_json(tmp_path / "x.json") == {"a": None, "b": [None, 1.5], "c": [None]}


def test_graded_largest_element_is_gmsh_bump_middle():
    """The Bump distribution's middle element, s_mid = size atanh(sqrt(1 - g)) / sqrt(1 - g): an upper bound of
    the measured longest edge of box-free's graded default mesh (Q3, 40 mm, g = 0.25: 48.6 mm measured)."""
    assert resolution.graded_largest_element(0.04, 1.0) == 0.04
    assert resolution.graded_largest_element(0.04, 0.25) == pytest.approx(0.04 * math.atanh(0.75**0.5) / 0.75**0.5)
    assert 0.0486 < resolution.graded_largest_element(0.04, 0.25) < 0.065
