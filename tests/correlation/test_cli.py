"""`housingfe update` / `housingfe correlate` bad input: one line naming the file and key, exit 2 (no FE)."""
import pytest

from housingfe.cli import main

SPEC = """
name = "t"
[[parameters]]
name = "h"
keys = ["geometry.height"]
lower = 0.1
upper = 0.3
start = 0.2
[[targets]]
name = "m"
scene = "box-free"
kind = "mass"
value = 24.5
"""


@pytest.mark.parametrize("edit,message", [
    (lambda s: s.replace('keys = ["geometry.height"]', 'keys = ["geometry.heigth"]'),
     "geometry.heigth: unknown parameter key"),
    (lambda s: s.replace("start = 0.2", "start = 0.5"), "parameters.0.start: must lie within [lower, upper]"),
    (lambda s: s.replace('kind = "mass"', 'kind = "count"'), "targets.0.band_hz: required for a count target"),
    (lambda s: s + "colour = 1\n", "colour: unknown key"),
    (lambda s: s.replace('kind = "mass"', 'kind = "count"\nband_hz = 4000.0').replace("value = 24.5", "value = 0"),
     "targets.0.value: a mode count is a whole number >= 1"),
    (lambda s: s.replace('scene = "box-free"', 'scene = "no-such-scene"'), "no-such-scene: no such scene"),
])
def test_update_bad_spec_is_one_line(tmp_path, capsys, edit, message):
    path = tmp_path / "spec.toml"
    path.write_text(edit(SPEC))
    assert main(["update", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and message in err, err
    assert not (tmp_path / "out").exists()


def test_correlate_needs_one_of_measured_or_export(capsys):
    assert main(["correlate", "box-free"]) == 2
    assert "exactly one of --measured" in capsys.readouterr().err


def test_correlate_unreadable_measured_file(tmp_path, capsys):
    bad = tmp_path / "ema.uff"
    bad.write_text("not a universal file\n")
    assert main(["correlate", "box-free", "--measured", str(bad), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(bad) in err
