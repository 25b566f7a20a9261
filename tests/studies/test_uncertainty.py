"""`housingfe uncertainty` (issue 28, item 5): seeded samples over the estimated inputs through the chain.

* the helix tolerance is ISO 1328-1's formula for quality 5 (hand-computed for set A's pinion);
* the Latin hypercube: the same seed gives the same samples, each uniform parameter has one sample per stratum,
  a zero-width range gives its value;
* on the coarse test gearbox (60 mm mesh, lines to 1.5 kHz, speeds 250-1500 rpm in 250 rpm steps, set A only):
  1 and 2 worker processes (mpi4py.futures) give the same numbers for the same seed; every range at zero width
  gives zero spread, equal to what `housingfe run` writes for the same scene;
* bad input as a user hits it: one line, exit 2, no result folder.
"""
from __future__ import annotations

import csv
import math
import re

import numpy as np
import pytest

from housingfe.errors import InputError
from housingfe.studies import uncertainty as unc
from tests.studies.runup_cli import cli_lwa_curves
from tests.test_cli import housingfe

COARSE = ('housing.set=["mesh.size=0.06"]', "runup.f_max_hz=1500", "runup.speed_min_rpm=250",
          "runup.speed_step_rpm=250")


def test_helix_tolerance_is_iso_1328_quality_5():
    # set A pinion (App. F): d = 98.145 mm, b = 66 mm -> 0.07 sqrt(d) + 0.45 sqrt(b) + 3.0 = 7.349 um
    assert unc.helix_slope_tolerance(0.098145, 0.066) == pytest.approx(7.3494e-6, rel=1e-4)
    # one quality step is a factor sqrt(2)
    assert unc.helix_slope_tolerance(0.1, 0.05, 6) / unc.helix_slope_tolerance(0.1, 0.05, 5) == pytest.approx(
        math.sqrt(2.0))


def test_latin_hypercube_samples():
    from housingfe.runup.scene import load_runup_scene

    scene, _ = load_runup_scene("test-gearbox-runup")
    a = unc.draw_samples(scene, 10, seed=3)
    assert a == unc.draw_samples(scene, 10, seed=3)
    assert a != unc.draw_samples(scene, 10, seed=4)
    for name, p in unc.PARAMETERS.items():
        if name in unc.OPT_IN:                     # not drawn without --range (test_the_mount_is_opt_in)
            assert {s[name] for s in a} == {None}, name
            continue
        if p.distribution == "uniform":            # one sample in each tenth of the range
            strata = sorted(int((s[name] - p.low) / (p.high - p.low) * 10) for s in a)
            assert strata == list(range(10)), name
        if p.distribution == "loguniform":
            strata = sorted(int(math.log(s[name] / p.low) / math.log(p.high / p.low) * 10) for s in a)
            assert strata == list(range(10)), name
    fixed = unc.draw_samples(scene, 4, seed=3, ranges=unc.parse_ranges(["damping_ratio=0.03", "radiation=foller"]))
    assert {s["damping_ratio"] for s in fixed} == {0.03}
    assert {s["radiation"] for s in fixed} == {"foller"}
    with pytest.raises(InputError, match="unknown parameter"):
        unc.parse_ranges(["stiffness=1:2"])
    with pytest.raises(InputError, match="low 2 above high 1"):
        unc.parse_ranges(["groove_inner=2:1"])


def test_every_range_lies_within_what_its_input_can_be():
    """Each numeric parameter has physical limits (a --range outside them is refused when read) and its own
    range and nominal value lie inside them; the edges behave as stated (open or closed)."""
    numeric = {name for name, p in unc.PARAMETERS.items() if p.distribution not in ("choice", "side")}
    assert set(unc.PHYSICAL_LIMITS) == numeric
    for name in numeric:
        p = unc.PARAMETERS[name]
        assert unc.parse_ranges([f"{name}={p.low!r}:{p.high!r}"]) == {name: (p.low, p.high)}
        if p.nominal is not None:
            assert unc.parse_ranges([f"{name}={p.nominal!r}"]) == {name: (p.nominal, p.nominal)}
    assert unc.parse_ranges(["clearance_position=0:1"]) == {"clearance_position": (0.0, 1.0)}
    for item in ("groove_outer=0.5:0.53", "damping_ratio=0.02:1", "helix_deviation_wheel=-12:0",
                 "spherical_contact_angle_deg=0:90", "quill_diameter_scale=0:1"):
        with pytest.raises(InputError, match=f"--range {item.split('=')[0]}: .*must be"):
            unc.parse_ranges([item])


# The parameter list before the mount (2026-11-27): name, distribution, low, high.  What `draw_samples` gave for a
# seed then is u = LatinHypercube(d=15, seed).random(n), column j mapped onto the j-th range (radiation: one of the
# scene's models, equally likely) - the draws docs/runup.md quotes (`--samples 24 --seed 1`).
OLD_PARAMETERS = (
    ("damping_ratio", "loguniform", 0.02, 0.08), ("radiation", "choice", 0.0, 1.0),
    ("clearance_position", "uniform", 0.0, 1.0), ("groove_inner", "uniform", 0.51, 0.53),
    ("groove_outer", "uniform", 0.52, 0.54), ("spherical_contact_angle_deg", "uniform", 7.0, 11.0),
    ("tapered_e_scale", "uniform", 0.85, 1.15), ("quill_diameter_scale", "uniform", 0.8, 1.25),
    ("quill_length_scale", "loguniform", 0.5, 2.0), ("coupling_inertia_scale", "loguniform", 0.5, 2.0),
    ("lumped_bearing_span_m", "uniform", 0.045, 0.075), ("appendix_c_bearing_scale", "loguniform", 0.7, 1.4),
    ("source_loss_factor", "loguniform", 0.05, 0.2), ("helix_deviation_pinion", "uniform", -1.0, 1.0),
    ("helix_deviation_wheel", "uniform", -1.0, 1.0))


