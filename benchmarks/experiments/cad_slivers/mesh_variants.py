"""gmsh options against the slivers of a real CAD part: docs/cad.md, "Slivers of real CAD parts" (first table).

    PYTHONPATH=. python benchmarks/experiments/cad_slivers/mesh_variants.py PART.stp SIZE VARIANT [VARIANT ...]

Imports the STEP file (mm) as the cad kind does, meshes it with the project's tetrahedral options at SIZE (m)
plus one VARIANT (see VARIANTS), without the sliver refinement, and prints the count of tetrahedra below shape
ratio 0.05, the worst, the tetrahedra, nodes and the time.  Run each variant in its own process: some options
hang or abort gmsh 4.8.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import gmsh

from housingfe.geometry.blocks import _set_mesh_options, _tet_qualities
from housingfe.geometry.cad import import_solid


def options(**values):
    def apply(size):
        for key, value in values.items():
            gmsh.option.setNumber(key, value)
    return apply


def feature_sizes(size, factor=1.0, curves=True, faces=True):
    """Point sizes from the features: the shortest curve at a point, and the width 2 area / perimeter of every
    face narrower than `size` at all of its points (a chamfer strip); times `factor`."""
    h = {}

    def put(point, value):
        h[point] = min(h.get(point, size), value)
    if curves:
        for _, c in gmsh.model.getEntities(1):
            length = gmsh.model.occ.getMass(1, c)
            if length > 1e-7:     # degenerate curves (zero length) of sphere poles and cone tips
                for _, p in gmsh.model.getBoundary([(1, c)], oriented=False):
                    put(abs(p), factor * length)
    if faces:
        for _, f in gmsh.model.getEntities(2):
            area = gmsh.model.occ.getMass(2, f)
            perimeter = sum(gmsh.model.occ.getMass(1, abs(c))
                            for _, c in gmsh.model.getBoundary([(2, f)], oriented=False))
            width = 2 * area / perimeter if perimeter > 0 else size
            if width < size:
                for _, p in gmsh.model.getBoundary([(2, f)], oriented=False, recursive=True):
                    put(abs(p), factor * width)
    for point, value in h.items():
        gmsh.model.mesh.setSize([(0, point)], value)


def both(*steps):
    def apply(size):
        for step in steps:
            step(size)
    return apply


MESHADAPT = options(**{"Mesh.Algorithm": 1})
VARIANTS = {
    "as-is": lambda size: None,
    "meshadapt": MESHADAPT,
    "delaunay2d": options(**{"Mesh.Algorithm": 5}),
    "curvature12": options(**{"Mesh.MeshSizeFromCurvature": 12}),
    "curves": lambda s: feature_sizes(s, faces=False),
    "curves+meshadapt": both(lambda s: feature_sizes(s, faces=False), MESHADAPT),
    "faces": lambda s: feature_sizes(s, curves=False),
    "faces+meshadapt": both(lambda s: feature_sizes(s, curves=False), MESHADAPT),
    "features+meshadapt": both(feature_sizes, MESHADAPT),
    "features2+meshadapt": both(lambda s: feature_sizes(s, factor=2.0), MESHADAPT),
}


def run(path: Path, size: float, variant: str) -> dict:
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        t0 = time.perf_counter()
        import_solid(path, "mm", "never")
        _set_mesh_options("tet")
        gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        gmsh.model.mesh.setSize(gmsh.model.getEntities(0), size)
        VARIANTS[variant](size)
        gmsh.model.mesh.generate(3)
        q, _ = _tet_qualities()
        return {"below_0.05": int((q < 0.05).sum()), "worst": float(q.min()), "tets": len(q),
                "nodes": len(gmsh.model.mesh.getNodes()[0]), "s": time.perf_counter() - t0}
    finally:
        gmsh.finalize()


if __name__ == "__main__":
    for name in sys.argv[3:]:
        print(name, run(Path(sys.argv[1]), float(sys.argv[2]), name), flush=True)
