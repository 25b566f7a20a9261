"""The C3D10 deck of `housingfe bench imported`: CalculiX solves the very mesh housingfe solved, so the two codes'
free modes agree to the small difference of their mass integration (the comparison is one of solvers)."""
import shutil

import numpy as np
import pytest

from housingfe.benchmarks.imported import run_calculix_case, run_housingfe_case, write_c3d10_deck


def test_calculix_gets_the_cad_mesh_housingfe_solves_and_finds_its_modes(tmp_path):
    from housingfe.geometry.cad import gmsh_session

    # a 400 x 300 x 20 mm steel plate with a 60 mm hole, written to STEP in m by gmsh's OpenCASCADE
    with gmsh_session() as gmsh:
        gmsh.model.add("b")
        occ = gmsh.model.occ
        occ.cut([(3, occ.addBox(0, 0, 0, 0.4, 0.3, 0.02))], [(3, occ.addCylinder(0.2, 0.15, -0.01, 0, 0, 0.04, 0.03))])
        occ.synchronize()
        gmsh.write(str(tmp_path / "block.step"))
    scene = tmp_path / "block.toml"
    scene.write_text('[scene]\nname = "block"\nkind = "housing"\n[geometry]\nkind = "cad"\nfile = "block.step"\n'
                     'units = "m"\n[mesh]\nelement = "tet"\ndegree = 2\nsize = 0.05\n[analysis.modal]\nf_max = 4000.0\n')
    ours = run_housingfe_case(str(scene))
    assert ours["complete"] and ours["rigid"] == 6
    # P2 on straight tetrahedra: a DOF triple per vertex and per edge, exactly the C3D10 nodes
    deck = write_c3d10_deck(str(scene), tmp_path / "block.inp", 6 + len(ours["frequencies_hz"]) + 5)
    assert 3 * deck["nodes"] == ours["dofs"] and deck["nodes"] == deck["vertices"] + deck["edges"]
    if not shutil.which("ccx"):
        pytest.skip("CalculiX (ccx) not installed")
    work = tmp_path / "ccx"
    work.mkdir()
    theirs = np.asarray(run_calculix_case(str(tmp_path / "block.inp"), work)["frequencies_hz"])
    f = np.asarray(ours["frequencies_hz"])
    assert len(f) >= 5
    assert theirs[:len(f)] == pytest.approx(f, rel=1e-3)