def old_draws(models, n, seed):
    from scipy.stats import qmc

    u = qmc.LatinHypercube(d=len(OLD_PARAMETERS), seed=seed).random(n)
    out = [{} for _ in range(n)]
    for j, (name, dist, lo, hi) in enumerate(OLD_PARAMETERS):
        for i in range(n):
            out[i][name] = (models[min(int(u[i, j] * len(models)), len(models) - 1)] if dist == "choice"
                            else lo * (hi / lo) ** u[i, j] if dist == "loguniform" else lo + (hi - lo) * u[i, j])
    return out


def test_the_mount_is_opt_in():
    """Without --range mount_stiffness_N_per_m every seed draws what it drew before the mount existed (the fixed
    feet: None); with it, the other inputs are still those draws and the mount is a log-uniform Latin hypercube of
    its own (one sample per tenth of log K_v over 1e8 ... 1e10 N/m)."""
    from housingfe.runup.scene import load_runup_scene

    scene, _ = load_runup_scene("test-gearbox-runup")
    models = list(scene.radiation.models)
    mount = unc.parse_ranges(["mount_stiffness_N_per_m=1e8:1e10"])
    for seed, n in ((1, 24), (0, 8), (7, 10)):
        old = old_draws(models, n, seed)
        for ranges in (None, mount):
            new = unc.draw_samples(scene, n, seed, ranges)
            assert [set(s) - {*unc.OPT_IN, *unc.SIDES} for s in new] == [set(s) for s in old]
            for a, b in zip(new, old):
                b = dict(b)
                assert a["radiation"] == b.pop("radiation")
                assert {k: a[k] for k in b} == pytest.approx(b, rel=1e-15, abs=1e-15), (seed, ranges)
        assert {s[unc.MOUNT] for s in unc.draw_samples(scene, n, seed)} == {None}
        kv = [s[unc.MOUNT] for s in unc.draw_samples(scene, n, seed, mount)]
        assert sorted(int(math.log10(k / 1e8) / 2.0 * n) for k in kv) == list(range(n))
    assert unc.nominal_ranges(scene).keys().isdisjoint(unc.OPT_IN)        # the deterministic run: the fixed feet
    fixed = unc.draw_samples(scene, 3, 1, unc.parse_ranges(["mount_stiffness_N_per_m=3e8"]))
    assert [s[unc.MOUNT] for s in fixed] == [3e8] * 3


def test_the_floating_axial_ratio_is_the_second_opt_in_input():
    """floating_axial_ratio (drivetrain.floating_axial_ratio) is drawn only with --range, from the second opt-in
    stream: every other column of a seed (the old inputs, the sides, the mount with or without its range) is what
    the seed drew without it; drawn, it is a uniform Latin hypercube (one sample per tenth of -0.2 ... 0.2)."""
    from housingfe.runup.scene import load_runup_scene

    scene, _ = load_runup_scene("test-gearbox-runup")
    models = list(scene.radiation.models)
    assert unc.OPT_IN == (unc.MOUNT, unc.FLOATING_AXIAL)
    ratio = unc.parse_ranges(["floating_axial_ratio=-0.2:0.2"])
    mount = unc.parse_ranges(["mount_stiffness_N_per_m=1e8:1e10"])
    for seed, n in ((1, 24), (0, 8), (7, 10)):
        for others in ({}, mount):
            without = unc.draw_samples(scene, n, seed, others)
            drawn = unc.draw_samples(scene, n, seed, {**others, **ratio})
            assert {s[unc.FLOATING_AXIAL] for s in without} == {None}
            assert [{k: v for k, v in s.items() if k != unc.FLOATING_AXIAL} for s in drawn] == \
                [{k: v for k, v in s.items() if k != unc.FLOATING_AXIAL} for s in without]
            r = [s[unc.FLOATING_AXIAL] for s in drawn]
            assert sorted(int((x + 0.2) / 0.4 * n) for x in r) == list(range(n))
        for a, b in zip(unc.draw_samples(scene, n, seed, ratio), old_draws(models, n, seed)):
            assert a["radiation"] == b.pop("radiation")
            assert {k: a[k] for k in b} == pytest.approx(b, rel=1e-15, abs=1e-15)
    assert unc.nominal_ranges(scene).keys().isdisjoint({unc.FLOATING_AXIAL})
    assert [s[unc.FLOATING_AXIAL] for s in unc.draw_samples(scene, 3, 1, unc.parse_ranges(
        ["floating_axial_ratio=0.1"]))] == [0.1] * 3
    for item in ("floating_axial_ratio=-0.35:0.2", "floating_axial_ratio=0.31"):
        with pytest.raises(InputError, match="--range floating_axial_ratio: .*must be within"):
            unc.parse_ranges([item])


def test_a_sample_s_floating_axial_ratio_reaches_its_drivetrain():
    """perturbed_drivetrain puts a drawn ratio on the configurations whose floating bearings carry an axial load
    (the bearings family), leaves it out of those that carry none (double helical: cylindrical roller, fluid film),
    and leaves the scene's (0) where it was not drawn."""
    from types import SimpleNamespace

    from housingfe.runup.scene import load_runup_scene

    scene, _ = load_runup_scene("test-gearbox-runup")
    base = SimpleNamespace(session=SimpleNamespace(scene=scene), surfaces={})
    values = {**{k: v[0] for k, v in unc.nominal_ranges(scene).items()}, unc.MOUNT: None}
    for ratio, bearings, gear_set, want in ((-0.12, "ball", "A", -0.12), (0.12, "tapered_roller", "B", 0.12),
                                            (0.12, "cylindrical_roller", "double_helical", 0.0),
                                            (None, "self_aligning", "B", 0.0)):
        dt = unc.perturbed_drivetrain(base, {**values, unc.FLOATING_AXIAL: ratio}, gear_set, bearings, 1000.0)
        assert dt.floating_axial_ratio == want, bearings


