"""Föller's box approximation of the radiation index (van Roosmalen 1994, Sec. 4.7, Fig. 4.22, App. E).

The housing is idealised as homogeneous plates (count, area S_i, perimeter U_i, thickness h_i, critical
frequency f_c,i).  The radiation index is built from
- an equivalent baffled piston: point P at the mean critical frequency, sigma'_P = 1.13 U_mean f_c,mean / c
  (eq. 4.11, 4.12), and a straight line of 25 dB per *decade* through P, capped at 0 dB;
- an acoustic-cancellation branch from the plate formula (eq. 4.13, 4.14), which only matters when the
  compactness criterion c^2 / (S_mean f_c,mean^2) > 1.31 (eq. 4.15) fails; then the index is the minimum
  of the two curves.

Slope note: Appendix E writes "25 dB/octave", but its own numbers (0 dB at 508 Hz and -15.2 dB at 125 Hz
for the scale model, 366 Hz and -11.7 dB for the test gearbox) follow from 25 dB per decade, as does the
caption of Fig. 4.22.  With 25 dB/octave the scale model would cross 0 dB at 600 Hz and reach -57 dB at
125 Hz.  We implement 25 dB/decade.
"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from housingfe.errors import InputError
from housingfe.radiation.analytic import SPEED_OF_SOUND, plate_critical_frequency
from housingfe.radiation.registry import Radiator, register_radiator

SLOPE_DB_PER_DECADE = 25.0   # Fig. 4.22 caption; reproduces the numbers of Appendix E
PISTON_FACTOR = 1.13         # eq. (4.11)
COMPACTNESS_LIMIT = 1.31     # eq. (4.15)

DATA_FILE = Path(__file__).resolve().parent.parent / "data" / "roosmalen1994.toml"
BUILTIN_TABLES = {"scale-model": "scale_model", "test-gearbox": "test_gearbox"}


@dataclass(frozen=True)
class Plate:
    """One homogeneous plate (or `count` identical plates) of a housing.

    area_m2 and perimeter_m describe one plate; thickness_m is informative when fc_hz is given
    (Appendix E prints both).  Use `Plate.from_material` to get fc_hz from E, rho, nu and h."""

    name: str
    count: int
    area_m2: float
    perimeter_m: float
    thickness_m: float
    fc_hz: float

    def __post_init__(self):
        where = f"plate {self.name!r}"
        if not isinstance(self.count, (int, np.integer)) or self.count < 1:
            raise InputError(f"{where}: count: must be a positive integer, got {self.count!r}")
        for key in ("area_m2", "perimeter_m", "thickness_m", "fc_hz"):
            value = getattr(self, key)
            if not isinstance(value, (int, float, np.floating, np.integer)) or not np.isfinite(value) \
                    or value <= 0:
                raise InputError(f"{where}: {key}: must be a positive number, got {value!r}")

    @classmethod
    def from_material(cls, name: str, count: int, area_m2: float, perimeter_m: float, thickness_m: float,
                      youngs_modulus_pa: float, density_kg_m3: float, poisson_ratio: float,
                      c: float = SPEED_OF_SOUND) -> Plate:
        """A plate whose critical frequency (Hz) follows from its material and thickness (SI units)."""
        fc = float(plate_critical_frequency(thickness_m, youngs_modulus_pa, density_kg_m3, poisson_ratio, c))
        return cls(name, count, area_m2, perimeter_m, thickness_m, fc)


def plate_from_triangles(name: str, vertices, triangles, thickness_m: float, fc_hz: float | None = None,
                         youngs_modulus_pa: float | None = None, density_kg_m3: float | None = None,
                         poisson_ratio: float | None = None, count: int = 1) -> Plate:
    """A `Plate` from the surface triangulation of one plate (e.g. the facets carrying one tag of the housing
    mesh): area = sum of triangle areas (m^2), perimeter = total length of the edges used by exactly one
    triangle (m).  vertices (m, 3) in m, triangles (t, 3) vertex indices (shared vertices must be merged).
    Give fc_hz, or the material (E in Pa, density in kg/m^3, Poisson ratio) to compute it from thickness_m."""
    x = np.asarray(vertices, dtype=float)
    tri = np.asarray(triangles, dtype=np.int64)
    if x.ndim != 2 or x.shape[1] != 3 or tri.ndim != 2 or tri.shape[1] != 3 or tri.size == 0:
        raise InputError(f"plate {name!r}: need vertices (m, 3) and triangles (t, 3)")
    if tri.min() < 0 or tri.max() >= len(x):
        raise InputError(f"plate {name!r}: triangles: vertex index out of range")
    a, b, c = x[tri[:, 0]], x[tri[:, 1]], x[tri[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()
    edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    unique, uses = np.unique(edges, axis=0, return_counts=True)
    boundary = unique[uses == 1]
    perimeter = np.linalg.norm(x[boundary[:, 0]] - x[boundary[:, 1]], axis=1).sum()
    if fc_hz is not None:
        return Plate(name, count, float(area), float(perimeter), thickness_m, fc_hz)
    if None in (youngs_modulus_pa, density_kg_m3, poisson_ratio):
        raise InputError(f"plate {name!r}: fc_hz: give it or the material (E, density, Poisson ratio)")
    return Plate.from_material(name, count, float(area), float(perimeter), thickness_m, youngs_modulus_pa,
                               density_kg_m3, poisson_ratio)


@dataclass(frozen=True)
class FollerResult:
    """The quantities of Appendix E and the radiation index over frequency.

    S_mean (m^2), U_mean (m), fc_mean (Hz), sigma_P (-) = sigma'_P at fc_mean, point_P_dB,
    zero_dB_crossing_hz (where the piston line reaches 0 dB), compactness_lhs = c^2/(S_mean fc_mean^2),
    is_compact (lhs > 1.31).  Arrays over `frequencies_hz`: L_piston_db (capped line), L_plates_db
    (eq. 4.13/4.14, capped at 0 dB) and L_sigma_db (the estimate)."""

    plates: tuple
    c: float
    S_mean: float
    U_mean: float
    fc_mean: float
    sigma_P: float
    point_P_dB: float
    zero_dB_crossing_hz: float
    compactness_lhs: float
    is_compact: bool
    frequencies_hz: np.ndarray = field(repr=False)
    L_piston_db: np.ndarray = field(repr=False)
    L_plates_db: np.ndarray = field(repr=False)
    L_sigma_db: np.ndarray = field(repr=False)
    mean_square_velocities: tuple | None = field(default=None, repr=False)

    def index_db(self, frequency_hz) -> np.ndarray:
        """Estimated radiation index L_sigma in dB at any frequencies (Hz)."""
        return radiation_index_from_plates(self, frequency_hz)


def _counts(plates) -> np.ndarray:
    return np.array([p.count for p in plates], dtype=float)


def mean_area(plates) -> float:
    """Mean plate area S_mean = sum(n S) / sum(n) in m^2 (Appendix E)."""
    n = _counts(plates)
    return float(np.dot(n, [p.area_m2 for p in plates]) / n.sum())


def mean_perimeter(plates) -> float:
    """Mean plate perimeter U_mean = sum(n U) / sum(n) in m (Appendix E)."""
    n = _counts(plates)
    return float(np.dot(n, [p.perimeter_m for p in plates]) / n.sum())


def mean_critical_frequency(plates) -> float:
    """Mean critical frequency f_c,mean = (U_mean / mean(U / f_c^1.5))^(2/3) in Hz (eq. 4.12)."""
    n = _counts(plates)
    u_over_fc = np.dot(n, [p.perimeter_m / p.fc_hz**1.5 for p in plates]) / n.sum()
    return float((mean_perimeter(plates) / u_over_fc) ** (2.0 / 3.0))


def piston_point(U_mean: float, fc_mean: float, c: float = SPEED_OF_SOUND) -> float:
    """sigma'_P at the mean critical frequency, 1.13 U_mean fc_mean / c (eq. 4.11); U in m, fc in Hz."""
    return PISTON_FACTOR * U_mean * fc_mean / c


