"""The run-up chain (housingfe.runup.chain).

* The mesh_force route's load F_n - k_m d_n on a model that holds the mean mesh stiffness k_m reproduces the
  lumped source's own harmonic-balance response exactly (eq. of motion rearranged; 1e-9), so the route adds no
  second, inconsistent interior.
* On a coarse coupled test gearbox: the Ritz reduction agrees with a direct solve of the full model (same
  hysteretic damping) within 0.3 dB per line; totals are energy sums of the harmonics; TF_omega is a property
  of the structure (the same line reached from two speeds gives the same TF); the Rayleigh-Ritz re-analysis at
  another torque reproduces a fresh basis' frequencies to 1e-3 and its run-up to 0.3 dB.
* 1 and 2 MPI ranks give the same run-up (runup.csv to 1e-6 dB).
"""
import csv
import math
import shutil

import numpy as np
import pytest

from housingfe.drivetrain.description import test_gearbox, with_torque
from housingfe.response.harmonic import Load, harmonic_response, loss_factor
from housingfe.response.reduced import RitzReduction
from housingfe.runup.chain import build_gearbox_model, runup, source_lines, unit_loads, with_drivetrain
from tests.runup.conftest import F_LINES, SPEEDS
from tests.test_cli import housingfe


def test_mesh_excitation_reproduces_the_lumped_response():
    src = test_gearbox("A").source_model()
    exc = src.operating_point(1000.0, 2000.0)
    op = src._point(2000.0)
    m = op.mats
    k_m = float(np.mean(src.mesh_stiffness(2000.0)[0]))
    F_exc = exc.mesh_force - k_m * exc.transmission_error
    H = src.harmonics
    for n in range(1, 6):
        w = 2 * math.pi * exc.frequency_hz[n - 1]
        Z = m.K0 + k_m * np.outer(m.h, m.h) - w**2 * m.M + 1j * w * m.D
        q = np.linalg.solve(Z, -m.h * F_exc[n - 1])
        np.testing.assert_allclose(q, 2 * exc.state.Q[H + n], rtol=1e-9, atol=1e-9 * np.abs(q).max())
        assert m.h @ q == pytest.approx(exc.transmission_error[n - 1], rel=1e-9)


