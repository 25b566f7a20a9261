"""The 20-node brick (S2R = CalculiX's C3D20R) with separate element layers through the 8 mm walls and the
15 mm flange: which layers decide the error at 1 %?

Each argument is SIZE:WALL_LAYERS:FLANGE_LAYERS:GRADING, e.g.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/experiments/same_mesh/layers.py 0.030:3:3:1 0.030:2:3:1

The block builder gives every edge as short as a wall thickness the same `mesh.layers`; here its `divisions` is
replaced for the run so that edges of exactly 8 mm and 15 mm get their own counts.  Prints the DOFs, the
in-process time (mesh, assembly, inertia count, eigensolve) and the three worst modes' errors (elastic mode
number: error %) against the extrapolated reference.
"""
from __future__ import annotations

import math
import sys

import numpy as np

import housingfe.geometry.blocks as blocks
from housingfe.benchmarks.modal import load_reference, run_housingfe_case

LAYERS_BY_THICKNESS: dict[float, int] = {}   # m -> element layers


def divisions(length: float, size: float, thin, layers: int, layer_size=None) -> int:
    """`blocks.divisions` with a layer count per wall thickness (mesh.layer_size is not used here)."""
    for thickness, n in LAYERS_BY_THICKNESS.items():
        if abs(length - thickness) < 1e-6:
            return max(n, math.ceil(length / size - 1e-6))
    if length <= max(thin, default=0.0) + 1e-6:
        return max(layers, math.ceil(length / size - 1e-6))
    return max(1, math.ceil(length / size - 1e-6))


def main(specs: list[str]) -> None:
    blocks.divisions = divisions
    reference, _ = load_reference()
    for spec in specs:
        size, wall_layers, flange_layers, grading = spec.split(":")
        LAYERS_BY_THICKNESS.clear()
        LAYERS_BY_THICKNESS.update({0.008: int(wall_layers), 0.015: int(flange_layers)})
        out = run_housingfe_case({"element": "hex", "degree": 2, "size": float(size), "layers": 1,
                                  "grading": float(grading), "family": "serendipity", "integration": "reduced"})
        rel = 100 * (np.asarray(out["frequencies_hz"][:len(reference)]) / reference - 1)
        worst = np.argsort(-np.abs(rel))[:3]
        print(f"{spec:18s} DOFs {out['dofs']:6d}  {out['wall_s']:5.2f} s  max {np.abs(rel).max():.3f} %  worst "
              + ", ".join(f"{i + 1}: {rel[i]:+.2f}" for i in worst), flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
