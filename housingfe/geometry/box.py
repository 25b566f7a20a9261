"""The welded box of van Roosmalen (1994) Sec. 4.2: five plates, open bottom, a foot flange around the bottom.

Fig. 4.2 (the dimension drawing) did not survive in the text.  The defaults are a reconstruction:
outer L x W x H = 0.325 x 0.225 x 0.125 m (H from the flange underside to the top), plates t = 8 mm,
flange t_f = 15 mm projecting b = 73 mm outside the walls.  They reproduce the published facts
(mass 24.4 kg vs 24.5 kg, lowest elastic mode near 641 Hz, about 35 elastic modes below 4 kHz);
they are not the drawing's dimensions.

Coordinates: origin at the centre of the flange underside, x along the length, y along the width,
z up.  The eight bolts (Sec. 4.3; positions not in the text) are assumed at the four flange corners and
the four side midpoints, on the flange centre line.
"""
from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import PositiveFloat, model_validator

from housingfe.geometry.blocks import BlockModel, cells_where, unique_planes
from housingfe.geometry.registry import StrictSpec as _Strict
from housingfe.geometry.registry import register_geometry


class BoxGeometry(_Strict):
    """The open welded box of Sec. 4.2 (lengths in m; H from the flange underside to the top)."""

    kind: Literal["box"]
    length: PositiveFloat           # outer length along x, walls included (flange not)
    width: PositiveFloat            # outer width along y, walls included (flange not)
    height: PositiveFloat           # along z, from the flange underside to the top of the top plate
    wall_thickness: PositiveFloat   # the five plates (top, front, back, left, right)
    flange_thickness: PositiveFloat  # the foot flange around the open bottom
    flange_width: PositiveFloat     # how far the flange stands out beyond the outer wall faces
    bolt_patch_size: PositiveFloat = 0.024  # side of the square bolt_1..bolt_8 patches on the flange underside

    @model_validator(mode="after")
    def _consistent(self):
        if 2 * self.wall_thickness >= min(self.length, self.width):
            raise ValueError("wall_thickness: walls thicker than half the length/width leave no box")
        if self.flange_thickness + self.wall_thickness >= self.height:
            raise ValueError("height: must exceed flange_thickness + wall_thickness")
        if self.bolt_patch_size >= self.flange_width:
            raise ValueError("bolt_patch_size: must be smaller than flange_width")
        # a flange wider than the box itself is a unit typo (5.0 for 0.05 m), not a housing: it would mesh
        # metres of flange at millimetre elements
        if self.flange_width > max(self.length, self.width):
            raise ValueError(f"flange_width: {self.flange_width:g} m is wider than the box itself "
                             f"({self.length:g} x {self.width:g} m); lengths are in m")
        if self.flange_thickness > self.height:
            raise ValueError(f"flange_thickness: {self.flange_thickness:g} m exceeds the box height "
                             f"{self.height:g} m; lengths are in m")
        return self

    @property
    def min_thickness(self) -> float:
        return min(self.wall_thickness, self.flange_thickness)

    @property
    def wall_thicknesses(self) -> dict[str, float]:
        """The plates whose bending waves the mesh must resolve: name -> thickness (m)."""
        return {"walls": self.wall_thickness, "flange": self.flange_thickness}

    @property
    def wall_cell_groups(self) -> dict[str, tuple[str, ...]]:
        """The cell groups (name prefixes) of each entry of wall_thicknesses."""
        return {"walls": ("top", "left", "right", "front", "back"), "flange": ("flange",)}


def box_model(length: float, width: float, height: float, wall_thickness: float,
              flange_thickness: float, flange_width: float, bolt_patch_size: float = 0.024) -> BlockModel:
    """Block model of the open box with foot flange (all lengths in m).

    Features (cell groups): top, front, back, left, right, flange.
    Surface groups: outer (radiating: outside of plates and flange, excluding the flange underside),
    inner, foot_bottom (flange underside), bolt_1..bolt_8 (square patches on the underside),
    and one outer group per plate (outer_top, outer_front, ...).
    """
    L2, W2, t, tf, b, H = length / 2, width / 2, wall_thickness, flange_thickness, flange_width, height
    bolts = _bolt_centres(L2, W2, b)
    s2 = bolt_patch_size / 2
    xs = [-L2 - b, -L2, -L2 + t, L2 - t, L2, L2 + b] + [x + d for x, _ in bolts for d in (-s2, s2)]
    ys = [-W2 - b, -W2, -W2 + t, W2 - t, W2, W2 + b] + [y + d for _, y in bolts for d in (-s2, s2)]
    zs = [0.0, tf, H - t, H]
    grid = (unique_planes(xs), unique_planes(ys), unique_planes(zs))

    def feature(x: float, y: float, z: float) -> str | None:
        inside_outer = abs(x) < L2 and abs(y) < W2
        inside_inner = abs(x) < L2 - t and abs(y) < W2 - t
        if z < tf:  # flange layer: everything but the opening
            return None if inside_inner else "flange"
        if z > H - t:
            return "top" if inside_outer else None
        if not inside_outer or inside_inner:
            return None
        if x <= -L2 + t:  # end walls own the vertical corner columns
            return "left"
        if x >= L2 - t:
            return "right"
        return "front" if y < 0 else "back"

    def classify(centre: np.ndarray, normal: np.ndarray) -> list[str]:
        x, y, z = centre
        if normal[2] < -0.5 and z < 1e-9:
            names = ["foot_bottom"]
            for n, (bx, by) in enumerate(bolts, start=1):
                if abs(x - bx) < s2 and abs(y - by) < s2:
                    names.append(f"bolt_{n}")
            return names
        inward = (abs(x) < L2 - t + 1e-9 and abs(y) < W2 - t + 1e-9 and z < H - t + 1e-9)
        if inward:
            return ["inner"]
        return ["outer", "outer_" + _plate_of_outer_face(centre, normal, L2, W2, H, tf)]

    points = {"bolts": [(bx, by, 0.0) for bx, by in bolts]}
    return BlockModel(grid=grid, cells=cells_where(grid, feature), classify_face=classify,
                      thin_dimensions=(t, tf), points=points)


def _bolt_centres(L2: float, W2: float, b: float) -> list[tuple[float, float]]:
    cx, cy = L2 + b / 2, W2 + b / 2
    return [(-cx, -cy), (0.0, -cy), (cx, -cy), (cx, 0.0), (cx, cy), (0.0, cy), (-cx, cy), (-cx, 0.0)]


def _plate_of_outer_face(c: np.ndarray, n: np.ndarray, L2: float, W2: float, H: float, tf: float) -> str:
    """Name of the plate an outer face belongs to (faces at or below the flange top are the flange's)."""
    if c[2] <= tf + 1e-9:
        return "flange"
    if n[2] > 0.5:
        return "top"
    if abs(n[0]) > 0.5:
        return "left" if n[0] < 0 else "right"
    return "front" if n[1] < 0 else "back"


def build_box(g: BoxGeometry) -> BlockModel:
    """Block model of a validated BoxGeometry."""
    return box_model(g.length, g.width, g.height, g.wall_thickness, g.flange_thickness, g.flange_width,
                     g.bolt_patch_size)


register_geometry(BoxGeometry, build_box)
