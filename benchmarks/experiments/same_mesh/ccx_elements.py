"""CalculiX's other hexahedra on the free box: is C3D20R really CalculiX's best element at <= 1 %?

Each argument is SIZE:LAYERS:GRADING:TYPE (m, element layers through the walls, hex grading, a ccx element
type: C3D8I / C3D8 / C3D8R on the linear mesh, C3D20R / C3D20 on the 20-node one), e.g.

    .venv/bin/python benchmarks/experiments/same_mesh/ccx_elements.py 0.015:3:1:C3D8I 0.010:3:1:C3D8I

It writes the same gmsh block geometry as `housingfe bench modal` (its `run_calculix_case`), runs `ccx`
(2 threads) in /tmp/ccx-elements/<case>/ and prints the DOFs, the wall time and the max / mean error of the
elastic modes below 4 kHz against the extrapolated reference
(housingfe/data/benchmarks/box_free_modes_reference.json).
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from housingfe.benchmarks.modal import errors_against, load_reference, run_calculix_case

WORK = Path("/tmp/ccx-elements")


def main(specs: list[str]) -> None:
    reference, _ = load_reference()
    for spec in specs:
        size, layers, grading, ccx_type = spec.split(":")
        workdir = WORK / spec.replace(":", "_")
        workdir.mkdir(parents=True, exist_ok=True)
        case = {"element": "hex", "ccx_type": ccx_type, "size": float(size), "layers": int(layers),
                "grading": float(grading)}
        out = run_calculix_case(case, workdir)
        freqs = np.asarray(out["frequencies_hz"])
        max_err, mean_err = errors_against(reference, freqs.tolist())
        worst = int(np.argmax(np.abs(freqs[:len(reference)] / reference - 1))) + 1
        print(f"{spec:24s} DOFs {out['dofs']:7d}  ccx {out['wall_s']:6.1f} s  max {100 * max_err:.3f} %  "
              f"mean {100 * mean_err:.3f} %  worst elastic mode {worst}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
