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
