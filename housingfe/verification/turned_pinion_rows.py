"""Rows for `housingfe validate`: the thesis' turned-pinion measurement beside the pitch models (issue 28).

Thesis Sec. 5.6 (Fig. 5.12; housingfe/data/roosmalen1994.toml test_gearbox.turned_pinion_*): set A at 2000 N m, the
pinion re-assembled turned by 8 and 16 teeth against the wheel changed L_W by 0.3 dB mean, 0.8 dB s.d. over speed;
the day-to-day repeatability (Fig. 5.11, repeatability_mean_dB / _sd_dB) is 0.3 / 0.5 dB.  Per pitch model of
gears as made (housingfe.source.as_made.PITCH_MODELS) one row (checks.as_made_row with AS_MADE_REINDEX_WHY:
reported beside the checks, never judged, no tolerance, no band, counted apart):

* 28.as_made.reindex.<independent|runout|none> — ours: the median over the draws of the per-draw s.d. over speed of
  L(turned) - L(0) (housingfe.runup.reindex.turned_pinion: the wheel's L_omega through the rigid-bore receptance,
  the 1/3-octave bands of tooth harmonics 1-8 A-weighted line by line, 30 speeds 50-1500 rpm, both shifts pooled;
  50 draws, seed 56: the rigid rows of benchmarks/experiments/reindex); measured: the 0.8 dB s.d.; why: the median
  mean, how many draws are consistent with the measurement (`consistent`), the s.d.'s p5-p95, the draw count.

No FE and no cache: about 10 s per validate (the contact weights of set A and 150 draws), in the full run and in
`housingfe validate --only runup-checks` alike.
"""
from __future__ import annotations

import numpy as np

from housingfe.verification import checks as ck
from housingfe.verification.published import thesis, thesis_source

SECTION = "test_gearbox"


def consistent(mean_db: np.ndarray, sd_db: np.ndarray, measured: tuple[float, float],
               repeatability: tuple[float, float]) -> np.ndarray:
    """Per draw: is (mean, s.d.) [dB] of L(turned) - L(0) consistent with the measured (mean, s.d.)?  The measured
    s.d. holds the repeatability's (independent of the turn), so sqrt(s.d.^2 + s.d._rep^2) <= s.d._measured; and
    |mean| <= mean_measured + mean_rep (the measured mean plus the repeatability's own: a judgement, stated)."""
    mean_db, sd_db = np.asarray(mean_db, float), np.asarray(sd_db, float)
    return (np.hypot(sd_db, repeatability[1]) <= measured[1]) & (np.abs(mean_db) <= measured[0] + repeatability[0])


def published_rows(draws: int | None = None, seed: int | None = None) -> list[dict]:
    """The rows of the module docstring (draws per pitch model and seed: housingfe.runup.reindex's DRAWS, SEED
    unless given; tests pass fewer draws)."""
    from housingfe.runup import reindex

    draws = reindex.DRAWS if draws is None else draws
    seed = reindex.SEED if seed is None else seed
    kind = "bands 1-8, A"
    results, _ = reindex.turned_pinion(draws, seed, kind=kind)
    ref = thesis()[SECTION]
    measured = (ref["turned_pinion_mean_dB"], ref["turned_pinion_sd_dB"])
    repeatability = (ref["repeatability_mean_dB"], ref["repeatability_sd_dB"])
    teeth = " and ".join(str(t) for t in ref["turned_pinion_teeth"])
    source = thesis_source(SECTION, "Sec. 5.6, Fig. 5.12; turned_pinion_*, repeatability_* (Fig. 5.11)")
    sd_limit = float(np.sqrt(measured[1] ** 2 - repeatability[1] ** 2))
    out = []
    for model, r in results.items():
        ok = consistent(r.mean_db, r.sd_db, measured, repeatability)
        p5, p95 = np.percentile(r.sd_db, [5, 95])
        speeds = f"{r.speeds_rpm.size} speeds {r.speeds_rpm[0]:g}-{r.speeds_rpm[-1]:g} rpm"
        out.append(ck.as_made_row(
            f"{ck.AS_MADE_REINDEX}{model}", f"{reindex.SCENE} (set A, {reindex.TORQUE_NM:g} N m, rigid bores)",
            f"pinion turned by {teeth} teeth against the wheel: median over {r.draws} draws of the s.d. over speed "
            f"of L(turned) - L(0), L_omega in the A-weighted bands of harmonics 1-8 (pitch model {model})",
            round(float(np.median(r.sd_db)), 2), "dB", source, measured=measured[1],
            prefix=ck.AS_MADE_REINDEX_WHY,
            why=f"{int(ok.sum())} of {r.draws} draws consistent (sqrt(s.d.^2 + {repeatability[1]:g}^2) <= "
                f"{measured[1]:g} dB, i.e. s.d. <= {sd_limit:.2f}, and |mean| <= {measured[0] + repeatability[0]:g} "
                f"dB: the measured mean {measured[0]:g} plus the repeatability's {repeatability[0]:g}); mean of "
                f"L(turned) - L(0) median {np.median(r.mean_db):+.2f} dB [p5 {np.percentile(r.mean_db, 5):+.2f}, "
                f"p95 {np.percentile(r.mean_db, 95):+.2f}] (measured {measured[0]:+g}); s.d. p5-p95 {p5:.2f}-{p95:.2f} "
                f"dB; route: the rigid-bore receptance (runup.as_made.te_receptance_rigid_bores), the wheel's L_omega "
                f"over the 1/3-octave bands of tooth harmonics 1-8 A-weighted line by line, {speeds}, shifts "
                f"{teeth} pooled; {r.draws} seeded draws (seed {r.seed}) of ISO 1328-1 grade-{reindex.GRADE} "
                f"deviations of all kinds on both gears, pitch model {model}; L_omega, not the measured L_W "
                "(docs/source.md \"The pinion turned against the wheel\", benchmarks/experiments/reindex)"))
    return out