@pytest.mark.slow
def test_totals_are_energy_sums_of_the_harmonics(coarse):
    gm, src, lines, res = coarse
    for row in res.totals:
        sel = [r for r in res.harmonic_rows() if r["route"] == row["route"] and r["radiation"] == row["radiation"]
               and r["speed_rpm"] == row["speed_rpm"]]
        assert len(sel) == row["harmonics"] == int(F_LINES // row["tooth_frequency_hz"])
        for key in ("Lv_dB", "LwA_dB"):
            assert row[key] == pytest.approx(10 * np.log10(sum(10 ** (r[key] / 10) for r in sel)), abs=1e-9)


@pytest.mark.slow
def test_tf_omega_depends_on_frequency_only(coarse):
    gm, src, lines, res = coarse
    tf = res.routes["tf_omega"].tf_omega
    a = np.flatnonzero((lines.speed == 500.0) & (lines.harmonic == 2))[0]     # 400 Hz
    b = np.flatnonzero((lines.speed == 1000.0) & (lines.harmonic == 1))[0]    # 400 Hz
    assert lines.frequency[a] == lines.frequency[b] == 400.0
    assert tf[a] == pytest.approx(tf[b], abs=1e-9)
    assert res.routes["tf_omega"].L_v[a] - lines.L_omega[a] == pytest.approx(tf[a], abs=1e-9)


@pytest.mark.slow
def test_ritz_reduction_matches_a_direct_solve(coarse):
    gm, src, lines, res = coarse
    loads, _, _ = unit_loads(gm.structure, gm.drivetrain)
    eta = 0.08
    red = RitzReduction(gm.basis, loads, loss_factor(eta), nodes=(gm.wheel_node,))
    sel = lines.speed == 1100.0
    f, amps = lines.frequency[sel], lines.mesh_excitation[sel]
    ours = red.evaluate(f, {"mesh": amps}).velocity_level_db
    ref = harmonic_response(gm.structure, Load("mesh", loads["mesh"], (f, amps)), loss_factor(eta), f,
                            solver="direct").velocity_level_db
    np.testing.assert_allclose(ours, ref, atol=0.3)


@pytest.mark.slow
def test_reanalysis_at_another_torque_matches_a_fresh_basis(coarse):
    gm, src, lines, res = coarse
    dt = with_torque(gm.drivetrain, 1000.0)
    re = with_drivetrain(gm, dt)
    fresh = build_gearbox_model(gm.housing_model, dt, F_LINES, radiators=gm.radiators)
    n = fresh.basis.rigid_count
    ref = fresh.basis.frequencies_hz[n:]
    ref = ref[ref < F_LINES]
    ritz = re.reduction.frequencies_hz[n:n + len(ref)]
    np.testing.assert_allclose(ritz, ref, rtol=1e-3)
    low, _ = source_lines(src, SPEEDS, [1000.0], F_LINES)
    a = runup(re, None, SPEEDS, [1000.0], lines=low)
    b = runup(fresh, None, SPEEDS, [1000.0], lines=low)
    for route in ("tf_omega", "mesh_force"):
        np.testing.assert_allclose(a.routes[route].L_v, b.routes[route].L_v, atol=0.3)


def test_shuttle_lines_are_the_force_times_the_centre_of_pressure_harmonics():
    """Lines.shuttle_moment (complex rms N m) = F W_n / sqrt 2 with W_n the harmonics of the moment arm w_c +
    tan(beta_b) s_c of the centre of pressure of a load distribution computed afresh (housingfe.source.mesh_moments.centre_of_pressure_curve) at the source's
    positions: the reuse of the stiffness curve's distributions changes nothing; "none" leaves them out."""
    from housingfe.source.mesh_moments import centre_of_pressure_curve
    from housingfe.source.stiffness import normal_force_from_torque

    src = test_gearbox("A").source_model()
    speeds = [500.0, 1300.0]
    lines, _ = source_lines(src, speeds, [2000.0], 2000.0, mesh_moment="shuttling")
    plain, _ = source_lines(src, speeds, [2000.0], 2000.0, mesh_moment="none")
    assert plain.shuttle_moment is None and set(plain.mesh_amplitudes()) == {"mesh"}
    np.testing.assert_array_equal(plain.mesh_excitation, lines.mesh_excitation)
    F = normal_force_from_torque(src.pair, 2000.0)
    cop = centre_of_pressure_curve(src.mesh_model, F, src.stiffness_positions)
    W = cop.moment_arm_harmonics(math.tan(src.pair.base_helix_angle), int(lines.harmonic.max()))
    np.testing.assert_allclose(lines.shuttle_moment, F * W[lines.harmonic - 1] / math.sqrt(2.0), rtol=1e-9)
    # set A at 2000 N m: the first harmonic is tens of N m (the centre moves millimetres over a 60 mm face)
    assert 20.0 < abs(lines.shuttle_moment[0]) * math.sqrt(2.0) < 500.0


@pytest.mark.slow
def test_shuttle_load_ritz_matches_a_direct_solve(coarse):
    """The mesh excitation with the shuttling moment through the Ritz reduction (its static vector "shuttle") against
    a direct solve of the full coupled model with the same two loads."""
    gm, src, _, _ = coarse
    lines, _ = source_lines(src, [1100.0], [2000.0], F_LINES, mesh_moment="shuttling")
    loads, _, _ = unit_loads(gm.structure, gm.drivetrain)
    eta = 0.08
    red = RitzReduction(gm.basis, loads, loss_factor(eta), nodes=(gm.wheel_node,))
    f = lines.frequency
    ours = red.evaluate(f, lines.mesh_amplitudes()).velocity_level_db
    moment_only = red.evaluate(f, {"shuttle": lines.shuttle_moment}).velocity_level_db
    ref = harmonic_response(gm.structure, [Load("mesh", loads["mesh"], (f, lines.mesh_excitation)),
                                           Load("shuttle", loads["shuttle"], (f, lines.shuttle_moment))],
                            loss_factor(eta), f, solver="direct")
    np.testing.assert_allclose(ours, ref.velocity_level_db, atol=0.3)
    assert np.max(moment_only) > np.max(ours) - 20.0          # the moment is not negligible here


# `housingfe run test-gearbox-runup` coarse (60 mm mesh, lines to 1.5 kHz, 1000-1500 rev/min), with the mesh moment
# set explicitly to what it is by default (the face-width engagement's "shuttling")
COARSE_CLI = ["run", "test-gearbox-runup", "--set", 'housing.set=["mesh.size=0.06"]', "--set",
              "runup.f_max_hz=1500.0", "--set", "runup.speed_min_rpm=1000.0", "--set", "runup.speed_step_rpm=250.0"]
SHUTTLING = ["--set", 'runup.mesh_moment="shuttling"']


@pytest.fixture(scope="module")
def coarse_cli_shuttling(tmp_path_factory):
    """(CompletedProcess, output folder) of COARSE_CLI + SHUTTLING on one rank, run once for the module: the ranks
    test compares it with two ranks, the mesh-moment test with mesh_moment = "none" and with friction (the same
    deterministic run both made before)."""
    folder = tmp_path_factory.mktemp("coarse_cli") / "shuttling"
    return housingfe(*COARSE_CLI, *SHUTTLING, "--out", str(folder)), folder


def _rows(path):
    with open(path) as fh:
        return list(csv.DictReader(fh))


@pytest.mark.slow
@pytest.mark.mpi
def test_one_and_two_ranks_agree(tmp_path, coarse_cli_shuttling):
    if not shutil.which("mpirun"):
        pytest.skip("mpirun not installed")
    one, one_dir = coarse_cli_shuttling        # the one-rank run test_cli_mesh_moment_changes_mesh_force_only reads
    assert one.returncode == 0, one.stderr
    two = housingfe(*COARSE_CLI, *SHUTTLING, "--out", str(tmp_path / "two"), mpi_ranks=2)
    assert two.returncode == 0, two.stderr
    a, b = _rows(one_dir / "runup.csv"), _rows(tmp_path / "two/runup.csv")
    assert len(a) == len(b) == 2 * 2 * 3
    # progress (housingfe.progress): housing model, coupled model, the run-up at the one torque; rank 0 alone
    for proc in (one, two):
        steps = [ln for ln in proc.stderr.splitlines() if ln.startswith("run-up test-gearbox-runup: ")]
        assert steps[0].startswith("run-up test-gearbox-runup: 1/3 steps, ") and "elapsed" in steps[0]
        assert steps[-1].startswith("run-up test-gearbox-runup: 3/3 steps, ") and "3 speeds, 8 lines" in steps[-1]
        assert len(steps) == len(set(steps)) <= 3
    for ra, rb in zip(a, b):
        for key in ("Lv_dB", "LwA_dB", "L_omega_dB"):
            assert float(ra[key]) == pytest.approx(float(rb[key]), abs=1e-6)
    # the run-up with the envelope bound on the same models (set A's overlap note): the same on both, printed once
    a, b = _rows(one_dir / "runup_envelope_bound.csv"), _rows(tmp_path / "two/runup_envelope_bound.csv")
    assert len(a) == len(b) == 2 * 2 * 3
    for ra, rb in zip(a, b):
        for key in ("Lv_dB", "LwA_dB", "L_omega_dB", "L_omega_coupled_dB"):
            assert (ra[key] == rb[key] == "") or float(ra[key]) == pytest.approx(float(rb[key]), abs=1e-6)
    assert two.stdout.count("with the envelope bound: max L_WA") == 1
    # the run-up per um of TE (runup.te_sensitivity, default n = 1) on the same models: the same on both
    a, b = _rows(one_dir / "te_sensitivity.csv"), _rows(tmp_path / "two/te_sensitivity.csv")
    assert len(a) == len(b) == 2 * 2 * 3
    for ra, rb in zip(a, b):
        for key in ("Lv_dB", "LwA_dB", "L_omega_dB", "LwA_total_dB"):
            assert float(ra[key]) == pytest.approx(float(rb[key]), abs=1e-6)
    assert two.stdout.count("TE sensitivity (runup.te_sensitivity") == 1


# the housing of COARSE_CLI on an elastic frame: supports.0 (the feet) with 1e9 N/m vertical, a third of it in plane
MOUNTED = ["--set", 'housing.set=["mesh.size=0.06","supports.0.kind=elastic","supports.0.total_normal_stiffness=1e9",'
           '"supports.0.total_tangential_stiffness=3.33333e8"]']


@pytest.mark.slow
@pytest.mark.mpi
def test_one_and_two_ranks_agree_on_an_elastic_mount(tmp_path, coarse_cli_shuttling):
    """The same coarse run-up with the feet on springs (total_normal_stiffness, spread over the feet's area on each
    rank's part of the mesh): the same modes and levels on 1 and 2 ranks.  The mount must matter, or the test
    proves nothing: the lowest housing mode (above the drive line's torsion at 76 Hz) falls well below the fixed
    feet's (2026-11-27: 130.1 Hz on the frame, 212.5 Hz fixed) and the levels change."""
    import json

    if not shutil.which("mpirun"):
        pytest.skip("mpirun not installed")
    fixed, fixed_dir = coarse_cli_shuttling
    assert fixed.returncode == 0, fixed.stderr
    args = [*COARSE_CLI[:2], *MOUNTED, *COARSE_CLI[4:], *SHUTTLING]
    one = housingfe(*args, "--out", str(tmp_path / "one"))
    assert one.returncode == 0, one.stderr
    two = housingfe(*args, "--out", str(tmp_path / "two"), mpi_ranks=2)
    assert two.returncode == 0, two.stderr
    basis = {name: json.loads((folder / "runup.json").read_text())["modal_basis"]
             for name, folder in (("fixed", fixed_dir), ("one", tmp_path / "one"), ("two", tmp_path / "two"))}
    for key in ("elastic_frequencies_hz", "ritz_frequencies_hz"):
        assert len(basis["one"][key]) == len(basis["two"][key])
        np.testing.assert_allclose(basis["one"][key], basis["two"][key], rtol=1e-6)
    mounted, feet = basis["one"]["elastic_frequencies_hz"], basis["fixed"]["elastic_frequencies_hz"]
    assert mounted[0] == pytest.approx(feet[0], rel=0.01)        # the drive line's torsion: the housing barely moves
    assert mounted[1] < 0.7 * feet[1]
    a, b, c = (_rows(folder / "runup.csv") for folder in (tmp_path / "one", tmp_path / "two", fixed_dir))
    assert len(a) == len(b) == len(c) == 2 * 2 * 3
    for ra, rb in zip(a, b):
        for key in ("Lv_dB", "LwA_dB", "L_omega_dB"):
            assert float(ra[key]) == pytest.approx(float(rb[key]), abs=1e-6)
    assert max(abs(float(ra["LwA_dB"]) - float(rc["LwA_dB"])) for ra, rc in zip(a, c)) > 3.0


@pytest.mark.slow
@pytest.mark.mpi
def test_one_and_two_ranks_agree_with_fluid_films_following_the_speed(tmp_path):
    """The double helical set on fluid films following the speed (runup.bearing_speeds = "follow", the default):
    every rank solves the films' Reynolds equation and projects their change itself, so 1 and 2 ranks must give
    the same run-up, 100 rev/min (below the film limit at 2000 N m) held at the nearest carried speed on both."""
    import json

    if not shutil.which("mpirun"):
        pytest.skip("mpirun not installed")
    args = ["run", "test-gearbox-runup-double-helical", "--set", "drivetrain.bearings=fluid_film", "--set",
            'housing.set=["mesh.size=0.06"]', "--set", "runup.f_max_hz=1500.0", "--set", "runup.torques_nm=[2000.0]",
            "--set", "runup.speed_min_rpm=100.0", "--set", "runup.speed_step_rpm=600.0"]
    one = housingfe(*args, "--out", str(tmp_path / "one"))
    assert one.returncode == 0, one.stderr
    two = housingfe(*args, "--out", str(tmp_path / "two"), mpi_ranks=2)
    assert two.returncode == 0, two.stderr
    a, b = _rows(tmp_path / "one/runup.csv"), _rows(tmp_path / "two/runup.csv")
    assert len(a) == len(b) and {float(r["speed_rpm"]) for r in a} == {100.0, 700.0, 1300.0}
    for ra, rb in zip(a, b):
        assert (ra["route"], ra["radiation"], ra["speed_rpm"]) == (rb["route"], rb["radiation"], rb["speed_rpm"])
        for key in ("Lv_dB", "LwA_dB", "L_omega_dB"):
            assert float(ra[key]) == pytest.approx(float(rb[key]), abs=1e-6)
    ja, jb = (json.loads((tmp_path / name / "runup.json").read_text())["bearing_speeds"] for name in ("one", "two"))
    assert ja == jb
    assert ja["setting"] == "follow" and ja["torques"]["2000"]["held"] == {"100": 700.0}
    assert ja["torques"]["2000"]["models"] == 2


@pytest.mark.slow
def test_reanalysis_by_the_change_of_the_matrices_equals_a_full_projection(coarse):
    """The re-analysis projects only K, M, C's change (the interior rows) on the Ritz vectors: the reduced
    matrices must be those of projecting the new matrices whole (round-off of the largest entry), and the change
    must really be confined to the interior (the shortcut is taken)."""
    from housingfe.solvers.harmonic import project

    gm, _, _, _ = coarse
    for dt in (with_torque(gm.drivetrain, 1000.0), test_gearbox("A", "self_aligning")):
        re = with_drivetrain(gm, dt)
        assert gm.reduction._projected_change(re.structure) is not None
        full = project(re.reduction.vectors, re.structure.K, re.structure.M, re.structure.C)
        for ours, ref in zip((re.reduction.system.Kr, re.reduction.system.Mr, re.reduction.system.Cr), full):
            np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-12 * max(np.abs(ref).max(), 1e-300))


