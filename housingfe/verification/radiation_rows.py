"""Rows for `housingfe validate`: van Roosmalen (1994) Appendix E (Föller's box model, Sec. 4.7) reproduced.

From the Appendix E plate tables of the scale model and the test gearbox (housingfe/data/roosmalen1994.toml,
[radiation.scale_model] and [radiation.test_gearbox]) housingfe.radiation.foller computes every printed result:
S_mean, U_mean, f_c,mean (eq. 4.12), sigma'_P at f_c,mean (eq. 4.11), the point P, the 0 dB crossing, L_sigma at
125 Hz and the compactness criterion (eq. 4.15); and the plates' critical frequencies from their thickness
(housingfe.radiation.plate_critical_frequency, steel of Sec. 4.2) against the table's f_c column.
The printed numbers were computed by hand with rounded intermediates: see tests/radiation/test_foller.py.
"""
from __future__ import annotations

from housingfe.verification.published import THESIS, row

CASES = {"scale_model": "Appendix E, scale model", "test_gearbox": "Appendix E, test gearbox"}
# FollerResult attribute, published key, quantity, unit
APPENDIX_E_RESULTS = (
    ("S_mean", "S_mean_m2", "mean plate area S_mean", "m2"),
    ("U_mean", "U_mean_m", "mean plate perimeter U_mean", "m"),
    ("fc_mean", "fc_mean_Hz", "mean critical frequency f_c,mean (eq. 4.12)", "Hz"),
    ("sigma_P", "sigma_P_at_fc_mean", "piston radiation efficiency at f_c,mean (eq. 4.11)", "-"),
    ("point_P_dB", "point_P_dB", "point P: 10 log sigma'_P", "dB"),
    ("zero_dB_crossing_hz", "zero_dB_crossing_Hz", "0 dB crossing of the piston line", "Hz"),
    ("compactness_lhs", "compactness_lhs", "compactness c^2/(S_mean f_c,mean^2) (eq. 4.15, compact if > 1.31)", "-"),
)


def published_rows() -> list[dict]:
    """Every printed Appendix E result of both housings, and the table's plate critical frequencies."""
    from housingfe.materials import LIBRARY
    from housingfe.radiation import foller, plate_critical_frequency

    steel = LIBRARY["steel"]
    out = []
    for name, label in CASES.items():
        table = foller.published_appendix_e(name)
        src = f"{THESIS}, {label} [radiation.{name}]"
        res = foller.foller_radiation_index(foller.plates_from_table(table, name), [125.0])
        for attr, key, quantity, unit in APPENDIX_E_RESULTS:
            out.append(row(name, quantity, float(getattr(res, attr)), table[key], unit, src))
        out.append(row(name, "L_sigma at 125 Hz (25 dB/decade below f_c,mean)", float(res.L_sigma_db[0]),
                       table["index_at_125Hz_dB"], "dB", src,
                       note="the printed '25 dB per octave' is read as per decade (only that reproduces Appendix E)"))
        seen = set()
        for plate, _, _, _, h, fc in table["plates"]:
            if h in seen:
                continue
            seen.add(h)
            ours = float(plate_critical_frequency(h, steel.youngs_modulus, steel.density, steel.poisson_ratio))
            out.append(row(name, f"critical frequency of the {h * 1e3:g} mm plates ('{plate}')", ours, fc, "Hz", src,
                           note="steel E = 210 GPa, nu = 0.3, 7850 kg/m3; the thesis uses f_c ~= 12/h"))
    return out
