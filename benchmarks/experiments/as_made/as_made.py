"""Can gears as made within DIN/ISO grade 5 explain set A's measured tooth-band L_omega? (issue 28): an experiment,
nothing tuned, the default chain untouched.

Gear set A at 2000 N m (scene `gearset-A`, corrections A, rigid-bore lumped source).  Over one hunting period
(lcm(24, 72) = 72 mesh periods = one wheel revolution) the loaded TE is the aligned pair's quasi-static TE of the
default face-width model, d_qs = (F - F_e)/S(t) (periodic: the tooth line and its harmonics), plus the first-order
TE of tooth-to-tooth deviations drawn within ISO 1328-1:1995 grade 5 (housingfe.source.as_made: the load-weighted
mean sum k_i e_i / sum k_i of the deviations of the contact points in contact, k_i the point stiffnesses of the 3-D
mesh model at each mesh position; valid while the deviations are small against the ~40 um deflection).  Per case
(pitch, profile slope, profile form, helix slope, twist, all; and a twist common to all teeth) and draw (seeded):

  * its spectrum in wheel orders (the tooth frequency is order 72);
  * the TE in the 1/3-octave band (IEC 61260 base-10, as housingfe.levels) that contains the tooth frequency at
    500 / 1000 / 1500 rpm - the measured quantity (Sec. 5.3: 1/3 octaves of a 2.44 Hz spectrum) -, the tooth line
    alone, the sidebands alone, and the same for the 2nd harmonic's band;
  * the wheel's L_omega on rigid bores: each line in the band times the rigid-bore receptance R_TE(f) of
    benchmarks/experiments/lomega_budget (mean-stiffness system loaded by k_m e; the tooth line agrees with the full
    harmonic balance to 0.1 dB there), energy-summed.

    PYTHONPATH=. OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/experiments/as_made/as_made.py [--draws 50]
"""
import argparse
import importlib.util
import math
import time
from pathlib import Path

import numpy as np

from housingfe import levels
from housingfe.outputs import write_csv
from housingfe.source import as_made as am

TORQUE = 2000.0
SPEEDS = (500.0, 1000.0, 1500.0)
MEASURED = {500.0: 109.9, 1000.0: 111.2, 1500.0: 120.8}    # Fig. 5.4, tooth 1/3-octave band, set A, 2000 N m
CASES = {"pitch": ["pitch"], "profile slope": ["profile_slope"], "profile form": ["profile_form"],
         "helix slope": ["helix_slope"], "twist": ["twist"], "all": list(am.DEVIATION_KINDS),
         "twist common to all teeth": "common-twist"}
HERE = Path(__file__).parent


