"""The shuttling moment beside the transmission-error excitation, per tooth harmonic (issue 28): nothing tuned.

For every built-in gear set (gearset-A, -B, -C, -D, -uncorrected, -double-helical) at 2000 N m, per harmonic
n = 1..6 of the tooth frequency (one-sided amplitudes, the source's stiffness-curve positions and slices):

  * excitation_N: the quasi-static TE excitation k_m (d - mean d), d = (F - F_e)/S(t) (face-width engagement, as
    `housingfe source-spectrum` and housingfe.source.roosmalen.studies.excitation_spectrum);
  * axial_arm_um: |W_n|, W_n the harmonic of the axial centre of pressure w_c of the mesh load
    (housingfe.source.mesh_moments, the stiffness curve's own load distributions);
  * line_term_Nm: F tan(beta_b) |S_n|, S_n the harmonic of the centre s_c along the line of action: the moment of
    the shift along the line of action, on the same axis (CentreOfPressure.moment_arm_harmonics);
  * shuttle_Nm: F |M_n|, M_n the harmonic of the moment arm w_c + tan(beta_b) s_c: the shuttling moment about the
    axis e_w x n that the run-up applies (its unit load "shuttle", housingfe.runup.chain.shuttle_moments).

  * friction_*: the sliding friction (housingfe.source.mesh_friction, from the same load distributions): the force
    normal to the plane of action (friction_force_N), the pinion and wheel torques (friction_pinion_torque_Nm,
    friction_wheel_torque_Nm; friction_pinion_equiv_N = torque / r_b1, the mesh force with the same pinion torque)
    and the tilt moment about the gear middle (friction_tilt_Nm), one-sided |harmonic n| at the central mean
    coefficient mu_central; *_low / *_high at mu_low / mu_high (the resultants are linear in mu).  mu: ISO/TR
    13989-1 (`mesh_mean_friction`) at 2000 N m with Shell Omala 150 at the thesis' 0.049 Pa s: central at
    1000 rev/min and Ra = 0.4 um (ground, DIN quality 5), low at 1500 rev/min and Ra = 0.2 um, high at 250 rev/min
    and Ra = 0.8 um (docs/source.md, "Sliding friction").

Two alignments: "aligned" (the gearset scene's source, MeshModel.lead_gap = 0) and "run-up" (the lead gap the
run-up uses by default: housingfe.drivetrain.misalignment.lead_gap_law(test_gearbox(set), "rigid-bores")).

    PYTHONPATH=. OPENBLAS_NUM_THREADS=1 /work/main/.venv/bin/python benchmarks/experiments/shuttling/shuttling.py
"""
import math
import time
from pathlib import Path

import numpy as np

from housingfe.drivetrain.description import GEAR_SETS, test_gearbox
from housingfe.drivetrain.misalignment import lead_gap_law
from housingfe.outputs import format_table, write_csv
from housingfe.source.mesh_friction import FrictionCurve, mesh_mean_friction
from housingfe.source.mesh_moments import CentreOfPressure
from housingfe.source.roosmalen import overlap as ov

TORQUE = 2000.0
HARMONICS = 6
HERE = Path(__file__).parent
VISCOSITY = 0.049          # Pa s: Shell Omala 150 as the thesis' fluid-film bearings take it (Sec. 3.5)
# (pinion speed rev/min, Ra m) of the central, low and high mean friction coefficients
MU_POINTS = {"central": (1000.0, 0.4e-6), "low": (1500.0, 0.2e-6), "high": (250.0, 0.8e-6)}


def friction_coefficients(pair) -> dict:
    """{"central", "low", "high"}: ISO/TR 13989-1 mean coefficients [-] at TORQUE (MU_POINTS)."""
    return {k: mesh_mean_friction(pair, TORQUE, n, VISCOSITY, ra) for k, (n, ra) in MU_POINTS.items()}


