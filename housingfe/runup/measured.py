"""A measured run-up the user brings, beside the chain's: `runup.measured = "measured.csv"` in a run-up scene.

The first thing an NVH engineer does with a predicted run-up is to lay it over the measured one.  The file holds
levels over speed, in the references the chain writes (van Roosmalen 1994: P0 = 1 pW, v0 = omega0 = 5e-8)::

    # gearbox 7, rig B, microphone array; 2026-10-01
    torque_Nm,speed_rpm,L_WA_dBA,L_v_dB
    2000,250,74.0,
    2000,500,80.0,92.1
    2000,1000,86.0,95.3

* `speed_rpm`: the pinion speed [rev/min] (required).
* `torque_Nm`: the pinion torque [N m] the row belongs to; may be left out when the run-up has one torque.  Every
  torque of the file must be one of the run's (runup.torques_nm): a level is not scaled to another load.
* one or more levels (QUANTITIES): `L_WA_dBA` (A-weighted sound power, dB(A) re 1 pW), `L_W_dB` (sound power,
  dB re 1 pW), `L_v_dB` (surface-averaged velocity, dB re 5e-8 m/s), `L_omega_dB` (the wheel's angular velocity in
  the tooth band, dB re 5e-8 rad/s).  An empty cell is a level not measured at that speed.

Ours at a measured speed is runup.csv's curve interpolated linearly in speed (L_omega: the source's on the tf_omega
route, which it drives; the wheel's in the coupled gearbox on mesh_force); measured speeds outside the run's
speeds are not compared (they are counted and said).  `compare` gives one row per measured point, route and
radiation model (measured_comparison.csv); `statistics` per series the mean and standard deviation of ours -
measured (the thesis' measure of a difference over speed, Sec. 5.7), the maxima and their speeds, and the slope per
doubling of speed of both over the compared speeds.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from housingfe.errors import InputError

# measured column -> (runup.csv column, what it is, unit); L_omega per route: COUPLED_L_OMEGA
QUANTITIES = {
    "L_WA_dBA": ("LwA_dB", "A-weighted sound power level", "dB(A) re 1 pW"),
    "L_W_dB": ("Lw_dB", "sound power level", "dB re 1 pW"),
    "L_v_dB": ("Lv_dB", "surface-averaged velocity level", "dB re 5e-8 m/s"),
    "L_omega_dB": ("L_omega_dB", "wheel angular velocity level, tooth band", "dB re 5e-8 rad/s"),
}
# the wheel's L_omega that belongs to a route: tf_omega is driven by the source's L_omega (runup.csv L_omega_dB);
# on mesh_force the wheel moves in the coupled gearbox (L_omega_coupled_dB), the one to hold against a measurement
COUPLED_L_OMEGA = {"mesh_force": "L_omega_coupled_dB"}
COLUMNS = ("torque_Nm", "speed_rpm", *QUANTITIES)
COMPARISON_COLUMNS = ("torque_nm", "quantity", "route", "radiation", "speed_rpm", "measured_dB", "ours_dB",
                      "difference_dB")
# torques closer than this (relative) are the same torque (a file's 2000 is the run's 2000.0)
SAME_TORQUE = 1e-9
# a level outside this range [dB] is not a level in these references (a unit or reference mix-up)
PLAUSIBLE_DB = (-50.0, 250.0)


@dataclass(frozen=True)
class MeasuredRunup:
    """Measured levels over speed: series {(quantity, torque [N m] or None): (speeds [rev/min], levels [dB])}, speeds
    ascending; torque None when the file has no torque column; source: the file (for messages), sha256: its bytes."""

    series: dict
    source: str
    sha256: str = ""

    @property
    def torques(self) -> list:
        """The file's torques [N m] (ascending; [None] without a torque column)."""
        keys = {t for _, t in self.series}
        return [None] if None in keys else sorted(keys)

    def torque_problem(self, run_torques) -> str | None:
        """Why this file cannot be laid over a run-up at run_torques [N m], or None."""
        run = [float(t) for t in run_torques]
        if self.torques == [None]:
            if len(run) > 1:
                return (f"{self.source}: has no torque_Nm column, and the run-up has {len(run)} torques "
                        f"({', '.join(f'{t:g}' for t in run)} N m): say which torque each row belongs to")
            return None
        for t in self.torques:
            if not any(abs(t - r) <= SAME_TORQUE * max(abs(r), 1.0) for r in run):
                return (f"{self.source}: its {t:g} N m is not a torque of the run-up ({', '.join(f'{r:g}' for r in run)}"
                        " N m; runup.torques_nm): a measured level is compared at its own load only")
        return None

    def run_torque(self, torque, run_torques) -> float:
        """The run's torque [N m] a file torque (None: the run's only one) stands for."""
        if torque is None:
            return float(run_torques[0])
        return min((float(r) for r in run_torques), key=lambda r: abs(r - torque))


