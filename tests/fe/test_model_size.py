"""Model-size guard (issue 12 item 12): DOFs and memory estimated before meshing, implausible geometry."""
import os
import subprocess
import sys

import pytest

from housingfe.errors import InputError
from housingfe.fe import model as model_module
from housingfe.geometry.mesh import estimate_dofs
from tests.conftest import load_scene


def _housingfe(tmp_path, *args):
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    # a timeout, not a timing: a guard that fails would start meshing metres of flange (13 GB in 2 min)
    return subprocess.run([sys.executable, "-m", "housingfe", "run", *args, "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=120, env=env, cwd=tmp_path)


def test_flange_typo_stops_before_meshing(tmp_path):
    """The issue's command: a 5 m flange on a 325 x 225 mm box is a unit typo -> one line, exit 2."""
    r = _housingfe(tmp_path, "box-free", "--set", "geometry.flange_width=5.0")
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "geometry.flange_width" in lines[0] and "Traceback" not in r.stderr
    assert not (tmp_path / "out").exists()


def test_too_fine_mesh_stops_with_the_estimate_and_the_override(tmp_path):
    """2 mm elements on the box: ~15 M DOFs, ~200 GB estimated, more than any machine this runs on."""
    r = _housingfe(tmp_path, "box-free", "--set", "mesh.size=0.002")
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr
    assert "mesh.size" in lines[0] and "GB" in lines[0] and "mesh.allow_large" in lines[0]
    assert not (tmp_path / "out").exists()


def test_guard_compares_with_available_memory_and_can_be_overridden(comm, monkeypatch):
    scene = load_scene("box-free", "mesh.size=0.04")
    monkeypatch.setattr(model_module, "available_memory_bytes", lambda: (10**8, 2 * 10**8))
    with pytest.raises(InputError, match="0.1 GB available"):
        model_module.check_model_size(scene.geometry, scene.mesh, 0.04, comm)
    allowed = load_scene("box-free", "mesh.size=0.04", "mesh.allow_large=true")
    estimate = model_module.check_model_size(allowed.geometry, allowed.mesh, 0.04, comm)
    assert estimate["memory_bytes"] > 10**8
    monkeypatch.setattr(model_module, "available_memory_bytes", lambda: (64 * 10**9, 64 * 10**9))
    assert model_module.check_model_size(scene.geometry, scene.mesh, 0.04, comm)["dofs"] > 0


@pytest.mark.parametrize("name, overrides, factor", [
    ("box-free", ("mesh.size=0.04",), 1.1),            # structured hexes: the estimated grid is the mesh
    ("nafems-fv12", (), 1.1),
    ("test-gearbox-interior", (), 3.0),                # tetrahedra with round bores: a factor 3
])
def test_dof_estimate_is_within_a_stated_factor_of_the_mesh(comm, name, overrides, factor):
    from housingfe.scene import build_model_from_scene

    scene = load_scene(name, *overrides)
    model = build_model_from_scene(scene, comm)
    m = scene.mesh
    estimate = estimate_dofs(scene.geometry, m.element, m.degree, model.housing.element_size, m.layers)
    assert 1 / factor < estimate / model.dofs < factor, (estimate, model.dofs)


@pytest.mark.parametrize("override, key", [
    ("geometry.flange_width=5.0", "geometry.flange_width"),
    ("geometry.flange_thickness=0.2", "geometry.height"),
])
def test_implausible_box_dimensions_name_the_key(override, key):
    with pytest.raises(InputError, match=key):
        load_scene("box-free", override)


def test_plate_thicker_than_wide_is_rejected():
    with pytest.raises(InputError, match="geometry.h"):
        load_scene("nafems-fv12", "geometry.h=20.0")
