"""Rectangular plate a x b x h as a single block, for verification (NAFEMS FV12 and plate theory).

Coordinates: the plate occupies [0, a] x [0, b] x [0, h].  Edge faces are tagged edge_x0 (x = 0),
edge_x1 (x = a), edge_y0, edge_y1; the faces top (z = h) and bottom (z = 0).
"""
from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import PositiveFloat, model_validator

from housingfe.geometry.blocks import BlockModel, cells_where
from housingfe.geometry.registry import StrictSpec as _Strict
from housingfe.geometry.registry import register_geometry

EdgeCondition = Literal["free", "clamped", "simply_supported"]


class PlateEdges(_Strict):
    x0: EdgeCondition = "free"  # the edge face x = 0 (surface edge_x0)
    x1: EdgeCondition = "free"  # the edge face x = a (surface edge_x1)
    y0: EdgeCondition = "free"  # the edge face y = 0 (surface edge_y0)
    y1: EdgeCondition = "free"  # the edge face y = b (surface edge_y1)


class PlateGeometry(_Strict):
    """Rectangular plate a x b x h (m) with per-edge conditions; simply supported = zero transverse
    displacement on the edge face."""

    kind: Literal["plate"]
    a: PositiveFloat  # length along x
    b: PositiveFloat  # width along y
    h: PositiveFloat  # thickness along z
    edges: PlateEdges = PlateEdges()

    @model_validator(mode="after")
    def _thin(self):
        if self.h > min(self.a, self.b):
            raise ValueError(f"h: a plate {self.h:g} m thick and {min(self.a, self.b):g} m wide is not a plate; "
                             f"lengths are in m")
        return self

    @property
    def min_thickness(self) -> float:
        return self.h

    @property
    def wall_thicknesses(self) -> dict[str, float]:
        """The plates whose bending waves the mesh must resolve: name -> thickness (m)."""
        return {"plate": self.h}

    @property
    def wall_cell_groups(self) -> dict[str, tuple[str, ...]]:
        """The cell groups (name prefixes) of each entry of wall_thicknesses."""
        return {"plate": ("plate",)}


def plate_model(a: float, b: float, h: float) -> BlockModel:
    """Block model of a plate (lengths in m)."""
    grid = (np.array([0.0, a]), np.array([0.0, b]), np.array([0.0, h]))

    def classify(centre: np.ndarray, normal: np.ndarray) -> list[str]:
        x, y, z = centre
        if abs(normal[2]) > 0.5:
            return ["top", "outer"] if normal[2] > 0 else ["bottom", "outer"]
        if abs(normal[0]) > 0.5:
            return ["edge_x0"] if x < a / 2 else ["edge_x1"]
        return ["edge_y0"] if y < b / 2 else ["edge_y1"]

    return BlockModel(grid=grid, cells=cells_where(grid, lambda x, y, z: "plate"), classify_face=classify,
                      thin_dimensions=(h,))


def build_plate(g: PlateGeometry) -> BlockModel:
    """Block model of a validated PlateGeometry (the edge conditions are supports, set by the FE model)."""
    return plate_model(g.a, g.b, g.h)


register_geometry(PlateGeometry, build_plate)
