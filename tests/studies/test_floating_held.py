"""`housingfe study` with drivetrain.floating_axial_ratio != 0: the written study says which variant's floating
rings slid and what each floating bearing held (issue 28).

The bearings family (gear set B) at ratio -0.15: a directional locating bearing (angular contact, tapered roller) is
relieved by a negative held load until it would lift off, so there the floating ring slides and holds less than
ratio |F_r|; ball and self-aligning locating bearings take either direction and hold the requested load
(docs/bearings.md, "The floating bearings' mean axial load").  The numbers in <family>.csv / .md and the summary are
checked against Drivetrain.floating_axial_held computed here from the scene's drivetrains (statics only, no FE: the
run-ups are synthetic flat curves, which the floating columns do not depend on).  At ratio 0 the files carry no
floating columns or section (the default study's files stay byte-identical to before)."""
import csv

import numpy as np
import pytest

from housingfe.studies import design_variants as dv
from housingfe.studies.chain_session import ChainSession

SPEEDS = np.array([800.0, 1150.0, 1500.0])
RATIO = -0.15


def _study(overrides: list[str]):
    """The bearings family's drivetrains from the scene with `overrides`, and a StudyResult on flat run-ups."""
    fam = dv.families()["bearings"]
    session = ChainSession.from_scene(fam.scene, overrides)
    routes = tuple(session.spec.routes)
    drivetrains, runs = {}, {}
    for i, v in enumerate(fam.variants):
        drivetrains[v.key] = dt = session.drivetrain(v.gear_set, v.bearings, v.torque)
        curves = {r: (SPEEDS, np.full(len(SPEEDS), 80.0 + i)) for r in routes}
        runs[v.key] = dv.VariantRun(v, curves, "built", 0.0, 0.0, **dv.floating_of(dt))
    result = dv.analyse(dv.StudyResult(fam, session.spec.engagement, session.radiation, routes, runs))
    return drivetrains, result


def test_the_study_names_the_rings_that_slid_and_what_each_floating_bearing_held(tmp_path):
    drivetrains, result = _study([f"drivetrain.floating_axial_ratio={RATIO}"])
    dv.write(tmp_path, result, 1.0)
    with open(tmp_path / "bearings.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0])[-len(dv.FLOATING_COLUMNS):] == list(dv.FLOATING_COLUMNS)
    assert len(rows) == 2 * len(drivetrains)                       # every route and variant
    slid_by_variant = {}
    for r in rows:
        dt = drivetrains[r["variant"]]
        held = dt.floating_axial_held()                            # the statics, not the written file
        loads = dt.bearing_loads()
        assert float(r["floating_axial_ratio"]) == RATIO
        slid = []
        for shaft, (requested, effective) in held.items():
            floating = next(b for b in dt.bearings if b.shaft == shaft and not b.locating)
            assert requested == pytest.approx(RATIO * np.hypot(*loads[floating.name][:2]), rel=1e-12)  # ratio |F_r|
            assert float(r[f"{shaft}_floating_requested_N"]) == pytest.approx(requested, abs=0.05)
            assert float(r[f"{shaft}_floating_held_N"]) == pytest.approx(effective, abs=0.05)
            if abs(effective) < abs(requested) - 1.0:                # slid: held well below the request (> 1 N)
                assert np.sign(effective) == np.sign(requested)
                slid.append(shaft)
            else:
                assert effective == requested
        assert r["floating_rings_slid"] == (" ".join(slid) or "none")
        slid_by_variant[r["variant"]] = slid
    # angular contact and tapered rollers locate directionally: relieved by -0.15 they let rings slide (set B: both
    # of the angular contact shafts, the tapered rollers' wheel); ball and self-aligning hold the request
    assert slid_by_variant == {"ball": [], "angular_contact": ["pinion", "wheel"], "self_aligning": [],
                               "tapered_roller": ["wheel"]}
    line = ("floating rings (drivetrain.floating_axial_ratio = -0.15): slid: angular_contact (pinion, wheel); "
            "tapered_roller (wheel); held as requested: ball, self_aligning")
    md = (tmp_path / "bearings.md").read_text()
    assert line + "." in md.splitlines()
    pinion, wheel = drivetrains["tapered_roller"].floating_axial_held().values()
    assert (f"| tapered_roller | 2000 | -0.15 | {pinion[0]:.0f} → {pinion[1]:.0f} | {wheel[0]:.0f} → {wheel[1]:.0f} "
            "| wheel |") in md
    summary = dv.summary_text(result).splitlines()
    assert line in summary
    assert (f"  tapered_roller at 2000 N m, held axial load: pinion {pinion[1]:.0f} N, wheel {wheel[0]:.0f} -> "
            f"{wheel[1]:.0f} N (slid)") in summary


def test_at_ratio_zero_the_study_files_have_no_floating_columns(tmp_path):
    _, result = _study([])
    dv.write(tmp_path, result, 1.0)
    with open(tmp_path / "bearings.csv") as fh:
        assert next(csv.reader(fh)) == list(dv.COLUMNS)
    assert "Floating" not in (tmp_path / "bearings.md").read_text()
    assert "floating" not in dv.summary_text(result)
