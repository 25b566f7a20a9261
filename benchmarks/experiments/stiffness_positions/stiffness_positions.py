"""Does the stiffness curve's resolution (positions per base pitch) alias harmonics the run-up uses? (issue 28)

The lumped source samples the mesh stiffness at `stiffness_positions` positions per base pitch
(housingfe.source.stiffness.stiffness_curve) and interpolates them linearly onto the 256 instants of S(t)
(housingfe.source.roosmalen.run.OperatingPoint); the harmonic balance takes S's harmonics up to 2H from those 256
instants (dynamics._fourier_coefficients: zero only beyond THEIR Nyquist limit, 128), and the run-up keeps the
lines n = 1..H (runup.harmonics = 30) below runup.f_max_hz = 4 kHz.  With P positions a harmonic n >= P / 2 of
S(t) is no harmonic of the stiffness but an image of the linear interpolation, and the harmonics below P / 2 are
aliased by those above.  This experiment measures, for gear set A and the uncorrected set at 2000 N m on the
test-gearbox-runup scene (ball bearings, its misalignment, engagement, shuttling moment, coupled source), and the
double helical set with cylindrical roller bearings at 1000 and 2000 N m (the torque-law check's case; own basis):

1. |S_n| / k_m, n = 1..60, of S(t) as the balance takes it, at P = 16 / 32 / 64 / 128 / 256 / 512 (and the mesh
   model's points per contact line 24 -> 48 at 128 and 512 positions: does it interact?);
2. the run-up's source lines and totals at every P against P = 512 (the reference; 256 gives the same S(t) at the
   256 instants and differs in the load share only): the mesh excitation F_n - k_m d_n (dB re 1 N) and the
   shuttling moment (dB re 1 N m) per line (mesh_force route), the rigid-bore L_omega per line, and
   L_WA per line and in total over speed (both routes, sigma = 1), computed with the scene's own coupled models
   (housingfe.studies.chain_session.ChainSession: one basis, the uncorrected set a re-analysis);
3. the cost of one operating point (stiffness curve, load share, whole SourceModel.prepared) per P.

    PYTHONPATH=. OPENBLAS_NUM_THREADS=1 /work/main/.venv/bin/python \
        benchmarks/experiments/stiffness_positions/stiffness_positions.py [--out DIR]

Writes stiffness_positions_spectra.csv, stiffness_positions_lines.csv (the lines at 250/500/1000/1500 rpm),
stiffness_positions_totals.csv (L_WA at every speed),
stiffness_positions.png and prints the README's tables.
"""
import argparse
import math
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from housingfe import levels
from housingfe.outputs import write_csv
from housingfe.runup.chain import run_source
from housingfe.source.roosmalen.operating import SourceModel
from housingfe.source.stiffness import face_load_share, normal_force_from_torque, stiffness_curve
from housingfe.studies.chain_session import ChainSession

HERE = Path(__file__).parent
SCENE = "test-gearbox-runup"
# (label, gear set, bearings, pinion torque N m): the scene's own, the uncorrected set, and the double helical set of
# the torque-law check (its own layout: a second basis)
CASES = (("A", "A", "ball", 2000.0), ("uncorrected", "uncorrected", "ball", 2000.0),
         ("double_helical@1000", "double_helical", "cylindrical_roller", 1000.0),
         ("double_helical@2000", "double_helical", "cylindrical_roller", 2000.0))
GEAR_SETS = tuple(c[0] for c in CASES)
POSITIONS = (16, 32, 64, 128, 256, 512)
REFERENCE = 512
SLICES = (24, 48)                 # MeshModel.n_slices (the drivetrain's default 24)
SLICE_POSITIONS = (128, 512)      # where the slices' effect on S_n is measured
SPEEDS_REPORTED = (250.0, 500.0, 1000.0, 1500.0)
N_SPECTRUM = 60                   # 2H: the highest harmonic of S in the balance's Toeplitz matrix
RADIATION = "erp"
REACH_DB = 10.0                   # a line "reaches L_WA" when it lies within this of its speed's total L_WA


def spectrum(S: np.ndarray, n_max: int = N_SPECTRUM) -> np.ndarray:
    """|S_n| / k_m, n = 1..n_max (one-sided) of one uniformly sampled period."""
    X = np.fft.rfft(S) / S.size
    return 2 * np.abs(X[1:n_max + 1]) / np.real(X[0])


