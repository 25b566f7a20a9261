"""How fragile the helix's cancellation of set A's tooth harmonics is (issue 28): a sensitivity, nothing tuned.

Gear set A at 2000 N m (scene `gearset-A`, corrections A) with the common face width b varied so that the overlap
ratio eps_beta = b sin(beta) / (pi m_n) runs over 0.70 ... 1.40 in 0.025 steps, plus set A's own 62 mm
(eps_beta = 1.026).  The pinion stays 4 mm wider than the wheel (66 / 62 mm in set A).  Everything else is the
scene's: gear data, corrections, shafts, bearings, and the lumped interior (masses and inertias) of the 62 mm set,
kept fixed so that only the mesh changes (the mesh stiffness and its mean grow with b).  Gears of other widths are
hypothetical: nobody measured them.

Per eps_beta it writes (one-sided amplitudes, 2000 N m):
  * the quasi-static TE d - mean d, d = (F - F_e)/S(t), harmonics n = 1-3 [um], of the face-width model (default),
    of the thesis' 2-D shock (thesis-2d), of the in-phase slice model (helix stagger zero) and the envelope bound
    (in-phase x min(1, 1/(pi n eps_beta)), housingfe.source.roosmalen.overlap) - the excitation k_m (d - mean d) [N]
    is TE x k_m (k_m in the CSV);
  * |sinc(n eps_beta)| and the envelope factor for n = 1;
  * the rigid-bore tooth-band L_omega at 500 / 1000 / 1500 rpm [dB re 5e-8 rad/s] of the source itself (full
    harmonic balance, H = 30 as the scene) for face-width and thesis-2d, and for the bound the face-width level
    + 20 lg(bound_1 / face-width_1): below the mesh mode the tooth line is the mean-stiffness system loaded by the
    quasi-static TE to 0.1 dB (docs/source.md, "Where the tooth-band L_omega deficit sits"), so the bound's level is
    scaled, not solved.

    PYTHONPATH=. OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/experiments/overlap_sensitivity/overlap_sensitivity.py
    ... --convergence     # the stiffness-position and slice convergence check (README)
"""
import argparse
import copy
import math
import time
from pathlib import Path

import numpy as np

from housingfe.outputs import write_csv
from housingfe.scenefile import read_scene_dict
from housingfe.source.roosmalen import dynamics as dyn
from housingfe.source.roosmalen import overlap as ov
from housingfe.source.roosmalen import run as rs

TORQUE = 2000.0
SPEEDS = (500.0, 1000.0, 1500.0)
MEASURED = {500.0: 109.9, 1000.0: 111.2, 1500.0: 120.8}   # Fig. 5.4, tooth 1/3-octave band, set A, 2000 N m
SET_A_WIDTH_MM = 62.0
PINION_EXTRA_MM = 4.0          # set A: pinion 66 mm, wheel 62 mm
HARMONICS = 3
HERE = Path(__file__).parent


def set_a():
    data, path = read_scene_dict("gearset-A")
    table = rs.parse(data, str(path))
    pair, corr, geometry, interior, model = rs.build(table, str(path))
    return data, path, table, pair, interior


def width_for(eps_beta: float, pair) -> float:
    """Common face width [mm] that gives eps_beta for set A's module and helix angle."""
    return eps_beta * math.pi * pair.module / math.sin(pair.helix_angle) * 1e3


