"""# The 6x6 stiffness of a ball bearing: deflection, tangent and secant stiffness

A rolling bearing is the spring between shaft and housing.  Its stiffness is not a constant: the balls are
Hertz contacts (force ~ approach^1.5), the radial clearance has to close before a ball carries load, and only
the balls on the loaded side touch.  So the 6x6 matrix the housing models use is the *tangent* stiffness
K = dF/d(delta) at the mean load the shaft puts on the bearing (van Roosmalen 1994, Sec. 3.2 and Appendix D,
after Lim), and the bearing's static deflection under that load comes from an equilibrium solve F(delta) = F_load.

This example computes, for a deep groove ball bearing SKF 6312 (the pinion bearing of the thesis' test gearbox,
Sec. 4.6):

1. the bearing from the catalogue (`lookup("SKF 6312")`) and the same bearing from its internal geometry
   written out (`RollingBearing(...)`): the two give the same K, because the catalogue entry *is* that geometry;
2. its deflection under a combined radial and axial load, with the tilt free, held at zero by the shaft, and
   prescribed (a 1 mrad misalignment);
3. the tangent stiffness K_ii against the secant stiffness F_i / delta_i.  Under a pure radial load without
   clearance K = 1.5 F / delta exactly (Hertz, F ~ delta^1.5), so delta = F / K would be 33 % low; the clearance
   makes the ratio larger (1.83 with the catalogue's 9.75 um: the play closes before the balls carry load, which
   adds deflection but no stiffness).  Under a combined load
   the DOFs are coupled (K has off-diagonal terms; the axial load has already brought balls all round into
   contact), and the per-DOF F_i / delta_i is then no stiffness of anything: it can even exceed K_ii.  Use K for
   vibration about the load and the solved deflection for the static displacement, never F / K.

Axes: z is the shaft axis, x and y are radial; DOF order (x, y, z, theta_x, theta_y, theta_z).  Units SI: loads
N and N m, deflections m and rad, stiffness N/m, N/rad (= N m/m) and N m/rad.  The load is what the shaft applies
to the inner ring; the deflection is the inner ring's motion relative to the outer ring.

Run:  .venv/bin/python examples/bearing_stiffness.py [--small] [--out DIR]
(--small changes nothing here: there is no mesh.  --out DIR also writes the two CSV files of OUTPUTS.)
"""
# %%
from __future__ import annotations

import argparse

import numpy as np

from housingfe.bearings import (
    DOF_NAMES,
    RollingBearing,
    bearing_stiffness,
    finite_difference_stiffness,
    lookup,
    make_model,
)
from housingfe.outputs import atomic_output_dir, format_table, write_csv

# The files written with --out DIR (tests/test_examples.py checks that they are there).
OUTPUTS = ("deflection_and_stiffness.csv", "stiffness_matrices.csv")

# %% [markdown]
# ## The bearing, twice
#
# The catalogue knows the boundary dimensions d x D x B = 60 x 130 x 31 mm (SKF) and the 8 balls of
# 22.22 mm the thesis prints; the rest is estimated and listed in `bearing.estimated`.  Written out, the same
# bearing is: pitch diameter (d + D)/2, groove conformities f = groove radius / ball diameter (Harris' typical
# 0.52 inner, 0.53 outer), and a radial clearance of 9.75 um (half the mid-range ISO 5753-1 normal-group
# diametral clearance of 11-28 um: the radial play of the centred rings).

# %%
MM, UM = 1e-3, 1e-6

catalogue = lookup("SKF 6312")
explicit = RollingBearing(
    designation="6312 (explicit geometry)", kind="ball",
    bore=60 * MM, outer_diameter=130 * MM, width=31 * MM,
    n_elements=8, element_diameter=22.22 * MM, pitch_diameter=95 * MM,
    groove_inner=0.52, groove_outer=0.53, contact_angle=0.0,
    radial_clearance=9.75 * UM,
    youngs_modulus=208e9, poisson_ratio=0.3,          # through-hardened bearing steel
)
# the textbook case: the same bearing with zero clearance
no_clearance = RollingBearing(
    designation="6312 zero clearance", kind="ball",
    n_elements=8, element_diameter=22.22 * MM, pitch_diameter=95 * MM,
    groove_inner=0.52, groove_outer=0.53, radial_clearance=0.0,
)

# %% [markdown]
# ## Load cases
#
# The load is (Fx, Fy, Fz, Mx, My) [N, N m].  A single deep groove bearing takes little moment, so under a
# combined radial and axial load with no moment its inner ring tilts (by a few mrad).  In a gearbox the shaft
# and the second bearing set the tilt: `fixed_tilt=(theta_x, theta_y)` prescribes it, and the moments it takes
# are returned in `result.load[3:5]`.

# %%
RADIAL = (0.0, -10_000.0, 0.0, 0.0, 0.0)           # 10 kN downwards
COMBINED = (0.0, -10_000.0, 4_000.0, 0.0, 0.0)      # plus 4 kN axial
CASES = {
    # name: (bearing, load, fixed_tilt)
    "radial, zero clearance": (no_clearance, RADIAL, None),
    "radial, catalogue": (catalogue, RADIAL, None),
    "catalogue, tilt free": (catalogue, COMBINED, None),
    "explicit, tilt free": (explicit, COMBINED, None),
    "catalogue, tilt held 0": (catalogue, COMBINED, (0.0, 0.0)),
    "catalogue, theta_y 1 mrad": (catalogue, COMBINED, (0.0, 1e-3)),
}


