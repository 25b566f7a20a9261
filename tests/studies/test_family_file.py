"""`housingfe study my_family.toml`: the user's own family of design variants (docs/design-variants.md, "Your own
family"), as a user hits it.

* bad family files: one line `housingfe: error: <file>: <key>: <what>`, exit 2, no traceback, no result folder;
  the gear sets and bearing configurations named by the run-up scene's own registries;
* a scene file given relative to the family file, the scene's drivetrain and torque as defaults;
* examples/study_family.toml end to end through the CLI on the coarse gearbox (--set: 60 mm mesh, lines to 1.5 kHz,
  three speeds): the reference's difference is exactly 0, the other variant's mean is the mean over 800-1500 rev/min
  of the run-up curves' difference, one basis for both variants, the user's measured numbers beside ours.
"""
import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest

from housingfe.bearings.configurations import configurations
from housingfe.drivetrain.description import GEAR_SETS
from housingfe.errors import InputError
from housingfe.scenefile import SCENE_DIR
from housingfe.studies.design_variants import MeasuredTorqueLaw, family_of
from tests.test_cli import housingfe

EXAMPLE = Path(__file__).parents[2] / "examples" / "study_family.toml"
TORQUE_EXAMPLE = Path(__file__).parents[2] / "examples" / "study_family_torque.toml"
COARSE = ['housing.set=["mesh.size=0.06"]', "runup.f_max_hz=1500", "runup.speed_min_rpm=800",
          "runup.speed_step_rpm=350"]          # 800, 1150, 1500 rev/min

GOOD = """name = "mine"
scene = "test-gearbox-runup"
reference = "ball"
[[variants]]
key = "ball"
gear_set = "B"
bearings = "ball"
torque_nm = 1500.0
[[variants]]
key = "self_aligning"
gear_set = "B"
bearings = "self_aligning"
torque_nm = 1500.0
measured_mean_db = -5.1
"""

BAD = {
    "malformed": (GOOD.replace('reference = "ball"', 'reference = ball"'), "malformed TOML"),
    "unknown_top_key": (GOOD.replace("reference =", "refrence ="),
                        "refrence: unknown key (known: name, scene, title, reference, source, notes, set, variants, "
                        "torque_laws)"),
    "unknown_variant_key": (GOOD.replace("measured_mean_db", "measured_mean"),
                            "variants.1.measured_mean: unknown key (known: key, gear_set, bearings, torque_nm, "
                            "measured_mean_db, measured_sd_db, measured_max_dba)"),
    "missing_reference": (GOOD.replace('reference = "ball"\n', ""), "reference: missing"),
    "reference_not_a_variant": (GOOD.replace('reference = "ball"', 'reference = "roller"'),
                                "reference: 'roller' is not a variant key (variants: ball, self_aligning)"),
    "duplicate_key": (GOOD.replace('key = "self_aligning"', 'key = "ball"'),
                      "variants.1.key: 'ball' is also variants.0.key"),
    "unknown_gear_set": (GOOD.replace('gear_set = "B"\nbearings = "self', 'gear_set = "E"\nbearings = "self'),
                         f"variants.1.gear_set: 'E' is not a gear set (known: {', '.join(GEAR_SETS)})"),
    "empty_gear_set": (GOOD.replace('gear_set = "B"\nbearings = "self', 'gear_set = ""\nbearings = "self'),
                       "variants.1.gear_set: '' is not a gear set"),
    "unknown_bearings": (GOOD.replace('bearings = "self_aligning"', 'bearings = "needle"'),
                         f"variants.1.bearings: 'needle' is not a bearing configuration (known: "
                         f"{', '.join(configurations())})"),
    "zero_torque": (GOOD.replace("torque_nm = 1500.0\nmeasured", "torque_nm = 0\nmeasured"),
                    "variants.1.torque_nm: Input should be greater than 0"),
    "negative_torque": (GOOD.replace("torque_nm = 1500.0\n[[", "torque_nm = -100.0\n[["),
                        "variants.0.torque_nm: Input should be greater than 0"),
    "housing_scene": (GOOD.replace('scene = "test-gearbox-runup"', 'scene = "box-free"'),
                      "scene: 'box-free' is a housing scene, not a run-up scene"),
    "missing_scene_file": (GOOD.replace('scene = "test-gearbox-runup"', 'scene = "no_such_scene.toml"'),
                           "scene: 'no_such_scene.toml': no such file"),
    "set_of_a_variant_key": (GOOD.replace('reference = "ball"', 'reference = "ball"\nset = ["drivetrain.bearings=ball"]'),
                             "set: drivetrain.bearings: each variant sets it"),
    "measured_on_the_reference": (GOOD.replace('torque_nm = 1500.0\n[[', 'torque_nm = 1500.0\nmeasured_mean_db = 1.0\n[['),
                                  "variants.0.measured_mean_db: the reference's difference to itself is 0"),
    "one_variant": (GOOD[:GOOD.index("[[variants]]\nkey = \"self")], "variants: 1 given: a family needs"),
    "bearing_cannot_carry_its_load": (GOOD.replace('bearings = "self_aligning"', 'bearings = "fluid_film"'),
                                      "variants.1 (self_aligning): drivetrain: bearings = 'fluid_film'"),
}


