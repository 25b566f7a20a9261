"""The double-helical torque law split into the source's terms, per tooth harmonic n = 1..4, against the mesh
model's own loaded static transmission error (the independent reference), with gear set A as the control.

The chain's excitation at a torque T (pinion, N m), from the lumped source (housingfe.source.roosmalen) with the
run-up's defaults (engagement "face-width", misalignment "rigid-bores"):

    S(t)        the tangent mesh stiffness dF/d(delta) of the load distribution (eq. 2.55): |S_n| / S_0
    F / S       the stiffness-only transmission error (F_e = 0), um
    F_e         the engagement shock (face-width Eq. 2.62), N
    d_qs        (F - F_e) / S, the chain's quasi-static mesh compression: what the harmonic balance gives at zero
                speed; k_m |d_qs,n| is the "TE excitation" the mesh_force route applies at low speed, N
    M_n         the shuttling moment (runup.chain.shuttle_moments, one-sided), N m
and beside it
    delta(t)    the mean approach of the SAME load distribution (StiffnessCurve.deflection): the loaded static
                transmission error with the reliefs as flank gaps inside the contact problem (the quantity of a
                Harris map), um; k_m |delta_n| its excitation, N
    TE_slices   an independent reference written here (none of the package's stiffness or shock code): thin
                face-width slices of uniform stiffness k_m / (eps_alpha n) on the contact lines, s = (t + k) p_bt +
                o tan(beta_b) over the path of contact, the tip reliefs as linear gaps (pinion from E, wheel from A),
                the exact contact problem F = sum k (delta - e)+ solved for delta(t) by bisection: the loaded static
                TE of the textbook (Harris) model, um
    eps_load    the loaded transverse contact ratio: the axial extent of the loaded contact lines / (b helices),
                mean over one mesh period (eps_alpha when every point of the path carries load)
    loss        the fraction of the face with less than 0.1 % of the mean load (contact_loss_fraction)
    share       min / max of the load share across the face (face_load_share, mean 1): the load distribution
                along the contact lines
    helix       load share of helix 0 (double helical: 0.5 when the helices share equally)
    lead gap    the misalignment under load the chain uses (um per m of face)

For a linear mesh every excitation grows 20 lg 2 = +6.02 dB per doubling of the load.

    PYTHONPATH=. .venv/bin/python benchmarks/experiments/torque_law/decompose.py [--out DIR]
        [--runup LABEL=FOLDER ...]

--runup reads run-up result folders (runup_harmonics.csv at 1000 and 2000 N m, e.g. from loaded_te_runup.py or
`housingfe run test-gearbox-runup-double-helical`) and splits their L_WA by harmonic: the energy mean over
800-1500 rev/min of each harmonic's L_WA line and its step 1000 -> 2000 N m (which harmonic carries the law).

Writes decompose.csv (every quantity, set, torque, harmonic), decompose_law.csv (1000 -> 2000 N m in dB) and
decompose.png; prints both tables.  Under a minute on one core.  Nothing in the package is changed or tuned.
"""
from __future__ import annotations

import argparse
import csv
import math
import time
from pathlib import Path

import numpy as np

HARMONICS = (1, 2, 3, 4, 5, 6, 7, 8)
LINEAR_DB = 20 * math.log10(2.0)
SETS = {  # label: (gear set, bearings, torques N m, corrections replaced by none?)
    "double_helical": ("double_helical", "cylindrical_roller", (500.0, 750.0, 1000.0, 1250.0, 1500.0, 1750.0,
                                                               2000.0, 2500.0), False),
    "double_helical_unrelieved": ("double_helical", "cylindrical_roller", (500.0, 1000.0, 1500.0, 2000.0), True),
    "A": ("A", "ball", (500.0, 1000.0, 1500.0, 2000.0), False),
}
PER_HARMONIC = ("S_ratio", "TE_stiffness_um", "shock_N", "TE_chain_um", "exc_chain_N", "LSTE_um", "exc_LSTE_N",
                "TE_slices_um", "shuttle_Nm")
SCALARS = ("F_N", "k_m_N_per_m", "mean_delta_um", "eps_load", "eps_alpha", "loss", "helix0_share", "share_min",
           "share_max", "lead_gap_um_per_m")


