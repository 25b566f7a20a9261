"""# The test gearbox housing with its drivetrain: modes of the coupled model

A gearbox housing does not vibrate alone: the shafts, gears and bearings inside it are springs and masses
hung in its bores, and some of the housing's modes in the tooth-frequency range are modes of that interior
(van Roosmalen 1994, Sec. 4.6 and 5.4).  This example builds the thesis' Ch. 5 test gearbox:

1. the housing (the `test-gearbox-interior` scene's geometry: 10 mm walls, 65 mm bearing plates, feet fixed to
   the base) as a quadratic tetrahedral FE model;
2. its drivetrain from ONE description, `test_gearbox("B")` (gear set B, SKF 6316 / 6219 ball bearings,
   2000 N m): `to_coupling_spec()` gives the FE interior - Timoshenko shafts, the gears as rigid discs, the
   bearings' 6x6 stiffness (Lim's model at the loads the gear forces put on them, tilt held by the shaft) in
   the housing's bores, and the gear mesh with its mean stiffness along the line of action;
3. the coupled system (`build_interior`: bore masters tied to the bore surfaces) and its modes
   (`modes(structure, f_max)`, complete by the inertia count), with each mode's share of kinetic energy in the
   interior (> 0.5: an interior-dominated mode) and the interior's own modes on rigid bores.

The same description reduces to the lumped source model (`to_lumped()`, see `gear_set_runup.py`).
Units SI; frequencies in Hz.

Run:  .venv/bin/python examples/housing_with_drivetrain.py [--small] [--out DIR]
(--small: a 70 mm mesh and modes to 700 Hz, some 20 s; the full run uses the scene's 35 mm mesh and 1500 Hz.)
"""
# %%
from __future__ import annotations

import argparse

from mpi4py import MPI

from housingfe.drivetrain.description import test_gearbox
from housingfe.drivetrain.interior import build_interior
from housingfe.outputs import atomic_output_dir, format_table, write_csv
from housingfe.scene import build_model_from_scene, load_housing_scene
from housingfe.solvers.modal import modes

OUTPUTS = ("modes.csv", "rigid_bore_modes.csv")

# %% [markdown]
# ## The housing and the drivetrain
#
# The scene supplies the housing (geometry, steel, supports, mesh).  Its own `[coupling]` table is NOT used: the
# interior comes from the description (tests/drivetrain/test_description.py checks that the two agree).

# %%
def coupled_modes(small: bool):
    """(coupled interior, ModalBasis) of the test gearbox with the drivetrain of the description."""
    f_max = 700.0 if small else 1500.0
    scene, _ = load_housing_scene("test-gearbox-interior", ["mesh.size=0.07"] if small else [])
    model = build_model_from_scene(scene, MPI.COMM_WORLD)
    spec = test_gearbox("B").to_coupling_spec()
    coupled = build_interior(model, spec, f_max)
    return coupled, modes(coupled, f_max)


# %%
def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0].lstrip("# "))
    parser.add_argument("--small", action="store_true", help="coarse mesh, modes to 700 Hz")
    parser.add_argument("--out", default=None, help="folder for the CSV files")
    args = parser.parse_args(argv)

    coupled, basis = coupled_modes(args.small)
    share = coupled.interior_fraction(basis.vectors)
    rows = [[i + 1, float(f), float(s)] for i, (f, s) in enumerate(zip(basis.frequencies_hz, share))]
    print(f"coupled model: {coupled.dofs} DOFs, {basis.rigid_count} zero modes "
          f"(expected {coupled.expected_zero_modes}: the gear train's free rotation)")
    print(format_table(["mode", "frequency_hz", "interior_kinetic_share"], rows, floatfmt="{:.3f}"))
    rigid = coupled.rigid
    rigid_rows = [[i + 1, float(f), float(e)] for i, (f, e) in enumerate(zip(rigid.frequencies_hz,
                                                                              rigid.bearing_energy))]
    print("\ninterior alone on rigid bores (share of strain energy in the bearings):")
    print(format_table(["mode", "frequency_hz", "bearing_energy_share"], rigid_rows, floatfmt="{:.3f}"))
    dominated = [r for r in rows if r[2] > 0.5 and r[1] > 1.0]
    print("\ninterior-dominated coupled modes [Hz]: " + ", ".join(f"{r[1]:.0f}" for r in dominated))

    if args.out:
        with atomic_output_dir(args.out, MPI.COMM_WORLD) as tmp:
            if MPI.COMM_WORLD.rank == 0:
                write_csv(tmp / OUTPUTS[0], ["mode", "frequency_hz", "interior_kinetic_share"], rows)
                write_csv(tmp / OUTPUTS[1], ["mode", "frequency_hz", "bearing_energy_share"], rigid_rows)
        if MPI.COMM_WORLD.rank == 0:
            for name in OUTPUTS:
                print(f"wrote {args.out}/{name}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
