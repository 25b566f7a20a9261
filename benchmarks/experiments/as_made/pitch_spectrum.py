"""Which deviations make the as-made sidebands, and how much hangs on the pitch deviations' spectrum shape?
(issue 28): an experiment, nothing tuned, the default chain untouched.

Gear set A at 2000 N m (the built-in drivetrain's lumped source, `test_gearbox("A").source_model()`, aligned mesh;
the run-up's contact weights also carry its rigid-bores misalignment).  The EXPECTED deviation power of the
first-order loaded TE (`housingfe.source.as_made.expected_order_spectrum`, ISO 1328-1 grade 5 on both gears, the
mesh normal factors of `housingfe.runup.as_made.deviation_spectrum`) per group of deviation kinds and per pitch
model (`as_made.PITCH_MODELS`: "independent" per tooth, the default, or "runout", the tooth positions one order-1
sinusoid per gear within F_p / 2; "none" is the flanks alone), summed over the wheel orders inside the 1/3-octave band (housingfe.levels) of each tooth harmonic
n = 1..8 at a speed: the equivalent line sqrt(E sum a_q^2) [um].  The bands of one speed may overlap at high n; each
band is summed on its own here.

    PYTHONPATH=. OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/experiments/as_made/pitch_spectrum.py
"""
import math
import time
from pathlib import Path

import numpy as np

from housingfe import levels
from housingfe.outputs import write_csv
from housingfe.source import as_made as am

TORQUE = 2000.0
SPEEDS = (500.0, 1000.0, 1400.0, 1500.0)
HARMONICS = range(1, 9)
GROUPS = {"pitch": ["pitch"], "flanks": [k for k in am.DEVIATION_KINDS if k != "pitch"],
          "all": list(am.DEVIATION_KINDS)}
HERE = Path(__file__).parent


def band(f: float) -> tuple[float, float]:
    b = levels.third_octave_bands(f / 1.3, f * 1.3)
    i = int(np.flatnonzero((b.lower <= f) & (f < b.upper))[0])
    return float(b.lower[i]), float(b.upper[i])


def main() -> None:
    from housingfe.drivetrain.description import test_gearbox

    t0 = time.perf_counter()
    source = test_gearbox("A").source_model()
    op = source._point(TORQUE)
    pair = source.pair
    z1, z2 = (int(z) for z in pair.teeth)
    weights = am.contact_weights(op.mesh_model, op.normal_force, op.n_positions)
    beta_b = pair.base_helix_angle
    pitch_factor = math.cos(pair.transverse_pressure_angle) * math.cos(beta_b)
    flank_factor = math.cos(beta_b)
    tolerances = [am.iso1328_tolerances(pair.module, pair.pitch_diameter[g], pair.face_width[g], 5) for g in (0, 1)]
    rows = []
    for model in ("independent", "runout"):      # "none" is the "flanks" row
        for group, kinds in GROUPS.items():
            if model == "runout" and group == "flanks":
                continue                       # the flanks do not depend on the pitch model
            stats = [am.deviation_statistics(z, t, kinds, pitch_factor, flank_factor, seed=28 + g, pitch_model=model)
                     for g, (z, t) in enumerate(zip((z1, z2), tolerances))]
            spec = am.expected_order_spectrum(pair, weights, *stats)
            label = "flanks (= all, pitch none)" if group == "flanks" else f"{group}, pitch {model}"
            for speed in SPEEDS:
                f_t = z1 * speed / 60.0
                f = spec.orders * f_t / z2
                row = {"deviations": label, "speed_rpm": speed}
                for n in HARMONICS:
                    lo, hi = band(n * f_t)
                    sel = (f >= lo) & (f < hi) & (spec.orders > 0)
                    row[f"n{n}_um"] = math.sqrt(float(np.sum(spec.deviations[sel]))) * 1e6
                rows.append(row)
    columns = ["deviations", "speed_rpm"] + [f"n{n}_um" for n in HARMONICS]
    write_csv(HERE / "pitch_spectrum.csv", columns, ([f"{r[c]:.4g}" if c != "deviations" else r[c] for c in columns]
                                                     for r in rows))
    print(f"set A, {TORQUE:g} N m, ISO 1328-1 grade 5, expected TE per 1/3-octave band of harmonic n, um "
          f"(sqrt of the band's expected energy); {time.perf_counter() - t0:.1f} s")
    print("| deviations | rpm | " + " | ".join(f"n = {n}" for n in HARMONICS) + " |")
    print("|---|---|" + "---|" * len(HARMONICS))
    for r in rows:
        print(f"| {r['deviations']} | {r['speed_rpm']:g} | " + " | ".join(f"{r[f'n{n}_um']:.3f}" for n in HARMONICS)
              + " |")


if __name__ == "__main__":
    main()
