"""The scene reference (issue 27, item 5): docs/scene-reference.md is what the schema generates today (so it
cannot drift), every key has its unit, every geometry kind its surfaces and picture; `housingfe describe` tells a
scene's geometry, surfaces and mesh without solving, with numbers checked against the dimensions."""
from __future__ import annotations

import importlib
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from housingfe import reference
from housingfe.geometry.registry import GEOMETRY_KINDS

ROOT = Path(__file__).resolve().parents[1]
HOUSINGFE = Path(sys.executable).with_name("housingfe")


def describe(*args) -> str:
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    proc = subprocess.run([str(HOUSINGFE), "describe", *args], capture_output=True, text=True, timeout=120,
                          env=env, check=False)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout


def test_committed_reference_is_what_the_schema_generates():
    committed = (ROOT / "docs" / "scene-reference.md").read_text()
    assert reference.scene_reference("img") == committed, \
        "docs/scene-reference.md is out of date: run `housingfe scene-reference --out docs`"


def test_every_geometry_kind_has_its_section_and_picture():
    text = (ROOT / "docs" / "scene-reference.md").read_text()
    for kind, registered in GEOMETRY_KINDS.items():
        assert f'### `kind = "{kind}"`' in text
        if registered.mesh is not None:     # an imported mesh: its surfaces are the file's sets, no picture
            continue
        assert f"(img/geometry-{kind}.png)" in text
        assert (ROOT / "docs" / "img" / f"geometry-{kind}.png").stat().st_size > 10_000


def test_every_numeric_key_has_a_unit():
    # the generator raises for a number without a unit; walk every model of every root to say which
    missing, seen = [], set()

    def walk(cls):
        if cls in seen:
            return
        seen.add(cls)
        for name, field in cls.model_fields.items():
            try:
                reference.field_unit(cls, name, field)
            except ValueError as exc:
                missing.append(str(exc).split(":")[0])
            for model in reference._models_in(field.annotation):
                walk(model)

    for _, module, name, _ in reference.SCENE_ROOTS:
        walk(getattr(importlib.import_module(module), name))
    for kind in GEOMETRY_KINDS.values():
        walk(kind.spec)
    assert not missing, missing


def test_reference_gives_type_unit_default_and_range_of_a_key():
    text = reference.scene_reference()
    # mesh.grading: float in (0, 1], default 1; geometry.length of a box: required, in m
    assert "| `grading` | float | - | 1 | > 0, <= 1 |" in text
    assert "| `length` | float | m | **required** | > 0 | outer length along x" in text
    assert "| `f_max` | float | Hz | **required** | > 0 |" in text


def _lines_after(text: str, heading: str) -> list[str]:
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(heading))
    return lines[start + 1:]


def test_describe_box_free_surfaces_and_dimensions():
    text = describe("box-free")
    assert 'geometry kind "box"' in text and "length = 0.325" in text and "wall_thickness = 0.008" in text
    assert "origin at the centre of the flange underside" in text
    surfaces = {}
    for line in _lines_after(text, "surfaces ("):
        if not line.strip():
            break
        cells = line.split()
        if cells[0] not in ("surface",) and not cells[0].startswith("-"):
            surfaces[cells[0]] = float(cells[1])
    expected = {"outer", "inner", "foot_bottom", "outer_top", "outer_front", "outer_back", "outer_left",
                "outer_right", "outer_flange", *(f"bolt_{i}" for i in range(1, 9))}
    assert set(surfaces) == expected
    # areas from the dimensions: L 0.325, W 0.225, H 0.125, flange 0.015 thick and 0.073 wide (walls 8 mm)
    L, W, H, tf, b = 0.325, 0.225, 0.125, 0.015, 0.073
    assert surfaces["outer_top"] == pytest.approx(L * W, rel=1e-3)
    assert surfaces["outer_front"] == pytest.approx(L * (H - tf), rel=1e-3)
    outer = L * W + 2 * (L + W) * (H - tf) + ((L + 2 * b) * (W + 2 * b) - L * W) + 2 * (L + W + 4 * b) * tf
    assert surfaces["outer"] == pytest.approx(outer, rel=1e-3)
    assert surfaces["bolt_1"] == pytest.approx(0.024 ** 2, rel=1e-3)
    assert "bolts: (-0.199, -0.149, 0)" in text          # flange corner: L/2 + b/2, W/2 + b/2
    assert "supports: none" in text and "modal: every mode below 4000 Hz" in text
    assert "mass ~24.4 kg" in text                       # van Roosmalen: 24.5 kg
    assert "estimated ~" in text and "DOFs" in text


def test_describe_plate_and_gearbox():
    plate = describe("nafems-fv12")
    assert 'geometry kind "plate"' in plate and "a = 10" in plate and "h = 0.05" in plate
    for name in ("edge_x0", "edge_x1", "edge_y0", "edge_y1", "top", "bottom", "outer"):
        assert re.search(rf"^\s*{name}\s", plate, re.M), name
    assert "material bounding box: x 0 .. 10, y 0 .. 10, z 0 .. 0.05 m" in plate
    gearbox = describe("test-gearbox")
    assert 'geometry kind "gearbox"' in gearbox
    assert "bores (m):" in gearbox
    for name in ("bore_pinion", "bore_wheel", "foot_bottom", "outer_bearing_plate_front"):
        assert name in gearbox
    assert "axis y" in gearbox                            # bearing bores run along the shafts (y)