def amplitudes(samples) -> np.ndarray:
    """One-sided amplitudes |2 X_n| of a periodic signal sampled uniformly, n = 0.. (n = 0: the mean)."""
    x = np.fft.rfft(np.asarray(samples, float)) / len(samples)
    x[1:] *= 2
    return np.abs(x)


def source_of(gear_set: str, bearings: str, unrelieved: bool):
    """The lumped source of the test gearbox with the run-up's misalignment law (rigid bores) and engagement."""
    from housingfe.drivetrain.description import test_gearbox
    from housingfe.drivetrain.misalignment import lead_gap_law
    from housingfe.source.roosmalen.operating import SourceModel
    from housingfe.source.stiffness import Corrections

    dt = test_gearbox(gear_set, bearings, 2000.0)
    src = dt.source_model(misalignment=lead_gap_law(dt, "rigid-bores"))
    if unrelieved:
        from dataclasses import replace
        src = SourceModel(src.pair, Corrections(), src.interior, src.geometry,
                          mesh_model=replace(src.mesh_model, corrections=Corrections()),
                          misalignment=src.misalignment)
    return src


def thin_slice_te(pair, corrections, k_m: float, force: float, n_positions: int = 128,
                  n_slices: int = 200) -> np.ndarray:
    """delta(t) [m] over one mesh period of the independent thin-slice reference (module docstring, TE_slices):
    uniform slices on both helices (they are alike), no plate coupling, Hertz or body compliance."""
    A, E = pair.path_of_contact
    p, b = pair.transverse_base_pitch, pair.contact_width
    tb = math.tan(pair.base_helix_angle)
    o = (np.arange(n_slices) + 0.5) / n_slices * b
    k = k_m / (pair.transverse_contact_ratio * n_slices)
    (c1, c2), (l1, l2) = corrections.tip_relief, corrections.tip_relief_length
    out = np.empty(n_positions)
    for i, t in enumerate(np.arange(n_positions) / n_positions):
        s = A + (t + np.arange(-4, 4))[:, None] * p + o[None, :] * tb
        s = s[(s >= A) & (s < E)]
        e = np.zeros_like(s)
        if c1 > 0:
            e += c1 * np.clip(1 - (E - s) / l1, 0, 1)
        if c2 > 0:
            e += c2 * np.clip(1 - (s - A) / l2, 0, 1)
        lo, hi = 0.0, float(e.max() + 10 * force / k_m)
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if k * np.maximum(mid - e, 0).sum() > force else (mid, hi)
        out[i] = 0.5 * (lo + hi)
    return out


def terms(src, torque: float) -> dict:
    """Every term of the module docstring at one torque: {name: value or (4,) array over HARMONICS}."""
    from housingfe.runup.chain import shuttle_moments
    from housingfe.source.roosmalen import dynamics as dyn
    from housingfe.source.stiffness import contact_loss_fraction

    op = src._point(float(torque))
    F, S, Fe = op.normal_force, op.S, op.shock
    k_m = float(S.mean())
    n = np.array(HARMONICS)
    t = np.arange(S.size) / S.size
    delta = np.interp(t, op.curve.position, op.curve.deflection, period=1.0)
    d_qs = dyn.quasi_static_compression(S, Fe, F)
    model = op.mesh_model
    pbt, b = src.pair.transverse_base_pitch, src.pair.contact_width
    loaded, helix0 = [], []
    for x in op.curve.position:
        pts, forces, _ = model.load_distribution(x * pbt, F)
        loaded.append(pts["width"][forces > 0].sum() / (b * model.helices))
        helix0.append(forces[pts["helix"] == 0].sum() / forces.sum())
    share = op.load_share if op.load_share is not None else np.ones((model.helices, 1))
    return {
        "F_N": F, "k_m_N_per_m": k_m, "mean_delta_um": float(delta.mean() * 1e6),
        "eps_load": float(np.mean(loaded)), "eps_alpha": src.pair.transverse_contact_ratio,
        "loss": contact_loss_fraction(share), "helix0_share": float(np.mean(helix0)),
        "share_min": float(share.min()), "share_max": float(share.max()),
        "lead_gap_um_per_m": op.lead_gap * 1e6,
        "S_ratio": amplitudes(S)[n] / k_m,
        "TE_stiffness_um": amplitudes(F / S)[n] * 1e6,
        "shock_N": amplitudes(Fe)[n],
        "TE_chain_um": amplitudes(d_qs)[n] * 1e6,
        "exc_chain_N": k_m * amplitudes(d_qs)[n],
        "LSTE_um": amplitudes(delta)[n] * 1e6,
        "exc_LSTE_N": k_m * amplitudes(delta)[n],
        "TE_slices_um": amplitudes(thin_slice_te(src.pair, src.corrections, k_m, F))[n] * 1e6,
        "shuttle_Nm": np.abs(shuttle_moments(src, float(torque), n)) * math.sqrt(2.0),
    }


