"""`housingfe source <scene>`: dispatch, outputs and one-line errors with exit code 2."""
import csv
import json
from pathlib import Path

import pytest

import housingfe
from housingfe.cli import main
from housingfe.data import thesis

SCENES = Path(housingfe.__file__).parent / "scenes"
REF = thesis()


def _small_scene(tmp_path, extra_source="", name="tiny"):
    """gearset-A with a coarse discretisation so the whole pipeline runs in a few seconds."""
    text = (SCENES / "gearset-A.toml").read_text()
    text = text.replace('name = "gearset-A"', f'name = "{name}"')
    for key, value in (("speed_steps", "3"), ("stiffness_positions", "8"), ("slices", "6"), ("harmonics", "10"),
                       ("torque_run_Nm", "[2000.0]")):
        lines = [ln for ln in text.splitlines() if ln.startswith(f"{key} =")]
        text = text.replace(lines[0], f"{key} = {value}")
    text = text.replace("[source.gears]", extra_source + "\n[source.gears]")
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return path


def test_source_run_writes_the_documented_outputs(tmp_path, capsys):
    out = tmp_path / "res"
    assert main(["source", str(_small_scene(tmp_path)), "--out", str(out)]) == 0
    geo = json.loads((out / "gear_geometry.json").read_text())
    ref = REF["gears"]["single_helical"]
    assert geo["transverse_contact_ratio"] == pytest.approx(ref["transverse_contact_ratio"], abs=5e-4)
    assert geo["base_diameter_mm"] == pytest.approx(ref["base_diameter_mm"], abs=5e-4)
    with open(out / "runup.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == ["speed_rpm", "torque_Nm", "tooth_frequency_hz", "L_omega_tooth_band_dB"]
    assert [float(r["tooth_frequency_hz"]) for r in rows] == pytest.approx([0.4 * float(r["speed_rpm"]) for r in rows])
    spectra = json.loads((out / "bearing_spectra.json").read_text())
    assert len(spectra["operating_points"]) == 3
    assert {b["name"] for b in spectra["operating_points"][0]["bearings"]} == {
        "pinion_left", "pinion_right", "wheel_left", "wheel_right"}
    for png in ("stiffness.png", "tooth_profiles.png", "L_omega_spectra.png", "runup.png"):
        assert (out / png).stat().st_size > 1000
    assert not list(tmp_path.glob(".res.tmp-*"))


@pytest.mark.parametrize("mutate, key", [
    (lambda t: t.replace('model = "roosmalen"', 'model = "nonsense"'), "source.model"),
    (lambda t: t.replace("slices = 6", "slices = 6\nslicez = 3"), "source.slicez"),
    (lambda t: t.replace("module_mm = 4.0", "module_mm = -4.0"), "source.gears.module_mm"),
    (lambda t: t.replace('kind = "source"', 'kind = "housing"'), "scene.kind"),
])
def test_bad_scenes_exit_2_with_one_line(tmp_path, capsys, mutate, key):
    path = _small_scene(tmp_path)
    path.write_text(mutate(path.read_text()))
    assert main(["source", str(path), "--out", str(tmp_path / "res")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and key in err and str(path) in err
    assert not (tmp_path / "res").exists()


def test_unknown_builtin_scene_exits_2(capsys):
    assert main(["source", "no-such-gearset"]) == 2
    assert "gearset-A" in capsys.readouterr().err


def test_builtin_gearsets_are_valid_source_scenes():
    from housingfe.source.cli import load_scene
    from housingfe.source.roosmalen.run import build, parse

    for name in ("gearset-A", "gearset-B", "gearset-C", "gearset-D", "gearset-uncorrected", "gearset-double-helical"):
        scene, path = load_scene(name)
        assert scene["scene"]["name"] == name
        pair = build(parse(scene, str(path)), str(path))[0]
        which = "double_helical" if "double" in name else "single_helical"
        assert pair.kind == which
        assert pair.transverse_contact_ratio == pytest.approx(REF["gears"][which]["transverse_contact_ratio"], abs=5e-4)


def test_engagement_key_selects_the_shock_model(tmp_path):
    """source.engagement: "face-width" (default), "thesis-2d" or "envelope-bound"; anything else is named as the bad
    key."""
    from housingfe.scenefile import read_scene_dict
    from housingfe.source.roosmalen import run as roosmalen

    data, path = read_scene_dict(str(_small_scene(tmp_path)))
    assert roosmalen.parse(data, str(path)).engagement == "face-width"
    data["source"]["engagement"] = "thesis-2d"
    assert roosmalen.parse(data, str(path)).engagement == "thesis-2d"
    data["source"]["engagement"] = "envelope-bound"
    assert roosmalen.parse(data, str(path)).engagement == "envelope-bound"
    data["source"]["engagement"] = "3-d"
    with pytest.raises(housingfe.errors.InputError, match="source.engagement"):
        roosmalen.parse(data, str(path))
