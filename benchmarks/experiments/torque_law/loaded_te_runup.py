"""What-if: the double-helical run-up with the source's quasi-static excitation replaced by the mesh model's own
loaded static transmission error (see decompose.py), nothing else changed.

The chain's mesh force is S(t) d(t) + F_e(t): S the tangent mesh stiffness dF/d(delta) of the load distribution
(eq. 2.55) and F_e the engagement shock (face-width Eq. 2.62), so at zero speed the compression is
d_qs = (F - F_e) / S.  Here F_e is replaced by F - S(t) delta(t), delta(t) the mean approach of the load distribution
at the same positions (StiffnessCurve.deflection: the flank gaps of the reliefs in the contact problem itself):
the tangent linearisation about the loaded static state, whose quasi-static compression IS the loaded static TE.
Patched in the experiment only (OperatingPoint), for both routes (tf_omega's rigid-bore L_omega and the coupled
source of mesh_force).

    PYTHONPATH=. .venv/bin/python benchmarks/experiments/torque_law/loaded_te_runup.py [--bearings cylindrical_roller]
        [--variant loaded-te|unrelieved|baseline] [--out /tmp/torque-law/runs]   (about 35-45 s per run on one core)

--variant unrelieved runs the source without any relief instead (Appendix F: the relief was ground "on only one
tooth flank side of each gear"; which flank carried the load in Fig. 5.21 is not stated), baseline the chain as it
is.  Prints L_WA(2000) - L_WA(1000 N m) per route and the per-harmonic L_WA (decompose.py --runup reads the folder).
"""
from __future__ import annotations

import argparse
import csv
from pathlib import Path

import numpy as np


def patch_loaded_te():
    """Make every new OperatingPoint's shock F - S(t) delta(t) (the loaded static TE as the excitation)."""
    from housingfe.source.roosmalen import run as roosmalen

    original = roosmalen.OperatingPoint.__init__

    def init(self, pair, corr, interior, model, torque, n_positions, n_samples=256, **kw):
        original(self, pair, corr, interior, model, torque, n_positions, n_samples, **kw)
        t = np.arange(n_samples) / n_samples
        delta = np.interp(t, self.curve.position, self.curve.deflection, period=1.0)
        self.shock = self.normal_force - self.S * delta

    roosmalen.OperatingPoint.__init__ = init


def patch_unrelieved():
    """Make every new OperatingPoint's source (stiffness curve, load share, shock) that of the same gears without
    any relief (the source only: the coupled model keeps the relieved mesh's mean stiffness)."""
    from dataclasses import replace

    from housingfe.source.roosmalen import run as roosmalen
    from housingfe.source.stiffness import Corrections

    original = roosmalen.OperatingPoint.__init__

    def init(self, pair, corr, interior, model, torque, n_positions, n_samples=256, **kw):
        original(self, pair, Corrections(), interior, replace(model, corrections=Corrections()), torque,
                 n_positions, n_samples, **kw)

    roosmalen.OperatingPoint.__init__ = init


def torque_law(folder: Path) -> list[dict]:
    """L_WA(2000) - L_WA(1000 N m) per route: mean over 800-1500 rpm speed by speed (the study's measure), at
    1500 rpm, and of the energy means (first radiator)."""
    rows = list(csv.DictReader(open(folder / "runup.csv")))
    rad = rows[0]["radiation"]
    out = []
    for route in sorted({r["route"] for r in rows}):
        lw = {}
        for t in ("1000", "2000"):
            sel = [r for r in rows if r["route"] == route and r["radiation"] == rad and r["torque_nm"] == t]
            lw[t] = {float(r["speed_rpm"]): float(r["LwA_dB"]) for r in sel}
        speeds = [s for s in sorted(lw["1000"]) if 800.0 <= s <= 1500.0]
        step = np.array([lw["2000"][s] - lw["1000"][s] for s in speeds])
        em = {t: 10 * np.log10(np.mean([10 ** (lw[t][s] / 10) for s in speeds])) for t in lw}
        out.append({"route": route, "step_mean_dB": float(step.mean()), "step_sd_dB": float(step.std()),
                    "step_1500rpm_dB": float(lw["2000"][1500.0] - lw["1000"][1500.0]),
                    "energy_mean_step_dB": float(em["2000"] - em["1000"])})
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bearings", default="cylindrical_roller")
    ap.add_argument("--out", default="/tmp/torque-law/runs")
    ap.add_argument("--variant", choices=("loaded-te", "unrelieved", "baseline"), default="loaded-te",
                    help="loaded-te: F_e = F - S delta; unrelieved: the source without reliefs (the flank the "
                         "thesis did not correct); baseline: the chain as it is")
    args = ap.parse_args(argv)
    from housingfe.run import run_scene

    if args.variant == "loaded-te":
        patch_loaded_te()
    elif args.variant == "unrelieved":
        patch_unrelieved()
    out = Path(args.out) / args.variant / args.bearings
    run_scene("test-gearbox-runup-double-helical", str(out),
              ["runup.torques_nm=[1000.0,2000.0]", f"drivetrain.bearings={args.bearings}"])
    for r in torque_law(out):
        print(f"{args.variant} {args.bearings:18s} {r['route']:10s} step mean 800-1500 {r['step_mean_dB']:+.2f} "
              f"(s.d. {r['step_sd_dB']:.2f}), at 1500 rpm {r['step_1500rpm_dB']:+.2f}, energy means "
              f"{r['energy_mean_step_dB']:+.2f} dB(A)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
