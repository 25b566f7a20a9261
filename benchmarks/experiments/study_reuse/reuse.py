"""Basis reuse of `housingfe study` against a fresh basis per variant (issue 28 item 4).

    PYTHONPATH=. .venv/bin/python benchmarks/experiments/study_reuse/reuse.py bearings full
    PYTHONPATH=. .venv/bin/python benchmarks/experiments/study_reuse/reuse.py double-helical full
    PYTHONPATH=. .venv/bin/python benchmarks/experiments/study_reuse/reuse.py bearings coarse   # 60 mm mesh, 1.5 kHz

Per variant of the family: the model's wall time re-analysed on the reference's Ritz vectors and with its own basis,
the largest |L_WA difference| over speed per route, and the largest relative difference of the coupled model's
frequencies below f_max.  Extra arguments are --set overrides of the family's scene.
"""
import sys
import time

import numpy as np

from housingfe.studies.chain_session import ChainSession
from housingfe.studies.design_variants import family_of

fam = family_of(sys.argv[1])
coarse = len(sys.argv) > 2 and sys.argv[2] == "coarse"
overrides = (['housing.set=["mesh.size=0.06"]', "runup.f_max_hz=1500", "runup.speed_min_rpm=800",
              "runup.speed_step_rpm=50"] if coarse else []) + sys.argv[3:]
reuse = ChainSession.from_scene(fam.scene, overrides)
fresh = ChainSession.from_scene(fam.scene, overrides, fresh_basis=True)
order = [fam.variant(fam.reference)] + [v for v in fam.variants if v.key != fam.reference]
for v in order:
    out = []
    for session in (reuse, fresh):
        if session is fresh and fresh.housing_model is None:
            fresh.housing_model, fresh.radiators = reuse.housing_model, reuse.radiators
        dt = session.drivetrain(v.gear_set, v.bearings, v.torque)
        t0 = time.perf_counter()
        model = session.model(dt, v.key)
        seconds = time.perf_counter() - t0
        res = session.runup(model, v.torque)
        out.append(({r: res.series(r, session.radiation, v.torque, "LwA_dB")[1] for r in session.spec.routes},
                    seconds, model))
    f_reused, f_fresh = out[0][2].reduction.frequencies_hz, out[1][2].reduction.frequencies_hz
    # the elastic frequencies below f_max of both reduced systems, in order (their sizes may differ: a static vector
    # that the basis already spans is dropped)
    a, b = (f[(f > 1.0) & (f < reuse.spec.f_max_hz)] for f in (f_reused, f_fresh))
    n = min(len(a), len(b))
    rel = np.abs(a[:n] - b[:n]) / b[:n] if len(a) == len(b) else np.array([np.inf])
    print(v.key, f"model re-analysed {out[0][1]:.1f} s, fresh {out[1][1]:.1f} s;",
          " ".join(f"{r}: max|dL_WA| {np.abs(out[0][0][r] - out[1][0][r]).max():.3f} dB" for r in out[0][0]),
          f"; frequencies below f_max: max relative {rel.max():.1e}", flush=True)
