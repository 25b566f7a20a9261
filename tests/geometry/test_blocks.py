"""The two ways a block model becomes one conforming gmsh solid: hexahedral meshes glue the grid cells in gmsh's
built-in kernel (shared faces by construction), tetrahedral ones fragment OCC boxes.  For the same model both must
give the same solid: as many volumes, faces, edges and corners, and the same boundary groups with the same areas."""
import gmsh
import numpy as np
import pytest

from housingfe.geometry import block_model_for, blocks
from tests.conftest import load_scene


def _solid(model, glue: bool) -> dict:
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("solid")
        if glue:
            _, atomic = blocks._glued_cells(model)
        else:
            blocks._fragmented_blocks(model, "hex")
            atomic = blocks._classify_boundary(model)
        counts = [len(gmsh.model.getEntities(d)) for d in range(4)]
        areas = {}
        for names, faces in atomic.items():
            total = 0.0
            for face in faces:
                lo, hi = np.split(np.array(gmsh.model.getBoundingBox(2, face)), 2)
                extent = np.sort(hi - lo)
                total += extent[1] * extent[2]   # an axis-aligned rectangle
            areas[names] = total
        return {"counts": counts, "areas": areas}
    finally:
        gmsh.finalize()


@pytest.mark.parametrize("scene", ["box-free", "box-halves", "nafems-fv12"])
def test_glued_cells_equal_fragmented_boxes(scene):
    model = block_model_for(load_scene(scene).geometry)
    glued, fragmented = _solid(model, True), _solid(model, False)
    assert glued["counts"] == fragmented["counts"]
    assert glued["counts"][3] == len(model.cells)
    assert set(glued["areas"]) == set(fragmented["areas"])
    for names, area in fragmented["areas"].items():
        # OCC bounding boxes carry ~1e-7 m of tolerance per side, the built-in kernel's are exact
        assert glued["areas"][names] == pytest.approx(area, rel=1e-4), names


@pytest.mark.parametrize("length, layers, layer_size, expected", [
    (0.008, 1, None, 1), (0.015, 3, None, 3),          # a layer count alone: every wall alike
    (0.008, 1, 0.004, 2), (0.015, 1, 0.004, 4),        # ceil(t / layer_size): 2.0 -> 2, 3.75 -> 4
    (0.008, 3, 0.004, 3),                               # never fewer than `layers`
    (0.015, 1, 0.010, 2),
    (0.150, 1, 0.004, 5),                               # an edge longer than a wall: from the element size only
])
def test_divisions_through_a_wall(length, layers, layer_size, expected):
    assert blocks.divisions(length, 0.030, (0.008, 0.015), layers, layer_size) == expected


def test_layer_size_puts_more_layers_through_the_thicker_flange(comm):
    """The free box's mesh with mesh.layer_size = 4 mm: element boundaries every 4 mm through the 8 mm walls (x)
    and every 3.75 mm through the 15 mm flange (z), nodes read from the distributed mesh."""
    from housingfe.geometry import build_mesh

    geometry = load_scene("box-free").geometry
    housing = build_mesh(geometry, "hex", 0.03, 1, comm, layer_size=0.004)
    owned = housing.mesh.geometry.x[:housing.mesh.geometry.index_map().size_local]
    x = np.unique(np.round(np.concatenate(comm.allgather(owned[:, 0])), 7))
    z = np.unique(np.round(np.concatenate(comm.allgather(owned[:, 2])), 7))
    wall_x0 = -geometry.length / 2
    through_wall = x[(x >= wall_x0 - 1e-9) & (x <= wall_x0 + geometry.wall_thickness + 1e-9)] - wall_x0
    through_flange = z[(z >= -1e-9) & (z <= geometry.flange_thickness + 1e-9)]
    # a quadratic geometry adds the mid-planes, so keep the element boundaries: every other plane
    step = 2 if len(through_wall) > 3 else 1
    assert np.allclose(through_wall[::step], [0.0, 0.004, 0.008])
    assert np.allclose(through_flange[::step], [0.0, 0.00375, 0.0075, 0.01125, 0.015])
