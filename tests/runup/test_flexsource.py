"""The source on the flexible housing (housingfe.runup.chain.coupled_source_lines, issue 28 item 2), on the coarse
coupled test gearbox:

* the mesh receptance of the Ritz reduction tends to 1/k_ref at zero frequency (the gears turn freely apart from
  the mesh: only the mesh spring resists a static compression) — the static value the balance uses;
* with the drive line (runup.drive_line = "quill-shafts") the static receptance is the mesh spring in parallel with
  the quill shafts' torsional stiffness seen along the line of action (chain.static_mesh_receptance), within the
  bearings' and housing's share;
* the rank-one harmonic balance on that receptance equals the full Hill system assembled on every Ritz coordinate
  of the coupled model (housingfe.benchmarks.flexsource.full_hill_on_ritz, which the benchmark times too; mesh
  compression per harmonic, 1e-8 of its largest dynamic harmonic);
* the first-order (mean-stiffness) solve agrees with the full one within the ripple of S(t) on the lines that
  matter (>= 1 % of the tooth line);
* the mesh_force route on the coupled lines gives the coupled source's own wheel level (one model, no second
  interior), and the scene key runup.source_receptance picks the source.
"""
import math

import numpy as np
import pytest

from housingfe.benchmarks.flexsource import full_hill_on_ritz
from housingfe.runup.chain import (
    coupled_source_lines,
    mesh_receptance,
    mesh_reference_stiffness,
    runup,
    source_lines,
    static_mesh_receptance,
)
from housingfe.source.roosmalen.dynamics import mesh_harmonic_balance
from housingfe.source.stiffness import normal_force_from_torque
from tests.runup.conftest import F_LINES, SPEEDS

TORQUE = 2000.0


@pytest.mark.slow
def test_static_mesh_receptance_is_one_over_the_mesh_stiffness(coarse):
    gm = coarse[0]
    k = mesh_reference_stiffness(gm)
    assert mesh_receptance(gm, [1e-3])[0] * k == pytest.approx(1.0, abs=1e-6)


@pytest.mark.slow
def test_double_helical_reference_stiffness_is_the_normal_mesh_stiffness(coarse):
    """Double helical: the FE element holds S cos^2(beta_b) along the transverse line of action and the "mesh" unit
    load is the resultant cos(beta_b) l of a unit normal force (docs/drivetrain.md), so along that load the static
    receptance is 1 / S, S the MeshModel's normal stiffness, and k_ref must be S (not the element's S cos^2(beta_b)):
    the balance's S(t) - k_ref then has zero mean."""
    from housingfe.drivetrain.description import test_gearbox
    from housingfe.runup.chain import build_gearbox_model
    from housingfe.source.stiffness import stiffness_curve

    dt = test_gearbox("double_helical", bearings="cylindrical_roller")
    gm = build_gearbox_model(coarse[0].housing_model, dt, F_LINES)
    pair = dt.gears.pair
    S = stiffness_curve(dt.to_lumped()[2], normal_force_from_torque(pair, dt.torque), dt.coupling_mesh_positions).mean
    k = mesh_reference_stiffness(gm)
    assert k == pytest.approx(S, rel=1e-12)
    assert gm.structure.spec.gear_meshes[0].stiffness == pytest.approx(S * math.cos(pair.base_helix_angle) ** 2,
                                                                       rel=1e-12)
    assert mesh_receptance(gm, [1e-3])[0] * k == pytest.approx(1.0, abs=1e-6)


@pytest.fixture(scope="module")
def coarse_drive_line(coarse):
    """The coarse model's housing and drivetrain with the quill shafts (runup.drive_line = "quill-shafts")."""
    from dataclasses import replace

    from housingfe.runup.chain import build_gearbox_model

    gm0 = coarse[0]
    return build_gearbox_model(gm0.housing_model, replace(gm0.drivetrain, drive_line="quill-shafts"), F_LINES)


@pytest.mark.slow
def test_static_mesh_receptance_with_the_drive_line(coarse_drive_line):
    """1/g(0) - k_ref = 1/s, s = a_p^2/k_p + a_w^2/k_w: the mesh pair turns each gear against its quill chain
    (near quill in series with the FE shaft's torsion from gear to shaft end, far quill to ground), a = the mesh
    normal's lever about each shaft axis (rotation-only model: g = s / (1 + k_ref s)).  The bearings and the
    housing add translational compliance along the line of action: within 3 %.  Without the drive line g(0) is
    1/k_ref exactly (above)."""
    gm = coarse_drive_line
    dt = gm.drivetrain
    k_ref = mesh_reference_stiffness(gm)
    mesh = gm.structure.spec.gear_meshes[0]
    pair = dt.gears.pair
    G = pair.youngs_modulus / (2 * (1 + pair.poisson_ratio))
    inverse = 0.0
    for name in ("pinion", "wheel"):
        line = dt.shaft(name)
        axis = np.asarray(line.axis, float) / np.linalg.norm(line.axis)
        lever = axis @ np.cross(np.asarray(mesh.point) - np.asarray(line.centre), np.asarray(mesh.direction))
        near, _, far = dt.drive_line_parts()[name]
        shaft = G * math.pi * line.diameter**4 / 32 / (0.0 - line.ends[0])
        inverse += lever**2 * (1 / near + 1 / far + 1 / shaft)
    g0 = static_mesh_receptance(gm)
    assert 0.99 < g0 * k_ref < 1.0                     # the quills are ~1000x softer than the mesh
    assert 1 / g0 - k_ref == pytest.approx(1 / inverse, rel=0.03)


