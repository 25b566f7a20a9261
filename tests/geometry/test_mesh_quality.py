"""The element-quality measure and rule: slivers counted with their share of the volume; a few slivers warn, a
mesh whose bad elements fill more than MAX_SLIVER_VOLUME_FRACTION of the volume is refused."""
from __future__ import annotations

import numpy as np
import pytest


def _two_tets(apex_offset: float):
    """The corner tetrahedron of the unit cube (volume 1/6) and a second one on its slanted face x+y+z = 1,
    apex (1 + apex_offset)/3 (1, 1, 1): a sliver of volume apex_offset / 6 for small offsets."""
    import ufl
    from dolfinx.mesh import create_mesh
    from mpi4py import MPI

    apex = (1 + apex_offset) / 3
    x = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [apex, apex, apex]], dtype=float)
    cells = np.array([[0, 1, 2, 3], [1, 2, 3, 4]], dtype=np.int64)
    domain = ufl.Mesh(ufl.VectorElement("Lagrange", "tetrahedron", 1))
    return create_mesh(MPI.COMM_WORLD, cells, x, domain)


def test_a_sliver_is_counted_with_its_share_of_the_volume():
    from housingfe.geometry.mesh import element_quality

    quality = element_quality(_two_tets(0.02))
    assert quality["elements"] == 2 and quality["low_count"] == 1
    assert quality["low_volume_fraction"] == pytest.approx((0.02 / 6) / (1 / 6 + 0.02 / 6), rel=1e-9)
    assert quality["min"] < 0.05 and quality["max"] > 0.7    # the corner tetrahedron: 0.77
    regular = element_quality(_two_tets(1.0))     # apex at (2/3, 2/3, 2/3): no sliver
    assert regular["low_count"] == 0 and regular["low_volume_fraction"] == 0.0


def test_a_few_slivers_warn_and_many_are_refused():
    from housingfe.errors import InputError
    from housingfe.fe.model import MAX_SLIVER_VOLUME_FRACTION, check_element_quality

    few = {"min": 0.0014, "measure": "tet", "low_count": 33, "elements": 10372, "low_volume_fraction": 4.9e-4}
    warning = check_element_quality(few, 0.02, 0.0142, "tet")
    assert warning.startswith("mesh: 33 of 10372 elements below quality 0.05 (worst 0.001")
    assert "4.9e-04 of the volume" in warning and few["warning"] == warning
    many = {**few, "low_count": 2000, "low_volume_fraction": 10 * MAX_SLIVER_VOLUME_FRACTION}
    with pytest.raises(InputError) as exc:
        check_element_quality(many, 0.02, 0.0142, "tet")
    assert str(exc.value).startswith("mesh.size: element quality 0.001 < 0.05 (2000 elements, 1.0e-02 of the volume")