def read(path: str | Path) -> MeasuredRunup:
    """The MeasuredRunup of a CSV file (module docstring); InputError naming the file, and the line where one is at
    fault, for anything it cannot take."""
    from housingfe.scenefile import csv_number, read_csv_rows

    path = Path(path)
    sha256, header, head, body = read_csv_rows(
        path, "the measured run-up file", COLUMNS,
        f"columns: speed_rpm, optionally torque_Nm, and one or more of {', '.join(QUANTITIES)}",
        "a header such as `torque_Nm,speed_rpm,L_WA_dBA` and one row per speed")
    if "speed_rpm" not in header:
        raise InputError(f"{path}: line {head}: no column 'speed_rpm'")
    levels = [h for h in header if h in QUANTITIES]
    if not levels:
        raise InputError(f"{path}: line {head}: no level column (one or more of {', '.join(QUANTITIES)})")
    col = {h: i for i, h in enumerate(header)}
    points: dict[tuple, dict[float, float]] = {}
    for number, row in body:
        where = f"{path}: line {number}"
        # an empty level cell is a level not measured at that speed
        values = {h: csv_number(where, h, row[col[h]]) for h in header
                  if row[col[h]].strip() or h not in QUANTITIES}
        speed = values["speed_rpm"]
        if speed <= 0.0:
            raise InputError(f"{where}: speed_rpm: {speed:g} is not a positive speed")
        torque = values.get("torque_Nm") if "torque_Nm" in header else None
        if torque is not None and torque <= 0.0:
            raise InputError(f"{where}: torque_Nm: {torque:g} is not a positive torque")
        for q in levels:
            if q not in values:
                continue
            if not PLAUSIBLE_DB[0] <= values[q] <= PLAUSIBLE_DB[1]:
                raise InputError(f"{where}: {q}: {values[q]:g} dB is not a level in {QUANTITIES[q][2]}")
            series = points.setdefault((q, torque), {})
            if speed in series:
                raise InputError(f"{where}: {q} at {speed:g} rev/min"
                                 + (f" and {torque:g} N m" if torque is not None else "") + " is given twice")
            series[speed] = values[q]
    if not points:
        raise InputError(f"{path}: no measured level after the header")
    series = {key: (np.array(sorted(s), float), np.array([s[v] for v in sorted(s)], float))
              for key, s in sorted(points.items(), key=lambda kv: (kv[0][0], kv[0][1] or 0.0))}
    return MeasuredRunup(series, str(path), sha256)


def checked_scene(spec):
    """A RunupSpec for its model validator: spec, or the ValueError naming why its `measured` file cannot be laid
    over its torques."""
    if not spec.measured:
        return spec
    problem = read(spec.measured).torque_problem(spec.torques_nm)
    if problem is not None:
        raise ValueError(f"measured: {problem}")
    return spec


def compare(measured: MeasuredRunup, totals: list[dict], run_torques) -> tuple[list[dict], int]:
    """Rows of measured_comparison.csv (COMPARISON_COLUMNS): every measured point inside the run's speeds beside ours
    (runup.csv's `totals`, linear in speed) per route and radiation model; and how many measured points lay outside
    the run's speeds (not compared)."""
    rows, outside = [], 0
    for (quantity, file_torque), (speeds, values) in measured.series.items():
        torque = measured.run_torque(file_torque, run_torques)
        curves: dict[tuple, list] = {}
        for r in totals:
            if abs(r["torque_nm"] - torque) <= SAME_TORQUE * max(abs(torque), 1.0):
                column = column_of(quantity, r["route"])
                curves.setdefault((r["route"], r["radiation"]), []).append((r["speed_rpm"], r[column]))
        first = True
        for (route, radiation), curve in curves.items():
            curve.sort()
            s = np.array([c[0] for c in curve], float)
            ours = np.array([c[1] for c in curve], float)
            inside = (speeds >= s[0] - 1e-9) & (speeds <= s[-1] + 1e-9)
            if first:
                outside += int(np.count_nonzero(~inside))
                first = False
            for speed, value in zip(speeds[inside], values[inside]):
                o = float(np.interp(speed, s, ours))
                rows.append({"torque_nm": torque, "quantity": quantity, "route": route, "radiation": radiation,
                             "speed_rpm": float(speed), "measured_dB": float(value), "ours_dB": o,
                             "difference_dB": o - float(value)})
    return rows, outside


