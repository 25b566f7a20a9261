"""Which term of the chain makes the speed law: the slope over speed of each term of L_WA (issue 28, item 3).

Per line (tooth harmonic n at one speed) the chain is a sum of levels (dB):

    L_WA = L_exc + T + L_S + L_sigma + A

* L_exc — the route's excitation: L_omega of the source (dB re 5e-8 rad/s) on the tf_omega route, the mesh
  excitation level L_F = 20 lg(|F_n - k_m d_n|_rms / 1 N) on the mesh_force route;
* T = L_v - L_exc — the transfer (TF_omega on the tf_omega route, the mobility level L_v - L_F on mesh_force);
* L_S = 10 lg(S / 1 m^2) — the radiating area (a constant: slope 0);
* L_sigma = 10 lg sigma — the radiator's radiation index;
* A — the A-weighting at the line's frequency.

Two choices of what "the level at a speed" is:

* "tooth_band": the tooth-frequency line alone (the 1/3-octave band of the tooth frequency holds only that line:
  the 2nd harmonic is an octave above).  The identity above holds line by line, so it holds exactly at every
  speed, and because a least-squares slope is linear in the data, the terms' slopes add up to L_WA's slope
  exactly (round-off).  With gears as made folded into the totals (runup.as_made_totals) the band also holds the
  incoherent sidebands (harmonic 1 = the lines in the tooth band): they are energy-summed as in the total below.
* "total": every harmonic energy-summed, the quantity of the run-up curves and of the speed-law check.  A sum
  of powers does not split into a sum of levels, so each total term is defined as the power-weighted mean of
  its per-line values, which telescopes:  L_exc,tot = 10 lg sum 10^(L_exc/10);  T_tot = L_v,tot - L_exc,tot
  (the excitation-power-weighted transfer);  L_sigma,tot = L_W,tot - L_v,tot - L_S (10 lg of the v^2-weighted
  mean sigma);  A_tot = L_WA,tot - L_W,tot (10 lg of the power-weighted mean A-weighting, which also holds the
  shift of power between harmonics as the lines move through the A-curve).  The residual of the sum is then
  round-off; it is reported (`sum_residual_db`), not assumed.

The transfer split into PATH and HOUSING (where the run-up holds the bearings' loads on the bores,
RouteResult.bore_force_db: housingfe.runup.chain.route_bore_loads):

    T = T_path + T_housing,   T_path = L_bore - L_exc,   T_housing = L_v - L_bore

with L_bore = 10 lg(sum over the bearings of |F|^2 of the three force components / 1 N^2) (rms, dB re 1 N) of the
loads the bearings put on the bore masters: T_path is what the mesh force, shafts, gear bodies and bearings make
of the excitation at the bores, T_housing what the housing makes of the bore forces at its surface.  Same two bases:
on the tooth band line by line, on the total with L_bore,tot = 10 lg sum 10^(L_bore/10) (telescoping as above:
T_path,tot = L_bore,tot - L_exc,tot, T_housing,tot = L_v,tot - L_bore,tot).  The split is of the transfer only: the
five terms and their sum are untouched; its residual slope(T_path) + slope(T_housing) - slope(T) is reported
(`split_residual_db`).  The bore moments are not in L_bore (their own level L_bore_moment, dB re 1 N m, is kept
beside it): T_housing holds the housing's answer to the moments too.

The slope is the least-squares fit of the level against log2(speed) over SPEED_LAW_RANGE_RPM (dB per doubling
of speed), the fit of the speed-law check (housingfe.runup.checks).  The term "that makes" the slope is the one
with the largest positive slope; the one "that holds it back" the most negative one.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from housingfe import levels

SPEED_LAW_RANGE_RPM = (250.0, 1500.0)
TERMS = ("excitation", "transfer", "L_S", "L_sigma", "A_weighting")      # their sum is L_WA
SUMS = ("L_v", "L_W", "L_WA")
SPLIT = ("transfer_path", "transfer_housing")     # their sum is the transfer (where the bore loads are known)
BORE_LEVELS = ("L_bore", "L_bore_moment")
BASES = ("total", "tooth_band")
TERM_LABELS = {"excitation": "excitation", "transfer": "transfer (L_v - excitation)", "L_S": "L_S (area)",
               "L_sigma": "L_sigma (radiation index)", "A_weighting": "A-weighting",
               "transfer_path": "T_path = L_bore - excitation (mesh, shafts, gears, bearings -> bore forces)",
               "transfer_housing": "T_housing = L_v - L_bore (bore forces -> surface velocity)",
               "L_bore": "L_bore, bearing forces on the bores (dB re 1 N)",
               "L_bore_moment": "L_bore_moment, bearing moments on the bores (dB re 1 N m)"}


def slope_per_doubling(speeds, values, speed_range=SPEED_LAW_RANGE_RPM) -> float:
    """Least-squares slope of `values` (dB) against log2(speeds) (rev/min) inside speed_range: dB per doubling of
    speed.  NaN when fewer than three speeds or less than a doubling of speed lie in the range, or a value in the
    range is not finite."""
    speeds, values = np.asarray(speeds, float), np.asarray(values, float)
    lo, hi = speed_range
    sel = (speeds >= lo) & (speeds <= hi)
    if np.count_nonzero(sel) < 3 or speeds[sel].max() < 2 * speeds[sel].min() or not np.all(np.isfinite(values[sel])):
        return float("nan")
    return float(np.polyfit(np.log2(speeds[sel]), values[sel], 1)[0])


def _energy_sum(values_db, groups, n_groups) -> np.ndarray:
    power = np.zeros(n_groups)
    np.add.at(power, groups, 10.0 ** (np.asarray(values_db, float) / 10.0))
    with np.errstate(divide="ignore"):
        return 10.0 * np.log10(power)


def term_levels(point, n_points: int, harmonic, frequency, excitation_db, L_v_db, L_sigma_db, area_level_db: float,
                basis: str = "total", bore_db=None, bore_moment_db=None) -> dict[str, np.ndarray]:
    """The terms (TERMS) and sums (SUMS) of L_WA per operating point (dB), from per-line arrays: point (index of the
    operating point, 0..n_points-1), harmonic number, frequency (Hz), excitation level, L_v (dB re 5e-8 m/s) and
    L_sigma (dB); area_level_db = L_S.  basis "tooth_band" (harmonic 1 only) or "total" (module docstring).
    bore_db (per line, dB re 1 N: L_bore) adds the transfer's split SPLIT and "L_bore"; bore_moment_db (dB re
    1 N m) adds "L_bore_moment"."""
    out = _term_levels(point, n_points, harmonic, frequency, excitation_db, L_v_db, L_sigma_db, area_level_db, basis)
    for key, values in (("L_bore", bore_db), ("L_bore_moment", bore_moment_db)):
        if values is not None:
            out[key] = _basis_level(point, n_points, harmonic, values, basis)
    if bore_db is not None:
        with np.errstate(invalid="ignore"):
            out["transfer_path"] = out["L_bore"] - out["excitation"]
            out["transfer_housing"] = out["L_v"] - out["L_bore"]
    return out


def _basis_level(point, n_points: int, harmonic, values_db, basis: str) -> np.ndarray:
    """A per-line level on a basis: the tooth line's (or the energy sum of the tooth band's lines), or the energy
    sum of every line of the operating point."""
    point = np.asarray(point, int)
    values_db = np.asarray(values_db, float)
    if basis == "total":
        return _energy_sum(values_db, point, n_points)
    tooth = np.flatnonzero(np.asarray(harmonic) == 1)
    return _energy_sum(values_db[tooth], point[tooth], n_points)


def _term_levels(point, n_points: int, harmonic, frequency, excitation_db, L_v_db, L_sigma_db, area_level_db: float,
                 basis: str) -> dict[str, np.ndarray]:
    point = np.asarray(point, int)
    exc = np.asarray(excitation_db, float)
    L_v = np.asarray(L_v_db, float)
    sigma = np.asarray(L_sigma_db, float)
    a_w = levels.a_weighting_db(frequency)
    L_W = L_v + area_level_db + sigma
    L_WA = L_W + a_w
    tooth = np.flatnonzero(np.asarray(harmonic) == 1)
    if basis == "tooth_band" and tooth.size > n_points:
        # incoherent lines beside the tooth line (gears as made folded into the totals, Lines.incoherent): the
        # tooth band holds several lines, energy-summed like the total, its terms the power-weighted means
        E, V, W, WA = (_energy_sum(x[tooth], point[tooth], n_points) for x in (exc, L_v, L_W, L_WA))
        with np.errstate(invalid="ignore"):
            out = {"excitation": E, "transfer": V - E, "L_sigma": W - V - area_level_db, "A_weighting": WA - W,
                   "L_v": V, "L_W": W, "L_WA": WA}
    elif basis == "tooth_band":
        idx = np.full(n_points, -1)
        idx[point[tooth]] = tooth
        if np.any(idx < 0):
            raise ValueError("term_levels: an operating point has no tooth-frequency line")
        with np.errstate(invalid="ignore"):
            out = {"excitation": exc[idx], "transfer": L_v[idx] - exc[idx], "L_sigma": sigma[idx],
                   "A_weighting": a_w[idx], "L_v": L_v[idx], "L_W": L_W[idx], "L_WA": L_WA[idx]}
    elif basis == "total":
        E, V, W, WA = (_energy_sum(x, point, n_points) for x in (exc, L_v, L_W, L_WA))
        with np.errstate(invalid="ignore"):
            out = {"excitation": E, "transfer": V - E, "L_sigma": W - V - area_level_db, "A_weighting": WA - W,
                   "L_v": V, "L_W": W, "L_WA": WA}
    else:
        raise ValueError(f"basis {basis!r}: must be one of {', '.join(BASES)}")
    out["L_S"] = np.full(n_points, float(area_level_db))
    return out


@dataclass
class SlopeDecomposition:
    """The slopes (dB per doubling of speed) of every term of L_WA of one run-up curve (route, radiation, torque) on
    one basis, with the levels they are fitted to.  excitation_name / transfer_name say what the route's excitation
    and transfer are; sum_residual_db = sum of the term slopes - slope of L_WA (round-off for both bases);
    made_by / held_back_by: the terms with the largest positive / most negative slope (L_S excluded; held_back_by
    is "" when no term falls with speed)."""

    route: str
    radiation: str
    torque_nm: float
    basis: str
    excitation_name: str
    transfer_name: str
    speeds_rpm: np.ndarray
    levels: dict
    slopes: dict = field(default_factory=dict)

    def __post_init__(self):
        if not self.slopes:
            self.slopes = {k: slope_per_doubling(self.speeds_rpm, v) for k, v in self.levels.items()}

    @property
    def term_sum(self) -> float:
        """Sum of the terms' slopes (dB per doubling): L_WA's slope when the decomposition adds up."""
        return float(sum(self.slopes[t] for t in TERMS))

    @property
    def sum_residual_db(self) -> float:
        return self.term_sum - self.slopes["L_WA"]

    @property
    def has_split(self) -> bool:
        """Whether the transfer is split into path and housing (the run-up held the bore loads)."""
        return all(k in self.slopes for k in SPLIT)

    @property
    def split_residual_db(self) -> float:
        """slope(T_path) + slope(T_housing) - slope(T) (dB per doubling; round-off), NaN without the split."""
        if not self.has_split:
            return float("nan")
        return self.slopes["transfer_path"] + self.slopes["transfer_housing"] - self.slopes["transfer"]

    @property
    def made_by(self) -> str:
        terms = [t for t in TERMS if t != "L_S" and np.isfinite(self.slopes[t])]
        return max(terms, key=lambda t: self.slopes[t]) if terms else ""

    @property
    def held_back_by(self) -> str:
        terms = [t for t in TERMS if t != "L_S" and np.isfinite(self.slopes[t]) and self.slopes[t] < 0.0]
        return min(terms, key=lambda t: self.slopes[t]) if terms else ""

    def label(self, term: str) -> str:
        """A term's name for people: the route's excitation and transfer by what they are."""
        return {"excitation": self.excitation_name, "transfer": self.transfer_name}.get(term, TERM_LABELS[term])

    def sentence(self) -> str:
        """One line: L_WA's slope, the terms that add up to it, and the term that makes it."""
        s = self.slopes
        where = f"{self.route} ({self.radiation}, {self.torque_nm:g} N m, {self.basis.replace('_', ' ')})"
        if not (np.isfinite(s["L_WA"]) and self.made_by):
            lo, hi = SPEED_LAW_RANGE_RPM
            return f"{where}: no speed law (fewer than three speeds or less than a doubling of speed in {lo:g}-{hi:g} rpm)"
        terms = " + ".join(f"{t} {s[t]:+.2f}" for t in TERMS if t != "L_S")
        held = (f", held back by {self.held_back_by} ({s[self.held_back_by]:+.2f})" if self.held_back_by
                else ", no term falls with speed")
        split = (f"; transfer {s['transfer']:+.2f} = path {s['transfer_path']:+.2f} (L_bore - excitation) + housing "
                 f"{s['transfer_housing']:+.2f} (L_v - L_bore) (residual {self.split_residual_db:.1e})"
                 if self.has_split and np.isfinite(self.split_residual_db) else "")
        return (f"{where}: L_WA {s['L_WA']:+.2f} dB(A)/doubling = {terms} (residual {self.sum_residual_db:.1e}); made by "
                f"{self.made_by} ({s[self.made_by]:+.2f}){held}{split}")

    def to_json(self) -> dict:
        def num(x):
            return float(x) if np.isfinite(x) else None

        return {"route": self.route, "radiation": self.radiation, "torque_nm": self.torque_nm, "basis": self.basis,
                "excitation": self.excitation_name, "transfer": self.transfer_name,
                "speed_range_rpm": list(SPEED_LAW_RANGE_RPM),
                "slopes_dB_per_doubling": {k: num(v) for k, v in self.slopes.items()},
                "term_sum_dB_per_doubling": num(self.term_sum), "sum_residual_dB": num(self.sum_residual_db),
                "made_by": self.made_by, "held_back_by": self.held_back_by,
                "split_residual_dB": num(self.split_residual_db) if self.has_split else None,
                "speeds_rpm": [float(x) for x in self.speeds_rpm],
                "levels_dB": {k: [num(x) for x in v] for k, v in self.levels.items()}}


