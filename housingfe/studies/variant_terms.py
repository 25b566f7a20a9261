"""Which term of the chain makes a design variant's difference to its family's reference (issue 28, bearings).

The run-up splits L_WA per speed into terms (housingfe.runup.slopes, basis "total": power-weighted, telescoping):

    L_WA = excitation + T_path + T_housing + L_S + L_sigma + A_weighting

with T_path = L_bore - excitation (the mesh, shafts, gear bodies and bearings: excitation -> forces on the bores)
and T_housing = L_v - L_bore (the housing: bore forces -> surface velocity).  A mean of differences is linear, so
the mean over 800-1500 rev/min (MEAN_RANGE_RPM, the speeds of the study's mean_diff_dB) of each term's difference
variant - reference adds up to the mean difference of L_WA.  The residual (sum of the terms' mean differences -
mean_diff_dB, the latter from the run-up's totals) is round-off when the terms and the curve are the same speeds
and the same totals; it is reported, not assumed.

Only the periodic lines are decomposed: with runup.as_made on, the as-made L_WA (sidebands added) is compared in
the study's other tables, not split here.
"""
from __future__ import annotations

import numpy as np

from housingfe.runup.slopes import decompose
from housingfe.studies.chain_session import MEAN_RANGE_RPM, difference_stats

# the terms whose mean differences add up to the mean difference of L_WA (L_S: the same area for every variant)
DELTA_TERMS = ("excitation", "transfer_path", "transfer_housing", "L_S", "L_sigma", "A_weighting")
KEPT = (*DELTA_TERMS, "transfer", "L_bore", "L_v", "L_WA")        # kept per variant and route (VariantRun.terms)
# candidates for the term that makes a difference (L_S is constant; the transfer stands in for its split where the
# run-up holds no bore loads)
MAKERS = ("excitation", "transfer_path", "transfer_housing", "L_sigma", "A_weighting")
TERM_NAMES = {"excitation": "excitation (source)", "transfer_path": "T_path (shafts, bearings -> bores)",
              "transfer_housing": "T_housing (bore loads -> surface)", "transfer": "transfer",
              "L_S": "L_S", "L_sigma": "L_sigma", "A_weighting": "A-weighting"}
COLUMNS = ("family", "route", "radiation", "variant", "reference", "speeds_in_mean", "mean_diff_dB",
           *(f"d_{t}_dB" for t in DELTA_TERMS), "d_transfer_dB", "residual_dB", "largest_term", "measured_mean_dB")


def term_curves(result, route: str, radiation: str, torque: float) -> tuple[np.ndarray, dict] | None:
    """(speeds rev/min, {term: level dB per speed}) of one run-up curve (housingfe.runup.chain.RunupResult) on the
    total basis, only the levels KEPT (a few arrays of the run-up's length); None for a route without an
    excitation level."""
    if result.routes[route].excitation_db is None:
        return None
    d = decompose(result, route, radiation, torque, "total")
    return d.speeds_rpm, {k: np.asarray(v, float) for k, v in d.levels.items() if k in KEPT}


def decompose_difference(speeds, terms: dict, ref_speeds, ref_terms: dict, lwa_curve=None, ref_lwa=None) -> dict:
    """The mean difference variant - reference over MEAN_RANGE_RPM of L_WA and of each term (dB).  speeds, terms:
    the variant's term_curves; ref_*: the reference's; lwa_curve / ref_lwa: the L_WA curves (speeds, dB(A)) the
    study's mean_diff_dB is taken from (default the terms' own L_WA).  The speeds must be the same.  Returns
    {"mean_diff_dB", "speeds_in_mean", "d_<term>_dB" per DELTA_TERMS and transfer, "residual_dB", "largest_term"};
    without bore loads T_path and T_housing are NaN and the transfer is summed instead."""
    speeds, ref_speeds = np.asarray(speeds, float), np.asarray(ref_speeds, float)
    if not np.array_equal(speeds, ref_speeds):
        raise ValueError("variant terms: the variant's speeds are not the reference's")
    if lwa_curve is None:
        lwa_curve, ref_lwa = (speeds, terms["L_WA"]), (ref_speeds, ref_terms["L_WA"])
    for s, _ in (lwa_curve, ref_lwa):
        if not np.array_equal(np.asarray(s, float), speeds):
            raise ValueError("variant terms: the L_WA curve's speeds are not the terms' speeds")
    mean, _, n = difference_stats(speeds, lwa_curve[1], ref_lwa[1])
    out = {"mean_diff_dB": mean, "speeds_in_mean": n}
    for t in (*DELTA_TERMS, "transfer"):
        out[f"d_{t}_dB"] = (difference_stats(speeds, terms[t], ref_terms[t])[0] if t in terms and t in ref_terms
                            else float("nan"))
    split = np.isfinite(out["d_transfer_path_dB"]) and np.isfinite(out["d_transfer_housing_dB"])
    summed = [t for t in DELTA_TERMS if split or t not in ("transfer_path", "transfer_housing")]
    total = sum(out[f"d_{t}_dB"] for t in summed) + (0.0 if split else out["d_transfer_dB"])
    out["residual_dB"] = float(total - mean)
    makers = [t for t in MAKERS if np.isfinite(out[f"d_{t}_dB"])] + ([] if split else ["transfer"])
    makers = [t for t in makers if out[f"d_{t}_dB"] != 0.0]          # the reference against itself: none
    out["largest_term"] = max(makers, key=lambda t: abs(out[f"d_{t}_dB"])) if makers else ""
    return out


