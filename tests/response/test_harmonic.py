"""The harmonic-response stage (housingfe.response.harmonic): one load with a flat spectrum reproduces the
unit-load responses of the forced-response run (modal and direct solvers, surface and points, to 1e-12); loads
are summed coherently with their phases (a load cancels its copy shifted by pi; the parallelogram law
<v^2>(a + b) + <v^2>(a - b) = 2 <v^2>(a) + 2 <v^2>(b) holds, while <v^2>(a + b) is not the incoherent sum)."""
import numpy as np
import pytest

from housingfe.response.forced import run as run_forced
from housingfe.response.harmonic import Load, harmonic_response, loss_factor
from housingfe.response.observers import RESPONSE_POINTS
from housingfe.scene import build_model_from_scene
from housingfe.solvers import modal
from tests.conftest import load_scene
from tests.response.test_reduced import PLATE as TWO_LOAD_PLATE

# the Ritz-reduction tests' plate (FV12, 0.3 x 0.2 x 0.005 m, loads p1 and p2, modes to 1.5 kHz) with a harmonic run
PLATE = [*TWO_LOAD_PLATE, "analysis.harmonic.f_max=1500.0", "analysis.harmonic.f_min=100.0",
         "analysis.harmonic.df=100.0", "analysis.harmonic.sample_points=[]", 'analysis.harmonic.surface="top"', "damping.loss_factor=0.01",
         'analysis.harmonic.solver="both"', "analysis.harmonic.residual=true",
         'analysis.harmonic.points=[{name="c", point=[0.15, 0.1, 0.005]}]']
ETA = 0.01


@pytest.fixture(scope="module")
def plate(comm):
    scene = load_scene("nafems-fv12", *PLATE)
    model = build_model_from_scene(scene, comm)
    forced = run_forced(model, scene.analysis.harmonic, scene.loads, scene.damping)
    loads = [Load.from_spec(model, spec) for spec in scene.loads]
    basis = modal.modes(model, scene.analysis.harmonic.modal_basis_factor * scene.analysis.harmonic.f_max)
    return scene, model, forced, loads, basis


def test_one_flat_load_is_the_unit_load_response(plate):
    scene, model, forced, loads, basis = plate
    spec = scene.analysis.harmonic
    for solver, name, source in (("modal", "modal+residual", basis), ("direct", "direct", model)):
        ref = forced.responses[name][0]
        resp = harmonic_response(source, loads[0], loss_factor(ETA), spec.frequencies, surface="top",
                                 points=spec.points, solver=solver)
        assert resp.solver == name
        assert resp.area == pytest.approx(0.3 * 0.2, rel=1e-12)
        np.testing.assert_allclose(resp.mean_square_velocity(), ref.mean_square_velocity * ref.amplitude**2,
                                   rtol=1e-12, atol=0)
        np.testing.assert_allclose(resp.transfer_db(), ref.transfer_db, rtol=0, atol=1e-10)
        u = resp.at_points("displacement")["c"]
        np.testing.assert_allclose(u, ref.extras["point_values"][RESPONSE_POINTS], rtol=1e-12,
                                   atol=1e-12 * np.abs(u).max())
        omega = 2 * np.pi * spec.frequencies
        np.testing.assert_allclose(resp.at_points("velocity", "z")["c"], 1j * omega * u[2], rtol=1e-14)
        np.testing.assert_allclose(resp.at_points("acceleration", [0, 0, 2.0])["c"], -omega**2 * u[2],
                                   rtol=1e-12)


@pytest.mark.parametrize("solver", ["modal", "direct"])
def test_loads_are_summed_coherently(plate, solver):
    scene, model, forced, loads, basis = plate
    f = np.array([150.0, 450.0, 1250.0]) if solver == "direct" else scene.analysis.harmonic.frequencies
    source = basis if solver == "modal" else model
    phi = 0.7
    a, b = loads

    def ms(*items):
        return harmonic_response(source, list(items), loss_factor(ETA), f, surface="top", solver=solver)

    ra, rb = ms(a), ms(Load("p2", b.vector, 1.0))
    plus = ms(a, Load("p2+", b.vector, np.exp(1j * phi)))
    minus = ms(a, Load("p2-", b.vector, np.exp(1j * (phi + np.pi))))
    sum_single = ra.mean_square_velocity() + rb.mean_square_velocity()
    np.testing.assert_allclose(plus.mean_square_velocity() + minus.mean_square_velocity(), 2 * sum_single,
                               rtol=1e-10)
    # the phases matter: the coherent sum is not the incoherent one
    assert np.max(np.abs(plus.mean_square_velocity() / sum_single - 1)) > 0.05
    # a load cancels its own copy shifted by pi, whatever its spectrum
    spectrum = (np.array([100.0, 1500.0]), np.array([2.0 + 1.0j, -0.5j]))
    cancel = ms(Load("x", a.vector, spectrum),
                Load("-x", a.vector, lambda fr: -Load("x", a.vector, spectrum).amplitude(fr)))
    assert np.all(cancel.mean_square_velocity() < 1e-24 * ra.mean_square_velocity())


def test_complex_spectrum_scales_the_response(plate):
    scene, model, forced, loads, basis = plate
    f = scene.analysis.harmonic.frequencies
    spectrum = lambda fr: (fr / 1000.0) * np.exp(1j * fr / 300.0)
    unit = harmonic_response(basis, loads[1], ETA, f, surface="top")
    shaped = harmonic_response(basis, Load("s", loads[1].vector, spectrum, "N"), ETA, f, surface="top")
    np.testing.assert_allclose(shaped.mean_square_velocity(), np.abs(spectrum(f))**2 * unit.mean_square_velocity(),
                               rtol=1e-12)
    # TF = L_v - L_F does not depend on the spectrum
    np.testing.assert_allclose(shaped.transfer_db(), unit.transfer_db(), atol=1e-9)
    bands, levels = shaped.band_levels(100.0, 1500.0)
    assert len(levels) == len(bands.nominal) and np.nanmax(levels) > np.max(shaped.velocity_level_db) - 1e-9


def test_load_table_spectrum_interpolates_real_and_imaginary_parts():
    load = Load("t", None, (np.array([10.0, 20.0]), np.array([1.0 + 2.0j, 3.0 - 2.0j])))
    np.testing.assert_allclose(load.amplitude([10.0, 15.0, 20.0]), [1 + 2j, 2 + 0j, 3 - 2j])
    assert Load("f", None, 2.5).amplitude([1.0, 2.0]).tolist() == [2.5, 2.5]
