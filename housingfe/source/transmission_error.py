"""A transmission error the user brings: the source's excitation from a file (measured, or from another code).

The chain's own excitation is a model (the engagement shock over the face width on the time-varying mesh stiffness,
docs/source.md).  Where the quasi-static transmission error (TE) of the real gears is known -- measured on a rig, or
computed by a loaded tooth contact analysis of another code -- it can replace that model: `runup.transmission_error =
"te.csv"` in a run-up scene (docs/source.md, "A transmission error from a file").

File format (CSV, one row per torque and harmonic; lines starting with '#' are comments)::

    # set A, loaded TE from <where>
    torque_Nm,harmonic,amplitude_um,phase_deg
    2000,1,0.56,-12.5
    2000,2,0.15,80.1

* `torque_Nm`: the pinion torque [N m] the row belongs to; every torque lists the same harmonics.
* `harmonic`: n = 1, 2, ... of the tooth-mesh frequency.
* the one-sided amplitude of harmonic n of the TE along the line of action (the flank normal), in one of
  `amplitude_um` (micrometres), `amplitude_mm` or `amplitude_m`: e(t) = sum_n a_n cos(2 pi n t / T_mesh + phi_n).
  TE positive = more mesh compression (the wheel lags).
* `phase_deg` or `phase_rad` (optional: without it every phase is 0).  The time origin is the source's: the mesh
  position T1 of the stiffness curve (`stiffness.csv` of `housingfe source`; a run-up writes the TE it used in the
  same format, `transmission_error.csv`).  Below the mesh mode the answer depends on the amplitudes alone (the
  first-order solve, docs/source.md); the phases matter only through the stiffness ripple's coupling of harmonics.

Between the file's torques the complex amplitudes are interpolated linearly; outside them nothing is extrapolated
(a TE is not linear in the load: InputError).  The mesh stiffness S(t) stays the model's: the source is given the
shock F_e(t) = F - S(t) (mean(F / S) + e(t)), whose quasi-static mesh compression (F - F_e) / S is mean(F / S) + e(t),
so the quasi-static excitation k_m (d - mean d) is k_m e(t) exactly (dynamics.engagement_force_from_transmission_error).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from housingfe.errors import InputError

AMPLITUDE_UNITS = {"amplitude_um": 1e-6, "amplitude_mm": 1e-3, "amplitude_m": 1.0}
PHASE_UNITS = {"phase_deg": math.pi / 180.0, "phase_rad": 1.0}
COLUMNS = ("torque_Nm", "harmonic", *AMPLITUDE_UNITS, *PHASE_UNITS)
# torques closer than this (relative) are the same torque: a file's 2000 serves a run-up's 2000.0000001
SAME_TORQUE = 1e-9
# samples of one mesh period on which the source holds S(t) and the TE (housingfe.source.roosmalen.run
# .OperatingPoint): a harmonic n of the file must lie below its Nyquist limit, n < SAMPLES_PER_MESH_PERIOD / 2
SAMPLES_PER_MESH_PERIOD = 256


@dataclass(frozen=True)
class TransmissionError:
    """A quasi-static transmission error per tooth-mesh harmonic at one or more pinion torques.

    torques (T,) [N m], ascending; harmonics (N,) [-], n >= 1, ascending; amplitudes (T, N) complex [m], one-sided:
    e(t) = Re sum_n amplitudes[., n] exp(i 2 pi n t / T_mesh); source: where it was read (a path, for messages)."""

    torques: np.ndarray
    harmonics: np.ndarray
    amplitudes: np.ndarray
    source: str = "transmission error"
    sha256: str = ""

    def torque_problem(self, torque: float) -> str | None:
        """Why this TE has nothing at a pinion torque [N m] (outside its torques), or None."""
        lo, hi = float(self.torques[0]), float(self.torques[-1])
        tol = SAME_TORQUE * max(abs(lo), abs(hi), 1.0)
        if lo - tol <= torque <= hi + tol:
            return None
        given = f"{lo:g} N m" if lo == hi else f"{lo:g}..{hi:g} N m"
        return (f"{self.source}: has no transmission error at {torque:g} N m (it gives {given}; a TE is not linear in "
                "the load, so it is not extrapolated)")

    def at(self, torque: float) -> np.ndarray:
        """Complex one-sided amplitudes [m] of `harmonics` at a pinion torque [N m], linear in the torque between the
        file's torques; InputError outside them."""
        problem = self.torque_problem(float(torque))
        if problem is not None:
            raise InputError(problem)
        if self.torques.size == 1:
            return self.amplitudes[0].copy()
        t = float(np.clip(torque, self.torques[0], self.torques[-1]))
        j = int(np.clip(np.searchsorted(self.torques, t) - 1, 0, self.torques.size - 2))
        w = (t - self.torques[j]) / (self.torques[j + 1] - self.torques[j])
        return (1.0 - w) * self.amplitudes[j] + w * self.amplitudes[j + 1]

    def samples(self, torque: float, n_samples: int) -> np.ndarray:
        """e(t) [m] at n_samples uniform instants of one mesh period (t = 0 at the source's mesh position T1)."""
        if self.harmonics[-1] >= n_samples / 2:
            raise InputError(f"{self.source}: harmonic {int(self.harmonics[-1])} is too high for {n_samples} samples "
                             f"per mesh period (at most {n_samples // 2 - 1})")
        spectrum = np.zeros(n_samples // 2 + 1, complex)
        spectrum[self.harmonics] = self.at(torque) * n_samples / 2.0     # one-sided amplitude -> rfft coefficient
        return np.fft.irfft(spectrum, n_samples)


def validated_scene_file(value: str, info) -> str:
    """The `transmission_error` key of a scene for a pydantic field validator (housingfe.scenefile.scene_file_key):
    the absolute path of a file `read` takes, relative to the scene file when it is there; "" stays ""."""
    from housingfe.scenefile import scene_file_key

    return scene_file_key(value, info, read)


def checked_scene(table, torques: dict):
    """A scene table (a pydantic model with `transmission_error`, `engagement` and `harmonics`) for its model
    validator: the table, or the ValueError naming why its TE file cannot serve it -- `engagement` set beside the file,
    every harmonic of the file above the source's `harmonics`, or a torque [N m] of {key: [torques]} outside the
    file's torques."""
    if not table.transmission_error:
        return table
    if "engagement" in table.model_fields_set:
        raise ValueError(f"transmission_error: the file replaces the engagement model; engagement = "
                         f"{table.engagement!r} is set as well: give one of the two")
    te = read(table.transmission_error)
    if te.harmonics[0] > table.harmonics:       # the harmonic balance keeps 1..harmonics: nothing of the file would act
        raise ValueError(f"transmission_error: {te.source}: its lowest harmonic {int(te.harmonics[0])} is above "
                         f"harmonics = {table.harmonics}, the highest the source's harmonic balance keeps: the file "
                         "would excite nothing (raise harmonics)")
    for key, values in torques.items():
        for torque in values:
            problem = te.torque_problem(torque)
            if problem is not None:
                raise ValueError(f"transmission_error: {problem} ({key}; set it within the file's torques)")
    return table


def harmonics_of(samples: np.ndarray, count: int) -> np.ndarray:
    """One-sided complex amplitudes of harmonics 1..count of samples of one period (the inverse of
    TransmissionError.samples for a band-limited signal)."""
    coefficients = np.fft.rfft(np.asarray(samples, float))
    return 2.0 * coefficients[1:count + 1] / len(samples)


def read(path: str | Path) -> TransmissionError:
    """The TransmissionError of a CSV file (module docstring); InputError naming the file, and the line where one is
    at fault, for anything it cannot take."""
    from housingfe.scenefile import csv_number, read_csv_rows

    path = Path(path)
    sha256, header, head, body = read_csv_rows(
        path, "the transmission error file", COLUMNS,
        f"columns: torque_Nm, harmonic, one of {', '.join(AMPLITUDE_UNITS)}, optionally one of {', '.join(PHASE_UNITS)}",
        "a header `torque_Nm,harmonic,amplitude_um,phase_deg` and one row per torque and harmonic")
    amplitude = [h for h in header if h in AMPLITUDE_UNITS]
    phase = [h for h in header if h in PHASE_UNITS]
    for need in ("torque_Nm", "harmonic"):
        if need not in header:
            raise InputError(f"{path}: line {head}: no column {need!r}")
    if len(amplitude) != 1 or len(phase) > 1:
        raise InputError(f"{path}: line {head}: give exactly one amplitude column ({', '.join(AMPLITUDE_UNITS)})"
                         f" and at most one phase column ({', '.join(PHASE_UNITS)})")
    col = {h: i for i, h in enumerate(header)}
    table: dict[float, dict[int, complex]] = {}
    for number, row in body:
        where = f"{path}: line {number}"
        values = {h: csv_number(where, h, row[col[h]]) for h in header}
        torque, n = values["torque_Nm"], values["harmonic"]
        if torque <= 0.0:
            raise InputError(f"{where}: torque_Nm: {torque:g} is not a positive torque")
        if n != int(n) or n < 1:
            raise InputError(f"{where}: harmonic: {n:g} is not a harmonic number 1, 2, ...")
        if n >= SAMPLES_PER_MESH_PERIOD // 2:      # else refused after the housing was meshed (or an overflow)
            raise InputError(f"{where}: harmonic: {n:g} is above the highest harmonic the source resolves "
                             f"({SAMPLES_PER_MESH_PERIOD // 2 - 1}: {SAMPLES_PER_MESH_PERIOD} samples per mesh period)")
        a = values[amplitude[0]]
        if a < 0.0:
            raise InputError(f"{where}: {amplitude[0]}: {a:g} is negative (an amplitude; put the sign in the phase)")
        a *= AMPLITUDE_UNITS[amplitude[0]]
        if a > 1e-3:
            raise InputError(f"{where}: {amplitude[0]}: {a * 1e6:g} um is implausible for a transmission error "
                             "(> 1 mm): check the unit in the column name")
        phi = values[phase[0]] * PHASE_UNITS[phase[0]] if phase else 0.0
        harmonics = table.setdefault(torque, {})
        if int(n) in harmonics:
            raise InputError(f"{where}: harmonic {int(n)} at {torque:g} N m is given twice")
        harmonics[int(n)] = a * complex(math.cos(phi), math.sin(phi))
    if not table:
        raise InputError(f"{path}: no rows after the header")
    torques = sorted(table)
    harmonics = sorted(table[torques[0]])
    for t in torques[1:]:
        if sorted(table[t]) != harmonics:
            raise InputError(f"{path}: {t:g} N m gives harmonics {sorted(table[t])}, {torques[0]:g} N m "
                             f"{harmonics}: every torque must list the same harmonics")
    amplitudes = np.array([[table[t][n] for n in harmonics] for t in torques], complex)
    return TransmissionError(np.array(torques, float), np.array(harmonics, int), amplitudes, source=str(path),
                             sha256=sha256)


def write(path: str | Path, torques, harmonics, amplitudes, comment: str = "") -> None:
    """Write a TE in the format `read` takes: torques [N m], harmonics [-], amplitudes (T, N) complex [m];
    `comment` lines go first, after '#'.  The caller writes into a result folder written atomically."""
    lines = [f"# {c}" for c in comment.splitlines() if c.strip()]
    lines.append("torque_Nm,harmonic,amplitude_um,phase_deg")
    for t, row in zip(torques, np.atleast_2d(amplitudes)):
        for n, a in zip(harmonics, row):
            lines.append(f"{float(t):.10g},{int(n)},{abs(a) * 1e6:.8g},{math.degrees(np.angle(a)):.6f}")
    Path(path).write_text("\n".join(lines) + "\n")
