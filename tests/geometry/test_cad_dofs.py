"""The memory guard's DOF estimate for an imported CAD housing (issue 29 item 8, `estimate_cad_dofs`) against the
mesh the guard protects: an open box with 10 mm walls, written to STEP by gmsh's own OpenCASCADE kernel, meshed
by build_cad_mesh (the `cad` kind's path) at an element size below the wall (5 mm: two elements through it) and
above it (20 mm: one).  The DOFs of the P2 field are counted on the mesh (vertices + edges, each three
components): 0.98 and 1.10 of the mesh's count (the former estimate, 60 V / (h^2 min(h, t)), 1.98 and 1.17)."""
from __future__ import annotations

import pytest
from mpi4py import MPI

from housingfe.geometry.cad import (
    CadGeometry,
    _native_output_captured,
    build_cad_mesh,
    estimate_cad_dofs,
    gmsh_session,
)

WALL_MM = 10.0


@pytest.fixture(scope="module")
def open_box(tmp_path_factory):
    path = tmp_path_factory.mktemp("dofs") / "open-box.step"
    with gmsh_session() as gmsh:
        occ = gmsh.model.occ
        outer = occ.addBox(0, 0, 0, 160, 100, 70)       # mm; the cavity overshoots the top: an open box
        occ.cut([(3, outer)], [(3, occ.addBox(WALL_MM, WALL_MM, WALL_MM, 160 - 2 * WALL_MM, 100 - 2 * WALL_MM, 80))])
        occ.synchronize()
        with _native_output_captured():
            gmsh.write(str(path))
    return CadGeometry(kind="cad", file=str(path), units="mm")


def _p2_dofs(mesh) -> int:
    mesh.topology.create_entities(1)
    return 3 * (mesh.topology.index_map(0).size_global + mesh.topology.index_map(1).size_global)


@pytest.mark.parametrize("size_mm", [5.0, 20.0])
def test_estimate_is_within_30_percent_of_the_mesh(open_box, size_mm):
    size = size_mm / 1e3
    estimate = estimate_cad_dofs(open_box, "tet", 2, size, 1)
    actual = _p2_dofs(build_cad_mesh(open_box, "tet", size, 1, MPI.COMM_SELF)["mesh"])
    assert 0.7 < estimate / actual < 1.3, (size_mm, estimate, actual)
