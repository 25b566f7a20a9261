"""`housingfe validate`: band counting against the thesis' own statements, reuse of up-to-date results,
the row files."""
import json
import os
import time

import numpy as np
import pytest

from housingfe import validate
from housingfe.published import thesis


def test_band_rows_reproduce_the_thesis_statement_from_its_own_frequencies():
    """Sec. 4.5: first modes 387, 703, 1119 Hz; 'the bands of 400, 630, 1000 and 1250 Hz are occupied by
    only one eigenfrequency, 500 and 800 Hz have none'.  The fourth mode is not printed: any value in the
    1250 Hz band (1122-1413 Hz) makes the statement true, one in 1413+ Hz false for that band."""
    freqs = np.array(thesis()["gearbox_model_empty"]["fem_first_three_elastic_Hz"] + [1300.0, 1500.0])
    rows = validate.gearbox_model_rows("gearbox-model", freqs)
    bands = {r["quantity"]: (r["ours"], r["published"]) for r in rows if "band" in r["quantity"]}
    assert len(bands) == 6
    for quantity, (ours, published) in bands.items():
        assert ours == published, quantity
    modes = [r for r in rows if r["quantity"].startswith("elastic mode")]
    assert [r["difference"] for r in modes] == [0.0, 0.0, 0.0]

    rows = validate.gearbox_model_rows("gearbox-model", np.array([387.0, 703.0, 1119.0, 1500.0]))
    band_1250 = next(r for r in rows if "1250 Hz" in r["quantity"])
    assert (band_1250["ours"], band_1250["published"]) == (0, 1)


def test_close_pair_row():
    rows = validate.close_pair_rows("box-supported", np.array([900.0, 1167.0, 1176.0, 2000.0]))
    assert rows[0]["ours"] == pytest.approx(9 / 1167)
    assert rows[0]["difference"] == pytest.approx(0.0, abs=1e-15)


def test_joint_rows_pair_modes_by_order():
    modal = {"box-halves": {"frequencies_hz": [1000.0, 2000.0]},
             "box-halves-gasket": {"frequencies_hz": [970.0, 2000.0, 2100.0]}}
    rows = {r["quantity"]: r for r in validate.joint_rows(modal)}
    assert rows["gasket: max relative eigenfrequency change"]["ours"] == pytest.approx(0.03)
    assert rows["gasket: mean relative eigenfrequency change"]["ours"] == pytest.approx(0.015)


def test_results_reused_only_when_newer_than_scene_and_sources(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text("")
    folder = tmp_path / "res"
    assert not validate.is_up_to_date(folder, scene)
    folder.mkdir()
    (folder / "modes.json").write_text("{}")
    future = time.time() + 3600
    os.utime(folder / "modes.json", (future, future))
    assert validate.is_up_to_date(folder, scene)
    os.utime(scene, (future + 10, future + 10))
    assert not validate.is_up_to_date(folder, scene)


def test_main_writes_csv_markdown_and_json(tmp_path, monkeypatch):
    """A stored result (made here, dated in the future so that it counts as up to date) is reused: no FE
    run; the rows of the scene, its Appendix E plates and the files come out."""
    monkeypatch.setattr(validate, "RESULTS", tmp_path / "results")
    folder = tmp_path / "results" / "gearbox-model"
    folder.mkdir(parents=True)
    summary = {"scene": "gearbox-model", "frequencies_hz": [400.0, 700.0, 1100.0, 1300.0],
               "published": [{"scene": "gearbox-model", "quantity": "elastic modes below 4000 Hz (thesis FEM)",
                              "ours": 4, "published": 42, "unit": "-", "source": "x", "difference": -38}]}
    (folder / "modes.json").write_text(json.dumps(summary))
    future = time.time() + 3600
    os.utime(folder / "modes.json", (future, future))
    out = tmp_path / "validate"
    rows = validate.main(out_dir=out, json_path=tmp_path / "rows.json", scenes=["gearbox-model"])
    stored = json.loads((tmp_path / "rows.json").read_text())
    assert len(stored) == len(rows)
    assert all(set(r) == {"scene", "quantity", "ours", "published", "unit", "source"} for r in stored)
    quantities = {r["quantity"] for r in stored}
    assert "elastic modes below 4000 Hz (thesis FEM)" in quantities
    assert "plate 'top' area" in quantities and "elastic mode 1 (thesis FEM)" in quantities
    top = next(r for r in stored if r["quantity"] == "plate 'top' area")
    assert top["published"] == 0.0544
    assert (out / "validate.csv").read_text().count("\n") == len(rows) + 1
    assert (out / "validate.md").read_text().startswith("| scene |")
