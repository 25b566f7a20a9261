"""A real third-party STEP file through `housingfe inspect` and `housingfe run`, as a user hits them.

NIST's FTC-06 test part (public domain, tests/geometry/data/README.md): one solid, millimetres, written by a
commercial CAD system (not by gmsh), 12 x 3.85 x 9.75 in on its drawing.  The expected numbers are the drawing's
inch dimensions and OpenCASCADE's own volume of the file, not earlier output of this package.
"""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

NIST_FTC_06 = Path(__file__).parent / "data" / "nist_ftc_06_asme1_rd.stp"
INCH = 25.4e-3


def _occ_volume_m3(path: Path) -> float:
    """The solid's volume by OpenCASCADE read directly (STEP in mm -> m^3)."""
    import gmsh

    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.occ.importShapes(str(path))
        gmsh.model.occ.synchronize()
        return sum(gmsh.model.occ.getMass(3, v) for _, v in gmsh.model.getEntities(3)) * 1e-9
    finally:
        gmsh.finalize()


def test_inspect_reads_the_nist_part_with_its_drawing_size_volume_and_through_hole(tmp_path):
    run = subprocess.run([sys.executable, "-m", "housingfe", "inspect", str(NIST_FTC_06), "--units", "mm",
                          "--material", "steel", "--out", str(tmp_path)], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    text = run.stdout
    assert f"{NIST_FTC_06}: 1 solid(s)" in text
    # the drawing: 12 in wide, 3.85 in deep, 9.75 in high; the file's mm coordinates become m
    assert f"bounding box [{-6 * INCH:.6g}, 0, {-9.75 * INCH:.6g}] .. [{6 * INCH:.6g}, {3.85 * INCH:.6g}, 0] m" in text
    assert "(304.8 x 97.79 x 247.7 mm, units = \"mm\")" in text
    volume = _occ_volume_m3(NIST_FTC_06)
    assert 3.0e-3 < volume < 3.6e-3          # a 26 kg steel part: the unit was honoured
    assert f"volume {volume:.6g} m^3, mass {7850 * volume:.5g} kg (steel" in text
    # 20 concave cylinders grouped into bores; among them the 1/4 in hole through the full 12 in width along x
    assert "candidate bores (concave cylindrical faces by axis): 20, the 12 largest shown" in text
    assert f"axis [1, 0, 0], radius {INCH / 8 * 1e3:.4g} mm, length {12 * INCH * 1e3:.4g} mm" in text
    assert (tmp_path / "nist_ftc_06_asme1_rd-inspect.png").stat().st_size > 10_000
    assert (tmp_path / "nist_ftc_06_asme1_rd-scene.toml").is_file()


@pytest.mark.xfail(strict=True, reason="known bug: gmsh 4.8's Delaunay (and the HXT fallback) leave slivers "
                   "(shape ratio 0.005) at this part's sub-millimetre features at every coarse size tried "
                   "(12-40 mm), so the run stops at the element-quality check; see docs/imported-bench.md")
def test_free_modes_of_the_nist_part_from_a_mm_scene(tmp_path):
    """`housingfe run` of a cad scene in mm: 6 rigid modes, complete, the rigid modes' mass = density x OCC's
    volume (to the faceting of the curved faces by straight-edged tetrahedra)."""
    shutil.copy(NIST_FTC_06, tmp_path / "part.stp")
    scene = tmp_path / "part.toml"
    scene.write_text('[scene]\nname = "nist-ftc-06"\nkind = "housing"\n'
                     '[geometry]\nkind = "cad"\nfile = "part.stp"\nunits = "mm"\n'
                     '[mesh]\nelement = "tet"\ndegree = 1\nsize = 0.03\n'
                     '[analysis.modal]\nf_max = 2000.0\n'
                     '[output]\nmode_pictures = 0\nparaview = false\npictures = false\n')
    out = tmp_path / "res"
    run = subprocess.run([sys.executable, "-m", "housingfe", "run", str(scene), "--out", str(out)],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    modes = json.loads((out / "modes.json").read_text())
    assert len(modes["rigid_body_frequencies_hz"]) == 6 and modes["complete"]
    exact = 7850.0 * _occ_volume_m3(NIST_FTC_06)
    assert modes["mass_kg"] == pytest.approx(exact, rel=1e-9)
    # straight-edged tetrahedra cut the chords of the holes and fillets: a fraction of a per cent
    assert modes["mass_from_rigid_modes_kg"] == pytest.approx(exact, rel=5e-3)
