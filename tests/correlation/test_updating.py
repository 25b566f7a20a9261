"""Model updating on a synthetic EMA: a free steel plate with known 'true' Young's modulus and thickness,
measured on a subset of points (normal direction only), one mode missed, 2 % shape noise and 0.2 % frequency
noise.  The modes are paired by MAC and both parameters are recovered within 1 %."""
import numpy as np
import pytest

from housingfe.correlation.points import computed_modes_at
from housingfe.correlation.uff import ModeSet, Nodes, write_uff
from housingfe.correlation.updating import (
    ParameterSpec,
    SceneEvaluator,
    TargetSpec,
    UpdateSpec,
    check_parameter_keys,
    evaluate_targets,
    fit,
)
from housingfe.errors import InputError
from tests.correlation.free_plate import PLATE_SCENE

E_TRUE, H_TRUE = 196e9, 0.0053
MASS_TRUE = 7850.0 * 0.4 * 0.3 * H_TRUE          # kg, exact for the block


@pytest.fixture(scope="module")
def synthetic(tmp_path_factory):
    from mpi4py import MPI

    from housingfe.scene import build_model_from_scene, load_housing_scene
    from housingfe.solvers.modal import modes

    folder = tmp_path_factory.mktemp("ema")
    scene = folder / "plate.toml"
    scene.write_text(PLATE_SCENE)
    sc, _ = load_housing_scene(str(scene), [f"material.youngs_modulus={E_TRUE}", f"geometry.h={H_TRUE}"])
    basis = modes(build_model_from_scene(sc, MPI.COMM_WORLD), 900.0)
    # 12 measured points on the top face, normal (z) direction: a 4 x 3 grid off the nodal lines' symmetry
    xs, ys = np.meshgrid([0.03, 0.14, 0.25, 0.37], [0.04, 0.16, 0.27])
    pts = np.column_stack([xs.ravel(), ys.ravel(), np.full(xs.size, H_TRUE)])
    channels = ModeSet(np.zeros(0), np.arange(1, 13), pts, np.tile([0.0, 0.0, 1.0], (12, 1)), np.zeros((12, 0)))
    truth = computed_modes_at(basis, channels)
    keep = [0, 1, 2, 4, 5, 6]                      # the EMA missed the 4th elastic mode
    rng = np.random.default_rng(7)
    shapes = truth.shapes[:, keep]
    shapes = shapes + 0.02 * np.abs(shapes).max(axis=0) * rng.standard_normal(shapes.shape)
    freqs = truth.frequencies_hz[keep] * (1 + 0.002 * rng.standard_normal(len(keep)))
    measured = ModeSet(freqs, channels.node_ids, pts, channels.directions, shapes, None)
    write_uff(folder / "ema.uff", Nodes(np.arange(1, 13), pts), measured)
    return scene, folder / "ema.uff", truth, keep


def _spec(scene, ema) -> UpdateSpec:
    return UpdateSpec(
        name="plate",
        parameters=[ParameterSpec(name="E", keys=["material.youngs_modulus"], lower=150e9, upper=260e9, start=210e9),
                    ParameterSpec(name="h", keys=["geometry.h"], lower=0.004, upper=0.0065, start=0.005)],
        targets=[TargetSpec(name="ema", scene=str(scene), kind="paired", measured=str(ema), sigma=0.005),
                 TargetSpec(name="mass", scene=str(scene), kind="mass", value=MASS_TRUE, sigma=0.005)],
        max_evaluations=30)