def piston_line_db(frequency_hz, fc_mean: float, point_P_dB: float) -> np.ndarray:
    """Equivalent-piston index in dB: 25 dB/decade through point P, capped at 0 dB (Fig. 4.22)."""
    f = np.asarray(frequency_hz, dtype=float)
    with np.errstate(divide="ignore"):
        line = point_P_dB + SLOPE_DB_PER_DECADE * np.log10(f / fc_mean)
    return np.minimum(line, 0.0)


def zero_db_crossing(fc_mean: float, point_P_dB: float) -> float:
    """Frequency in Hz where the piston line through P reaches 0 dB."""
    return float(fc_mean * 10.0 ** (-point_P_dB / SLOPE_DB_PER_DECADE))


def plate_sigma(frequency_hz, plate: Plate, c: float = SPEED_OF_SOUND) -> np.ndarray:
    """Radiation efficiency of one plate with acoustic cancellation below its f_c (eq. 4.14),
    sigma = U c / (4 pi^2 S f_c) * ((1 - a^2) ln((1 + a)/(1 - a)) + 2a) / (1 - a^2)^(3/2), a = sqrt(f/f_c);
    capped at 1 (and 1 at and above f_c)."""
    f = np.asarray(frequency_hz, dtype=float)
    alpha = np.sqrt(np.clip(f / plate.fc_hz, 0.0, 1.0 - 1e-12))
    one_minus = 1.0 - alpha**2
    shape = (one_minus * np.log((1.0 + alpha) / (1.0 - alpha)) + 2.0 * alpha) / one_minus**1.5
    sigma = plate.perimeter_m * c / (4.0 * np.pi**2 * plate.area_m2 * plate.fc_hz) * shape
    return np.where(f >= plate.fc_hz, 1.0, np.minimum(sigma, 1.0))


