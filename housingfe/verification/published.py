"""Published numbers (van Roosmalen 1994, NAFEMS) and the rows that put ours next to them."""
from __future__ import annotations

import math

import numpy as np

from housingfe.data import thesis  # noqa: F401  (rows and tests read the thesis through here too)

THESIS = "van Roosmalen 1994"


# where in the thesis each table of roosmalen1994.toml comes from (the TOML's comments, which tomllib drops)
SECTIONS = {"box_free": "Sec. 4.2", "box_supported": "Sec. 4.3", "box_halves": "Sec. 4.4",
            "gearbox_model_empty": "Sec. 4.5", "gearbox_model_interior": "Sec. 4.6", "radiation": "Sec. 4.7, Appendix E",
            "fluid_film_bearings": "Sec. 3.5", "shaft_bearing_rig": "Sec. 3.4", "gears": "Ch. 2, Appendix F",
            "test_gearbox": "Ch. 5", "test_gearbox.bearings": "Sec. 5.8", "test_gearbox.profile_corrections": "Sec. 5.7",
            "test_gearbox.double_helical": "Sec. 5.9"}


def thesis_source(section: str, detail: str = "") -> str:
    """Provenance of a thesis number: 'van Roosmalen 1994, Sec. 4.2[, detail] [box_free]' from the table name."""
    where = SECTIONS.get(section) or SECTIONS.get(section.split(".")[0], "")
    return ", ".join(x for x in (THESIS, where, detail) if x) + f" [{section}]"




def row(scene: str, quantity: str, ours, published, unit: str, source: str, note: str = "") -> dict:
    """One comparison row; `difference` is ours - published (and relative where meaningful).  `ours` is None
    for a published number the package does not reproduce (say why in `note`); `source` names the publication
    and its table/section/equation, `note` any assumption the comparison rests on."""
    out = {"scene": scene, "quantity": quantity, "ours": ours, "published": published, "unit": unit,
           "source": source, "note": note}
    if isinstance(ours, (int, float)) and isinstance(published, (int, float)) and not math.isnan(published) \
            and not math.isnan(ours):
        out["difference"] = ours - published
        if published:
            out["relative_difference"] = (ours - published) / published
    return out


def modal_comparison(scene, summary: dict) -> list[dict]:
    """Rows comparing a modal result with the published data the scene names."""
    ref = scene.reference
    if ref is None:
        return []
    name = scene.scene.name
    freqs = np.asarray(summary["frequencies_hz"])
    rows = []
    if ref.frequencies_hz:
        for i, f_ref in enumerate(ref.frequencies_hz):
            # a published mode above this run's f_max has no counterpart here: no number (null in JSON)
            ours = float(freqs[i]) if i < len(freqs) else None
            rows.append(row(name, f"elastic mode {i + 1}", ours, f_ref, "Hz", ref.source,
                            "" if ours is not None else _above_f_max(len(freqs), summary["f_max_hz"])))
    if ref.section:
        data = thesis()[ref.section]
        src = thesis_source(ref.section)
        if "mass_kg" in data:
            rows.append(row(name, "mass", summary["mass_kg"], data["mass_kg"], "kg", src))
        if "fem_first_elastic_Hz" in data:
            rows.append(row(name, "first elastic mode (thesis FEM)", float(freqs[0]) if len(freqs) else None,
                            data["fem_first_elastic_Hz"], "Hz", src,
                            "" if len(freqs) else _above_f_max(0, summary["f_max_hz"])))
        for key, value in data.items():
            if key.startswith("fem_modes_below_"):
                f_lim = float(key.removeprefix("fem_modes_below_").removesuffix("Hz"))
                if f_lim <= summary["f_max_hz"] * (1 + 1e-9):
                    rows.append(row(name, f"elastic modes below {f_lim:g} Hz (thesis FEM)",
                                    int(np.sum(freqs < f_lim)), value, "-", src))
            if key.startswith("ema_modes_below_"):
                f_lim = float(key.removeprefix("ema_modes_below_").removesuffix("Hz"))
                if f_lim <= summary["f_max_hz"] * (1 + 1e-9):
                    rows.append(row(name, f"elastic modes below {f_lim:g} Hz (thesis EMA found)",
                                    int(np.sum(freqs < f_lim)), value, "-", src))
    return rows


def _above_f_max(found: int, f_max: float) -> str:
    return f"not computed: {found} elastic mode(s) below this run's f_max = {f_max:g} Hz"


def interior_comparison(scene, interior: dict) -> list[dict]:
    """Rows for a housing coupled with its interior (thesis Sec. 4.6): the interior on rigid bores and the
    coupled model, next to the published values of the scene's reference section (when it has them)."""
    ref = scene.reference
    data = thesis().get(ref.section, {}) if ref is not None and ref.section else {}
    if "interior_on_rigid_bores_first_Hz" not in data:
        return []
    name, src = scene.scene.name, thesis_source(ref.section)
    f_rigid = np.asarray(interior["rigid_bores_frequencies_hz"])
    energy = np.asarray(interior["rigid_bores_bearing_energy"])
    nan = float("nan")
    whole = f_rigid[energy > 0.5]
    f_max = scene.analysis.f_max
    rows = [row(name, "interior on rigid bores: first mode", float(f_rigid[0]) if len(f_rigid) else nan,
                data["interior_on_rigid_bores_first_Hz"], "Hz", src),
            row(name, "interior on rigid bores: first mode moving as a whole on the bearings (bearing energy > 50 %)",
                float(whole[0]) if len(whole) else nan, data["interior_on_rigid_bores_whole_body_Hz"], "Hz", src)]
    if f_max >= 4000.0:
        rows.append(row(name, "interior on rigid bores: modes below 4000 Hz", int(np.sum(f_rigid < 4000.0)),
                        data["interior_on_rigid_bores_modes_below_4000Hz"], "-", src))
    coupled = list(interior["coupled_interior_modes_hz"])
    for i, f_pub in enumerate(data.get("coupled_interior_modes_Hz", [])):
        rows.append(row(name, f"coupled: interior-dominated mode {i + 1} (interior kinetic energy > 50 %)",
                        float(coupled[i]) if i < len(coupled) else nan, f_pub, "Hz", src))
    if "coupled_housing_modes_below_4000Hz" in data and f_max >= 4000.0:
        rows.append(row(name, "coupled: housing-dominated modes below 4000 Hz", interior["coupled_housing_modes"],
                        data["coupled_housing_modes_below_4000Hz"], "-", src))
    return rows
