"""The size ladder (housingfe.fe.model.mesh_on_size_ladder): a DERIVED element size whose mesh the quality rule
refuses is meshed again at most SIZE_LADDER_STEPS times, each 0.9 x the size before on the 3-significant-digit
grid, and the first mesh that passes is used; none passing is refused in one line naming the sizes tried; a
derived size that passes is meshed once, exactly as before the ladder.  The real part it is for, NIST FTC-06:
tests/geometry/test_cad_real_files.py.

The parts here are thin steel slabs written by gmsh's own OpenCASCADE kernel: at low f_max the derived size is
tens of wall thicknesses, and how many flat tetrahedra Delaunay leaves depends on the size.
"""
from __future__ import annotations

import subprocess
import sys
from decimal import Decimal
from pathlib import Path

import numpy as np
import pytest

from housingfe.fe.model import DERIVED_SIZE_DIGITS, SIZE_LADDER_STEPS, element_size, size_ladder
from housingfe.geometry.cad import _native_output_captured, gmsh_session


def _slab(folder: Path, thickness: float, f_max: float) -> Path:
    """A 300 x 200 mm steel slab `thickness` (m) thick as STEP, and a P1 tetrahedral scene of it meshed for
    f_max (Hz) at 6 elements per bending wavelength; returns the scene file."""
    with gmsh_session() as gmsh:
        gmsh.model.add("slab")
        gmsh.model.occ.addBox(0, 0, 0, 0.3, 0.2, thickness)
        gmsh.model.occ.synchronize()
        with _native_output_captured():
            gmsh.write(str(folder / "slab.step"))
    scene = folder / "slab.toml"
    scene.write_text('[scene]\nname = "slab"\nkind = "housing"\n'
                     '[geometry]\nkind = "cad"\nfile = "slab.step"\nunits = "m"\n[material]\nname = "steel"\n'
                     '[mesh]\nelement = "tet"\ndegree = 1\nelements_per_wavelength = 6.0\n'
                     f'[analysis.modal]\nf_max = {f_max}\n'
                     '[output]\nmode_pictures = 0\nparaview = false\npictures = false\n')
    return scene


def test_the_ladder_steps_by_0_9_rounded_down_to_3_digits():
    assert size_ladder(0.044) == [0.044, 0.0396, 0.0356, 0.032]           # 35.64 -> 35.6, 32.04 -> 32.0 mm
    assert size_ladder(0.0254) == [0.0254, 0.0228, 0.0205, 0.0184]        # 22.86 -> 22.8, 20.52 -> 20.5 mm
    for sizes in (size_ladder(0.044), size_ladder(0.0999), size_ladder(0.1)):
        assert len(sizes) == SIZE_LADDER_STEPS + 1
        for coarse, fine in zip(sizes, sizes[1:]):
            # rounded down by less than one step of the last digit (0.1-1 %); 1e-12: 0.9 * 0.044 is 0.03959999...
            assert 0.9 * coarse * (1 - 10 ** (1 - DERIVED_SIZE_DIGITS)) <= fine <= 0.9 * coarse * (1 + 1e-12)
            assert len(Decimal(repr(fine)).normalize().as_tuple().digits) <= DERIVED_SIZE_DIGITS


def test_a_derived_size_that_passes_is_meshed_once_as_before(tmp_path):
    """3 mm slab at 120 Hz: the derived 82.6 mm passes the quality rule; build_model's mesh is, node for node and
    cell for cell, the mesh build_mesh makes at that size (what build_model made before the ladder)."""
    from mpi4py import MPI

    from housingfe.fe.model import build_model
    from housingfe.geometry import build_mesh
    from housingfe.scene import load_housing_scene

    scene = load_housing_scene(str(_slab(tmp_path, 0.003, 120.0)))[0]
    material = scene.material.resolve()
    size = element_size(scene.mesh, scene.geometry, 120.0, material)
    model = build_model(scene.geometry, material, scene.mesh, 120.0, MPI.COMM_SELF)
    before = build_mesh(scene.geometry, "tet", size, 1, MPI.COMM_SELF)
    assert [t["size_m"] for t in model.element_size_tries] == [size] and model.element_size_tries[0]["passed"]
    assert model.housing.element_size == size
    after = model.housing.mesh
    assert np.array_equal(after.geometry.x, before.mesh.geometry.x)
    assert np.array_equal(after.geometry.dofmap.array, before.mesh.geometry.dofmap.array)


def test_no_size_on_the_ladder_passing_is_refused_in_one_line_naming_the_sizes_tried(tmp_path):
    """1 mm slab at 30 Hz: the derived size is ~95 wall thicknesses, every tetrahedron of every mesh on the ladder
    is flat: exit 2, one line, the four sizes named, no result folder."""
    from housingfe.scene import load_housing_scene

    scene_file = _slab(tmp_path, 0.001, 30.0)
    scene = load_housing_scene(str(scene_file))[0]
    sizes = size_ladder(element_size(scene.mesh, scene.geometry, 30.0, scene.material.resolve()))
    assert sizes[0] == pytest.approx(0.0954, rel=0.01)
    run = subprocess.run([sys.executable, "-m", "housingfe", "run", scene_file.name, "--out", "res"],
                         capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert run.returncode == 2 and run.stderr.count("\n") == 1 and "Traceback" not in run.stderr
    assert run.stderr.startswith("housingfe: error: slab.toml: mesh.size: element quality")
    named = run.stderr.split("finer sizes of the ladder tried: ")[1]
    assert [float(part.split(" mm")[0]) for part in named.split(", ")] == [s * 1e3 for s in sizes]
    assert not (tmp_path / "res").exists()


def test_a_finer_size_the_memory_guard_refuses_ends_the_ladder(tmp_path, monkeypatch):
    """3 mm slab at 80 Hz: the derived 101 mm mesh is refused (flat tetrahedra); with the memory available set
    between the guard's estimates at 101 and 90.9 mm, the ladder stops before meshing 90.9 mm and the refusal
    names both."""
    from mpi4py import MPI

    from housingfe.errors import InputError
    from housingfe.fe import model as model_module
    from housingfe.scene import load_housing_scene

    scene = load_housing_scene(str(_slab(tmp_path, 0.003, 80.0)))[0]
    size = element_size(scene.mesh, scene.geometry, 80.0, scene.material.resolve())
    assert size_ladder(size)[:2] == [0.101, 0.0909]
    need = [model_module.check_model_size(scene.geometry, scene.mesh, s, MPI.COMM_SELF)["memory_bytes"]
            for s in (0.101, 0.0909)]
    assert need[1] > need[0]
    between = int((need[0] + need[1]) / 2)
    monkeypatch.setattr(model_module, "available_memory_bytes", lambda: (between, 2 * between))
    with pytest.raises(InputError) as exc:
        model_module.mesh_on_size_ladder(scene.geometry, scene.mesh, size, MPI.COMM_SELF, derived=True)
    message = str(exc.value)
    assert message.startswith("mesh.size: element quality")
    assert "ladder tried: 101 mm " in message and "the next finer size, 90.9 mm, exceeds the memory guard" in message
    assert "81.8 mm" not in message
