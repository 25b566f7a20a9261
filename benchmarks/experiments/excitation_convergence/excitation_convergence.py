"""Is the plateau of set A's quasi-static excitation at n = 5-10 physics or discretisation? (issue 28)

The quasi-static excitation k_m (d - mean d), d = (F - F_e)/S(t) (`housingfe source-spectrum`, the check
28.excitation.envelope.*), and the engagement shock F_e and the stiffness S per tooth harmonic n = 1..15, of gear
sets A and uncorrected at 2000 N m, against every resolution parameter one at a time from the scene default:

  mesh_slices   MeshModel.n_slices, points per contact line (stiffness curve and load share)   24 / 48 / 96 / 192
  positions     stiffness_curve n_positions (and the load share's positions)                     32 / 64 / 128
  dyn_slices    engagement_force_face_width n_slices (face-width slices of F_e)                 256 / 1024 / 4096
  samples       samples per mesh period of S(t) (linear interpolation) and F_e                  256 / 1024

each with the face-width shock's contact edges at the slice midpoints (edges "midpoint", before) and cut exactly
(edges "exact", `exact_edges=True`, the default since this experiment).  The reference: every parameter at its
finest (192 / 128 / 4096 / 1024, exact edges); "reference-1" (96 / 64 / 1024 / 512) says how converged it is.

    PYTHONPATH=. OPENBLAS_NUM_THREADS=1 /work/main/.venv/bin/python \
        benchmarks/experiments/excitation_convergence/excitation_convergence.py [--out DIR]

Writes excitation_convergence.csv (one row per case, edges, configuration and n), excitation_convergence.png and
prints the tables of the README.
"""
import argparse
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from housingfe.outputs import write_csv
from housingfe.source.cli import load_scene
from housingfe.source.roosmalen import dynamics as dyn
from housingfe.source.roosmalen import run as rs
from housingfe.source.roosmalen.studies import envelope_decay
from housingfe.source.stiffness import face_load_share, normal_force_from_torque, stiffness_curve

HERE = Path(__file__).parent
TORQUE = 2000.0
HARMONICS = 15
CASES = ("gearset-A", "gearset-uncorrected")
DEFAULT = {"mesh_slices": 24, "positions": 32, "dyn_slices": 256, "samples": 256}
LEVELS = {"mesh_slices": (48, 96, 192), "positions": (64, 128), "dyn_slices": (1024, 4096), "samples": (1024,)}
REFERENCE = {"mesh_slices": 192, "positions": 128, "dyn_slices": 4096, "samples": 1024}
REFERENCE_1 = {"mesh_slices": 96, "positions": 64, "dyn_slices": 1024, "samples": 512}


def amplitudes(x: np.ndarray) -> np.ndarray:
    """One-sided amplitudes of harmonics 1..HARMONICS of one uniformly sampled period."""
    return 2 * np.abs(np.fft.rfft(x)[1:HARMONICS + 1]) / x.size


class Case:
    """One scene's gear pair, corrections and mesh model, with the stiffness curves and load shares cached per
    (mesh_slices, positions): they do not depend on the face-width shock's parameters."""

    def __init__(self, name: str):
        scene, path = load_scene(name)
        table = rs.parse(scene, str(path))
        self.name = name
        self.pair, self.corr, _, _, self.model = rs.build(table, str(path))
        self.force = normal_force_from_torque(self.pair, TORQUE)
        self._mesh = {}

    def mesh(self, mesh_slices: int, positions: int):
        key = (mesh_slices, positions)
        if key not in self._mesh:
            model = replace(self.model, n_slices=mesh_slices)
            t0 = time.perf_counter()
            curve = stiffness_curve(model, self.force, positions)
            t1 = time.perf_counter()
            share = face_load_share(model, self.force, n_positions=positions)    # as OperatingPoint does
            t2 = time.perf_counter()
            self._mesh[key] = (curve, share, t1 - t0, t2 - t1)
        return self._mesh[key]

    def edge_residual(self) -> np.ndarray:
        """2 F |sin(pi n eps_alpha)| |sinc(n eps_beta)| / (pi n eps_alpha) [N]: the quasi-static excitation of the
        face-width model for uncorrected flanks, a uniform load across the face and a constant S (continuous
        slices; tests/source/roosmalen/test_dynamics.py): the helix's residual of the entry and exit steps."""
        n = np.arange(1, HARMONICS + 1)
        ea, eb = self.pair.transverse_contact_ratio, self.pair.overlap_ratio
        return 2 * self.force * np.abs(np.sin(np.pi * n * ea)) * np.abs(np.sinc(n * eb)) / (np.pi * n * ea)

    def spectrum(self, mesh_slices, positions, dyn_slices, samples, exact_edges=True) -> dict:
        curve, share, t_curve, t_share = self.mesh(mesh_slices, positions)
        S = np.interp(np.arange(samples) / samples, curve.position, curve.stiffness, period=1.0)   # as OperatingPoint
        t0 = time.perf_counter()
        shock = dyn.engagement_force_face_width(self.pair, self.corr, S, self.force, load_share=share,
                                                n_slices=dyn_slices, exact_edges=exact_edges)
        t_shock = time.perf_counter() - t0
        excitation = curve.mean * dyn.quasi_static_compression(S, shock, self.force)
        excitation -= excitation.mean()
        return {"excitation": amplitudes(excitation), "shock": amplitudes(shock), "edge_residual": self.edge_residual(),
                "stiffness_rel": amplitudes(curve.stiffness) / curve.mean if positions > 2 * HARMONICS
                else np.full(HARMONICS, np.nan),
                "t_curve": t_curve, "t_share": t_share, "t_shock": t_shock, "k_m": curve.mean}