@pytest.mark.slow
def test_cli_mesh_moment_changes_mesh_force_only(tmp_path, coarse_cli_shuttling):
    """`housingfe run test-gearbox-runup --set runup.mesh_moment=...` as a user runs it (coarse): the shuttling moment
    raises the mesh_force route's tooth line, leaves tf_omega exactly as it was, and the result says it is on."""
    import json

    args = COARSE_CLI
    out = {}
    for moment in ("none", "shuttling"):
        if moment == "shuttling":       # the one-rank run test_one_and_two_ranks_agree compares with two ranks
            proc, folder = coarse_cli_shuttling
        else:
            folder = tmp_path / moment
            proc = housingfe(*args, "--set", f'runup.mesh_moment="{moment}"', "--out", str(folder))
        assert proc.returncode == 0, proc.stderr
        assert ("mesh moment: the shuttling moment" in proc.stdout) == (moment == "shuttling")
        assert json.loads((folder / "runup.json").read_text())["mesh_moment"] == moment
        out[moment] = _rows(folder / "runup.csv")
    for ra, rb in zip(out["none"], out["shuttling"]):
        if ra["route"] == "tf_omega":
            assert ra["Lv_dB"] == rb["Lv_dB"]
    tooth = [(float(ra["Lv_tooth_dB"]), float(rb["Lv_tooth_dB"])) for ra, rb in zip(out["none"], out["shuttling"])
             if ra["route"] == "mesh_force"]
    assert max(b - a for a, b in tooth) > 3.0          # set A: the moment is not a small correction
    assert json.loads((coarse_cli_shuttling[1] / "runup.json").read_text())["mesh_friction"] == {
        "setting": "none", "applied": False, "mu": {}}
    # the sliding friction on top (runup.mesh_friction = 0.06): said and recorded; tf_omega moves only by the four
    # static vectors the Ritz space gains; mesh_force's total moves by up to a few dB (set A: about +-1 dB)
    proc = housingfe(*args, "--set", "runup.mesh_friction=0.06", "--out", str(tmp_path / "friction"))
    assert proc.returncode == 0, proc.stderr
    assert "mesh friction: the sliding friction (runup.mesh_friction), mu 0.060 fixed, is applied" in proc.stdout
    record = json.loads((tmp_path / "friction" / "runup.json").read_text())["mesh_friction"]
    assert record == {"setting": 0.06, "applied": True, "mu": {"2000": [0.06, 0.06]}}
    rows = _rows(tmp_path / "friction" / "runup.csv")
    moved = []
    for ra, rb in zip(out["shuttling"], rows):
        if ra["route"] == "tf_omega":
            assert float(rb["Lv_dB"]) == pytest.approx(float(ra["Lv_dB"]), abs=0.01)
        else:
            moved.append(abs(float(rb["LwA_dB"]) - float(ra["LwA_dB"])))
    assert 0.05 < max(moved) < 6.0


