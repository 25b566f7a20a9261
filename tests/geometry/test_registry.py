"""The registry of geometry kinds (housingfe.geometry.registry.GEOMETRY_KINDS): the scene's geometry union and the
block-model lookup both come from it; a registered toy kind validates through the union and builds its model."""
from typing import Literal

import pytest
from pydantic import PositiveFloat, TypeAdapter

from housingfe.errors import InputError
from housingfe.geometry.mesh import block_model_for, estimate_dofs
from housingfe.geometry.plate import plate_model
from housingfe.geometry.registry import GEOMETRY_KINDS, StrictSpec, geometry_union, register_geometry
from housingfe.scene import HousingScene
from housingfe.scenefile import parse_table


def test_built_in_kinds_in_order_and_the_scene_knows_exactly_them():
    assert list(GEOMETRY_KINDS) == ["box", "plate", "box-halves", "gearbox", "mesh", "cad"]
    with pytest.raises(InputError, match="expected tags: 'box', 'plate', 'box-halves', 'gearbox', 'mesh', 'cad'$"):
        parse_table(HousingScene, {"scene": {"name": "x", "kind": "housing"}, "geometry": {"kind": "sphere"},
                                   "analysis": {"modal": {"f_max": 100.0}}}, "toy.toml")


def test_lookup_builds_the_registered_model():
    box = TypeAdapter(geometry_union()).validate_python(
        {"kind": "box", "length": 0.325, "width": 0.225, "height": 0.125, "wall_thickness": 0.008,
         "flange_thickness": 0.015, "flange_width": 0.073})
    # five 8 mm plates and the 15 mm flange ring, exactly (outer box minus the cavity, plus the flange)
    L, W, H, t, tf, b = 0.325, 0.225, 0.125, 0.008, 0.015, 0.073
    walls = L * W * (H - tf) - (L - 2 * t) * (W - 2 * t) * (H - tf - t)
    flange = ((L + 2 * b) * (W + 2 * b) - (L - 2 * t) * (W - 2 * t)) * tf
    assert block_model_for(box).volume() == pytest.approx(walls + flange, rel=1e-12)


def test_a_registered_toy_kind_validates_and_builds():
    class Slab(StrictSpec):
        """A plate given by its area and aspect ratio (m^2, -) and thickness (m)."""
        kind: Literal["slab"]
        area: PositiveFloat
        aspect: PositiveFloat = 1.0
        h: PositiveFloat

        @property
        def min_thickness(self) -> float:
            return self.h

    register_geometry(Slab, lambda g: plate_model((g.area * g.aspect) ** 0.5, (g.area / g.aspect) ** 0.5, g.h))
    try:
        slab = TypeAdapter(geometry_union()).validate_python({"kind": "slab", "area": 0.08, "aspect": 2.0,
                                                              "h": 0.01})
        assert isinstance(slab, Slab)
        model = block_model_for(slab)
        assert model.volume() == pytest.approx(0.08 * 0.01, rel=1e-12)
        assert estimate_dofs(slab, "hex", 2, 0.05, 1) > 0
        with pytest.raises(ValueError, match="registered twice"):
            register_geometry(Slab, lambda g: None)
    finally:
        del GEOMETRY_KINDS["slab"]
    with pytest.raises(InputError, match="geometry.kind: no builder for 'slab'"):
        block_model_for(slab)
