"""housingfe.fe.loads: a force or moment point must lie on its surface (issue 12 item 10: a point 5 m away used to
move silently to the nearest facets)."""
from types import SimpleNamespace

import numpy as np
import pytest
from dolfinx import mesh as dmesh
from mpi4py import MPI

from housingfe.errors import InputError
from housingfe.fe.loads import _check_point_on_surface, point_tolerance, surface_distance_bound


@pytest.fixture(scope="module")
def top_face():
    """A 0.2 x 0.1 x 0.05 m block of coarse hexes (50 mm elements) and the facets of its top face z = 0.05."""
    msh = dmesh.create_box(MPI.COMM_WORLD, [np.zeros(3), np.array([0.2, 0.1, 0.05])], [4, 2, 1],
                           dmesh.CellType.hexahedron)
    msh.topology.create_connectivity(2, 3)
    facets = dmesh.locate_entities_boundary(msh, 2, lambda x: np.isclose(x[2], 0.05))
    return msh, facets


def _spec(point, radius=0.005):
    return SimpleNamespace(name="top", point=point, radius=radius, surface="outer_top")


def test_point_on_the_surface_is_accepted_on_a_coarse_mesh(top_face):
    msh, facets = top_face
    # facet midpoints lie up to 35 mm from this point, far beyond the 5 mm radius: the bound must still be <= 0
    point = np.array([0.05, 0.05, 0.05])
    assert surface_distance_bound(msh, facets, point) <= 0.0
    _check_point_on_surface(msh, facets, point, _spec(list(point)))


def test_distance_bound_is_within_a_facet_size_of_the_true_distance(top_face):
    msh, facets = top_face
    for offset in (0.01, 0.1, 5.0):
        bound = surface_distance_bound(msh, facets, np.array([0.1, 0.05, 0.05 + offset]))
        assert offset - 0.04 <= bound <= offset      # facet 50 x 50 mm: reach 35 mm


def test_force_five_metres_off_its_surface_names_the_point(top_face):
    msh, facets = top_face
    point = [0.1, 0.05, 5.05]
    with pytest.raises(InputError, match=r"loads\.top\.point: .* at least 49\d\d mm from surface 'outer_top'"):
        _check_point_on_surface(msh, facets, np.array(point), _spec(point))


def test_tolerance_is_the_load_radius_with_a_millimetre_floor(top_face):
    msh, facets = top_face
    assert point_tolerance(_spec(None, 0.02)) == 0.02
    assert point_tolerance(_spec(None, 1e-5)) == 1e-3
    # 3 mm above the face with a 50 mm patch radius: accepted; 100 mm above (bound >= 65 mm): not
    _check_point_on_surface(msh, facets, np.array([0.1, 0.05, 0.053]), _spec([0.1, 0.05, 0.053], 0.05))
    with pytest.raises(InputError, match=r"loads\.top\.point"):
        _check_point_on_surface(msh, facets, np.array([0.1, 0.05, 0.15]), _spec([0.1, 0.05, 0.15], 0.05))
