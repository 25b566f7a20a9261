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

    Kinds that bring their own mesh (an imported mesh file) have no block model: `mesh(spec, comm)` returns the
    fields of the distributed housingfe.geometry.mesh.HousingMesh (a dict; build_mesh adds the quality) and `estimate_dofs(spec, degree)` its displacement DOFs."""

    spec: type
    build: Callable | None
    mesh: Callable | None = None
    estimate_dofs: Callable | None = None


GEOMETRY_KINDS: dict[str, GeometryKind] = {}


def register_geometry(spec: type, build: Callable | None, *, mesh: Callable | None = None,
                      estimate_dofs: Callable | None = None) -> type:
    """Register a geometry kind: `spec` is a pydantic model with `kind: Literal["<name>"]`, `build(spec)` returns
    its housingfe.geometry.blocks.BlockModel; a kind with its own mesh gives build=None, `mesh(spec, comm)` ->
    the HousingMesh fields (dict) and `estimate_dofs(spec, degree)` -> DOFs instead.  Returns spec."""
    (name,) = typing.get_args(spec.model_fields["kind"].annotation)
    if name in GEOMETRY_KINDS:
        raise ValueError(f"geometry kind {name!r} is registered twice")
    if (build is None) == (mesh is None):
        raise ValueError(f"geometry kind {name!r}: give either a block-model builder or a mesher")
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
