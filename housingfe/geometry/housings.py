"""The housings of van Roosmalen (1994) Ch. 4-5 built from the blocks of housingfe.geometry.features.

- `box_halves_model`: two Sec. 4.2 boxes joined at their flanges (Sec. 4.4), joint monolithic or a thin
  elastic layer (gasket) of its own cell group "joint".
- `gearbox_model`: the welded gearbox of Sec. 4.5 (80 % scale model) and the Ch. 5 test gearbox: thin
  walls split at the bearing centre plane, thick front/back bearing plates with round bores, an optional rim
  around the split, two feet.  The reconstruction from Appendix E's plate table is documented in
  docs/housings.md and in the scenes; `appendix_e_plates` gives the plate areas and perimeters of a
  reconstruction in the table's own convention so that they can be compared with it.

Coordinates: x along the length, y across (shaft axes of the gearboxes), z up; all lengths in m.
"""
from __future__ import annotations

import itertools
import math
from typing import Literal

from pydantic import Field, PositiveFloat, model_validator

from housingfe.geometry.blocks import BlockModel
from housingfe.geometry.box import BoxGeometry
from housingfe.geometry.features import (
    Part,
    assemble,
    bore_through,
    box_part,
    face_grid_points,
    face_patch,
    rim_parts,
)
from housingfe.geometry.registry import StrictSpec as _Strict
from housingfe.geometry.registry import register_geometry


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

    @property
    def wall_thicknesses(self) -> dict[str, float]:
        """The plates whose bending waves the mesh must resolve: name -> thickness (m); the rim counts as a plate
        of its smaller cross-section dimension, a rib as one of its thinnest extent."""
        walls = {"walls": self.wall_thickness, "bearing plates": self.bearing_plate.thickness}
        if self.rim is not None:
            walls["rim"] = min(self.rim.width, self.rim.height)
        if self.feet is not None:
            walls["feet"] = self.feet.thickness
        if self.covers is not None:
            walls["covers"] = self.covers.thickness
        for rib in self.ribs:
            walls[f"rib {rib.name}"] = min(hi - lo for lo, hi in (rib.x, rib.y, rib.z))
        return walls

    @property
    def wall_cell_groups(self) -> dict[str, tuple[str, ...]]:
        """The cell groups (name prefixes) of each entry of wall_thicknesses."""
        groups = {"walls": ("top", "front", "back", "side"), "bearing plates": ("bearing_plate",), "rim": ("rim",),
                  "feet": ("foot",), "covers": ("cover_",)}
        groups.update({f"rib {rib.name}": (f"rib_{rib.name}",) for rib in self.ribs})
        return {name: groups[name] for name in self.wall_thicknesses}

# --------------------------------------------------------------------------------------------- box halves


def _box_half_parts(suffix: str, L: float, W: float, H: float, t: float, tf: float, b: float,
                    joint: float, sign: int) -> list[Part]:
    """Parts of one Sec. 4.2 box standing on the joint plane z = 0 (sign +1, upwards) or hanging from it
    (sign -1); the flange starts at joint/2 from the plane (the joint layer takes half of it from each
    flange, so that the total thickness between the outer flange faces stays 2 tf)."""
    L2, W2 = L / 2, W / 2

    def z(a: float, c: float) -> tuple[float, float]:
        return (a, c) if sign > 0 else (-c, -a)

    zf, zw, zt = z(joint / 2, tf), z(tf, H - t), z(H - t, H)
    return [
        box_part(f"top{suffix}", (-L2, L2), (-W2, W2), zt),
        box_part(f"left{suffix}", (-L2, -L2 + t), (-W2, W2), zw),
        box_part(f"right{suffix}", (L2 - t, L2), (-W2, W2), zw),
        box_part(f"front{suffix}", (-L2 + t, L2 - t), (-W2, -W2 + t), zw),
        box_part(f"back{suffix}", (-L2 + t, L2 - t), (W2 - t, W2), zw),
        *_flange_ring(f"flange{suffix}", L2, W2, t, b, zf),
    ]


def _flange_ring(name: str, L2: float, W2: float, t: float, b: float, z: tuple[float, float]) -> list[Part]:
    """The flange of the Sec. 4.2 box: from the inner wall faces to b outside the walls."""
    return [box_part(name, (-L2 - b, L2 + b), (-W2 - b, -W2 + t), z),
            box_part(name, (-L2 - b, L2 + b), (W2 - t, W2 + b), z),
            box_part(name, (-L2 - b, -L2 + t), (-W2 + t, W2 - t), z),
            box_part(name, (L2 - t, L2 + b), (-W2 + t, W2 - t), z)]


