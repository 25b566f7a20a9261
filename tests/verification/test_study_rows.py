"""Validate rows of the design-variant studies (housingfe.verification.study_rows): pass/fail against the issue's
goals on a study result worked by hand, and `--quick` computes nothing (no cached result: no rows, one note)."""
from housingfe.verification import study_rows, validate


def _study(family, engagement, rows, rankings=(), torque_law=()):
    return {"family": family, "engagement": engagement, "source": "van Roosmalen 1994, Sec. 5.7", "reference": "A",
            "rows": rows, "rankings": list(rankings), "torque_law": list(torque_law)}


def _row(variant, mean, measured, calc=None, route="tf_omega"):
    return {"route": route, "variant": variant, "mean_diff_dB": mean, "sd_diff_dB": 1.0, "measured_mean_dB": measured,
            "measured_sd_dB": 3.1, "thesis_calc_mean_dB": calc, "thesis_calc_sd_dB": 0.2, "LwA_max_dBA": 90.0,
            "at_rpm": 1000.0, "measured_max_dBA": 99.2, "thesis_calc_max_dBA": None}


def test_goals_are_judged_as_the_issue_states_them():
    rows = study_rows.study_rows(_study("profile-corrections", "face-width",
                                        [_row("D", 2.6, -0.3, -5.1), _row("C", 3.5, 0.4, 2.9)]))
    mean = {r["quantity"].split(":")[1].strip()[0]: r for r in rows if "mean L_WA difference" in r["quantity"]}
    assert mean["D"]["ours"] == 2.6 and mean["D"]["published"] == -0.3
    assert mean["D"]["note"].endswith("passed: yes")            # 2.9 dB from the measured mean: within 3 dB
    assert mean["C"]["note"].endswith("passed: no")             # 3.1 dB
    d = next(r for r in rows if "correction D" in r["quantity"])
    assert (d["ours"], d["published"]) == (2.9, 4.8) and d["note"].endswith("passed: yes")   # better than -5.1
    replica = study_rows.study_rows(_study("profile-corrections", "thesis-2d",
                                           [_row("D", -3.7, -0.3, -5.1), _row("B", 1.2, -0.9, -0.4)]))
    assert [(r["published"], r["note"].endswith("passed: yes")) for r in replica] == [(-5.1, True), (-0.4, False)]


def test_quick_computes_nothing(tmp_path, monkeypatch, capsys):
    def no(*a, **k):
        raise AssertionError("computed in --quick")

    monkeypatch.setattr(validate, "compute", no)
    assert study_rows.published_rows(tmp_path, quick=True) == []
    assert "left out with --quick" in capsys.readouterr().out


def test_provider_gets_the_cache_folder_and_quick(monkeypatch):
    seen = {}

    def rows(results=None, quick=False):
        seen.update(results=results, quick=quick)
        return []

    monkeypatch.setattr(study_rows, "published_rows", rows)
    monkeypatch.setattr(validate, "ROW_PROVIDERS", ("housingfe.verification.study_rows",))
    assert validate.provider_rows(results="somewhere", quick=True) == []
    assert seen == {"results": "somewhere", "quick": True}