def test_synthetic_ema_is_paired_and_parameters_recovered(synthetic):
    scene, ema, truth, keep = synthetic
    evaluator = SceneEvaluator(_spec(scene, ema))
    # at the (wrong) start the modes are already paired one to one, the missed mode is left unpaired
    start = evaluate_targets(evaluator, np.array([210e9, 0.005]), {})
    pairing = start[0].model
    assert [(p.measured, p.computed) for p in pairing.pairs] == list(enumerate(keep))
    assert 3 in pairing.unpaired_computed
    assert min(p.mac for p in pairing.pairs) > 0.95
    result = fit(evaluator)
    E, h = result.values
    print(f"recovered E = {E / 1e9:.2f} GPa (true {E_TRUE / 1e9:.0f}) +- {result.std[0] / 1e9:.2f}, h = {h * 1e3:.4f} mm "
          f"(true {H_TRUE * 1e3:.1f}) +- {result.std[1] * 1e3:.4f}; {result.evaluations} evaluations, "
          f"{result.seconds_per_evaluation:.2f} s each; {result.status}")
    assert E == pytest.approx(E_TRUE, rel=0.01)
    assert h == pytest.approx(H_TRUE, rel=0.01)
    # the standard deviations from the Jacobian (frequency sigma 0.5 %, mass 0.5 %) are a few per cent at most
    # and cover the error within 3 sigma
    assert result.std[0] < 0.02 * E_TRUE and result.std[1] < 0.02 * H_TRUE
    assert abs(E - E_TRUE) < 3 * result.std[0] + 1e-3 * E_TRUE
    after = evaluate_targets(evaluator, result.values, {})[0].model
    assert [(p.measured, p.computed) for p in after.pairs] == list(enumerate(keep))
    assert after.mean_abs_error() < 0.003
    assert len(result.history) == result.evaluations and result.seconds_per_evaluation > 0


def test_measured_modal_damping_fits_the_loss_factor(synthetic, tmp_path):
    """Measured modal damping (UFF 55, zeta = 0.6 % +- 5 % noise per mode) fits the scene's loss factor through
    the paired target's damping residuals: eta = 2 zeta recovered within 3 %, the frequencies untouched."""
    from housingfe.correlation.uff import read_measured_modes

    scene, ema, _, _ = synthetic
    measured = read_measured_modes(str(ema))
    rng = np.random.default_rng(11)
    zeta = 0.006 * (1 + 0.05 * rng.standard_normal(len(measured.frequencies_hz)))
    damped = ModeSet(measured.frequencies_hz, measured.node_ids, measured.points, measured.directions,
                     measured.shapes, zeta)
    write_uff(tmp_path / "damped.uff", Nodes(measured.node_ids, measured.points), damped)
    spec = UpdateSpec(
        name="damping",
        parameters=[ParameterSpec(name="eta", keys=["damping.loss_factor"], lower=0.001, upper=0.1, start=0.03)],
        targets=[TargetSpec(name="ema", scene=str(scene), kind="paired", measured=str(tmp_path / "damped.uff"),
                            sigma=0.005, use_damping=True, sigma_damping=0.05)],
        scene_overrides={str(scene): ["damping.loss_factor=0.03", f"material.youngs_modulus={E_TRUE}",
                                      f"geometry.h={H_TRUE}"]},
        max_evaluations=12)
    check_parameter_keys(spec)
    evaluator = SceneEvaluator(spec)   # the model evaluations in the worker process, as `housingfe update` runs them
    try:
        result = fit(evaluator)
    finally:
        evaluator.close()
    eta = result.values[0]
    assert eta == pytest.approx(2 * np.exp(np.mean(np.log(zeta))), rel=0.03)
    assert result.std[0] < 0.05 * eta


def test_modal_damping_of_one_material_loss_factor_is_half_eta(synthetic):
    """Per-material loss factor (damping matrix D = eta K for one material): the modal strain energy gives
    zeta_k = phi_k^T D phi_k / (2 lambda_k) = eta / 2 for every elastic mode, to round-off."""
    from mpi4py import MPI

    from housingfe.correlation.updating import modal_damping_ratios
    from housingfe.scene import build_model_from_scene, load_housing_scene
    from housingfe.solvers.modal import modes

    scene, _, _, _ = synthetic
    sc, _ = load_housing_scene(str(scene), ["material.loss_factor=0.03"])
    model = build_model_from_scene(sc, MPI.COMM_WORLD)
    basis = modes(model, 900.0)
    zeta = modal_damping_ratios(sc.damping, model, basis)
    assert len(zeta) == len(basis.frequencies_hz) - basis.rigid_count >= 5
    np.testing.assert_allclose(zeta, 0.015, rtol=1e-8)


