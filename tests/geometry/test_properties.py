"""Property-based tests (hypothesis, issue 30 item 2) of the geometry blocks, the cheap stage before meshing: over
the valid ranges of the box and plate kinds no traceback, the block model's volume and centroid exact against the
closed form, every named surface with a finite positive area.  Derandomized (fixed examples in CI)."""
from __future__ import annotations

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from housingfe.geometry.box import BoxGeometry
from housingfe.geometry.plate import PlateGeometry
from housingfe.geometry.registry import GEOMETRY_KINDS
from housingfe.geometry.surfaces import named_surfaces

SETTINGS = settings(max_examples=30, derandomize=True, deadline=None)


@SETTINGS
@given(length=st.floats(0.1, 2.0), width=st.floats(0.1, 2.0), height=st.floats(0.05, 1.5),
       wall=st.floats(0.002, 0.04), flange_t=st.floats(0.003, 0.04), flange_w=st.floats(0.03, 0.2))
def test_box_block_model_volume_centroid_and_surfaces(length, width, height, wall, flange_t, flange_w):
    """An open box (five plates) on a foot flange: volume = L W H - (L - 2t)(W - 2t)(H - t) + flange ring."""
    assume(2 * wall < 0.8 * min(length, width) and flange_t + wall < 0.8 * height and flange_w <= max(length, width))
    spec = BoxGeometry(kind="box", length=length, width=width, height=height, wall_thickness=wall,
                       flange_thickness=flange_t, flange_width=flange_w, bolt_patch_size=0.5 * flange_w)
    model = GEOMETRY_KINDS["box"].build(spec)
    shell = length * width * height - (length - 2 * wall) * (width - 2 * wall) * (height - wall)
    ring = ((length + 2 * flange_w) * (width + 2 * flange_w) - length * width) * flange_t
    assert np.isclose(model.volume(), shell + ring, rtol=1e-12)
    c = model.centroid()
    assert np.allclose(c[:2], 0.0, atol=1e-12 * max(length, width)) and 0.0 < c[2] < height
    surfaces = named_surfaces(model)
    assert {"outer", "inner", "foot_bottom"} <= set(surfaces)
    for s in surfaces.values():
        assert np.isfinite(s.area) and s.area > 0


@SETTINGS
@given(a=st.floats(0.05, 20.0), b=st.floats(0.05, 20.0), ratio=st.floats(1e-4, 0.9))
def test_plate_block_model_volume_and_centroid(a, b, ratio):
    h = ratio * min(a, b)
    model = GEOMETRY_KINDS["plate"].build(PlateGeometry(kind="plate", a=a, b=b, h=h))
    assert np.isclose(model.volume(), a * b * h, rtol=1e-12)
    assert np.allclose(model.centroid(), [a / 2, b / 2, h / 2], rtol=1e-12)