def box_bolt_centres(L: float, W: float, b: float) -> list[tuple[float, float]]:
    """The eight bolts of Sec. 4.3/4.4 (positions not in the text): flange corners and side midpoints, on the
    flange centre line (the same assumption as housingfe.geometry.box)."""
    cx, cy = L / 2 + b / 2, W / 2 + b / 2
    return [(-cx, -cy), (0.0, -cy), (cx, -cy), (cx, 0.0), (cx, cy), (0.0, cy), (-cx, cy), (-cx, 0.0)]


def bearing_point(W: float, t: float, offset: float) -> tuple[float, float, float]:
    """The 'bearing-like point' of Sec. 4.4 on the joint plane: at mid-length, `offset` (m; 15 mm in the
    thesis) outside the heart line (mid-plane) of the front plate."""
    return (0.0, -W / 2 + t / 2 - offset, 0.0)


def box_halves_model(length: float, width: float, height: float, wall_thickness: float,
                     flange_thickness: float, flange_width: float, bolt_patch_size: float = 0.024,
                     joint: str = "monolithic", joint_thickness: float = 0.15e-3,
                     bearing_point_offset: float = 0.015, bearing_point_size: float = 0.010) -> BlockModel:
    """Two boxes of Sec. 4.2 joined at their flanges (Sec. 4.4), joint plane z = 0.

    joint "monolithic": the flanges are welded into one 2 x flange_thickness plate (the thesis' model).
    joint "layer": a layer of joint_thickness (cell group "joint", give it its own material in the scene's
    [regions]) replaces the middle of the flange pair.
    Cell groups: top/left/right/front/back/flange + "_upper"/"_lower", joint.  Surfaces: outer,
    outer_<part>, inner, bolt_1..bolt_8 (head face on the upper flange and nut face on the lower one; group
    "bolts"), bearing_point (a bearing_point_size square on the upper flange top, centred above the Sec. 4.4
    bearing-like point), joint_edge (outer edge faces of the joint layer).
    Points: bolts (on the joint plane), bearing_point (on the joint plane), response_points.
    """
    L, W, H, t, tf, b = length, width, height, wall_thickness, flange_thickness, flange_width
    g = joint_thickness if joint == "layer" else 0.0
    parts = _box_half_parts("_upper", L, W, H, t, tf, b, g, +1) + _box_half_parts("_lower", L, W, H, t, tf, b, g, -1)
    if g:
        parts += _flange_ring("joint", L / 2, W / 2, t, b, (-g / 2, g / 2))
    cavity = box_part("cavity", (-L / 2 + t, L / 2 - t), (-W / 2 + t, W / 2 - t), (-H + t, H - t))
    s = bolt_patch_size
    patches = []
    for n, (x, y) in enumerate(box_bolt_centres(L, W, b), start=1):
        patches.append(face_patch(f"bolt_{n}", (x, y, tf), (s, s), (0, 0, 1), ("bolts",)))
        patches.append(face_patch(f"bolt_{n}", (x, y, -tf), (s, s), (0, 0, -1), ("bolts",)))
    bp = bearing_point(W, t, bearing_point_offset)
    patches.append(face_patch("bearing_point", (bp[0], bp[1], tf), (bearing_point_size,) * 2, (0, 0, 1)))
    if g:
        for normal, at in (((0, -1, 0), (0, -W / 2 - b, 0)), ((0, 1, 0), (0, W / 2 + b, 0)),
                           ((-1, 0, 0), (-L / 2 - b, 0, 0)), ((1, 0, 0), (L / 2 + b, 0, 0))):
            patches.append(face_patch("joint_edge", at, (L + 2 * b, g) if normal[0] == 0 else (W + 2 * b, g),
                                      normal))
    points = {
        "bolts": [(x, y, 0.0) for x, y in box_bolt_centres(L, W, b)],
        "bearing_point": [bp],
        "response_points": face_grid_points((-L / 2, -W / 2, tf), (L / 2, -W / 2, H), 3)
        + face_grid_points((-L / 2, -W / 2, H), (L / 2, W / 2, H), 3),
    }
    return assemble(parts, [cavity], patches, thin=(t, tf - g / 2) + ((g,) if g else ()), points=points)


# ------------------------------------------------------------------------------------------------ gearbox


