"""The registry of radiation models (housingfe.radiation.radiators.RADIATORS) and sound_power(response, radiator):
eq. 4.16 checked line by line and for the A-weighted total, the scene schema takes its names from the registry,
a registered toy radiator is accepted by the scene and used by sound_power."""
from types import SimpleNamespace

import numpy as np
import pytest
from pydantic import ValidationError

from housingfe import levels
from housingfe.errors import InputError
from housingfe.radiation.foller import Plate, foller_radiation_index
from housingfe.radiation.radiators import (
    RADIATORS,
    Radiator,
    SoundPower,
    radiator_from_spec,
    register_radiator,
    sound_power,
)
from housingfe.scene import RadiationSpec

F = np.arange(100.0, 2001.0, 50.0)
LV = 70.0 + 10 * np.sin(F / 300.0)      # any L_v spectrum (dB re 5e-8 m/s)
S = 0.35                                 # m^2


def response():
    return SimpleNamespace(frequencies=F, velocity_level_db=LV)


def test_built_in_radiators():
    assert set(RADIATORS) >= {"erp", "foller", "numerical"}
    assert [RADIATORS[n].needs_plates for n in ("erp", "foller", "numerical")] == [False, True, True]


def test_erp_sound_power_is_lv_plus_area_level_and_a_weighted_energy_sum():
    erp = radiator_from_spec(SimpleNamespace(model="erp", plates=[]), None, None)
    p = sound_power(response(), erp, area=S)
    assert isinstance(p, SoundPower) and p.radiator == "erp" and p.facts is None
    np.testing.assert_allclose(p.L_W_db, LV + 10 * np.log10(S), atol=1e-12)
    # A-weighted total: the energy sum over lines of L_W + A(f) (IEC 61672)
    expected = 10 * np.log10(np.sum(10 ** ((LV + 10 * np.log10(S) + levels.a_weighting_db(F)) / 10)))
    assert p.total_L_WA_db == pytest.approx(expected, abs=1e-9)
    # bands hold the energy of their lines: their energy sum is the total
    assert 10 * np.log10(np.sum(10 ** (p.band_L_W_db / 10))) == pytest.approx(p.spectrum.total_L_W_db, abs=1e-9)


def test_stage_api_response_with_mean_square_velocity_and_area_gives_the_same():
    v2 = levels.V0**2 * 10 ** (LV / 10)
    r = SimpleNamespace(frequencies=F, area=S, mean_square_velocity=lambda: v2)
    erp = RADIATORS["erp"]()
    np.testing.assert_allclose(sound_power(r, erp).L_W_db, sound_power(response(), erp, area=S).L_W_db,
                               atol=1e-9)


def test_foller_radiator_from_plates_adds_its_index():
    plates = [Plate("top", 1, 0.12, 1.4, 0.008, 1500.0), Plate("side", 4, 0.05, 0.9, 0.006, 2000.0)]
    radiator = RADIATORS["foller"](plates)
    p = sound_power(response(), radiator, area=S)
    L_sigma = foller_radiation_index(plates, F).L_sigma_db
    np.testing.assert_allclose(p.L_W_db, LV + 10 * np.log10(S) + L_sigma, atol=1e-12)
    assert np.all(L_sigma <= 1e-12) and L_sigma[0] < -10      # below f_c a box radiates less than sigma = 1
    assert p.facts["S_mean"] == pytest.approx((0.12 + 4 * 0.05) / 5)
    assert [q["surface"] for q in p.facts["plates"]] == ["top", "side"]


def test_numerical_radiator_needs_its_points_evaluated():
    radiator = radiator_from_spec(SimpleNamespace(model="numerical", plates=[SimpleNamespace(surface="top")]),
                                  None, None)
    assert radiator.surfaces == ("top",)
    with pytest.raises(InputError, match="extra_points"):
        radiator.radiation_index_db(response())


def test_scene_schema_takes_its_names_from_the_registry():
    assert RadiationSpec(model="erp").model == "erp"
    with pytest.raises(ValidationError, match="'bem' is not a radiation model; known: erp, foller, numerical"):
        RadiationSpec(model="bem")
    with pytest.raises(ValidationError, match="plates: the foller model needs the radiating plates"):
        RadiationSpec(model="foller")


def test_a_registered_toy_radiator_is_accepted_by_the_scene_and_used():
    @register_radiator("half")
    class Half(Radiator):
        """sigma = 1/2 at every line: L_sigma = -3.01 dB."""
        needs_plates = False

        @classmethod
        def from_spec(cls, spec, housing, material):
            return cls()

        def radiation_index_db(self, response):
            return np.full(len(response.frequencies), 10 * np.log10(0.5))

    try:
        spec = RadiationSpec(model="half")
        p = sound_power(response(), radiator_from_spec(spec, None, None), area=S)
        np.testing.assert_allclose(p.L_W_db, LV + 10 * np.log10(S) - 3.0103, atol=1e-4)
        assert p.radiator == "half"
        with pytest.raises(ValueError, match="registered twice"):
            register_radiator("half")(Half)
    finally:
        del RADIATORS["half"]
    with pytest.raises(ValidationError, match="'half' is not a radiation model"):
        RadiationSpec(model="half")