def mean_plate_sigma(frequency_hz, plates, mean_square_velocities=None, c: float = SPEED_OF_SOUND):
    """Mean plate radiation efficiency (eq. 4.13), weighted by n_i S_i <v_i^2>.  Without per-plate
    mean-square velocities (m^2/s^2, one per plate entry) all plates are taken to vibrate equally."""
    if mean_square_velocities is None:
        v2 = np.ones(len(plates))
    else:
        v2 = np.asarray(mean_square_velocities, dtype=float)
        if v2.shape != (len(plates),) or np.any(v2 < 0) or not np.any(v2 > 0):
            raise InputError("mean_square_velocities: need one non-negative value per plate, not all zero")
    weights = _counts(plates) * np.array([p.area_m2 for p in plates]) * v2
    sig = np.array([plate_sigma(frequency_hz, p, c) for p in plates])
    return np.tensordot(weights, sig, axes=1) / weights.sum()


def foller_radiation_index(plates, frequencies_hz, c: float = SPEED_OF_SOUND,
                           mean_square_velocities=None) -> FollerResult:
    """Föller's box estimate of the radiation index (Sec. 4.7) for a list of `Plate`s at
    `frequencies_hz` (Hz); c in m/s.  See the module docstring for the model."""
    plates = tuple(plates)
    if not plates:
        raise InputError("plates: at least one plate is needed")
    if not np.isfinite(c) or c <= 0:
        raise InputError(f"c: must be positive, got {c!r}")
    f = np.asarray(frequencies_hz, dtype=float)
    if np.any(~np.isfinite(f)) or np.any(f <= 0):
        raise InputError("frequencies_hz: must be positive")
    S_mean, U_mean, fc_mean = mean_area(plates), mean_perimeter(plates), mean_critical_frequency(plates)
    sigma_P = piston_point(U_mean, fc_mean, c)
    point_db = 10.0 * np.log10(sigma_P)
    compactness = c**2 / (S_mean * fc_mean**2)
    is_compact = bool(compactness > COMPACTNESS_LIMIT)
    L_piston = piston_line_db(f, fc_mean, point_db)
    L_plates = 10.0 * np.log10(mean_plate_sigma(f, plates, mean_square_velocities, c))
    # Compact housings: no acoustic cancellation, the two straight lines alone (Appendix E).
    L_sigma = L_piston if is_compact else np.minimum(L_piston, L_plates)
    v2 = None if mean_square_velocities is None else tuple(float(v) for v in mean_square_velocities)
    return FollerResult(plates, float(c), S_mean, U_mean, fc_mean, float(sigma_P), float(point_db),
                        zero_db_crossing(fc_mean, point_db), float(compactness), is_compact,
                        f, L_piston, L_plates, L_sigma, v2)


