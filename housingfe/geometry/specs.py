"""Scene specifications of the geometries (validated with pydantic; lengths in m).

Each geometry kind has a spec here and a block-model builder registered in housingfe.geometry.mesh.
"""
from __future__ import annotations

import itertools
from typing import Annotated, Literal

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

    @model_validator(mode="after")
    def _thin(self):
        if self.h > min(self.a, self.b):
            raise ValueError(f"h: a plate {self.h:g} m thick and {min(self.a, self.b):g} m wide is not a plate; "
                             f"lengths are in m")
        return self

    @property
    def min_thickness(self) -> float:
        return self.h


class BoxHalvesGeometry(BoxGeometry):
    """Two Sec. 4.2 boxes joined at their flanges (Sec. 4.4), lengths in m.

    joint "monolithic" welds the flanges into one plate (the thesis' model); "layer" puts a joint layer of
    joint_thickness (cell group "joint"; give it a material in [regions.joint]) between them, taken half from
    each flange.  bearing_point_offset: the Sec. 4.4 bearing-like point lies this far outside the mid-plane
    of the front plate on the joint (15 mm in the thesis)."""

    kind: Literal["box-halves"]
    joint: Literal["monolithic", "layer"] = "monolithic"
    joint_thickness: PositiveFloat = 0.15e-3
    bearing_point_offset: PositiveFloat = 0.015
    bearing_point_size: PositiveFloat = 0.010

    @model_validator(mode="after")
    def _joint_fits(self):
        if self.joint == "layer" and self.joint_thickness >= self.flange_thickness:
            raise ValueError("joint_thickness: must be thinner than flange_thickness (half is taken from each)")
        inner_edge = self.wall_thickness / 2 + self.bearing_point_offset - self.bearing_point_size / 2
        if inner_edge <= self.wall_thickness:
            raise ValueError("bearing_point_offset: the bearing point patch overlaps the front plate")
        if self.bearing_point_offset + self.bearing_point_size / 2 > self.flange_width:
            raise ValueError("bearing_point_offset: the bearing point patch runs off the flange")
        return self


class BearingPlateSpec(_Strict):
    """The thick front/back plate carrying the bearing bores (m): flush with the inner wall face, standing
    out by thickness - wall_thickness; `width` along x from x_start (measured from the housing end at
    -length/2); it reaches `below` under and `above` over the split plane."""

    thickness: PositiveFloat
    width: PositiveFloat
    below: PositiveFloat
    above: PositiveFloat
    x_start: float = Field(0.0, ge=0.0)


class BoreSpec(_Strict):
    """A bearing bore through both bearing plates (m): axis along y at x (from the housing centre) on the
    split plane; `bearing` names the bearing whose outer ring it takes (metadata)."""

    name: str = Field(pattern=r"^[A-Za-z0-9_]+$")
    bearing: str = ""
    x: float
    diameter: PositiveFloat


class RimSpec(_Strict):
    """Solid rim around the outside of the walls at the split (m): width outward x height."""

    width: PositiveFloat
    height: PositiveFloat


class FeetSpec(_Strict):
    """Two feet along the bottom of the front and back walls (m): inner edge flush with the inner wall
    face, `width` across, `thickness` high, the full housing length.  on_base: the feet rest on a base,
    so their underside does not radiate (supports are set in the scene)."""

    width: PositiveFloat
    thickness: PositiveFloat
    on_base: bool = False
    bolts_per_foot: int = Field(3, ge=1, le=12)
    bolt_patch_size: PositiveFloat = 0.024


class CoverSpec(_Strict):
    """Bearing covers (m): a square plate of `thickness` on the outside of each bore, reaching `margin`
    beyond the bore all round (square, not round: the block grid; a round cover of diameter + 2 margin has
    pi/4 of its area and mass)."""

    thickness: PositiveFloat
    margin: PositiveFloat = 0.010


class RibSpec(_Strict):
    """A stiffening rib: an axis-aligned plate welded to the outside of the housing, given by its extent
    (m) in x, y and z (housing coordinates).  It must touch the housing (share a face with a wall)."""

    name: str
    x: tuple[float, float]
    y: tuple[float, float]
    z: tuple[float, float]

    @model_validator(mode="after")
    def _ordered(self):
        for axis in ("x", "y", "z"):
            lo, hi = getattr(self, axis)
            if not hi > lo:
                raise ValueError(f"{axis}: the rib's extent must increase (lo < hi)")
        return self


