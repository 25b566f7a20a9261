"""A volume mesh written by another project, as a user brings it: scikit-fem's ex21 mesh (`beams.msh`, gmsh 2.2,
BSD-3; tests/geometry/data/README.md) read as geometry kind "mesh", clamped at its physical surface `fixed`.

The reference is another code on the same file: scikit-fem 12.0.2 solving the same discrete problem (P2
tetrahedra, E = 200 GPa, nu = 0.3, rho = 8050 kg/m^3; tests/geometry/data/skfem_beams_reference.py says how the
numbers were produced).  Both integrate P2 stiffness and mass exactly on straight tetrahedra, so the eigenvalues must
agree to the eigensolvers' tolerance (1e-11 measured; 1e-8 asserted), and the DOF count must be scikit-fem's."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.geometry.test_imported_mesh import mesh_scene

BEAMS = Path(__file__).parent / "data" / "skfem_beams.msh"
# scikit-fem 12.0.2, ex21 on skfem_beams.msh: the lowest eigenvalues omega^2, (rad/s)^2, and its DOF count
SKFEM_EIGENVALUES = np.array([50194.94437033, 251542.76238882, 301210.39794464, 598305.23144171])
SKFEM_DOFS = 4899
F_MAX_HZ = 130.0            # the four modes above (35.7, 79.8, 87.3, 123.1 Hz) and no fifth


def beams_scene(folder: Path, units: str = "m") -> Path:
    """A housing scene of the scikit-fem mesh with ex21's steel, clamped at `fixed`."""
    # the imported-mesh tests' scene (their kind "mesh" header, degree 2, no pictures) with ex21's steel and clamp
    return mesh_scene(folder, str(BEAMS), units, f_max=F_MAX_HZ, extra="""[[geometry.surfaces]]
name = "fixed"
set = "fixed"
[material]
name = "steel"
youngs_modulus = 200e9
poisson_ratio = 0.3
density = 8050.0
[[supports]]
surface = "fixed"
kind = "fixed"
""")


def run_cli(*args, cwd: Path, ranks: int = 1) -> subprocess.CompletedProcess:
    command = [sys.executable, "-m", "housingfe", *args]
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    if ranks > 1:
        command = [shutil.which("mpirun"), "-n", str(ranks), *command]
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return subprocess.run(command, capture_output=True, text=True, timeout=300, cwd=cwd, env=env)


def test_housingfe_run_gives_scikit_fems_eigenvalues_on_its_mesh(tmp_path):
    run = run_cli("run", str(beams_scene(tmp_path)), "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    result = json.loads((tmp_path / "out" / "modes.json").read_text())
    assert result["dofs"] == SKFEM_DOFS and result["complete"]
    assert result["mass_kg"] == pytest.approx(0.12 * 8050.0, rel=1e-12)     # the file's 0.12 m^3 of steel
    eigenvalues = (2 * np.pi * np.array(result["frequencies_hz"])) ** 2
    assert eigenvalues.size == SKFEM_EIGENVALUES.size
    assert np.max(np.abs(eigenvalues / SKFEM_EIGENVALUES - 1)) < 1e-8


@pytest.mark.mpi
def test_two_ranks_give_the_same_eigenvalues(tmp_path):
    if not shutil.which("mpirun"):
        pytest.skip("mpirun not installed")
    run = run_cli("run", str(beams_scene(tmp_path)), "--out", str(tmp_path / "two"), cwd=tmp_path, ranks=2)
    assert run.returncode == 0, run.stderr
    result = json.loads((tmp_path / "two" / "modes.json").read_text())
    assert result["dofs"] == SKFEM_DOFS
    eigenvalues = (2 * np.pi * np.array(result["frequencies_hz"])) ** 2
    assert np.max(np.abs(eigenvalues / SKFEM_EIGENVALUES - 1)) < 1e-8


def test_the_wrong_unit_is_refused_with_the_one_that_fits(tmp_path):
    """Read in mm the 2.4 m frame would be 2.4 mm across: one line naming the file and the key, exit 2, no
    result folder."""
    run = run_cli("run", str(beams_scene(tmp_path, units="mm")), "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert run.returncode == 2
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("housingfe: error: "), run.stderr
    assert "skfem_beams.msh" in lines[0] and "geometry.units" in lines[0] and 'geometry.units = "m"' in lines[0]
    assert not (tmp_path / "out").exists()
