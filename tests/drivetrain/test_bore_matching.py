"""The drivetrain's bearings matched to an imported housing's bores (housingfe.drivetrain.bore_matching): the right
bore by position and by name, the fitted cylinders where the geometry puts them, and one-line errors for a bore off
its shaft (with the distance), a bore that does not hold its bearing, a bore the housing does not have, a bearing
the drivetrain does not have."""
from __future__ import annotations

import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from housingfe.errors import InputError
from tests.runup.imported_gearbox import write_imported_gearbox

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def imported(tmp_path_factory, comm):
    """(run-up scene path, HousingModel of the STEP housing on a 60 mm mesh)."""
    from housingfe.runup.scene import housing_model_for
    from housingfe.scene import load_housing_scene

    runup = write_imported_gearbox(tmp_path_factory.mktemp("imported"))
    hs, _ = load_housing_scene(str(runup.parent / "housing.toml"))
    return runup, housing_model_for(hs, 1500.0, comm)


def test_each_bearing_finds_the_bore_on_its_shaft_by_position(imported):
    from housingfe.drivetrain.bore_matching import bore_shape, match_bores
    from housingfe.drivetrain.description import test_gearbox

    _, model = imported
    matched = match_bores(model, test_gearbox("A"), match="position")
    assert matched == {"pinion_front": "bore_A_front", "pinion_back": "bore_A_back",
                       "wheel_front": "bore_B_front", "wheel_back": "bore_B_back"}
    # the fitted cylinder of a bore: the scene's 170 mm bore on the pinion axis, mid-plate (the linear mesh's
    # vertices lie on the CAD cylinder)
    b = bore_shape(model, "A_front", "bore_A_front")
    assert abs(abs(b.axis[1]) - 1.0) < 1e-6
    assert np.allclose(b.centre, [-0.126, -0.1075, 0.2], atol=2e-4)
    assert b.radius == pytest.approx(0.085, abs=2e-4)
    assert 2 * b.s_hi == pytest.approx(0.065, abs=1e-6)         # the 65 mm bearing plate


def test_a_map_overrides_and_a_bore_beyond_the_bearing_is_refused(imported):
    from housingfe.drivetrain.bore_matching import match_bores
    from housingfe.drivetrain.description import test_gearbox

    _, model = imported
    dt = test_gearbox("A")
    swapped = {"pinion_front": "A_front", "pinion_back": "bore_A_back", "wheel_front": "B_front",
               "wheel_back": "B_back"}
    assert match_bores(model, dt, swapped)["pinion_back"] == "bore_A_back"
    # the back bore (y 75..140 mm) does not hold the front bearing at y = -107.5 mm: 182.5 mm beyond its end
    with pytest.raises(InputError, match=r"^housing.bores: bore 'A_back' .* does not hold the bearing at "
                                         r"\(-0.126, -0.1075, 0.2\) m: it lies 182.5 mm beyond the bore's end"):
        match_bores(model, dt, {"pinion_front": "A_back"})


def test_a_bore_off_its_shaft_names_the_bore_and_the_distance(imported):
    """The pinion shaft moved 12.3 mm along x: its bores no longer line up (tolerance 1 mm)."""
    from housingfe.drivetrain.bore_matching import match_bores
    from housingfe.drivetrain.description import test_gearbox

    _, model = imported
    dt = test_gearbox("A")
    pinion, wheel = dt.shafts
    moved = replace(dt, shafts=(replace(pinion, centre=(-0.126 + 0.0123, 0.0, 0.2)), wheel))
    with pytest.raises(InputError) as err:
        match_bores(model, moved, {"pinion_front": "A_front"})
    msg = str(err.value)
    assert msg.startswith("housing.bores: bore 'A_front' (centre (-0.126, -0.1075, 0.2) m) lies 12.3 mm off the "
                          "pinion shaft's axis (tolerance 1 mm)"), msg
    assert "\n" not in msg
    # by position: nothing holds the front bearing; the nearest bore is named with the same distance
    with pytest.raises(InputError, match=r"no bore holds the bearing 'pinion_front' .* the nearest: bore 'A_front' "
                                         r".* lies 12.3 mm off"):
        match_bores(model, moved, match="position")
    # a looser tolerance accepts it
    assert match_bores(model, moved, match="position", tolerance=0.013)["pinion_front"] == "bore_A_front"


