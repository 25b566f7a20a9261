"""The registry of geometry kinds: `kind` -> (scene spec class, block-model builder).

Each kind lives in its own module (box.py, plate.py, housings.py), which defines its pydantic spec (with a field
`kind: Literal["<name>"]`) and its builder (spec -> BlockModel) and registers both with one call of
`register_geometry`.  housingfe.geometry.specs imports the kind modules (one line per module) and builds the
scene's discriminated union from the registry; housingfe.geometry.mesh looks the builder up.

This module imports none of the kinds, so that every kind module can import it.
"""
from __future__ import annotations

import typing
from dataclasses import dataclass
from typing import Annotated, Callable

from pydantic import BaseModel, ConfigDict, Field

from housingfe.errors import InputError


class StrictSpec(BaseModel):
    """Base of the geometry specs: unknown keys are errors, values are frozen."""

    model_config = ConfigDict(extra="forbid", frozen=True)


@dataclass(frozen=True)
class GeometryKind:
    """A registered geometry kind: its scene spec class and its builder (spec -> BlockModel).

    A kind that is no block model (an imported CAD solid, a mesh file) gives `mesh` instead, with build_mesh's
    signature (spec, element, size, layers, comm, grading=, layer_size=) -> dict of the HousingMesh fields mesh,
    cell_tags, facet_tags, cell_groups, facet_groups, volume, centroid, points and quality (extra entries;
    build_mesh adds the element size, element and timing unless given, and the element quality), and
    `estimate_dofs` with estimate_dofs' signature (spec, element, degree, size, layers, layer_size) -> int; its
    `build` may be None."""

    spec: type
    build: Callable | None
    mesh: Callable | None = None
    estimate_dofs: Callable | None = None


GEOMETRY_KINDS: dict[str, GeometryKind] = {}


def register_geometry(spec: type, build: Callable | None, *, mesh: Callable | None = None,
                      estimate_dofs: Callable | None = None) -> type:
    """Register a geometry kind: `spec` is a pydantic model with `kind: Literal["<name>"]`, `build(spec)` returns
    its housingfe.geometry.blocks.BlockModel; a kind that meshes itself (no block model) gives `mesh` and
    `estimate_dofs` (see GeometryKind) and may give build=None.  Returns spec."""
    (name,) = typing.get_args(spec.model_fields["kind"].annotation)
    if name in GEOMETRY_KINDS:
        raise ValueError(f"geometry kind {name!r} is registered twice")
    if build is None and mesh is None:
        raise ValueError(f"geometry kind {name!r}: give a block-model builder or a mesher")
    GEOMETRY_KINDS[name] = GeometryKind(spec, build, mesh, estimate_dofs)
    return spec


def own_mesh_kind(geometry) -> GeometryKind | None:
    """The registered kind of a geometry section if it brings its own mesh (no block model), else None."""
    kind = GEOMETRY_KINDS.get(geometry.kind)
    return kind if kind is not None and kind.mesh is not None else None


def geometry_union():
    """The scene's `geometry` type: the registered spec classes, told apart by their `kind` (in registration
    order, which is the order pydantic lists them in when a kind is unknown)."""
    specs = tuple(k.spec for k in GEOMETRY_KINDS.values())
    return Annotated[typing.Union[specs], Field(discriminator="kind")]


def block_model_for(geometry):
    """The block model (housingfe.geometry.blocks.BlockModel) of a validated scene geometry section."""
    kind = GEOMETRY_KINDS.get(geometry.kind)
    if kind is None:
        raise InputError(f"geometry.kind: no builder for {geometry.kind!r}")
    if kind.build is None:
        raise InputError(f"geometry.kind: a {geometry.kind!r} geometry is a mesh, not a block model")
    return kind.build(geometry)
