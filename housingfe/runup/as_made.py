"""Gears as made in the run-up (issue 28; scene key runup.as_made; docs/runup.md "Gears as made in the run-up").

The run-up's source computes the periodic lines n f_tooth of an aligned pair whose teeth are all alike.  Real
gears ground to an ISO 1328-1 accuracy grade differ from tooth to tooth; over the hunting period their first-order
loaded TE has lines at every shaft order (housingfe.source.as_made), and a measured 1/3-octave band level holds
those sidebands beside the tooth line.  With runup.as_made = <grade> the run-up adds, at every operating point, the
EXPECTED power of the deviations' lines (`as_made.expected_order_spectrum`: the mean over the random teeth, not one
draw) at the wheel orders inside the 1/3-octave bands of the tooth harmonics n = 1..n_max, each an incoherent line
(energies add) at f = order x f_wheel:

* excitation: first order on the mean-stiffness system, the mesh force k e of the deviations' TE e (k_ref of the
  coupled model's mesh element on the mesh_force route; the rigid-bore source's k_m for its L_omega), valid below
  the mesh mode (docs/source.md "Where the tooth-band L_omega deficit sits": 0.1 dB at the tooth line);
* mesh_force route: that force on the coupled model's gear mesh (the routes' own `mesh_force_route`), WITHOUT the
  shuttling moment's or the friction's share: the deviations move the force's size, their moment arm is not
  modelled;
* tf_omega route: L_omega = the rigid-bore lumped source's wheel velocity per unit TE (its mean system loaded by
  k_m e along the mesh normal) x e, then + TF_omega(f) (`tf_omega_route`).

The expected line power at a tooth-harmonic order (the deviations' tooth-periodic part) is added too: E|D + X|^2 =
|D|^2 + E|X|^2.  Bands: the run-up's harmonics n whose 1/3-octave band (IEC 61260, housingfe.levels) lies below
the Nyquist order of the contact weights' sampling with a factor 2 margin, n <= positions / 4 (32 at the source's default 128
positions per mesh period), and f <= f_max; overlapping bands of neighbouring harmonics count each order once.
Assumptions beside every result: the deviations are uniform within the grade's tolerances as
`as_made.draw_deviations` draws them (pitch, profile slope and form, helix slope, twist), both gears the same grade,
ISO 1328-1:1995 standing in for DIN 3962 (the thesis' "DIN 5" ~ ISO 5).  The pitch deviations' spectrum shape
(runup.as_made_pitch, `as_made.PITCH_MODELS`): "independent" per tooth (default: sidebands at every shaft order, the
upper bound of the high-order sideband energy), "runout" (the tooth positions one order-1 sinusoid per gear within
F_p / 2: sidebands only at tooth orders +- 1 shaft order) or "none" (no pitch deviations: the first-order limit of a
pure eccentricity); the flank deviations stay independent per tooth in all three.

By default runup.csv, runup_harmonics.csv and the checks stay the periodic model's; the sideband lines run
through the routes as a second set of Lines on the SAME models, and runup_as_made.csv holds the tooth band and the
total with and without them.  With runup.as_made_totals = true, `folded_result` makes one RunupResult of both sets
(Lines.incoherent flags the sidebands): its totals, tooth band, spectra, slope terms, peaks and checks then hold the
sideband energy beside the coherent periodic harmonics (energy sums; at a tooth-harmonic order |D|^2 + E|X|^2)."""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from housingfe import levels
from housingfe.errors import InputError
from housingfe.runup.chain import (
    Lines,
    RouteResult,
    RunupResult,
    line_coefficients,
    mesh_reference_stiffness,
    runup,
)

AS_MADE_OFF = "none"
# ISO 1328-1:1995 defines the accuracy grades 0 (finest) to 12
ISO_GRADES = tuple(range(13))
CSV = "runup_as_made.csv"
# the unit load each route solves for (housingfe.runup.chain: tf_omega_route, mesh_force_route without the moment)
ROUTE_LOADS = {"tf_omega": "wheel_torque", "mesh_force": "mesh"}


