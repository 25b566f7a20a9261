"""`housingfe radiation foller` end to end."""
import csv
import json

import pytest

from housingfe import cli


def test_foller_builtin_writes_appendix_e_numbers(tmp_path, capsys):
    out = tmp_path / "tg"
    assert cli.main(["radiation", "foller", "builtin:test-gearbox", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert round(summary["point_P_dB"], 1) == 1.8
    assert round(summary["L_125"], 1) == -11.7
    with open(out / "foller.csv") as fh:
        rows = list(csv.DictReader(fh))
    by_band = {float(r["band_nominal_hz"]): float(r["L_sigma_db"]) for r in rows}
    # the CSV is at exact IEC 61260 centres: 125.89 Hz lies 25 lg(125.89/125) = 0.08 dB above App. E's -11.7
    assert by_band[125.0] == pytest.approx(-11.69 + 0.077, abs=0.02)
    assert by_band[1000.0] == 0.0                       # above the 0 dB crossing (366 Hz)
    assert (out / "foller.png").stat().st_size > 1000
    assert "printed (App. E)" in capsys.readouterr().out


def test_foller_bad_table_exits_2_without_traceback(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("plates = [[\"top\", 1, 0.05, 0.9, 0.01]]\n")
    assert cli.main(["radiation", "foller", str(bad), "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert "plates[0]" in err and "Traceback" not in err