@pytest.mark.slow
def test_reanalysis_with_other_quill_shafts(coarse_drive_line):
    """The uncertainty's quill samples re-use the basis (with_drivetrain): with every quill 20 % thinner (stiffness
    x 0.41) the re-analysed rig mode is the spring chain's (tests/drivetrain/test_drive_line.py) within 0.5 %, as
    the fresh model's is; the Ritz space holds the static torques across the quills (chain.bearing_pairs)."""
    from dataclasses import replace

    from housingfe.runup.chain import with_drivetrain
    from tests.drivetrain.test_drive_line import _rig_chain_hz

    gm = coarse_drive_line
    thin = replace(gm.drivetrain, quill_shafts=tuple(replace(q, diameter=0.8 * q.diameter)
                                                     for q in gm.drivetrain.quill_shafts))
    before = gm.reduction.frequencies_hz[0]
    after = with_drivetrain(gm, thin).reduction.frequencies_hz[0]
    assert before == pytest.approx(_rig_chain_hz(gm.drivetrain), rel=5e-3)
    assert after == pytest.approx(_rig_chain_hz(thin), rel=5e-3) and after < 0.75 * before


@pytest.mark.slow
@pytest.mark.parametrize("speed", [500.0, 1100.0])
def test_rank_one_balance_equals_the_full_hill_system_on_the_ritz_coordinates(coarse, speed):
    gm, src = coarse[0], coarse[1]
    H = 8
    k = mesh_reference_stiffness(gm)
    S, shock = src.mesh_stiffness(TORQUE)
    F = normal_force_from_torque(src.pair, TORQUE)
    f_t = src.pair.tooth_frequency(speed)
    g = np.concatenate([[1 / k], mesh_receptance(gm, f_t * np.arange(1, H + 1))])
    d = mesh_harmonic_balance(g, F / k, S, shock, k, f_t).compression
    lam = (2 * math.pi * gm.reduction.system.frequencies_hz) ** 2
    assert np.sum(lam < 1e-6 * lam.max()) == 1     # one zero mode (the gears turning freely), held in the Hill system
    d_full, _ = full_hill_on_ritz(gm, src, speed, TORQUE, H)
    np.testing.assert_allclose(d, d_full, rtol=0, atol=1e-8 * np.abs(d_full[H + 1:]).max())


@pytest.mark.slow
def test_first_order_agrees_within_the_ripple(coarse):
    gm, src = coarse[0], coarse[1]
    full, _ = coupled_source_lines(gm, src, SPEEDS, [TORQUE], F_LINES)
    first, _ = coupled_source_lines(gm, src, SPEEDS, [TORQUE], F_LINES, first_order=True)
    S, _ = src.mesh_stiffness(TORQUE)
    ripple = np.abs(np.fft.rfft(S)[1:]).max() * 2 / S.size / S.mean()
    for p in range(len(SPEEDS)):
        sel = full.point == p
        a, b = first.mesh_excitation[sel], full.mesh_excitation[sel]
        big = np.abs(b) >= 0.01 * np.abs(b[0])
        assert np.all(np.abs(a[big] - b[big]) <= ripple * np.abs(b[big]))


@pytest.mark.slow
def test_mesh_force_route_on_the_coupled_source_is_its_wheel_level(coarse):
    gm, src = coarse[0], coarse[1]
    lines, _ = coupled_source_lines(gm, src, SPEEDS, [TORQUE], F_LINES)
    rigid, _ = source_lines(src, SPEEDS, [TORQUE], F_LINES)
    res = runup(gm, None, SPEEDS, [TORQUE], lines=lines)
    np.testing.assert_allclose(res.routes["mesh_force"].L_omega_coupled, lines.L_omega_flexible, atol=1e-9)
    np.testing.assert_array_equal(lines.L_omega, rigid.L_omega)       # tf_omega keeps the thesis' source
    assert lines.receptance == "coupled"


def test_source_receptance_key_defaults_to_coupled_and_rejects_unknown(tmp_path):
    import subprocess

    from housingfe.runup.scene import load_runup_scene
    from tests.runup.test_scene import HOUSINGFE

    scene, _ = load_runup_scene("test-gearbox-runup")
    assert scene.runup.source_receptance == "coupled"
    scene, _ = load_runup_scene("test-gearbox-runup", ['runup.source_receptance="rigid-bores"'])
    assert scene.runup.source_receptance == "rigid-bores"
    out = tmp_path / "out"
    proc = subprocess.run(HOUSINGFE + ["run", "test-gearbox-runup", "--out", str(out), "--set",
                                       'runup.source_receptance="flexible"'], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 2, proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "runup.source_receptance" in lines[0] and "Traceback" not in proc.stderr, proc.stderr
    assert not out.exists()
