"""Speed-dependent bearings that follow the run-up's speed (runup.bearing_speeds = "follow",
housingfe.runup.chain.follow_speeds), on the coarse coupled test gearbox with the double helical set on fluid films:

* the per-speed models are the re-analysis `with_drivetrain` makes with the drivetrain's bearings at that speed, built
  independently (the coupled matrices re-assembled and their change projected, instead of the bearing elements'
  change on their nodes' rows): the projected K, C to round-off, and a two-speed run-up (coupled source, both
  routes) equal, line by line, to the two single-speed run-ups on those models (measured 3e-12 dB), and different
  from the films at 1500 rev/min (up to 1.3 dB per line at 800 rev/min);
* against a fresh modal basis at the speed (a converged reference: `build_gearbox_model` with the bearings at that
  speed): L_WA within 0.02 dB (measured 0.0016 dB at 800 rev/min, both routes);
* below the speed at which the film carries its load a speed holds the nearest carried speed's matrices, flagged;
  no carried speed at all is one InputError; rolling-element bearings are untouched (the model itself, no
  re-analysis); a bad setting names the key.
"""
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from housingfe.drivetrain.description import test_gearbox
from housingfe.errors import InputError
from housingfe.runup.chain import (
    build_gearbox_model,
    coupled_source_lines,
    follow_speeds,
    held_speed_note,
    peak_contributions,
    runup,
    with_drivetrain,
)
from housingfe.runup.scene import load_runup_scene

F_LINES = 1500.0
TORQUE = 2000.0
SPEEDS = [800.0, 1200.0]


@pytest.fixture(scope="module")
def film(comm):
    """(GearboxModel with the fluid films at 1500 rev/min, its drivetrain, a coarse source): double helical set,
    2000 N m, the rig's quill shafts (the run-up's default drive line: g(0) depends on the bearings too)."""
    from housingfe.radiation.radiators import RADIATORS
    from housingfe.runup.scene import housing_model_for
    from housingfe.scene import load_housing_scene

    hs, _ = load_housing_scene("test-gearbox", ["mesh.size=0.06"])
    hm = housing_model_for(hs, F_LINES, comm)
    dt = replace(test_gearbox("double_helical", "fluid_film", TORQUE), drive_line="quill-shafts")
    gm = build_gearbox_model(hm, dt, F_LINES, radiators={"erp": RADIATORS["erp"]()})
    return gm, dt, dt.source_model(stiffness_positions=32)


def _run(model, source, speeds):
    lines, _ = coupled_source_lines(model, source, speeds, [TORQUE], F_LINES)
    return runup(model, None, speeds, [TORQUE], lines=lines)


@pytest.mark.slow
def test_follow_is_the_reanalysis_at_each_speed(film):
    gm, dt, src = film
    following = follow_speeds(gm, SPEEDS)
    assert sorted(following.speed_models) == SPEEDS and not following.held_speeds
    res = _run(following, src, SPEEDS)
    fixed = _run(gm, src, SPEEDS)           # the films at 1500 rev/min throughout
    for speed in SPEEDS:
        ref_model = with_drivetrain(gm, replace(dt, bearing_speed_rpm=speed))
        mine = following.at_speed(speed).reduction.system
        ref = ref_model.reduction.system
        for a, b in ((mine.Kr, ref.Kr), (mine.Cr, ref.Cr)):
            assert np.max(np.abs(a - b)) <= 1e-9 * np.max(np.abs(b))
        one = _run(ref_model, src, [speed])
        at = res.lines.speed == speed
        for route in res.routes:
            np.testing.assert_allclose(res.routes[route].L_v[at], one.routes[route].L_v, atol=1e-7)
            np.testing.assert_allclose(res.L_W[route, "erp"][at], one.L_W[route, "erp"], atol=1e-7)
            assert res.series(route, "erp", TORQUE, "LwA_dB")[1][SPEEDS.index(speed)] == pytest.approx(
                one.series(route, "erp", TORQUE, "LwA_dB")[1][0], abs=1e-7)
        # the coupled source saw the speed's bearings too
        np.testing.assert_allclose(np.abs(res.lines.mesh_excitation[at]), np.abs(one.lines.mesh_excitation),
                                   rtol=1e-8)
        # the film at 800 rev/min is 1.5x stiffer and 2x more damped than at 1500: the run-up must see it
    d = np.abs(res.routes["mesh_force"].L_v - fixed.routes["mesh_force"].L_v)
    assert d.max() > 0.2
    # the peak's modes come from the model at the peak's speed
    pc = peak_contributions(following, res, "mesh_force", 0)
    k = int(np.flatnonzero(res.lines.point == 0)[0])
    freqs, _ = following.at_speed(res.lines.speed[k]).reduction.modal_contributions(
        res.lines.frequency[k], res.routes["mesh_force"].coefficients[:, k])
    assert pc["modes"][0][0] in freqs


@pytest.mark.slow
def test_follow_against_a_fresh_basis_at_the_speed(film):
    gm, dt, src = film
    speed = 800.0
    fresh = build_gearbox_model(gm.housing_model, replace(dt, bearing_speed_rpm=speed), F_LINES,
                                radiators=gm.radiators)
    a = _run(follow_speeds(gm, [speed]), src, [speed])
    b = _run(fresh, src, [speed])
    for route in a.routes:
        assert a.series(route, "erp", TORQUE, "LwA_dB")[1][0] == pytest.approx(
            b.series(route, "erp", TORQUE, "LwA_dB")[1][0], abs=0.02)


@pytest.mark.slow
def test_speeds_below_the_film_limit_hold_the_nearest_carried_speed(film):
    gm, _, _ = film
    # 2000 N m: the pinion's film needs an eccentricity ratio above 0.98 below 200 rev/min (150 refused, 200 carried)
    following = follow_speeds(gm, [100.0, 800.0])
    assert following.held_speeds == {100.0: 800.0}
    assert following.at_speed(100.0) is following.at_speed(800.0)
    assert "0.98" in following.held_reason
    note = held_speed_note(following, TORQUE)
    assert "100 rev/min" in note and "800 rev/min" in note and "\n" not in note
    with pytest.raises(InputError, match=r"runup.bearing_speeds: .*none of the run-up's speeds"):
        follow_speeds(gm, [50.0, 100.0])


@pytest.mark.parametrize("bearings", ["cylindrical_roller", "ball"])
def test_rolling_bearings_are_untouched(bearings):
    gear_set = "double_helical" if bearings == "cylindrical_roller" else "A"
    model = SimpleNamespace(drivetrain=test_gearbox(gear_set, bearings))    # no structure: nothing may be built
    assert not model.drivetrain.speed_dependent_bearings
    assert follow_speeds(model, [100.0, 800.0]) is model
    assert test_gearbox("double_helical", "fluid_film").speed_dependent_bearings


def test_bearing_speeds_setting():
    scene, _ = load_runup_scene("test-gearbox-runup-double-helical")
    assert scene.runup.bearing_speeds == "follow"            # the default since 2026-11-27
    scene, _ = load_runup_scene("test-gearbox-runup-double-helical", ['runup.bearing_speeds="fixed"'])
    assert scene.runup.bearing_speeds == "fixed"
    with pytest.raises(InputError) as err:
        load_runup_scene("test-gearbox-runup-double-helical", ['runup.bearing_speeds="sometimes"'])
    assert ": runup.bearing_speeds" in str(err.value) and "\n" not in str(err.value).strip()
