"""# Your own transmission error as the source: a TE file from a measurement or another code

The chain's excitation is a model of the gears' quasi-static transmission error (TE): the time-varying mesh stiffness
with the engagement shock spread over the face width (docs/source.md).  Where the TE of the real gears is known -- a
loaded TE measured on a rig, or computed by a loaded tooth contact analysis (LTCA) of another code -- it can replace
that model: a CSV per pinion torque and tooth harmonic, read by `housingfe.source.transmission_error.read`, and
`runup.transmission_error = "te.csv"` in a run-up scene.

This example:

1. writes the TE of gear set A's own model at 2000 N m (what `housingfe run` writes as `transmission_error.csv`),
   and a second file as an LTCA might give it: 1.5 um at the tooth frequency and 0.5 um at its 2nd harmonic;
2. reads both back and drives the gear set's source with them (`SourceModel.with_transmission_error`): the model's
   own TE reproduces the model's L_omega, the other TE gives its own;
3. prints the tooth-band L_omega per speed for the three, and the L_omega per um of TE at the tooth frequency -- the
   chain is linear in the TE, so a TE of a um adds 20 lg(a) dB.

Run:  .venv/bin/python examples/your_transmission_error.py [--small] [--out DIR]
(--small: 4 speeds instead of 15; --out DIR writes the files of OUTPUTS.)
"""
# %%
from __future__ import annotations

import argparse
import math
import tempfile
from pathlib import Path

import numpy as np

from housingfe.drivetrain.description import test_gearbox
from housingfe.outputs import atomic_output_dir, format_table, write_csv
from housingfe.source import transmission_error

OUTPUTS = ("model_te.csv", "ltca_te.csv", "l_omega.csv")
TORQUE_NM = 2000.0
LTCA_TE = "torque_Nm,harmonic,amplitude_um,phase_deg\n2000,1,1.5,0\n2000,2,0.5,90\n"   # an LTCA's output, say

# %% [markdown]
# ## The file: one row per torque and tooth harmonic
#
# `amplitude_um` is the one-sided amplitude of harmonic n of the TE along the flank normal (or `amplitude_mm`,
# `amplitude_m`), `phase_deg` its phase (optional); between the file's torques the amplitudes are interpolated,
# outside them nothing is extrapolated.  Below the mesh mode only the amplitudes matter.


# %%
def levels(source, speeds_rpm) -> list[float]:
    """Tooth-band L_omega (dB re 5e-8 rad/s) of a source at each speed (rev/min), TORQUE_NM."""
    return [source.operating_point(float(rpm), TORQUE_NM).L_omega_tooth_band for rpm in speeds_rpm]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0].lstrip("# "))
    parser.add_argument("--small", action="store_true", help="4 speeds instead of 15")
    parser.add_argument("--out", default=None, help="folder for the files of OUTPUTS")
    args = parser.parse_args(argv)
    speeds = np.array([250.0, 500.0, 1000.0, 1500.0]) if args.small else np.linspace(100.0, 1500.0, 15)

    model = test_gearbox("A", torque=TORQUE_NM).source_model()
    harmonics = range(1, model.harmonics + 1)
    own = model.quasi_static_transmission_error(TORQUE_NM, model.harmonics)      # complex amplitudes, m
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        transmission_error.write(tmp / OUTPUTS[0], [TORQUE_NM], harmonics, [own], comment="gear set A's model")
        (tmp / OUTPUTS[1]).write_text(LTCA_TE)
        model_te, ltca_te = transmission_error.read(tmp / OUTPUTS[0]), transmission_error.read(tmp / OUTPUTS[1])
        files = {name: (tmp / name).read_text() for name in OUTPUTS[:2]}

    print(f"gear set A at {TORQUE_NM:g} N m: the model's TE at n = 1, 2, 3: "
          + ", ".join(f"{abs(a) * 1e6:.3f}" for a in own[:3]) + " um")
    unit = transmission_error.TransmissionError(np.array([TORQUE_NM]), np.array([1]), np.array([[1e-6 + 0j]]),
                                                source="1 um at the tooth frequency")
    curves = {"model": levels(model, speeds),
              "model's TE from the file": levels(model.with_transmission_error(model_te), speeds),
              "LTCA TE (1.5 / 0.5 um)": levels(model.with_transmission_error(ltca_te), speeds),
              "per 1 um at n = 1": levels(model.with_transmission_error(unit), speeds)}
    rows = [[float(s), *(curves[k][i] for k in curves)] for i, s in enumerate(speeds)]
    header = ["speed_rpm", "model_dB", "model_te_file_dB", "ltca_te_dB", "per_um_dB"]
    print("tooth-band L_omega of the wheel, dB re 5e-8 rad/s:")
    print(format_table(header, rows, floatfmt="{:.2f}"))
    worst = max(abs(r[1] - r[2]) for r in rows)
    print(f"the model's own TE through the file reproduces the model within {worst:.1e} dB")
    shift = 20 * math.log10(abs(own[0]) / 1e-6)
    print(f"linearity: the model's tooth line = per-um level {shift:+.1f} dB (its {abs(own[0]) * 1e6:.2f} um at n = 1) "
          "where the tooth line carries the band")

    if args.out:
        with atomic_output_dir(args.out) as out:
            for name, text in files.items():
                (out / name).write_text(text)
            write_csv(out / OUTPUTS[2], header, rows)
        for name in OUTPUTS:
            print(f"wrote {args.out}/{name}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
