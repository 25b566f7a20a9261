"""Speed-dependent bearings that follow the run-up's speed (runup.bearing_speeds = "follow",
housingfe.runup.chain.follow_speeds), on the coarse coupled test gearbox with the double helical set on fluid films:

* the per-speed models are the re-analysis `with_drivetrain` makes with the drivetrain's bearings at that speed, built
  independently (the coupled matrices re-assembled and their change projected, instead of the bearing elements'
  change on their nodes' rows): the projected K, C to round-off, and a two-speed run-up (coupled source, both
  routes) equal, line by line, to the two single-speed run-ups on those models (measured 3e-12 dB), and different
  from the films at 1500 rev/min (up to 1.3 dB per line at 800 rev/min);
* against a fresh modal basis at the speed (a converged reference: `build_gearbox_model` with the bearings at that
  speed): L_WA within 0.02 dB (measured 0.0016 dB at 800 rev/min, both routes);
* a model at one speed never gives the base speed's bearings silently: its bearing elements and spec are the
  speed's, a re-analysis of it or another damping starts from the speed's matrices, the coupled K, C (the base
  speed's) are a RuntimeError; another reduction of a following model (`with_reduction`) reaches every speed;
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
def test_a_speed_model_never_gives_the_base_speeds_bearings(film):
    """A model at one speed (`at_speed`) shares the base model's coupled matrices, whose bearings are those of 1500
    rev/min.  What it gives must be the speed's or refused: its bearing elements (against the structure built with
    the bearings at the speed), a re-analysis of it and another damping (against those of the model built at the
    speed); the coupled K, C a RuntimeError naming follow_speeds; geometry and loads stay."""
    from housingfe.response.harmonic import Load, harmonic_response
    from housingfe.runup.chain import mesh_reference_stiffness, unit_loads
    from housingfe.solvers import modal

    gm, dt, _ = film
    speed = 800.0
    m = follow_speeds(gm, [speed, 1500.0]).at_speed(speed)
    ref = with_drivetrain(gm, replace(dt, bearing_speed_rpm=speed))     # the coupled matrices at the speed
    for a, b, base in zip(m.structure.parts.bearings, ref.structure.parts.bearings, gm.structure.parts.bearings):
        np.testing.assert_allclose(a.K, b.K, rtol=1e-12)
        np.testing.assert_allclose(a.C, b.C, rtol=1e-12)
        assert np.max(np.abs(a.K - base.K)) > 0.1 * np.max(np.abs(base.K))     # the film at 800 is another one
    assert m.structure.spec.bearings == ref.structure.spec.bearings
    # re-analysing the speed's model on its own drivetrain is the model at the speed (on main before 2026-11-27 it
    # added the speed's change twice: the base's projection plus the speed's change plus the coupled difference)
    again = with_drivetrain(m, m.drivetrain)
    for x, y in ((again.reduction.system.Kr, ref.reduction.system.Kr), (again.reduction.system.Cr,
                                                                        ref.reduction.system.Cr)):
        assert np.max(np.abs(x - y)) <= 1e-9 * np.max(np.abs(y))
    # another damping keeps the speed's bearings (re-projecting the structure would drop them)
    d = m.reduction.with_damping(0.02).system
    r = ref.reduction.with_damping(0.02).system
    assert np.max(np.abs(d.Kr - r.Kr)) <= 1e-9 * np.max(np.abs(r.Kr))
    np.testing.assert_allclose(d.frequencies_hz, r.frequencies_hz, rtol=1e-9, atol=1e-6)
    # what would be the base speed's is refused, loudly
    mine, ours = unit_loads(m.structure, m.drivetrain)[0], unit_loads(gm.structure, gm.drivetrain)[0]
    for get in (lambda: m.structure.K, lambda: m.structure.C, lambda: m.structure.system.K,
                lambda: m.reduction.structure.K, lambda: m.basis.structure.K,
                lambda: modal.modes(m.structure, 100.0),
                lambda: harmonic_response(m.structure, Load("mesh", mine["mesh"]), 0.02, [100.0])):
        with pytest.raises(RuntimeError, match=r"follow_speeds.*1500 rev/min"):
            get()
    # geometry and loads do not depend on the bearings
    assert mesh_reference_stiffness(m) == mesh_reference_stiffness(gm)
    assert m.structure.dofs == gm.structure.dofs and m.structure.spec.drive_lines == gm.structure.spec.drive_lines
    for name in mine:
        assert mine[name].equal(ours[name])


@pytest.mark.slow
def test_another_reduction_reaches_every_speed(film):
    """A model following the speeds with another damping (housingfe runup-causes' variants): `with_reduction`
    follows again, so every speed's model has it (the model at 800 rev/min with xi 0.02 is the re-analysis at 800
    rev/min with xi 0.02); replacing the reduction alone, which would leave the speed models on the old one, is
    refused."""
    from housingfe.runup.chain import with_reduction

    gm, dt, _ = film
    following = follow_speeds(gm, SPEEDS)
    other = with_reduction(following, following.reduction.with_damping(0.02))
    ref = with_drivetrain(gm, replace(dt, bearing_speed_rpm=800.0)).reduction.with_damping(0.02)
    mine = other.at_speed(800.0).reduction
    assert mine.damping is other.reduction.damping
    np.testing.assert_allclose(mine.frequencies_hz, ref.frequencies_hz, rtol=1e-9, atol=1e-6)
    assert np.max(np.abs(mine.system.Kr - ref.system.Kr)) <= 1e-9 * np.max(np.abs(ref.system.Kr))
    with pytest.raises(RuntimeError, match="with_reduction"):
        replace(following, reduction=following.reduction.with_damping(0.02))


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