def test_the_wheel_locating_side_is_a_fair_seeded_draw():
    """The wheel's locating side where the thesis does not state it (ball, self-aligning; Sec. 5.8) is drawn per
    sample: front or back with probability 1/2 each (over 400 seeds, one sample each, the share of "back" lies
    within 0.5 +- 0.075, 3 s.d. of a fair coin; n = 24 samples of one seed hold 12 of each, the draw being
    stratified), the two configurations' sides independently (they differ in some samples), reproducible from the
    seed, and the other inputs are what the seed drew before the side existed (old_draws)."""
    from housingfe.runup.scene import load_runup_scene

    scene, _ = load_runup_scene("test-gearbox-runup")
    assert set(unc.SIDES) == {"wheel_locating_ball", "wheel_locating_self_aligning"}
    models = list(scene.radiation.models)
    for name in unc.SIDES:
        singles = [unc.draw_samples(scene, 1, seed)[0][name] for seed in range(400)]
        assert set(singles) == {"front", "back"}
        assert abs(singles.count("back") / 400 - 0.5) < 0.075, name
    a = unc.draw_samples(scene, 24, seed=5)
    assert a == unc.draw_samples(scene, 24, seed=5)
    for name in unc.SIDES:
        assert [s[name] for s in a].count("back") == 12, name
    assert any(s["wheel_locating_ball"] != s["wheel_locating_self_aligning"] for s in a)
    assert [s["wheel_locating_ball"] for s in a] != [s["wheel_locating_ball"] for s in unc.draw_samples(scene, 24, 6)]
    for new, old in zip(a, old_draws(models, 24, 5)):
        assert new["radiation"] == old.pop("radiation")
        assert {k: new[k] for k in old} == pytest.approx(old, rel=1e-15, abs=1e-15)
    # fixed: by --range, by an explicit scene side; the deterministic run's side (nominal_ranges) is front
    pinned = unc.draw_samples(scene, 6, 5, unc.parse_ranges(["wheel_locating_ball=back"]))
    assert {s["wheel_locating_ball"] for s in pinned} == {"back"}
    free = unc.draw_samples(scene, 6, 5)                 # pinning one side leaves the other's draws as they were
    assert [s["wheel_locating_self_aligning"] for s in pinned] == [s["wheel_locating_self_aligning"] for s in free]
    back, _ = load_runup_scene("test-gearbox-runup", ["drivetrain.wheel_locating=back"])
    assert {s[n] for s in unc.draw_samples(back, 8, 5) for n in unc.SIDES} == {"back"}
    assert {n: unc.nominal_ranges(scene)[n] for n in unc.SIDES} == {n: ("front",) for n in unc.SIDES}
    with pytest.raises(InputError, match="--range wheel_locating_ball: middle: not a bearing side"):
        unc.parse_ranges(["wheel_locating_ball=middle"])


@pytest.fixture
def process_cache():
    """The process's cache of bases (`_STATE`) and of the current mount (`_MOUNT`), restored after the test."""
    saved_state, saved_mount = dict(unc._STATE), dict(unc._MOUNT)
    yield
    unc._STATE.clear()
    unc._STATE.update(saved_state)
    unc._MOUNT.clear()
    unc._MOUNT.update(saved_mount)


def test_a_mount_drops_the_previous_mounts_bases(process_cache):
    """A process holds the bases of one mount at a time: a sample of another mount value drops them first (no
    FE here: the state is the process's cache)."""
    from types import SimpleNamespace

    from mpi4py import MPI

    unc._MOUNT.clear()
    pool = unc._mount_pool(1e9, MPI.COMM_SELF)
    unc._STATE["mount-1e9"] = SimpleNamespace(session=SimpleNamespace(housing_model=None))   # not built
    unc._MOUNT["keys"].add("mount-1e9")
    assert unc._mount_pool(1e9, MPI.COMM_SELF) is pool and "mount-1e9" in unc._STATE      # same mount: kept
    other = unc._mount_pool(3e8, MPI.COMM_SELF)
    assert other is not pool and "mount-1e9" not in unc._STATE and unc._MOUNT["keys"] == set()


def test_a_mount_frees_its_dropped_housing_fields(capfd, process_cache):
    """Dropping a mount's bases frees the housing fields they dropped last (release_fe_garbage): dolfinx 0.5.2
    makes them on its IndexMap's own communicator, which no other cleanup reaches; before, each rebuilt base left
    them (~12 MB per base on the 80 mm test gearbox mesh).  A small block's field stands in for a basis'."""
    import gc
    from types import SimpleNamespace

    from dolfinx import fem, la
    from mpi4py import MPI

    from housingfe.scene import build_model_from_scene
    from tests.drivetrain.test_coupling import block_scene, garbage_entries

    model = build_model_from_scene(block_scene(2.1e11), MPI.COMM_SELF)
    V = model.V
    held = la.create_petsc_vector(V.dofmap.index_map, V.dofmap.index_map_bs)     # holds their communicator
    comm = held.getComm()
    field_vector = fem.Function(V).vector            # a housing field, dropped at once: parked, not freed
    del field_vector
    gc.collect()
    assert garbage_entries(comm, capfd) == 1
    try:
        unc._MOUNT.clear()
        unc._mount_pool(1e9, MPI.COMM_SELF)
        unc._STATE["mount-1e9"] = SimpleNamespace(session=SimpleNamespace(housing_model=model))
        unc._MOUNT["keys"].add("mount-1e9")
        del model
        unc._mount_pool(3e8, MPI.COMM_SELF)          # another mount: drops the bases and frees their fields
        assert garbage_entries(comm, capfd) == 0
    finally:
        held.destroy()


