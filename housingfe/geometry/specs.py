"""Scene specifications of the geometries (validated with pydantic; lengths in m).

Each geometry kind has a spec here and a block-model builder registered in housingfe.geometry.mesh.
"""
from __future__ import annotations

from typing import Annotated, Literal, Union

from pydantic import BaseModel, ConfigDict, Field, PositiveFloat, model_validator


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class BoxGeometry(_Strict):
    """The open welded box of Sec. 4.2 (lengths in m; H from the flange underside to the top)."""

    kind: Literal["box"]
    length: PositiveFloat
    width: PositiveFloat
    height: PositiveFloat
    wall_thickness: PositiveFloat
    flange_thickness: PositiveFloat
    flange_width: PositiveFloat
    bolt_patch_size: PositiveFloat = 0.024

    @model_validator(mode="after")
    def _consistent(self):
        if 2 * self.wall_thickness >= min(self.length, self.width):
            raise ValueError("wall_thickness: walls thicker than half the length/width leave no box")
        if self.flange_thickness + self.wall_thickness >= self.height:
            raise ValueError("height: must exceed flange_thickness + wall_thickness")
        if self.bolt_patch_size >= self.flange_width:
            raise ValueError("bolt_patch_size: must be smaller than flange_width")
        return self

    @property
    def min_thickness(self) -> float:
        return min(self.wall_thickness, self.flange_thickness)


EdgeCondition = Literal["free", "clamped", "simply_supported"]


class PlateEdges(_Strict):
    x0: EdgeCondition = "free"
    x1: EdgeCondition = "free"
    y0: EdgeCondition = "free"
    y1: EdgeCondition = "free"


class PlateGeometry(_Strict):
    """Rectangular plate a x b x h (m) with per-edge conditions; simply supported = zero transverse
    displacement on the edge face."""

    kind: Literal["plate"]
    a: PositiveFloat
    b: PositiveFloat
    h: PositiveFloat
    edges: PlateEdges = PlateEdges()

    @property
    def min_thickness(self) -> float:
        return self.h


# A new geometry kind: add its spec to this union and its builder to housingfe.geometry.mesh.block_model_for.
Geometry = Annotated[Union[BoxGeometry, PlateGeometry], Field(discriminator="kind")]