@pytest.mark.parametrize("kwargs, words", [
    ({"mapping": {"pinion_front": "C_front"}}, "housing.bores.pinion_front: the housing has no bore 'C_front' "
                                               "(its bores: A_back, A_front, B_back, B_front)"),
    ({"match": "name"}, "housing.bores: the bearing 'pinion_front' needs the housing bore 'pinion_front'"),
    ({"mapping": {"input_front": "A_front"}}, "housing.bores.input_front: the drivetrain has no bearing "
                                              "'input_front'"),
    ({"mapping": {"pinion_front": "A_front", "pinion_back": "A_front"}}, "housing.bores: bore 'A_front' (centre"),
])
def test_a_missing_bore_or_bearing_is_one_line(imported, kwargs, words):
    from housingfe.drivetrain.bore_matching import match_bores
    from housingfe.drivetrain.description import test_gearbox

    _, model = imported
    with pytest.raises(InputError) as err:
        match_bores(model, test_gearbox("A"), **kwargs)
    assert str(err.value).startswith(words) and "\n" not in str(err.value), str(err.value)


def test_the_built_in_housing_matches_by_name_unchanged(comm):
    """The built-in path: the drivetrain's own bore names, checked against the shafts, nothing renamed."""
    from housingfe.drivetrain.bore_matching import match_bores
    from housingfe.drivetrain.description import test_gearbox
    from housingfe.runup.scene import housing_model_for
    from housingfe.scene import load_housing_scene

    hs, _ = load_housing_scene("test-gearbox", ["mesh.size=0.06"])
    model = housing_model_for(hs, 1500.0, comm)
    dt = test_gearbox("A")
    assert match_bores(model, dt) == {b.name: b.bore for b in dt.bearings}
    # the whole-axis groups bore_pinion / bore_wheel hold the bearings too: by position that is ambiguous
    with pytest.raises(InputError, match=r"housing.bores: 2 bores \(pinion, pinion_front\) hold the bearing "
                                         r"'pinion_front'"):
        match_bores(model, dt, match="position")


def test_cli_a_bore_mapped_off_its_shaft_is_exit_2_one_line_no_folder(imported, tmp_path):
    runup, _ = imported
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "housingfe", "run", str(runup), "--out", str(out), "--set",
                           'housing.bores={wheel_front = "A_front"}'], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2, proc.stderr
    # the match needs the FE mesh: the progress line of the housing model comes first, then the error alone
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip() and not ln.startswith("run-up ")]
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert lines[0] == (f"housingfe: error: {runup}: housing.bores: bore 'A_front' (centre (-0.126, -0.1075, 0.2) m) "
                        f"lies 200 mm off the wheel shaft's axis (tolerance 1 mm) (bearing 'wheel_front')"), lines[0]
    assert not out.exists() and not list(tmp_path.glob(".out*"))


def test_a_mesh_housing_matches_its_bore_sets_by_position(tmp_path, comm):
    """The `mesh` kind names its bores by their own name (no bore_ prefix): the built-in gearbox mesh written to
    gmsh .msh with its four bearing bores as node sets, read back with other names, matched by position."""
    from housingfe.drivetrain.bore_matching import match_bores
    from housingfe.drivetrain.description import test_gearbox
    from housingfe.geometry.imported_mesh import write_mesh_file
    from housingfe.runup.scene import housing_model_for
    from housingfe.scene import load_housing_scene

    hs, _ = load_housing_scene("test-gearbox", ["mesh.size=0.06"])
    built_in = housing_model_for(hs, 1500.0, comm)
    seats = ["pinion_front", "pinion_back", "wheel_front", "wheel_back"]
    write_mesh_file(built_in.housing, tmp_path / "gearbox.msh", units="m", node_sets=[f"bore_{s}" for s in seats])
    bores = "".join(f'[[geometry.bores]]\nname = "seat_{i}"\nset = "bore_{s}"\n' for i, s in enumerate(seats))
    (tmp_path / "housing.toml").write_text(f"""[scene]
name = "mesh-gearbox"
kind = "housing"
[geometry]
kind = "mesh"
file = "gearbox.msh"
units = "m"
{bores}
[mesh]
degree = 2
[analysis.modal]
f_max = 1500.0
""")
    hm, _ = load_housing_scene(str(tmp_path / "housing.toml"))
    model = housing_model_for(hm, 1500.0, comm)
    assert match_bores(model, test_gearbox("A"), match="position") == {s: f"seat_{i}" for i, s in enumerate(seats)}