TWO_SCENES_DROP = """
import gc
from types import SimpleNamespace

from dolfinx import fem, la
from mpi4py import MPI
from petsc4py import PETSc

from housingfe.scene import build_model_from_scene
from housingfe.studies import uncertainty as unc
from tests.drivetrain.test_coupling import block_scene

unc._mount_pool(1e9, MPI.COMM_WORLD)
for round in range(3):
    shared, other = (build_model_from_scene(block_scene(E), MPI.COMM_WORLD) for E in (2.1e11, 1.0e11))
    held = [la.create_petsc_vector(m.V.dofmap.index_map, m.V.dofmap.index_map_bs) for m in (shared, other)]
    fields = [fem.Function(m.V).vector for m in (shared, other)]
    del fields
    gc.collect()
    for h in held:
        PETSc.garbage_view(h.getComm())
    for key, m in (("single helical", shared), ("double helical", shared), ("other", other)):
        unc._STATE[key] = SimpleNamespace(session=SimpleNamespace(housing_model=m))
        unc._MOUNT["keys"].add(key)
    del shared, other, m
    unc._mount_pool(3e8 + round, MPI.COMM_WORLD)          # the next mount: drops the three bases, two models
    for h in held:
        PETSc.garbage_view(h.getComm())
        h.destroy()
print("dropped", flush=True)
"""


@pytest.mark.parametrize("ranks", [None, pytest.param(2, marks=pytest.mark.mpi)])
def test_a_mount_of_two_scenes_sharing_a_housing_model_is_dropped_safely(ranks):
    """--family all: the single and the double helical scene of a mount share one housing model (ModelPool), so the
    drop meets it twice.  Cleaning its communicator's garbage twice through K's handle segfaulted at the first drop
    (2026-11-27: the handle dangles once the first cleanup freed the last object on it); now each model is cleaned
    once through a probe that keeps the communicator, in the same order on every rank.  Three drops, a subprocess
    (a segfault must fail this test, not end the session); the housing fields dropped before are freed (garbage
    list: 1 entry before, 0 after, for each model)."""
    import os
    import shutil
    import subprocess
    import sys

    cmd = [sys.executable, "-c", TWO_SCENES_DROP]
    if ranks:
        if not shutil.which("mpirun"):
            pytest.skip("mpirun not installed")
        cmd = [shutil.which("mpirun"), "-n", str(ranks), *cmd]
    env = {**os.environ, "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OPENBLAS_NUM_THREADS": "1"}
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=300)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert proc.stdout.count("dropped") == (ranks or 1)
    entries = [int(n) for n in re.findall(r"Total entries: (\d+)", proc.stdout)]
    n = 2 * (ranks or 1)                    # garbage_view prints each rank's list of the two models' communicators
    assert entries == ([1] * n + [0] * n) * 3


def test_a_sample_with_a_mount_runs_on_the_housing_on_that_frame(process_cache):
    """A sample with K_v = 1e8 N/m runs on a housing model and basis of its own whose lowest modes are the
    gearbox's six rigid-body modes on the frame: below 160 Hz (frame_mount, default mesh: 48-146 Hz; the fixed
    feet's lowest mode apart from the drive line's torsion at 76 Hz is 212 Hz), the bounce within 10 % of the
    rigid mass on a spring, sqrt(K_v / m) / 2 pi with m = 169.4 kg (the coupled gearbox, frame_mount README);
    K_v spread by the model over the two feet of 0.075 x 0.490 m.  Coarsest mesh (80 mm), lines to 600 Hz."""
    from housingfe.runup.scene import load_runup_scene

    overrides = ('housing.set=["mesh.size=0.08"]', "runup.f_max_hz=600", "runup.speed_min_rpm=250",
                 "runup.speed_step_rpm=250")
    kv = 1e8
    scene, _ = load_runup_scene("test-gearbox-runup", list(overrides))
    values = unc.draw_samples(scene, 1, 2, unc.parse_ranges([f"mount_stiffness_N_per_m={kv:g}"]))[0]
    mounted = unc.mount_overrides("test-gearbox-runup", overrides, kv)
    sets = json_list(mounted[-1])            # the scene's own housing.set stays, then supports.0 on the bed
    assert sets[:2] == ["mesh.size=0.08", "supports.0.kind=elastic"]
    assert float(sets[2].removeprefix("supports.0.total_normal_stiffness=")) == pytest.approx(kv, rel=1e-12)
    assert float(sets[3].removeprefix("supports.0.total_tangential_stiffness=")) == pytest.approx(kv / 3, rel=1e-12)
    m = unc.evaluate_sample("test-gearbox-runup", overrides, values, ())
    assert m["mount"] and m["setup_s"] > 0                   # its own base, built for the sample
    assert len(unc._MOUNT["keys"]) == 1
    base = unc._STATE[next(iter(unc._MOUNT["keys"]))]
    assert base.session.scene.housing.set == list(json_list(mounted[-1]))
    f = np.asarray(base.model.basis.frequencies_hz)
    below = f[f < 160.0]
    assert len(below) == 7 and below[0] < 60.0              # six mount modes and the drive line's torsion
    bounce = math.sqrt(kv / 169.4) / (2 * math.pi)
    assert np.min(np.abs(below / bounce - 1.0)) < 0.10
    assert np.isfinite(m["mesh_force/max_lwa_dBA"]) and m["checks"]


