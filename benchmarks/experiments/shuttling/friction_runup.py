"""What the sliding friction does to the run-up (issue 28): a measurement beside the chain's runup.mesh_friction, nothing tuned.

Since the friction is a run-up option (scene key runup.mesh_friction), the unit loads and amplitudes here are the
chain's (housingfe.runup.chain.unit_loads with friction, friction_lines; Drivetrain.friction_node_loads): this script
adds the comparison of coefficients and the split by resultant.

The run-up of `housingfe run test-gearbox-runup` (sets A-D with ball bearings, and
test-gearbox-runup-double-helical with cylindrical rollers; the largest torque, 2000 N m; the scenes' defaults:
coupled source, the shuttling moment on) is rebuilt here with four more unit loads in the Ritz reduction: the friction force pair
(+e_f on the pinion node, -e_f on the wheel node, e_f from the pinion centre to T1, normal to the plane of action),
the friction torque about the pinion's and about the wheel's rotation vector, and the tilt pair (+/- e_w x e_f).
Their amplitudes per line are harmonic n of `FrictionCurve.of_curve(source stiffness curve, mu)` / sqrt(2), with the
time origin of S(t) and F_e(t) (housingfe.source.mesh_friction), applied coherently with the chain's own mesh
excitation and shuttling moment in the mesh_force route; friction does not enter the source's harmonic balance
(first order).  The same reduction without the friction amplitudes is the reference, so the difference is the
friction alone.  mu: the central, low and high coefficients of shuttling.py (ISO/TR 13989-1), constant over the
run-up, and "iso": ISO/TR 13989-1 at each speed (Ra 0.4 um).  Writes friction_runup.csv (L_WA per speed and
radiator without and with friction, mesh_force route); the console output is friction_runup.txt.

    PYTHONPATH=. OPENBLAS_NUM_THREADS=1 /work/main/.venv/bin/python benchmarks/experiments/shuttling/friction_runup.py [A B C D double_helical]
"""
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from shuttling import friction_coefficients  # noqa: E402

from housingfe.drivetrain.description import FRICTION_LOADS  # noqa: E402
from housingfe.outputs import format_table, write_csv  # noqa: E402
from housingfe.runup.chain import friction_lines, run_source, runup  # noqa: E402

HERE = Path(__file__).parent
SCENE = "test-gearbox-runup"


CASES = {"A": (SCENE, []), "B": (SCENE, ["drivetrain.gear_set=B"]), "C": (SCENE, ["drivetrain.gear_set=C"]),
         "D": (SCENE, ["drivetrain.gear_set=D"]), "double_helical": ("test-gearbox-runup-double-helical", [])}


