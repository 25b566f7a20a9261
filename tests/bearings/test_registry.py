"""The registry of bearing models (housingfe.bearings.rolling.BEARING_MODELS): one list of names that make_model,
the scene schema (BearingSpec.model) and the error messages all use; a registered toy model shows up in both."""
import numpy as np
import pytest
from pydantic import ValidationError

from housingfe.bearings import lookup
from housingfe.bearings.rolling import (
    BEARING_MODELS,
    LimBall,
    default_model,
    make_model,
    register_bearing_model,
)
from housingfe.drivetrain.interior import BearingSpec
from housingfe.errors import InputError

BUILT_IN = {"lim-ball", "lim-roller", "sliced-roller", "sliced-roller-thesis", "self-aligning",
            "spherical-point-contact"}
LOAD = (2000.0, 0.0, 500.0, 0.0, 0.0)


def spec(model):
    return BearingSpec(shaft_node="s:0", designation="6312", load=LOAD, model=model)


def test_built_in_models_are_registered_with_the_kinds_they_fit():
    assert set(BEARING_MODELS) == BUILT_IN
    for name, cls in BEARING_MODELS.items():
        assert cls.name == name and cls.kinds
    for designation in ("6312", "NU2219", "22219CC"):      # ball, cylindrical roller, spherical roller
        b = lookup(designation)
        assert b.kind in BEARING_MODELS[default_model(b)].kinds


def test_kind_mismatch_is_an_input_error_naming_model_and_kind():
    with pytest.raises(InputError, match="model 'sliced-roller' does not fit a ball bearing$"):
        make_model(lookup("6312"), "sliced-roller")
    with pytest.raises(InputError, match="does not fit a spherical_roller bearing .spherical roller bearings use"):
        make_model(lookup("22219CC"), "lim-roller")


def test_scene_schema_takes_the_names_from_the_registry():
    assert spec("lim-ball").model == "lim-ball"
    with pytest.raises(ValidationError, match="'hertz' is not a bearing model; known: lim-ball, lim-roller"):
        spec("hertz")


def test_a_registered_toy_model_is_accepted_by_scene_and_make_model():
    @register_bearing_model
    class ToyBall(LimBall):
        """Lim's ball bearing with twice the contact stiffness: twice the stiffness at the same deflection."""
        name = "toy-ball"

        def __init__(self, bearing):
            super().__init__(bearing)
            self.k_n = 2 * self.k_n

    try:
        assert spec("toy-ball").model == "toy-ball"
        b = lookup("6312")
        q = np.array([20e-6, 0.0, 5e-6, 0.0, 0.0])
        toy, lim = make_model(b, "toy-ball"), make_model(b, "lim-ball")
        assert isinstance(toy, ToyBall)
        np.testing.assert_allclose(toy.evaluate(q)[2], 2 * lim.evaluate(q)[2], rtol=1e-12)
        with pytest.raises(InputError, match="does not fit a cylindrical_roller bearing"):
            make_model(lookup("NU2219"), "toy-ball")
        with pytest.raises(ValueError, match="needs a new, non-empty name"):
            register_bearing_model(ToyBall)                       # registered twice
    finally:
        del BEARING_MODELS["toy-ball"]
    with pytest.raises(ValidationError, match="'toy-ball' is not a bearing model"):
        spec("toy-ball")