def column_of(quantity: str, route: str) -> str:
    """The runup.csv column that a measured quantity is held against on a route (QUANTITIES, COUPLED_L_OMEGA)."""
    if quantity == "L_omega_dB":
        return COUPLED_L_OMEGA.get(route, "L_omega_dB")
    return QUANTITIES[quantity][0]


def slope_per_doubling(speeds, levels) -> float:
    """Least-squares slope of levels [dB] against log2(speed): dB per doubling of speed (NaN for fewer than two
    speeds or less than a doubling)."""
    speeds, levels = np.asarray(speeds, float), np.asarray(levels, float)
    if speeds.size < 2 or speeds.max() < 2.0 * speeds.min():
        return float("nan")
    return float(np.polyfit(np.log2(speeds), levels, 1)[0])


def statistics(rows: list[dict]) -> list[dict]:
    """Per (torque, quantity, route, radiation) of `compare`'s rows: points, mean and sample standard deviation of
    ours - measured [dB] (s.d. NaN for one point), the measured and our maximum over the compared speeds with their
    speeds [rev/min], and both slopes [dB per doubling of speed] over them."""
    groups: dict[tuple, list[dict]] = {}
    for r in rows:
        groups.setdefault((r["torque_nm"], r["quantity"], r["route"], r["radiation"]), []).append(r)
    out = []
    for (torque, quantity, route, radiation), sel in groups.items():
        sel = sorted(sel, key=lambda r: r["speed_rpm"])
        speeds = np.array([r["speed_rpm"] for r in sel])
        meas = np.array([r["measured_dB"] for r in sel])
        ours = np.array([r["ours_dB"] for r in sel])
        diff = ours - meas
        out.append({"torque_nm": torque, "quantity": quantity, "route": route, "radiation": radiation,
                    "points": len(sel), "speed_min_rpm": float(speeds[0]), "speed_max_rpm": float(speeds[-1]),
                    "mean_difference_dB": float(diff.mean()),
                    "sd_difference_dB": float(diff.std(ddof=1)) if len(sel) > 1 else float("nan"),
                    "measured_max_dB": float(meas.max()), "measured_max_speed_rpm": float(speeds[meas.argmax()]),
                    "ours_max_dB": float(ours.max()), "ours_max_speed_rpm": float(speeds[ours.argmax()]),
                    "measured_slope_dB_per_doubling": slope_per_doubling(speeds, meas),
                    "ours_slope_dB_per_doubling": slope_per_doubling(speeds, ours)})
    return out


def summary_lines(measured: MeasuredRunup, stats: list[dict], outside: int, radiation: str) -> list[str]:
    """The run-up summary's lines on the comparison (the first radiation model's rows)."""
    def f(x, fmt="+.1f"):
        return "-" if not math.isfinite(x) else format(x, fmt)

    lines = [f"measured run-up (runup.measured): {measured.source} (sha256 {measured.sha256[:12]}); ours - measured, "
             "dB (mean +- s.d. over the compared speeds), maxima and slopes over them:"]
    for s in stats:
        if s["radiation"] != radiation:
            continue
        lines.append(f"  {s['torque_nm']:g} N m  {s['quantity']:<10} {s['route']:<10}: {f(s['mean_difference_dB'])} "
                     f"+- {f(s['sd_difference_dB'], '.1f')} dB over {s['points']} speeds "
                     f"{s['speed_min_rpm']:g}-{s['speed_max_rpm']:g} rpm; max ours {s['ours_max_dB']:.1f} @ "
                     f"{s['ours_max_speed_rpm']:g} / measured {s['measured_max_dB']:.1f} @ "
                     f"{s['measured_max_speed_rpm']:g} rpm; slope ours {f(s['ours_slope_dB_per_doubling'])} / "
                     f"measured {f(s['measured_slope_dB_per_doubling'])} dB per doubling")
    if outside:
        lines.append(f"  {outside} measured point(s) outside the run's speeds were not compared")
    return lines
