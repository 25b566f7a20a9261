"""The double helical set against single helical (housingfe.studies.helical_vs_single): the thesis' measure on
synthetic run-up tables whose differences are worked out by hand here, and the measured numbers as published."""
import csv

import numpy as np
import pytest

from housingfe.errors import InputError
from housingfe.studies import helical_vs_single as hvs

SPEEDS = np.arange(50.0, 1501.0, 50.0)          # the study's grid: 15 speeds in 800-1500 rev/min


def _levels(base, at=None):
    out = np.full(SPEEDS.size, float(base))
    for speed, level in (at or {}).items():
        out[SPEEDS == speed] = level
    return out


def test_difference_is_the_mean_of_db_differences_at_the_common_speeds():
    # double helical 80 dB(A) everywhere but 90 at 1500 rpm; the reference 85 with a 95 peak at 600 rpm and an
    # extra speed (1550 rpm, 120 dB(A)) the double helical run does not have: it takes part in nothing
    mine = _levels(80.0, {1500.0: 90.0})
    ref_s = np.append(SPEEDS, 1550.0)
    ref = np.append(_levels(85.0, {600.0: 95.0}), 120.0)
    d = hvs.difference(SPEEDS, mine, ref_s, ref)
    # 800-1500: 14 differences of -5 and one of +5 -> mean -65/15; population s.d. sqrt((14 (2/3)^2 + (28/3)^2)/15)
    assert d["n"] == 15
    assert d["mean_dB"] == pytest.approx(-65.0 / 15.0, abs=1e-12)
    assert d["sd_dB"] == pytest.approx(np.sqrt((14 * 4 / 9 + 784 / 9) / 15), abs=1e-12)
    # maxima over the common speeds: 90 at 1500 against 95 at 600 -> 5 dB(A) quieter
    assert (d["max_dB"], d["at_rpm"], d["ref_max_dB"], d["ref_at_rpm"]) == (90.0, 1500.0, 95.0, 600.0)
    assert d["reduction_dB"] == pytest.approx(5.0)
    with pytest.raises(InputError, match="800-1500"):
        hvs.difference([100.0, 200.0], [1.0, 2.0], [100.0, 200.0], [1.0, 1.0])


def test_the_measured_numbers_are_the_thesis():
    m = hvs.measured()
    assert m[("roller", "A")] == (-5.3, 9.5) and m[("fluid_film", "A")] == (-7.2, 12.8)
    # against self-aligning B the thesis gives the means, and the maxima 92.3 -> 91.0 / 87.7 dB(A)
    assert m[("roller", "B_self_aligning")] == (-0.2, pytest.approx(92.3 - 91.0))
    assert m[("fluid_film", "B_self_aligning")] == (-2.1, pytest.approx(92.3 - 87.7))
    # the stated reductions against A are those of the stated maxima 100.5 -> 91.0 / 87.7
    assert m[("roller", "A")][1] == pytest.approx(100.5 - 91.0) and m[("fluid_film", "A")][1] == pytest.approx(
        100.5 - 87.7)


def write_table(path, columns):
    path.parent.mkdir(parents=True, exist_ok=True)
    names = ["speed_rpm", *columns]
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(names)
        for i, s in enumerate(SPEEDS):
            w.writerow([s, *(columns[c][i] for c in columns)])


def write_study(folder, skip=()):
    """The three default-engagement run-up tables as `housingfe study` writes them (validate's job folders), with
    known levels: rollers 80 (mesh_force 70), fluid films 78 (68); set A 85 (75); self-aligning B 81 (71), each
    with +10 dB(A) at one speed; the as-made columns 200 (must be ignored)."""
    tables = {
        "double-helical": {"LwA_tf_omega_cylindrical_roller@2000_dBA": _levels(80.0, {1000.0: 90.0}),
                           "LwA_tf_omega_fluid_film@2000_dBA": _levels(78.0, {1000.0: 88.0}),
                           "LwA_mesh_force_cylindrical_roller@2000_dBA": _levels(70.0, {1000.0: 80.0}),
                           "LwA_mesh_force_fluid_film@2000_dBA": _levels(68.0, {1000.0: 78.0}),
                           "LwA_tf_omega_cylindrical_roller@1000_dBA": _levels(0.0),
                           "LwA_as_made_tf_omega_cylindrical_roller@2000_dBA": _levels(200.0)},
        "profile-corrections": {"LwA_tf_omega_A_dBA": _levels(85.0, {500.0: 95.0}),
                                "LwA_tf_omega_B_dBA": _levels(0.0),
                                "LwA_mesh_force_A_dBA": _levels(75.0, {500.0: 85.0})},
        "bearings": {"LwA_tf_omega_self_aligning_dBA": _levels(81.0, {1200.0: 91.0}),
                     "LwA_tf_omega_ball_dBA": _levels(0.0),
                     "LwA_mesh_force_self_aligning_dBA": _levels(71.0, {1200.0: 81.0}),
                     "LwA_as_made_mesh_force_self_aligning_dBA": _levels(200.0)}}
    for family, columns in tables.items():
        if family not in skip:
            write_table(folder / f"{family}-face-width" / f"{family}_runup.csv", columns)