def check_as_made(value) -> str | int:
    """The runup.as_made setting as the chain takes it ("none" or an ISO grade 0..12), or InputError "as_made: ..."."""
    if value == AS_MADE_OFF:
        return AS_MADE_OFF
    if isinstance(value, int) and not isinstance(value, bool) and value in ISO_GRADES:
        return int(value)
    raise InputError(f"as_made: {value!r} is neither \"none\" nor an ISO 1328-1 accuracy grade (an integer "
                     f"{ISO_GRADES[0]}..{ISO_GRADES[-1]}, e.g. 5 for the thesis' DIN 5)")


def te_receptance_rigid_bores(mats, frequencies_hz) -> np.ndarray:
    """|Omega_wheel / e| [(rad/s)/m] of the rigid-bore lumped source's mean system (K0 + k_m h h^T, M, D: `mats`,
    housingfe.source.roosmalen.dynamics.Matrices) loaded by k_m e along the mesh normal h, at each frequency [Hz]."""
    from housingfe.source.roosmalen.dynamics import WHEEL_THETA_Z

    km, h = mats.mean_mesh_stiffness, mats.h
    K = mats.K0 + km * np.outer(h, h)
    w = 2 * math.pi * np.asarray(frequencies_hz, float)
    A = K[None] - (w**2)[:, None, None] * mats.M[None] + 1j * w[:, None, None] * mats.D[None]
    q = np.linalg.solve(A, np.broadcast_to(km * h, (w.size, h.size))[..., None])[..., 0]
    return np.abs(w * q[:, WHEEL_THETA_Z])


@dataclass
class Spectrum:
    """The expected deviation spectrum of one torque: wheel orders, E a_q^2 [m^2] (one-sided peak amplitudes),
    the harmonics whose bands are added (n_max), the seconds it took."""

    orders: np.ndarray
    power: np.ndarray
    n_max: int
    seconds: float