# a family with a torque-law group (ball at 1000 and 2000 N m) and a [[torque_laws]] entry of it
TORQUE = GOOD.replace("torque_nm = 1500.0\n[[", "torque_nm = 2000.0\n[[") + """[[variants]]
key = "ball@1000"
gear_set = "B"
bearings = "ball"
torque_nm = 1000.0
[[torque_laws]]
gear_set = "B"
bearings = "ball"
from_nm = 1000.0
to_nm = 2000.0
measured_step_dba = 3.4
"""

BAD_TORQUE_LAWS = {
    "unknown_key": (TORQUE.replace("measured_step_dba", "measured_step"),
                    "torque_laws.0.measured_step: unknown key (known: gear_set, bearings, from_nm, to_nm, "
                    "measured_step_dba, measured_slope_dba_per_doubling)"),
    "torque_no_variant_has": (TORQUE.replace("from_nm = 1000.0", "from_nm = 1200.0"),
                              "torque_laws.0.from_nm: 1200 N m: no variant with gear set 'B' and bearings 'ball' runs "
                              "at it (their torques: 1000, 2000 N m)"),
    "to_below_from": (TORQUE.replace("from_nm = 1000.0\nto_nm = 2000.0", "from_nm = 2000.0\nto_nm = 1000.0"),
                      "torque_laws.0.to_nm: 1000 N m: give a torque above from_nm (2000 N m)"),
    "bearings_no_variant_has": (TORQUE.replace('bearings = "ball"\nfrom_nm', 'bearings = "tapered_roller"\nfrom_nm'),
                                "torque_laws.0.bearings: no variant has gear set 'B' and bearings 'tapered_roller'"),
    "gear_set_no_variant_has": (TORQUE.replace('gear_set = "B"\nbearings = "ball"\nfrom_nm',
                                               'gear_set = "C"\nbearings = "ball"\nfrom_nm'),
                                "torque_laws.0.gear_set: no variant has gear set 'C' and bearings 'ball'"),
    "one_torque": (TORQUE.replace('bearings = "ball"\nfrom_nm = 1000.0\nto_nm = 2000.0\n',
                                  'bearings = "self_aligning"\n'),
                   "torque_laws.0: the variants with gear set 'B' and bearings 'self_aligning' are at one torque "
                   "(1500 N m)"),
    "nothing_measured": (TORQUE.replace("measured_step_dba = 3.4\n", ""), "torque_laws.0.measured_step_dba: missing"),
    "step_not_a_number": (TORQUE.replace("measured_step_dba = 3.4", 'measured_step_dba = "a lot"'),
                          "torque_laws.0.measured_step_dba: Input should be a valid number"),
    "negative_torque": (TORQUE.replace("from_nm = 1000.0", "from_nm = -1000.0"),
                        "torque_laws.0.from_nm: Input should be greater than 0"),
    "twice": (TORQUE + '[[torque_laws]]\ngear_set = "B"\nbearings = "ball"\nmeasured_slope_dba_per_doubling = 3.0\n',
              "torque_laws.1: gear set 'B' and bearings 'ball' has a torque law already (torque_laws.0)"),
}


