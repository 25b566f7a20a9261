"""The run-up once more with another engagement shock (housingfe.runup.chain.engagement_rerun, the envelope bound
of the default run-up at set A's near-integer overlap ratio) reuses what does not depend on the engagement — the
reduction's unit-load solves (the coupled mesh receptance at every harmonic, the line solves of both routes;
RitzReduction.unit_coordinates) — and must give exactly the lines of a fresh source built with that engagement on a
reduction that has solved nothing yet.  On the coarse coupled test gearbox (tests/runup/conftest.py)."""
from dataclasses import replace

import numpy as np
import pytest

from housingfe.runup.chain import engagement_rerun, run_source, runup
from tests.runup.conftest import F_LINES, SPEEDS

TORQUE = 2000.0


@pytest.mark.slow
def test_unit_solves_are_remembered_per_system_and_damping(coarse):
    red = coarse[0].reduction
    f = np.array([333.0, 777.0, 1222.0])
    first = red.unit_coordinates(f, "mesh")
    assert red.unit_coordinates(f.copy(), "mesh") is first           # same lines: the remembered solve
    assert not first.flags.writeable                                  # nobody can spoil it for the next caller
    other = red.with_damping(0.08)                                    # another system: solved afresh
    assert np.max(np.abs(other.unit_coordinates(f, "mesh") - first)) > 1e-3 * np.max(np.abs(first))
    assert red.unit_coordinates(f, "wheel_torque") is not first       # another load, its own solve


@pytest.mark.slow
@pytest.mark.parametrize("receptance", ["coupled", "rigid-bores"])
def test_rerun_equals_a_fresh_source_with_the_engagement(coarse, receptance):
    gm, src = coarse[0], coarse[1]
    assert src.engagement == "face-width"
    # the first pass (as run_scene): fills the reduction's memo of unit solves
    lines, _ = run_source(gm, src, SPEEDS, [TORQUE], F_LINES, receptance)
    first = runup(gm, None, SPEEDS, [TORQUE], lines=lines)
    bound = engagement_rerun({TORQUE: gm}, src, "envelope-bound", SPEEDS, F_LINES, receptance)[0][TORQUE]

    # fresh: a new source with the engagement, on a reduction with nothing remembered (the same projection)
    fresh_model = replace(gm, reduction=gm.reduction.with_damping(gm.reduction.damping))
    fresh_src = gm.drivetrain.source_model(engagement="envelope-bound", stiffness_positions=src.stiffness_positions)
    fresh_lines, _ = run_source(fresh_model, fresh_src, SPEEDS, [TORQUE], F_LINES, receptance)
    fresh = runup(fresh_model, None, SPEEDS, [TORQUE], lines=fresh_lines)

    b, f = bound.lines, fresh.lines
    np.testing.assert_array_equal(b.frequency, f.frequency)
    np.testing.assert_allclose(b.mesh_excitation, f.mesh_excitation, rtol=1e-12, atol=0)
    np.testing.assert_allclose(b.L_omega, f.L_omega, rtol=0, atol=1e-9)
    if receptance == "coupled":
        np.testing.assert_allclose(b.L_omega_flexible, f.L_omega_flexible, rtol=0, atol=1e-9)
    for route in first.routes:
        np.testing.assert_allclose(bound.routes[route].L_v, fresh.routes[route].L_v, rtol=0, atol=1e-9)
        np.testing.assert_allclose([r["LwA_dB"] for r in bound.totals if r["route"] == route],
                                   [r["LwA_dB"] for r in fresh.totals if r["route"] == route], rtol=0, atol=1e-9)
    # and it is the bound, not the first pass again: at the helix's cancellation the bound's tooth line lies far
    # above the face-width excitation (+16.9 dB at n = 1 on the default model, docs/source.md)
    tooth = lines.harmonic == 1
    rise = 20 * np.log10(np.abs(b.mesh_excitation[tooth]) / np.abs(lines.mesh_excitation[tooth]))
    assert np.all(rise > 10.0)           # 17.1 dB on the coarse model


def test_te_sensitivity_on_a_source_with_points_at_other_torques(coarse):
    """runup.te_sensitivity of a run-up at several torques: the unit TE of one torque must not be asked at the
    source's other torques (found by housingfe validate on the double helical run-ups at 1000 and 2000 N m)."""
    from housingfe.runup.chain import te_sensitivity

    gm, src, _, _ = coarse
    src.prepared([1000.0, 2000.0])
    out, _ = te_sensitivity({2000.0: gm}, src, [1], SPEEDS, F_LINES)
    assert list(out) == [2000.0] and list(out[2000.0]) == [1]
    assert all(np.isfinite(r["LwA_dB"]) for r in out[2000.0][1].totals)