def solve_cases() -> dict:
    """BearingResult per case (deflection [m, rad], K [N/m, N/rad, N m/rad])."""
    return {name: bearing_stiffness(b, load, fixed_tilt=tilt) for name, (b, load, tilt) in CASES.items()}


# %% [markdown]
# ## Equilibrium, tangent and secant
#
# `result.displacement` solves F(delta) = F_load (Newton on the bearing's potential energy).  We check it by
# evaluating the bearing's load vector at that deflection (`make_model(b).evaluate(q)[1]`), and check the
# analytic tangent K against central differences of that load vector (agreement ~1e-10; only ~1e-4 for the
# zero-clearance case, where the balls at psi = 0 and 180 deg sit exactly at contact onset and the contact law
# delta^1.5 has no second derivative for the differences to rely on).

# %%
def equilibrium_residual(bearing, result) -> float:
    """max |F(delta) - F_load| over the five DOFs, relative to the largest load (moments / pitch radius)."""
    force = make_model(bearing, result.model).evaluate(result.displacement)[1]
    arm = np.array([1.0, 1.0, 1.0, 2.0 / bearing.pitch_diameter, 2.0 / bearing.pitch_diameter])
    return float(np.max(np.abs(force - result.load[:5]) * arm) / np.max(np.abs(result.load[:5]) * arm))


def tangent_vs_differences(bearing, result) -> float:
    """max |K - K_central_differences| / max |K|."""
    k_fd = finite_difference_stiffness(make_model(bearing, result.model), result.displacement)
    return float(np.max(np.abs(result.K - k_fd)) / np.max(np.abs(result.K)))


def table_rows(results: dict, *, moving_only: bool) -> list[list]:
    """One row per case and DOF (moving_only: skip DOFs with no load and no motion): load, deflection,
    secant F/delta, tangent K_ii, their ratio (None where the secant is undefined)."""
    rows = []
    for name, res in results.items():
        secant = res.secant_stiffness()
        for i in range(5):
            # a zero-load DOF's deflection is round-off (1e-20 m) or exactly zero
            if moving_only and res.load[i] == 0.0 and abs(res.displacement[i]) < 1e-12:
                continue
            ratio = res.K[i, i] / secant[i] if secant[i] else None
            rows.append([name, DOF_NAMES[i], float(res.load[i]), float(res.displacement[i]),
                         secant[i], float(res.K[i, i]), ratio])
    return rows


# %%
def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0].lstrip("# "))
    parser.add_argument("--small", action="store_true", help="accepted for uniformity; no mesh here")
    parser.add_argument("--out", default=None, help="folder for the CSV files")
    args = parser.parse_args(argv)

    results = solve_cases()
    rows = table_rows(results, moving_only=True)
    print("Deflection under the load and stiffness per DOF (load N | N m, deflection m | rad, "
          "stiffness N/m | N m/rad):")
    print(format_table(["case", "dof", "load", "deflection", "secant F/d", "tangent K_ii", "K_ii/(F/d)"],
                       [[v if v is not None else "-" for v in row] for row in rows]))

    same = np.max(np.abs(results["catalogue, tilt free"].K - results["explicit, tilt free"].K))
    print(f"\ncatalogue vs explicit geometry: max |K difference| = {same:.3g} "
          f"(of max |K| {np.max(np.abs(results['explicit, tilt free'].K)):.4g})")
    for name, res in results.items():
        bearing = CASES[name][0]
        print(f"{name:28s} equilibrium residual {equilibrium_residual(bearing, res):.1e}, "
              f"K vs central differences {tangent_vs_differences(bearing, res):.1e}, "
              f"max |K - K^T| {np.max(np.abs(res.K - res.K.T)):.1e} N/m")

    tilted = results["catalogue, theta_y 1 mrad"]
    print(f"\n6x6 tangent stiffness of '{tilted.designation}', {CASES['catalogue, theta_y 1 mrad'][2]} rad "
          f"tilt held, moments taken Mx = {tilted.load[3]:.4g}, My = {tilted.load[4]:.4g} N m "
          "(rows/columns " + ", ".join(DOF_NAMES) + "; N/m, N/rad, N m/rad):")
    for row in tilted.K:
        print("  " + "  ".join(f"{v:11.4g}" for v in row))

    if args.out:
        with atomic_output_dir(args.out) as tmp:
            write_csv(tmp / OUTPUTS[0], ["case", "dof", "load_N_or_Nm", "deflection_m_or_rad",
                                         "secant_stiffness", "tangent_stiffness_Kii", "ratio_K_over_secant"],
                      [[("" if v is None else v) for v in row]
                       for row in table_rows(results, moving_only=False)])
            write_csv(tmp / OUTPUTS[1], ["case", "row", *DOF_NAMES],
                      [[name, DOF_NAMES[i], *map(float, res.K[i])] for name, res in results.items()
                       for i in range(6)])
        for name in OUTPUTS:
            print(f"wrote {args.out}/{name}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