def test_describe_of_a_bad_scene_is_one_line(tmp_path):
    scene = tmp_path / "bad.toml"
    scene.write_text('[scene]\nname = "b"\nkind = "housing"\n[geometry]\nkind = "box"\n[analysis.modal]\n'
                     "f_max = 100.0\n")
    proc = subprocess.run([str(HOUSINGFE), "describe", str(scene)], capture_output=True, text=True, timeout=60,
                          check=False)
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert "geometry.length" in proc.stderr and "geometry.flange_width" in proc.stderr


def test_describe_runup_scene_describes_its_housing():
    text = describe("test-gearbox-runup")
    assert "its housing is the scene test-gearbox" in text and "runup.f_max_hz = 4000 Hz" in text
    assert 'geometry kind "gearbox"' in text and "bore_pinion" in text and "at 4000 Hz" in text


def _block_file(path: Path, scale: float) -> Path:
    """A 300 x 200 x 40 mm block written by gmsh (coordinates x scale: 1 = mm, 1e-3 = m), its underside a
    physical surface FEET; a .msh gets 3-D elements, a .step only the solid."""
    import gmsh

    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("block")
        v = gmsh.model.occ.addBox(0, 0, 0, 300 * scale, 200 * scale, 40 * scale)
        gmsh.model.occ.synchronize()
        if path.suffix == ".msh":
            bottom = [t for d, t in gmsh.model.getBoundary([(3, v)], oriented=False)
                      if abs(gmsh.model.occ.getCenterOfMass(2, t)[2]) < 1e-9]
            gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, [v]), "solid")
            gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, bottom), "FEET")
            gmsh.option.setNumber("Mesh.MeshSizeMax", 40 * scale)
            gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
            gmsh.model.mesh.generate(3)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    return path


def test_describe_a_mesh_file_scene(tmp_path):
    """`housingfe describe` on `kind = "mesh"` (before: "geometry.kind: a 'mesh' geometry is a mesh, not a block
    model", exit 2): the file's extent in m, its sets, and the named surfaces' areas, which for a block are exact
    (outer skin 2 (0.3 x 0.2 + 0.3 x 0.04 + 0.2 x 0.04) = 0.16 m^2, the underside 0.06 m^2); a set the file lacks is
    one line naming the scene and the key."""
    _block_file(tmp_path / "block.msh", 1.0)
    scene = tmp_path / "block.toml"
    text = ('[scene]\nname = "block"\nkind = "housing"\n[geometry]\nkind = "mesh"\nfile = "block.msh"\n'
            'units = "mm"\n[[geometry.surfaces]]\nname = "feet"\nset = "FEET"\n[mesh]\ndegree = 2\n'
            "[analysis.modal]\nf_max = 3000.0\n")
    scene.write_text(text)
    out = describe(str(scene))
    assert out.startswith("scene block ("), out[:200]          # nothing before it (meshio's stray blank line)
    assert "bounding box x 0 .. 0.3, y 0 .. 0.2, z 0 .. 0.04 m" in out
    areas = {m.group(1): float(m.group(2)) for m in re.finditer(r"^\s*(outer|feet)\s+([0-9.e-]+)\s+\d+$", out, re.M)}
    assert areas == pytest.approx({"outer": 0.16, "feet": 0.06}, rel=1e-9), out
    assert "DOFs (counted from the file)" in out
    scene.write_text(text.replace('set = "FEET"', 'set = "FEEET"'))
    proc = subprocess.run([str(HOUSINGFE), "describe", str(scene)], capture_output=True, text=True, timeout=60,
                          check=False)
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert str(scene) in proc.stderr and "geometry.surfaces.0.set: no node or surface set 'FEEET'" in proc.stderr
    assert "Traceback" not in proc.stderr and not proc.stdout.strip()


def test_describe_a_cad_scene(tmp_path):
    """`housingfe describe` on `kind = "cad"` (before: "geometry.kind: an imported CAD housing has no block model",
    exit 2): volume 0.3 x 0.2 x 0.04 = 2.4e-3 m^3 and the mass 18.84 kg of steel, the skin 0.16 m^2, the selected
    underside 0.06 m^2, the element size from the thinnest wall the file gives (40 mm)."""
    _block_file(tmp_path / "block.step", 1e-3)
    scene = tmp_path / "block.toml"
    scene.write_text('[scene]\nname = "block"\nkind = "housing"\n[geometry]\nkind = "cad"\nfile = "block.step"\n'
                     'units = "m"\n[[geometry.surfaces]]\nname = "feet"\nplane = { point = [0.1, 0.1, 0.0], '
                     'normal = [0, 0, -1] }\n[material]\nname = "steel"\n[analysis.modal]\nf_max = 3000.0\n')
    out = describe(str(scene))
    assert "volume 0.0024 m^3" in out and "mass ~18.84 kg" in out, out
    areas = {m.group(1): float(m.group(2)) for m in re.finditer(r"^\s*(outer|feet)\s+([0-9.e-]+)\s+plane$", out, re.M)}
    assert areas == pytest.approx({"outer": 0.16, "feet": 0.06}, rel=1e-6), out
    assert "thinnest wall (40 mm, estimated from the CAD file)" in out