def test_unknown_parameter_key_is_input_error(synthetic):
    scene, ema, _, _ = synthetic
    spec = _spec(scene, ema)
    bad = spec.model_copy(update={"parameters": [ParameterSpec(name="h", keys=["geometry.thickness"],
                                                               lower=0.004, upper=0.006, start=0.005)]})
    with pytest.raises(InputError, match=r"plate.toml: geometry.thickness: unknown parameter key") as exc:
        check_parameter_keys(bad)
    assert "\n" not in str(exc.value)


def test_scene_overrides_introduce_a_parameter_key(synthetic):
    """A key no scene has (a region's modulus) is a parameter once the spec's scene_overrides introduce it; every
    evaluation applies scene_overrides first, then the search/confirmation overrides, then the parameters."""
    scene, ema, _, _ = synthetic
    rim = ParameterSpec(name="E_rim", keys=["regions.rim.youngs_modulus"], lower=1e9, upper=3e11, start=2e11)
    spec = _spec(scene, ema).model_copy(update={"parameters": [rim]})
    with pytest.raises(InputError, match="regions.rim.youngs_modulus: unknown parameter key"):
        check_parameter_keys(spec)
    introduced = ["regions.rim.name=steel", "regions.rim.youngs_modulus=2.1e11"]
    spec = spec.model_copy(update={"scene_overrides": {str(scene): introduced}})
    check_parameter_keys(spec)
    evaluator = SceneEvaluator(spec, isolate=False)
    assert evaluator.overrides(str(scene), np.array([5e10]), ["mesh.size=0.1"]) == \
        introduced + ["mesh.size=0.1", "regions.rim.youngs_modulus=50000000000.0"]


def test_cli_no_paired_modes_is_one_line_error(synthetic, tmp_path, capsys):
    from housingfe.cli import main

    scene, _, _, _ = synthetic
    rng = np.random.default_rng(3)
    rows = ["mode,frequency_hz,point,x,y,z,dx,dy,dz,value"]
    grid = [(x, y) for x in (0.03, 0.11, 0.2, 0.29, 0.37) for y in (0.03, 0.11, 0.19, 0.27)]
    for mode in (1, 2):          # white-noise 'shapes' on 20 points: no smooth plate mode looks like them
        for p, (x, y) in enumerate(grid):
            rows.append(f"{mode},{300.0 * mode},{p + 1},{x},{y},0.005,0,0,1,{rng.standard_normal()}")
    (tmp_path / "bad.csv").write_text("\n".join(rows) + "\n")
    code = main(["correlate", str(scene), "--measured", str(tmp_path / "bad.csv"), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1
    assert "bad.csv: no measured mode pairs" in err
    assert not (tmp_path / "out").exists()


def test_cli_correlate_and_export_round_trip(synthetic, tmp_path, capsys):
    """Our exported UFF read back as 'measured' correlates with the same model: every mode paired with
    itself at MAC ~ 1 and zero frequency error."""
    from housingfe.cli import main

    scene, _, _, _ = synthetic
    assert main(["correlate", str(scene), "--export", str(tmp_path / "ours.uff"), "--points", "16"]) == 0
    assert main(["correlate", str(scene), "--measured", str(tmp_path / "ours.uff"), "--out", str(tmp_path / "c")]) == 0
    rows = np.loadtxt(tmp_path / "c" / "pairs.csv", delimiter=",", skiprows=1)
    assert np.array_equal(rows[:, 0], rows[:, 2])               # measured i paired with computed i
    assert np.all(rows[:, 5] > 0.999) and np.all(np.abs(rows[:, 4]) < 1e-3)
    assert (tmp_path / "c" / "mac.png").is_file() and (tmp_path / "c" / "computed.uff").is_file()
    # the exported point receptances against the modal receptances of the correlated basis (more modes: up to
    # 1.25 x the highest exported one) at the same channels
    frac = np.loadtxt(tmp_path / "c" / "frf.csv", delimiter=",", skiprows=1, usecols=4)
    assert len(frac) == 48 and np.all(frac > 0.99)
