"""The thesis' turned-pinion measurement (Sec. 5.6, Fig. 5.12) as reported rows of `housingfe validate`
(housingfe.verification.turned_pinion_rows): 28.as_made.reindex.<pitch>, beside the checks, never judged, no band,
counted apart; the published numbers from housingfe/data/roosmalen1994.toml."""
import csv

import pytest

from housingfe.verification import checks as ck
from housingfe.verification import turned_pinion_rows, validate
from housingfe.verification.published import thesis


def test_consistent_holds_the_repeatability_in_the_measured_spread():
    """sqrt(s.d.^2 + 0.5^2) <= 0.8 (s.d. <= 0.6245) and |mean| <= 0.3 + 0.3."""
    measured, repeatability = (0.3, 0.8), (0.3, 0.5)
    ok = turned_pinion_rows.consistent([0.0, 0.0, 0.59, -0.61, 0.0], [0.62, 0.63, 0.1, 0.1, 0.0], measured,
                                       repeatability)
    assert ok.tolist() == [True, False, True, False, True]


def test_the_published_numbers_are_the_thesis():
    ref = thesis()["test_gearbox"]
    assert ref["turned_pinion_teeth"] == [8, 16]
    assert (ref["turned_pinion_mean_dB"], ref["turned_pinion_sd_dB"]) == (0.3, 0.8)       # seed 004, line 2032
    assert (ref["repeatability_mean_dB"], ref["repeatability_sd_dB"]) == (0.3, 0.5)       # Fig. 5.11


@pytest.fixture(scope="module")
def rows():
    return turned_pinion_rows.published_rows(draws=5)


def test_rows_are_reported_per_pitch_model_and_runout_moves_less(rows):
    assert [r["check_id"] for r in rows] == ["28.as_made.reindex.independent", "28.as_made.reindex.runout",
                                             "28.as_made.reindex.none"]
    for r in rows:
        assert ck.is_as_made(r) and ck.is_reported_beside(r) and not ck.is_as_made_check(r)
        assert r["passed"] == "" and r["tolerance"] == "" and r["band"] is None
        assert r["measured"] == 0.8 and r["published"] == 0.8 and r["unit"] == "dB"
        assert r["why"].startswith(ck.AS_MADE_REINDEX_WHY) and "of 5 draws consistent" in r["why"]
        assert "rigid-bore receptance" in r["why"] and "A-weighted" in r["why"] and "seed 56" in r["why"]
        assert r["note"].startswith("reported, not judged")
        assert 0 < r["ours"] < 3
        ck._check_id_of_band("x", "k", r["check_id"])             # a valid check id (raises otherwise)
    by = {r["check_id"].rsplit(".", 1)[1]: r["ours"] for r in rows}
    assert by["runout"] < by["independent"]
    assert ck.attach_bands(rows, {r["check_id"]: (0.0, 1.0) for r in rows}) == 0   # no band on a reported row


def test_the_checks_and_their_count_do_not_change(rows, tmp_path):
    checks = [ck.check_row(f"28.default.max_lwa.{route}", "s", "q", 90.0, "dB(A)", "src", measured=100.5,
                           tolerance="3 dB", passed=route == "tf_omega") for route in ("tf_omega", "mesh_force")]
    made = [ck.as_made_row("28.as_made.default.max_lwa.tf_omega", "s", "q", 80.0, "dB(A)", "src")]
    before = ck.checks_markdown(checks + made).splitlines()[-1]
    after = ck.checks_markdown(checks + made + rows).splitlines()[-1]
    assert before.startswith("2 checks: 1 passed, 1 failed, 0 reported") and after.startswith(before.split(";")[0])
    assert "and 1 rows of gears as made (28.as_made.*, ISO grade 5 sidebands), reported" in before
    assert ("and 4 rows of gears as made (28.as_made.*, ISO grade 5 sidebands: 1 of the default run-up, 3 of the "
            "pinion turned against the wheel 28.as_made.reindex.* (Sec. 5.6)), reported: not checks") in after
    ck.write_checks(checks + made + rows, tmp_path)
    with open(tmp_path / "checks.csv", newline="") as fh:
        written = list(csv.DictReader(fh))
    assert [r["check_id"] for r in written][:2] == ["28.default.max_lwa.tf_omega", "28.default.max_lwa.mesh_force"]
    assert [r["passed"] for r in written] == ["yes", "no", "report", "report", "report", "report"]
    assert all(r["band"] == "" for r in written[2:])


def test_validate_collects_them_in_the_full_run_and_with_only(rows, tmp_path, monkeypatch):
    """A provider of the full validate (found by its name) and a part of `--only runup-checks` (only_rows, here with
    the other computations stubbed out), after the other rows; a failure there costs these rows alone."""
    from housingfe.errors import SolverError
    from housingfe.verification import runup_checks_rows, source_rows, study_rows

    assert "housingfe.verification.turned_pinion_rows" in validate.ROW_PROVIDERS
    default = ck.check_row("28.default.max_lwa.tf_omega", "s", "q", 90.0, "dB(A)", "src", passed=False)
    monkeypatch.setattr(validate, "runup_rows", lambda *a, **k: [default])
    monkeypatch.setattr(runup_checks_rows, "published_rows", lambda *a, **k: [])
    monkeypatch.setattr(source_rows, "excitation_rows", lambda: [])
    monkeypatch.setattr(study_rows, "published_rows", lambda *a, **k: [])
    monkeypatch.setattr(turned_pinion_rows, "published_rows", lambda: rows)
    failures = []
    assert runup_checks_rows.only_rows(tmp_path, failures=failures) == [default] + rows and failures == []

    def boom():
        raise SolverError("no set A")
    monkeypatch.setattr(turned_pinion_rows, "published_rows", boom)
    assert runup_checks_rows.only_rows(tmp_path, failures=failures) == [default]
    assert failures == ["turned pinion (28.as_made.reindex.*): no set A"]
