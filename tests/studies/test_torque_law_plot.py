"""The torque-law figure of a design-variant study (design_variants.plot_torque_law, <family>_torque_law.png):
written where the study has a torque law and only there, and what it plots is the torque law's numbers: per group
and route the 800-1500 rev/min energy means at the group's torques, the least-squares line with the slope per
doubling, the measured step / slope drawn from our level at the lower torque, gears as made dashed.

The synthetic runs of tests/studies/test_torque_law.py: L_WA = a(speed) + k lg T inside 800-1500 rev/min, so the
slope is k lg 2 per doubling exactly (k = 20 ball, 10 self-aligning; 6 as made)."""
import math

import numpy as np
import pytest

from housingfe.studies import design_variants as dv
from tests.studies.test_torque_law import ROUTES, SPEEDS, _level, _result

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _slope(line: dict) -> float:
    x, y = line["torques_nm"], line["LwA_dBA"]
    return float((y[-1] - y[0]) / math.log2(x[-1] / x[0]))


def test_figure_plots_the_torque_law_numbers(tmp_path):
    measured = dv.MeasuredTorqueLaw("B", "ball", 1000.0, 2000.0, measured_step=3.4, measured_slope=3.0)
    result = _result([measured], k_as_made=6.0)
    dv.write(tmp_path, result, 1.0)
    png = tmp_path / "synthetic_torque_law.png"
    assert png.read_bytes()[:8] == PNG_MAGIC and png.stat().st_size > 10_000

    lines = dv.plot_torque_law(tmp_path / "again.png", result)
    made_laws = {(t["bearings"], t["route"]): t for t in result.as_made["torque_law"]}
    for t in result.torque_law:
        mine = {(ln["kind"], ln["what"]): ln for ln in lines
                if (ln["gear_set"], ln["bearings"], ln["route"]) == (t["gear_set"], t["bearings"], t["route"])}
        k = 20.0 if t["bearings"] == "ball" else 10.0
        for kind, law, k_law in ((dv.PERIODIC, t, k), (dv.AS_MADE, made_laws[t["bearings"], t["route"]], 6.0)):
            means, fit = mine[kind, "means"], mine[kind, "fit"]
            assert list(means["torques_nm"]) == [float(x) for x in law["torques_nm"].split()]
            assert means["LwA_dBA"] == pytest.approx([float(x) for x in law["energy_means_dBA"].split()], abs=0.05)
            assert _slope(fit) == pytest.approx(law["slope_dB_per_doubling"], abs=0.005)
            assert _slope(fit) == pytest.approx(k_law * math.log10(2), abs=1e-9)
            # the line passes through the means (they lie on it exactly here)
            assert np.interp(np.log2(means["torques_nm"]), np.log2(fit["torques_nm"]), fit["LwA_dBA"]) == \
                pytest.approx(means["LwA_dBA"], abs=1e-9)
            assert fit["linestyle"] == ("--" if kind == dv.AS_MADE else "-")
        periodic = mine[dv.PERIODIC, "means"]
        at_1000 = periodic["LwA_dBA"][list(periodic["torques_nm"]).index(1000.0)]
        if t["bearings"] == "ball":
            step, slope = mine["measured_step", "measured"], mine["measured_slope", "measured"]
            assert list(step["torques_nm"]) == [1000.0, 2000.0]
            assert step["LwA_dBA"] == pytest.approx([at_1000, at_1000 + 3.4], abs=1e-9)
            assert slope["LwA_dBA"] == pytest.approx([at_1000, at_1000 + 3.0], abs=1e-9)
        else:
            assert ("measured_step", "measured") not in mine and ("measured_slope", "measured") not in mine
    assert {ln["bearings"] for ln in lines} == {"ball", "self_aligning"}
    assert len({(ln["bearings"], ln["route"], ln["kind"], ln["what"]) for ln in lines}) == len(lines)


def test_no_torque_law_no_figure(tmp_path):
    """The bearings family (every variant at 2000 N m): its figures as before, no torque-law figure."""
    bearings = dv.families()["bearings"]
    runs = {v.key: dv.VariantRun(v, {r: (SPEEDS, _level(SPEEDS, v.torque, 20.0, r)) for r in ROUTES}, "built", 0, 0)
            for v in bearings.variants}
    result = dv.analyse(dv.StudyResult(bearings, "face-width", "erp", ROUTES, runs))
    dv.write(tmp_path, result, 1.0)
    assert (tmp_path / "bearings.png").exists()
    assert not list(tmp_path.glob("*torque_law*"))
