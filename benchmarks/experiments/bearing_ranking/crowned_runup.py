"""Run-up of gear set B with crowned roller bearings: straight vs crowned rollers, one basis.

The setting of runup_factors.py (`test-gearbox-runup --set drivetrain.gear_set=B`, 2000 N m, sigma = 1, a basis for
ball bearings, every variant a Rayleigh-Ritz re-analysis on the same Ritz vectors): per variant and route
L_WA(variant) - L_WA(ball), mean and s.d. over 800-1500 rpm (total and tooth line) and the max L_WA.  Variants:
the self-aligning and tapered-roller configurations with the rollers as the catalogue has them (straight, line
contact), with the ISO/TS 16281 logarithmic crown (roller_profile = "logarithmic"), and the spherical rollers as
Hertz point contacts (model "spherical-point-contact", osculation 0.97).  Each roller bearing's K is recomputed at
the same load, model and held tilt as the configuration's; ball bearings are unchanged.

    PYTHONPATH=. .venv/bin/python benchmarks/experiments/bearing_ranking/crowned_runup.py [--out DIR] [--coarse]
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from runup_factors import ball_reference, gear_set_b_args, metrics  # noqa: E402

TORQUE = 2000.0


class Variant:
    """A Drivetrain whose FE reduction (to_coupling_spec) resolves its bearing matrices with other roller internals:
    `internals` for catalogue.estimated_internals (e.g. roller_profile="logarithmic"), and the spherical roller
    bearings with `spherical_model` at the same loads (tilt held, as configurations.evaluate does); all else
    delegated.  The bearing matrices are computed when to_coupling_spec is called, so the context must be there."""

    def __init__(self, drivetrain, spherical_model: str | None = None, **internals):
        self._dt, self._model, self._internals = drivetrain, spherical_model, internals

    def __getattr__(self, key):
        return getattr(self._dt, key)

    def to_coupling_spec(self, forces=None):
        from housingfe.bearings import bearing_stiffness
        from housingfe.bearings.catalogue import estimated_internals
        from housingfe.bearings.configurations import configurations

        with estimated_internals(**self._internals):
            spec = self._dt.to_coupling_spec(forces)
            if self._model is None:
                return spec
            choices = configurations()[self._dt.bearing_configuration].positions
            loads = self._dt.bearing_loads(forces or self._dt.gear_forces())
            new = []
            for b in spec.bearings:
                choice = choices[b.name]
                if choice.designation and "CC" in choice.designation:        # the spherical roller bearings
                    k = bearing_stiffness(choice.designation, loads[b.name], model=self._model,
                                          fixed_tilt=(0.0, 0.0)).K
                    k[5, :] = k[:, 5] = 0.0
                    b = b.model_copy(update={"stiffness_matrix": k.tolist()})
                new.append(b)
            return spec.model_copy(update={"bearings": new})


def main(argv=None):
    import numpy as np

    from housingfe.runup.chain import runup, with_drivetrain

    args, overrides = gear_set_b_args(__doc__, "/tmp/bearing_ranking_crowned_runup", argv)
    t0 = time.perf_counter()
    spec, ball, config, gm, lines, ref = ball_reference(overrides, ("self_aligning", "tapered_roller"))
    variants = {
        "self_aligning, straight rollers (catalogue)": config["self_aligning"],
        "self_aligning, logarithmic crown (ISO/TS 16281)": Variant(config["self_aligning"],
                                                                   roller_profile="logarithmic"),
        "self_aligning, Hertz point contacts (spherical-point-contact)": Variant(
            config["self_aligning"], spherical_model="spherical-point-contact"),
        "tapered_roller, straight rollers (catalogue)": config["tapered_roller"],
        "tapered_roller, logarithmic crown (ISO/TS 16281)": Variant(config["tapered_roller"],
                                                                    roller_profile="logarithmic"),
    }
    rows = []
    for name, dt in variants.items():
        res = runup(with_drivetrain(gm, dt), None, spec.speeds, [TORQUE], lines=lines)
        diag = {b.label: np.diag(np.array(b.matrices()[0]))[:5].tolist() for b in dt.to_coupling_spec().bearings}
        for route in res.routes:
            rows.append({"variant": name, "route": route, **metrics(res, ref, route), "diagonals": diag})
            r = rows[-1]
            print(f"{name:62s} {route:10s} total {r['mean_total_dB']:+.1f} ({r['sd_total_dB']:.1f})  tooth "
                  f"{r['mean_tooth_dB']:+.1f} ({r['sd_tooth_dB']:.1f})  max {r['max_LwA_dBA']:.1f}", flush=True)
    for route in ref.routes:
        s, a = ref.series(route, "erp", TORQUE, "LwA_dB")
        rows.append({"variant": "ball (reference)", "route": route, "max_LwA_dBA": float(a.max()),
                     "max_at_rpm": float(s[np.argmax(a)])})
        print(f"{'ball (reference)':62s} {route:10s} max {a.max():.1f} at {s[np.argmax(a)]:.0f} rpm")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "crowned_runup.json").write_text(json.dumps(rows, indent=1))
    print(f"{time.perf_counter() - t0:.0f} s; {out}/crowned_runup.json")


if __name__ == "__main__":
    main()
