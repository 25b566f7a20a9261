"""Run-up scenes: bad input is one line naming the key, exit 2, no result folder (issue 14's list: an unknown
gear set, a speed range outside what the source supports, a bearing that cannot carry the load at a torque, a
missing drivetrain; plus an unknown route or radiator); the built-in scenes validate."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

from housingfe.errors import InputError
from housingfe.runup.scene import load_runup_scene

HOUSINGFE = [sys.executable, "-m", "housingfe"]


@pytest.mark.parametrize("name", ["test-gearbox-runup", "test-gearbox-runup-double-helical"])
def test_builtin_scenes_validate(name):
    scene, _ = load_runup_scene(name)
    assert scene.runup.speeds[0] == 50.0 and scene.runup.speeds[-1] == 1500.0 and len(scene.runup.speeds) == 30
    assert scene.drivetrain.gearbox == "test_gearbox"
    # the wheel located where the thesis says for the scene's bearings ("front" where it says nothing)
    assert scene.drivetrain.wheel_locating == "configuration"


@pytest.mark.parametrize("override, key", [
    ("drivetrain.gear_set=Z", "drivetrain.gear_set"),
    ("drivetrain.wheel_locating=middle", "drivetrain.wheel_locating"),
    ("runup.speed_max_rpm=3000.0", "runup.speed_max_rpm"),
    ("runup.speed_min_rpm=10.0", "runup.speed_min_rpm"),
    ('runup.routes=["tf_omega","shaker"]', "runup.routes"),
    ('radiation.models=["erp","sonar"]', "radiation.models"),
    ("runup.torques_nm=[-5.0]", "runup.torques_nm"),
    ("runup.colour=1", "runup.colour"),
    ('runup.engagement="3-d"', "runup.engagement"),
    ('runup.engagement="envelope-bund"', "runup.engagement"),
    ('runup.mesh_moment="shutling"', "runup.mesh_moment"),
    ('runup.drive_line="quills"', "runup.drive_line"),
    ('runup.drive_line="back-to-front"', "runup.drive_line"),
    ("runup.as_made=13", "runup.as_made"),
    ('runup.as_made="5"', "runup.as_made"),
    ("runup.te_sensitivity=[1, 1]", "runup.te_sensitivity"),
    ("runup.te_sensitivity=[31]", "runup.te_sensitivity"),
    ("runup.te_sensitivity=[0]", "runup.te_sensitivity"),
    ('runup.transmission_error="no-such-te.csv"', "runup.transmission_error"),
])
def test_bad_values_name_the_key(override, key):
    with pytest.raises(InputError) as err:
        load_runup_scene("test-gearbox-runup", [override])
    assert f": {key}" in str(err.value)


@pytest.mark.parametrize("engagement, misalignment", [("face-width", "rigid-bores"), ("thesis-2d", "none"),
                                                       ("envelope-bound", "rigid-bores")])
def test_engagement_choices_and_their_default_misalignment(engagement, misalignment):
    """runup.engagement: the three shock models of housingfe.source.roosmalen.dynamics.ENGAGEMENT_MODELS; the
    envelope bound keeps the face-width model's load share and so its misalignment."""
    scene, _ = load_runup_scene("test-gearbox-runup", [f'runup.engagement="{engagement}"'])
    assert scene.runup.engagement == engagement and scene.runup.misalignment_model == misalignment


@pytest.mark.parametrize("overrides, moment", [([], "shuttling"), (['runup.engagement="thesis-2d"'], "none"),
                                               (['runup.mesh_moment="shuttling"'], "shuttling"),
                                               (['runup.engagement="thesis-2d"', 'runup.mesh_moment="none"'], "none")])
def test_mesh_moment_choices(overrides, moment):
    """runup.mesh_moment: the shuttling moment on (the default) or off; the thesis' replica keeps "none" unless asked."""
    scene, _ = load_runup_scene("test-gearbox-runup", overrides)
    assert scene.runup.mesh_moment_model == moment