def source_of(drivetrain, spec, law, positions: int, n_slices: int | None = None) -> SourceModel:
    """The run-up's lumped source (as housingfe.runup.scene._source makes it) with `positions` per base pitch and,
    if given, another number of points per contact line."""
    if n_slices is None:
        return drivetrain.source_model(harmonics=spec.harmonics, engagement=spec.engagement, misalignment=law,
                                       stiffness_positions=positions)
    interior, geometry, model = drivetrain.to_lumped()
    return SourceModel(drivetrain.gears.pair, drivetrain.gears.corrections, interior, geometry,
                       mesh_model=replace(model, n_slices=n_slices), harmonics=spec.harmonics,
                       engagement=spec.engagement, misalignment=law, stiffness_positions=positions)


def costs(source: SourceModel, positions: int, torque: float) -> dict:
    """Seconds of one operating point at `torque` [N m]: stiffness curve, load share (as OperatingPoint calls them) and the
    whole SourceModel.prepared (curve, load share, F_e, matrices)."""
    force = normal_force_from_torque(source.pair, torque)
    model = replace(source.mesh_model, lead_gap=source.lead_gap(torque))
    t0 = time.perf_counter()
    stiffness_curve(model, force, positions)
    t1 = time.perf_counter()
    face_load_share(model, force, n_positions=positions)
    t2 = time.perf_counter()
    source.prepared([torque])
    t3 = time.perf_counter()
    return {"t_curve": t1 - t0, "t_share": t2 - t1, "t_prepared": t3 - t2}


def run() -> tuple[list, list, list]:
    from housingfe.drivetrain.misalignment import lead_gap_law

    session = ChainSession.from_scene(SCENE)
    spec = session.spec
    spec_rows, line_rows, total_rows = [], [], []
    for gear_set, gears, bearings, torque in CASES:
        dt = session.drivetrain(gears, bearings, torque)
        t0 = time.perf_counter()
        model = session.model(dt, gear_set)
        print(f"{gear_set}: coupled model {time.perf_counter() - t0:.1f} s ({session.log[-1].how})")
        law = lead_gap_law(dt, spec.misalignment_model)
        law(torque)                                   # cached: not part of the costs below
        for positions in POSITIONS:
            source = source_of(dt, spec, law, positions)
            cost = costs(source, positions, torque)
            S, _ = source.mesh_stiffness(torque)
            spec_rows.append({"gear_set": gear_set, "positions": positions, "slices": 24, "S_rel": spectrum(S),
                              **cost})
            lines, t_lines = run_source(model, source, spec.speeds, [torque], spec.f_max_hz, spec.source_receptance,
                                        spec.mesh_moment_model, spec.mesh_friction)
            res = session.runup(model, torque, lines=lines)
            a_w = levels.a_weighting_db(lines.frequency)
            moment = lines.shuttle_moment if lines.shuttle_moment is not None else np.zeros(len(lines.frequency))
            for route in spec.routes:
                Lw = res.L_W[route, RADIATION]
                for k in range(len(lines.frequency)):
                    line_rows.append({"gear_set": gear_set, "positions": positions, "route": route,
                                      "speed_rpm": float(lines.speed[k]), "harmonic": int(lines.harmonic[k]),
                                      "frequency_hz": float(lines.frequency[k]),
                                      "L_F_dB": float(levels.level(abs(lines.mesh_excitation[k]) ** 2, levels.F0)),
                                      "L_M_dB": float(levels.level(abs(moment[k]) ** 2 + 1e-300, 1.0)),
                                      "L_omega_dB": float(lines.L_omega[k]), "LwA_dB": float(Lw[k] + a_w[k])})
                speeds, lwa = res.series(route, RADIATION, torque, "LwA_dB")
                total_rows += [{"gear_set": gear_set, "positions": positions, "route": route, "speed_rpm": float(s),
                                "LwA_dB": float(v)} for s, v in zip(speeds, lwa)]
            print(f"{gear_set} P = {positions:3d}: curve {cost['t_curve']:.2f} s, share {cost['t_share']:.2f} s, "
                  f"operating point {cost['t_prepared']:.2f} s, lines {t_lines:.1f} s")
        for n_slices in SLICES[1:]:
            for positions in SLICE_POSITIONS:
                source = source_of(dt, spec, law, positions, n_slices)
                S, _ = source.mesh_stiffness(torque)
                spec_rows.append({"gear_set": gear_set, "positions": positions, "slices": n_slices,
                                  "S_rel": spectrum(S), "t_curve": math.nan, "t_share": math.nan,
                                  "t_prepared": math.nan})
    return spec_rows, line_rows, total_rows