def law_rows(results: dict) -> list[dict]:
    """1000 -> 2000 N m in dB per set, quantity and harmonic (amplitude ratios), and minus the linear +6.02."""
    rows = []
    for label, by_torque in results.items():
        if 1000.0 not in by_torque or 2000.0 not in by_torque:
            continue
        lo, hi = by_torque[1000.0], by_torque[2000.0]
        for name in PER_HARMONIC:
            db = 20 * np.log10(np.asarray(hi[name]) / np.asarray(lo[name]))
            rows.append({"set": label, "quantity": name,
                         **{f"n{k}_dB": round(float(v), 2) for k, v in zip(HARMONICS, db)},
                         **{f"n{k}_excess_dB": round(float(v - LINEAR_DB), 2) for k, v in zip(HARMONICS, db)}})
    return rows


def runup_harmonics(folder: Path, n_max: int = 8) -> list[dict]:
    """Per route and torque (1000, 2000 N m) the energy mean over 800-1500 rev/min of each harmonic's L_WA line
    (first radiator) and of the total, dB(A)."""
    rows = list(csv.DictReader(open(Path(folder) / "runup_harmonics.csv")))
    rad = rows[0]["radiation"]
    out = []
    for route in sorted({r["route"] for r in rows}):
        for torque in ("1000", "2000"):
            sel = [r for r in rows if r["route"] == route and r["radiation"] == rad and r["torque_nm"] == torque
                   and 800.0 <= float(r["speed_rpm"]) <= 1500.0]
            speeds = len({r["speed_rpm"] for r in sel})
            power = {}
            for r in sel:
                power[int(r["harmonic"])] = power.get(int(r["harmonic"]), 0.0) + 10 ** (float(r["LwA_dB"]) / 10)
            row = {"route": route, "torque_nm": float(torque),
                   "total": 10 * math.log10(sum(power.values()) / speeds)}
            row.update({f"n{k}": 10 * math.log10(power[k] / speeds) for k in range(1, n_max + 1) if k in power})
            out.append(row)
    return out