def rows_of(gear_set: str, alignment: str) -> list[dict]:
    dt = test_gearbox(gear_set, torque=TORQUE)
    misalignment = lead_gap_law(dt, "rigid-bores") if alignment == "run-up" else "none"
    source = dt.source_model(misalignment=misalignment)
    op = source._point(TORQUE)
    pair = source.pair
    cop = CentreOfPressure.of_curve(op.curve)
    F = op.normal_force
    W = np.abs(cop.axial_arm_harmonics(HARMONICS))
    S = np.abs(cop.line_arm_harmonics(HARMONICS))
    tan_bb = 0.0 if pair.kind == "double_helical" else math.tan(pair.base_helix_angle)
    M = np.abs(cop.moment_arm_harmonics(tan_bb, HARMONICS))
    exc = ov.harmonic_amplitudes(ov.quasi_static_excitation(op.S, op.shock, F, op.curve.mean), HARMONICS)
    mu = friction_coefficients(pair)
    fric = FrictionCurve.of_curve(op.curve, mu["central"])
    fr = {k: np.abs(fric.harmonics(k, HARMONICS)) for k in ("force", "pinion_torque", "wheel_torque", "tilt_moment")}
    r_b1 = float(pair.base_diameter[0]) / 2
    low, high = mu["low"] / mu["central"], mu["high"] / mu["central"]
    return [{"gear_set": gear_set, "alignment": alignment, "lead_gap_um_per_m": op.lead_gap * 1e6, "n": n,
             "eps_alpha": pair.transverse_contact_ratio, "eps_beta": pair.overlap_ratio, "normal_force_N": F,
             "mean_axial_centre_mm": float(cop.axial_centre.mean() * 1e3),
             "axial_centre_ptp_mm": float(np.ptp(cop.axial_centre) * 1e3),
             "excitation_N": float(exc[n - 1]), "axial_arm_um": float(W[n - 1] * 1e6),
             "line_term_Nm": float(F * tan_bb * S[n - 1]), "shuttle_Nm": float(F * M[n - 1]),
             "mu_central": mu["central"], "mu_low": mu["low"], "mu_high": mu["high"],
             "friction_force_mean_N": fric.mean("force"), "friction_force_N": float(fr["force"][n - 1]),
             "friction_pinion_torque_Nm": float(fr["pinion_torque"][n - 1]),
             "friction_wheel_torque_Nm": float(fr["wheel_torque"][n - 1]),
             "friction_pinion_equiv_N": float(fr["pinion_torque"][n - 1] / r_b1),
             "friction_tilt_Nm": float(fr["tilt_moment"][n - 1]),
             "friction_force_low_N": float(low * fr["force"][n - 1]),
             "friction_force_high_N": float(high * fr["force"][n - 1]),
             "friction_pinion_torque_low_Nm": float(low * fr["pinion_torque"][n - 1]),
             "friction_pinion_torque_high_Nm": float(high * fr["pinion_torque"][n - 1]),
             "friction_wheel_torque_low_Nm": float(low * fr["wheel_torque"][n - 1]),
             "friction_wheel_torque_high_Nm": float(high * fr["wheel_torque"][n - 1]),
             "friction_vs_te_dB": float(20 * math.log10(fr["force"][n - 1] / exc[n - 1])),
             "friction_tilt_vs_shuttle_dB": float(20 * math.log10(fr["tilt_moment"][n - 1] / (F * M[n - 1])))}
            for n in range(1, HARMONICS + 1)]


def main():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t0 = time.perf_counter()
    rows = [r for g in GEAR_SETS for a in ("aligned", "run-up") for r in rows_of(g, a)]
    keys = list(rows[0])
    write_csv(HERE / "shuttling.csv", keys, [[r[k] for k in keys] for r in rows])
    table = []
    for g in GEAR_SETS:
        for a in ("aligned", "run-up"):
            sel = [r for r in rows if r["gear_set"] == g and r["alignment"] == a]
            table.append([g, a, f"{sel[0]['eps_beta']:.3f}", f"{sel[0]['axial_centre_ptp_mm']:.2f}",
                          " / ".join(f"{r['excitation_N']:.0f}" for r in sel),
                          " / ".join(f"{r['shuttle_Nm']:.1f}" for r in sel),
                          " / ".join(f"{r['axial_arm_um']:.0f}" for r in sel),
                          f"{max(r['line_term_Nm'] for r in sel):.2f}"])
    print(format_table(["set", "alignment", "eps_beta", "w_c p-p mm", "TE excitation n=1..6 N",
                        "shuttle n=1..6 N m", "axial arm n=1..6 um", "max line term N m"], table))
    table = []
    for g in GEAR_SETS:
        for a in ("aligned", "run-up"):
            sel = [r for r in rows if r["gear_set"] == g and r["alignment"] == a]
            table.append([g, a, f"{sel[0]['mu_central']:.3f} ({sel[0]['mu_low']:.3f}-{sel[0]['mu_high']:.3f})",
                          f"{sel[0]['friction_force_mean_N']:.0f}",
                          " / ".join(f"{r['friction_force_N']:.1f}" for r in sel),
                          " / ".join(f"{r['friction_pinion_torque_Nm']:.2f}" for r in sel),
                          " / ".join(f"{r['friction_wheel_torque_Nm']:.2f}" for r in sel),
                          " / ".join(f"{r['friction_tilt_Nm']:.2f}" for r in sel[:3]),
                          " / ".join(f"{r['friction_vs_te_dB']:.1f}" for r in sel[:3]),
                          " / ".join(f"{r['friction_tilt_vs_shuttle_dB']:.1f}" for r in sel[:3])])
    print(format_table(["set", "alignment", "mu (low-high)", "mean F_f N", "friction force n=1..6 N",
                        "pinion torque n=1..6 N m", "wheel torque n=1..6 N m", "tilt n=1..3 N m",
                        "F_f/TE n=1..3 dB", "tilt/shuttle n=1..3 dB"], table))
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2))
    n = np.arange(1, HARMONICS + 1)
    for g in GEAR_SETS:
        sel = [r for r in rows if r["gear_set"] == g and r["alignment"] == "run-up"]
        line, = axes[0].semilogy(n, [r["excitation_N"] for r in sel], "o-", label=g)
        axes[1].semilogy(n, [r["shuttle_Nm"] for r in sel], "s-", color=line.get_color(), label=g)
        axes[2].semilogy(n, [r["friction_force_N"] for r in sel], "^-", color=line.get_color(), label=g)
        axes[2].fill_between(n, [r["friction_force_low_N"] for r in sel], [r["friction_force_high_N"] for r in sel],
                             color=line.get_color(), alpha=0.12)
    axes[0].set_title("TE excitation k_m (d - mean d), N (run-up alignment)", fontsize=9)
    axes[1].set_title("shuttling moment F |W_n|, N m (run-up alignment)", fontsize=9)
    axes[2].set_title("friction force normal to the plane of action, N (mu central; band: low-high)", fontsize=9)
    for ax in axes:
        ax.set_xlabel("tooth harmonic n")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(HERE / "shuttling.png", dpi=110)
    print(f"wall time {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()
