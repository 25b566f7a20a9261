"""Geometric selectors (housingfe.geometry.selectors) on hand-made face descriptions: a bore found by axis and
centre, two coaxial bores told apart by radius, planes by point and outward normal, boxes, the nearest face,
and the grouping of candidate bores and flat faces."""
import math

import numpy as np
import pytest

from housingfe.errors import InputError
from housingfe.geometry.selectors import (
    BoreSelector,
    Face,
    SurfaceSelector,
    bore_candidates,
    flat_candidates,
    select_bore,
    select_surface,
)


def cylinder(tag, centre, radius, y0, y1, concave=True):
    """A cylinder face along y: sample points on its rim circles."""
    phi = np.linspace(0, 2 * math.pi, 12, endpoint=False)
    pts = [[centre[0] + radius * math.cos(p), y, centre[2] + radius * math.sin(p)] for y in (y0, y1) for p in phi]
    return Face(tag, "cylinder", np.array(pts), 2 * math.pi * radius * (y1 - y0), axis=np.array([0.0, 1.0, 0.0]),
                axis_point=np.array([centre[0], 0.0, centre[2]]), radius=radius, concave=concave)


def rectangle(tag, z, normal_z, x=(0.0, 0.2), y=(0.0, 0.1)):
    pts = np.array([[x[i], y[j], z] for i in (0, 1) for j in (0, 1)])
    triangles = np.array([pts[[0, 1, 3]], pts[[0, 3, 2]]])
    return Face(tag, "plane", pts, (x[1] - x[0]) * (y[1] - y[0]), normal=np.array([0.0, 0.0, normal_z]),
                triangles=triangles)


FACES = [cylinder(1, (0.05, 0, 0.05), 0.02, 0.0, 0.04), cylinder(2, (0.05, 0, 0.05), 0.025, 0.04, 0.1),
         cylinder(3, (0.15, 0, 0.05), 0.02, 0.0, 0.1), cylinder(4, (0.15, 0, 0.05), 0.03, 0.0, 0.1, concave=False),
         rectangle(5, 0.0, -1.0), rectangle(6, 0.1, 1.0), rectangle(7, 0.0, 1.0, x=(0.3, 0.4))]


def test_a_bore_by_axis_and_centre_takes_every_face_on_that_axis_but_no_boss():
    sel = BoreSelector(name="B", axis=[0, -1, 0], centre=[0.15, 0.7, 0.05])
    assert select_bore(FACES, sel, "geometry.bores[0]") == [3]   # face 4 is convex (a boss), never a bore


def test_two_coaxial_bores_of_different_radius_need_the_radius():
    sel = BoreSelector(name="A", axis=[0, 1, 0], centre=[0.05, 0.0, 0.05])
    with pytest.raises(InputError, match=r"geometry.bores\[1\]: matches 2 bores of different radius \(20, 25 mm\)"):
        select_bore(FACES, sel, "geometry.bores[1]")
    assert select_bore(FACES, sel.model_copy(update={"radius": 0.025}), "k") == [2]


def test_a_bore_off_every_axis_says_where_the_nearest_is():
    sel = BoreSelector(name="A", axis=[0, 1, 0], centre=[0.06, 0.0, 0.05])
    with pytest.raises(InputError, match=r"^k: no cylindrical face .* nearest bore .* 10 mm from centre"):
        select_bore(FACES, sel, "k")


def test_planes_by_point_and_outward_normal_boxes_and_the_nearest_face():
    under = SurfaceSelector(name="feet", plane={"point": [1.0, 1.0, 0.0], "normal": [0, 0, -1]})
    assert select_surface(FACES, under, "k") == [5]           # 7 lies in the plane but faces up
    up = SurfaceSelector(name="up", plane={"point": [0, 0, 0], "normal": [0, 0, 1]})
    assert select_surface(FACES, up, "k") == [7]
    box = SurfaceSelector(name="b", box={"min": [0.25, -1, -1], "max": [1, 1, 1]})
    assert select_surface(FACES, box, "k") == [7]
    near = SurfaceSelector(name="n", nearest=[0.1, 0.05, 0.11])
    assert select_surface(FACES, near, "k") == [6]
    with pytest.raises(InputError, match=r"^geometry.surfaces\[2\]: no face in the plane"):
        select_surface(FACES, SurfaceSelector(name="x", plane={"point": [0, 0, 0.05], "normal": [0, 0, 1]}),
                       "geometry.surfaces[2]")


def test_candidates_group_by_axis_and_plane():
    bores = bore_candidates(FACES, 1e-6)
    assert [(round(b["radius"], 6), b["tags"]) for b in bores] == [(0.025, [2]), (0.02, [1]), (0.02, [3])]
    assert bores[2]["length"] == pytest.approx(0.1) and bores[2]["centre"] == pytest.approx([0.15, 0.05, 0.05])
    flats = flat_candidates(FACES, 1e-6)
    assert [f["tags"] for f in flats] == [[5], [6], [7]] and flats[0]["area"] == pytest.approx(0.02)


def test_a_selector_needs_exactly_one_way_to_select():
    with pytest.raises(ValueError, match="exactly one of plane, box or nearest"):
        SurfaceSelector(name="x", nearest=[0, 0, 0], box={"min": [0, 0, 0], "max": [1, 1, 1]})