def gearbox_parts(g) -> list[Part]:
    """Parts of a welded gearbox (spec g: housingfe.geometry.specs.GearboxGeometry), in ownership order."""
    L2, W2, H, t, zs = g.length / 2, g.width / 2, g.height, g.wall_thickness, g.split_height
    bp = g.bearing_plate
    proud = bp.thickness - t  # the bearing plate is flush with the inner wall face and stands out by `proud`
    xb = (-L2 + bp.x_start, -L2 + bp.x_start + bp.width)
    zb = (zs - bp.below, zs + bp.above)
    parts = [
        box_part("top", (-L2, L2), (-W2, W2), (H - t, H)),
        box_part("bearing_plate_front", xb, (-W2 - proud, -W2 + t), zb),
        box_part("bearing_plate_back", xb, (W2 - t, W2 + proud), zb),
    ]
    if g.rim is not None:
        h = g.rim.height
        parts += rim_parts("rim", (-L2, L2), (-W2, W2), (zs - h / 2, zs + h / 2), g.rim.width)
    if g.feet is not None:
        f = g.feet
        parts += [box_part("foot_front", (-L2, L2), (-W2 + t - f.width, -W2 + t), (0.0, f.thickness)),
                  box_part("foot_back", (-L2, L2), (W2 - t, W2 - t + f.width), (0.0, f.thickness))]
    for side, y in (("front", (-W2, -W2 + t)), ("back", (W2 - t, W2))):
        parts += [box_part(f"{side}_low", (-L2, L2), y, (0.0, zs)),
                  box_part(f"{side}_up", (-L2, L2), y, (zs, H - t))]
    for side, x in (("left", (-L2, -L2 + t)), ("right", (L2 - t, L2))):
        parts += [box_part(f"side_low_{side}", x, (-W2 + t, W2 - t), (0.0, zs)),
                  box_part(f"side_up_{side}", x, (-W2 + t, W2 - t), (zs, H - t))]
    parts += [box_part(f"rib_{r.name}", r.x, r.y, r.z) for r in g.ribs]   # outside, so tagged outer_rib_<name>
    return parts


def gearbox_model(g) -> BlockModel:
    """Block model of a welded gearbox housing with round bores (spec g: GearboxGeometry).

    Cell groups: top, front_up/low, back_up/low, side_up/low_left/right, bearing_plate_front/back, rim,
    foot_front/back.  Surfaces: outer (radiating; feet contact faces excluded when feet.on_base),
    outer_<part>, inner, bore_<name>_front/back (groups bore_<name>, bores), foot_bottom (contact faces),
    foot_bolt_1..n (groups foot_bolts), excitation_point (a small patch on the front bearing plate between
    the bores, the Sec. 4.5 axial force input).  Points: bearing_centres, excitation_point, response_points.
    """
    L2, W2, H, t, zs = g.length / 2, g.width / 2, g.height, g.wall_thickness, g.split_height
    bp = g.bearing_plate
    proud = bp.thickness - t
    parts = gearbox_parts(g)
    cavity = box_part("cavity", (-L2 + t, L2 - t), (-W2 + t, W2 - t), (-1.0, H - t))
    bores, points = [], {"bearing_centres": [], "response_points": []}
    for bore in g.bores:
        for side, y in (("front", (-W2 - proud, -W2 + t)), ("back", (W2 - t, W2 + proud))):
            overshoot = ((0.0, 1e-3) if side == "front" else (1e-3, 0.0)) if g.covers else (1e-3, 1e-3)
            bores.append(bore_through(f"bore_{bore.name}_{side}", bore.x, zs, bore.diameter, y,
                                      (f"bore_{bore.name}", "bores"), overshoot))
            points["bearing_centres"].append((bore.x, (y[0] + y[1]) / 2, zs))
    if g.covers is not None:
        parts = cover_parts(g) + parts
    patches = []
    x_exc = sum(b.x for b in g.bores) / len(g.bores) if g.bores else 0.0
    exc = (x_exc, -W2 - proud, zs)
    patches.append(face_patch("excitation_point", exc, (g.excitation_patch_size,) * 2, (0, -1, 0)))
    points["excitation_point"] = [exc]
    if g.feet is not None:
        f = g.feet
        for y0, y1 in ((-W2 + t - f.width, -W2 + t), (W2 - t, W2 - t + f.width)):
            patches.append(face_patch("foot_bottom", (0.0, (y0 + y1) / 2, 0.0),
                                      (2 * L2, f.width), (0, 0, -1), radiates=not f.on_base))
        for n, (x, y) in enumerate(foot_bolt_centres(g), start=1):
            patches.append(face_patch(f"foot_bolt_{n}", (x, y, 0.0), (f.bolt_patch_size,) * 2, (0, 0, -1),
                                      ("foot_bolts",), radiates=not f.on_base))
    # side walls reach z = 0 between the feet; with feet on a base their bottom edges touch it too
    points["response_points"] = (face_grid_points((-L2, -W2, 0.0), (L2, -W2, H), 3)
                                 + face_grid_points((-L2, -W2, H), (L2, W2, H), 3)
                                 + face_grid_points((-L2, -W2, 0.0), (-L2, W2, H), 2))
    thin = [t, bp.thickness] + ([g.feet.thickness] if g.feet else []) + ([g.rim.width] if g.rim else [])
    cavities = [cavity] + ([Part("bore", (b.centre[0] - b.radius, b.span[0], b.centre[2] - b.radius),
                                 (b.centre[0] + b.radius, b.span[1], b.centre[2] + b.radius)) for b in bores]
                           if g.covers is not None else [])
    return assemble(parts, cavities, patches, bores, thin=thin, points=points)