def decompose(result, route: str, radiation: str, torque: float, basis: str = "total") -> SlopeDecomposition:
    """The slope decomposition of one curve of a run-up (housingfe.runup.chain.RunupResult)."""
    ln = result.lines
    rr = result.routes[route]
    pts = [p for p, pt in enumerate(ln.points) if pt[0] == torque]
    renumber = np.full(len(ln.points), -1)
    renumber[pts] = np.arange(len(pts))
    sel = np.flatnonzero(renumber[ln.point] >= 0)
    bore = getattr(rr, "bore_force_db", None)
    moment = getattr(rr, "bore_moment_db", None)
    lv = term_levels(renumber[ln.point[sel]], len(pts), ln.harmonic[sel], ln.frequency[sel], rr.excitation_db[sel],
                     rr.L_v[sel], result.L_sigma[route, radiation][sel], result.area_level_db, basis,
                     None if bore is None else bore[sel], None if moment is None else moment[sel])
    speeds = np.array([ln.points[p][1] for p in pts])
    return SlopeDecomposition(route, radiation, float(torque), basis, rr.excitation_name, rr.transfer_name, speeds,
                              lv)


def decompose_all(result) -> list[SlopeDecomposition]:
    """Every route x radiation x torque x basis of a run-up (routes without an excitation level are skipped)."""
    torques = sorted({pt[0] for pt in result.lines.points})
    return [decompose(result, route, rad, t, basis) for route, rr in result.routes.items()
            if rr.excitation_db is not None for rad in result.radiators for t in torques for basis in BASES]