def json_list(override):
    import json

    return json.loads(override.split("=", 1)[1])


@pytest.fixture(scope="module")
def serial():
    return unc.run_uncertainty("test-gearbox-runup", 3, seed=7, workers=1, overrides=COARSE, families=())


@pytest.mark.slow
def test_one_and_two_workers_agree(serial, tmp_path):
    # two samples per process: the three samples run in two spawned processes, each with its own basis
    pooled = unc.run_uncertainty("test-gearbox-runup", 3, seed=7, workers=2, overrides=COARSE, families=(),
                                 samples_per_process=2)
    assert pooled.engine == "mpi4py.futures"
    assert pooled.samples == serial.samples
    assert len({m["pid"] for m in pooled.metrics}) == 2 and pooled.timings["processes"] == 2
    for key in serial.quantities:
        np.testing.assert_allclose(pooled.values(key), serial.values(key), rtol=0, atol=1e-9, err_msg=key)
    # the samples differ from each other: the ranges act
    assert np.ptp(serial.values("max_lwa_dBA")) > 0.1
    # the written result reads back with the same bands (the API the validate column uses)
    unc.write(tmp_path, serial)
    assert {p.name for p in tmp_path.iterdir()} >= {"samples.csv", "summary.csv", "summary.txt", "uncertainty.png",
                                                      "uncertainty.json"}
    loaded = unc.UncertaintyResult.load(tmp_path)
    for key in serial.quantities:
        np.testing.assert_array_equal(loaded.band(key), serial.band(key))


@pytest.mark.slow
def test_zero_width_ranges_give_the_deterministic_run(serial, tmp_path):
    from housingfe.runup.scene import load_runup_scene

    scene, _ = load_runup_scene("test-gearbox-runup", list(COARSE))
    res = unc.run_uncertainty("test-gearbox-runup", 2, seed=1, workers=1, overrides=COARSE, families=(),
                              ranges=unc.nominal_ranges(scene))
    for route, curve in cli_lwa_curves("test-gearbox-runup", COARSE, tmp_path / "run").items():
        p5, p50, p95 = res.band("max_lwa_dBA", route)
        assert p5 == p95 == p50
        assert p50 == pytest.approx(curve.max(), abs=2e-3)
        for m in res.metrics:
            np.testing.assert_allclose(m[f"{route}/lwa_curve_dBA"], curve, atol=2e-3)
        assert res.band("slope_dBA_per_doubling", route)[0] == res.band("slope_dBA_per_doubling", route)[2]


@pytest.mark.slow
def test_a_sample_with_the_wheel_located_at_the_back_is_the_run_with_that_side(tmp_path):
    """Two samples, every range at zero width but the ball's side (front, back: one each, the draw being
    stratified): the back sample, a re-analysis on the process's (front) basis, gives the L_WA curves `housingfe run
    --set drivetrain.wheel_locating=back` writes with a basis of its own, to 2e-3 dB (measured 2026-11-28: 6e-4 dB),
    and the side acts (the front sample differs by more than 3 dB somewhere on mesh_force; measured up to 10 dB)."""
    from housingfe.runup.scene import load_runup_scene

    scene, _ = load_runup_scene("test-gearbox-runup", list(COARSE))
    ranges = {**unc.nominal_ranges(scene), "wheel_locating_ball": ("front", "back")}
    res = unc.run_uncertainty("test-gearbox-runup", 2, seed=1, workers=1, overrides=COARSE, families=(),
                              ranges=ranges)
    sides = [s["wheel_locating_ball"] for s in res.samples]
    assert sorted(sides) == ["back", "front"]
    back, front = res.metrics[sides.index("back")], res.metrics[sides.index("front")]
    # one process, at most one basis for both sides (none when an earlier test of this process built it)
    assert res.timings["processes"] == 1 and sum(m["setup_s"] > 0 for m in res.metrics) <= 1
    run = cli_lwa_curves("test-gearbox-runup", COARSE + ("drivetrain.wheel_locating=back",), tmp_path / "run")
    for route, curve in run.items():
        np.testing.assert_allclose(back[f"{route}/lwa_curve_dBA"], curve, atol=2e-3, err_msg=route)
    assert np.max(np.abs(np.subtract(front["mesh_force/lwa_curve_dBA"], run["mesh_force"]))) > 3.0


@pytest.mark.slow
def test_a_sample_s_floating_axial_ratio_is_the_run_with_that_ratio(tmp_path):
    """One sample, every range at zero width and floating_axial_ratio = 0.15: the re-analysis on the process's
    (ratio 0) basis gives the L_WA curves `housingfe run --set drivetrain.floating_axial_ratio=0.15` writes with a
    basis of its own, to 2e-3 dB, and the ratio acts (tf_omega differs from the ratio-0 run by more than 3 dB
    somewhere; measured 12.2 dB on this coarse setting, 2026-11-28)."""
    from housingfe.runup.scene import load_runup_scene

    scene, _ = load_runup_scene("test-gearbox-runup", list(COARSE))
    ranges = {**unc.nominal_ranges(scene), unc.FLOATING_AXIAL: (0.15, 0.15)}
    res = unc.run_uncertainty("test-gearbox-runup", 1, seed=1, workers=1, overrides=COARSE, families=(),
                              ranges=ranges)
    assert res.samples[0][unc.FLOATING_AXIAL] == 0.15
    run = cli_lwa_curves("test-gearbox-runup", COARSE + ("drivetrain.floating_axial_ratio=0.15",), tmp_path / "run")
    for route, curve in run.items():
        np.testing.assert_allclose(res.metrics[0][f"{route}/lwa_curve_dBA"], curve, atol=2e-3, err_msg=route)
    plain = cli_lwa_curves("test-gearbox-runup", COARSE, tmp_path / "plain")
    assert np.max(np.abs(np.subtract(run["tf_omega"], plain["tf_omega"]))) > 3.0