def cover_parts(g) -> list[Part]:
    """Square bearing covers on the outside of the bearing plates (spec g.covers), one per bore and side."""
    W2, zs, c = g.width / 2, g.split_height, g.covers
    proud = g.bearing_plate.thickness - g.wall_thickness
    out = []
    for bore in g.bores:
        half = bore.diameter / 2 + c.margin
        x, z = (bore.x - half, bore.x + half), (zs - half, zs + half)
        out += [box_part(f"cover_{bore.name}_front", x, (-W2 - proud - c.thickness, -W2 - proud), z),
                box_part(f"cover_{bore.name}_back", x, (W2 + proud, W2 + proud + c.thickness), z)]
    return out


def foot_bolt_centres(g) -> list[tuple[float, float]]:
    """Bolt centres (x, y) on the feet: feet.bolts_per_foot evenly spread along each foot, half a pitch from
    the ends, on the foot centre line (positions not in the thesis: an assumption)."""
    f = g.feet
    W2, t = g.width / 2, g.wall_thickness
    pitch = g.length / f.bolts_per_foot
    xs = [-g.length / 2 + (i + 0.5) * pitch for i in range(f.bolts_per_foot)]
    yc = W2 - t + f.width / 2
    return [(x, -yc) for x in xs] + [(x, yc) for x in xs]


def appendix_e_plates(g) -> dict[str, tuple[float, float]]:
    """Areas (m^2) and perimeters (m) of one plate of each kind of a gearbox reconstruction, in the
    convention of the thesis' Appendix E table: plates end at the housing edges, the split and the
    thickness boundaries; the L-shaped thin front plates count with their true area and the perimeter of a
    rectangle of that area over the full housing length; the side plates span the housing width, the upper
    one up to the underside of the top plate; the front/low plates run from z = 0 (feet included)."""
    L, W, H, t, zs = g.length, g.width, g.height, g.wall_thickness, g.split_height
    bp = g.bearing_plate
    thick_h = bp.below + bp.above
    front_up = L * (H - zs) - bp.width * bp.above
    front_low = L * zs - bp.width * bp.below
    out = {
        "top": (L * W, 2 * (L + W)),
        "side up": (W * (H - t - zs), 2 * (W + H - t - zs)),
        "side low": (W * zs, 2 * (W + zs)),
        "front up": (front_up, 2 * (L + front_up / L)),
        "front low": (front_low, 2 * (L + front_low / L)),
        "front": (bp.width * thick_h, 2 * (bp.width + thick_h)),
    }
    if g.feet is not None:
        out["foot"] = (L * g.feet.width, 2 * (L + g.feet.width))
    return out


def bore_ligaments(g) -> dict[str, float]:
    """Smallest material width (m) between each bore and the edges of the bearing plate or its neighbour
    bore: a bore that breaks out or leaves a sliver is a bad parameter, reported by name."""
    bp = g.bearing_plate
    x0 = -g.length / 2 + bp.x_start
    x1 = x0 + bp.width
    out = {}
    bores = sorted(g.bores, key=lambda b: b.x)
    for i, b in enumerate(bores):
        r = b.diameter / 2
        gaps = [b.x - r - x0, x1 - b.x - r, bp.above - r, bp.below - r]
        if i > 0:
            gaps.append(b.x - bores[i - 1].x - r - bores[i - 1].diameter / 2)
        out[b.name] = min(gaps)
    return out


def appendix_e_total_area(g) -> float:
    """Total plate area (m^2) of the Appendix E table convention: one top, two of every other plate."""
    return math.fsum(s * (1 if name == "top" else 2) for name, (s, _) in appendix_e_plates(g).items())


def build_box_halves(g: BoxHalvesGeometry) -> BlockModel:
    """Block model of a validated BoxHalvesGeometry."""
    return box_halves_model(g.length, g.width, g.height, g.wall_thickness, g.flange_thickness, g.flange_width,
                            g.bolt_patch_size, g.joint, g.joint_thickness, g.bearing_point_offset,
                            g.bearing_point_size)


register_geometry(BoxHalvesGeometry, build_box_halves)
register_geometry(GearboxGeometry, gearbox_model)