@pytest.mark.parametrize("overrides, friction", [([], "none"), (["runup.mesh_friction=iso13989"], "iso13989"),
                                                 (["runup.mesh_friction=0.06"], 0.06),
                                                 (['runup.mesh_friction="none"'], "none")])
def test_mesh_friction_choices(overrides, friction):
    """runup.mesh_friction: off by default (the ISO/TR 13989-1 formula is unverified), the ISO coefficient per
    operating point, or a fixed mean coefficient."""
    scene, _ = load_runup_scene("test-gearbox-runup", overrides)
    assert scene.runup.mesh_friction == friction


@pytest.mark.parametrize("overrides, drive_line", [([], "quill-shafts"), (['runup.engagement="thesis-2d"'], "none"),
                                                   (['runup.drive_line="none"'], "none"),
                                                   (['runup.engagement="thesis-2d"', 'runup.drive_line="quill-shafts"'],
                                                    "quill-shafts"),
                                                   (['runup.drive_line="back-to-back"'], "back-to-back")])
def test_drive_line_choices(overrides, drive_line):
    """runup.drive_line: the quill shafts and couplings in the coupled model by default; the thesis' replica keeps
    the shafts ending at the plates unless asked; "back-to-back" closes the loop through the auxiliary gearbox.  The
    run's drivetrains carry the choice to their FE reduction."""
    from housingfe.runup.scene import drivetrain_of

    scene, _ = load_runup_scene("test-gearbox-runup", overrides)
    assert scene.runup.drive_line_model == drive_line
    spec = drivetrain_of(scene.drivetrain, 2000.0, scene.runup.drive_line_model).to_coupling_spec()
    assert len(spec.drive_lines) == (0 if drive_line == "none" else 2)
    assert (spec.aux_gearbox is not None) == (drive_line == "back-to-back")


@pytest.mark.parametrize("overrides, as_made", [([], "none"), (["runup.as_made=5"], 5), (["runup.as_made=none"], "none"),
                                                (["runup.as_made=0"], 0)])
def test_as_made_choices(overrides, as_made):
    """runup.as_made: off by default (the periodic lines of identical teeth), or an ISO 1328-1 grade 0..12."""
    scene, _ = load_runup_scene("test-gearbox-runup", overrides)
    assert scene.runup.as_made == as_made


def test_missing_drivetrain_is_named(tmp_path):
    text = (Path(__file__).parents[2] / "housingfe/scenes/test-gearbox-runup.toml").read_text()
    start = text.index("[drivetrain]")
    end = text.index("[runup]")
    path = tmp_path / "no-drivetrain.toml"
    path.write_text(text[:start] + text[end:])
    with pytest.raises(InputError, match=r"no-drivetrain.toml: drivetrain: missing \[drivetrain\]: the routes "
                                         r"tf_omega, mesh_force"):
        load_runup_scene(str(path))


