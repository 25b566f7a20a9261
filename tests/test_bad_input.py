"""The bad-input corpus (issue 12, item 10): malformed scenes and command lines must stop with exit code 2,
one line on stderr that names the offending key (or argument, or file), no traceback and no result folder.

Scenes are written as TOML into tmp_path and run in-process through `housingfe.cli.main` (a subprocess per case
would cost seconds of imports each); a few cases run the console script end to end.  Almost every case is
rejected by the scene check before any meshing; the few that need the mesh (a load point off its surface) use
a coarse linear mesh.  `CORPUS_SIZE` counts the cases (hypothesis examples not included).  Bad output places
(`--out` onto a folder of the user's, `.`, a file, a read-only or busy place; path-like scene names) and killed
runs are the corpus of tests/test_output_safety.py.
"""
from __future__ import annotations

import copy
import os
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from housingfe import cli
from housingfe.scenefile import SCENE_DIR
from tests.correlation.test_cli import SPEC

# A valid, cheap housing scene: every section present, so each case changes exactly one thing.
BASE = {
    "scene": {"name": "bad-input-base", "kind": "housing", "description": "bad-input corpus base"},
    "geometry": {"kind": "box", "length": 0.325, "width": 0.225, "height": 0.125, "wall_thickness": 0.008,
                 "flange_thickness": 0.015, "flange_width": 0.073},
    "material": {"name": "steel"},
    "regions": {},
    "supports": [{"surface": "bolt_1", "kind": "fixed"}],
    "mesh": {"element": "hex", "degree": 1, "size": 0.04, "layers": 1},
    "analysis": {"modal": {"f_max": 200.0},
                 "harmonic": {"f_min": 10.0, "f_max": 50.0, "df": 20.0}},
    "loads": [{"name": "top", "kind": "force", "surface": "outer_top", "point": [0.06, 0.04, 0.125],
               "direction": [0.0, 0.0, -1.0], "radius": 0.005}],
    "damping": {"loss_factor": 0.01},
    "radiation": {"model": "erp"},
    "output": {"mode_pictures": 0, "paraview": False, "pictures": False},
    "reference": {"frequencies_hz": [641.0], "source": "bad-input corpus"},
}

GEARBOX = {"kind": "gearbox", "length": 0.5, "width": 0.3, "height": 0.4, "wall_thickness": 0.008,
           "split_height": 0.2, "bearing_plate": {"thickness": 0.02, "width": 0.4, "below": 0.05, "above": 0.05}}
COUPLING = {"bores": [{"name": "b1", "surface": "outer_top"}],
            "shafts": [{"name": "s", "origin": [0.0, 0.0, 0.2], "axis": [0.0, 1.0, 0.0],
                        "segments": [[0.1, 0.05]]}],
            "bearings": [], "gear_meshes": [], "tie_rods": []}