def test_compare_reads_the_families_tables(tmp_path):
    write_study(tmp_path)
    folders = {f: tmp_path / f"{f}-face-width" for f in ("double-helical", "profile-corrections", "bearings")}
    rows = {(r["double_helical"], r["single_helical"], r["route"]): r for r in hvs.compare(hvs.tables_of(folders))}
    assert len(rows) == 8
    # rollers - A on tf_omega: 80 - 85 = -5 dB at every speed in 800-1500 but 1000 rpm (90 - 85 = +5): mean
    # (14 * -5 + 5) / 15; the maxima 90 (1000 rpm) and 95 (500 rpm)
    r = rows[("roller", "A", "tf_omega")]
    assert r["mean_diff_dB"] == round(-65.0 / 15.0, 2) and r["speeds_in_mean"] == 15
    assert r["max_reduction_dBA"] == 95.0 - 90.0 and r["at_rpm_single"] == 500.0 and r["at_rpm_double"] == 1000.0
    assert (r["measured_mean_dB"], r["measured_max_reduction_dBA"]) == (-5.3, 9.5)
    # fluid films - self-aligning B on mesh_force: 68 - 71 = -3 except 1000 (+7) and 1200 (-13): mean (13 * -3 + 7
    # - 13) / 15; population s.d. by hand
    r = rows[("fluid_film", "B_self_aligning", "mesh_force")]
    d = np.array([-3.0] * 13 + [7.0, -13.0])
    assert r["mean_diff_dB"] == round(-45.0 / 15.0, 2) == -3.0
    assert r["sd_diff_dB"] == round(float(np.sqrt(np.mean((d + 3.0) ** 2))), 2)
    assert r["max_reduction_dBA"] == 81.0 - 78.0 and r["measured_mean_dB"] == -2.1
    # one family missing: its rows alone are left out; the double helical table missing: an error naming it
    write_study(tmp_path / "no_bearings", skip=("bearings",))
    sub = {f: d for f, d in ((f, tmp_path / "no_bearings" / f"{f}-face-width") for f in folders)
           if f != "bearings"}
    assert {k[1] for k in (tuple(r[c] for c in ("double_helical", "single_helical", "route"))
                           for r in hvs.compare(hvs.tables_of(sub)))} == {"A"}
    with pytest.raises(InputError, match="no run-up table of the double-helical family"):
        hvs.compare({})


def test_a_missing_run_is_named(tmp_path):
    write_study(tmp_path, skip=("bearings",))
    folders = {f: tmp_path / f"{f}-face-width" for f in ("double-helical", "profile-corrections", "bearings")}
    with pytest.raises(InputError, match=r"bearings-face-width/bearings_runup\.csv: cannot read"):
        hvs.tables_of(folders)
    table = hvs.read_runup_table(tmp_path / "profile-corrections-face-width" / "profile-corrections_runup.csv")
    with pytest.raises(InputError, match=r"pc\.csv: no column LwA_<route>_fluid_film@2000_dBA"):
        hvs.curves(table, "fluid_film@2000", "pc.csv")


def test_families_run_together_are_compared_with_the_same_shock(tmp_path):
    write_study(tmp_path)
    written = [("double-helical", "face-width", tmp_path / "double-helical-face-width"),
               ("profile-corrections", "thesis-2d", tmp_path / "nowhere"),          # another shock: not compared
               ("profile-corrections", "face-width", tmp_path / "profile-corrections-face-width")]
    rows = hvs.from_studies(written)
    assert {(r["single_helical"], r["route"]) for r in rows} == {("A", "tf_omega"), ("A", "mesh_force")}
    assert rows[0]["mean_diff_dB"] == round(-65.0 / 15.0, 2)
    assert hvs.from_studies(written[1:]) == [] and hvs.from_studies(written[:1]) == []
    hvs.write(tmp_path, rows)
    with open(tmp_path / "double-helical_vs_single.csv") as fh:
        assert [r["single_helical"] for r in csv.DictReader(fh)] == ["A"] * 4
    assert "| roller | A | tf_omega | -4.3 (2.5) | -5.3 | +5.0 (90.0 / 95.0) | +9.5 |" in \
        (tmp_path / "double-helical_vs_single.md").read_text()


def test_speed_law_fits_over_the_set_a_range():
    # 70 + 6 log2(s/250) with +3 dB at 500 rpm and -1.5 dB at 250 and 1000 rpm (mean zero, orthogonal to log2 s):
    # slope 6 exactly, residual population s.d. sqrt((9 + 2 * 2.25) / 26) over the 26 speeds of 250-1500 rpm
    levels = 70.0 + 6.0 * np.log2(SPEEDS / 250.0)
    levels[SPEEDS == 500.0] += 3.0
    levels[(SPEEDS == 250.0) | (SPEEDS == 1000.0)] -= 1.5
    levels[SPEEDS < 250.0] = -50.0                   # outside the range: takes part in nothing
    law = hvs.speed_law(SPEEDS, levels)
    assert law["slope_dB"] == pytest.approx(6.0, abs=1e-9)
    assert law["residual_sd_dB"] == pytest.approx(np.sqrt(13.5 / 26), abs=1e-9)
    assert (law["n"], law["from_rpm"], law["to_rpm"]) == (26, 250.0, 1500.0)
    with pytest.raises(InputError, match="doubling"):
        hvs.speed_law([800.0, 1000.0, 1200.0], [1.0, 2.0, 3.0])