@pytest.mark.parametrize("args, message", [
    (["--samples", "-3"], "uncertainty: --samples: -3: must be a whole number >= 1"),
    (["--range", "wheel_locating_ball=middle"], "--range wheel_locating_ball: middle: not a bearing side"),
    (["--range", "bearing_magic=1:2"], "--range bearing_magic: unknown parameter"),
    (["--family", "gears"], "--family gears: unknown"),
    (["--samples-per-process", "0"], "--samples-per-process: 0: must be >= 1"),
    (["--range", "radiation=numerical"], "--range radiation: numerical: not a radiation model of the scene"),
    (["--range", "mount_stiffness_N_per_m=0:1e9"], "--range mount_stiffness_N_per_m: 0: must be > 0"),
    (["--range", "mount_stiffness_N_per_m=-1e9"], "--range mount_stiffness_N_per_m: -1e+09: must be > 0"),
    (["--range", "floating_axial_ratio=-0.5:0.2"], "--range floating_axial_ratio: -0.5: must be within +-0.3"),
])
def test_bad_input_is_one_line_and_no_folder(tmp_path, args, message):
    out = tmp_path / "u"
    proc = housingfe("uncertainty", "--out", str(out), *args)
    assert proc.returncode == 2
    assert proc.stderr.strip().count("\n") == 0 and "Traceback" not in proc.stderr
    assert proc.stderr.startswith("housingfe: error:") and message in proc.stderr
    assert not out.exists()


def test_an_old_run_still_gives_the_bands_of_its_quantities():
    """A result written before the samples carried their check rows (no "checks" in the metrics): bands.json maps
    each sampled quantity to the check_id of its validate row (28.default.max_lwa.<route>, ...) with the 5-95 % band
    of the samples: 0..100 uniformly spaced gives (5, 95)."""
    values = np.linspace(0.0, 100.0, 101)
    metrics = [{"mesh_force/max_lwa_dBA": v, "mesh_force/slope_dBA_per_doubling": v / 10,
                "mesh_force/variant_mean_self_aligning_dB": -v} for v in values]
    result = unc.UncertaintyResult("test-gearbox-runup", 1, [{}] * len(values), metrics, ("mesh_force",),
                                   np.array([500.0]), (), {}, "processes", 1)
    bands = result.check_bands()
    sampled = {k for k, v in bands.items() if v["band"] is not None}
    assert sampled == {"28.default.max_lwa.mesh_force", "28.speed_law.mesh_force",
                       "28.variants.mean.bearings.self_aligning.mesh_force"}
    assert bands["28.default.max_lwa.mesh_force"]["band"] == pytest.approx([5.0, 95.0])
    assert bands["28.variants.mean.bearings.self_aligning.mesh_force"]["band"] == pytest.approx([-95.0, -5.0])
    # the excitation checks: no sampled input acts on them, said as such
    assert bands["28.excitation.envelope.A"]["note"].startswith("no sampled input acts on this")


def test_check_bands_from_the_samples_check_rows():
    """Each sample keeps its check rows ({check_id: {ours, passed}}): a numeric check gets the 5-95 % band of its
    values and the count of samples it passed in; a yes/no check (ours a ranking text) the count alone, k of the
    samples that judged it; a check missing in some samples says in how many it was computed."""
    n = 21
    metrics = []
    for i in range(n):
        checks = {"28.default.max_lwa.mesh_force": {"ours": 60.0 + i, "passed": "yes" if 60.0 + i >= 77.5 else "no"},
                  "28.variants.ranking.bearings.mean.tf_omega": {"ours": "a < b", "passed": "yes" if i % 7 == 0
                                                                 else "no"}}
        if i < 20:
            checks["28.l_omega.resonance"] = {"ours": 1400.0, "passed": "yes"}
        metrics.append({"checks": checks})
    result = unc.UncertaintyResult("test-gearbox-runup", 1, [{}] * n, metrics, ("mesh_force",), np.array([500.0]),
                                   (), {}, "processes", 1)
    bands = result.check_bands()
    top = bands["28.default.max_lwa.mesh_force"]
    assert top["band"] == pytest.approx([61.0, 79.0])            # 60..80 in steps of 1: 5 % = 61, 95 % = 79
    assert (top["passes"], top["samples"]) == (3, 21)            # 78, 79, 80
    ranking = bands["28.variants.ranking.bearings.mean.tf_omega"]
    assert ranking["band"] is None and (ranking["passes"], ranking["samples"]) == (3, 21)   # i = 0, 7, 14
    assert bands["28.l_omega.resonance"]["note"] == "computed in 20 of 21 samples"