def test_friction_lines_are_the_resultants_harmonics_of_fresh_load_distributions():
    """Lines.friction (runup.mesh_friction): harmonic n of each sliding-friction resultant / sqrt 2 of load
    distributions computed afresh (housingfe.source.mesh_friction.friction_curve) at the source's positions; the
    mesh excitation itself is unchanged (first order); "iso13989" scales them by ISO/TR 13989-1's mu per speed,
    which goes as v^-0.2 below the standard's 50 m/s cap; "none" leaves them out."""
    from housingfe.drivetrain.description import FRICTION_LOADS
    from housingfe.source.mesh_friction import friction_curve
    from housingfe.source.stiffness import normal_force_from_torque

    src = test_gearbox("A").source_model()
    speeds = [250.0, 1300.0]
    lines, _ = source_lines(src, speeds, [2000.0], 2000.0, mesh_moment="shuttling", mesh_friction=0.06)
    plain, _ = source_lines(src, speeds, [2000.0], 2000.0, mesh_moment="shuttling")
    assert plain.friction is None and plain.friction_mu is None
    assert set(plain.mesh_amplitudes()) == {"mesh", "shuttle"}
    assert set(lines.mesh_amplitudes()) == {"mesh", "shuttle", *FRICTION_LOADS.values()}
    np.testing.assert_array_equal(plain.mesh_excitation, lines.mesh_excitation)
    np.testing.assert_array_equal(plain.shuttle_moment, lines.shuttle_moment)
    F = normal_force_from_torque(src.pair, 2000.0)
    fresh = friction_curve(src.mesh_model, F, 0.06, src.stiffness_positions)
    H = int(lines.harmonic.max())
    for resultant, name in FRICTION_LOADS.items():
        ref = fresh.harmonics(resultant, H)[lines.harmonic - 1] / math.sqrt(2.0)
        np.testing.assert_allclose(lines.friction[name], ref, rtol=1e-9, atol=1e-9 * np.abs(ref).max())
    np.testing.assert_array_equal(lines.friction_mu, 0.06)
    # set A at 2000 N m, mu 0.06: the friction force's first harmonic is tens of N (0.06 of a ~30 kN force's split)
    assert 10.0 < abs(lines.friction["friction_force"][0]) * math.sqrt(2.0) < 1000.0
    iso, _ = source_lines(src, speeds, [2000.0], 2000.0, mesh_moment="shuttling", mesh_friction="iso13989")
    mu = {s: iso.friction_mu[iso.speed == s] for s in speeds}
    assert mu[250.0][0] / mu[1300.0][0] == pytest.approx((1300.0 / 250.0) ** 0.2, rel=1e-12)
    assert 0.03 < mu[1300.0][0] < mu[250.0][0] < 0.15
    for name in FRICTION_LOADS.values():
        np.testing.assert_allclose(iso.friction[name], lines.friction[name] * iso.friction_mu / 0.06, rtol=1e-12)


