"""The newcomer's traps of issue 27 (item 3), each as a user meets it: the console script on real files.

Bearing geometry in millimetres, --set into [[loads]], every missing key named, a UTF-8 byte-order mark,
sound_power.png saying what it plots, commands saying where they wrote, tables that fit 120 columns.
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from housingfe.scenefile import SCENE_DIR

HOUSINGFE = Path(sys.executable).with_name("housingfe")


def housingfe(*args, cwd=None, timeout=300):
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    return subprocess.run([str(HOUSINGFE), *map(str, args)], cwd=cwd, capture_output=True, text=True,
                          timeout=timeout, env=env, check=False)


def one_error_line(proc) -> str:
    lines = [line for line in proc.stderr.strip().splitlines() if line.strip()]
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    assert "Traceback" not in proc.stderr and len(lines) == 1, proc.stderr
    assert lines[0].startswith("housingfe: error: "), lines[0]
    return lines[0]


# ---------------------------------------------------------------- bearing geometry in millimetres
def _bearing_file(tmp_path: Path, **values) -> Path:
    path = tmp_path / "bearing.toml"
    path.write_text("[bearing]\n" + "".join(f"{k} = {v!r}\n" for k, v in values.items()))
    return path


LOAD = ["--load", "1e4", "0", "0", "0", "0"]


@pytest.mark.parametrize("values, key", [
    ({"elements": 9, "element_diameter": 25.0, "pitch_diameter": 125.0}, "element_diameter"),
    ({"elements": 9, "element_diameter": 0.025, "pitch_diameter": 125.0}, "pitch_diameter"),
    ({"elements": 9, "element_diameter": 0.025, "pitch_diameter": 0.125, "radial_clearance": 0.02},
     "radial_clearance"),
], ids=["ball-25", "pitch-125", "clearance-mm"])
def test_bearing_geometry_in_millimetres_is_refused(tmp_path, values, key):
    line = one_error_line(housingfe("bearing", "--geometry", _bearing_file(tmp_path, **values), *LOAD))
    assert str(tmp_path / "bearing.toml") in line and key in line and "millimetres" in line, line


@pytest.mark.parametrize("flags, flag, unit", [
    (["--balls", "9", "--ball-diameter", "25", "--pitch-diameter", "0.125"], "--ball-diameter", "millimetres"),
    (["--balls", "9", "--ball-diameter", "0.025", "--pitch-diameter", "125"], "--pitch-diameter", "millimetres"),
    (["--balls", "9", "--ball-diameter", "0.025", "--pitch-diameter", "0.125", "--youngs-modulus", "208"],
     "--youngs-modulus", "GPa"),
    (["SKF 6312", "--ball-diameter", "22"], "--ball-diameter", "millimetres"),
], ids=["flag-ball", "flag-pitch", "flag-modulus-gpa", "designation-override"])
def test_bearing_flags_in_other_units_are_refused_naming_the_flag(flags, flag, unit):
    line = one_error_line(housingfe("bearing", *flags, *LOAD))
    assert flag in line and unit in line, line


def test_bearing_geometry_in_metres_still_runs(tmp_path):
    # the same bearing in metres: Hertz, 9 balls of 25 mm, 10 kN radial -> a deflection of tens of micrometres
    proc = housingfe("bearing", "--geometry", _bearing_file(tmp_path, elements=9, element_diameter=0.025,
                                                             pitch_diameter=0.125), *LOAD, "--json")
    assert proc.returncode == 0, proc.stderr
    import json

    deflection = json.loads(proc.stdout)["displacement"][0]
    assert 1e-5 < deflection < 1e-4, deflection


# ---------------------------------------------------------------- --set into arrays of tables
def test_set_reaches_an_array_of_tables_entry():
    proc = housingfe("describe", "box-free-frf", "--set", "loads.0.amplitude=3",
                     "--set", "loads.0.point=[0.05, 0.0, 0.125]")
    assert proc.returncode == 0, proc.stderr
    first_load = next(line for line in proc.stdout.splitlines() if line.startswith("  ") and "force" in line)
    assert "force 3 N" in first_load and "(0.05, 0, 0.125)" in first_load, first_load


@pytest.mark.parametrize("item, needles", [
    ("loads.5.amplitude=2", ["loads.5.amplitude", "out of range", "2 entries"]),
    ("loads.first.amplitude=2", ["loads.first.amplitude", "index"]),
    ("loads[0].amplitude=2", ["loads[0].amplitude", "loads.0.amplitude"]),
    ("loads.0.amplitude=loud", ["loads.0.amplitude"]),
])
def test_bad_array_override_is_one_line(item, needles, tmp_path):
    out = tmp_path / "out"
    line = one_error_line(housingfe("run", "box-free-frf", "--out", out, "--set", item))
    for needle in needles:
        assert needle in line, line
    assert not out.exists()


# ---------------------------------------------------------------- missing keys, byte-order marks
def test_every_missing_key_is_named(tmp_path):
    scene = tmp_path / "mine.toml"
    scene.write_text('[scene]\nname = "mine"\nkind = "housing"\n[geometry]\nkind = "box"\nlength = 0.4\n'
                     "[analysis.modal]\nf_max = 1000.0\n")
    line = one_error_line(housingfe("run", scene, "--out", tmp_path / "out"))
    for key in ("width", "height", "wall_thickness", "flange_thickness", "flange_width"):
        assert f"geometry.{key}" in line, line
    assert "more)" not in line


def test_utf8_byte_order_mark_is_accepted(tmp_path):
    text = (SCENE_DIR / "box-free.toml").read_text()
    plain, bom = tmp_path / "plain.toml", tmp_path / "bom.toml"
    plain.write_text(text)
    bom.write_bytes(b"\xef\xbb\xbf" + text.encode())
    a, b = housingfe("describe", plain), housingfe("describe", bom)
    assert b.returncode == 0, b.stderr
    assert a.stdout.replace(str(plain), "F") == b.stdout.replace(str(bom), "F")


def test_utf16_file_is_named_as_such(tmp_path):
    scene = tmp_path / "utf16.toml"
    scene.write_bytes((SCENE_DIR / "box-free.toml").read_text().encode("utf-16"))
    line = one_error_line(housingfe("run", scene, "--out", tmp_path / "out"))
    assert "utf16.toml" in line and "UTF-16 byte-order mark" in line and "UTF-8" in line, line


# ---------------------------------------------------------------- sound_power.png says what it plots
@pytest.mark.timeout(300)
def test_sound_power_png_is_labelled(tmp_path):
    from PIL import Image

    from tests.test_bad_input import BASE, to_toml

    scene = tmp_path / "radiating.toml"
    scene.write_text(to_toml(dict(BASE, output={"mode_pictures": 0, "paraview": False, "pictures": True})))
    out = tmp_path / "out"
    proc = housingfe("run", scene, "--out", out)
    assert proc.returncode == 0, proc.stderr
    assert f"results: {out}/" in proc.stdout
    text = Image.open(out / "sound_power.png").text
    assert "bad-input-base" in text["Title"] and "radiation model erp" in text["Title"], text
    assert "S = 0.321 m^2" in text["Title"], text      # the box's radiating surface, as describe computes it
    assert "y L_W (dB re 1 pW)" in text["Description"] and "x frequency (Hz)" in text["Description"], text
    assert "1/3-octave band centre frequency (Hz)" in text["Description"], text


# ---------------------------------------------------------------- every command says where it wrote
@pytest.mark.timeout(300)
@pytest.mark.parametrize("args, says", [
    (["bench", "bearings", "--quick", "--out", "{out}"], "results: {out}/"),
    (["radiation", "foller", "builtin:scale-model", "--out", "{out}"], "wrote {out}/foller.csv"),
    (["scene-reference", "--out", "{out}", "--no-pictures"], "wrote {out}/scene-reference.md"),
], ids=["bench-bearings", "radiation-foller", "scene-reference"])
def test_command_prints_where_it_wrote(args, says, tmp_path):
    out = tmp_path / "written"
    proc = housingfe(*[a.format(out=out) for a in args], cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert says.format(out=out) in proc.stdout, proc.stdout[-2000:]
    assert out.exists()


# ---------------------------------------------------------------- tables fit 120 columns
def test_wide_table_fits_120_columns_and_keeps_every_cell():
    from housingfe.outputs import format_table

    header = [f"column_number_{i}" for i in range(14)]
    rows = [[f"row{r}"] + [float(r * 100 + i) for i in range(1, 14)] for r in range(3)]
    text = format_table(header, rows)
    assert max(len(line) for line in text.splitlines()) <= 120
    for name in header:
        assert name in text
    for r in range(3):
        assert text.count(f"row{r}") == 3          # the first column repeated in each block of columns
        for i in range(1, 14):
            assert f"{r * 100 + i:g}" in text


def test_wide_table_repeats_every_key_column_in_each_block():
    """Rows told apart by three columns (variant, route, radiation, as `housingfe runup-causes` prints them) stay
    told apart in every block of a split table: each block's line of a row carries its route and radiation, and
    the long variant names are shortened so that the keys fit."""
    from housingfe.outputs import format_table

    header = ["variant", "route", "radiation"] + [f"quantity_number_{i}" for i in range(6)]
    rows = [["reference: xi 0.04, modes to 6000 Hz + static vectors, harmonics to 4000 Hz", route, rad]
            + [float(100 * k + i) for i in range(6)]
            for k, (route, rad) in enumerate([(r, s) for r in ("tf_omega", "mesh_force") for s in ("erp", "foller")])]
    text = format_table(header, rows, keys=3)
    assert max(len(line) for line in text.splitlines()) <= 120, text
    blocks = text.split("\n\n")
    assert len(blocks) >= 2, text
    for block in blocks:
        lines = block.splitlines()[2:]
        assert len(lines) == 4, block
        for k, (row, line) in enumerate(zip(rows, lines)):
            assert f" {row[1]} " in line and f" {row[2]} " in line, (k, line)
    for k in range(4):
        for i in range(6):
            assert f"{100 * k + i:g}" in text


def test_validate_terminal_table_fits_and_points_to_the_files():
    from housingfe.verification.validate import format_rows

    rows = [{"scene": "box-free", "quantity": f"elastic mode {i}", "ours": 640.1 + i, "published": 641.0,
             "difference": i - 0.9, "relative_difference": (i - 0.9) / 641.0, "unit": "Hz", "source": "van Roosmalen (1994) Table 4.1, p. 53 " * 2,
             "note": "a long note on the reconstruction of the box's dimensions and the mesh used " * 3}
            for i in range(5)]
    text = format_rows(rows)
    assert max(len(line) for line in text.splitlines()) <= 120, text
    assert all(f"{640.1 + i:.4g}" in text for i in range(5))