@pytest.mark.slow
def test_every_sample_carries_the_default_chain_checks(serial, tmp_path):
    """Set A alone (--family none): each sample holds every check row of the default run-up, made by the row
    functions of `housingfe validate`; its max L_WA row is the sample's max L_WA; the written bands.json counts a
    check's passes from the per-sample rows (sample_checks.csv) and fills the band column of validate's rows."""
    from housingfe.verification import checks as ck

    expected = {"28.l_omega.flexible.500rpm", "28.l_omega.flexible.1000rpm", "28.l_omega.flexible.1500rpm",
                "28.l_omega.resonance"}
    for route in ("tf_omega", "mesh_force"):
        expected |= {f"28.default.{w}.{route}" for w in ("max_lwa", "max_lwa_harmonic", "peaks",
                                                         "no_high_harmonic_peak", "tooth_band.L_omega",
                                                         "tooth_band.L_v", "tooth_band.L_W")}
        expected.add(f"28.speed_law.{route}")
    for m in serial.metrics:
        assert set(m["checks"]) == expected
        for route in ("tf_omega", "mesh_force"):
            assert m["checks"][f"28.default.max_lwa.{route}"]["ours"] == pytest.approx(m[f"{route}/max_lwa_dBA"],
                                                                                       abs=0.051)
    unc.write(tmp_path, serial)
    with open(tmp_path / "sample_checks.csv") as fh:
        per_sample = list(csv.DictReader(fh))
    bands = ck.read_bands(tmp_path / "bands.json")
    for check_id in expected:
        mine = [r for r in per_sample if r["check_id"] == check_id]
        assert len(mine) == 3
        assert bands[check_id]["passes"] == sum(r["passed"] == "yes" for r in mine), check_id
    rows = [ck.check_row(c, "s", "q", 1.0, "-", "src") for c in sorted(expected)]
    assert ck.attach_bands(rows, bands) == len(expected)
    assert all(ck.band_text(r) != ck.NO_BAND and "samples" in ck.band_text(r) for r in rows)


# the 59 check rows of issue 28 in `housingfe validate --only runup-checks` (docs/runup.md)
ALL_CHECK_IDS = (
    ["28.replica.max_lwa"] + [f"28.replica.correction.{v}" for v in ("B", "C", "D", "uncorrected")]
    + [f"28.default.{w}.{r}" for r in ("tf_omega", "mesh_force")
       for w in ("max_lwa", "max_lwa_harmonic", "peaks", "no_high_harmonic_peak", "tooth_band.L_omega",
                 "tooth_band.L_v", "tooth_band.L_W")]
    + [f"28.excitation.envelope.{s}" for s in ("A", "B", "C", "D", "uncorrected", "double-helical")]
    + [f"28.speed_law.{r}" for r in ("tf_omega", "mesh_force")]
    + [f"28.l_omega.flexible.{s}rpm" for s in (500, 1000, 1500)] + ["28.l_omega.resonance"]
    + [f"28.variants.{w}.{r}" for r in ("tf_omega", "mesh_force")
       for w in ("mean.profile-corrections.B", "mean.profile-corrections.C", "mean.profile-corrections.D",
                 "correction_d", "mean.bearings.angular_contact", "mean.bearings.self_aligning",
                 "mean.bearings.tapered_roller", "ranking.bearings.mean", "ranking.bearings.max",
                 "mean.double-helical.fluid_film_at_2000", "ranking.rollers_vs_fluid_films.mean",
                 "ranking.rollers_vs_fluid_films.max", "torque_law.cylindrical_roller", "torque_law.fluid_film")])


@pytest.mark.slow
def test_all_families_give_every_check_row_a_band(tmp_path):
    """`housingfe uncertainty --family all` (one sample, coarse): bands.json holds an uncertainty statement for
    every one of the 59 check rows, so `validate --bands` leaves no "—"."""
    from housingfe.verification import checks as ck

    assert len(ALL_CHECK_IDS) == len(set(ALL_CHECK_IDS)) == 59
    out = tmp_path / "u"
    # three speeds (500, 1000, 1500 rpm: the l_omega.flexible rows' own) instead of six: the rows are asserted,
    # not their numbers, and the flexible rows need exactly these speeds
    speeds = COARSE[:2] + ("runup.speed_min_rpm=500", "runup.speed_step_rpm=500")
    proc = housingfe("uncertainty", "--samples", "1", "--seed", "2", "--family", "all", "--out", str(out),
                     *[x for s in speeds for x in ("--set", s)])
    assert proc.returncode == 0, proc.stderr
    bands = ck.read_bands(out / "bands.json")
    assert set(bands) == set(ALL_CHECK_IDS)
    rows = [ck.check_row(c, "s", "q", 1.0, "-", "src", measured=0.0) for c in ALL_CHECK_IDS]
    assert ck.attach_bands(rows, bands) == 59
    texts = {r["check_id"]: ck.band_text(r) for r in rows}
    assert ck.NO_BAND not in texts.values()
    assert texts["28.variants.ranking.rollers_vs_fluid_films.mean.tf_omega"] in (
        "passes in 0/1 samples", "passes in 1/1 samples")
    assert texts["28.excitation.envelope.A"].startswith("no sampled input acts on this")


NEVER_STARTS = """
import sys

from mpi4py.futures import MPIPoolExecutor

from housingfe.cli import main
from housingfe.studies import uncertainty as unc

# workers that never call MPI_Init (a "python" that sleeps): the spawn never returns
unc.POOL_START_S = 3.0
started = unc._started
unc._executor = lambda engine, workers, folder: started(
    MPIPoolExecutor(max_workers=workers, python_exe=sys.argv[1], mpi_info={"map_by": ":OVERSUBSCRIBE"}), workers)
raise SystemExit(main(sys.argv[2:]))
"""


@pytest.mark.mpi
def test_a_pool_that_never_starts_stops_with_one_line(tmp_path):
    """An mpi4py.futures pool whose workers never start (here a worker "python" that only sleeps) left the command
    waiting for ever, and even past a time-out the process could not end (its pool thread blocked in
    MPI_Comm_spawn; 2026-11-27).  Now: after POOL_START_S one error line, exit 2, no result folder, the process
    gone within seconds."""
    import os
    import subprocess
    import sys
    import time

    fake = tmp_path / "sleeping-python"
    fake.write_text("#!/bin/sh\nexec sleep 20\n")
    fake.chmod(0o755)
    out = tmp_path / "never"
    env = {**os.environ, "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OPENBLAS_NUM_THREADS": "1"}
    t0 = time.monotonic()
    proc = subprocess.run([sys.executable, "-c", NEVER_STARTS, str(fake), "uncertainty", "--samples", "2",
                           "--workers", "2", "--family", "none", "--set", 'housing.set=["mesh.size=0.08"]',
                           "--out", str(out)], capture_output=True, text=True, env=env, timeout=120)
    wall = time.monotonic() - t0
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert proc.returncode == 2, proc.stderr
    assert lines == ["housingfe: error: uncertainty: the mpi4py.futures pool of 2 worker(s) did not start within "
                     "3 s (MPI_Comm_spawn); try --engine processes"]
    assert not out.exists()
    assert wall < 60.0                      # not the sleeping workers' 20 s twice over, nor for ever