def _assert_refused(proc, message, tmp_path, out):
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("housingfe: error: ") and message in lines[0], proc.stderr
    assert "Traceback" not in proc.stderr
    assert not out.exists()


@pytest.mark.parametrize("case", list(BAD))
def test_bad_family_file_is_one_line_exit_2_and_no_folder(tmp_path, case):
    text, message = BAD[case]
    family = tmp_path / "fam.toml"
    family.write_text(text)
    out = tmp_path / "out"
    proc = housingfe("study", str(family), "--out", str(out))
    _assert_refused(proc, f"{family}: {message}", tmp_path, out)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fam.toml"]


def test_torque_laws_of_a_family_file(tmp_path):
    """A [[torque_laws]] entry names its group's gear set and bearings (defaults: the scene's) and two of its
    torques (defaults: the lowest and highest)."""
    family = tmp_path / "fam.toml"
    family.write_text(TORQUE)
    assert family_of(str(family)).torque_laws == (MeasuredTorqueLaw("B", "ball", 1000.0, 2000.0, 3.4),)
    # the scene's drivetrain (gear set A, ball bearings) and the group's lowest and highest torque
    family.write_text('scene = "test-gearbox-runup"\nreference = "a"\n[[variants]]\nkey = "a"\ntorque_nm = 500\n'
                      '[[variants]]\nkey = "b"\ntorque_nm = 1500\n[[variants]]\nkey = "c"\ntorque_nm = 1000\n'
                      '[[torque_laws]]\nmeasured_slope_dba_per_doubling = 3.0\n')
    assert family_of(str(family)).torque_laws == (MeasuredTorqueLaw("A", "ball", 500.0, 1500.0, None, 3.0),)


@pytest.mark.parametrize("case", list(BAD_TORQUE_LAWS))
def test_bad_torque_law_names_the_file_and_key(tmp_path, case):
    text, message = BAD_TORQUE_LAWS[case]
    family = tmp_path / "fam.toml"
    family.write_text(text)
    with pytest.raises(InputError) as err:
        family_of(str(family))
    assert str(err.value).startswith(f"{family}: {message}"), str(err.value)


def test_bad_torque_law_is_one_line_exit_2_and_no_folder(tmp_path):
    """As a user hits it: the torque law is checked before any FE work or folder."""
    text, message = BAD_TORQUE_LAWS["torque_no_variant_has"]
    family = tmp_path / "fam.toml"
    family.write_text(text)
    out = tmp_path / "out"
    _assert_refused(housingfe("study", str(family), "--out", str(out)), f"{family}: {message}", tmp_path, out)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fam.toml"]


def test_unreadable_family_file_and_mixed_with_a_built_in_family(tmp_path):
    out = tmp_path / "out"
    proc = housingfe("study", "bearings", str(tmp_path / "absent.toml"), "--out", str(out))
    _assert_refused(proc, f"{tmp_path / 'absent.toml'}: no such family file", tmp_path, out)
    family = tmp_path / "bearings.toml"               # its name (the stem) is the built-in family's: one folder
    family.write_text(GOOD.replace('name = "mine"\n', ""))
    proc = housingfe("study", "bearings", str(family), "--out", str(out))
    _assert_refused(proc, "two jobs write into the same folder", tmp_path, out)


