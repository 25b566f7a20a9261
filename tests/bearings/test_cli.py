"""`housingfe bearing`: exit codes, JSON output equal to the API."""
import json

import numpy as np

from housingfe.bearings import bearing_stiffness
from housingfe.cli import main


def test_json_output_matches_api(capsys):
    assert main(["bearing", "SKF 6312", "--load", "0", "-10000", "4000", "0", "0", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    ref = bearing_stiffness("6312", [0, -10000, 4000, 0, 0])
    assert np.allclose(data["K"], ref.K, rtol=1e-12, atol=0)
    assert np.allclose(data["displacement"], ref.displacement, rtol=1e-12, atol=1e-30)
    assert len(data["element_loads"]) == 8 and sum(data["element_loads"]) > 10000


def test_text_output_and_bad_input(capsys):
    assert main(["bearing", "NJ316", "--load", "0", "-10000", "0", "0", "0"]) == 0
    out = capsys.readouterr().out
    assert "sliced-roller" in out and "estimated inputs" in out
    assert main(["bearing", "6999", "--load", "0", "-1", "0", "0", "0"]) == 2
    err = capsys.readouterr().err
    assert "6999" in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert main(["bearing", "7316B", "--load", "0", "-1000", "-4000", "0", "0"]) == 2


def test_preload_axial_adds_to_fz(capsys):
    assert main(["bearing", "6215", "--load", "0", "-5000", "0", "0", "0", "--preload-axial", "3000", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    ref = bearing_stiffness("6215", [0, -5000, 3000, 0, 0])
    assert np.allclose(data["K"], ref.K, rtol=1e-12, atol=0)
    assert data["load"][2] == 3000.0


# ---------------------------------------------------------------- internal geometry on the command line (issue 12)
GEOMETRY = ["--balls", "12", "--ball-diameter", "0.025", "--pitch-diameter", "0.125", "--conformity-inner", "0.52",
            "--conformity-outer", "0.53", "--contact-angle-deg", "40", "--radial-clearance", "0"]


def test_geometry_from_flags_and_from_toml_equal_the_api(capsys, tmp_path):
    import math

    from housingfe.bearings import RollingBearing

    load = ["0", "0", "8000", "0", "0"]
    assert main(["bearing", *GEOMETRY, "--load", *load, "--json"]) == 0
    flags = json.loads(capsys.readouterr().out)
    toml = tmp_path / "ac.toml"
    toml.write_text("[bearing]\ndesignation = 'AC 40 deg'\nelements = 12\nelement_diameter = 0.025\n"
                    "pitch_diameter = 0.125\nconformity_inner = 0.52\nconformity_outer = 0.53\n"
                    "contact_angle_deg = 40.0\nradial_clearance = 0.0\n")
    assert main(["bearing", "--geometry", str(toml), "--load", *load, "--json"]) == 0
    from_file = json.loads(capsys.readouterr().out)
    ref = bearing_stiffness(RollingBearing("api", "ball", n_elements=12, element_diameter=0.025,
                                           pitch_diameter=0.125, contact_angle=math.radians(40)),
                            [0, 0, 8000.0, 0, 0])
    for data in (flags, from_file):
        assert np.allclose(data["K"], ref.K, rtol=1e-12, atol=0)
        assert np.allclose(data["displacement"], ref.displacement, rtol=1e-12, atol=1e-30)
        assert data["secant_stiffness"][2] == 8000.0 / ref.displacement[2]
        assert "equilibrium" in data["displacement_is"] and "tangent" in data["K_is"]


def test_text_output_labels_deflection_tangent_and_secant(capsys):
    assert main(["bearing", *GEOMETRY, "--load", "0", "0", "8000", "0", "0"]) == 0
    out = capsys.readouterr().out
    assert "deflection under the load" in out and "equilibrium solve" in out
    assert "tangent stiffness K = dF/d(deflection)" in out and "secant stiffness F/deflection" in out


def test_flags_override_a_catalogue_entry(capsys):
    assert main(["bearing", "6312", "--radial-clearance", "0", "--load", "0", "-10000", "0", "0", "0", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    import dataclasses

    from housingfe.bearings import lookup
    ref = bearing_stiffness(dataclasses.replace(lookup("6312"), radial_clearance=0.0), [0, -10000, 0, 0, 0])
    assert np.allclose(data["K"], ref.K, rtol=1e-12, atol=0)
    assert "radial_clearance" not in data["estimated"]


def _one_line_exit_2(capsys, argv, match):
    assert main(argv) == 2
    captured = capsys.readouterr()
    err = captured.err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert match in err, err
    assert captured.out == ""


def test_bad_geometry_exit_2_one_line(capsys, tmp_path):
    load = ["--load", "0", "0", "8000", "0", "0"]
    bad = {"--ball-diameter": ("-0.025", "element_diameter"), "--conformity-inner": ("0.5", "conformity_inner"),
           "--conformity-outer": ("0.45", "conformity_outer"), "--contact-angle-deg": ("90", "contact_angle_deg")}
    for flag, (value, key) in bad.items():
        argv = list(GEOMETRY)
        argv[argv.index(flag) + 1] = value
        _one_line_exit_2(capsys, ["bearing", *argv, *load], key)
    _one_line_exit_2(capsys, ["bearing", "--balls", "12", "--pitch-diameter", "0.125", *load], "element_diameter")
    _one_line_exit_2(capsys, ["bearing", *load], "designation")
    toml = tmp_path / "bad.toml"
    toml.write_text("[bearing]\nelements = 12\nelement_diameter = 0.025\npitch_diameter = 0.125\nballs = 3\n")
    _one_line_exit_2(capsys, ["bearing", "--geometry", str(toml), *load], "balls: unknown key")
    toml.write_text("[bearing\n")
    _one_line_exit_2(capsys, ["bearing", "--geometry", str(toml), *load], "malformed TOML")
    _one_line_exit_2(capsys, ["bearing", "--geometry", str(tmp_path / "none.toml"), *load], "no such file")
    _one_line_exit_2(capsys, ["bearing", "6312", "--geometry", str(toml), *load], "not both")
    # an angular contact bearing loaded axially the wrong way cannot carry it
    _one_line_exit_2(capsys, ["bearing", *GEOMETRY, "--load", "0", "-1000", "-8000", "0", "0"], "cannot carry")


def test_negative_loads_in_scientific_notation_are_numbers(tmp_path):
    """`--load 0 -1e4 0 0 0` (the sweep of the sub-commands): Python 3.11's argparse took -1e4 for an option and
    stopped with 'expected 5 arguments'; it is the same load as -10000 (console script, as a user types it)."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    env = dict(os.environ, OPENBLAS_NUM_THREADS="1",
               PYTHONPATH=os.pathsep.join([str(Path(__file__).parents[2]), os.environ.get("PYTHONPATH", "")]))
    proc = subprocess.run([str(Path(sys.executable).with_name("housingfe")), "bearing", "6312", "--load", "0", "-1e4",
                           "-2.5e3", "0", "0", "--preload-axial", "-1E2", "--json"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=120, env=env, check=False)
    assert proc.returncode == 0, proc.stderr
    data = json.loads(proc.stdout)
    assert data["load"][:3] == [0.0, -10000.0, -2600.0]
    ref = bearing_stiffness("6312", [0, -10000, -2600, 0, 0])
    assert np.allclose(data["K"], ref.K, rtol=1e-12, atol=0)
