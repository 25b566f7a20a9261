"""# The noise chain end to end: gear set + speed + torque -> L_WA over speed

What the package exists for (van Roosmalen 1994, Ch. 5): how loud is the test gearbox over its speed range?

1. the housing: the reconstructed test gearbox (10 mm walls, 65 mm bearing plates, 170 mm bores, feet on a rigid
   base), meshed for the highest line of interest;
2. the drivetrain, described once (`test_gearbox("A")`: gear set A, ball bearings, 2000 N m): its FE reduction
   (shafts, gears, Lim 6x6 bearings at star connections to the bores, the gear mesh) is coupled with the housing,
   its lumped reduction is the source (`source_model()`);
3. `build_gearbox_model`: once per run, the coupled model's complete modal basis to 1.5 x the highest line plus
   static Ritz vectors, reduced to its surface quantities;
4. `runup`: per speed the source's operating point (harmonic balance of the time-varying mesh stiffness with the
   engagement shock), then two routes per tooth harmonic — "tf_omega" (the thesis' L_v = L_omega + TF_omega) and
   "mesh_force" (the mesh excitation F_n - k_m d_n on the coupled gear mesh) — then L_W = L_v + L_S + L_sigma
   (sigma = 1 here) and the A-weighted total;
5. `with_drivetrain`: gear set B on the same basis (a Rayleigh-Ritz re-analysis: seconds, no new eigensolve).

Run:  .venv/bin/python examples/gearbox_runup.py [--small] [--out DIR]
(--small: a 60 mm mesh, lines to 1.5 kHz and 7 speeds: about 20 s; the full run: lines to 4 kHz, 30 speeds,
about a minute.  `housingfe run test-gearbox-runup` is the same chain from a scene, with every output.)
"""
# %%
from __future__ import annotations

import argparse

import numpy as np
from mpi4py import MPI

from housingfe.drivetrain.description import test_gearbox
from housingfe.fe.model import build_model
from housingfe.outputs import atomic_output_dir, format_table, write_csv
from housingfe.radiation.radiators import RADIATORS
from housingfe.runup.chain import build_gearbox_model, runup, with_drivetrain
from housingfe.scene import load_housing_scene

OUTPUTS = ("runup.csv", "runup.png")
TORQUE_NM = 2000.0
MEASURED_LWA_MAX = 100.5        # dB(A), gear set A, 2000 N m (Sec. 5.6); the thesis calculated 89.4


# %% [markdown]
# ## The housing and the drivetrain
# The housing geometry is the built-in `test-gearbox` scene's (its reconstruction notes: docs/housings.md); the mesh
# size follows from the highest line (six quadratic elements per bending wavelength of the 10 mm walls) unless
# --small coarsens it.

# %%
def gearbox(f_lines_max: float, mesh_size: float | None):
    housing = load_housing_scene("test-gearbox", [f"mesh.size={mesh_size}"] if mesh_size else [])[0]
    model = build_model(housing.geometry, housing.material.resolve(), housing.mesh, f_lines_max, MPI.COMM_WORLD,
                        supports=housing.supports)
    return build_gearbox_model(model, test_gearbox("A", torque=TORQUE_NM), f_lines_max,
                               radiators={"erp": RADIATORS["erp"]()})


# %%
def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0].lstrip("# "))
    parser.add_argument("--small", action="store_true", help="coarse mesh, lines to 1.5 kHz, 7 speeds")
    parser.add_argument("--out", default=None, help="folder for runup.csv and runup.png")
    args = parser.parse_args(argv)

    f_lines_max, mesh_size = (1500.0, 0.06) if args.small else (4000.0, None)
    speeds = np.arange(50.0, 1501.0, 50.0) if not args.small else np.array([300.0, 500., 700., 900., 1100., 1300.,
                                                                             1500.0])
    gm = gearbox(f_lines_max, mesh_size)
    print(f"coupled gearbox: {gm.structure.dofs} DOFs, {len(gm.basis.eigenvalues)} modes to {gm.basis.f_max:.0f} Hz")
    result = runup(gm, gm.drivetrain.source_model(), speeds, [TORQUE_NM])

    # gear set B on the same basis: its mesh stiffness and bearing loads re-projected, its own source
    gm_b = with_drivetrain(gm, test_gearbox("B", torque=TORQUE_NM))
    result_b = runup(gm_b, gm_b.drivetrain.source_model(), speeds, [TORQUE_NM])

    header = ["speed_rpm", "L_omega_dB", "Lv_tf_omega_dB", "Lv_mesh_force_dB", "LwA_tf_omega_dBA",
              "LwA_mesh_force_dBA", "LwA_mesh_force_set_B_dBA"]
    s, L_om = result.series("tf_omega", "erp", TORQUE_NM, "L_omega_dB")
    cols = [s, L_om]
    for key in ("Lv_dB", "LwA_dB"):
        for route in ("tf_omega", "mesh_force"):
            cols.append(result.series(route, "erp", TORQUE_NM, key)[1])
    cols.append(result_b.series("mesh_force", "erp", TORQUE_NM, "LwA_dB")[1])
    rows = np.column_stack(cols).tolist()
    print(format_table(header, rows, floatfmt="{:.1f}"))
    for route in ("tf_omega", "mesh_force"):
        sp, lwa = result.series(route, "erp", TORQUE_NM, "LwA_dB")
        print(f"{route}: max L_WA {lwa.max():.1f} dB(A) at {sp[lwa.argmax()]:g} rev/min "
              f"(measured {MEASURED_LWA_MAX} dB(A))")

    if args.out:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        with atomic_output_dir(args.out) as tmp:
            write_csv(tmp / OUTPUTS[0], header, rows)
            fig, ax = plt.subplots(figsize=(7, 4))
            for j, name in enumerate(header[4:]):
                ax.plot(s, [r[4 + j] for r in rows], "o-", ms=3, label=name)
            ax.axhline(MEASURED_LWA_MAX, color="r", ls="--", label="measured max (set A)")
            ax.set_xlabel("pinion speed [rev/min]")
            ax.set_ylabel("L_WA [dB(A) re 1 pW]")
            ax.legend(fontsize=7)
            fig.tight_layout()
            fig.savefig(tmp / OUTPUTS[1], dpi=100)
            plt.close(fig)
        for name in OUTPUTS:
            print(f"wrote {args.out}/{name}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