def _key(r, *names):
    return tuple(r[n] for n in names)


def errors(line_rows, total_rows) -> tuple[list, list]:
    """Per line and per total: the value at P minus the reference's (dB)."""
    ref_l = {_key(r, "gear_set", "route", "speed_rpm", "harmonic"): r for r in line_rows if r["positions"] == REFERENCE}
    ref_t = {_key(r, "gear_set", "route", "speed_rpm"): r for r in total_rows if r["positions"] == REFERENCE}
    for r in line_rows:
        ref = ref_l[_key(r, "gear_set", "route", "speed_rpm", "harmonic")]
        tot = ref_t[_key(r, "gear_set", "route", "speed_rpm")]["LwA_dB"]
        r.update({f"d{k}": r[k] - ref[k] for k in ("L_F_dB", "L_M_dB", "L_omega_dB", "LwA_dB")},
                 reaches=bool(ref["LwA_dB"] >= tot - REACH_DB))
    for r in total_rows:
        r["dLwA_dB"] = r["LwA_dB"] - ref_t[_key(r, "gear_set", "route", "speed_rpm")]["LwA_dB"]
    return line_rows, total_rows


def write(spec_rows, line_rows, total_rows, out: Path) -> None:
    ref = {r["gear_set"]: r["S_rel"] for r in spec_rows if r["positions"] == REFERENCE and r["slices"] == 24}
    write_csv(out / "stiffness_positions_spectra.csv",
              ["gear_set", "positions", "slices", "n", "S_rel", "S_rel_reference", "t_curve_s", "t_share_s",
               "t_operating_point_s"],
              [[r["gear_set"], r["positions"], r["slices"], n + 1, r["S_rel"][n], ref[r["gear_set"]][n], r["t_curve"],
                r["t_share"], r["t_prepared"]] for r in spec_rows for n in range(N_SPECTRUM)])
    cols = ["gear_set", "positions", "route", "speed_rpm", "harmonic", "frequency_hz", "L_F_dB", "L_M_dB", "L_omega_dB",
            "LwA_dB", "dL_F_dB", "dL_M_dB", "dL_omega_dB", "dLwA_dB", "reaches"]
    # the lines at the reported speeds only (every speed's total: stiffness_positions_totals.csv)
    write_csv(out / "stiffness_positions_lines.csv", cols,
              [[r[c] for c in cols] for r in line_rows if r["speed_rpm"] in SPEEDS_REPORTED])
    cols = ["gear_set", "positions", "route", "speed_rpm", "LwA_dB", "dLwA_dB"]
    write_csv(out / "stiffness_positions_totals.csv", cols, [[r[c] for c in cols] for r in total_rows])


