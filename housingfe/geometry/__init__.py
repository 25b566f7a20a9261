"""Geometry: parametric housings built with gmsh (OpenCASCADE) and handed to dolfinx with named tags.

`build_mesh(geometry, mesh_settings, size, comm)` is the one entry point the rest of the chain uses.
"""
from housingfe.geometry.mesh import HousingMesh, block_model_for, build_mesh  # noqa: F401
