"""Sound power of a housing from its computed forced response (eq. 4.16):
L_W(f) = L_v(f) + 10 lg(S/S0) + L_sigma(f), with L_sigma from ERP, Föller's box model on the housing's
own plates (areas and perimeters measured on the mesh), or the Rayleigh integral plate by plate."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from housingfe.errors import InputError
from housingfe.radiation.foller import Plate, foller_radiation_index, plate_from_triangles
from housingfe.radiation.numerical import baffled_plates_radiated_power
from housingfe.radiation.power import SoundPowerSpectrum, sound_power_spectrum

RADIATION_POINTS = "radiation"


@dataclass
class HousingSoundPower:
    """Per load case: the radiation index per line (dB) and the sound power spectrum."""

    load_case: str
    model: str
    radiation_index_db: np.ndarray
    spectrum: SoundPowerSpectrum
    plates: tuple = ()
    foller: dict | None = None   # Appendix E quantities of the housing's own plates


def housing_plates(model, spec) -> list[Plate]:
    """Föller plates from the mesh: area and perimeter of each listed surface, fc from the material."""
    from housingfe.response.observers import surface_outline

    m = model.material
    plates = []
    for i, p in enumerate(spec.plates):
        if p.surface not in model.housing.facet_groups:
            raise InputError(f"radiation.plates[{i}].surface: no surface {p.surface!r}")
        vertices, triangles = surface_outline(model.housing, p.surface)
        plates.append(plate_from_triangles(p.surface, vertices, triangles, p.thickness, count=p.count,
                                           youngs_modulus_pa=m.youngs_modulus, density_kg_m3=m.density,
                                           poisson_ratio=m.poisson_ratio))
    return plates


def radiation_points(model, spec):
    """Facet points (and one id per plate) of the listed plates, for the numerical model."""
    from housingfe.response.observers import SamplePoints, facet_points

    pts, nrm, w, keys = [], [], [], []
    for i, p in enumerate(spec.plates):
        sp, _ = facet_points(model.housing, p.surface)
        pts.append(sp.points), nrm.append(sp.normals), w.append(sp.weights)
        # a listed surface may fold (a flange top and its rim): each plane part radiates in its own baffle
        keys.append(np.column_stack([np.full(len(sp.weights), i), np.round(sp.normals, 3)]))
    _, ids = np.unique(np.concatenate(keys), axis=0, return_inverse=True)
    return SamplePoints(np.concatenate(pts), np.concatenate(nrm), np.concatenate(w)), ids.ravel()


def sound_power(forced, model, spec, plate_ids=None) -> list[HousingSoundPower]:
    """Sound power of every load case of a ForcedResult (the first solver's responses); spec: the radiation
    spec (housingfe.scene.RadiationSpec); plate_ids: from radiation_points (numerical model)."""
    solver = next(iter(forced.responses))
    area = forced.observer.area
    plates = housing_plates(model, spec) if spec.model == "foller" else []
    out = []
    for resp in forced.responses[solver]:
        f = resp.frequencies
        if spec.model == "erp":
            L_sigma = np.zeros(len(f))
        elif spec.model == "foller":
            fr = foller_radiation_index(plates, f)
            L_sigma = fr.L_sigma_db
        else:
            L_sigma = _rayleigh_index(resp, forced.observer.extra_samples[RADIATION_POINTS], plate_ids)
        spectrum = sound_power_spectrum(f, resp.velocity_level_db, area, L_sigma, f_min=max(f.min(), 10.0),
                                        f_max=f.max())
        facts = None
        if spec.model == "foller":
            facts = {k: getattr(fr, k) for k in ("S_mean", "U_mean", "fc_mean", "sigma_P", "point_P_dB",
                                                  "zero_dB_crossing_hz", "compactness_lhs", "is_compact")}
            facts["plates"] = [{"surface": p.name, "count": p.count, "area_m2": p.area_m2, "perimeter_m": p.perimeter_m,
                                "thickness_m": p.thickness_m, "fc_hz": p.fc_hz} for p in plates]
        out.append(HousingSoundPower(resp.name, spec.model, L_sigma, spectrum, tuple(plates), facts))
    return out


def _rayleigh_index(resp, points, plate_ids) -> np.ndarray:
    disp = resp.extras["point_values"][RADIATION_POINTS]
    out = np.empty(len(resp.frequencies))
    for k, f in enumerate(resp.frequencies):
        v = 1j * 2 * math.pi * f * disp[:, k] * resp.amplitude[k]
        r = baffled_plates_radiated_power(points.points, points.normals, points.weights, v, plate_ids, f,
                                          velocity_is_rms=True)
        out[k] = 10 * np.log10(max(r.sigma, 1e-30))
    return out
