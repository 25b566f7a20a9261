"""Parameter studies of van Roosmalen's Ch. 2 that are not tied to one scene.

  overlap study (Sec. 2.4, Fig. 2.9): z = 18/90, m = 2.25 mm, alpha = 20 deg, h_a = 1, h_f = 1.25,
      x = 0.472 / -0.110, F/B = 50 N/mm, B = 20.25 ... 81 mm.  The helix angle is not printed; we take
      beta = asin(pi/18) = 10.05 deg, which makes the seven widths give eps_beta = 0.5, 0.75, ..., 2.0
      (the quarter steps of B/d1 = 0.5 ... 1.5 of the text).  Spur reference (beta = 0) at B = 40.5 mm.
  correction study (Fig. 2.18, Sec. 5.7): L_omega in the tooth band of the built-in gear sets over torque
      at 1500 rpm and averaged (energy) over 800-1500 rpm, differences relative to set A (the thesis' own
      calculation, so with its two-dimensional engagement shock, engagement = "thesis-2d").
  excitation spectrum (issue 28): the quasi-static engagement shock F_e and excitation k_m (d - mean d) per
      tooth harmonic of the built-in gear sets, both engagement models (`housingfe source-spectrum`).

Run: `python -m housingfe.source.roosmalen.studies [out_dir]` (default results/source-studies); writes CSV + PNG.
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from housingfe.errors import InputError
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

    from housingfe.source.roosmalen.run import correction_study

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

    study = correction_study(engagement="thesis-2d")
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


# ------------------------------------------------------------------------------------------------ spectrum
SPECTRUM_SCENES = ("gearset-A", "gearset-B", "gearset-C", "gearset-D", "gearset-uncorrected", "gearset-double-helical")
ENGAGEMENT_LABELS = {"thesis-2d": "thesis 2-D (Eq. 2.62)", "face-width": "face width (default)"}
FLAT_OCTAVE_DB = 3.0       # an octave of harmonics whose envelope falls by less than half of 1/n's 6 dB is "flat"


def excitation_spectrum(scenes=SPECTRUM_SCENES, harmonics: int = 15, torque_nm: float | None = None) -> list[dict]:
    """Quasi-static excitation per tooth harmonic n = 1..harmonics of every scene (built-in roosmalen source scene
    or TOML path) at its torque_Nm (or `torque_nm`, pinion, N m), for both engagement models.

    Per row: scene, engagement, n, overlap_ratio, shock_N (one-sided amplitude of the engagement shock F_e, N)
    and excitation_N: one-sided amplitude of k_m (d - mean d) with d = (F - F_e) / S(t) the quasi-static mesh
    compression (what mesh stiffness variation and shock together impose on a structure that holds the mean
    stiffness k_m: the load of the run-up's mesh_force route at low speed), N."""
    from housingfe.source.cli import load_scene
    from housingfe.source.roosmalen import dynamics as dyn
    from housingfe.source.roosmalen import run as rs

    rows = []
    for name in scenes:
        scene, path = load_scene(name)
        table = rs.parse(scene, str(path))
        pair, corr, _, interior, model = rs.build(table, str(path))
        torque = torque_nm or table.torque_Nm
        label = scene.get("scene", {}).get("name", str(name))
        op = rs.OperatingPoint(pair, corr, interior, model, torque, table.stiffness_positions, engagement="face-width")
        shocks = {"thesis-2d": dyn.engagement_force(pair, corr, op.S, op.normal_force), "face-width": op.shock}
        highest = min(s.size for s in shocks.values()) // 2 - 1     # below Nyquist of the samples per period
        if harmonics > highest:
            raise InputError(f"{path}: --harmonics: {harmonics}: the mesh period is sampled at "
                             f"{2 * (highest + 1)} points here: at most {highest} harmonics")
        for engagement, shock in shocks.items():
            d = (op.normal_force - shock) / op.S
            excitation = op.curve.mean * (d - d.mean())
            amp_f = 2 * np.abs(np.fft.rfft(shock)[1:harmonics + 1]) / shock.size
            amp_x = 2 * np.abs(np.fft.rfft(excitation)[1:harmonics + 1]) / excitation.size
            for n in range(1, harmonics + 1):
                rows.append({"scene": label, "engagement": engagement, "n": n, "torque_Nm": torque,
                             "overlap_ratio": pair.overlap_ratio, "shock_N": float(amp_f[n - 1]),
                             "excitation_N": float(amp_x[n - 1])})
    return rows


def envelope_decay(amplitudes) -> dict:
    """Does a harmonic spectrum a_1..a_N decay at least as 1/n with no flat range?  The upper envelope
    E(n) = max_{m >= n} a_m; "at least as 1/n": n E(n) <= a_1 for every n (max_n_envelope_ratio = max n E(n) / a_1
    <= 1); "no flat range": every octave n -> 2n (2n <= N) lowers the envelope by at least FLAT_OCTAVE_DB
    (min_octave_drop_dB; 1/n gives 6.0 dB).  Returns those two numbers, the octave where the drop is smallest
    and passed (both hold)."""
    a = np.asarray(amplitudes, dtype=float)
    N = a.size
    env = np.maximum.accumulate(a[::-1])[::-1]
    n = np.arange(1, N + 1)
    ratio = float(np.max(n * env) / a[0]) if a[0] > 0 else math.inf
    drops = [(20 * math.log10(env[k - 1] / env[2 * k - 1]) if env[2 * k - 1] > 0 else math.inf, k)
             for k in range(1, N // 2 + 1)]
    worst, at = min(drops)
    return {"max_n_envelope_ratio": ratio, "min_octave_drop_dB": float(worst), "worst_octave": (at, 2 * at),
            "passed": bool(ratio <= 1.0 + 1e-9 and worst >= FLAT_OCTAVE_DB)}


def _markdown_table(series: dict, scenes: list, models: list, key: str) -> tuple[str, dict]:
    """One Markdown table of `key` per harmonic (rows) for every scene and model (columns), with eps_beta and the
    envelope check (`envelope_decay`) below; returns (text, {(scene, model): check})."""
    checks = {k: envelope_decay([r[key] for r in v]) for k, v in series.items()}
    harmonics = [r["n"] for r in series[(scenes[0], models[0])]]
    short = {"thesis-2d": "2-D", "face-width": "fw"}
    cols = [(s, m) for s in scenes for m in models]
    head = ["n"] + [f"{s.removeprefix('gearset-')} {short[m]}" for s, m in cols]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for i, n in enumerate(harmonics):
        lines.append("| " + " | ".join([str(n)] + [f"{series[c][i][key]:.0f}" for c in cols]) + " |")
    lines.append("| eps_beta | " + " | ".join(f"{series[c][0]['overlap_ratio']:.3f}" for c in cols) + " |")
    lines.append("| smallest octave drop, dB | " + " | ".join(f"{checks[c]['min_octave_drop_dB']:.1f}" for c in cols)
                 + " |")
    lines.append("| max n E(n) / a_1 | " + " | ".join(f"{checks[c]['max_n_envelope_ratio']:.3f}" for c in cols) + " |")
    lines.append("| envelope check | " + " | ".join("pass" if checks[c]["passed"] else "FAIL" for c in cols) + " |")
    return "\n".join(lines), checks


def write_excitation_spectrum(rows: list[dict], out_dir: Path) -> dict:
    """excitation_spectrum.csv (all rows), excitation_spectrum.md (the shock F_e and the quasi-static excitation
    per harmonic, both models, every set, with the envelope check), excitation_spectrum.png; returns
    {(scene, engagement): envelope_decay(excitation)} (the validate check)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    keys = ["scene", "engagement", "n", "torque_Nm", "overlap_ratio", "shock_N", "excitation_N"]
    write_csv(out_dir / "excitation_spectrum.csv", keys, [[r[k] for k in keys] for r in rows])
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    models = list(ENGAGEMENT_LABELS)
    series = {(s, m): [r for r in rows if r["scene"] == s and r["engagement"] == m] for s in scenes for m in models}
    shock_md, _ = _markdown_table(series, scenes, models, "shock_N")
    excitation_md, checks = _markdown_table(series, scenes, models, "excitation_N")
    torque = rows[0]["torque_Nm"]
    (out_dir / "excitation_spectrum.md").write_text(
        f"Engagement shock F_e, one-sided amplitude per tooth harmonic n [N], {torque:g} N m (2-D: thesis Eq. 2.62, "
        "engagement = \"thesis-2d\"; fw: per face-width slice, engagement = \"face-width\")\n\n" + shock_md
        + "\n\nQuasi-static excitation k_m (d - mean d), d = (F - F_e) / S(t), one-sided amplitude per tooth harmonic "
        "n [N] (the check of issue 28 is on this one)\n\n" + excitation_md + "\n")
    harmonics = [r["n"] for r in series[(scenes[0], models[0])]]
    cols = min(3, len(scenes))
    rows_fig = math.ceil(len(scenes) / cols)
    fig, axes = plt.subplots(rows_fig, cols, figsize=(4.2 * cols, 3.4 * rows_fig), squeeze=False, sharey=True)
    for ax, s in zip(axes.flat, scenes):
        for m, colour, marker in zip(models, ("C0", "C1"), ("s", "o")):
            ax.semilogy(harmonics, [max(r["shock_N"], 1e-3) for r in series[(s, m)]], "-", color=colour,
                        marker=marker, ms=3, label=f"F_e, {ENGAGEMENT_LABELS[m]}")
            ax.semilogy(harmonics, [max(r["excitation_N"], 1e-3) for r in series[(s, m)]], "--", color=colour,
                        lw=0.9, label=f"k_m (d - mean d), {m}")
        f1 = series[(s, "thesis-2d")][0]["shock_N"]
        ax.semilogy(harmonics, [f1 / n for n in harmonics], "k:", lw=0.8, label="1/n from the 2-D n = 1")
        ax.set_title(f"{s} (eps_beta = {series[(s, models[0])][0]['overlap_ratio']:.2f})", fontsize=9)
        ax.set_xlabel("tooth harmonic n")
        ax.grid(True, which="both", lw=0.3)
    for ax in axes.flat[len(scenes):]:
        ax.set_visible(False)
    axes[0, 0].set_ylabel("amplitude [N]")
    axes[0, 0].legend(fontsize=6)
    fig.suptitle(f"quasi-static engagement shock F_e and excitation per tooth harmonic, {torque:g} N m", fontsize=10)
    fig.tight_layout()
    fig.savefig(out_dir / "excitation_spectrum.png", dpi=120)
    plt.close(fig)
    return checks


def _cmd_spectrum(args: argparse.Namespace) -> int:
    from housingfe.errors import InputError
    from housingfe.outputs import atomic_output_dir, reserve_output
    from housingfe.source.cli import load_scene

    scenes = args.scenes or list(SPECTRUM_SCENES)
    if args.harmonics < 2:
        raise InputError(f"source-spectrum: --harmonics: {args.harmonics} must be >= 2")
    if args.torque is not None and not (math.isfinite(args.torque) and args.torque > 0):
        raise InputError(f"source-spectrum: --torque: {args.torque:g} must be a pinion torque > 0 N m")
    paths = []
    for name in scenes:                      # bad names stop here, before any computation or folder
        scene, path = load_scene(name)
        paths.append(path)
        if scene["source"]["model"] != "roosmalen":
            raise InputError(f"{path}: source.model: source-spectrum needs 'roosmalen', not {scene['source']['model']!r}")
        if args.torque is not None:
            from housingfe.source.roosmalen.run import scene_pair

            problem = scene_pair(str(path)).torque_problem(args.torque)
            if problem is not None:
                raise InputError(f"{path}: --torque: {problem}")
    # a refused --out (a folder of your own) stops now, not after the minute the spectra take
    out_dir = reserve_output(args.out, inputs=paths)
    rows = excitation_spectrum(scenes, harmonics=args.harmonics, torque_nm=args.torque)
    with atomic_output_dir(out_dir) as tmp:
        write_excitation_spectrum(rows, tmp)
    print((out_dir / "excitation_spectrum.md").read_text())
    print(f"results in {out_dir}")
    return 0


def register_cli(subparsers) -> None:
    """Add `housingfe source-spectrum [SCENE ...] [--harmonics N] [--torque T] [--out DIR]`."""
    p = subparsers.add_parser("source-spectrum", help="quasi-static engagement shock per tooth harmonic, both "
                              "engagement models (thesis-2d, face-width), table + plot")
    p.add_argument("scenes", nargs="*", help="roosmalen source scenes (default: gear sets A-D, uncorrected, "
                   "double helical)")
    p.add_argument("--harmonics", type=int, default=15, help="tooth harmonics n = 1..N (default 15)")
    p.add_argument("--torque", type=float, default=None, help="pinion torque, N m (default: each scene's)")
    p.add_argument("--out", default="results/source-spectrum", help="result folder (default results/source-spectrum)")
    p.set_defaults(func=_cmd_spectrum, mpi="serial")


if __name__ == "__main__":
    # argparse, so that `--help` prints help instead of becoming the name of the output folder
    parser = argparse.ArgumentParser(prog="python -m housingfe.source.roosmalen.studies",
                                     description="Overlap-ratio study (Fig. 2.9) and correction study (Fig. 2.18): "
                                                 "CSV + PNG into OUT_DIR.")
    parser.add_argument("out_dir", nargs="?", default="results/source-studies", type=Path)
    main(parser.parse_args().out_dir)
