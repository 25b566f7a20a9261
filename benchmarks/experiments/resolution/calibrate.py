"""Calibration of housingfe.fe.resolution: eigenfrequency error against element size per bending wavelength.

A free steel plate 0.4 x 0.3 x 0.006 m (free: the serendipity brick takes no Dirichlet condition) meshed with each element
family of the scenes (Q2, Q3, S2R hexes with one layer, P2 tets) at several element sizes; every elastic mode below
3 kHz is compared, in sorted order, with the same 3-D model converged (Q3, 12.5 mm, checked against Q3 16.7 mm).
Each row: family, nominal size h (m), the mesh's largest cell edge (m, the measure housingfe.fe.resolution uses),
mode number, reference frequency (Hz), the bending wavelength of the plate at that frequency (m) and the relative
frequency error.  Writes housingfe/data/benchmarks/resolution_calibration.csv (the data the fit is made from).

Run: PYTHONPATH=. OPENBLAS_NUM_THREADS=1 python benchmarks/experiments/resolution/calibrate.py  (~3 min)
"""
from __future__ import annotations

import csv
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from housingfe.fe.model import build_model
from housingfe.fe.resolution import largest_cell_edge
from housingfe.geometry.mesh import bending_wavelength
from housingfe.geometry.specs import PlateGeometry
from housingfe.materials import Material
from housingfe.scene import MeshSpec
from housingfe.solvers import modal

A, B = 0.4, 0.3
CASES = [(0.006, 3000.0), (0.012, 6000.0)]   # thickness (m), f_max (Hz)
STEEL = Material(name="steel", youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)
FAMILIES = {
    "Q2": dict(element="hex", degree=2),
    "Q3": dict(element="hex", degree=3),
    "S2R": dict(element="hex", degree=2, family="serendipity", integration="reduced"),
    "S2": dict(element="hex", degree=2, family="serendipity"),
    "P2": dict(element="tet", degree=2),
    "P3": dict(element="tet", degree=3),
}
FINE = [0.1, 0.075, 0.05, 0.0375, 0.025, 0.02, 0.015]
SIZES = {"Q2": FINE, "Q3": [0.15, 0.1, 0.075, 0.05, 0.0375, 0.025], "S2R": FINE, "S2": FINE, "P2": FINE,
         "P3": [0.1, 0.075, 0.05, 0.0375, 0.025]}
OUT = Path(__file__).resolve().parents[3] / "housingfe" / "data" / "benchmarks" / "resolution_calibration.csv"


def solve(thickness: float, family: str, size: float, f_max: float):
    mesh = MeshSpec(size=size, layers=1, allow_coarse=True, **FAMILIES[family])
    model = build_model(PlateGeometry(kind="plate", a=A, b=B, h=thickness), STEEL, mesh, f_max, MPI.COMM_WORLD)
    result = modal.solve_modes(model.K, model.M, f_max)
    return result.frequencies_hz[result.rigid_count:], largest_cell_edge(model.housing.mesh), model.dofs


def main() -> None:
    t0 = time.perf_counter()
    rows, notes = [], []
    for thickness, f_max in CASES:
        ref, _, dofs = solve(thickness, "Q3", 0.0125, f_max)
        check, _, dofs_check = solve(thickness, "Q3", 0.4 / 24, f_max)
        n = len(ref)
        notes.append(f"{thickness * 1e3:g} mm: reference Q3 12.5 mm ({dofs} DOFs), {n} modes below {f_max:g} Hz, "
                     f"Q3 16.7 mm ({dofs_check} DOFs) differs by at most {np.max(np.abs(check[:n] / ref - 1)):.2e}")
        print(notes[-1], flush=True)
        for family, sizes in SIZES.items():
            for size in sizes:
                # a coarse mesh is stiff: solve far enough above f_max to have as many modes as the reference
                f, h, dofs = solve(thickness, family, size, 3 * f_max)
                m = min(n, len(f))
                err = f[:m] / ref[:m] - 1
                for i in range(m):
                    lam = bending_wavelength(ref[i], thickness, STEEL.youngs_modulus, STEEL.poisson_ratio,
                                             STEEL.density)
                    rows.append([thickness, family, size, h, dofs, i + 1, ref[i], lam, err[i]])
                print(f"{thickness * 1e3:g} mm {family} {size * 1e3:.1f} mm (largest edge {h * 1e3:.1f} mm, {dofs} "
                      f"DOFs): max error {np.max(np.abs(err)):.3%} over {m} modes  [{time.perf_counter() - t0:.0f} s]",
                      flush=True)
    with open(OUT, "w", newline="") as fh:
        fh.write(f"# {__doc__.splitlines()[0]}\n# made by benchmarks/experiments/resolution/calibrate.py\n")
        for note in notes:
            fh.write(f"# {note}\n")
        writer = csv.writer(fh)
        writer.writerow(["thickness_m", "family", "size_m", "largest_edge_m", "dofs", "mode", "reference_hz", "wavelength_m",
                         "relative_error"])
        writer.writerows(rows)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
