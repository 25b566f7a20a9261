"""CalculiX's other hexahedra on the free box: is C3D20R really CalculiX's best element at <= 1 %?

Each argument is SIZE:LAYERS:GRADING:TYPE (m, element layers through the walls, hex grading, a ccx element
type: C3D8I / C3D8 / C3D8R on the linear mesh, C3D20R / C3D20 on the 20-node one), e.g.

    .venv/bin/python benchmarks/experiments/same_mesh/ccx_elements.py 0.015:3:1:C3D8I 0.010:3:1:C3D8I

It meshes the same gmsh block geometry as `housingfe bench modal`, runs `ccx` (2 threads) in
/tmp/ccx-elements/<case>/ and prints the DOFs, the wall time and the max / mean error of the elastic modes below
4 kHz against the extrapolated reference (housingfe/data/benchmarks/box_free_modes_reference.json).
"""
from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import gmsh
import numpy as np

from housingfe.benchmarks.modal import (
    SOLVE_TO,
    _volume_part_of_inp,
    errors_against,
    load_reference,
    parse_calculix_frequencies,
)
from housingfe.geometry.blocks import build_gmsh_model
from housingfe.geometry.mesh import block_model_for
from housingfe.scene import load_housing_scene

WORK = Path("/tmp/ccx-elements")


def write_deck(size: float, layers: int, grading: float, ccx_type: str, path: Path) -> int:
    """The box-free geometry as a ccx *FREQUENCY deck with `ccx_type` elements; returns the node count."""
    scene, _ = load_housing_scene("box-free")
    gmsh.initialize()
    try:
        gmsh.model.add("ccx")
        build_gmsh_model(block_model_for(scene.geometry), "hex", size, layers, grading)
        if ccx_type.startswith("C3D20"):
            gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 1)   # 20-node hexahedra
            gmsh.model.mesh.setOrder(2)
        raw = path.with_suffix(".gmsh.inp")
        gmsh.write(str(raw))
    finally:
        gmsh.finalize()
    nodes, elements = _volume_part_of_inp(raw.read_text(), ccx_type)
    m = scene.material.resolve()
    path.write_text(nodes + elements + (
        "*MATERIAL,NAME=STEEL\n*ELASTIC\n"
        f"{m.youngs_modulus:.6e},{m.poisson_ratio}\n*DENSITY\n{m.density}\n"
        "*SOLID SECTION,ELSET=EALL,MATERIAL=STEEL\n"
        f"*STEP\n*FREQUENCY,SOLVER=SPOOLES\n60,0.,{SOLVE_TO}\n*END STEP\n"))
    return nodes.count("\n") - 1


def main(specs: list[str]) -> None:
    reference, _ = load_reference()
    for spec in specs:
        size, layers, grading, ccx_type = spec.split(":")
        workdir = WORK / spec.replace(":", "_")
        workdir.mkdir(parents=True, exist_ok=True)
        n_nodes = write_deck(float(size), int(layers), float(grading), ccx_type, workdir / "box.inp")
        env = {**os.environ, "OMP_NUM_THREADS": "2", "CCX_NPROC_EQUATION_SOLVER": "2"}
        t0 = time.perf_counter()
        subprocess.run(["ccx", "-i", "box"], cwd=workdir, capture_output=True, check=True, env=env)
        wall = time.perf_counter() - t0
        freqs = parse_calculix_frequencies(workdir / "box.dat")
        freqs = freqs[freqs > 1.0]
        max_err, mean_err = errors_against(reference, freqs.tolist())
        worst = int(np.argmax(np.abs(freqs[:len(reference)] / reference - 1))) + 1
        print(f"{spec:24s} DOFs {3 * n_nodes:7d}  ccx {wall:6.1f} s  max {100 * max_err:.3f} %  "
              f"mean {100 * mean_err:.3f} %  worst elastic mode {worst}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