def plot(results: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.4))
    dh = results["double_helical"]
    T = np.array(sorted(dh))
    for ax, k in zip(axes[:2], (0, 4)):   # the tooth harmonic (the thesis measure) and n = 5 (our L_WA)
        for name, style, what in (("exc_chain_N", "o-", "chain: k_m (F - F_e)/S"),
                                  ("exc_LSTE_N", "s-", "loaded static TE of the load distribution, k_m delta"),
                                  ("shock_N", "^:", "face-width shock F_e"),):
            ax.plot(T, [dh[t][name][k] for t in T], style, label=what)
        for name, style, what in (("TE_slices_um", "v--", "independent thin-slice reference, k_m x TE"),):
            ax.plot(T, [dh[t][name][k] * 1e-6 * dh[t]["k_m_N_per_m"] for t in T], style, label=what)
        un = results["double_helical_unrelieved"]
        Tu = np.array(sorted(un))
        ax.plot(Tu, [un[t]["exc_LSTE_N"][k] for t in Tu], "k--", label="loaded static TE, no relief")
        ax.plot(T, dh[1000.0]["exc_chain_N"][k] * T / 1000.0, color="0.6", lw=0.8, label="linear through 1000 N m")
        ax.set_xlabel("pinion torque, N m")
        ax.set_ylabel(f"harmonic n = {k + 1}, N (one-sided)")
        ax.set_yscale("log")
        ax.set_title(f"double helical, n = {k + 1}")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    ax = axes[2]
    ax.plot(T, [dh[t]["S_ratio"][0] * 100 for t in T], "o-", label="|S_1|/S_0, %")
    ax.plot(T, [dh[t]["eps_load"] for t in T], "s-", label="loaded eps_alpha")
    ax.plot(T, [dh[t]["mean_delta_um"] / 10 for t in T], "^-", label="mean approach / 10 um")
    ax.axhline(2.0, color="C3", lw=0.6, ls=":")
    ax.axhline(4.2, color="C3", lw=0.6, ls=":")
    ax.text(T[0], 2.05, "pinion relief 20 um", fontsize=7, color="C3")
    ax.text(T[0], 4.25, "wheel relief 42 um", fontsize=7, color="C3")
    ax.set_xlabel("pinion torque, N m")
    ax.set_title("double helical: what the load changes")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="/tmp/torque-law/decompose")
    ap.add_argument("--runup", nargs="*", default=[], metavar="LABEL=FOLDER")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    results = {}
    for label, (gear_set, bearings, torques, unrelieved) in SETS.items():
        src = source_of(gear_set, bearings, unrelieved)
        results[label] = {t: terms(src, t) for t in torques}
    with open(out / "decompose.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["set", "torque_nm", "quantity", "harmonic", "value"])
        for label, by_torque in results.items():
            for t, d in by_torque.items():
                for name in SCALARS:
                    w.writerow([label, t, name, "", f"{d[name]:.6g}"])
                for name in PER_HARMONIC:
                    for k, v in zip(HARMONICS, d[name]):
                        w.writerow([label, t, name, k, f"{v:.6g}"])
    law = law_rows(results)
    with open(out / "decompose_law.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(law[0]))
        w.writeheader()
        w.writerows(law)
    plot(results, out / "decompose.png")

    for label, by_torque in results.items():
        print(f"\n{label}: per torque (per-harmonic rows: n = " + " / ".join(map(str, HARMONICS)) + ")")
        print("  T N m | F kN  | k_m N/um | delta um | eps_load/eps_alpha | loss | helix0 | share min-max | "
              "lead gap um/m")
        for t, d in by_torque.items():
            print(f"  {t:5.0f} | {d['F_N'] / 1e3:5.1f} | {d['k_m_N_per_m'] / 1e6:8.1f} | {d['mean_delta_um']:8.2f} |"
                  f" {d['eps_load']:.3f}/{d['eps_alpha']:.3f} | {d['loss']:.2f} | {d['helix0_share']:.3f} |"
                  f" {d['share_min']:.2f}-{d['share_max']:.2f} | {d['lead_gap_um_per_m']:+.1f}")
        for name in PER_HARMONIC:
            print(f"  {name:16s}" + "".join(f" {t:5.0f}: " + "/".join(f"{v:.3g}" for v in d[name])
                                          for t, d in by_torque.items()))
    print("\n1000 -> 2000 N m, dB (a linear mesh: +6.02), harmonics n = " + " / ".join(map(str, HARMONICS)))
    for r in law:
        print(f"  {r['set']:26s} {r['quantity']:16s} " + " ".join(f"{r[f'n{k}_dB']:+7.2f}" for k in HARMONICS))
    lwa_rows = []
    for item in args.runup:
        label, folder = item.split("=", 1)
        rows = runup_harmonics(Path(folder))
        print(f"\nrun-up {label}: L_WA energy mean 800-1500 rpm per harmonic, dB(A)")
        keys = [k for k in rows[0] if k.startswith("n")]
        print("  route      T     total " + " ".join(f"{k:>6s}" for k in keys))
        for r in rows:
            lwa_rows.append({"run": label, **r})
            print(f"  {r['route']:10s} {r['torque_nm']:5.0f} {r['total']:6.1f} "
                  + " ".join(f"{r.get(k, float('nan')):6.1f}" for k in keys))
        for route in sorted({r["route"] for r in rows}):
            lo, hi = [r for r in rows if r["route"] == route]
            print(f"  {route:10s} step  {hi['total'] - lo['total']:+5.1f} "
                  + " ".join(f"{hi[k] - lo[k]:+6.1f}" for k in keys))
    if lwa_rows:
        with open(out / "decompose_lwa.csv", "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(dict.fromkeys(k for r in lwa_rows for k in r)))
            w.writeheader()
            w.writerows(lwa_rows)
    print(f"\nwrote {out}/decompose.csv, decompose_law.csv, decompose.png ({time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