SLOPE_COLUMNS = ("route", "radiation", "torque_nm", "basis", "term", "meaning", "slope_dB_per_doubling",
                 "level_at_250rpm_dB", "level_at_1500rpm_dB")


def slope_rows(decompositions) -> list[dict]:
    """One row per decomposition and term/sum (slope_terms.csv); the row 'sum of terms' is the check.  With the
    bore loads also the transfer's split (SPLIT), its check 'path + housing' and the bore levels (BORE_LEVELS)."""
    rows = []
    for d in decompositions:
        extra = ((*SPLIT, "path + housing", *(k for k in BORE_LEVELS if k in d.levels)) if d.has_split else ())
        for key in (*TERMS, "sum of terms", *SUMS, *extra):
            if key == "sum of terms":
                slope, meaning, lv = d.term_sum, f"residual to L_WA {d.sum_residual_db:.2e} dB", None
            elif key == "path + housing":
                slope = d.slopes["transfer_path"] + d.slopes["transfer_housing"]
                meaning, lv = f"residual to the transfer {d.split_residual_db:.2e} dB", None
            else:
                slope = d.slopes[key]
                meaning = (d.label(key) if key in TERMS or key in TERM_LABELS
                           else {"L_v": "L_v", "L_W": "L_W", "L_WA": "L_WA"}[key])
                lv = d.levels[key]

            def at(s):
                if lv is None or s not in d.speeds_rpm:
                    return float("nan")
                return float(lv[np.flatnonzero(d.speeds_rpm == s)[0]])

            rows.append({"route": d.route, "radiation": d.radiation, "torque_nm": d.torque_nm, "basis": d.basis,
                         "term": key, "meaning": meaning, "slope_dB_per_doubling": slope,
                         "level_at_250rpm_dB": at(250.0), "level_at_1500rpm_dB": at(1500.0)})
    return rows


