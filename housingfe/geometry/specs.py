"""Scene specifications of the geometries (validated with pydantic; lengths in m).

Each geometry kind defines its spec and its block-model builder in its own module and registers them there
(housingfe.geometry.registry.register_geometry); the imports below are the one line per kind module that puts
the built-in kinds into the registry, in the order the scene's error messages list them.  `Geometry`, the
scene's geometry section, is the discriminated union (on `kind`) of the registered specs.
"""
from __future__ import annotations

# registration order = the order of the kinds in the scene's messages: box, plate, box-halves, gearbox, mesh, cad
# isort: off
from housingfe.geometry.box import BoxGeometry
from housingfe.geometry.plate import EdgeCondition, PlateEdges, PlateGeometry
from housingfe.geometry.housings import (
    BearingPlateSpec,
    BoreSpec,
    BoxHalvesGeometry,
    CoverSpec,
    FeetSpec,
    GearboxGeometry,
    RibSpec,
    RimSpec,
)
from housingfe.geometry.imported_mesh import MeshGeometry, MeshSet
from housingfe.geometry.cad import CadGeometry
# isort: on
from housingfe.geometry.registry import GEOMETRY_KINDS, block_model_for, geometry_union, register_geometry

__all__ = ["GEOMETRY_KINDS", "BearingPlateSpec", "BoreSpec", "BoxGeometry", "BoxHalvesGeometry", "CadGeometry", "CoverSpec",
           "EdgeCondition", "FeetSpec", "GearboxGeometry", "Geometry", "MeshGeometry", "MeshSet", "PlateEdges", "PlateGeometry", "RibSpec",
           "RimSpec", "block_model_for", "geometry_union", "register_geometry"]

Geometry = geometry_union()
