"""Sound power from a computed forced response: ERP identity, Föller plates measured on the mesh."""
import numpy as np
import pytest

from housingfe.report import sound_power_rows
from housingfe.run import forced_response
from housingfe.scene import build_model_from_scene
from tests.conftest import load_scene

PLATE = ["geometry.a=0.3", "geometry.b=0.2", "geometry.h=0.005", "mesh.size=0.05", "analysis.modal.f_max=1500.0",
         'loads=[{name="p", kind="force", surface="top", point=[0.07, 0.05, 0.005], direction=[0,0,-1]}]',
         "analysis.harmonic.f_max=1500.0", "analysis.harmonic.f_min=100.0", "analysis.harmonic.df=25.0",
         "analysis.harmonic.sample_points=[]", "analysis.harmonic.surface=\"top\"", "damping.loss_factor=0.01"]


def forced_with(comm, radiation):
    scene = load_scene("nafems-fv12", *PLATE, f"radiation={radiation}")
    model = build_model_from_scene(scene, comm)
    return model, forced_response(scene, model, model)


def test_erp_is_lv_plus_area_level(comm):
    model, forced = forced_with(comm, '{model="erp"}')
    rows = [r for r in sound_power_rows(forced) if r[2] in ("line", "band")]
    S = 0.3 * 0.2
    for r in rows:
        assert r[6] == pytest.approx(r[4] + 10 * np.log10(S), abs=1e-9)   # L_W = L_v + 10 lg S, sigma = 1


def test_foller_plates_are_measured_on_the_mesh(comm):
    model, forced = forced_with(comm, '{model="foller", plates=[{surface="top", thickness=0.005}]}')
    plate = forced.sound_power[0].plates[0]
    assert plate.area_m2 == pytest.approx(0.06, rel=1e-12)
    assert plate.perimeter_m == pytest.approx(1.0, rel=1e-12)
    # steel-like plate, 5 mm: f_c = c^2/(1.8 c_L h) ~ 12/h
    assert plate.fc_hz == pytest.approx(12 / 0.005, rel=0.1)
    L_sigma = forced.sound_power[0].radiation_index_db
    assert np.all(L_sigma <= 1e-9) and np.all(np.diff(L_sigma) >= -1e-9)   # rises to 0 dB, never above


def test_numerical_rayleigh_index_is_finite_and_below_piston_limit(comm):
    model, forced = forced_with(comm, '{model="numerical", plates=[{surface="top", thickness=0.005}]}')
    L_sigma = forced.sound_power[0].radiation_index_db
    assert np.all(np.isfinite(L_sigma))
    # a baffled plate below its critical frequency (2.4 kHz) radiates less than sigma = 1
    assert np.all(L_sigma < 0.5) and L_sigma[0] < -10