def markdown(spec_rows, line_rows, total_rows) -> str:
    out = []
    shown = (1, 2, 4, 6, 8, 9, 11, 13, 15, 16, 17, 20, 24, 30, 40)
    for gs in GEAR_SETS:
        out.append(f"\nset {gs}, |S_n| / k_m x 1e4 (S(t) as the balance takes it):\n")
        out.append("| P (slices) | " + " | ".join(f"n={n}" for n in shown) + " | curve s | share s | op. point s |")
        out.append("|" + "---|" * (len(shown) + 4))
        for r in (r for r in spec_rows if r["gear_set"] == gs):
            t = "" if math.isnan(r["t_curve"]) else f" {r['t_curve']:.2f} | {r['t_share']:.2f} | {r['t_prepared']:.2f}"
            out.append(f"| {r['positions']} ({r['slices']}) | " + " | ".join(f"{r['S_rel'][n - 1] * 1e4:.2f}"
                                                                        for n in shown) + f" |{t or ' | | '} |")
    for route in ("mesh_force", "tf_omega"):
        keys = ("dL_F_dB", "dL_M_dB") if route == "mesh_force" else ("dL_omega_dB",)
        what = "L_F / L_M (mesh force / shuttling moment)" if route == "mesh_force" else "L_omega"
        out.append(f"\n{route}: largest |error| vs P = {REFERENCE} [dB] of the source's lines ({what}) over the lines "
                   f"that reach L_WA (within {REACH_DB:g} dB of the speed's total in the reference) / of the total "
                   "L_WA, at each speed:\n")
        out.append("| set | P | " + " | ".join(f"{s:g} rpm" for s in SPEEDS_REPORTED) + " | all speeds | total, "
                   f">= {SPEEDS_REPORTED[0]:g} rpm |")
        out.append("|" + "---|" * (len(SPEEDS_REPORTED) + 4))
        for gs in GEAR_SETS:
            for p in POSITIONS[:-1]:
                ls = [r for r in line_rows if r["gear_set"] == gs and r["positions"] == p and r["route"] == route
                      and r["reaches"]]
                ts = [r for r in total_rows if r["gear_set"] == gs and r["positions"] == p and r["route"] == route]
                cells = []
                for s in SPEEDS_REPORTED:
                    le = [max((abs(r[k]) for r in ls if r["speed_rpm"] == s), default=math.nan) for k in keys]
                    te = next(abs(r["dLwA_dB"]) for r in ts if r["speed_rpm"] == s)
                    cells.append(" / ".join(f"{x:.2f}" for x in (*le, te)))
                le = [max(abs(r[k]) for r in ls) for k in keys]
                cells.append(" / ".join(f"{x:.2f}" for x in (*le, max(abs(r["dLwA_dB"]) for r in ts))))
                cells.append(f"{max(abs(r['dLwA_dB']) for r in ts if r['speed_rpm'] >= SPEEDS_REPORTED[0]):.2f}")
                out.append(f"| {gs} | {p} | " + " | ".join(cells) + " |")
    return "\n".join(out)


def plot(spec_rows, total_rows, out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = np.arange(1, N_SPECTRUM + 1)
    fig, axes = plt.subplots(2, len(GEAR_SETS), figsize=(4.8 * len(GEAR_SETS), 8.5), squeeze=False)
    for j, gs in enumerate(GEAR_SETS):
        ax = axes[0, j]
        for k, r in enumerate(r for r in spec_rows if r["gear_set"] == gs and r["slices"] == 24):
            ax.semilogy(n, np.maximum(r["S_rel"], 1e-7), "-o" if r["positions"] == 32 else "-", ms=3,
                        color=f"C{k}", lw=2 if r["positions"] == REFERENCE else 1, label=f"P = {r['positions']}")
        for p in POSITIONS[:-1]:
            if p / 2 <= N_SPECTRUM:
                ax.axvline(p / 2, color="0.7", lw=0.6, ls=":")
        ax.axvspan(30.5, N_SPECTRUM, color="0.93")
        ax.set_title(f"{gs}: |S_n| / k_m of S(t) as the balance takes it\n(dotted: Nyquist P/2; grey: "
                     "beyond the lines H = 30, in the Toeplitz matrix only)", fontsize=8)
        ax.set_xlabel("tooth harmonic n")
        ax.set_ylabel("|S_n| / k_m")
        ax.set_ylim(1e-6, 0.1)
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=7, ncol=2)
        ax = axes[1, j]
        for k, p in enumerate(POSITIONS[:-1]):
            for route, style in (("mesh_force", "-"), ("tf_omega", "--")):
                ts = [r for r in total_rows if r["gear_set"] == gs and r["positions"] == p and r["route"] == route]
                ax.plot([r["speed_rpm"] for r in ts], [r["dLwA_dB"] for r in ts], style, color=f"C{k}",
                        label=f"P = {p}, {route}")
        ax.axhspan(-0.5, 0.5, color="0.9")
        ax.set_title(f"{gs}: L_WA(P) - L_WA(P = {REFERENCE}) over speed (sigma = 1)", fontsize=8)
        ax.set_xlabel("pinion speed [rev/min]")
        ax.set_ylabel("error of total L_WA [dB]")
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=6, ncol=2)
    fig.tight_layout()
    fig.savefig(out / "stiffness_positions.png", dpi=120)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=HERE)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    spec_rows, line_rows, total_rows = run()
    line_rows, total_rows = errors(line_rows, total_rows)
    write(spec_rows, line_rows, total_rows, args.out)
    plot(spec_rows, total_rows, args.out)
    print(markdown(spec_rows, line_rows, total_rows))
    print(f"\n{time.perf_counter() - t0:.0f} s wall")


if __name__ == "__main__":
    main()
