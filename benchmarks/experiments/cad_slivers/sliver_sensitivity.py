"""How much do the slivers of a real CAD part's mesh move its modes?  docs/cad.md, "Slivers of real CAD parts".

    PYTHONPATH=. python benchmarks/experiments/cad_slivers/sliver_sensitivity.py SCENE.toml

Builds the housing scene's model (the cad scene of NIST FTC-06 at 20 mm, P2, free, f_max 6 kHz in the docs),
then solves its free modes as meshed and with the Young's modulus of the cells below quality 0.05 scaled by 1e-3
(as if the slivers were cut out of the part) and by 10; prints the first ten elastic frequencies and the largest
relative change of each against the mesh as meshed.
"""
from __future__ import annotations

import dataclasses
import sys

import numpy as np
from dolfinx import mesh as dmesh
from mpi4py import MPI

from housingfe.geometry.blocks import tet_quality
from housingfe.scene import build_model_from_scene, load_housing_scene
from housingfe.solvers.elasticity import MaterialField, assemble_stiffness_mass
from housingfe.solvers.modal import solve_modes


def main(path: str) -> None:
    scene, _ = load_housing_scene(path)
    model = build_model_from_scene(scene, MPI.COMM_WORLD)
    m = model.housing.mesh
    n = m.topology.index_map(3).size_local
    cells = m.geometry.dofmap.array.reshape(n + m.topology.index_map(3).num_ghosts, -1)
    q = tet_quality(m.geometry.x[cells[:n, :4]])
    slivers = np.flatnonzero(q < 0.05).astype(np.int32)
    print(f"{len(slivers)} cells below 0.05, worst {q.min():.4f}")
    tags = dmesh.meshtags(m, 3, slivers, np.full(len(slivers), 7, dtype=np.int32))
    f_max = scene.analysis.f_max
    base = solve_modes(model.K, model.M, f_max)
    f0 = base.frequencies_hz[base.rigid_count:]
    print("as meshed:", np.round(f0[:10], 2))
    for scale in (1e-3, 10.0):
        material = dataclasses.replace(model.material, youngs_modulus=model.material.youngs_modulus * scale)
        K, M = assemble_stiffness_mass(model.V, MaterialField(m, model.material, tags, {7: material}), [])
        r = solve_modes(K, M, f_max)
        f = r.frequencies_hz[r.rigid_count:]
        k = min(len(f), len(f0), 10)
        print(f"slivers' E x {scale:g}: {r.rigid_count} rigid,", np.round(f[:10], 2),
              f"largest change of the first {k}: {np.max(np.abs(f[:k] / f0[:k] - 1)):.2%}")


if __name__ == "__main__":
    main(sys.argv[1])