def test_scene_file_relative_to_the_family_file_and_the_scene_defaults(tmp_path, monkeypatch):
    """A run-up scene file beside the family file is found from any working directory; a variant without gear
    set, bearings or torque takes the scene's drivetrain and first torque."""
    scene = (SCENE_DIR / "test-gearbox-runup.toml").read_text()
    scene = scene.replace('gear_set = "A"', 'gear_set = "C"').replace("torques_nm = [2000.0]",
                                                                        "torques_nm = [1200.0, 2000.0]")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "my-runup.toml").write_text(scene)
    family = tmp_path / "sub" / "fam.toml"
    family.write_text('scene = "my-runup.toml"\nreference = "as-scene"\nset = ["runup.engagement=thesis-2d"]\n'
                      '[[variants]]\nkey = "as-scene"\n[[variants]]\nkey = "tapered"\nbearings = "tapered_roller"\n'
                      'torque_nm = 800\n')
    monkeypatch.chdir(tmp_path)
    fam = family_of("sub/fam.toml")
    assert fam.name == "fam" and fam.reference == "as-scene"
    assert Path(fam.scene) == Path("sub/my-runup.toml") and fam.path == Path("sub/fam.toml")
    assert fam.overrides == ("runup.engagement=thesis-2d",)
    assert [(v.key, v.gear_set, v.bearings, v.torque) for v in fam.variants] == \
        [("as-scene", "C", "ball", 1200.0), ("tapered", "C", "tapered_roller", 800.0)]
    with pytest.raises(InputError, match=r"fam.toml: set: .*runup.engagement"):
        family.write_text(family.read_text().replace("thesis-2d", "no-such-shock"))
        family_of(str(family))


@pytest.mark.slow
def test_example_family_end_to_end_through_the_cli(tmp_path):
    out = tmp_path / "out"
    proc = housingfe("study", str(EXAMPLE), "--out", str(out), *[x for s in COARSE for x in ("--set", s)])
    assert proc.returncode == 0, proc.stderr
    name = "ball-vs-self-aligning"
    assert {f"{name}.csv", f"{name}.md", f"{name}.png", f"{name}_runup.csv", "study.json"} <= \
        {p.name for p in out.iterdir()}
    rows = list(csv.DictReader(open(out / f"{name}.csv")))
    assert [(r["route"], r["variant"]) for r in rows] == [(route, v) for route in ("tf_omega", "mesh_force")
                                                          for v in ("ball", "self_aligning")]
    curves = list(csv.DictReader(open(out / f"{name}_runup.csv")))
    speeds = [float(c["speed_rpm"]) for c in curves]
    assert speeds == [800.0, 1150.0, 1500.0]
    for r in rows:
        assert int(r["speeds_in_mean"]) == 3
        if r["variant"] == "ball":
            assert float(r["mean_diff_dB"]) == 0.0 and float(r["sd_diff_dB"]) == 0.0
            assert float(r["measured_max_dBA"]) == 98.3 and r["measured_mean_dB"] == ""
            continue
        # the mean of the speed-by-speed difference of the curves, recomputed from the written run-up
        d = [float(c[f"LwA_{r['route']}_self_aligning_dBA"]) - float(c[f"LwA_{r['route']}_ball_dBA"]) for c in curves]
        assert float(r["mean_diff_dB"]) == pytest.approx(np.mean(d), abs=0.006)
        assert float(r["sd_diff_dB"]) == pytest.approx(np.std(d), abs=0.006)
        # the energy means of the two curves over 800-1500 rev/min, as written beside them
        for key in ("ball", "self_aligning"):
            lw = [float(c[f"LwA_{r['route']}_{key}_dBA"]) for c in curves]
            energy = 10 * math.log10(np.mean([10 ** (x / 10) for x in lw]))
            row = next(x for x in rows if x["route"] == r["route"] and x["variant"] == key)
            assert float(row["LwA_energy_mean_800_1500_dBA"]) == pytest.approx(energy, abs=0.06)
        assert (float(r["measured_mean_dB"]), float(r["measured_sd_dB"]), float(r["measured_max_dBA"])) == \
            (-5.1, 6.0, 92.3)
        assert r["basis"] == "re-analysed"
    data = json.loads((out / "study.json").read_text())
    assert data["basis_builds"] == 1 and data["family"] == name and data["reference"] == "ball"
    md = (out / f"{name}.md").read_text()
    assert "| self_aligning | " in md and "van Roosmalen (1994), Figs. 5.16/5.17" in md


