"""The run-up on an imported housing (issue 29 item 4): the built-in test gearbox housing written to STEP, read
back as a `cad` housing scene (bore selectors per bearing seat, feet by boxes), its bearings matched by position,
gives the built-in housing's run-up to the difference between two meshes of one size.

Tolerance, measured (60 mm P2 tetrahedra, lines to 1.5 kHz, modal basis to 2.25 kHz, 500/800/1100 rev/min, set A,
2000 N m, sigma = 1): the STEP mesh is not node for node the built-in's (docs/cad.md, Round trips), so the two
differ as two meshes of one size do.  Imported vs built-in: coupled modes to 2.25 kHz within 0.64 %, max L_WA
within 0.08 dB (tf_omega) and 0.12 dB (mesh_force), every speed within 0.12 dB.  Two built-in meshes (58 and
60 mm): modes within 1.55 %, L_WA within 0.11 dB.  Asserted: modes within 1.5 %, L_WA within 0.5 dB at every
speed."""
from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from tests.runup.imported_gearbox import write_imported_gearbox

pytestmark = pytest.mark.slow

SETTINGS = ['housing.set=["mesh.size=0.06"]', "runup.speed_min_rpm=500.0", "runup.speed_max_rpm=1100.0",
            "runup.speed_step_rpm=300.0", "runup.f_max_hz=1500.0", 'radiation.models=["erp"]',
            "runup.spectrum_speeds_rpm=[500.0]"]


def _result(folder):
    facts = json.loads((folder / "runup.json").read_text())["modal_basis"]
    with open(folder / "runup.csv") as fh:
        lwa = {(r["route"], float(r["speed_rpm"])): float(r["LwA_dB"]) for r in csv.DictReader(fh)}
    return facts, lwa


def test_the_run_up_on_the_step_round_trip_equals_the_built_in_one(tmp_path, scene_run):
    from housingfe.runup.scene import run_scene

    scene = write_imported_gearbox(tmp_path / "step")
    imported, lwa_imported = _result(run_scene(str(scene), str(tmp_path / "imported")))
    built_in, lwa_built_in = _result(scene_run("test-gearbox-runup", SETTINGS))     # test_as_made's "off" run too

    assert [b["surface"] for b in imported["bores"]] == ["bore_A_front", "bore_A_back", "bore_B_front", "bore_B_back"]
    assert [b["surface"] for b in built_in["bores"]] == ["bore_pinion_front", "bore_pinion_back",
                                                         "bore_wheel_front", "bore_wheel_back"]
    for a, b in zip(imported["bores"], built_in["bores"]):
        assert np.allclose(a["centre_m"], b["centre_m"], atol=2e-4) and a["radius_m"] == pytest.approx(0.085, abs=2e-4)

    f_imp = np.array(imported["elastic_frequencies_hz"])
    f_bi = np.array(built_in["elastic_frequencies_hz"])
    assert len(f_imp) == len(f_bi) >= 12
    assert np.max(np.abs(f_imp / f_bi - 1)) < 0.015, (f_imp, f_bi)
    assert lwa_imported.keys() == lwa_built_in.keys() and len(lwa_imported) == 6
    diff = {k: lwa_imported[k] - lwa_built_in[k] for k in lwa_imported}
    assert max(abs(d) for d in diff.values()) < 0.5, diff