def _lomega_budget():
    spec = importlib.util.spec_from_file_location("lomega_budget", HERE.parent / "lomega_budget" / "lomega_budget.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def band_of(f: float):
    bands = levels.third_octave_bands(f / 1.3, f * 1.3)
    i = int(np.flatnonzero((bands.lower <= f) & (f < bands.upper))[0])
    return float(bands.nominal[i]), float(bands.lower[i]), float(bands.upper[i])


def coupled_te_receptance():
    """f [Hz] -> |Omega_wheel / e| [(rad/s)/m] of the coupled gearbox of `test-gearbox-runup` at TORQUE (housing,
    ball bearings, shafts, gear bodies; its Ritz reduction loaded by k_ref e at the gear mesh: the receptance of
    lomega_budget's coupled part).  Building it takes 10-60 s; each frequency about 1 ms."""
    from housingfe.response.observers import node_key
    from housingfe.studies.chain_session import ChainSession

    session = ChainSession.from_scene("test-gearbox-runup")
    dspec = session.scene.drivetrain
    model = session.model(session.drivetrain(dspec.gear_set, dspec.bearings, TORQUE))
    red = model.reduction
    k_ref = float(model.structure.spec.gear_meshes[0].stiffness)
    node = red.reduced.points[node_key(model.wheel_node)]
    axis = model.wheel_axis / np.linalg.norm(model.wheel_axis)

    def receptance(f):
        f = np.asarray(f, float)
        c = red.coefficients(f, {"mesh": np.full(f.size, k_ref, complex)})
        return np.abs(2 * math.pi * f * (axis @ (node[3:6] @ c)))
    return receptance


def coupled_receptances(orders, f_tooth, z2, bands):
    """`coupled_te_receptance` at the wheel orders inside the bands of each speed (NaN elsewhere)."""
    t0 = time.perf_counter()
    receptance = coupled_te_receptance()
    out = {}
    for v in SPEEDS:
        f = orders * f_tooth[v] / z2
        sel = np.zeros(f.size, bool)
        for _, lo, hi in bands[v]:
            sel |= (f >= lo) & (f < hi)
        out[v] = np.full(f.size, np.nan)
        out[v][sel] = receptance(f[sel])
    print(f"coupled gearbox (test-gearbox-runup, ball bearings): receptance at {sum(np.isfinite(r).sum() for r in out.values())}"
          f" lines in {time.perf_counter() - t0:.1f} s")
    return out


def draw_case(rng, case, pair, tolerances, pitch_factor, flank_factor):
    if case == "common-twist":            # one twist for every tooth of a gear (a grinding setting), sign random
        devs = []
        for g, z in enumerate(pair.teeth):
            d = am.ToothDeviations.zeros(int(z))
            d.twist[:] = rng.choice([-1.0, 1.0]) * tolerances[g]["f_Halpha"] * flank_factor
            devs.append(d)
        return devs
    return [am.draw_deviations(rng, int(z), tolerances[g], case, pitch_factor, flank_factor)
            for g, z in enumerate(pair.teeth)]


def set_a(positions: int):
    """Set A at TORQUE (housingfe.runup.reindex.set_a: scene gearset-A, rigid-bore lumped source, face-width
    engagement): pair, mesh model, operating point, normal force [N], the aligned d_qs at `positions` samples per mesh
    period [m], contact weights, grade-5 tolerances per gear, the pitch and flank factors to the mesh normal."""
    from housingfe.errors import InputError
    from housingfe.runup.reindex import set_a as package_set_a

    try:
        a = package_set_a(positions, TORQUE)
    except InputError as exc:
        raise SystemExit(f"--positions: {exc}") from None
    return (a.pair, a.model, a.op, a.normal_force, a.aligned_te, a.weights, a.tolerances, a.pitch_factor,
            a.flank_factor)


def main(draws: int, seed: int, positions: int, exact: bool, out_dir: Path = HERE, with_coupled: bool = True):
    t0 = time.perf_counter()
    pair, model, op, F, d_qs, weights, tolerances, pitch_factor, flank_factor = set_a(positions)
    z1, z2 = (int(z) for z in pair.teeth)
    periods = am.hunting_mesh_periods(pair)
    wheel_revs = periods // z2
    deflection = float(op.curve.deflection.mean())
    print(f"set A: z = {z1}/{z2}, m_n = {pair.module * 1e3:.1f} mm, d = {pair.pitch_diameter[0] * 1e3:.1f} / "
          f"{pair.pitch_diameter[1] * 1e3:.1f} mm, b = 66 / 62 mm, eps_alpha = {pair.transverse_contact_ratio:.3f}, "
          f"eps_beta = {pair.overlap_ratio:.3f}; hunting period {periods} mesh periods = {wheel_revs} wheel rev.")
    print("ISO 1328-1:1995 grade 5, um (pinion / wheel): " + ", ".join(
        f"{k} {tolerances[0][k] * 1e6:g} / {tolerances[1][k] * 1e6:g}" for k in tolerances[0]))
    print(f"to the mesh normal: pitch x cos(alpha_t) cos(beta_b) = {pitch_factor:.3f}, profile/helix x cos(beta_b) = "
          f"{flank_factor:.3f}; mean mesh approach at {F:.0f} N: {deflection * 1e6:.1f} um")
    print(f"contact weights: sum k_i = {weights.stiffness.mean():.4e} N/m mean over {positions} positions "
          f"(stiffness curve k_m = {op.curve.mean:.4e} N/m)")

    budget = _lomega_budget()
    f_tooth = {v: pair.tooth_frequency(v) for v in SPEEDS}
    bands = {v: (band_of(f_tooth[v]), band_of(2 * f_tooth[v])) for v in SPEEDS}
    n_orders = periods * positions // 2 + 1
    orders = np.arange(n_orders) / wheel_revs
    receptance = {v: budget.lumped_te_receptance(op.mats, np.maximum(orders[1:] * f_tooth[v] / z2, 1e-3))
                  for v in SPEEDS}
    coupled = coupled_receptances(orders[1:], f_tooth, z2, bands) if with_coupled else None

    def metrics(te):
        _, a = am.order_amplitudes(te - te.mean(), wheel_revs)
        out = {"line_1": a[z2], "line_2": a[2 * z2]}
        for v in SPEEDS:
            f = orders * f_tooth[v] / z2
            for h, (_, lo, hi) in zip((1, 2), bands[v]):
                sel = (f >= lo) & (f < hi)
                out[f"band{h}_{v:.0f}"] = float(np.sqrt(np.sum(a[sel] ** 2)))
                out[f"side{h}_{v:.0f}"] = float(np.sqrt(max(np.sum(a[sel] ** 2) - a[h * z2] ** 2, 0.0)))
                ms = np.sum((receptance[v][sel[1:]] * a[1:][sel[1:]]) ** 2) / 2
                out[f"L{h}_{v:.0f}"] = 10 * math.log10(ms / levels.OMEGA0**2)
                if coupled is not None:
                    ms = np.sum((coupled[v][sel[1:]] * a[1:][sel[1:]]) ** 2) / 2
                    out[f"Lc{h}_{v:.0f}"] = 10 * math.log10(ms / levels.OMEGA0**2)
        return out, a

    base_te = np.tile(d_qs, periods)
    model_only, a_model = metrics(base_te)
    print(f"aligned pair alone (face-width default): tooth line {model_only['line_1'] * 1e6:.3f} um, 2nd "
          f"{model_only['line_2'] * 1e6:.3f} um; rigid-bore L_omega tooth band " + " / ".join(
              f"{model_only[f'L1_{v:.0f}']:.1f}" for v in SPEEDS) + " dB")
    for v in SPEEDS:
        (n1, lo1, hi1), (n2, lo2, hi2) = bands[v]
        print(f"  {v:.0f} rpm: f_tooth {f_tooth[v]:.0f} Hz in the {n1:g} Hz band {lo1:.0f}-{hi1:.0f} Hz "
              f"(orders {lo1 / f_tooth[v] * z2:.1f}-{hi1 / f_tooth[v] * z2:.1f}); 2nd harmonic in the {n2:g} Hz band "
              f"(orders {lo2 / f_tooth[v] * z2:.1f}-{hi2 / f_tooth[v] * z2:.1f})")

    rows, keep, exact_rows = [], {}, []
    row = {"case": "aligned pair (model)", "draws": 1}
    for key, val in model_only.items():
        for q in ("p5", "median", "p95"):
            row[f"{key}_{q}"] = val * (1e6 if not key.startswith("L") else 1.0)
    rows.append(row)
    print("\n| deviations (grade 5) | tooth line n = 1, um | tooth band 500 / 1000 / 1500 rpm, um (median [p5-p95]) "
          "| sidebands in the band, um | 2nd-harmonic band, um | L_omega rigid bores 500 / 1000 / 1500 rpm, dB (median) "
          "| max spread of e in contact, um |")
    print("|---|---|---|---|---|---|---|")
    for ci, (name, kinds) in enumerate(CASES.items()):
        rng = np.random.default_rng([seed, ci])
        results, spreads = [], []
        for _ in range(draws):
            pin, whl = draw_case(rng, kinds, pair, tolerances, pitch_factor, flank_factor)
            te_dev, spread = am.first_order_te(pair, weights, pin, whl, with_spread=True)
            m, a = metrics(base_te + te_dev)
            results.append(m)
            spreads.append(spread)
        stats = {k: np.percentile([r[k] for r in results], [5, 50, 95]) for k in results[0]}
        row = {"case": name, "draws": draws}
        for key, (p5, p50, p95) in stats.items():
            s = 1.0 if key.startswith("L") else 1e6
            row.update({f"{key}_p5": p5 * s, f"{key}_median": p50 * s, f"{key}_p95": p95 * s})
        row["max_spread_um"] = max(spreads) * 1e6
        rows.append(row)
        if name in ("all", "pitch"):          # the median draw (tooth band at 1500 rpm): spectrum, exact check
            i = int(np.argsort([r["band1_1500"] for r in results])[len(results) // 2])
            rng = np.random.default_rng([seed, ci])
            for _ in range(i + 1):
                pin, whl = draw_case(rng, kinds, pair, tolerances, pitch_factor, flank_factor)
            keep[name] = (pin, whl, metrics(base_te + am.first_order_te(pair, weights, pin, whl))[1])
        fmt = lambda k: " / ".join(f"{row[f'{k}_{v:.0f}_median']:.2f}" for v in SPEEDS)   # noqa: E731
        rng_s = lambda k: " / ".join(f"{row[f'{k}_{v:.0f}_p5']:.2f}-{row[f'{k}_{v:.0f}_p95']:.2f}"  # noqa: E731
                                     for v in SPEEDS)
        print(f"| {name} | {row['line_1_median']:.2f} [{row['line_1_p5']:.2f}-{row['line_1_p95']:.2f}] | "
              f"{fmt('band1')} [{rng_s('band1')}] | {fmt('side1')} | {fmt('band2')} | "
              + " / ".join(f"{row[f'L1_{v:.0f}_median']:.1f}" for v in SPEEDS) + f" | {row['max_spread_um']:.1f} |")
    # the TE amplitude at the tooth frequency alone that the measured level needs (one line x R_TE(f_tooth))
    needed = {"rigid": {v: budget.amplitude_for_level(MEASURED[v]) / budget.lumped_te_receptance(
        op.mats, f_tooth[v])[0] for v in SPEEDS}}
    if coupled is not None:
        needed["coupled"] = {v: budget.amplitude_for_level(MEASURED[v]) / coupled[v][z2 * wheel_revs - 1]
                             for v in SPEEDS}
    print("\nmeasured L_omega 109.9 / 111.2 / 120.8 dB; TE the measurement needs at n = 1 (one line at f_tooth): "
          + ", ".join(f"{route} " + " / ".join(f"{x * 1e6:.2f}" for x in vals.values()) + " um"
                      for route, vals in needed.items()))
    route = "coupled" if coupled is not None else "rigid"
    print("| deviations | L_omega rigid bores - measured, dB (median, p95) | L_omega coupled gearbox - measured, dB "
          f"(median, p95; every line x the coupled R_TE(f)) | band TE / TE needed ({route}), dB (median) |")
    print("|---|---|---|---|")
    for row in rows:
        r = " / ".join(f"{row[f'L1_{v:.0f}_median'] - MEASURED[v]:+.1f} ({row[f'L1_{v:.0f}_p95'] - MEASURED[v]:+.1f})"
                       for v in SPEEDS)
        c = " / ".join(f"{row[f'Lc1_{v:.0f}_median'] - MEASURED[v]:+.1f} ({row[f'Lc1_{v:.0f}_p95'] - MEASURED[v]:+.1f})"
                       for v in SPEEDS) if coupled is not None else "(--rigid-only)"
        n = " / ".join(f"{20 * math.log10(row[f'band1_{v:.0f}_median'] * 1e-6 / needed[route][v]):+.1f}"
                       for v in SPEEDS)
        print(f"| {row['case']} | {r} | {c} | {n} |")
    if exact:
        print("\n## First order against the full load distribution (the median draw; deviations in the flank gaps, "
              "contact loss and Hertz included)")
        print("| deviations | tooth band 500 / 1000 / 1500 rpm, um: first order | full | L_omega rigid, dB: first order "
              "| full | max abs(full - first order) over the period, um | rms TE change first order / full, um |")
        print("|---|---|---|---|---|---|---|")
        for name, (pin, whl, _) in keep.items():
            t1 = time.perf_counter()
            first = am.first_order_te(pair, weights, pin, whl)
            full = am.exact_deviation_te(model, F, pin, whl, positions)
            m1, m2 = metrics(base_te + first)[0], metrics(base_te + full)[0]
            for key, val in (("first", m1), ("full", m2)):
                exact_rows.append({"case": f"{name}, median draw, {key}", **{
                    k: v * (1.0 if k.startswith("L") else 1e6) for k, v in val.items()}})
            print(f"| {name} | " + " / ".join(f"{m1[f'band1_{v:.0f}'] * 1e6:.2f}" for v in SPEEDS) + " | "
                  + " / ".join(f"{m2[f'band1_{v:.0f}'] * 1e6:.2f}" for v in SPEEDS) + " | "
                  + " / ".join(f"{m1[f'L1_{v:.0f}']:.1f}" for v in SPEEDS) + " | "
                  + " / ".join(f"{m2[f'L1_{v:.0f}']:.1f}" for v in SPEEDS)
                  + f" | {np.max(np.abs(full - first)) * 1e6:.2f} | {np.std(first) * 1e6:.2f} / {np.std(full) * 1e6:.2f}"
                  f" | ({time.perf_counter() - t1:.0f} s)")
    keys = list(rows[1])
    write_csv(out_dir / "as_made.csv", keys, [[_fmt(r.get(k, "")) for k in keys] for r in rows + exact_rows])
    upto = orders <= 2.6 * z2
    write_csv(out_dir / "as_made_spectrum.csv", ["wheel_order", "aligned_um", "pitch_median_draw_um",
                                                 "all_median_draw_um"],
              [[f"{q:g}", f"{a0 * 1e6:.4g}", f"{a1 * 1e6:.4g}", f"{a2 * 1e6:.4g}"] for q, a0, a1, a2 in
               zip(orders[upto], a_model[upto], keep["pitch"][2][upto], keep["all"][2][upto])])
    plot(orders, a_model, keep["all"][2], rows, bands, f_tooth, z2, {v: x * 1e6 for v, x in needed[route].items()},
         route, out_dir / "as_made.png")
    print(f"\n{draws} draws x {len(CASES)} cases, {positions} positions per mesh period"
          + (", full check of 2 median draws" if exact else "") + ": "
          f"{time.perf_counter() - t0:.1f} s")


def _fmt(x):
    return f"{x:.4g}" if isinstance(x, float) else x


def plot(orders, a_model, a_all, rows, bands, f_tooth, z2, needed_um: dict, route: str, out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    ax = axes[0]
    sel = (orders > 0) & (orders <= 2.6 * z2)
    if a_all is not None:
        ax.semilogy(orders[sel], a_all[sel] * 1e6, "C1.-", lw=0.5, ms=2, label="aligned + grade-5 deviations "
                                                                           "(all kinds, median draw at 1500 rpm)")
    ax.semilogy(orders[sel], np.maximum(a_model[sel], 1e-12) * 1e6, "C0o", ms=4, label="aligned pair (model)")
    for v, colour in zip(SPEEDS, ("C2", "C3", "C4")):
        for (_, lo, hi) in bands[v]:
            ax.axvspan(lo / f_tooth[v] * z2, hi / f_tooth[v] * z2, color=colour, alpha=0.08)
    lo, hi = min(needed_um.values()), max(needed_um.values())
    ax.axhspan(lo, hi, color="0.85", label=f"TE the measurement needs ({route}, {lo:.1f}-{hi:.1f} um)")
    ax.set_ylim(1e-3, 30)
    ax.set_xlabel("wheel order (tooth = 72); shaded: 1/3-octave bands at 500/1000/1500 rpm")
    ax.set_ylabel("TE amplitude [um]")
    ax.set_title("set A, 2000 N m, one hunting period (1 wheel revolution)", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(True, which="both", lw=0.3)
    ax = axes[1]
    names = [r["case"] for r in rows]
    x = np.arange(len(names))
    for j, (v, colour) in enumerate(zip(SPEEDS, ("C2", "C3", "C4"))):
        med = np.array([r[f"band1_{v:.0f}_median"] for r in rows])
        lo = med - np.array([r[f"band1_{v:.0f}_p5"] for r in rows])
        hi = np.array([r[f"band1_{v:.0f}_p95"] for r in rows]) - med
        ax.errorbar(x + (j - 1) * 0.2, med, yerr=[lo, hi], fmt="o", color=colour, ms=4, capsize=2,
                    label=f"{v:.0f} rpm tooth band (p5-median-p95)")
        ax.plot([x[0] - 0.4, x[-1] + 0.4], [needed_um[v]] * 2, "--", color=colour, lw=0.8)
    ax.set_yscale("log")
    ax.set_xticks(x)
    ax.set_xticklabels(names, rotation=30, ha="right", fontsize=7)
    ax.set_ylabel("TE in the tooth 1/3-octave band [um]")
    ax.set_title(f"p5 / median / p95 over the draws; dashed: TE the measurement needs ({route})", fontsize=9)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--draws", type=int, default=50, help="random draws per deviation case (default 50)")
    ap.add_argument("--seed", type=int, default=28, help="seed of the draws (default 28)")
    ap.add_argument("--positions", type=int, default=32, help="mesh positions per base pitch (default 32)")
    ap.add_argument("--no-exact", action="store_true",
                    help="skip the full load-distribution check of the median draws (about 2 x 25 s)")
    ap.add_argument("--rigid-only", action="store_true",
                    help="skip the coupled gearbox (housing mesh, basis, reduction: 10-60 s)")
    ap.add_argument("--out", type=Path, default=HERE, help="folder for as_made.csv and as_made.png (default: here)")
    a = ap.parse_args()
    main(a.draws, a.seed, a.positions, not a.no_exact, a.out, not a.rigid_only)