def test_a_file_reproducing_the_bearings_family_is_the_same_family(tmp_path):
    """The file route is the built-in machinery: a family file that writes out the built-in `bearings` family (its
    variants and the measured numbers of housingfe/data/roosmalen1994.toml) gives the same variants, reference and
    scene, hence the same run (measured on the full model: `housingfe study bearings` and this file's study wrote
    byte-identical bearings_runup.csv and bearings.csv but for the timing columns; docs/design-variants.md)."""
    from housingfe.studies.design_variants import families

    builtin = families()["bearings"]
    entries = []
    for v in builtin.variants:
        entry = [f'key = "{v.key}"', f'gear_set = "{v.gear_set}"', f'bearings = "{v.bearings}"',
                 f"torque_nm = {v.torque}"]
        entry += [f"{name} = {value}" for name, value in (("measured_mean_db", v.measured_mean),
                                                          ("measured_sd_db", v.measured_sd),
                                                          ("measured_max_dba", v.measured_max)) if value is not None]
        entries.append("[[variants]]\n" + "\n".join(entry))
    family = tmp_path / "bearings.toml"
    family.write_text(f'scene = "{builtin.scene}"\nreference = "{builtin.reference}"\n' + "\n".join(entries) + "\n")
    mine = family_of(str(family))
    assert (mine.name, mine.scene, mine.reference, mine.controlled, mine.overrides) == \
        (builtin.name, builtin.scene, builtin.reference, builtin.controlled, builtin.overrides)
    assert mine.variants == builtin.variants
    assert [v.measured_mean for v in mine.variants] == [None, -4.2, -5.1, -3.6]


@pytest.mark.slow
def test_torque_example_end_to_end_through_the_cli(tmp_path):
    """examples/study_family_torque.toml on the coarse gearbox: per bearings group (1000 and 2000 N m) and route
    the step is the mean of the speed-by-speed difference of the written run-up curves, the slope of two torques
    the step of their 800-1500 rev/min energy means (per doubling: log2(2000 / 1000) = 1), the measured +3.4 /
    +2.7 dB(A) of the file beside them in study.json, <name>_torque_law.csv, <name>.md and the printed summary."""
    out = tmp_path / "out"
    proc = housingfe("study", str(TORQUE_EXAMPLE), "--out", str(out), *[x for s in COARSE for x in ("--set", s)])
    assert proc.returncode == 0, proc.stderr
    name = "double-helical-torque"
    curves = list(csv.DictReader(open(out / f"{name}_runup.csv")))
    laws = json.loads((out / "study.json").read_text())["torque_law"]
    assert [(t["bearings"], t["route"]) for t in laws] == [(b, r) for b in ("cylindrical_roller", "fluid_film")
                                                           for r in ("tf_omega", "mesh_force")]
    assert list(csv.DictReader(open(out / f"{name}_torque_law.csv")))[0]["measured_step_dBA"] == "3.4"
    prefix = {"cylindrical_roller": "roller", "fluid_film": "fluid_film"}
    for t in laws:
        hi, lo = ([float(c[f"LwA_{t['route']}_{prefix[t['bearings']]}@{torque}_dBA"]) for c in curves]
                  for torque in (2000, 1000))
        assert (t["from_nm"], t["to_nm"], t["torques_nm"]) == (1000.0, 2000.0, "1000 2000")
        assert t["step_mean_dB"] == pytest.approx(np.mean(np.subtract(hi, lo)), abs=0.006)
        assert t["step_sd_dB"] == pytest.approx(np.std(np.subtract(hi, lo)), abs=0.006)
        energy = [10 * math.log10(np.mean([10 ** (x / 10) for x in lw])) for lw in (lo, hi)]
        assert t["slope_dB_per_doubling"] == pytest.approx(energy[1] - energy[0], abs=0.006)
        assert t["measured_step_dBA"] == {"cylindrical_roller": 3.4, "fluid_film": 2.7}[t["bearings"]]
        line = (f"torque law {t['bearings']}, {t['route']}: 1000 -> 2000 N m {t['step_mean_dB']:+.1f} ± "
                f"{t['step_sd_dB']:.1f} dB(A) (measured {t['measured_step_dBA']:+.1f}); slope "
                f"{t['slope_dB_per_doubling']:+.1f} dB(A) per doubling over 1000 2000 N m")
        assert line in proc.stdout
        assert f"| {t['bearings']} | {t['route']} | {t['step_mean_dB']:+.1f} ± {t['step_sd_dB']:.1f} |" in \
            (out / f"{name}.md").read_text()
