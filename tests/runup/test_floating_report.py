"""`housingfe run <run-up scene> --set drivetrain.floating_axial_ratio=X`: summary.txt and runup.json say what each
shaft's floating bearing held per torque and which ring slid (housingfe.runup.report.floating_axial_json /
floating_axial_lines), checked against Drivetrain.floating_axial_held of the scene's own drivetrains (statics only,
no FE: the report reads the models' drivetrains, stood in for here).

Gear set B at ratio -0.15: the tapered rollers' wheel ring slides (its locating bearing would lift off), the pinion's
holds the request; with ball bearings nothing slides; at ratio 0 there is nothing to report (runup.json null, no
summary line)."""
from types import SimpleNamespace

import pytest

from housingfe.runup import report
from housingfe.runup.scene import drivetrain_of, load_runup_scene

TORQUES = (1000.0, 2000.0)


def _results(settings: list[str]) -> tuple[dict, dict]:
    """{torque: (model with .drivetrain, run-up)} as run_scene passes them, and the drivetrains per torque."""
    scene, _ = load_runup_scene("test-gearbox-runup", ["drivetrain.gear_set=B", *settings])
    dts = {t: drivetrain_of(scene.drivetrain, t, scene.runup.drive_line_model) for t in TORQUES}
    return {t: (SimpleNamespace(drivetrain=dt), None) for t, dt in dts.items()}, dts


def test_the_run_up_reports_the_held_axial_loads_and_the_ring_that_slid():
    results, dts = _results(["drivetrain.bearings=tapered_roller", "drivetrain.floating_axial_ratio=-0.15"])
    data = report.floating_axial_json(results)
    assert data["ratio"] == -0.15 and list(data["torques"]) == ["1000", "2000"]
    lines = report.floating_axial_lines(results)
    assert len(lines) == len(TORQUES)
    for (t, dt), line in zip(dts.items(), lines):
        held = dt.floating_axial_held()
        got = data["torques"][f"{t:g}"]
        for shaft, (requested, effective) in held.items():
            assert got[shaft]["requested_N"] == pytest.approx(requested, rel=1e-12)
            assert got[shaft]["held_N"] == pytest.approx(effective, rel=1e-12)
        # the tapered rollers' wheel: slid, less than requested in magnitude, same sign; the pinion: as requested
        wheel, pinion = held["wheel"], held["pinion"]
        assert got["wheel"]["slid"] and wheel[0] < wheel[1] < 0.0
        assert not got["pinion"]["slid"] and pinion[0] == pinion[1] < 0.0
        assert line == (f"floating bearings (drivetrain.floating_axial_ratio = -0.15) at {t:g} N m, held axial load: "
                         f"pinion {pinion[1]:.0f} N, wheel {wheel[0]:.0f} -> {wheel[1]:.0f} N (slid); the wheel "
                         "floating ring slid (the locating bearing would lift off under the requested load)")


def test_ball_bearings_hold_the_request_and_ratio_zero_reports_nothing():
    results, dts = _results(["drivetrain.bearings=ball", "drivetrain.floating_axial_ratio=-0.15"])
    data = report.floating_axial_json(results)
    for t, dt in dts.items():
        assert not any(r["slid"] for r in data["torques"][f"{t:g}"].values())
    assert all(line.endswith("no ring slid") for line in report.floating_axial_lines(results))
    results, _ = _results(["drivetrain.bearings=tapered_roller"])
    assert report.floating_axial_json(results) is None and report.floating_axial_lines(results) == []