def configurations():
    """(label, parameter, value, settings) one parameter at a time from the default, then the two references."""
    yield "default", "default", "", dict(DEFAULT)
    for param, values in LEVELS.items():
        for v in values:
            yield f"{param}={v}", param, v, {**DEFAULT, param: v}
    yield "reference-1", "reference-1", "", dict(REFERENCE_1)
    yield "reference", "reference", "", dict(REFERENCE)


def run() -> list[dict]:
    rows = []
    for name in CASES:
        case = Case(name)
        for edges in ("midpoint", "exact"):
            for label, param, value, cfg in configurations():
                if edges == "midpoint" and label.startswith("reference"):
                    continue
                r = case.spectrum(**cfg, exact_edges=(edges == "exact"))
                check = envelope_decay(r["excitation"])
                rows.append({"case": name, "edges": edges, "label": label, "parameter": param, "value": value, **cfg,
                             **r, "min_octave_drop_dB": check["min_octave_drop_dB"],
                             "worst_octave": f"{check['worst_octave'][0]}-{check['worst_octave'][1]}",
                             "envelope_passed": check["passed"]})
                print(f"{name:20s} {edges:8s} {label:18s} t_curve {r['t_curve']:5.2f} s t_share {r['t_share']:5.2f} s "
                      f"t_shock {r['t_shock']:5.2f} s  X: " + " ".join(f"{x:5.1f}" for x in r["excitation"])
                      + f"  drop {check['min_octave_drop_dB']:.1f} dB")
    return rows


def reference_of(rows, case):
    return next(r for r in rows if r["case"] == case and r["label"] == "reference")


def write(rows: list[dict], out: Path) -> None:
    header = ["case", "edges", "label", "mesh_slices", "positions", "dyn_slices", "samples", "n", "excitation_N",
              "excitation_reference_N", "excitation_error_N", "shock_N", "shock_reference_N", "stiffness_rel",
              "stiffness_rel_reference", "t_curve_s", "t_share_s", "t_shock_s", "min_octave_drop_dB", "worst_octave",
              "envelope_passed"]
    table = []
    for r in rows:
        ref = reference_of(rows, r["case"])
        for i in range(HARMONICS):
            table.append([r["case"], r["edges"], r["label"], r["mesh_slices"], r["positions"], r["dyn_slices"],
                          r["samples"], i + 1, r["excitation"][i], ref["excitation"][i],
                          r["excitation"][i] - ref["excitation"][i], r["shock"][i], ref["shock"][i],
                          r["stiffness_rel"][i], ref["stiffness_rel"][i], r["t_curve"], r["t_share"], r["t_shock"],
                          r["min_octave_drop_dB"], r["worst_octave"], r["envelope_passed"]])
    write_csv(out / "excitation_convergence.csv", header, table)


