"""Box geometry: exact volume, tags, outer surface area against the analytic value."""
import numpy as np
import pytest
import ufl
from dolfinx import fem

from housingfe.geometry.box import box_model

DIMS = dict(length=0.325, width=0.225, height=0.125, wall_thickness=0.008, flange_thickness=0.015,
            flange_width=0.073)


def test_block_model_volume_is_exact():
    L, W, H, t, tf, b = (DIMS[k] for k in ("length", "width", "height", "wall_thickness",
                                           "flange_thickness", "flange_width"))
    walls_and_top = L * W * (H - tf) - (L - 2 * t) * (W - 2 * t) * (H - tf - t)
    flange = ((L + 2 * b) * (W + 2 * b) - (L - 2 * t) * (W - 2 * t)) * tf
    assert box_model(**DIMS).volume() == pytest.approx(walls_and_top + flange, rel=1e-12)


@pytest.mark.parametrize("element", ["hex", "tet"])
def test_mesh_tags_and_areas(coarse_box_model, comm, element):
    from housingfe.geometry import build_mesh
    from tests.conftest import load_scene

    g = load_scene("box-free").geometry
    hm = coarse_box_model.housing if element == "hex" else build_mesh(g, "tet", 0.03, 1, comm)
    L, W, H, t, tf, b = g.length, g.width, g.height, g.wall_thickness, g.flange_thickness, g.flange_width
    expected = {
        "outer_top": L * W,
        "outer_front": L * (H - tf), "outer_back": L * (H - tf),
        "outer_left": W * (H - tf), "outer_right": W * (H - tf),
        "foot_bottom": (L + 2 * b) * (W + 2 * b) - (L - 2 * t) * (W - 2 * t),
        "bolt_1": g.bolt_patch_size**2,
    }
    ds = ufl.Measure("ds", domain=hm.mesh, subdomain_data=hm.facet_tags)
    for name, area in expected.items():
        value = comm.allreduce(fem.assemble_scalar(fem.form(1.0 * ds(hm.facet_tag_values(name)))))
        assert value == pytest.approx(area, rel=1e-10), name
    for n in range(1, 9):
        assert f"bolt_{n}" in hm.facet_groups
    assert {"top", "front", "back", "left", "right", "flange"} <= set(hm.cell_groups)
    from housingfe.fe.model import MIN_ELEMENT_QUALITY

    # structured hexes are perfect boxes; Delaunay tetrahedra must pass the threshold the model enforces
    assert hm.quality["min"] > (0.999 if element == "hex" else MIN_ELEMENT_QUALITY)


def test_outer_surface_excludes_foot_and_inner(coarse_box_model, comm):
    g = coarse_box_model.scene.geometry
    hm = coarse_box_model.housing
    L, W, H, tf, b = g.length, g.width, g.height, g.flange_thickness, g.flange_width
    ds = ufl.Measure("ds", domain=hm.mesh, subdomain_data=hm.facet_tags)
    outer = comm.allreduce(fem.assemble_scalar(fem.form(1.0 * ds(hm.facet_tag_values("outer")))))
    plates = L * W + 2 * (L + W) * (H - tf)
    flange_top_and_rim = (L + 2 * b) * (W + 2 * b) - L * W + 2 * (L + W + 4 * b) * tf
    assert outer == pytest.approx(plates + flange_top_and_rim, rel=1e-10)
    assert np.isclose(hm.volume * 7850, 24.4048, rtol=1e-4)
