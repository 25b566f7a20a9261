"""Source studies: the envelope check of a harmonic spectrum against analytic spectra, and
`housingfe source-spectrum` as a user runs it (subprocess, real files, one-line errors)."""
import csv
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from housingfe.source.roosmalen.studies import envelope_decay

HOUSINGFE = [sys.executable, "-m", "housingfe"]
ENV = {**os.environ, "PYTHONPATH": str(Path(__file__).parents[3]), "OPENBLAS_NUM_THREADS": "1"}


def test_envelope_of_a_step_spectrum_decays_6_dB_per_octave():
    """A single step has |F_n| = J / (pi n): the envelope drops 20 lg 2 = 6.02 dB every octave and n E(n) = F_1."""
    n = np.arange(1, 16)
    check = envelope_decay(1.0 / n)
    assert check["min_octave_drop_dB"] == pytest.approx(20 * math.log10(2), abs=1e-9)
    assert check["max_n_envelope_ratio"] == pytest.approx(1.0, abs=1e-12)
    assert check["passed"]
    # 1/n^2 (a kink, e.g. long correct relief) passes with 12 dB
    assert envelope_decay(1.0 / n**2)["min_octave_drop_dB"] == pytest.approx(20 * math.log10(4), abs=1e-9)


def test_a_plateau_fails_the_envelope_check():
    """The thesis-2d shape of set A: 1/n to n = 5, then flat (~0.5 kN from n = 6 to 12)."""
    n = np.arange(1, 16)
    spectrum = np.where(n <= 5, 7.8 / n, 0.5)
    check = envelope_decay(spectrum)
    assert check["min_octave_drop_dB"] == pytest.approx(0.0, abs=1e-12) and not check["passed"]
    assert check["worst_octave"][0] >= 5
    # and a spectrum that exceeds the 1/n line from the tooth line fails even without a plateau
    assert not envelope_decay(np.where(n == 2, 1.0, 1.0 / n**2))["passed"]


def test_source_spectrum_command_writes_table_and_plot(tmp_path):
    out = tmp_path / "spec"
    scene = Path(__file__).parents[3] / "housingfe/scenes/gearset-A.toml"
    text = scene.read_text().replace("stiffness_positions = 32", "stiffness_positions = 8").replace(
        "slices = 24", "slices = 6")
    path = tmp_path / "small-A.toml"
    path.write_text(text.replace('name = "gearset-A"', 'name = "small-A"'))
    proc = subprocess.run(HOUSINGFE + ["source-spectrum", str(path), "--harmonics", "6", "--out", str(out)],
                          capture_output=True, text=True, timeout=300, env=ENV)
    assert proc.returncode == 0, proc.stderr
    rows = list(csv.DictReader((out / "excitation_spectrum.csv").open()))
    assert {r["engagement"] for r in rows} == {"thesis-2d", "face-width"}
    assert [int(r["n"]) for r in rows if r["engagement"] == "face-width"] == list(range(1, 7))
    shock = {r["engagement"]: float(r["shock_N"]) for r in rows if r["n"] == "1"}
    # set A (eps_beta = 1.03): spread over the face width the tooth-frequency shock falls by more than 20 dB
    assert shock["face-width"] < 0.1 * shock["thesis-2d"]
    md = (out / "excitation_spectrum.md").read_text()
    assert "| n | small-A 2-D | small-A fw |" in md and "envelope check" in md
    assert (out / "excitation_spectrum.png").stat().st_size > 5000
    assert "excitation_spectrum" not in proc.stderr


@pytest.mark.parametrize("args, words", [
    (["no-such-gearset"], "no-such-gearset"),
    (["box-free"], "scene.kind"),
    (["gearset-A", "--harmonics", "1"], "--harmonics"),
    (["gearset-A", "--torque", "-5"], "--torque"),
])
def test_source_spectrum_bad_input_one_line_exit_2_no_folder(tmp_path, args, words):
    out = tmp_path / "spec"
    proc = subprocess.run(HOUSINGFE + ["source-spectrum", *args, "--out", str(out)], capture_output=True, text=True,
                          timeout=120, env=ENV)
    assert proc.returncode == 2, proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and words in lines[0] and "Traceback" not in proc.stderr, proc.stderr
    assert not out.exists()