def deviation_spectrum(source, torque_nm: float, grade: int, *, pitch_samples: int = 20000, seed: int = 28,
                       pitch_model: str = "independent") -> Spectrum:
    """E a_q^2 of the first-order TE of grade-`grade` deviations on both gears of `source` (SourceModel) at a pinion
    torque [N m]: contact weights of the source's mesh model (with its misalignment) at its stiffness positions,
    ISO 1328-1 tolerances per gear (module, reference diameter, face width), deviation_statistics of all kinds,
    expected_order_spectrum; pitch_model: the pitch deviations' spectrum shape (as_made.PITCH_MODELS).  Mesh normal
    factors as the experiment: pitch x cos(alpha_t) cos(beta_b), flanks x cos(beta_b)."""
    from housingfe.source import as_made as am

    t0 = time.perf_counter()
    op = source._point(float(torque_nm))
    pair = source.pair
    weights = am.contact_weights(op.mesh_model, op.normal_force, op.n_positions)
    beta_b = pair.base_helix_angle
    pitch_factor = math.cos(pair.transverse_pressure_angle) * math.cos(beta_b)
    flank_factor = math.cos(beta_b)
    stats = []
    for g, z in enumerate(pair.teeth):
        tol = am.iso1328_tolerances(pair.module, pair.pitch_diameter[g], pair.face_width[g], grade)
        stats.append(am.deviation_statistics(int(z), tol, am.DEVIATION_KINDS, pitch_factor, flank_factor,
                                             pitch_samples=pitch_samples, seed=seed + g, pitch_model=pitch_model))
    spec = am.expected_order_spectrum(pair, weights, *stats)
    return Spectrum(spec.orders, spec.deviations, max(1, op.n_positions // 4), time.perf_counter() - t0)


def band_of(frequency: float) -> tuple[float, float]:
    """(lower, upper) [Hz] of the 1/3-octave band (housingfe.levels) with lower <= frequency < upper."""
    b = levels.third_octave_bands(frequency / 1.3, frequency * 1.3)
    i = int(np.flatnonzero((b.lower <= frequency) & (frequency < b.upper))[0])
    return float(b.lower[i]), float(b.upper[i])


def sideband_lines(source, model, periodic: Lines, torque_nm: float, spectrum: Spectrum, f_lines_max: float) -> Lines:
    """Lines of the expected deviation power at one torque (`Lines`; the periodic run's `points`, so totals group
    per operating point): per operating point the wheel orders q > 0 inside the 1/3-octave band of harmonic n
    (n = 1..spectrum.n_max and n f_tooth <= f_lines_max; `harmonic` = the lowest n whose band holds the line),
    frequency q f_tooth / z2, mesh_excitation k_ref sqrt(E a_q^2 / 2) (real rms N: the phase of an incoherent line
    is immaterial), L_omega the rigid-bore source's level of the same TE (te_receptance_rigid_bores)."""
    z2 = int(source.pair.teeth[1])
    k_ref = mesh_reference_stiffness(model)
    mats = source._point(float(torque_nm)).mats
    cols = {k: [] for k in ("torque", "speed", "harmonic", "frequency", "power", "point")}
    for p, (torque, speed, f_t, *_) in enumerate(periodic.points):
        if torque != float(torque_nm):
            continue
        f = spectrum.orders * f_t / z2
        band = np.zeros(f.size, int)
        for n in range(spectrum.n_max, 0, -1):          # the lowest harmonic's band wins where bands overlap
            if n * f_t > f_lines_max * (1 + 1e-12):
                continue
            lo, hi = band_of(n * f_t)
            band[(f >= lo) & (f < hi) & (f <= f_lines_max * (1 + 1e-12)) & (spectrum.orders > 0)] = n
        keep = (band > 0) & (spectrum.power > 0)
        m = int(keep.sum())
        cols["torque"] += [torque] * m
        cols["speed"] += [speed] * m
        cols["harmonic"] += list(band[keep])
        cols["frequency"] += list(f[keep])
        cols["power"] += list(spectrum.power[keep])
        cols["point"] += [p] * m
    freq = np.array(cols["frequency"], float)
    power = np.array(cols["power"], float)
    omega_ms = te_receptance_rigid_bores(mats, freq) ** 2 * power / 2 if freq.size else np.zeros(0)
    return Lines(torque=np.array(cols["torque"], float), speed=np.array(cols["speed"], float),
                 harmonic=np.array(cols["harmonic"], int), frequency=freq,
                 L_omega=levels.level(omega_ms, levels.OMEGA0),
                 mesh_excitation=(k_ref * np.sqrt(power / 2)).astype(complex),
                 point=np.array(cols["point"], int), points=periodic.points, receptance=periodic.receptance)


def _power(db) -> np.ndarray:
    return 10.0 ** (np.asarray(db, float) / 10.0)


def _db(power) -> float:
    return float(10.0 * np.log10(power)) if power > 0 else float("-inf")


COLUMNS = ("route", "radiation", "torque_nm", "speed_rpm", "tooth_frequency_hz", "grade", "pitch_model",
           "sideband_lines",
           "L_omega_tooth_band_dB", "L_omega_tooth_band_as_made_dB", "L_omega_total_dB", "L_omega_total_as_made_dB",
           "Lv_tooth_band_dB", "Lv_tooth_band_as_made_dB", "Lv_dB", "Lv_as_made_dB",
           "Lw_tooth_band_dB", "Lw_tooth_band_as_made_dB", "Lw_dB", "Lw_as_made_dB",
           "LwA_tooth_band_dB", "LwA_tooth_band_as_made_dB", "LwA_dB", "LwA_as_made_dB",
           "LwA_peak_band_hz", "LwA_peak_band_dB", "LwA_peak_band_as_made_hz", "LwA_peak_band_as_made_dB")


def _peak_band(frequency: np.ndarray, lwa_db: np.ndarray) -> tuple[float, float]:
    """(nominal centre Hz, level dB) of the 1/3-octave band holding the most A-weighted power of the lines."""
    if frequency.size == 0:
        return float("nan"), float("-inf")
    bands = levels.third_octave_bands(frequency.min() / 1.3, frequency.max() * 1.3)
    power = levels.band_sum(frequency, _power(lwa_db), bands)
    i = int(np.argmax(power))
    return float(bands.nominal[i]), _db(float(power[i]))


def table_rows(periodic: RunupResult, sidebands: RunupResult, grade: int, pitch_model: str = "independent") -> \
        list[dict]:
    """One row per route, radiator and operating point (COLUMNS): in the tooth band (the 1/3-octave band of
    f_tooth) and over all lines, L_omega (tf_omega: the rigid-bore source's; mesh_force: the wheel on the coupled
    model), L_v, L_W and L_WA of the periodic lines alone and with the expected sidebands (energy sums); and the
    1/3-octave band (nominal Hz) with the most A-weighted power, with its level, without and with them."""
    rows = []
    P, S = periodic.lines, sidebands.lines
    a_P, a_S = levels.a_weighting_db(P.frequency), levels.a_weighting_db(S.frequency)
    for route, rp in periodic.routes.items():
        rs = sidebands.routes[route]
        omega_P = P.L_omega if route == "tf_omega" else rp.L_omega_coupled
        omega_S = S.L_omega if route == "tf_omega" else rs.L_omega_coupled
        for rad in periodic.radiators:
            for p, (torque, speed, f_t, *_) in enumerate(P.points):
                lo, hi = band_of(f_t)
                inP, inS = P.point == p, S.point == p
                bandP = inP & (P.frequency >= lo) & (P.frequency < hi)
                bandS = inS & (S.frequency >= lo) & (S.frequency < hi)
                row = {"route": route, "radiation": rad, "torque_nm": torque, "speed_rpm": speed,
                       "tooth_frequency_hz": f_t, "grade": grade, "pitch_model": pitch_model,
                       "sideband_lines": int(inS.sum())}
                for key, vP, vS in (("L_omega", omega_P, omega_S), ("Lv", rp.L_v, rs.L_v),
                                    ("Lw", periodic.L_W[route, rad], sidebands.L_W[route, rad]),
                                    ("LwA", periodic.L_W[route, rad] + a_P, sidebands.L_W[route, rad] + a_S)):
                    total = "L_omega_total" if key == "L_omega" else key
                    for name, selP, selS in ((f"{key}_tooth_band", bandP, bandS), (total, inP, inS)):
                        base = float(np.sum(_power(vP[selP])))
                        row[f"{name}_dB"] = _db(base)
                        row[f"{name}_as_made_dB"] = _db(base + float(np.sum(_power(vS[selS]))))
                lwaP, lwaS = periodic.L_W[route, rad][inP] + a_P[inP], sidebands.L_W[route, rad][inS] + a_S[inS]
                row["LwA_peak_band_hz"], row["LwA_peak_band_dB"] = _peak_band(P.frequency[inP], lwaP)
                row["LwA_peak_band_as_made_hz"], row["LwA_peak_band_as_made_dB"] = _peak_band(
                    np.concatenate([P.frequency[inP], S.frequency[inS]]), np.concatenate([lwaP, lwaS]))
                rows.append(row)
    return rows


@dataclass
class AsMadeRun:
    """The as-made addition of a run-up: grade, rows (COLUMNS), the sideband RunupResult per torque, the bands'
    harmonics 1..n_max, the number of sideband lines, seconds, the pitch deviations' spectrum model."""

    grade: int
    rows: list
    sidebands: dict
    n_max: int
    lines: int
    seconds: float
    pitch_model: str = "independent"


def as_made_run(results: dict, source, grade: int, f_lines_max: float, routes,
                pitch_model: str = "independent") -> AsMadeRun:
    """The expected sidebands of grade-`grade` gears through `routes` on the run-up's own models (results: {torque:
    (GearboxModel, RunupResult)} of the periodic run-up); pitch_model: the pitch deviations' spectrum shape
    (runup.as_made_pitch, housingfe.source.as_made.PITCH_MODELS)."""
    from housingfe.source.as_made import check_pitch_model

    t0 = time.perf_counter()
    grade = check_as_made(grade)
    pitch_model = check_pitch_model(pitch_model)
    rows, side, n_max, count = [], {}, 1, 0
    for torque, (model, res) in results.items():
        spectrum = deviation_spectrum(source, float(torque), grade, pitch_model=pitch_model)
        n_max = spectrum.n_max
        lines = sideband_lines(source, model, res.lines, float(torque), spectrum, f_lines_max)
        speeds = sorted({s for t, s, *_ in res.lines.points if t == float(torque)})
        # both routes' unit loads in one factorisation per line (the sideband lines are many: ~500 per speed)
        names = [ROUTE_LOADS[r] for r in routes if r in ROUTE_LOADS]
        if model.speed_models:          # bearings following the speed: each speed's lines on its own model
            for s in np.unique(lines.speed):
                at = np.flatnonzero(lines.speed == s)
                model.at_speed(s).reduction.prefetch_unit_coordinates(lines.frequency[at], names)
        else:
            model.reduction.prefetch_unit_coordinates(lines.frequency, names)
        side[torque] = runup(model, None, speeds, [float(torque)], routes=tuple(routes), lines=lines)
        rows += table_rows(res, side[torque], grade, pitch_model)
        count += len(lines.frequency)
    return AsMadeRun(grade, rows, side, n_max, count, time.perf_counter() - t0, pitch_model)


def lwa_curve(run: AsMadeRun, route: str, radiation: str, torque: float,
              column: str = "LwA_as_made_dB") -> tuple[np.ndarray, np.ndarray]:
    """(speeds rev/min, L_WA dB(A)) over the run-up of one route, radiator and torque (N m) from the rows: the total
    with the expected sidebands (column "LwA_as_made_dB") or the periodic one ("LwA_dB")."""
    sel = sorted((r for r in run.rows if r["route"] == route and r["radiation"] == radiation
                  and r["torque_nm"] == float(torque)), key=lambda r: r["speed_rpm"])
    return (np.array([r["speed_rpm"] for r in sel], float), np.array([r[column] for r in sel], float))


def speed_laws(run: AsMadeRun, radiation: str) -> dict:
    """{torque (N m, text): {route: {"as_made": slope, "periodic": slope}}}: the speed law of L_WA with and
    without the expected sidebands, dB(A) per doubling of speed over slopes.SPEED_LAW_RANGE_RPM (the least-squares
    fit of the speed-law check, housingfe.runup.slopes.slope_per_doubling; NaN where the speeds span less than a
    doubling there)."""
    from housingfe.runup.slopes import slope_per_doubling

    out = {}
    for torque, side in run.sidebands.items():
        out[f"{float(torque):g}"] = {route: {kind: slope_per_doubling(*lwa_curve(run, route, radiation, torque, col))
                                             for kind, col in (("as_made", "LwA_as_made_dB"), ("periodic", "LwA_dB"))}
                                     for route in side.routes}
    return out


def summary_lines(run: AsMadeRun, radiation: str) -> list[str]:
    """The summary's lines: per torque and route, max L_WA with the expected sidebands beside the periodic one, and
    the speed law (dB(A) per doubling, 250-1500 rev/min) of both."""
    out = []
    laws = speed_laws(run, radiation)
    for torque in run.sidebands:
        parts = []
        for route in run.sidebands[torque].routes:
            sel = [r for r in run.rows if r["route"] == route and r["radiation"] == radiation
                   and r["torque_nm"] == float(torque)]
            i = int(np.argmax([r["LwA_as_made_dB"] for r in sel]))
            j = int(np.argmax([r["LwA_dB"] for r in sel]))
            law = laws[f"{float(torque):g}"][route]
            parts.append(f"{route} {sel[i]['LwA_as_made_dB']:.1f} dB(A) @ {sel[i]['speed_rpm']:g} rpm, most in the "
                         f"{sel[i]['LwA_peak_band_as_made_hz']:g} Hz band (periodic {sel[j]['LwA_dB']:.1f} @ "
                         f"{sel[j]['speed_rpm']:g} rpm, {sel[j]['LwA_peak_band_hz']:g} Hz band), speed law "
                         f"{law['as_made']:.1f} dB(A)/doubling (periodic {law['periodic']:.1f})")
        out.append(f"  {torque:g} N m as made (ISO 1328-1 grade {run.grade}, pitch {run.pitch_model}, expected "
                   f"sidebands in the bands of "
                   f"harmonics 1-{run.n_max}, {run.lines} lines, {run.seconds:.1f} s): max L_WA " + "; ".join(parts)
                   + f"; sigma {radiation} ({CSV})")
    return out


# ------------------------------------------------------------------------------------------ folded into the totals
def _cat(a, b, order) -> np.ndarray:
    return np.concatenate([np.asarray(a), np.asarray(b)])[order]


def _energy_sum(values_db, groups, n_groups: int) -> np.ndarray:
    power = np.zeros(n_groups)
    np.add.at(power, groups, 10.0 ** (np.asarray(values_db, float) / 10.0))
    with np.errstate(divide="ignore"):
        return 10.0 * np.log10(power)


def sideband_wheel_levels(model, lines: Lines) -> np.ndarray:
    """L_omega [dB re 5e-8 rad/s] of the wheel on the coupled model per sideband line: its mesh force alone (the
    Lines' mesh_excitation, no moment) on the model's gear mesh, what the mesh_force route's L_omega_coupled is for
    these lines (used where that route was not run)."""
    from housingfe.response.observers import node_key

    freq = lines.frequency
    c = line_coefficients(model, freq, lines.speed, {"mesh": lines.mesh_excitation})
    node = model.reduction.reduced.points[node_key(model.wheel_node)]
    rot = (model.wheel_axis / np.linalg.norm(model.wheel_axis)) @ (node[3:6] @ c)
    return levels.level(np.abs(2 * math.pi * freq * rot) ** 2, levels.OMEGA0)


def folded_result(model, periodic: RunupResult, sidebands: RunupResult) -> RunupResult:
    """One RunupResult of a torque's periodic lines and its expected sidebands (`as_made_run`'s, on the same model
    and operating points) with Lines.incoherent flagging the sidebands, ordered per operating point by frequency
    (the periodic line before a sideband at the same frequency).  Energies add: the totals (runup.csv's columns)
    sum every line of a point; the tooth band (L_omega_dB: the rigid-bore source's; L_omega_coupled_dB: the wheel
    on the coupled model; Lv_tooth_dB) sums the lines of harmonic 1 (the periodic tooth line and the sidebands in
    its 1/3-octave band, `sideband_lines`), so at the tooth order the line's expected power is |D|^2 + E|X|^2.
    "harmonics" stays the number of periodic tooth harmonics.  L_omega_flexible (the coupled source's wheel) of a
    sideband line is its mesh force's wheel level on the coupled model (`sideband_wheel_levels`).  The sidebands
    carry no shuttling moment nor friction (zeros where the periodic lines have them)."""
    P, S = periodic.lines, sidebands.lines
    nP, nS = len(P.frequency), len(S.frequency)
    flag = np.r_[np.zeros(nP, bool), np.ones(nS, bool)]
    point = np.r_[P.point, S.point]
    freq = np.r_[P.frequency, S.frequency]
    order = np.lexsort((flag, freq, point))
    n = len(P.points)
    tooth_S = S.harmonic == 1
    # the rigid-bore source's tooth band with the sidebands in it (points[3], the checks' L_omega rows)
    rigid_S = np.zeros(n)
    np.add.at(rigid_S, S.point[tooth_S], 10.0 ** (S.L_omega[tooth_S] / 10.0))
    points = [(t, s, f, float(10.0 * np.log10(10.0 ** (L / 10.0) + rigid_S[p])), k)
              for p, (t, s, f, L, k) in enumerate(P.points)]
    zeros = np.zeros(nS, complex)
    flexible = None
    if P.L_omega_flexible is not None:
        side = (sidebands.routes["mesh_force"].L_omega_coupled if "mesh_force" in sidebands.routes
                else sideband_wheel_levels(model, S))
        flexible = _cat(P.L_omega_flexible, side, order)
    mu = None
    if P.friction_mu is not None:       # a sideband line's friction coefficient: its operating point's
        mu_point = np.zeros(n)
        mu_point[P.point] = P.friction_mu
        mu = _cat(P.friction_mu, mu_point[S.point], order)
    lines = Lines(torque=_cat(P.torque, S.torque, order), speed=_cat(P.speed, S.speed, order),
                  harmonic=_cat(P.harmonic, S.harmonic, order).astype(int), frequency=freq[order],
                  L_omega=_cat(P.L_omega, S.L_omega, order),
                  mesh_excitation=_cat(P.mesh_excitation, S.mesh_excitation, order), point=point[order],
                  points=points, receptance=P.receptance, L_omega_flexible=flexible,
                  shuttle_moment=None if P.shuttle_moment is None else _cat(P.shuttle_moment, zeros, order),
                  friction=None if P.friction is None else {k: _cat(v, zeros, order) for k, v in P.friction.items()},
                  friction_mu=mu, incoherent=flag[order])
    routes = {}
    for name, rp in periodic.routes.items():
        rs = sidebands.routes[name]
        routes[name] = RouteResult(
            name, _cat(rp.L_v, rs.L_v, order), None,
            np.concatenate([rp.coefficients, rs.coefficients], axis=1)[:, order],
            _cat(rp.L_omega_coupled, rs.L_omega_coupled, order),
            None if rp.tf_omega is None else _cat(rp.tf_omega, rs.tf_omega, order),
            None if rp.excitation_db is None else _cat(rp.excitation_db, rs.excitation_db, order),
            rp.excitation_name, rp.transfer_name,
            *((None, None, None) if rp.bore_loads is None or rs.bore_loads is None else
              (_cat(rp.bore_loads, rs.bore_loads, order), _cat(rp.bore_force_db, rs.bore_force_db, order),
               _cat(rp.bore_moment_db, rs.bore_moment_db, order))))
    L_sigma = {k: _cat(v, sidebands.L_sigma[k], order) for k, v in periodic.L_sigma.items()}
    L_W = {k: _cat(v, sidebands.L_W[k], order) for k, v in periodic.L_W.items()}
    totals = folded_totals(lines, routes, L_W, periodic.radiators)
    return RunupResult(lines, routes, L_sigma, L_W, periodic.area_level_db, list(periodic.radiators), totals,
                       dict(periodic.timings))


def folded_totals(lines: Lines, routes: dict, L_W: dict, radiators) -> list[dict]:
    """The totals rows (the keys of housingfe.runup.chain.runup's) of lines that hold incoherent ones: every level
    the energy sum of its lines, the tooth band that of the harmonic-1 lines (module docstring of `folded_result`)."""
    n = len(lines.points)
    tooth = lines.harmonic == 1
    a_w = levels.a_weighting_db(lines.frequency)
    count = np.bincount(lines.point[~lines.incoherent], minlength=n)
    rows = []
    for name, rr in routes.items():
        Lv_tot = _energy_sum(rr.L_v, lines.point, n)
        Lv_band = _energy_sum(rr.L_v[tooth], lines.point[tooth], n)
        Lc_band = _energy_sum(rr.L_omega_coupled[tooth], lines.point[tooth], n)
        Lc_all = _energy_sum(rr.L_omega_coupled, lines.point, n)
        for rad in radiators:
            Lw_tot = _energy_sum(L_W[name, rad], lines.point, n)
            LwA_tot = _energy_sum(L_W[name, rad] + a_w, lines.point, n)
            for p, (torque, speed, f_t, L_om, k_m) in enumerate(lines.points):
                rows.append({"route": name, "radiation": rad, "torque_nm": torque, "speed_rpm": speed,
                             "tooth_frequency_hz": f_t, "L_omega_dB": L_om,
                             "L_omega_coupled_dB": float(Lc_band[p]), "L_omega_coupled_all_dB": float(Lc_all[p]),
                             "Lv_tooth_dB": float(Lv_band[p]), "Lv_dB": float(Lv_tot[p]),
                             "Lw_dB": float(Lw_tot[p]), "LwA_dB": float(LwA_tot[p]), "harmonics": int(count[p])})
    return rows