def one_width(data, path, interior, width_mm: float, positions: int, slices: int, harmonics: int) -> dict:
    scene = copy.deepcopy(data)
    scene["source"]["gears"]["face_width_mm"] = [width_mm + PINION_EXTRA_MM, width_mm]
    scene["source"]["slices"] = slices
    table = rs.parse(scene, str(path))
    pair, corr, _, _, model = rs.build(table, str(path))       # one MeshModel per face width
    op = rs.OperatingPoint(pair, corr, interior, model, TORQUE, positions, engagement="face-width")
    k_m = op.curve.mean
    bound = ov.envelope_bound(pair, corr, op.S, op.normal_force, op.shock, op.load_share, k_m, harmonics=HARMONICS)
    shock_2d = dyn.engagement_force(pair, corr, op.S, op.normal_force)
    te_2d = ov.harmonic_amplitudes(ov.quasi_static_excitation(op.S, shock_2d, op.normal_force, k_m), HARMONICS) / k_m
    row = {"face_width_mm": width_mm, "eps_beta": pair.overlap_ratio, "eps_alpha": pair.transverse_contact_ratio,
           "k_m_N_per_m": k_m, "sinc_1": float(bound.sinc[0]), "envelope_1": float(bound.envelope[0])}
    for n in range(HARMONICS):
        row[f"te_fw_{n + 1}_um"] = bound.face_width[n] / k_m * 1e6
        row[f"te_2d_{n + 1}_um"] = te_2d[n] * 1e6
        row[f"te_in_phase_{n + 1}_um"] = bound.in_phase[n] / k_m * 1e6
        row[f"te_bound_{n + 1}_um"] = bound.bound[n] / k_m * 1e6
    row["bound_above_fw_1_dB"] = float(bound.above_dB[0])
    for rpm in SPEEDS:
        f_tooth = pair.tooth_frequency(rpm)
        L_fw = dyn.tooth_band_level(op.steady_state(pair, rpm, harmonics))
        L_2d = dyn.tooth_band_level(dyn.harmonic_balance(op.mats, op.S, shock_2d, op.f0, f_tooth, H=harmonics))
        row[f"L_fw_{rpm:.0f}_dB"] = L_fw
        row[f"L_2d_{rpm:.0f}_dB"] = L_2d
        row[f"L_bound_{rpm:.0f}_dB"] = L_fw + float(bound.above_dB[0])
    return row


