"""# The modes of a free box housing

The simplest housing of the thesis (van Roosmalen 1994, Sec. 4.2) is an open welded steel box on a foot flange:
five 8 mm plates and a 15 mm flange, 325 x 225 x 125 mm, 24.5 kg.  Hung free, it has six rigid-body modes at
0 Hz and then its elastic plate modes; the thesis measured and computed the first elastic one at 641 Hz and
35 of them below 4 kHz.

This example goes through the first two stages of the chain, on the public API:

1. `build_model(geometry, material, mesh, f_max, comm)` meshes the box and assembles K and M: a
   `HousingModel`, which is a `Structure` (`housingfe.fe.structure`): K, M, C, its DOF count, how a load becomes
   a vector, how a vector maps back to the housing's field, and how many zero modes it must have (6: free);
2. `modes(structure, f_max)` returns every mode below f_max, proven complete by an inertia count (Sylvester:
   the negative pivots of K - (2 pi f_max)^2 M count the eigenvalues below), and checks the number of zero modes
   against the structure's `expected_zero_modes`.

The six rigid-body modes carry the box's mass: projecting the exact rigid motions on them gives the mass and the
centre of gravity, a check of the model that needs no reference.

Units SI: m, kg, Pa, Hz.  Run:  .venv/bin/python examples/box_modes.py [--small] [--out DIR]
(--small: 40 mm elements, modes to 2 kHz, a few seconds; default: the element size from 6 elements per bending
wavelength at 4 kHz, about a minute.  --out DIR also writes modes.csv.)
"""
# %%
from __future__ import annotations

import argparse

import numpy as np
from mpi4py import MPI

from housingfe.fe.model import build_model
from housingfe.fe.structure import Structure
from housingfe.geometry.box import BoxGeometry
from housingfe.materials import LIBRARY
from housingfe.outputs import atomic_output_dir, format_table, write_csv
from housingfe.report import resolution_text
from housingfe.scene import MeshSpec
from housingfe.solvers import elasticity
from housingfe.solvers.modal import modes, rigid_body_mass_properties

# The files written with --out DIR (tests/test_examples.py checks that they are there).
OUTPUTS = ("modes.csv",)

# %% [markdown]
# ## The box
#
# The geometry spec is the same object a scene's `[geometry]` table becomes (`kind = "box"`); the dimensions
# are the reconstruction of Fig. 4.2 that the scene box-free uses (mass 24.4 kg against the published 24.5 kg).

# %%
BOX = BoxGeometry(kind="box", length=0.325, width=0.225, height=0.125, wall_thickness=0.008,
                  flange_thickness=0.015, flange_width=0.073)
STEEL = LIBRARY["steel"]                       # E = 210 GPa, nu = 0.3, rho = 7850 kg/m^3


def box_structure(small: bool, f_max: float) -> Structure:
    """The free box as a HousingModel: structured quadratic hexahedra (Q2), one layer through each wall."""
    mesh = MeshSpec(element="hex", degree=2, size=0.04) if small else MeshSpec(element="hex", degree=2,
                                                                              elements_per_wavelength=6)
    return build_model(BOX, STEEL, mesh, f_max, MPI.COMM_WORLD)


# %% [markdown]
# ## Modes
#
# `modes` raises a SolverError if the eigensolver returned fewer modes than the inertia count says lie below
# f_max, or if the free box does not show exactly six zero modes.

# %%
def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0].lstrip("# "))
    parser.add_argument("--small", action="store_true", help="coarse mesh, modes to 2 kHz (seconds)")
    parser.add_argument("--out", default=None, help="folder for modes.csv")
    args = parser.parse_args(argv)
    f_max = 2000.0 if args.small else 4000.0

    box = box_structure(args.small, f_max)
    assert isinstance(box, Structure)
    basis = modes(box, f_max)
    n0 = basis.rigid_count
    f = basis.frequencies_hz

    # the mass the rigid-body modes carry, against density x volume of the mesh
    rigid = rigid_body_mass_properties(box.M, basis.vectors[:n0], elasticity.rigid_body_vectors(box.V))
    mass = STEEL.density * box.housing.volume

    rows = [[i + 1, "rigid" if i < n0 else "elastic", float(f[i]), float(basis.residuals[i])] for i in range(len(f))]
    if MPI.COMM_WORLD.rank == 0:
        print(f"free box: {box.dofs} DOFs, {len(f)} modes below {f_max:g} Hz (complete, of the discrete model: "
              f"{basis.complete}), {n0} rigid-body modes (expected {box.expected_zero_modes})")
        # how close the discrete model's modes are to the box's: the mesh's resolution of f_max
        print(resolution_text(box.resolution.as_dict()))
        print(f"first elastic mode {f[n0]:.1f} Hz (thesis Sec. 4.2: 641 Hz; coarser meshes are stiffer)")
        print(f"mass from the rigid-body modes {rigid['mass_kg']:.3f} kg, density x volume {mass:.3f} kg; "
              f"centre of gravity {np.round(rigid['centre_of_gravity_m'], 4).tolist()} m")
        print(format_table(["mode", "kind", "frequency_hz", "residual"], rows[:n0 + 8]))
    if args.out:
        with atomic_output_dir(args.out) as tmp:
            write_csv(tmp / OUTPUTS[0], ["mode", "kind", "frequency_hz", "residual"], rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