@pytest.mark.parametrize("args, words", [
    (["--set", "drivetrain.gear_set=Z"], "drivetrain.gear_set: 'Z' is not a gear set"),
    (["--set", "runup.speed_max_rpm=2000.0"], "outside the range the source supports"),
    # single helical set A on cylindrical roller bearings: the axial tooth force has nothing to carry it
    (["--set", "drivetrain.bearings=cylindrical_roller"], "cannot carry it"),
    (["--set", "runup.engagement=envelope-bund"],
     "runup.engagement: Input should be 'face-width', 'thesis-2d' or 'envelope-bound'"),
    # the sliding friction's mean coefficient: 0 < mu < 0.3, or one of the words
    (["--set", "runup.mesh_friction=-0.1"], "runup.mesh_friction: a mean friction coefficient must lie between 0"),
    (["--set", "runup.mesh_friction=0.5"], "runup.mesh_friction: a mean friction coefficient must lie between 0"),
    (["--set", "runup.mesh_friction=foo"], "runup.mesh_friction: 'foo' is not one of none, iso13989"),
    (["--set", "runup.drive_line=quills"],
     "runup.drive_line: Input should be 'quill-shafts', 'none' or 'back-to-back'"),
    (["--set", "runup.as_made=grade5"], "runup.as_made: 'grade5' is neither \"none\" nor an ISO 1328-1 accuracy grade"),
    (["--set", "runup.bearing_speeds=sometimes"], "runup.bearing_speeds: Input should be 'fixed' or 'follow'"),
])
def test_cli_bad_input_one_line_exit_2_no_folder(tmp_path, args, words):
    out = tmp_path / "out"
    proc = subprocess.run(HOUSINGFE + ["run", "test-gearbox-runup", "--out", str(out), *args], capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 2, proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and words in lines[0] and "Traceback" not in proc.stderr, proc.stderr
    assert not out.exists() and not list(tmp_path.glob(".out*"))


def test_transmission_error_file_is_found_beside_the_scene_then_in_the_current_folder(tmp_path, monkeypatch):
    """runup.transmission_error: relative to the scene file, else to the current folder (a --set on a built-in
    scene); its torques must span runup.torques_nm; it replaces the engagement model, so both cannot be set."""
    text = (Path(__file__).parents[2] / "housingfe/scenes/test-gearbox-runup.toml").read_text()
    (tmp_path / "scene").mkdir()
    (tmp_path / "scene/te.csv").write_text("torque_Nm,harmonic,amplitude_um\n1000,1,1.0\n2500,1,2.0\n")
    (tmp_path / "scene/gearbox.toml").write_text(text)
    scene, _ = load_runup_scene(str(tmp_path / "scene/gearbox.toml"), ['runup.transmission_error="te.csv"'])
    assert scene.runup.transmission_error == str((tmp_path / "scene/te.csv").resolve())
    monkeypatch.chdir(tmp_path / "scene")
    scene, _ = load_runup_scene("test-gearbox-runup", ['runup.transmission_error="te.csv"'])
    assert scene.runup.transmission_error == str((tmp_path / "scene/te.csv").resolve())
    assert load_runup_scene("test-gearbox-runup")[0].runup.transmission_error == ""
    with pytest.raises(InputError, match=r"runup.transmission_error: .*te.csv: has no transmission error at 3000 N m "
                                         r"\(it gives 1000..2500 N m.*\(runup.torques_nm; set it within"):
        load_runup_scene("test-gearbox-runup", ['runup.transmission_error="te.csv"', "runup.torques_nm=[2000.0, 3000.0]"])
    with pytest.raises(InputError, match=r"runup.transmission_error: the file replaces the engagement model; "
                                         r"engagement = 'thesis-2d' is set as well"):
        load_runup_scene("test-gearbox-runup", ['runup.transmission_error="te.csv"', 'runup.engagement="thesis-2d"'])
    with pytest.raises(InputError, match=r"runup.transmission_error: .*missing.csv: cannot read the transmission "
                                         r"error file"):
        load_runup_scene("test-gearbox-runup", ['runup.transmission_error="missing.csv"'])


def test_cli_bad_transmission_error_file_one_line_exit_2_no_folder(tmp_path):
    (tmp_path / "te.csv").write_text("torque_Nm,harmonic,amplitude_um\n2000,1,-3\n")
    out = tmp_path / "out"
    proc = subprocess.run(HOUSINGFE + ["run", "test-gearbox-runup", "--out", str(out), "--set",
                                       "runup.transmission_error=te.csv"], capture_output=True, text=True,
                          timeout=300, cwd=tmp_path,      # the file is found in the current folder
                          env={**os.environ, "PYTHONPATH": str(Path(__file__).parents[2])})
    assert proc.returncode == 2, proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "runup.transmission_error:" in lines[0] and "te.csv: line 2: amplitude_um: -3 is " \
        "negative" in lines[0] and "Traceback" not in proc.stderr, proc.stderr
    assert not out.exists() and not list(tmp_path.glob(".out*"))
