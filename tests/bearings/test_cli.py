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