def plot(rows: list[dict], out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    eb = np.array([r["eps_beta"] for r in rows])
    col = lambda k: np.array([r[k] for r in rows])      # noqa: E731
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    ax = axes[0]
    for key, label, style in (("te_2d_1_um", "thesis-2d", "C1s-"), ("te_in_phase_1_um", "in-phase slices (no helix)",
                                                                     "C2^-"),
                              ("te_bound_1_um", "envelope bound", "C3v-"), ("te_fw_1_um", "face-width (default)",
                                                                              "C0o-")):
        ax.semilogy(eb, col(key), style, ms=3, label=f"{label}, n = 1")
    ax.semilogy(eb, col("te_fw_2_um"), "C0--", lw=0.8, label="face-width, n = 2")
    ax.semilogy(eb, col("te_bound_2_um"), "C3--", lw=0.8, label="envelope bound, n = 2")
    ax.axhspan(5.3, 13.1, color="0.85", label="TE the measured L_omega needs (coupled, 5.3-13.1 um)")
    ax.axvline(1.026, color="k", lw=0.6, ls=":")
    ax.set_xlabel("overlap ratio eps_beta (common face width varied; set A: 1.026)")
    ax.set_ylabel("quasi-static TE amplitude [um]")
    ax.set_title("set A geometry, 2000 N m: TE per harmonic", fontsize=9)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=6)
    ax = axes[1]
    for rpm, colour in zip(SPEEDS, ("C0", "C1", "C2")):
        ax.plot(eb, col(f"L_fw_{rpm:.0f}_dB"), "-", color=colour, label=f"{rpm:.0f} rpm face-width")
        ax.plot(eb, col(f"L_bound_{rpm:.0f}_dB"), ":", color=colour, label=f"{rpm:.0f} rpm envelope bound")
        ax.plot(eb, col(f"L_2d_{rpm:.0f}_dB"), "--", color=colour, lw=0.8, label=f"{rpm:.0f} rpm thesis-2d")
        ax.plot([1.026], [MEASURED[rpm]], "s", color=colour, mec="k", label=f"{rpm:.0f} rpm measured (set A)")
    ax.set_xlabel("overlap ratio eps_beta")
    ax.set_ylabel("L_omega tooth band, rigid bores [dB re 5e-8 rad/s]")
    ax.set_title("source's tooth-band L_omega", fontsize=9)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=5.5, ncol=2)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def main(out_dir: Path, positions: int, slices: int, step: float, convergence: bool) -> None:
    t0 = time.perf_counter()
    data, path, table, pair_a, interior = set_a()
    harmonics = table.harmonics
    if convergence:
        print("| face width, mm | eps_beta | positions x slices | TE fw n = 1/2/3, um | bound n = 1, um | L_fw 500/1000/1500 |")
        print("|---|---|---|---|---|---|")
        for eps in (0.8, 1.026, 1.2):
            w = SET_A_WIDTH_MM if eps == 1.026 else width_for(eps, pair_a)
            for p, s in ((16, 24), (32, 24), (64, 24), (32, 48)):
                r = one_width(data, path, interior, w, p, s, harmonics)
                print(f"| {w:.2f} | {r['eps_beta']:.3f} | {p} x {s} | {r['te_fw_1_um']:.3f} / {r['te_fw_2_um']:.3f} / "
                      f"{r['te_fw_3_um']:.3f} | {r['te_bound_1_um']:.3f} | " + " / ".join(
                          f"{r[f'L_fw_{v:.0f}_dB']:.1f}" for v in SPEEDS) + " |")
        print(f"wall {time.perf_counter() - t0:.0f} s")
        return
    grid = np.round(np.arange(0.70, 1.40 + 1e-9, step), 6)
    # the grid point next to set A (eps_beta 1.025, 61.96 mm) gives way to set A's own 62 mm
    widths = sorted({round(width_for(e, pair_a), 4) for e in grid
                     if abs(width_for(e, pair_a) - SET_A_WIDTH_MM) > 0.3} | {SET_A_WIDTH_MM})
    rows = []
    for w in widths:
        # set A's own width with the scene's 32 positions: its row is the default chain's numbers
        p = table.stiffness_positions if w == SET_A_WIDTH_MM else positions
        rows.append(one_width(data, path, interior, w, p, slices, harmonics) | {"stiffness_positions": p})
    keys = list(rows[0])
    out_dir.mkdir(parents=True, exist_ok=True)
    write_csv(out_dir / "overlap_sensitivity.csv", keys, [[r[k] for k in keys] for r in rows])
    plot(rows, out_dir / "overlap_sensitivity.png")
    short = ["face_width_mm", "eps_beta", "sinc_1", "envelope_1", "te_fw_1_um", "te_fw_2_um", "te_fw_3_um",
             "te_2d_1_um", "te_bound_1_um", "bound_above_fw_1_dB", "L_fw_500_dB", "L_fw_1000_dB", "L_fw_1500_dB",
             "L_bound_500_dB", "L_bound_1000_dB", "L_bound_1500_dB"]
    print("| " + " | ".join(short) + " |")
    print("|" + "---|" * len(short))
    for r in rows:
        print("| " + " | ".join(f"{r[k]:.3g}" if k.startswith(("te_", "sinc", "env")) else f"{r[k]:.1f}"
                                 if k != "eps_beta" else f"{r[k]:.3f}" for k in short) + " |")
    print(f"{len(rows)} face widths, wall {time.perf_counter() - t0:.0f} s; results in {out_dir}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=HERE, help="folder for the CSV and PNG (default: beside this script)")
    parser.add_argument("--positions", type=int, default=32, help="stiffness positions per pitch for the swept widths "
                        "(scene default 32; set A's 62 mm row always uses the scene's)")
    parser.add_argument("--slices", type=int, default=24, help="slices of the contact lines (scene default 24)")
    parser.add_argument("--step", type=float, default=0.025, help="eps_beta step")
    parser.add_argument("--convergence", action="store_true", help="only the positions/slices convergence table")
    args = parser.parse_args()
    main(args.out, args.positions, args.slices, args.step, args.convergence)