DIES = """
import os
import signal
import sys
import time

from housingfe.cli import main
from housingfe.studies import uncertainty as unc

# runs in the parent and, imported as the main module, in every worker: the worker given sample 2 kills itself
unc.POLL_S = 0.2
real_task = unc._task


def dying_task(folder, numbers, batch):
    if 2 in numbers:
        unc._note(folder, numbers)
        time.sleep(1.0)
        os.kill(os.getpid(), signal.SIGKILL)
    return real_task(folder, numbers, batch)


unc._task = dying_task
if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
"""


def _processes_with(tag: str) -> list[int]:
    """pids of the processes whose environment holds `tag` (this test's run and its workers)."""
    import os

    found = []
    for d in os.listdir("/proc"):
        try:
            with open(f"/proc/{d}/environ", "rb") as fh:
                if tag.encode() in fh.read():
                    found.append(int(d))
        except (OSError, ValueError):
            pass
    return found


@pytest.mark.mpi
@pytest.mark.parametrize("engine, pool", [("mpi", "mpi4py.futures"), ("processes", "concurrent.futures")])
def test_a_worker_that_dies_mid_sample_stops_with_one_line(tmp_path, engine, pool):
    """A worker killed (SIGKILL) while running its sample left engine "mpi" waiting for ever (mpi4py.futures never
    notices; 2026-11-27) and engine "processes" ending in a BrokenProcessPool traceback.  Now: within a few poll
    intervals one "housingfe: error:" line naming the dead worker's pid and its sample, exit 2, no result folder,
    no worker process left."""
    import os
    import re
    import subprocess
    import sys
    import time
    import uuid

    script = tmp_path / "dies.py"
    script.write_text(DIES)
    out = tmp_path / "dead"
    tag = f"HOUSINGFE_TEST_TAG={uuid.uuid4().hex}"
    env = {**os.environ, "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OPENBLAS_NUM_THREADS": "1", tag.split("=")[0]: tag.split("=")[1]}
    t0 = time.monotonic()
    proc = subprocess.run([sys.executable, str(script), "uncertainty", "--samples", "2", "--workers", "2",
                           "--engine", engine, "--family", "none", "--set", 'housing.set=["mesh.size=0.08"]',
                           "--out", str(out)], capture_output=True, text=True, env=env, timeout=120)
    wall = time.monotonic() - t0
    ours = [ln for ln in proc.stderr.splitlines() if ln.startswith("housingfe")]
    assert proc.returncode == 2, proc.stderr
    assert len(ours) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert re.fullmatch(rf"housingfe: error: uncertainty: worker pid \d+ of the {pool} pool died"
                        rf"{' [(]signal 9[)]' if engine == 'processes' else ''} while running sample 2; the run "
                        r"stopped, nothing written \(killed for memory\? try fewer --workers\)", ours[0]), ours[0]
    if engine == "processes":                       # Open MPI adds its own report of the dead worker
        assert proc.stderr.strip() == ours[0]
    assert not out.exists()
    left = _processes_with(tag)
    for _ in range(50):                             # Open MPI's daemon ends the spawned workers it still holds
        if not left:
            break
        time.sleep(0.1)
        left = _processes_with(tag)
    assert left == []
    assert wall < 30.0                              # ~4.3 s here: spawn, imports, 1 s into sample 2, 0.2 s poll


RAISES_EARLY = """
import sys

from housingfe.cli import main
from housingfe.studies import uncertainty as unc


def task(folder, numbers, batch):
    if 2 in numbers:                    # fails before anything of its own starts PETSc
        raise RuntimeError("sample 2 failed early")
    from petsc4py import PETSc          # what every sample does first (dolfinx)
    return [{"pid": PETSc.COMM_WORLD.getRank(), "seconds": 0.0}]


unc._task = task
if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
"""


@pytest.mark.mpi
def test_a_sample_failing_before_petsc_does_not_block_the_others(tmp_path):
    """PETSc starts collectively on the mpi4py.futures workers' COMM_WORLD: when it started in a worker's first
    sample, a sample that failed before it left the other workers blocked in PetscInitialize and the command
    waiting for ever (> 200 s, 2026-11-27).  The pool's initializer now starts it in every worker: the failure comes
    back (a traceback: a bug, not an input; exit 1) in seconds."""
    import os
    import subprocess
    import sys

    script = tmp_path / "raises.py"
    script.write_text(RAISES_EARLY)
    env = {**os.environ, "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OPENBLAS_NUM_THREADS": "1"}
    proc = subprocess.run([sys.executable, str(script), "uncertainty", "--samples", "2", "--workers", "2",
                           "--family", "none", "--set", 'housing.set=["mesh.size=0.08"]',
                           "--out", str(tmp_path / "r")], capture_output=True, text=True, env=env, timeout=60)
    assert proc.returncode == 1, proc.stderr
    assert proc.stderr.strip().endswith("RuntimeError: sample 2 failed early")
    assert not (tmp_path / "r").exists()