# ---------------------------------------------------------------- TOML writing (inline tables only)
def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value) if value == value and abs(value) != float("inf") else ("nan" if value != value
                                                                                   else "inf")
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, dict):
        return "{" + ", ".join(f"{_toml_key(k)} = {_toml_value(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise TypeError(value)


def _toml_key(key: str) -> str:
    return key if key and key.replace("_", "").replace("-", "").isalnum() else _toml_value(key)


def to_toml(data: dict) -> str:
    """A scene dict as TOML (every top-level key one line, tables inline); round-trips through tomllib."""
    return "".join(f"{_toml_key(k)} = {_toml_value(v)}\n" for k, v in data.items())


def test_toml_writer_round_trips_and_base_scene_is_valid(tmp_path):
    from housingfe.scene import load_housing_scene

    path = tmp_path / "base.toml"
    path.write_text(to_toml(BASE))
    assert tomllib.loads(path.read_text()) == BASE
    scene, _ = load_housing_scene(str(path))     # so that every case below fails for its own change only
    assert scene.loads[0].name == "top"
    data = copy.deepcopy(BASE)
    data["geometry"] = GEARBOX
    data["coupling"] = COUPLING
    path.write_text(to_toml(data))
    load_housing_scene(str(path))


# ---------------------------------------------------------------- cases
def _set(path: str, value):
    def apply(data):
        *parents, last = path.split(".")
        node = data
        for p in parents:
            node = node[int(p)] if isinstance(node, list) else node.setdefault(p, {})
        if isinstance(node, list):
            node[int(last)] = value
        else:
            node[last] = value
    return apply


def _del(path: str):
    def apply(data):
        *parents, last = path.split(".")
        node = data
        for p in parents:
            node = node[int(p)] if isinstance(node, list) else node[p]
        del node[int(last) if isinstance(node, list) else last]
    return apply


def _all(*changes):
    def apply(data):
        for change in changes:
            change(data)
    return apply


# (id, change to BASE, substrings the one error line must contain)
SCENE_CASES = [
    # [scene]
    ("scene-wrong-type", _set("scene.name", 5), ["scene.name"]),
    ("scene-bad-kind", _set("scene.kind", "gearbox"), ["scene.kind"]),
    ("scene-missing", _del("scene"), ["scene"]),
    ("scene-unknown", _set("scene.author", "me"), ["scene.author", "unknown key"]),
    ("scene-source-kind", _set("scene.kind", "source"), ["scene.kind", "housingfe source"]),
    # [geometry], each kind
    ("box-wrong-type", _set("geometry.length", "long"), ["geometry.length"]),
    ("box-negative", _set("geometry.wall_thickness", -0.008), ["geometry.wall_thickness"]),
    ("box-missing", _del("geometry.height"), ["geometry.height"]),
    # issue 27: every missing key named, not "(and N more)"
    ("box-missing-three", _all(_del("geometry.height"), _del("geometry.width"), _del("geometry.flange_width")),
     ["geometry.height", "geometry.width", "geometry.flange_width", "missing"]),
    ("box-unknown", _set("geometry.depth", 0.1), ["geometry.depth", "unknown key"]),
    ("box-walls-too-thick", _set("geometry.wall_thickness", 0.2), ["geometry.wall_thickness"]),
    ("box-bolt-patch-off-flange", _set("geometry.bolt_patch_size", 0.1), ["geometry.bolt_patch_size"]),
    ("geometry-unknown-kind", _set("geometry.kind", "sphere"), ["geometry"]),
    ("geometry-missing", _del("geometry"), ["geometry"]),
    ("plate-missing", lambda d: d.update(geometry={"kind": "plate", "a": 0.3, "b": 0.2}), ["geometry.h"]),
    ("plate-bad-edge", lambda d: d.update(geometry={"kind": "plate", "a": 0.3, "b": 0.2, "h": 0.005,
                                                    "edges": {"x0": "glued"}}), ["geometry.edges.x0"]),
    ("plate-zero-thickness", lambda d: d.update(geometry={"kind": "plate", "a": 0.3, "b": 0.2, "h": 0.0}),
     ["geometry.h"]),
    ("halves-bad-joint", _all(_set("geometry.kind", "box-halves"), _set("geometry.joint", "bolted")),
     ["geometry.joint"]),
    ("halves-joint-too-thick", _all(_set("geometry.kind", "box-halves"), _set("geometry.joint", "layer"),
                                    _set("geometry.joint_thickness", 0.02)), ["geometry.joint_thickness"]),
    ("gearbox-missing", lambda d: d.update(geometry={k: v for k, v in GEARBOX.items() if k != "bearing_plate"}),
     ["geometry.bearing_plate"]),
    ("gearbox-split-outside", lambda d: d.update(geometry=dict(GEARBOX, split_height=0.5)),
     ["geometry.split_height"]),
    ("gearbox-bore-bad-name", lambda d: d.update(geometry=dict(GEARBOX, bores=[
        {"name": "a b", "x": 0.0, "diameter": 0.05}])), ["geometry.bores.0.name"]),
    # [material]
    ("material-wrong-type", _set("material.youngs_modulus", "stiff"), ["material.youngs_modulus"]),
    ("material-poisson-out-of-range", _set("material.poisson_ratio", 0.5), ["material.poisson_ratio"]),
    ("material-negative-density", _set("material.density", -7850.0), ["material.density"]),
    ("material-unknown", _set("material.E", 2.1e11), ["material.E", "unknown key"]),
    ("material-not-in-library", _set("material.name", "unobtainium"), ["material.name"]),
    ("material-loss-factor-1", _set("material.loss_factor", 1.5), ["material.loss_factor"]),
    # [regions]
    ("regions-wrong-type", _set("regions", {"joint": 3}), ["regions.joint"]),
    ("regions-out-of-range", _set("regions", {"joint": {"name": "steel", "poisson_ratio": 0.7}}),
     ["regions.joint.poisson_ratio"]),
    ("regions-unknown", _set("regions", {"joint": {"name": "steel", "stiffness": 1.0}}),
     ["regions.joint.stiffness", "unknown key"]),
    ("regions-missing-values", _set("regions", {"joint": {"name": "gasket"}}), ["regions.joint.name"]),
    # [[supports]]
    ("supports-wrong-type", _set("supports.0.surface", 7), ["supports.0.surface"]),
    ("supports-bad-kind", _set("supports.0.kind", "glued"), ["supports.0.kind"]),
    ("supports-missing", _del("supports.0.kind"), ["supports.0.kind"]),
    ("supports-unknown", _set("supports.0.stiffness", 1e9), ["supports.0.stiffness", "unknown key"]),
    ("supports-elastic-no-stiffness", _set("supports.0.kind", "elastic"), ["supports.0.normal_stiffness"]),
    ("supports-negative-stiffness", _all(_set("supports.0.kind", "elastic"),
                                         _set("supports.0.normal_stiffness", -1e12)),
     ["supports.0.normal_stiffness"]),
    ("supports-not-a-list", _set("supports", {"surface": "bolt_1", "kind": "fixed"}), ["supports"]),
    # [mesh]
    ("mesh-wrong-type", _set("mesh.size", "fine"), ["mesh.size"]),
    ("mesh-bad-degree", _set("mesh.degree", 5), ["mesh.degree"]),
    ("mesh-bad-element", _set("mesh.element", "prism"), ["mesh.element"]),
    ("mesh-zero-layers", _set("mesh.layers", 0), ["mesh.layers"]),
    ("mesh-negative-layer-size", _set("mesh.layer_size", -0.004), ["mesh.layer_size"]),
    ("mesh-unknown", _set("mesh.order", 2), ["mesh.order", "unknown key"]),
    ("mesh-negative-size", _set("mesh.size", -0.01), ["mesh.size"]),
    ("mesh-grading-above-one", _set("mesh.grading", 1.5), ["mesh.grading"]),
    ("mesh-grading-zero", _set("mesh.grading", 0.0), ["mesh.grading"]),
    # [analysis]
    ("analysis-none", _set("analysis", {}), ["analysis"]),
    ("analysis-missing", _del("analysis"), ["analysis"]),
    ("analysis-unknown", _set("analysis.static", {"f_max": 1.0}), ["analysis.static", "unknown key"]),
    ("modal-wrong-type", _set("analysis.modal.f_max", "high"), ["analysis.modal.f_max"]),
    ("modal-negative", _set("analysis.modal.f_max", -100.0), ["analysis.modal.f_max"]),
    ("modal-missing", _set("analysis.modal", {"tolerance": 1e-10}), ["analysis.modal.f_max"]),
    ("modal-unknown", _set("analysis.modal.n_modes", 20), ["analysis.modal.n_modes", "unknown key"]),
    ("harmonic-wrong-type", _set("analysis.harmonic.df", [1.0]), ["analysis.harmonic.df"]),
    ("harmonic-negative", _set("analysis.harmonic.f_min", -5.0), ["analysis.harmonic.f_min"]),
    ("harmonic-missing", _del("analysis.harmonic.f_max"), ["analysis.harmonic.f_max"]),
    ("harmonic-unknown", _set("analysis.harmonic.lines", 10), ["analysis.harmonic.lines", "unknown key"]),
    ("harmonic-bad-solver", _set("analysis.harmonic.solver", "fast"), ["analysis.harmonic.solver"]),
    ("harmonic-fmin-above-fmax", _set("analysis.harmonic.f_min", 500.0), ["analysis.harmonic.f_min"]),
    ("harmonic-basis-factor", _set("analysis.harmonic.modal_basis_factor", 10.0),
     ["analysis.harmonic.modal_basis_factor"]),
    ("harmonic-node-without-coupling", _set("analysis.harmonic.angular_velocity_node", "wheel:8"),
     ["analysis.harmonic.angular_velocity_node"]),
    # [[loads]]
    ("loads-wrong-type", _set("loads.0.amplitude", "loud"), ["loads.0.amplitude"]),
    ("loads-bad-kind", _set("loads.0.kind", "torque"), ["loads.0.kind"]),
    ("loads-missing-name", _del("loads.0.name"), ["loads.0.name"]),
    ("loads-missing-point", _del("loads.0.point"), ["loads.0.point"]),
    ("loads-unknown", _set("loads.0.phase", 0.0), ["loads.0.phase", "unknown key"]),
    ("loads-point-two-coordinates", _set("loads.0.point", [0.06, 0.04]), ["loads.0.point"]),
    ("loads-zero-direction", _set("loads.0.direction", [0.0, 0.0, 0.0]), ["loads.0.direction"]),
    ("loads-negative-radius", _set("loads.0.radius", -0.005), ["loads.0.radius"]),
    ("loads-surface-and-node", _set("loads.0.node", "wheel:8"), ["loads.0.surface"]),
    ("loads-node-without-coupling", _all(_del("loads.0.surface"), _del("loads.0.point"),
                                         _set("loads.0.node", "wheel:8")), ["loads", "coupling"]),
    ("loads-duplicate-names", lambda d: d["loads"].append(copy.deepcopy(d["loads"][0])), ["loads"]),
    ("loads-none-for-harmonic", _set("loads", []), ["loads"]),
    ("loads-spectrum-lengths", _set("loads.0.spectrum", {"frequencies": [10.0, 100.0], "values": [1.0]}),
     ["loads.0.spectrum.values"]),
    ("loads-spectrum-decreasing", _set("loads.0.spectrum", {"frequencies": [100.0, 10.0], "values": [1.0, 2.0]}),
     ["loads.0.spectrum.frequencies"]),
    # [damping]
    ("damping-wrong-type", _set("damping.loss_factor", "some"), ["damping.loss_factor"]),
    ("damping-out-of-range", _set("damping", {"modal_damping_ratio": 0.7}), ["damping.modal_damping_ratio"]),
    ("damping-negative", _set("damping.loss_factor", -0.01), ["damping.loss_factor"]),
    ("damping-unknown", _set("damping.rayleigh", [1.0, 2.0]), ["damping.rayleigh", "unknown key"]),
    ("damping-two-models", _set("damping.modal_damping_ratio", 0.01), ["damping.loss_factor"]),
    ("damping-bands-missing-values", _set("damping", {"loss_factor_bands": {"frequencies": [100.0]}}),
     ["damping.loss_factor_bands.values"]),
    # [radiation]
    ("radiation-wrong-type", _set("radiation.plates", "all"), ["radiation.plates"]),
    ("radiation-bad-model", _set("radiation.model", "bem"), ["radiation.model"]),
    ("radiation-missing", _set("radiation", {"plates": []}), ["radiation.model"]),
    ("radiation-unknown", _set("radiation.c", 340.0), ["radiation.c", "unknown key"]),
    ("radiation-foller-no-plates", _set("radiation.model", "foller"), ["radiation.plates"]),
    ("radiation-negative-thickness", _set("radiation", {"model": "foller", "plates": [
        {"surface": "outer_top", "thickness": -0.008}]}), ["radiation.plates.0.thickness"]),
    ("radiation-without-harmonic", _del("analysis.harmonic"), ["radiation"]),
    # [output]
    ("output-wrong-type", _set("output.paraview", "maybe"), ["output.paraview"]),
    ("output-out-of-range", _set("output.mode_pictures", 50), ["output.mode_pictures"]),
    ("output-unknown", _set("output.format", "vtk"), ["output.format", "unknown key"]),
    # [reference]
    ("reference-wrong-type", _set("reference.frequencies_hz", "641"), ["reference.frequencies_hz"]),
    ("reference-negative", _set("reference.frequencies_hz", [-641.0]), ["reference.frequencies_hz.0"]),
    ("reference-unknown", _set("reference.doi", "x"), ["reference.doi", "unknown key"]),
    # [coupling]
    ("coupling-unknown", _all(_set("geometry", GEARBOX), _set("coupling", dict(COUPLING, springs=[]))),
     ["coupling.springs", "unknown key"]),
    ("coupling-wrong-type", _all(_set("geometry", GEARBOX), _set("coupling", dict(
        COUPLING, tie_rods=[{"a": "b1", "b": "s:0", "diameter": "thick"}]))),
     ["coupling.tie_rods.0.diameter"]),
    ("coupling-out-of-range", _all(_set("geometry", GEARBOX), _set("coupling", dict(
        COUPLING, tie_rods=[{"a": "b1", "b": "s:0", "diameter": -0.01}]))),
     ["coupling.tie_rods.0.diameter"]),
    ("coupling-missing", _all(_set("geometry", GEARBOX), _set("coupling", dict(
        COUPLING, bores=[{"name": "b1"}]))), ["coupling.bores.0.surface"]),
    ("coupling-bad-bore-kind", _all(_set("geometry", GEARBOX), _set("coupling", dict(
        COUPLING, bores=[{"name": "b1", "surface": "outer_top", "kind": "glue"}]))), ["coupling.bores.0.kind"]),
    # unknown top-level section
    ("top-level-unknown", _set("solver", {"kind": "mumps"}), ["solver", "unknown key"]),
]

# Cases that need the mesh (the check is in housingfe.fe.loads); the box mesh at 40 mm linear hexes takes seconds.
MESH_CASES = [
    ("force-5m-off-surface", _set("loads.0.point", [0.06, 0.04, 5.125]), ["loads.top.point"]),
    ("moment-off-surface", _all(_set("loads.0.kind", "moment"), _set("loads.0.point", [0.06, 0.04, 0.2])),
     ["loads.top.point"]),
    ("force-on-unknown-surface", _set("loads.0.surface", "outer_roof"), ["loads.top.surface"]),
    # sample_points are counts (item 3: [1] is valid and now runs); more points than the surface has facets is not
    ("sample-points-too-many", _set("analysis.harmonic.sample_points", [100000]), ["analysis.harmonic.sample_points"]),
]


def _expect_one_line_error(code: int, err: str, needles, tmp_path: Path, out: Path):
    lines = [line for line in err.strip().splitlines() if line.strip()]
    assert code == 2, (code, err)
    assert "Traceback" not in err, err
    assert len(lines) == 1, lines
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
    assert not out.exists(), "a result folder was written"
    assert not list(out.parent.glob(out.name + ".tmp*")), "a temporary result folder was left"


def _run_cli(argv, capsys):
    try:
        code = cli.main(argv)
    except SystemExit as exc:     # argparse usage errors
        code = exc.code
    captured = capsys.readouterr()
    return code, captured.err


def _scene_case(change, tmp_path) -> tuple[Path, Path]:
    data = copy.deepcopy(BASE)
    change(data)
    path = tmp_path / "scene.toml"
    path.write_text(to_toml(data))
    return path, tmp_path / "out"


@pytest.mark.parametrize("change, needles", [c[1:] for c in SCENE_CASES], ids=[c[0] for c in SCENE_CASES])
def test_bad_scene_is_rejected_before_meshing(change, needles, tmp_path, capsys, monkeypatch):
    # any attempt to build the model means the scene check let the case through: fail fast instead of meshing
    import housingfe.fe.model

    def no_meshing(*args, **kwargs):
        raise AssertionError("the scene check accepted a bad scene (build_model was called)")

    monkeypatch.setattr(housingfe.fe.model, "build_model", no_meshing)
    path, out = _scene_case(change, tmp_path)
    code, err = _run_cli(["run", str(path), "--out", str(out)], capsys)
    _expect_one_line_error(code, err, needles, tmp_path, out)


def _mesh_params():
    return [pytest.param(change, needles, id=case_id) for case_id, change, needles in MESH_CASES]


@pytest.mark.timeout(300)
@pytest.mark.parametrize("change, needles", _mesh_params())
def test_bad_scene_found_on_the_mesh(change, needles, tmp_path, capsys):
    path, out = _scene_case(change, tmp_path)
    code, err = _run_cli(["run", str(path), "--out", str(out)], capsys)
    _expect_one_line_error(code, err, needles, tmp_path, out)


def test_five_metre_flange_is_stopped_before_meshing(tmp_path, capsys, monkeypatch):
    # issue 12's typo (0.05 -> 5.0): it must stop before gmsh; meshing it here would take gigabytes, so any
    # call of the mesher counts as the failure
    import housingfe.fe.model

    def no_meshing(*args, **kwargs):
        raise AssertionError("a 5 m flange reached the mesher")

    monkeypatch.setattr(housingfe.fe.model, "build_mesh", no_meshing)
    path, out = _scene_case(_set("geometry.flange_width", 5.0), tmp_path)
    code, err = _run_cli(["run", str(path), "--out", str(out)], capsys)
    _expect_one_line_error(code, err, ["geometry.flange_width"], tmp_path, out)


# issue 27: a mesh far too coarse for f_max (about one element per bending wavelength of the walls, or a plate
# asked for everything below 1 MHz) stops before gmsh, naming the size key (housingfe.fe.resolution)
COARSE_CASES = [
    ("coarse-6mm-walls-2kHz", _all(_set("geometry.wall_thickness", 0.006), _set("mesh.size", 0.15),
                                   _set("mesh.degree", 2), _set("analysis.modal.f_max", 2000.0)),
     ["mesh.size", "mesh.allow_coarse"]),
    ("plate-1MHz", _all(_set("geometry", {"kind": "plate", "a": 0.3, "b": 0.2, "h": 0.005}), _set("supports", []),
                        _set("mesh.size", 0.05), _set("analysis.modal.f_max", 1e6), _del("analysis.harmonic"),
                        _del("loads"), _del("radiation")), ["mesh.size", "far too coarse"]),
]


@pytest.mark.parametrize("change, needles", [c[1:] for c in COARSE_CASES], ids=[c[0] for c in COARSE_CASES])
def test_mesh_far_too_coarse_for_f_max_is_stopped_before_meshing(change, needles, tmp_path, capsys, monkeypatch):
    import housingfe.fe.model

    def no_meshing(*args, **kwargs):
        raise AssertionError("a mesh far too coarse for f_max reached the mesher")

    monkeypatch.setattr(housingfe.fe.model, "build_mesh", no_meshing)
    path, out = _scene_case(change, tmp_path)
    code, err = _run_cli(["run", str(path), "--out", str(out)], capsys)
    _expect_one_line_error(code, err, needles, tmp_path, out)


# ---------------------------------------------------------------- --set
SET_CASES = [
    ("set-no-equals", "mesh.size", ["--set", "mesh.size"]),
    ("set-unknown-key", "mesh.sise=0.01", ["mesh.sise", "unknown key"]),
    ("set-wrong-type", "mesh.size=abc", ["mesh.size"]),
    ("set-empty-value", "analysis.modal.f_max=", ["analysis.modal.f_max"]),
    ("set-into-non-table", "scene.name.x=1", ["--set", "scene.name.x"]),
    # issue 27: a dotted index from 0 reaches an entry of an array of tables; a bad one is named
    ("set-array-index-out-of-range", "loads.1.amplitude=2", ["--set", "loads.1.amplitude", "out of range"]),
    ("set-array-not-an-index", "loads.top.amplitude=2", ["--set", "loads.top.amplitude", "index"]),
    ("set-array-brackets", "loads[0].amplitude=2", ["--set", "loads[0].amplitude", "loads.0.amplitude"]),
    ("set-array-entry-bad-value", "loads.0.amplitude=loud", ["loads.0.amplitude"]),
    ("set-array-entry-unknown-key", "loads.0.phase=1", ["loads.0.phase", "unknown key"]),
    ("set-out-of-range", "material.poisson_ratio=0.7", ["material.poisson_ratio"]),
    ("set-empty-key", "=5", ["--set"]),
]


@pytest.mark.parametrize("item, needles", [c[1:] for c in SET_CASES], ids=[c[0] for c in SET_CASES])
def test_bad_set_is_rejected(item, needles, tmp_path, capsys, monkeypatch):
    import housingfe.fe.model

    monkeypatch.setattr(housingfe.fe.model, "build_model", lambda *a, **k: pytest.fail("scene accepted"))
    path, out = _scene_case(lambda d: None, tmp_path)
    code, err = _run_cli(["run", str(path), "--out", str(out), "--set", item], capsys)
    _expect_one_line_error(code, err, needles, tmp_path, out)


# ---------------------------------------------------------------- files
def _file_cases(tmp_path: Path) -> dict:
    """name -> (path argument, substring of the error line)."""
    cases = {}
    empty = tmp_path / "empty.toml"
    empty.write_text("")
    cases["empty-file"] = (empty, "scene")
    blank = tmp_path / "blank.toml"
    blank.write_text("\n# only a comment\n\n")
    cases["comment-only-file"] = (blank, "scene")
    garbage = tmp_path / "garbage.toml"
    garbage.write_bytes(bytes(range(256)) * 4)
    cases["binary-garbage"] = (garbage, "garbage.toml")
    latin1 = tmp_path / "latin1.toml"
    latin1.write_bytes('[scene]\nname = "b\xf6x"\n'.encode("latin-1"))
    cases["not-utf8"] = (latin1, "latin1.toml")
    malformed = tmp_path / "malformed.toml"
    malformed.write_text("[scene\nname = 'x'\n")
    cases["malformed-toml"] = (malformed, "malformed TOML")
    duplicate = tmp_path / "duplicate.toml"
    duplicate.write_text(to_toml(BASE) + 'scene = {name = "again"}\n')
    cases["duplicate-key"] = (duplicate, "malformed TOML")
    folder = tmp_path / "folder.toml"
    folder.mkdir()
    cases["directory-named-toml"] = (folder, "folder.toml")
    plain_dir = tmp_path / "plain_dir"
    plain_dir.mkdir()
    cases["directory"] = (plain_dir, "plain_dir")
    dangling = tmp_path / "dangling.toml"
    dangling.symlink_to(tmp_path / "nowhere.toml")
    cases["dangling-symlink"] = (dangling, "dangling.toml")
    loop = tmp_path / "loop.toml"
    loop.symlink_to(loop)
    cases["symlink-loop"] = (loop, "loop.toml")
    cases["missing-file"] = (tmp_path / "missing.toml", "missing.toml")
    cases["unknown-scene-name"] = ("box-freee", "box-freee")
    utf16 = tmp_path / "utf16.toml"
    utf16.write_bytes(to_toml(BASE).encode("utf-16"))      # issue 27: a byte-order mark named as such
    cases["utf16-with-bom"] = (utf16, "UTF-16 byte-order mark")
    top_array = tmp_path / "array.toml"
    top_array.write_text("scene = [1, 2]\n")
    cases["scene-not-a-table"] = (top_array, "scene")
    return cases


FILE_CASE_NAMES = ["empty-file", "comment-only-file", "binary-garbage", "not-utf8", "malformed-toml",
                   "duplicate-key", "directory-named-toml", "directory", "dangling-symlink", "symlink-loop",
                   "missing-file", "unknown-scene-name", "scene-not-a-table", "utf16-with-bom"]


@pytest.mark.parametrize("command", ["run", "source"])
@pytest.mark.parametrize("name", FILE_CASE_NAMES)
def test_unreadable_or_empty_file_is_rejected(name, command, tmp_path, capsys):
    path, needle = _file_cases(tmp_path)[name]
    out = tmp_path / "out"
    code, err = _run_cli([command, str(path), "--out", str(out)], capsys)
    _expect_one_line_error(code, err, [needle], tmp_path, out)


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads a file whatever its permissions")
def test_unreadable_file_is_rejected(tmp_path, capsys):
    path = tmp_path / "secret.toml"
    path.write_text(to_toml(BASE))
    path.chmod(0)
    out = tmp_path / "out"
    code, err = _run_cli(["run", str(path), "--out", str(out)], capsys)
    _expect_one_line_error(code, err, ["secret.toml", "cannot read"], tmp_path, out)


# ---------------------------------------------------------------- source scenes
def _source_base() -> dict:
    return tomllib.loads((SCENE_DIR / "gearset-A.toml").read_text())


SOURCE_CASES = [
    ("source-wrong-type", _set("source.torque_Nm", "much"), ["source.torque_Nm"]),
    ("source-negative", _set("source.speed_min_rpm", -50.0), ["source.speed_min_rpm"]),
    ("source-unknown", _set("source.colour", "red"), ["source.colour"]),
    ("source-missing-gears", _del("source.gears"), ["source.gears"]),
    ("source-bad-model", _set("source.model", "wizard"), ["source.model"]),
    ("source-gears-wrong-type", _set("source.gears.teeth", "many"), ["source.gears.teeth"]),
    ("source-gears-unknown", _set("source.gears.colour", "red"), ["source.gears.colour"]),
    ("source-housing-kind", _set("scene.kind", "housing"), ["scene.kind"]),
    ("source-missing-section", _del("source"), ["source"]),
    # torques beyond the teeth's strength and speeds at which the wheel bursts (GearPair.torque_problem /
    # speed_problem, docs/source.md): 1e12 N m was "solver error: load distribution did not converge" (exit 3),
    # 1e9 rev/min ran to a result
    ("source-torque-beyond-strength", _set("source.torque_Nm", 1e12),
     ["source.torque_Nm", "875 N/mm^2 at which the teeth of any steel gear break", "at most 1.065e+04 N m"]),
    ("source-torque-run-beyond-strength", _set("source.torque_run_Nm", [400.0, 20000.0]),
     ["source.torque_run_Nm.1", "875 N/mm^2"]),
    ("source-torque-nan", _set("source.torque_Nm", float("nan")), ["source.torque_Nm", "finite"]),
    ("source-speed-zero", _set("source.speed_min_rpm", 0.0), ["source.speed_min_rpm"]),
    ("source-speed-bursts", _set("source.speed_max_rpm", 1e9), ["source.speed_max_rpm", "1000 m/s", "bursts"]),
    ("source-spectrum-speed-bursts", _set("source.spectrum_speeds_rpm", [500.0, 1e9]),
     ["source.spectrum_speeds_rpm.1", "1000 m/s"]),
    # no torque run: an IndexError traceback after the run (torque_run.png); a torque twice: run and written twice
    ("source-torque-run-empty", _set("source.torque_run_Nm", []), ["source.torque_run_Nm", "at least 1 item"]),
    ("source-torque-run-twice", _set("source.torque_run_Nm", [2000.0, 2000.0]),
     ["source.torque_run_Nm: 2000 N m is given twice"]),
]


@pytest.mark.parametrize("change, needles", [c[1:] for c in SOURCE_CASES], ids=[c[0] for c in SOURCE_CASES])
def test_bad_source_scene_is_rejected(change, needles, tmp_path, capsys):
    _expect_source_scene_refused(_source_base(), change, needles, tmp_path, capsys)


def _expect_source_scene_refused(data, change, needles, tmp_path, capsys):
    """`housingfe source` on the scene `data` with `change` applied: one line naming `needles`, exit 2, no folder."""
    change(data)
    path = tmp_path / "source.toml"
    path.write_text(to_toml(data))
    out = tmp_path / "out"
    code, err = _run_cli(["source", str(path), "--out", str(out)], capsys)
    _expect_one_line_error(code, err, needles, tmp_path, out)


# the Fukuma and Trueman source models: the same limits on their gears (Fukuma's torque is only recorded: 0 is valid)
OTHER_SOURCE_CASES = [
    ("fukuma-torque-beyond-strength", "fukuma-series-a", _set("loads.torque_Nm", 1e12),
     ["loads.torque_Nm", "875 N/mm^2"]),
    ("fukuma-speed-bursts", "fukuma-series-a", _set("sweep.speeds_rpm", [700.0, 1e9]),
     ["sweep.speeds_rpm.1", "1000 m/s"]),
    ("trueman-torque-beyond-strength", "trueman-type-a", _set("forced.mean_mesh_torque_Nm", 1e12),
     ["forced.mean_mesh_torque_Nm", "875 N/mm^2"]),
    ("trueman-speed-bursts", "trueman-type-a", _set("forced.speed_max_rpm", 1e9), ["forced.speed_max_rpm", "1000 m/s"]),
]


@pytest.mark.parametrize("scene, change, needles", [c[1:] for c in OTHER_SOURCE_CASES],
                         ids=[c[0] for c in OTHER_SOURCE_CASES])
def test_impossible_operating_point_of_other_source_models_is_rejected(scene, change, needles, tmp_path, capsys):
    _expect_source_scene_refused(tomllib.loads((SCENE_DIR / f"{scene}.toml").read_text()), change, needles, tmp_path,
                                 capsys)


# ---------------------------------------------------------------- housingfe bearing
COMMAND_CASES = [
    ("bearing-unknown-designation", ["bearing", "SKF 99999", "--load", "1000", "0", "0", "0", "0"], ["99999"]),
    ("bearing-load-not-a-number", ["bearing", "SKF 6312", "--load", "1e4", "x", "0", "0", "0"], ["--load"]),
    ("bearing-load-too-few", ["bearing", "SKF 6312", "--load", "1e4", "0"], ["--load"]),
    ("bearing-unknown-model", ["bearing", "SKF 6312", "--load", "1e4", "0", "0", "0", "0", "--model", "magic"],
     ["model"]),
    ("bearing-unknown-option", ["bearing", "SKF 6312", "--load", "1e4", "0", "0", "0", "0", "--speed", "3"],
     ["--speed"]),
    ("bearing-nan-load", ["bearing", "SKF 6312", "--load", "nan", "0", "0", "0", "0"], ["load"]),
    # issue 27: bearing geometry in millimetres (a 25 m ball) or in GPa is refused, naming the flag and the unit
    ("bearing-ball-diameter-mm", ["bearing", "--balls", "9", "--ball-diameter", "25", "--pitch-diameter", "0.125",
                                  "--load", "1e4", "0", "0", "0", "0"], ["--ball-diameter", "millimetres"]),
    ("bearing-pitch-diameter-mm", ["bearing", "--balls", "9", "--ball-diameter", "0.025", "--pitch-diameter",
                                   "125", "--load", "1e4", "0", "0", "0", "0"], ["--pitch-diameter", "millimetres"]),
    ("bearing-modulus-gpa", ["bearing", "SKF 6312", "--youngs-modulus", "208", "--load", "1e4", "0", "0", "0", "0"],
     ["--youngs-modulus", "GPa"]),
    ("bench-unknown", ["bench", "modall"], ["modall"]),
    ("bench-only-not-all", ["bench", "modal", "--only", "mpi"], ["--only"]),
    ("bench-notes-not-all", ["bench", "modal", "--notes"], ["--notes"]),
    ("bench-notes-with-only", ["bench", "all", "--notes", "--only", "modal"], ["--notes"]),
    ("bench-resume-not-kept", ["bench", "frf", "--resume"], ["--resume", "frf does not keep its runs"]),
    ("bench-resume-with-notes", ["bench", "all", "--notes", "--resume"], ["--resume", "--notes"]),
    ("bench-size-not-taken", ["bench", "frf", "--size", "10"], ["--size", "frf does not take it", "imported"]),
    ("bench-size-negative", ["bench", "imported", "--size", "-5"], ["--size", "-5 must be a finite positive"]),
    ("bench-cases-unknown", ["bench", "imported", "--cases", "housingfe1,housingfe3"],
     ["--cases", "unknown case housingfe3", "housingfe2"]),
    ("bench-cases-calculix-alone", ["bench", "imported", "--cases", "calculix"], ["--cases", "needs housingfe1"]),
]


@pytest.mark.parametrize("argv, needles", [c[1:] for c in COMMAND_CASES], ids=[c[0] for c in COMMAND_CASES])
def test_bad_bearing_or_bench_command_is_rejected(argv, needles, tmp_path, capsys):
    code, err = _run_cli(argv, capsys)
    assert code == 2, (code, err)
    assert "Traceback" not in err, err
    errors = err.strip().splitlines()      # one line, argparse's own errors included (cli._OneLineParser)
    assert len(errors) == 1 and "error" in errors[0], err
    for needle in needles:
        assert needle in errors[0], (needle, errors[0])


# ---------------------------------------------------------------- generated wrong types (hypothesis)
# Scalar keys of the base scene that take a number; a value of the wrong kind must name the key, whatever it is.
NUMERIC_KEYS = ["geometry.length", "geometry.wall_thickness", "material.youngs_modulus", "mesh.size",
                "analysis.modal.f_max", "analysis.harmonic.f_max", "analysis.harmonic.df", "loads.0.radius",
                "loads.0.amplitude", "damping.loss_factor", "output.mode_pictures"]

_not_a_number = st.one_of(
    st.text(alphabet="abcxyz _-", min_size=1, max_size=8),
    st.lists(st.floats(allow_nan=False, allow_infinity=False), min_size=1, max_size=3),
    st.dictionaries(st.sampled_from(["a", "b"]), st.integers(), min_size=1, max_size=2),
)


def _assert_rejected_naming(key: str, value, tmp_path: Path) -> None:
    """The base scene with `key` set to `value` is rejected by the scene check with one line naming the key."""
    from housingfe.errors import InputError
    from housingfe.scene import load_housing_scene

    data = copy.deepcopy(BASE)
    _set(key, value)(data)
    path = tmp_path / "generated.toml"
    path.write_text(to_toml(data))
    with pytest.raises(InputError) as info:
        load_housing_scene(str(path))
    line = str(info.value)
    assert "\n" not in line and key in line, (key, value, line)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(key=st.sampled_from(NUMERIC_KEYS), value=_not_a_number)
def test_generated_wrong_types_name_the_key(key, value, tmp_path, capsys):
    _assert_rejected_naming(key, value, tmp_path)


_out_of_range = st.one_of(st.floats(max_value=0.0, allow_nan=False, allow_infinity=False),
                          st.just(float("inf")), st.just(float("nan")))


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(key=st.sampled_from(["geometry.length", "geometry.flange_thickness", "material.density", "mesh.size",
                            "analysis.modal.f_max", "analysis.harmonic.df", "loads.0.radius"]),
       value=_out_of_range)
def test_generated_non_positive_lengths_and_frequencies_name_the_key(key, value, tmp_path):
    _assert_rejected_naming(key, value, tmp_path)


# ---------------------------------------------------------------- end to end (console script)
HOUSINGFE = Path(sys.executable).with_name("housingfe")


@pytest.mark.parametrize("args", [
    ["run", "{bad}"],
    ["run", "box-free", "--set", "mesh.degree=7"],
    ["run", "{bad}", "--set", "mesh.size"],
    ["source", "{empty}"],
    ["bearing", "SKF 99999", "--load", "1000", "0", "0", "0", "0"],
], ids=["run-bad-scene", "run-builtin-bad-set", "run-set-without-equals", "source-empty", "bearing-unknown"])
def test_console_script_end_to_end(args, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(to_toml(dict(BASE, mesh={"element": "hex", "degree": "two"})))
    empty = tmp_path / "empty.toml"
    empty.write_text("")
    argv = [a.format(bad=bad, empty=empty) for a in args]
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    proc = subprocess.run([str(HOUSINGFE), *argv], cwd=tmp_path, capture_output=True, text=True, timeout=120,
                          env=env, check=False)
    lines = [line for line in proc.stderr.strip().splitlines() if line.strip()]
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr
    assert len(lines) == 1, lines
    assert not (tmp_path / "results").exists()




# ---------------------------------------------------------------- the CLI sweep: every sub-command as a user hits it
# Each case is the console script in a fresh folder holding a few files of the user's (SWEEP_FILES); it must stop
# with exit 2, one line naming what is wrong, no traceback, and leave the folder exactly as it was (no result, no
# partial output, nothing of the user's changed).  Cases found by the sweep over the 20 sub-commands; each was a
# traceback, a silent acceptance or work started before the refusal.
UPDATE_SPEC = SPEC    # a valid update spec (tests/correlation/test_cli.py); each defect below is one edit of it
SWEEP_FILES = {"afile": "precious", "userdir/keep.txt": "precious", "binary.toml": bytes(range(128, 256)) * 4,
               "typo-bands.json": '{"28.defualt.max_lwa.mesh_force": [80.0, 90.0]}',
               # update specs, each with one defect (UPDATE_SPEC alone is valid: tests/correlation/test_cli.py)
               "multistart-name.toml": UPDATE_SPEC.replace("[[parameters]]", "multistart = [{hh = 0.15}]\n[[parameters]]"),
               "multistart-bounds.toml": UPDATE_SPEC.replace("[[parameters]]", "multistart = [{h = 5.0}]\n[[parameters]]"),
               "override-scene-typo.toml": UPDATE_SPEC + '[search_overrides]\n"box-fre" = ["mesh.size=0.06"]\n',
               "override-key-typo.toml": UPDATE_SPEC + '[search_overrides]\n"box-free" = ["mesh.sise=0.06"]\n',
               "plates-row.toml": 'plates = [["side", 1, "big", 1.3, 0.005, 2000.0]]\n',
               "duplicate-target.toml": UPDATE_SPEC + '[[targets]]\nname = "m"\nscene = "box-free"\nkind = "mass"\n'
                                                      'value = 20.0\n',
               # transmission errors (runup.transmission_error): harmonics the source cannot take
               "te-harmonic-40.csv": "torque_Nm,harmonic,amplitude_um\n2000,40,0.5\n",
               "te-harmonic-huge.csv": "torque_Nm,harmonic,amplitude_um\n2000,1e300,0.5\n"}


def _sweep_folder(tmp_path: Path) -> Path:
    for name, content in SWEEP_FILES.items():
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(content if isinstance(content, bytes) else content.encode())
    return tmp_path


def _snapshot(folder: Path) -> dict:
    return {p.relative_to(folder).as_posix(): (p.read_bytes() if p.is_file() else None)
            for p in sorted(folder.rglob("*"))}


def _sweep(argv: list[str], needles: list[str], tmp_path: Path) -> None:
    folder = _sweep_folder(tmp_path)
    before = _snapshot(folder)
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1",
               PYTHONPATH=os.pathsep.join([str(Path(cli.__file__).parent.parent), os.environ.get("PYTHONPATH", "")]))
    proc = subprocess.run([str(HOUSINGFE), *argv], cwd=folder, capture_output=True, text=True, timeout=120,
                          env=env, check=False)
    lines = [line for line in proc.stderr.splitlines() if line.strip()]
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr, proc.stderr
    assert len(lines) == 1 and "error: " in lines[0], lines
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
    assert _snapshot(folder) == before, "the refused command left or changed files"


SWEEP_CASES = [
    # `--only ""` / `--cases ","` named nothing and started the whole suite (every benchmark / case: hours)
    ("bench-only-empty", ["bench", "all", "--only", ","], ["--only", "names nothing"]),
    ("bench-cases-empty", ["bench", "imported", "--cases", ""], ["--cases", "names nothing"]),
    # inf passed `--size > 0`, wrote results/bench-imported.inputs/ and was refused by the scene made from it
    ("bench-size-infinite", ["bench", "imported", "--size", "inf"], ["--size", "inf must be a finite positive"]),
    # correlate: a non-positive --f-max was a ValueError traceback after meshing, --loss-factor was not checked,
    # an --export into a folder (or a missing one) a traceback after the solve, with <name>.tmp left behind
    # --out with --export was ignored silently (the solve ran, only the .uff was written, the folder never)
    ("correlate-export-with-out", ["correlate", "box-free", "--export", "x.uff", "--out", "c"],
     ["--out: c: applies to --measured", "--export writes the one file x.uff"]),
    ("correlate-f-max-negative", ["correlate", "box-free", "--export", "x.uff", "--f-max", "-100"],
     ["--f-max", "-100 Hz must be a finite positive"]),
    ("correlate-loss-factor", ["correlate", "box-free", "--export", "x.uff", "--loss-factor", "1.5"],
     ["--loss-factor", "1.5 is not in [0, 1)"]),
    ("correlate-export-folder", ["correlate", "box-free", "--export", "userdir"], ["userdir", "--export", "folder"]),
    # validate: --json into a folder was a traceback after the computation (minutes to hours), --results naming a
    # file a NotADirectoryError traceback; a band under a misspelt check id was silently never shown
    ("validate-json-folder", ["validate", "--only", "runup-checks", "--json", "userdir", "--out", "v", "--results",
                              "r"], ["userdir", "--json", "is a folder"]),
    ("validate-results-file", ["validate", "--only", "runup-checks", "--results", "afile", "--out", "v"],
     ["afile", "--results", "is a file"]),
    ("validate-bands-typo", ["validate", "--only", "runup-checks", "--bands", "typo-bands.json", "--out", "v",
                             "--results", "r"], ["typo-bands.json", "28.defualt.max_lwa.mesh_force", "not a check id"]),
    # update: a multistart naming no parameter was refused after the first solves, one outside the bounds not at
    # all (least_squares then fails at that start), overrides of a misspelt scene were never applied, a bad search
    # override was refused only after the confirmation mesh was solved, two targets of one name were accepted
    ("update-multistart-name", ["update", "multistart-name.toml", "--out", "u"], ["multistart.0.hh", "not a parameter"]),
    ("update-multistart-bounds", ["update", "multistart-bounds.toml", "--out", "u"],
     ["multistart.0.h", "[lower, upper] = [0.1, 0.3]"]),
    ("update-override-scene-typo", ["update", "override-scene-typo.toml", "--out", "u"],
     ["search_overrides.box-fre", "no target uses this scene"]),
    ("update-override-key-typo", ["update", "override-key-typo.toml", "--out", "u"],
     ["search_overrides.box-free", "mesh.sise: unknown key"]),
    ("update-duplicate-target", ["update", "duplicate-target.toml", "--out", "u"], ["targets.1.name", "used twice"]),
    # radiation foller: a plate table that is not UTF-8, or a row with a word for a number, was a traceback
    ("foller-binary-table", ["radiation", "foller", "binary.toml"], ["binary.toml", "not a UTF-8 text file"]),
    ("foller-row-not-a-number", ["radiation", "foller", "plates-row.toml"],
     ["plates-row.toml: plates[0]: area_m2: must be a number"]),
    # mesh-picture / scene-reference: a file as --out was a FileExistsError traceback; mesh-picture made docs/img/
    # and meshed (and drew) the good scenes before refusing a bad one named after them
    ("mesh-picture-out-file", ["mesh-picture", "box-free", "--out", "afile"], ["afile", "is a file, not a folder"]),
    ("mesh-picture-bad-second-scene", ["mesh-picture", "box-free", "no-such-scene"], ["no-such-scene: no such scene"]),
    ("scene-reference-out-file", ["scene-reference", "--out", "afile/sub", "--no-pictures"],
     ["afile/sub", "afile is a file, not a folder"]),
    # bearing-variants --torque -5 said "stiffness: total force must be > 0 N, got -110.9"; reduce --cutoff inf
    # passed the check, built the model and did not finish
    ("bearing-variants-torque", ["bearing-variants", "--torque", "-5", "--out", "bv"],
     ["--torque", "-5 must be a pinion torque > 0 N m"]),
    # a misspelt scene name was refused only when validate reached it: after the scenes before it (box-free: an FE
    # run) and a progress line
    ("validate-unknown-scene", ["validate", "box-free", "no-such-scene", "--out", "v"],
     ["no-such-scene: no such scene"]),
    # a misspelt --configs name was refused only after the housing model was built (16 s, a progress line first)
    ("bearing-variants-config-unknown", ["bearing-variants", "--configs", "ball", "bogus", "--out", "bv"],
     ["--configs: 'bogus': unknown (known: ball,", "ball_zero_moment"]),
    ("reduce-cutoff-infinite", ["reduce", "test-gearbox-interior", "--cutoff", "inf", "--out", "r"],
     ["--cutoff", "inf Hz must be a finite positive"]),
    # a cut-off far above what the mesh resolves meshed the housing, then the eigensolver failed (exit 3, PETSc's
    # error stack on stderr): now the resolution check of `run` is applied at the cut-off, before meshing
    ("reduce-cutoff-above-the-mesh", ["reduce", "test-gearbox-interior", "--cutoff", "1e6", "--out", "r"],
     ["--cutoff", "above what the scene's mesh resolves", "far too coarse", "mesh.allow_coarse"]),
    # uncertainty --range outside what the input can be: a clearance position of 5 Group N ranges ran to a result;
    # a 95 deg contact angle failed half a minute later in the bearing model, not naming --range
    ("uncertainty-range-unphysical", ["uncertainty", "--range", "clearance_position=5:6", "--out", "u"],
     ["--range clearance_position", "5: must be a position within the Group N clearance range"]),
    ("uncertainty-range-fails-late", ["uncertainty", "--range", "spherical_contact_angle_deg=95:100", "--out", "u"],
     ["--range spherical_contact_angle_deg", "95: must be a contact angle in [0, 90) deg"]),
    # the wheel's locating side drawn by uncertainty (front / back): another word is refused when read
    ("uncertainty-range-side", ["uncertainty", "--range", "wheel_locating_ball=middle", "--out", "u"],
     ["--range wheel_locating_ball: middle: not a bearing side (give front, back or front,back)"]),
    ("runup-wheel-locating", ["run", "test-gearbox-runup", "--set", "drivetrain.wheel_locating=configurations",
                              "--out", "r"],
     ["drivetrain.wheel_locating: 'configurations' is not a bearing side (known: configuration, front, back)"]),
    # the floating bearings' held axial load (drivetrain.floating_axial_ratio): beyond any ring-in-bore friction, on
    # floating bearings that carry no axial load, and a --range of uncertainty beyond the same limit
    ("runup-floating-axial-ratio", ["run", "test-gearbox-runup", "--set", "drivetrain.floating_axial_ratio=0.5",
                                    "--out", "r"],
     ["drivetrain.floating_axial_ratio: 0.5: must be within +-0.3"]),
    ("runup-floating-axial-fluid-film", ["run", "test-gearbox-runup", "--set", "drivetrain.floating_axial_ratio=0.1",
                                         "--set", "drivetrain.gear_set=double_helical", "--set",
                                         "drivetrain.bearings=fluid_film", "--out", "r"],
     ["drivetrain.floating_axial_ratio: 0.1: the floating bearing(s) pinion_back (fluid film)", "carry no axial load"]),
    ("uncertainty-range-floating-axial", ["uncertainty", "--range", "floating_axial_ratio=-0.5:0.2", "--out", "u"],
     ["--range floating_axial_ratio: -0.5: must be within +-0.3"]),
    # `--out ""` (a shell variable that was not set) wrote into the default folder, replacing the result there
    ("out-empty", ["run", "box-free", "--out", ""], ["--out", "empty path"]),
    # a housing or source scene given to a run-up command: its keys were named as unknown run-up keys
    ("runup-command-housing-scene", ["runup-causes", "test-gearbox"],
     ["test-gearbox.toml: scene.kind: 'housing'", "takes a run-up scene", "housingfe run"]),
    # the list of known configurations named "ball" twice
    ("misalignment-bearings", ["misalignment", "--bearings", "balll", "--out", "m"],
     ["bearings: 'balll' unknown (known: ball, angular_contact,"]),
    # source-spectrum --harmonics above the samples per mesh period: an IndexError traceback
    ("source-spectrum-harmonics", ["source-spectrum", "gearset-A", "--harmonics", "100000", "--out", "s"],
     ["gearset-A.toml: --harmonics: 100000", "at most 127 harmonics"]),
    # correlate --export --points above the outer surface's facets: refused after the modal solve, naming
    # analysis.harmonic.sample_points (a scene key the user never wrote); now after meshing, before the solve
    ("correlate-points-too-many", ["correlate", "box-free", "--export", "x.uff", "--points", "10000000"],
     ["--points: 10000000 points asked for", "facets"]),
    ("correlate-export-no-folder", ["correlate", "box-free", "--export", "nowhere/x.uff"],
     ["nowhere/x.uff", "--export", "nowhere is not an existing folder"]),
    # a torque beyond the teeth's strength (GearPair.torque_problem, docs/source.md): each command that takes one
    # ended in "housingfe: solver error: stiffness: load distribution did not converge at u = 0.000e+00 m" (exit 3;
    # bearing-variants after 3 s of work); the other impossible values (0, < 0, nan, inf) were already refused
    ("source-spectrum-torque-beyond-strength", ["source-spectrum", "gearset-A", "--torque", "1e12", "--out", "s"],
     ["gearset-A.toml: --torque: 1e+12 N m", "875 N/mm^2", "at most 1.065e+04 N m"]),
    ("source-spectrum-torque-nan", ["source-spectrum", "gearset-A", "--torque", "nan", "--out", "s"],
     ["--torque: nan must be a pinion torque > 0 N m"]),
    ("misalignment-torque-beyond-strength", ["misalignment", "--torques", "2000", "1e12", "--out", "m"],
     ["--torques: gear set A: 1e+12 N m", "875 N/mm^2"]),
    ("misalignment-torque-zero", ["misalignment", "--torques", "0", "--out", "m"], ["--torques: 0 must be"]),
    ("bearing-variants-torque-beyond-strength", ["bearing-variants", "--torque", "1e12", "--out", "bv"],
     ["--torque: gear set", "875 N/mm^2"]),
    ("bearing-variants-torque-inf", ["bearing-variants", "--torque", "inf", "--out", "bv"], ["--torque: inf"]),
    ("runup-torque-beyond-strength", ["run", "test-gearbox-runup", "--set", "runup.torques_nm=[1e12]", "--out", "r"],
     ["runup.torques_nm.0: 1e+12 N m", "875 N/mm^2"]),
    ("runup-torque-negative", ["run", "test-gearbox-runup", "--set", "runup.torques_nm=[-5.0]", "--out", "r"],
     ["runup.torques_nm.0"]),
    ("uncertainty-torque-beyond-strength", ["uncertainty", "--set", "runup.torques_nm=[2000.0, 1e12]", "--out", "u"],
     ["runup.torques_nm.1: 1e+12 N m", "875 N/mm^2"]),
    # run-up speeds: 0 and 1e9 rev/min were refused already; a spectrum speed outside the run-up was skipped silently
    ("runup-speed-zero", ["run", "test-gearbox-runup", "--set", "runup.speed_min_rpm=0", "--out", "r"],
     ["runup.speed_min_rpm"]),
    ("runup-speed-huge", ["run", "test-gearbox-runup", "--set", "runup.speed_max_rpm=1e9", "--out", "r"],
     ["runup.speed_max_rpm", "outside the range the source supports"]),
    ("runup-spectrum-speed-huge", ["run", "test-gearbox-runup", "--set", "runup.spectrum_speeds_rpm=[1e9]", "--out",
                                   "r"], ["runup.spectrum_speeds_rpm: 1e+09 rev/min", "outside the range"]),
    # the run-up audit of 2026-11-28: each was accepted (or refused only after meshing) before
    # a step beyond the range ran speed_min alone (one speed, no speed law, spectra skipped) and reported it as usual
    ("runup-speed-step-above-range", ["run", "test-gearbox-runup", "--set", "runup.speed_step_rpm=5000", "--out", "r"],
     ["runup.speed_step_rpm: 5000 rev/min is larger than the run-up 50..1500 rev/min"]),
    # f_max below every tooth line: the housing meshed at elements metres wide (gmsh did not finish in minutes)
    ("runup-f-max-below-the-tooth-frequency", ["run", "test-gearbox-runup", "--set", "runup.f_max_hz=1e-3", "--out",
                                               "r"], ["test-gearbox-runup.toml: runup.f_max_hz: 0.001 Hz is below the "
                                                      "tooth frequency 20 Hz at runup.speed_min_rpm = 50 rev/min"]),
    # a torque or a route given twice was run (and written) twice
    ("runup-torque-twice", ["run", "test-gearbox-runup", "--set", "runup.torques_nm=[2000.0, 2000.0]", "--out", "r"],
     ["runup.torques_nm: 2000.0 is given twice"]),
    ("runup-route-twice", ["run", "test-gearbox-runup", "--set", 'runup.routes=["tf_omega", "tf_omega"]', "--out",
                           "r"], ["runup.routes: 'tf_omega' is given twice"]),
    # 100000 harmonics: a MemoryError traceback (298 GiB) after the housing and its basis were built
    ("runup-harmonics-huge", ["run", "test-gearbox-runup", "--set", "runup.harmonics=100000", "--out", "r"],
     ["runup.harmonics", "less than or equal to 400"]),
    # a TE file whose harmonics all lie above runup.harmonics excited nothing (its harmonics dropped without a word);
    # a harmonic of 1e300 was an OverflowError traceback, one of 500 refused after meshing
    ("runup-te-above-the-harmonics", ["run", "test-gearbox-runup", "--set", "runup.transmission_error=te-harmonic-40.csv",
                                      "--out", "r"],
     ["runup.transmission_error", "te-harmonic-40.csv: its lowest harmonic 40 is above harmonics = 30"]),
    ("runup-te-harmonic-huge", ["run", "test-gearbox-runup", "--set", "runup.transmission_error=te-harmonic-huge.csv",
                                "--out", "r"],
     ["te-harmonic-huge.csv: line 2: harmonic: 1e+300 is above the highest harmonic the source resolves (127"]),
    # a misspelt runup.surface was found after the coupled model and its basis (25 s), named
    # analysis.harmonic.surface (a housing-scene key) without the file; now right after meshing (~10 s)
    ("runup-surface-unknown", ["run", "test-gearbox-runup", "--set", "runup.surface=outr", "--out", "r"],
     ["test-gearbox-runup.toml: runup.surface: no surface 'outr' on the housing test-gearbox (known: "]),
    # a radiation model twice was computed and reported twice; a plate on a surface the housing lacks did not name
    # the run-up scene
    ("runup-radiation-model-twice", ["run", "test-gearbox-runup", "--set", 'radiation.models=["erp", "erp"]', "--out",
                                     "r"], ["test-gearbox-runup.toml: radiation.models: 'erp' is given twice"]),
    ("runup-radiation-plate-unknown", ["run", "test-gearbox-runup", "--set",
                                       'radiation.plates=[{surface = "nowhere", thickness = 0.01}]', "--out", "r"],
     ["test-gearbox-runup.toml: radiation.plates[0].surface: no surface 'nowhere'"]),
    # a parameter's second --range replaced its first without a word
    ("uncertainty-range-twice", ["uncertainty", "--range", "clearance_position=0.1:0.2", "--range",
                                 "clearance_position=0.3:0.4", "--out", "u"], ["--range clearance_position: given twice"]),
]


@pytest.mark.parametrize("argv, needles", [c[1:] for c in SWEEP_CASES], ids=[c[0] for c in SWEEP_CASES])
def test_cli_sweep_refuses_before_any_work(argv, needles, tmp_path):
    _sweep(argv, needles, tmp_path)


CORPUS_SIZE = (len(SCENE_CASES) + len(MESH_CASES) + 1 + len(COARSE_CASES) + len(SET_CASES) + 2 * len(FILE_CASE_NAMES) + 1
               + len(SOURCE_CASES) + len(OTHER_SOURCE_CASES) + len(COMMAND_CASES) + 5
               + len(SWEEP_CASES))


def test_corpus_is_at_least_fifty_cases():
    assert CORPUS_SIZE >= 50, CORPUS_SIZE