def run_case(case: str, scene_name: str, overrides: list, housings: dict) -> tuple[list, list, list]:
    """(CSV rows, summary table rows, per-resultant table rows) of one scene at its largest torque."""
    from mpi4py import MPI

    from housingfe.drivetrain.misalignment import lead_gap_law
    from housingfe.runup.chain import build_gearbox_model
    from housingfe.runup.scene import (
        drivetrain_of,
        housing_model_for,
        load_runup_scene,
        matched_drivetrains,
        radiators_of,
    )
    from housingfe.scene import load_housing_scene

    t0 = time.perf_counter()
    scene, path = load_runup_scene(scene_name, overrides)
    spec = scene.runup
    torque = max(spec.torques_nm)
    if scene.housing.scene not in housings:
        housing_scene, _ = load_housing_scene(scene.housing.scene, list(scene.housing.set))
        housings[scene.housing.scene] = housing_model_for(housing_scene, spec.f_max_hz, MPI.COMM_WORLD)
    model = housings[scene.housing.scene]
    radiators = radiators_of(scene.radiation, model)
    drivetrains, _ = matched_drivetrains(scene.housing, model, {torque: drivetrain_of(scene.drivetrain, torque)}, path)
    dt = drivetrains[torque]
    # the chain's reduction with the friction loads among the unit loads (their static vectors join), as
    # runup.mesh_friction builds it (housingfe.runup.chain.unit_loads, Drivetrain.friction_node_loads)
    gm = build_gearbox_model(model, dt, spec.f_max_hz, damping_ratio=spec.damping_ratio,
                             basis_factor=spec.basis_factor, radiators=radiators, surface=spec.surface, friction=True)
    assert spec.misalignment_model == "rigid-bores", spec.misalignment_model
    source = dt.source_model(harmonics=spec.harmonics, engagement=spec.engagement,
                             misalignment=lead_gap_law(dt, "rigid-bores"))
    lines, _ = run_source(gm, source, spec.speeds, [torque], spec.f_max_hz, spec.source_receptance,
                          spec.mesh_moment_model)
    print(f"{case}: {scene_name} {' '.join(overrides)} at {torque:g} N m ({scene.drivetrain.bearings} bearings):"
          f" model and source lines {time.perf_counter() - t0:.1f} s; mesh moment {spec.mesh_moment_model}, "
          f"receptance {spec.source_receptance}")
    mus = friction_coefficients(source.pair)
    # "iso": ISO/TR 13989-1 at each line's own speed (Ra 0.4 um; mu ~ v^-0.2): runup.mesh_friction = "iso13989"
    mus["iso"] = "iso13989"
    base = runup(gm, None, spec.speeds, [torque], routes=("mesh_force",), lines=lines)
    mu_line = friction_lines(source, lines, "iso13989")[1]

    def with_friction(mu, names):
        amp = friction_lines(source, lines, mu)[0]
        fl = replace(lines, friction={FRICTION_LOADS[k]: amp[FRICTION_LOADS[k]] for k in names})
        return runup(gm, None, spec.speeds, [torque], routes=("mesh_force",), lines=fl)

    everything = tuple(FRICTION_LOADS)
    out = {label: with_friction(mu, everything) for label, mu in mus.items()}
    # which resultant does it: each alone at the central mu
    parts = {"force pair": ("force",), "torques": ("pinion_torque", "wheel_torque"), "tilt": ("tilt_moment",)}
    part_rows = []
    for part, names in parts.items():
        res = with_friction(mus["central"], names)
        d = np.array([a["LwA_dB"] - b["LwA_dB"] for a, b in zip(res.totals, base.totals)])
        part_rows.append([case, part, f"{d.min():+.2f}", f"{d.max():+.2f}", f"{np.mean(np.abs(d)):.2f}"])
    rows = []
    for i, r in enumerate(base.totals):
        row = {"case": case, "torque_nm": torque, "speed_rpm": r["speed_rpm"], "radiation": r["radiation"],
               "LwA_none_dB": r["LwA_dB"]}
        for label in mus:
            row[f"mu_{label}"] = float(mu_line[lines.speed == r["speed_rpm"]][0]) if label == "iso" else mus[label]
            row[f"LwA_{label}_dB"] = out[label].totals[i]["LwA_dB"]
            row[f"delta_{label}_dB"] = out[label].totals[i]["LwA_dB"] - r["LwA_dB"]
        rows.append(row)
    table = []
    for rad in sorted({r["radiation"] for r in rows}):
        sel = [r for r in rows if r["radiation"] == rad]
        i_max = int(np.argmax([r["LwA_none_dB"] for r in sel]))
        for label in mus:
            d = np.array([r[f"delta_{label}_dB"] for r in sel])
            j = int(np.argmax([r[f"LwA_{label}_dB"] for r in sel]))
            value = f"{mu_line.min():.3f}-{mu_line.max():.3f}" if label == "iso" else f"{mus[label]:.3f}"
            table.append([case, rad, label, value, f"{d.min():+.2f}", f"{d.max():+.2f}",
                          f"{np.mean(np.abs(d)):.2f}",
                          f"{sel[i_max]['LwA_none_dB']:.1f} @ {sel[i_max]['speed_rpm']:.0f}",
                          f"{sel[j][f'LwA_{label}_dB']:.1f} @ {sel[j]['speed_rpm']:.0f}"])
    return rows, table, part_rows


def main():
    t0 = time.perf_counter()
    cases = sys.argv[1:] or list(CASES)
    housings, rows, table, parts = {}, [], [], []
    for case in cases:
        r, t, p = run_case(case, *CASES[case], housings)
        rows += r
        table += t
        parts += p
    keys = list(rows[0])
    write_csv(HERE / "friction_runup.csv", keys, [[r[k] for k in keys] for r in rows])
    print(format_table(["case", "central mu, alone", "min dL_WA dB", "max dL_WA dB", "mean |dL_WA| dB"], parts))
    print(format_table(["case", "radiation", "mu", "value", "min dL_WA dB", "max dL_WA dB", "mean |dL_WA| dB",
                        "max L_WA without", "max L_WA with"], table))
    print(f"wall time {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()
