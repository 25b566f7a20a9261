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

import numpy as np
import pytest

from housingfe.errors import InputError
from housingfe.studies import uncertainty as unc
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
    out = tmp_path / "run"
    proc = housingfe("run", "test-gearbox-runup", *[x for s in COARSE for x in ("--set", s)], "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    rows = list(csv.DictReader(open(out / "runup.csv")))
    for route in ("tf_omega", "mesh_force"):
        curve = np.array([float(r["LwA_dB"]) for r in rows if r["route"] == route and r["radiation"] == "erp"])
        p5, p50, p95 = res.band("max_lwa_dBA", route)
        assert p5 == p95 == p50
        assert p50 == pytest.approx(curve.max(), abs=2e-3)
        for m in res.metrics:
            np.testing.assert_allclose(m[f"{route}/lwa_curve_dBA"], curve, atol=2e-3)
        assert res.band("slope_dBA_per_doubling", route)[0] == res.band("slope_dBA_per_doubling", route)[2]


@pytest.mark.parametrize("args, message", [
    (["--samples", "-3"], "uncertainty: --samples: -3: must be a whole number >= 1"),
    (["--range", "bearing_magic=1:2"], "--range bearing_magic: unknown parameter"),
    (["--family", "gears"], "--family gears: unknown"),
    (["--samples-per-process", "0"], "--samples-per-process: 0: must be >= 1"),
    (["--range", "radiation=numerical"], "--range radiation: numerical: not a radiation model of the scene"),
])
def test_bad_input_is_one_line_and_no_folder(tmp_path, args, message):
    out = tmp_path / "u"
    proc = housingfe("uncertainty", "--out", str(out), *args)
    assert proc.returncode == 2
    assert proc.stderr.strip().count("\n") == 0 and "Traceback" not in proc.stderr
    assert proc.stderr.startswith("housingfe: error:") and message in proc.stderr
    assert not out.exists()


def test_check_bands_name_the_validate_check_rows_and_hold_the_5_95_percent_band():
    """bands.json maps each sampled quantity to the check_id of its validate row (28.default.max_lwa.<route>, ...)
    with the 5-95 % band of the samples: 0..100 uniformly spaced gives (5, 95)."""
    from housingfe.studies.uncertainty import UncertaintyResult

    values = np.linspace(0.0, 100.0, 101)
    metrics = [{"mesh_force/max_lwa_dBA": v, "mesh_force/slope_dBA_per_doubling": v / 10,
                "mesh_force/variant_mean_self_aligning_dB": -v} for v in values]
    result = UncertaintyResult("test-gearbox-runup", 1, [{}] * len(values), metrics, ("mesh_force",),
                               np.array([500.0]), (), {}, "processes", 1)
    bands = result.check_bands()
    assert set(bands) == {"28.default.max_lwa.mesh_force", "28.speed_law.mesh_force",
                          "28.variants.mean.bearings.self_aligning.mesh_force"}
    assert bands["28.default.max_lwa.mesh_force"] == pytest.approx((5.0, 95.0))
    assert bands["28.variants.mean.bearings.self_aligning.mesh_force"] == pytest.approx((-95.0, -5.0))