def markdown(rows: list[dict]) -> str:
    """The README's tables: per case, the harmonics of the default (both edges), the reference and reference-1, and
    per configuration the largest error over n = 4-12 against the reference with the cost."""
    out = []
    for case in CASES:
        sel = {(r["edges"], r["label"]): r for r in rows if r["case"] == case}
        ref = sel[("exact", "reference")]
        cols = [("midpoint", "default"), ("exact", "default"), ("exact", "reference-1"), ("exact", "reference")]
        for key, what in (("excitation", "quasi-static excitation k_m (d - mean d) [N]"), ("shock", "F_e [N]")):
            out.append(f"\n{case}, {what}:\n")
            out.append("| n | " + " | ".join(f"{lab} ({e})" for e, lab in cols) + " | default before - ref | "
                       "default after - ref |")
            out.append("|" + "---|" * (len(cols) + 3))
            for i in range(HARMONICS):
                vals = [sel[c][key][i] for c in cols]
                out.append(f"| {i + 1} | " + " | ".join(f"{v:.1f}" for v in vals)
                           + f" | {vals[0] - vals[-1]:+.1f} | {vals[1] - vals[-1]:+.1f} |")
            if key == "excitation":
                out.append("| smallest octave drop, dB | " + " | ".join(
                    f"{sel[c]['min_octave_drop_dB']:.1f} (n = {sel[c]['worst_octave']})" for c in cols) + " | | |")
        out.append(f"\n{case}, one parameter at a time: largest |error| of the excitation over n = 4-12 against the "
                   "reference [N], and cost [s]:\n")
        out.append("| configuration | midpoint edges | exact edges | stiffness curve, s | load share, s | F_e, s |")
        out.append("|---|---|---|---|---|---|")
        for label, *_ in configurations():
            if label.startswith("reference"):
                continue
            err = {e: np.max(np.abs(sel[(e, label)]["excitation"][3:12] - ref["excitation"][3:12]))
                   for e in ("midpoint", "exact")}
            r = sel[("exact", label)]
            out.append(f"| {label} | {err['midpoint']:.1f} | {err['exact']:.1f} | {r['t_curve']:.2f} | "
                       f"{r['t_share']:.2f} | {r['t_shock']:.3f} |")
        r1 = sel[("exact", "reference-1")]
        out.append(f"| reference-1 | | {np.max(np.abs(r1['excitation'][3:12] - ref['excitation'][3:12])):.1f} | "
                   f"{r1['t_curve']:.2f} | {r1['t_share']:.2f} | {r1['t_shock']:.3f} |")
        out.append(f"| reference | | 0 | {ref['t_curve']:.2f} | {ref['t_share']:.2f} | {ref['t_shock']:.3f} |")
    return "\n".join(out)


def plot(rows: list[dict], out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = np.arange(1, HARMONICS + 1)
    fig, axes = plt.subplots(2, len(CASES), figsize=(5.5 * len(CASES), 8), squeeze=False)
    for j, case in enumerate(CASES):
        sel = {(r["edges"], r["label"]): r for r in rows if r["case"] == case}
        ref = sel[("exact", "reference")]
        ax = axes[0, j]
        ax.semilogy(n, ref["excitation"], "k-", lw=2, label="reference (192/128/4096/1024, exact)")
        ax.semilogy(n, sel[("midpoint", "default")]["excitation"], "C3s--", ms=4, label="default, midpoint edges (before)")
        ax.semilogy(n, sel[("exact", "default")]["excitation"], "C0o:", ms=4, label="default, exact edges (after)")
        ax.semilogy(n, ref["excitation"][0] / n, "0.6", lw=0.8, label="a_1 / n")
        if case == "gearset-uncorrected":
            ax.semilogy(n, ref["edge_residual"], "C2-", lw=0.8, label="uniform load, constant S (analytic edge residual)")
        ax.set_title(f"{case}, 2000 N m: quasi-static excitation", fontsize=9)
        ax.set_xlabel("tooth harmonic n")
        ax.set_ylabel("k_m (d - mean d) [N]")
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=6)
        ax = axes[1, j]
        for k, (label, *_rest) in enumerate(c for c in configurations() if not c[0].startswith("reference")):
            for edges, marker in (("midpoint", "s"), ("exact", "o")):
                r = sel[(edges, label)]
                cost = r["t_curve"] + r["t_share"] + r["t_shock"]
                err = np.max(np.abs(r["excitation"][3:12] - ref["excitation"][3:12]))
                ax.loglog(cost, max(err, 1e-2), marker, color=f"C{k % 10}", ms=5,
                          mfc="none" if edges == "midpoint" else f"C{k % 10}",
                          label=label if edges == "exact" else None)
        ax.set_title("open: midpoint edges (before), filled: exact edges (after)", fontsize=9)
        ax.set_xlabel("cost: stiffness curve + load share + F_e [s]")
        ax.set_ylabel("max |error| n = 4-12 vs reference [N]")
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=6, ncol=2)
    fig.tight_layout()
    fig.savefig(out / "excitation_convergence.png", dpi=120)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=HERE)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    rows = run()
    write(rows, args.out)
    plot(rows, args.out)
    print(markdown(rows))
    print(f"\n{time.perf_counter() - t0:.0f} s wall")


if __name__ == "__main__":
    main()