def _touches(lo: float, hi: float, planes) -> bool:
    return any(abs(lo - p) < 1e-9 or abs(hi - p) < 1e-9 for p in planes)


class GearboxGeometry(_Strict):
    """A welded gearbox housing without bottom plate (Sec. 4.5 model, Ch. 5 test gearbox), lengths in m.

    length (x), width (y, along the shafts) and height (z, from the feet underside to the top) are outer
    wall dimensions; split_height is the plane of the bearing centres (the split of a bolted housing)."""

    kind: Literal["gearbox"]
    length: PositiveFloat
    width: PositiveFloat
    height: PositiveFloat
    wall_thickness: PositiveFloat
    split_height: PositiveFloat
    bearing_plate: BearingPlateSpec
    bores: list[BoreSpec] = []
    rim: RimSpec | None = None
    feet: FeetSpec | None = None
    covers: CoverSpec | None = None
    ribs: list[RibSpec] = []
    excitation_patch_size: PositiveFloat = 0.010

    @model_validator(mode="after")
    def _consistent(self):
        t, bp = self.wall_thickness, self.bearing_plate
        if 2 * t >= min(self.length, self.width):
            raise ValueError("wall_thickness: walls thicker than half the length/width leave no housing")
        if not t < self.split_height < self.height - t:
            raise ValueError("split_height: must lie between the bottom and the top plate")
        if bp.thickness <= t:
            raise ValueError("bearing_plate.thickness: must exceed wall_thickness")
        if bp.x_start + bp.width > self.length + 1e-12:
            raise ValueError("bearing_plate.width: x_start + width exceeds the housing length")
        if self.split_height - bp.below <= (self.feet.thickness if self.feet else 0.0):
            raise ValueError("bearing_plate.below: reaches down into the feet / below the housing")
        if self.split_height + bp.above >= self.height - t:
            raise ValueError("bearing_plate.above: reaches up into the top plate")
        names = [b.name for b in self.bores]
        if len(set(names)) != len(names):
            raise ValueError("bores: bore names must be unique")
        from housingfe.geometry.housings import bore_ligaments

        for name, gap in bore_ligaments(self).items():
            # a ligament thinner than the wall would be a sliver of material: bad geometry, bad tets
            if gap < t:
                raise ValueError(f"bores: bore {name!r} leaves a ligament of {gap * 1e3:.1f} mm to the bearing "
                                 f"plate edge or the next bore (less than wall_thickness)")
        if self.covers is not None:
            ordered = sorted(self.bores, key=lambda b: b.x)
            for a, b in itertools.pairwise(ordered):
                if b.x - a.x - (a.diameter + b.diameter) / 2 <= 2 * self.covers.margin:
                    raise ValueError(f"covers: margin {self.covers.margin} m makes the covers of bores "
                                     f"{a.name!r} and {b.name!r} overlap")
        if self.rim is not None and self.rim.height >= bp.below + bp.above:
            raise ValueError("rim.height: taller than the bearing plate")
        for r in self.ribs:
            self._check_rib(r)
        return self

    def _check_rib(self, r: RibSpec) -> None:
        """A rib lies outside the housing's outer envelope and shares a plane with one of its walls."""
        L2, W2, H = self.length / 2, self.width / 2, self.height
        proud = self.bearing_plate.thickness - self.wall_thickness
        inside = (r.x[0] < L2 and r.x[1] > -L2) and (r.y[0] < W2 and r.y[1] > -W2) and (r.z[0] < H and r.z[1] > 0)
        touching = (_touches(*r.x, (-L2, L2)) or _touches(*r.y, (-W2, W2, -W2 - proud, W2 + proud))
                    or _touches(*r.z, (H,)))
        if inside or not touching:
            raise ValueError(f"ribs: rib {r.name!r} must sit outside the walls and share a face with one "
                             "(x = +-length/2, y = +-width/2 or the bearing plate face, z = height)")

    @property
    def min_thickness(self) -> float:
        return self.wall_thickness


# A new geometry kind: add its spec to this union and its builder to housingfe.geometry.mesh.block_model_for.
Geometry = Annotated[BoxGeometry | PlateGeometry | BoxHalvesGeometry | GearboxGeometry,
                     Field(discriminator="kind")]


