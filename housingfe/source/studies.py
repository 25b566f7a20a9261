"""Parameter studies of van Roosmalen's Ch. 2 that are not tied to one scene.

  overlap study (Sec. 2.4, Fig. 2.9): z = 18/90, m = 2.25 mm, alpha = 20 deg, h_a = 1, h_f = 1.25,
      x = 0.472 / -0.110, F/B = 50 N/mm, B = 20.25 ... 81 mm.  The helix angle is not printed; we take
      beta = asin(pi/18) = 10.05 deg, which makes the seven widths give eps_beta = 0.5, 0.75, ..., 2.0
      (the quarter steps of B/d1 = 0.5 ... 1.5 of the text).  Spur reference (beta = 0) at B = 40.5 mm.
  correction study (Fig. 2.18, Sec. 5.7): L_omega in the tooth band of the built-in gear sets over torque
      at 1500 rpm and averaged (energy) over 800-1500 rpm, differences relative to set A.

Run: `python -m housingfe.source.studies [out_dir]` (default results/source-studies); writes CSV + PNG.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

from housingfe.outputs import format_table, write_csv
from housingfe.source.gears import GearPair
from housingfe.source.stiffness import MeshModel, stiffness_curve

OVERLAP_WIDTHS_MM = (20.25, 30.375, 40.5, 50.625, 60.75, 70.875, 81.0)
THESIS_CALC_VS_A_DB = {"gearset-B": -0.4, "gearset-C": 2.9, "gearset-D": -5.1, "gearset-uncorrected": 3.5}


def overlap_study_pair(width: float, helix_angle: float = math.asin(math.pi / 18)) -> GearPair:
    """The gear pair of Sec. 2.4 with face width `width` [m] at zero-backlash centre distance."""
    kind = "spur" if helix_angle == 0 else "single_helical"
    # tips shortened by DIN 3960 k m (the tip clearance 0.25 m of Sec. 2.4 kept), as before tips became explicit
    return GearPair(2.25e-3, (18, 90), math.radians(20), helix_angle, (0.472, -0.110), (width, width), None,
                    1.0, 1.25, 0.38, kind=kind, tip_shortening=True)


def overlap_study(n_positions: int = 40, n_slices: int = 16) -> list[dict]:
    """Mean stiffness and amplitude (half peak-to-peak) per unit width [N/m^2] over the seven widths."""
    rows = []
    for width_mm in OVERLAP_WIDTHS_MM:
        pair = overlap_study_pair(width_mm * 1e-3)
        force = 50e3 * pair.contact_width / math.cos(pair.base_helix_angle)       # F/B = 50 N/mm
        curve = stiffness_curve(MeshModel(pair, n_slices=n_slices), force, n_positions)
        rows.append({"face_width_mm": width_mm, "B_over_d1": width_mm / 40.5, "overlap_ratio": pair.overlap_ratio,
                     "mean_s": curve.per_width.mean(), "amplitude_s": curve.amplitude / pair.total_contact_width,
                     "curve": curve})
    return rows


def main(out_dir: Path) -> None:
    """Write overlap_study.csv/png and corrections.csv/png into out_dir."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from housingfe.source.roosmalen import correction_study

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    rows = overlap_study()
    table = [[r["face_width_mm"], r["B_over_d1"], r["overlap_ratio"], r["mean_s"] / 1e9, r["amplitude_s"] / 1e9]
             for r in rows]
    header = ["face_width_mm", "B_over_d1", "overlap_ratio", "mean_s_N_per_mm_um", "amplitude_s_N_per_mm_um"]
    write_csv(out_dir / "overlap_study.csv", header, table)
    print(format_table(header, table, floatfmt="{:.3f}"))
    spur = overlap_study_pair(0.0405, 0.0)
    spur_curve = stiffness_curve(MeshModel(spur, n_slices=8), 50e3 * 0.0405, 80)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    axes[0].plot([r[2] for r in table], [r[4] for r in table], "o-")
    axes[0].set_xlabel("overlap ratio eps_beta")
    axes[0].set_ylabel("stiffness amplitude [N/(mm um)]")
    axes[0].set_title("Sec. 2.4 / Fig. 2.9: z = 18/90, m = 2.25, F/B = 50 N/mm")
    axes[1].plot(spur_curve.position * 100, spur_curve.per_width / 1e9, label="spur, B = 40.5 mm (Fig. 2.8)")
    for r in rows[::2]:
        axes[1].plot(r["curve"].position * 100, r["curve"].per_width / 1e9, label=f"eps_beta = {r['overlap_ratio']:.2f}")
    axes[1].set_xlabel("mesh position [% of base pitch]")
    axes[1].set_ylabel("s [N/(mm um)]")
    axes[1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out_dir / "overlap_study.png", dpi=120)
    plt.close(fig)

    study = correction_study()
    ref = study["gearset-A"]
    rows = []
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for name, r in study.items():
        ax.plot(r["torque"], r["L_1500"], "o-", label=name.removeprefix("gearset-"))
        for T, L15, Lm, L15a, Lma in zip(r["torque"], r["L_1500"], r["L_mean"], ref["L_1500"], ref["L_mean"]):
            rows.append([name, T, L15, L15 - L15a, Lm, Lm - Lma, THESIS_CALC_VS_A_DB.get(name, 0.0) if T == 2000 else ""])
    header = ["scene", "torque_Nm", "L_1500rpm_dB", "vs_A_1500rpm_dB", "L_mean_800_1500rpm_dB", "vs_A_mean_dB",
              "thesis_calc_vs_A_dB"]
    write_csv(out_dir / "corrections.csv", header, rows)
    print(format_table(header, [r for r in rows if r[1] == 2000.0], floatfmt="{:.1f}"))
    ax.set_xlabel("pinion torque [N m]")
    ax.set_ylabel("L_omega in tooth band at 1500 rpm [dB]")
    ax.set_title("profile corrections (Fig. 2.18)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out_dir / "corrections.png", dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("results/source-studies"))