@pytest.mark.slow
def test_friction_loads_through_the_mesh_force_route(coarse):
    """runup.mesh_friction = 0.06 on the coarse gearbox: the model built with friction holds the four unit loads
    (the default one does not), the mesh_force route's L_v is the superposition of the six unit responses with the
    lines' amplitudes (1e-9 dB), that Ritz reduction agrees with a direct solve of the full model within 0.3 dB,
    the re-analysis keeps the loads, and a model without them refuses friction."""
    from housingfe.errors import InputError
    from housingfe.runup.chain import has_friction_loads, run_source

    gm0, src, _, _ = coarse
    assert set(gm0.reduction.names) == {"wheel_torque", "mesh", "shuttle"} and not has_friction_loads(gm0)
    gm = build_gearbox_model(gm0.housing_model, gm0.drivetrain, F_LINES, radiators=gm0.radiators, friction=True)
    # their static vectors join (one of the four may already lie in the span of the others and the bearing pairs)
    assert has_friction_loads(gm) and len(gm.reduction.vectors) >= len(gm0.reduction.vectors) + 3
    lines, _ = run_source(gm, src, [1100.0], [2000.0], F_LINES, "rigid-bores", "shuttling", 0.06)
    f = lines.frequency
    res = runup(gm, None, [1100.0], [2000.0], routes=("mesh_force",), lines=lines)
    amps = lines.mesh_amplitudes()
    c = sum(gm.reduction.unit_coordinates(f, name) * np.asarray(a)[None, :] for name, a in amps.items())
    np.testing.assert_allclose(res.routes["mesh_force"].L_v, gm.reduction.response_of(f, c).velocity_level_db,
                               rtol=0, atol=1e-9)
    loads, _, _ = unit_loads(gm.structure, gm.drivetrain, friction=True)
    eta = 0.08
    red = RitzReduction(gm.basis, loads, loss_factor(eta), nodes=(gm.wheel_node,))
    ours = red.evaluate(f, amps).velocity_level_db
    friction_only = red.evaluate(f, {k: v for k, v in amps.items() if k.startswith("friction_")}).velocity_level_db
    ref = harmonic_response(gm.structure, [Load(k, loads[k], (f, a)) for k, a in amps.items()], loss_factor(eta), f,
                            solver="direct")
    np.testing.assert_allclose(ours, ref.velocity_level_db, atol=0.3)
    assert np.max(friction_only) > np.max(ours) - 30.0        # not negligible at mu 0.06
    assert has_friction_loads(with_drivetrain(gm, with_torque(gm.drivetrain, 1000.0)))
    with pytest.raises(InputError, match="mesh_friction: the gearbox model has no friction unit loads"):
        run_source(gm0, src, [1100.0], [2000.0], F_LINES, "rigid-bores", "shuttling", 0.06)