def radiation_index_from_plates(result: FollerResult, frequency_hz) -> np.ndarray:
    """Re-evaluate the estimate of `result` at other frequencies (Hz); returns L_sigma in dB."""
    f = np.asarray(frequency_hz, dtype=float)
    L_piston = piston_line_db(f, result.fc_mean, result.point_P_dB)
    if result.is_compact:
        return L_piston
    plates_sigma = mean_plate_sigma(f, result.plates, result.mean_square_velocities, result.c)
    return np.minimum(L_piston, 10.0 * np.log10(plates_sigma))


# ------------------------------------------------------------------ tables (TOML)
_ROW_KEYS = ("name", "count", "area_m2", "perimeter_m", "thickness_m", "fc_hz")
_TABLE_KEYS = set(_ROW_KEYS) | {"youngs_modulus_pa", "density_kg_m3", "poisson_ratio"}


def _plate_from_row(row, where: str) -> Plate:
    """A Plate from a table row; InputError "<where>: <key>: ..." (the file and row) for any bad value."""
    try:
        return _plate_from_row_unchecked(row, where)
    except InputError as exc:
        message = str(exc)
        raise InputError(message if message.startswith(where) else f"{where}: {message}") from None


def _number(value, where: str, key: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"{where}: {key}: must be a number, got {value!r}")
    return float(value)


def _plate_from_row_unchecked(row, where: str) -> Plate:
    if isinstance(row, list):
        if len(row) != 6:
            raise InputError(f"{where}: a row needs [name, count, area_m2, perimeter_m, thickness_m, fc_hz]")
        keys = ("area_m2", "perimeter_m", "thickness_m", "fc_hz")
        return Plate(str(row[0]), row[1], *[_number(v, where, k) for k, v in zip(keys, row[2:])])
    if not isinstance(row, dict):
        raise InputError(f"{where}: a plate must be a table or a 6-element row")
    unknown = set(row) - _TABLE_KEYS
    if unknown:
        raise InputError(f"{where}: {min(unknown)}: unknown key")
    for key in ("name", "count", "area_m2", "perimeter_m", "thickness_m"):
        if key not in row:
            raise InputError(f"{where}: {key}: missing")
    material = [k for k in ("youngs_modulus_pa", "density_kg_m3", "poisson_ratio") if k in row]
    if "fc_hz" in row:
        if material:
            raise InputError(f"{where}: {material[0]}: give either fc_hz or the material, not both")
        return Plate(str(row["name"]), row["count"], row["area_m2"], row["perimeter_m"], row["thickness_m"],
                     row["fc_hz"])
    if len(material) != 3:
        raise InputError(f"{where}: fc_hz: missing (or give youngs_modulus_pa, density_kg_m3, poisson_ratio)")
    for key in material:
        _number(row[key], where, key)
    return Plate.from_material(str(row["name"]), row["count"], row["area_m2"], row["perimeter_m"],
                               row["thickness_m"], row["youngs_modulus_pa"], row["density_kg_m3"],
                               row["poisson_ratio"])


def plates_from_table(data: dict, source: str = "table") -> list[Plate]:
    """Plates from a parsed TOML table with `plates = [...]` (rows [name, count, S, U, h, fc] as in
    Appendix E, or tables with keys name, count, area_m2, perimeter_m, thickness_m and either fc_hz or
    youngs_modulus_pa, density_kg_m3, poisson_ratio).  Other keys of `data` are ignored by this function."""
    if "plates" not in data:
        raise InputError(f"{source}: plates: missing")
    rows = data["plates"]
    if not isinstance(rows, list) or not rows:
        raise InputError(f"{source}: plates: must be a non-empty list")
    return [_plate_from_row(r, f"{source}: plates[{i}]") for i, r in enumerate(rows)]


