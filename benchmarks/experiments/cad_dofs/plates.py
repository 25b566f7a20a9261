"""How gmsh's Delaunay (housingfe.geometry.blocks.mesh_tetrahedra) fills a plate: docs/cad.md, "Model size: the
DOF estimate" (the plate table behind housingfe.geometry.cad's SURFACE_NODES_PER_H2, INTERIOR_NODES_PER_H3,
BOUNDARY_LAYER, EDGES_PER_NODE, CELLS_PER_NODE).

    PYTHONPATH=. python benchmarks/experiments/cad_dofs/plates.py [SIDE/h] [THICKNESS/h,...]

Meshes a square plate of SIDE x SIDE x t (h = 1, default 40 h; t/h default 0.25,0.5,...,8) and prints, per
thickness, the nodes, edges, tetrahedra, the nodes per h^2 of boundary area and the edges per node.
"""
from __future__ import annotations

import json
import sys

import gmsh
import numpy as np

from housingfe.geometry.blocks import mesh_tetrahedra


def counts(side: float, thickness: float, size: float = 1.0) -> tuple[int, int, int]:
    """Nodes, edges and tetrahedra of the plate's mesh at element size `size`."""
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("plate")
        gmsh.model.occ.addBox(0, 0, 0, side, side, thickness)
        gmsh.model.occ.synchronize()
        mesh_tetrahedra(size, hxt_fallback=False)
        nodes = len(gmsh.model.mesh.getNodes()[0])
        ends = gmsh.model.mesh.getElementEdgeNodes(4).reshape(-1, 2)
        edges = len(np.unique(np.sort(ends, axis=1), axis=0))
        cells = len(gmsh.model.mesh.getElements(3)[1][0])
    finally:
        gmsh.finalize()
    return nodes, edges, cells


def main(side: float = 40.0, ratios=(0.25, 0.5, 0.75, 1, 1.25, 1.5, 2, 2.5, 3, 4, 6, 8)) -> None:
    for t in ratios:
        nodes, edges, cells = counts(side, t)
        area = 2 * side * side + 4 * side * t
        print(json.dumps({"side/h": side, "t/h": t, "nodes": nodes, "edges": edges, "cells": cells,
                          "nodes_per_h2": round(nodes / area, 3), "edges_per_node": round(edges / nodes, 2)}),
              flush=True)


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 40.0,
         *([tuple(float(x) for x in sys.argv[2].split(","))] if len(sys.argv) > 2 else []))
