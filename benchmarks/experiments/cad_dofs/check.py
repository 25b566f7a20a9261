"""The CAD DOF estimate against the mesh it stands for: docs/cad.md, "Model size: the DOF estimate" (the table).

    PYTHONPATH=. python benchmarks/experiments/cad_dofs/check.py PART.step UNITS SIZE_MM [SIZE_MM ...]

For each element size: estimate_cad_dofs (P2) and its time, then the mesh of build_cad_mesh (the `cad` kind's
path, one rank) and its P2 DOFs, 3 x (vertices + edges).  The bench's parts: `write_step` of the test gearbox
(units m) and `write_bolted_housing(path, 1250)` (mm, minutes per mesh); one line of JSON per size.
"""
from __future__ import annotations

import json
import sys
import time

from mpi4py import MPI

from housingfe.geometry.cad import CadGeometry, build_cad_mesh, cad_facts, estimate_cad_dofs


def main(path: str, units: str, sizes_mm: list[float]) -> None:
    spec = CadGeometry(kind="cad", file=path, units=units)
    facts = cad_facts(spec)
    for size_mm in sizes_mm:
        size = size_mm / 1e3
        t0 = time.perf_counter()
        estimate = estimate_cad_dofs(spec, "tet", 2, size, 1)
        t1 = time.perf_counter()
        mesh = build_cad_mesh(spec, "tet", size, 1, MPI.COMM_SELF)["mesh"]
        mesh.topology.create_entities(1)
        dofs = 3 * (mesh.topology.index_map(0).size_global + mesh.topology.index_map(1).size_global)
        print(json.dumps({"part": path, "size_mm": size_mm, "thin_wall_mm": facts.thin_wall * 1e3,
                          "estimate": estimate, "mesh_dofs": dofs, "ratio": round(estimate / dofs, 3),
                          "estimate_s": round(t1 - t0, 2), "mesh_s": round(time.perf_counter() - t1, 1)}),
              flush=True)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], [float(x) for x in sys.argv[3:]])
