"""The gearbox interior of a housing scene: the `[coupling]` table -> bore masters, shafts, gears, bearings,
gear meshes and tie rods -> a coupled system (housingfe.coupling).

Validated like the rest of a scene (unknown keys are errors that name the key).  All values SI: m, N, N m,
N/m, N m/rad, rev/min only where the key says so.
"""
from __future__ import annotations

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, PositiveFloat, PositiveInt, model_validator

from housingfe import coupling as cp
from housingfe.errors import InputError

Vector3 = tuple[float, float, float]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class BoreSpec(_Strict):
    """A bore master: surface of the housing, centre (m; default: centre of the surface's bounding box),
    axis, kind (rbe2 | rbe3 | star) and rod_stiffness (N/m per rod, star only)."""

    name: str
    surface: str
    centre: Vector3 | None = None
    axis: Vector3 = (0.0, 0.0, 1.0)
    kind: str = Field("rbe2", pattern="^(rbe2|rbe3|star)$")
    rod_stiffness: PositiveFloat | None = None


class DiscSpec(_Strict):
    """A gear as a rigid cylinder (m) on shaft node `node`."""

    node: int = Field(ge=0)
    outer_diameter: PositiveFloat
    width: PositiveFloat
    inner_diameter: float = Field(0.0, ge=0.0)


class ShaftSpec(_Strict):
    """A stepped Timoshenko shaft: segments [[length, outer_d(, inner_d)], ...] (m) from origin along axis."""

    name: str = Field(pattern=r"^[A-Za-z0-9_]+$")
    origin: Vector3
    axis: Vector3
    segments: list[list[float]]
    elements_per_segment: PositiveInt = 4
    discs: list[DiscSpec] = []


class BearingSpec(_Strict):
    """A bearing from shaft node (e.g. "pinion:0") to a bore master (None: ground): a catalogue designation
    with its mean load (Fx, Fy, Fz, Mx, My) (N, N m) in the bearing frame, or a diagonal stiffness (6 values,
    N/m and N m/rad, bearing frame)."""

    shaft_node: str
    bore: str | None = None
    axis: Vector3 = (0.0, 0.0, 1.0)
    designation: str | None = None
    load: tuple[float, float, float, float, float] | None = None
    stiffness: tuple[float, float, float, float, float, float] | None = None

    @model_validator(mode="after")
    def _one(self):
        if (self.designation is None) == (self.stiffness is None):
            raise ValueError("give either designation (+ load) or stiffness")
        if self.designation is not None and self.load is None:
            raise ValueError("load: required with a designation (N, N m)")
        return self


class GearMeshSpec(_Strict):
    """Mesh stiffness (N/m) along the line of action `direction` through the contact `point` (m)."""

    a: str
    b: str
    stiffness: PositiveFloat
    point: Vector3
    direction: Vector3
    damping: float = Field(0.0, ge=0.0)


class TieRodSpec(_Strict):
    """A solid round beam (m) between two nodes."""

    a: str
    b: str
    diameter: PositiveFloat


class CouplingSpec(_Strict):
    bores: list[BoreSpec] = []
    shafts: list[ShaftSpec] = []
    bearings: list[BearingSpec] = []
    gear_meshes: list[GearMeshSpec] = []
    tie_rods: list[TieRodSpec] = []


def couple_from_spec(model, spec: CouplingSpec | dict) -> cp.CoupledSystem:
    """housingfe.coupling.couple() from a scene's [coupling] section (a CouplingSpec or the raw dict)."""
    from housingfe.bearings import bearing_stiffness
    from housingfe.shafts import CircularSection, RigidDisc, Shaft

    if isinstance(spec, dict):
        from pydantic import ValidationError

        try:
            spec = CouplingSpec.model_validate(spec)
        except ValidationError as exc:
            err = exc.errors()[0]
            raise InputError(f"coupling.{'.'.join(str(p) for p in err['loc'])}: {err['msg']}") from None
    connections = [cp.BoreConnection(b.name, b.surface, tuple(b.centre if b.centre is not None
                                                              else cp.surface_centre(model, b.surface)),
                                     b.axis, b.kind, b.rod_stiffness) for b in spec.bores]
    shafts, elements = {}, []
    for s in spec.shafts:
        shaft = Shaft.stepped([tuple(seg) for seg in s.segments], origin=s.origin, axis=s.axis,
                              elements_per_segment=s.elements_per_segment)
        for d in s.discs:
            shaft.add_disc(d.node, RigidDisc.cylinder(d.outer_diameter, d.width, d.inner_diameter))
        shafts[s.name] = shaft
    for b in spec.bearings:
        k = (bearing_stiffness(b.designation, b.load).K if b.designation is not None else np.diag(b.stiffness))
        elements.append(cp.bearing(b.shaft_node, b.bore, k, b.axis))
    meshes = [cp.GearMesh(g.a, g.b, g.stiffness, g.point, g.direction, g.damping) for g in spec.gear_meshes]
    rods = [cp.TieRod(t.a, t.b, CircularSection(t.diameter)) for t in spec.tie_rods]
    return cp.couple(model, connections, elements, shafts, meshes, rods)