def table(decompositions) -> str:
    """The slopes as a text table (one row per curve and basis, one column per term)."""
    from housingfe.outputs import format_table

    split = any(d.has_split for d in decompositions)
    head = ["route", "radiation", "N m", "basis", *(t for t in TERMS if t != "L_S"), "sum", "L_W", "L_WA",
            "made by", "held back by", *(("T path", "T housing") if split else ())]
    rows = [[d.route, d.radiation, f"{d.torque_nm:g}", d.basis, *(round(d.slopes[t], 2) for t in TERMS if t != "L_S"),
             round(d.term_sum, 2), round(d.slopes["L_W"], 2), round(d.slopes["L_WA"], 2), d.made_by, d.held_back_by or "-",
             *((round(d.slopes[k], 2) if d.has_split else "-" for k in SPLIT) if split else ())]
            for d in decompositions]
    return ("slope over speed, dB per doubling, 250-1500 rpm (terms add up to L_WA; L_S is constant"
            + ("; T path + T housing = transfer: L_bore - excitation, L_v - L_bore" if split else "") + "):\n"
            + format_table(head, rows))


def plot(path, decompositions) -> None:
    """Per route: each term's level over speed relative to its value at the lowest speed in the range (total and
    tooth band), and a bar chart of the slopes."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    curves = [d for d in decompositions if d.radiation == decompositions[0].radiation]
    if not any(np.isfinite(d.slopes["L_WA"]) for d in curves):
        return                                  # no speed law to draw (less than a doubling of speed)
    keys = sorted({(d.route, d.torque_nm) for d in curves})
    fig, axes = plt.subplots(len(keys), 3, figsize=(15, 3.8 * len(keys)), squeeze=False)
    names = (*(t for t in TERMS if t != "L_S"), "L_W", "L_WA")
    for row, (route, torque) in enumerate(keys):
        by_basis = {d.basis: d for d in curves if d.route == route and d.torque_nm == torque}
        for col, basis in enumerate(BASES):
            d = by_basis[basis]
            ax = axes[row, col]
            s = d.speeds_rpm
            sel = (s >= SPEED_LAW_RANGE_RPM[0]) & (s <= SPEED_LAW_RANGE_RPM[1])
            if not np.any(sel):
                continue
            for j, t in enumerate(names):
                v = d.levels[t][sel]
                ax.plot(s[sel], v - v[0], "-" if t in TERMS else "--", color=f"C{j}",
                        lw=2.2 if t == "L_WA" else 1.2, label=f"{d.label(t) if t in TERMS else t} "
                        f"({d.slopes[t]:+.1f})")
            ax.set_xscale("log", base=2)
            ax.set_xlabel("pinion speed (rev/min)")
            ax.set_ylabel(f"level - level at {s[sel][0]:g} rpm (dB)")
            ax.set_title(f"{route}, {torque:g} N m, {basis.replace('_', ' ')} (dB per doubling)", fontsize=9)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7)
        ax = axes[row, 2]
        bars = names + (SPLIT if all(by_basis[b].has_split for b in BASES) else ())
        x = np.arange(len(bars))
        for j, basis in enumerate(BASES):
            d = by_basis[basis]
            ax.bar(x + (j - 0.5) * 0.38, [d.slopes[t] for t in bars], 0.38, label=basis.replace("_", " "))
        ax.axhline(6.0, color="r", ls="--", lw=0.8, label="measured L_WA speed law, 6 dB(A)")
        ax.set_xticks(x, [{"transfer_path": "T path", "transfer_housing": "T housing"}.get(t, t) for t in bars],
                      rotation=20, fontsize=8)
        ax.set_ylabel("slope (dB per doubling)")
        ax.set_title(f"{route}, {torque:g} N m: slopes, 250-1500 rpm", fontsize=9)
        ax.grid(True, axis="y", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