def variant_terms(result) -> list[dict]:
    """One row per route and variant (COLUMNS) of a study (housingfe.studies.design_variants.StudyResult whose runs
    hold `terms`): the mean difference to the reference over 800-1500 rev/min of L_WA (the periodic curves, as
    mean_diff_dB) and of each term; routes without terms are left out."""
    fam = result.family
    ref = result.runs[fam.reference]
    rows = []
    for route in result.routes:
        if ref.terms.get(route) is None:
            continue
        rs, rt = ref.terms[route]
        for key, run in result.runs.items():
            s, t = run.terms[route]
            d = decompose_difference(s, t, rs, rt, run.curves[route], ref.curves[route])
            rows.append({"family": fam.name, "route": route, "radiation": result.radiation, "variant": key,
                         "reference": fam.reference, **d, "measured_mean_dB": run.variant.measured_mean})
    return rows


def csv_cells(row: dict) -> list:
    """A row's cells in COLUMNS order, levels rounded to 1e-3 dB, the residual as computed."""
    return [round(row[c], 3) if c.startswith("d_") or c == "mean_diff_dB" else row[c] for c in COLUMNS]


def _cell(x: float) -> str:
    return "-" if not np.isfinite(x) else f"{round(x, 2) + 0.0:+.2f}"        # + 0.0: no "-0.00"


def markdown(rows: list[dict]) -> list[str]:
    """The Markdown section: per route and variant the terms' mean differences and the term that makes it."""
    lo, hi = MEAN_RANGE_RPM
    out = ["## Which term makes the difference (periodic lines, total basis)", "",
           f"Mean over {lo:g}–{hi:g} rpm of each term's difference to the reference (dB; they add up to Δ L_WA, the "
           "residual is the check). T_path = L_bore − excitation (shafts, gear bodies, bearings: excitation → "
           "forces on the bores), T_housing = L_v − L_bore (bore loads → surface velocity); docs/runup.md. "
           "Largest: the term of largest |Δ|. Gears as made are not decomposed.", "",
           "| route | variant | Δ L_WA | Δ excitation | Δ T_path | Δ T_housing | Δ L_sigma | Δ A-weighting "
           "| residual | largest | measured |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["variant"] == r["reference"]:
            continue
        m = r["measured_mean_dB"]
        out.append(f"| {r['route']} | {r['variant']} | {_cell(r['mean_diff_dB'])} | {_cell(r['d_excitation_dB'])} | "
                   f"{_cell(r['d_transfer_path_dB'])} | {_cell(r['d_transfer_housing_dB'])} | "
                   f"{_cell(r['d_L_sigma_dB'])} | {_cell(r['d_A_weighting_dB'])} | {r['residual_dB']:.1e} | "
                   f"{TERM_NAMES[r['largest_term']] if r['largest_term'] else '-'} | "
                   f"{'-' if m is None else f'{m:+.1f}'} |")
    return out + [""]


def summary_lines(rows: list[dict]) -> list[str]:
    """The console lines: per route and variant the terms of the difference and the largest."""
    out = []
    for r in rows:
        if r["variant"] == r["reference"]:
            continue
        out.append(f"terms {r['route']}, {r['variant']}: Δ L_WA {r['mean_diff_dB']:+.2f} = exc "
                   f"{_cell(r['d_excitation_dB'])} + T_path {_cell(r['d_transfer_path_dB'])} + T_housing "
                   f"{_cell(r['d_transfer_housing_dB'])} + L_sigma {_cell(r['d_L_sigma_dB'])} + A "
                   f"{_cell(r['d_A_weighting_dB'])} (residual {r['residual_dB']:.1e}); largest {r['largest_term']}")
    return out