def published_appendix_e(name: str) -> dict:
    """The Appendix E table and printed results for `scale_model` or `test_gearbox` (from the shipped
    copy of the thesis' numbers)."""
    with open(DATA_FILE, "rb") as fh:
        radiation = tomllib.load(fh)["radiation"]
    if name not in radiation:
        raise InputError(f"builtin: {name}: unknown (choose {', '.join(BUILTIN_TABLES)})")
    return radiation[name]


_USER_FILE_KEYS = {"plates", "c"}


def load_plate_table(spec: str) -> tuple[list[Plate], float]:
    """Plates and speed of sound (m/s) from `builtin:scale-model`, `builtin:test-gearbox` or a TOML file
    with `plates = [...]` (see `plates_from_table`) and optionally `c = 344.0`."""
    if spec.startswith("builtin:"):
        key = spec.split(":", 1)[1]
        if key not in BUILTIN_TABLES:
            raise InputError(f"{spec}: unknown built-in table (choose {', '.join(BUILTIN_TABLES)})")
        return plates_from_table(published_appendix_e(BUILTIN_TABLES[key]), spec), SPEED_OF_SOUND
    from housingfe.scenefile import load_toml_file

    data = load_toml_file(Path(spec))     # one line for a missing, unreadable, non-UTF-8 or malformed file
    unknown = set(data) - _USER_FILE_KEYS
    if unknown:
        raise InputError(f"{spec}: {min(unknown)}: unknown key")
    c = data.get("c", SPEED_OF_SOUND)
    if not isinstance(c, (int, float)) or not np.isfinite(c) or c <= 0:
        raise InputError(f"{spec}: c: must be a positive number (m/s)")
    return plates_from_table(data, spec), float(c)


# ------------------------------------------------------------------ as a radiation model of a housing
@register_radiator("foller")
class FollerRadiator(Radiator):
    """Föller's box model (Sec. 4.7) on given plates: L_sigma per line from `foller_radiation_index`."""

    def __init__(self, plates):
        self.plates = tuple(plates)

    @classmethod
    def from_spec(cls, spec, housing, material) -> FollerRadiator:
        """The housing's own plates: area and perimeter of each listed surface measured on the mesh (a
        HousingMesh), f_c from the material (E, density, Poisson ratio) and the listed thickness."""
        from housingfe.response.observers import surface_outline

        plates = []
        for i, p in enumerate(spec.plates):
            if p.surface not in housing.facet_groups:
                raise InputError(f"radiation.plates[{i}].surface: no surface {p.surface!r}")
            vertices, triangles = surface_outline(housing, p.surface)
            plates.append(plate_from_triangles(p.surface, vertices, triangles, p.thickness, count=p.count,
                                               youngs_modulus_pa=material.youngs_modulus,
                                               density_kg_m3=material.density,
                                               poisson_ratio=material.poisson_ratio))
        return cls(plates)

    def radiation_index_db(self, response) -> np.ndarray:
        return foller_radiation_index(self.plates, response.frequencies).L_sigma_db

    def facts(self) -> dict:
        """Appendix E quantities of the plates (they do not depend on frequency) and the plates themselves."""
        fr = foller_radiation_index(self.plates, [1.0])
        facts = {k: getattr(fr, k) for k in ("S_mean", "U_mean", "fc_mean", "sigma_P", "point_P_dB",
                                              "zero_dB_crossing_hz", "compactness_lhs", "is_compact")}
        facts["plates"] = [{"surface": p.name, "count": p.count, "area_m2": p.area_m2, "perimeter_m": p.perimeter_m,
                            "thickness_m": p.thickness_m, "fc_hz": p.fc_hz} for p in self.plates]
        return facts
