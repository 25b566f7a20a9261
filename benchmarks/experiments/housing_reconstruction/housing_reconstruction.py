"""Can any open choice of the reconstructed `test-gearbox` housing move the mesh_force speed law into the measured
6 +/- 2 dB(A) per doubling (issue 28)?  One factor at a time from `test-gearbox-runup` (set A, ball bearings,
2000 N m), each variant a full run-up of the scene's chain with the housing changed through the run-up scene's
`housing.set` (docs/runup.md "Which term makes the speed law"; docs/housings.md "Ch. 5 test gearbox (full size)").

The reconstruction's open choices (published: the 10 mm walls and the 65 mm bearing plate, the plates' areas and
perimeters of Appendix E; everything below is assumed there, docs/housings.md):

* the split flange, modelled as a rim 37.5 x 37.5 mm scaled from the 80 % model: none / 50 x 50 mm;
* the wall thickness of a real housing against the nominal 10 mm: x 0.85 / x 1.15 (a casting's tolerance);
* the housing length: 0.52 m (what the table's thin front plates imply) instead of 0.49 m (its top);
* the bearing plate's split 0.129 below / 0.113 above the bores (the 80 % model's proportions): 0.121 / 0.121;
* the feet 75 x 31.25 mm (the 80 % model's x 1/0.8): 20 mm thick;
* no ribs: one pair of transverse ribs on the top plate.

Per variant: the housing's mass, the coupled modes (the run-up's complete basis) in 150-600 Hz and how many of them
are the housing's (interior kinetic-energy share < 0.5), the first housing mode, the modal overlap; per route max L_WA
and its speed, the L_WA slope over 250-1500 rev/min (the speed-law check's fit) and its terms (excitation, transfer =
T_path + T_housing, L_sigma, A-weighting) from the run's slope decomposition (housingfe.runup.slopes, as
slope_terms.csv of `housingfe run`).  Nothing is tuned: each variant's values are stated beside its results.

    PYTHONPATH=. /work/main/.venv/bin/python benchmarks/experiments/housing_reconstruction/housing_reconstruction.py \
        [--out DIR] [--coarse] [--only NAME ...]

Writes variants.csv, slopes.csv, modes.csv, housing_reconstruction.png, run.json.  No default of the package changes.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import re
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

SCENE = "test-gearbox-runup"
HOUSING = "test-gearbox"
TORQUE = 2000.0
ROUTES = ("mesh_force", "tf_omega")
MODAL_BAND_HZ = (150.0, 600.0)       # the tooth frequencies of 375-1500 rev/min: where the speed law is fitted
MODES_LISTED_HZ = 2000.0             # modes.csv and the picture: the coupled modes up to here
HOUSING_SHARE = 0.5                  # a coupled mode is the housing's when the interior holds < half its kinetic energy
T_HOUSING_NEEDED = 3.17              # benchmarks/experiments/first_mode: the T_housing the measured 6 would need
SPEED_LAW = (6.0, 2.0)               # measured slope and the check's tolerance (dB(A) per doubling)
RADIATION_THIN_PLATES = 9            # the run-up scene's radiation.plates 0..8 are the 10 mm walls (Foeller's sigma)
COARSE = ["mesh.size=0.06"]          # --coarse: 60 mm housing mesh, lines to 1.5 kHz (as first_mode --coarse)
L_DEFAULT, W_DEFAULT = 0.490, 0.170  # the scene's length and width (m)


def top_ribs(height: float = 0.030, thickness: float = 0.010, height_top: float = 0.3753) -> list[str]:
    """Two transverse ribs on the top plate (the largest thin panel, 0.49 x 0.17 m) at its third points x = +-L/6,
    across its full width, `height` (m) above the top, `thickness` (m) along x: TOML inline tables for
    geometry.ribs."""
    ribs = []
    for name, xc in (("top_pinion", -L_DEFAULT / 6), ("top_wheel", L_DEFAULT / 6)):
        ribs.append(f'{{name="{name}", x=[{xc - thickness / 2:.5f}, {xc + thickness / 2:.5f}], '
                    f'y=[{-W_DEFAULT / 2:.4f}, {W_DEFAULT / 2:.4f}], z=[{height_top:.4f}, {height_top + height:.4f}]}}')
    return [f"geometry.ribs=[{', '.join(ribs)}]"]


def wall(thickness: float) -> tuple[list[str], list[str]]:
    """(housing.set, run-up overrides) of a wall thickness (m): the housing's walls and the thin plates of Foeller's
    radiator (sigma = 1, the checks' radiator, does not use them)."""
    return ([f"geometry.wall_thickness={thickness}"],
            [f"radiation.plates.{i}.thickness={thickness}" for i in range(RADIATION_THIN_PLATES)])


@dataclass
class Variant:
    """One open choice of the reconstruction, changed alone: its name, the values changed (text), why a reader would
    accept the value, the housing scene's --set items, other run-up scene overrides, and whether the housing scene
    is the built-in one without its [geometry.rim] table (a table cannot be removed by --set)."""

    name: str
    changed: str
    why: str
    housing_set: list = field(default_factory=list)
    overrides: list = field(default_factory=list)
    no_rim: bool = False
    in_range: bool = True          # False: a what-if outside what a reader would accept (not in the answer)


def variants() -> list[Variant]:
    """The default and the one-factor variants (docs/housings.md "Ch. 5 test gearbox (full size)" for the defaults)."""
    thin, thick = wall(0.0085), wall(0.0115)
    return [
        Variant("default", "rim 37.5 x 37.5 mm, wall 10 mm, bearing plate 0.129 below / 0.113 above, feet 75 x "
                "31.25 mm, length 0.49 m, no ribs", "the built-in reconstruction (docs/housings.md)"),
        Variant("no rim", "rim removed (no split flange)",
                "the lower bound: the flange's section is not published; a split bolted through a thickened wall "
                "or an inside flange leaves no rim", no_rim=True),
        Variant("rim 50 x 50", "rim 50 x 50 mm (37.5 x 37.5)",
                "a bolted split flange for M16-M20 bolts needs about 2.5-3 bolt diameters of width; its height is "
                "both halves' flanges (2 x 25 mm): x 1.33 the default, still below the 65 mm bearing plate",
                ["geometry.rim.width=0.05", "geometry.rim.height=0.05"]),
        Variant("wall 8.5 mm", "wall 8.5 mm (10 mm x 0.85)",
                "-1.5 mm: a sand-cast 10 mm wall's deviation from nominal (ISO 8062-3: DCTG 10-12, +-1.0-2.1 mm "
                "for up to 10 mm); a rolled plate is held far closer", thin[0], thin[1]),
        Variant("wall 11.5 mm", "wall 11.5 mm (10 mm x 1.15)", "+1.5 mm, as above", thick[0], thick[1]),
        Variant("wall 5 mm (out of range)", "wall 5 mm (10 mm x 0.5): NOT an accepted range",
                "a what-if outside any tolerance, to show the direction: the top's first panel mode (simply "
                "supported, f proportional to t) moves from about 1.2 kHz to 0.6 kHz", *wall(0.005), in_range=False),
        Variant("length 0.52", "length 0.52 m (0.49); bearing plate and bores where they were (x_start 0.015 m)",
                "the Appendix E table's thin front plates imply a 0.52 m wide front; the 30 mm go to the thin "
                "walls, 15 mm at each end",
                ["geometry.length=0.52", "geometry.bearing_plate.x_start=0.015"]),
        Variant("plate 0.121 / 0.121", "bearing plate 0.121 below / 0.121 above the split (0.129 / 0.113)",
                "the published 0.242 m height centred on the bores, without the 80 % model's proportions",
                ["geometry.bearing_plate.below=0.121", "geometry.bearing_plate.above=0.121"]),
        Variant("feet 20 mm", "feet 75 x 20 mm (75 x 31.25)",
                "2 x the wall: the thin end of a welded foot strip; the 31.25 mm are the 80 % model's scaled",
                ["geometry.feet.thickness=0.020"]),
        Variant("top ribs", "two transverse ribs on the top, 10 mm x 30 mm, at x = -0.082 / +0.082 m, across its "
                "0.17 m (no ribs)",
                "the thesis shows none; a pair across the largest thin panel at its third points, as thick as the "
                "wall and 3 x as high, is the usual first stiffening", top_ribs()),
    ]


# ------------------------------------------------------------------------------------------------ one run
def no_rim_scene(folder: Path) -> Path:
    """The built-in housing scene without its [geometry.rim] table, written to `folder` (its path)."""
    from housingfe.scenefile import resolve_scene_path

    text = resolve_scene_path(HOUSING).read_text()
    new, n = re.subn(r"\[geometry\.rim\]\nwidth = [^\n]*\nheight = [^\n]*\n", "", text)
    if n != 1:
        raise RuntimeError(f"{HOUSING}: expected one [geometry.rim] table with width and height, found {n}")
    path = folder / f"{HOUSING}-no-rim.toml"
    path.write_text(new)
    return path


def scene_overrides(v: Variant, coarse: bool, folder: Path) -> list[str]:
    """The run-up scene's overrides of a variant (housing.set as a TOML array; JSON strings are TOML strings)."""
    housing_set = (COARSE if coarse else []) + list(v.housing_set)
    out = [f"housing.set={json.dumps(housing_set)}"] if housing_set else []
    if v.no_rim:
        out.append(f"housing.scene={json.dumps(str(no_rim_scene(folder)))}")
    out += list(v.overrides)
    if coarse:
        out.append("runup.f_max_hz=1500.0")
    return out


def modal_summary(model, xi: float) -> tuple[dict, list[dict]]:
    """(summary, rows) of the coupled basis: elastic modes, their interior kinetic-energy shares; in MODAL_BAND_HZ the
    number of modes, of housing modes (share < HOUSING_SHARE), the modal overlap M = n eta f at the band's
    geometric centre (n = count / band width, eta = 2 xi; xi the modal damping ratio)."""
    basis = model.basis
    fr = np.asarray(basis.frequencies_hz[basis.rigid_count:], float)
    share = np.asarray(model.interior_share, float)
    lo, hi = MODAL_BAND_HZ
    inband = (fr >= lo) & (fr <= hi)
    housing = share < HOUSING_SHARE
    fc = math.sqrt(lo * hi)
    first_h = fr[housing]
    rows = [{"mode": i + 1, "frequency_Hz": float(f), "interior_share": float(s), "housing_mode": bool(s < HOUSING_SHARE)}
            for i, (f, s) in enumerate(zip(fr, share)) if f <= MODES_LISTED_HZ]
    return {"first_modes_Hz": " ".join(f"{f:.0f}" for f in fr[:4]),
            "first_housing_mode_Hz": float(first_h[0]) if len(first_h) else float("nan"),
            "housing_modes_to_2kHz_Hz": " ".join(f"{f:.0f}" for f in first_h[first_h <= MODES_LISTED_HZ]),
            "modes_150_600": int(inband.sum()), "housing_modes_150_600": int((inband & housing).sum()),
            "housing_modes_150_600_Hz": " ".join(f"{f:.0f}" for f in fr[inband & housing]),
            "modal_overlap_300Hz": inband.sum() / (hi - lo) * 2 * xi * fc, "modes_to_basis": int(len(fr)),
            "housing_mass_kg": float(model.housing_model.housing.volume * model.housing_model.material.density)}, rows


def panel_mode_hz(a: float, b: float, t: float, E: float, nu: float, rho: float) -> float:
    """First bending mode (Hz) of a simply supported flat plate a x b (m), thickness t (m), of E (Pa), nu, rho
    (kg/m^3): (pi/2) (1/a^2 + 1/b^2) sqrt(D / (rho t)), D = E t^3 / (12 (1 - nu^2))."""
    D = E * t ** 3 / (12 * (1 - nu ** 2))
    return math.pi / 2 * (1 / a ** 2 + 1 / b ** 2) * math.sqrt(D / (rho * t))


def top_panel_hz(session, model) -> float:
    """The analytic first mode of the top plate between the walls' inner faces (simply supported, ribs and rim
    ignored): the scale of the housing's thin-wall modes, for comparison with the FE's first housing mode."""
    from housingfe.scene import load_housing_scene

    hs, _ = load_housing_scene(session.scene.housing.scene, list(session.scene.housing.set))
    g, m = hs.geometry, model.housing_model.material
    t = g.wall_thickness
    return panel_mode_hz(g.length - 2 * t, g.width - 2 * t, t, m.youngs_modulus, m.poisson_ratio, m.density)


def route_rows(res, radiation: str) -> list[dict]:
    """Per route: max L_WA and its speed, the check's L_WA slope and the total basis' slope terms (dB per doubling),
    the tooth band's T_housing and L_WA, and the two identities' residuals."""
    from housingfe.runup import slopes
    from housingfe.runup.checks import speed_law_slope

    out = []
    for route in ROUTES:
        s, lwa = res.series(route, radiation, TORQUE, "LwA_dB")
        i = int(np.argmax(lwa))
        tot = slopes.decompose(res, route, radiation, TORQUE, "total")
        tb = slopes.decompose(res, route, radiation, TORQUE, "tooth_band")
        d = tot.slopes
        law = speed_law_slope(s, lwa)
        out.append({"route": route, "max_LWA_dBA": float(lwa[i]), "max_LWA_rpm": float(s[i]),
                    "speed_law": law, "speed_law_passes": abs(law - SPEED_LAW[0]) <= SPEED_LAW[1],
                    "excitation": d["excitation"], "transfer": d["transfer"], "T_path": d["transfer_path"],
                    "T_housing": d["transfer_housing"], "L_sigma": d["L_sigma"], "A_weighting": d["A_weighting"],
                    "L_WA": d["L_WA"], "L_bore": d["L_bore"],
                    "T_housing_tooth_band": tb.slopes["transfer_housing"], "L_WA_tooth_band": tb.slopes["L_WA"],
                    "sum_residual_dB": tot.sum_residual_db, "split_residual_dB": tot.split_residual_db})
    return out


def run_variant(v: Variant, coarse: bool, folder: Path) -> dict:
    """The scene's run-up (ChainSession, as `housingfe run`) with the variant's housing; its modal summary, modes and
    route rows, the overrides and wall times (s)."""
    from housingfe.studies.chain_session import ChainSession

    t0 = time.perf_counter()
    overrides = scene_overrides(v, coarse, folder)
    session = ChainSession.from_scene(SCENE, overrides)
    sc = session.scene.drivetrain
    dt = session.drivetrain(sc.gear_set, sc.bearings, TORQUE)
    model = session.model(dt, label=v.name)
    t1 = time.perf_counter()
    res = session.runup(model, TORQUE)
    t2 = time.perf_counter()
    summary, modes = modal_summary(model, session.spec.damping_ratio)
    summary["top_panel_ss_Hz"] = top_panel_hz(session, model)
    return {"variant": v, "overrides": overrides, "summary": summary, "modes": modes,
            "routes": route_rows(res, session.radiation), "radiation": session.radiation,
            "dofs": int(model.housing_model.dofs), "model_s": t1 - t0, "runup_s": t2 - t1}


# ------------------------------------------------------------------------------------------------ main
def main(argv=None):
    from housingfe.outputs import write_records

    names = [v.name for v in variants()]
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", default="/tmp/housing-reconstruction-exp")
    p.add_argument("--coarse", action="store_true", help="60 mm housing mesh, lines to 1.5 kHz (a quick look)")
    p.add_argument("--only", nargs="+", choices=names, metavar="NAME",
                   help=f"run only these variants (default: all): {', '.join(repr(n) for n in names)}")
    args = p.parse_args(argv)
    # --coarse leaves out the what-if outside the accepted ranges unless named: its 5 mm walls need a finer mesh than
    # 60 mm tetrahedra (mesh.size: element quality refused)
    chosen = [v for v in variants() if (v.name in args.only if args.only else v.in_range or not args.coarse)]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0, load0 = time.perf_counter(), os.getloadavg()
    runs = []
    with tempfile.TemporaryDirectory(prefix="housing-reconstruction-") as tmp:
        for v in chosen:
            r = run_variant(v, args.coarse, Path(tmp))
            runs.append(r)
            mf = next(x for x in r["routes"] if x["route"] == "mesh_force")
            print(f"{v.name}: {r['dofs']} DOFs, model {r['model_s']:.1f} s, run-up {r['runup_s']:.1f} s; "
                  f"modes {r['summary']['first_modes_Hz']} Hz, first housing mode "
                  f"{r['summary']['first_housing_mode_Hz']:.0f} Hz, {r['summary']['modes_150_600']} modes "
                  f"({r['summary']['housing_modes_150_600']} housing) in 150-600 Hz; mesh_force L_WA "
                  f"{mf['speed_law']:+.2f} = exc {mf['excitation']:+.2f} + T_path {mf['T_path']:+.2f} + T_housing "
                  f"{mf['T_housing']:+.2f} + L_sigma {mf['L_sigma']:+.2f} + A {mf['A_weighting']:+.2f}; max "
                  f"{mf['max_LWA_dBA']:.1f} dB(A) at {mf['max_LWA_rpm']:g} rpm", flush=True)
    vrows, srows, mrows = [], [], []
    base = next((r for r in runs if r["variant"].name == "default"), None)
    base_mf = None if base is None else next(x for x in base["routes"] if x["route"] == "mesh_force")
    for r in runs:
        v = r["variant"]
        vrows.append({"variant": v.name, "changed": v.changed, "why": v.why, "in_range": v.in_range,
                      "housing_dofs": r["dofs"],
                      **r["summary"], "model_s": r["model_s"], "runup_s": r["runup_s"]})
        for x in r["routes"]:
            d = {} if base is None else {
                "d_speed_law": x["speed_law"] - next(y for y in base["routes"] if y["route"] == x["route"])["speed_law"],
                "d_T_housing": x["T_housing"] - next(y for y in base["routes"] if y["route"] == x["route"])["T_housing"]}
            srows.append({"variant": v.name, **x, **d})
        mrows += [{"variant": v.name, **m} for m in r["modes"]]
    write_records(out / "variants.csv", vrows)
    write_records(out / "slopes.csv", srows)
    write_records(out / "modes.csv", mrows)
    _table(srows, vrows)
    answer = {}
    if base_mf is not None:
        accepted = {r["variant"].name for r in runs if r["variant"].in_range}
        mf_rows = [x for x in srows if x["route"] == "mesh_force" and x["variant"] != "default"
                   and x["variant"] in accepted]
        if mf_rows:
            most = max(mf_rows, key=lambda x: abs(x["d_speed_law"]))
            most_h = max(mf_rows, key=lambda x: abs(x["d_T_housing"]))
            answer = {"default_speed_law": base_mf["speed_law"], "default_T_housing": base_mf["T_housing"],
                      "T_housing_needed": T_HOUSING_NEEDED,
                      "variants_in_6_pm_2": [x["variant"] for x in mf_rows if x["speed_law_passes"]],
                      "moves_speed_law_most": [most["variant"], most["speed_law"], most["d_speed_law"]],
                      "moves_T_housing_most": [most_h["variant"], most_h["T_housing"], most_h["d_T_housing"]],
                      "T_housing_range": [min(x["T_housing"] for x in mf_rows), max(x["T_housing"] for x in mf_rows)],
                      "speed_law_range": [min(x["speed_law"] for x in mf_rows), max(x["speed_law"] for x in mf_rows)],
                      "out_of_range": {x["variant"]: [x["speed_law"], x["T_housing"]] for x in srows
                                       if x["route"] == "mesh_force" and x["variant"] not in accepted}}
            print("answer", json.dumps(answer))
    _plot(out / "housing_reconstruction.png", srows, mrows, [r["variant"].name for r in runs])
    wall_s = time.perf_counter() - t0
    json.dump({"coarse": args.coarse, "scene": SCENE, "torque_nm": TORQUE, "radiation": runs[0]["radiation"],
               "variants": [{"name": r["variant"].name, "changed": r["variant"].changed, "overrides": r["overrides"],
                             "model_s": r["model_s"], "runup_s": r["runup_s"]} for r in runs],
               "answer": answer, "wall_s": wall_s, "loadavg_start": load0, "loadavg_end": os.getloadavg()},
              open(out / "run.json", "w"), indent=1)
    print(f"wall {wall_s:.0f} s; wrote {out}")
    return {"variants": vrows, "slopes": srows, "modes": mrows, "answer": answer}


def _table(srows, vrows) -> None:
    """The mesh_force rows as a Markdown table (the README's)."""
    by = {v["variant"]: v for v in vrows}
    print("| variant | housing kg | top panel (s.s.) Hz | first housing mode Hz | modes (housing) 150-600 Hz | max L_WA dB(A) @ rpm | "
          "L_WA slope | excitation | T_path | T_housing | L_sigma | A | tf_omega L_WA slope |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for x in srows:
        if x["route"] != "mesh_force":
            continue
        v = by[x["variant"]]
        tf = next(y for y in srows if y["variant"] == x["variant"] and y["route"] == "tf_omega")
        print(f"| {x['variant']} | {v['housing_mass_kg']:.1f} | {v['top_panel_ss_Hz']:.0f} | "
              f"{v['first_housing_mode_Hz']:.0f} | "
              f"{v['modes_150_600']} ({v['housing_modes_150_600']}) | {x['max_LWA_dBA']:.1f} @ {x['max_LWA_rpm']:g} | "
              f"**{x['speed_law']:.2f}** | {x['excitation']:+.2f} | {x['T_path']:+.2f} | **{x['T_housing']:+.2f}** | "
              f"{x['L_sigma']:+.2f} | {x['A_weighting']:+.2f} | {tf['speed_law']:.2f} |")


def _plot(path, srows, mrows, names) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(15, 5.2), gridspec_kw={"width_ratios": [1.6, 1]})
    ax = axes[0]
    terms = (("excitation", "excitation L_F"), ("T_path", "T_path"), ("T_housing", "T_housing"),
             ("L_sigma", "L_sigma"), ("A_weighting", "A-weighting"))
    x = np.arange(len(names))
    width = 0.8 / len(terms)
    mf = {r["variant"]: r for r in srows if r["route"] == "mesh_force"}
    for k, (key, label) in enumerate(terms):
        ax.bar(x + (k - (len(terms) - 1) / 2) * width, [mf[n][key] for n in names], width, label=label)
    ax.plot(x, [mf[n]["speed_law"] for n in names], "kD", ms=7, label="= L_WA slope (speed law)")
    ax.axhspan(SPEED_LAW[0] - SPEED_LAW[1], SPEED_LAW[0] + SPEED_LAW[1], color="g", alpha=0.12,
               label="measured L_WA 6 +/- 2")
    ax.axhline(T_HOUSING_NEEDED, color="r", ls="--", lw=1, label=f"T_housing the measured 6 needs (+{T_HOUSING_NEEDED})")
    ax.axhline(20 * math.log10(2), color="grey", ls=":", lw=1, label="stiffness control +6.02")
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xticks(x)
    ax.set_xticklabels(names, rotation=25, ha="right", fontsize=8)
    ax.set_ylabel("mesh_force, dB per doubling of speed (250-1500 rpm)")
    ax.set_title("slope terms per housing variant (sigma = 1, 2000 N m, total basis)")
    ax.set_ylim(-1.0, 13.5)
    ax.legend(fontsize=7, ncol=3, loc="upper center")
    ax = axes[1]
    for i, n in enumerate(names):
        rr = [m for m in mrows if m["variant"] == n]
        sc = ax.scatter([i] * len(rr), [m["frequency_Hz"] for m in rr], c=[m["interior_share"] for m in rr],
                        cmap="coolwarm", vmin=0, vmax=1, s=28, edgecolors="k", linewidths=0.3)
    ax.axhspan(*MODAL_BAND_HZ, color="y", alpha=0.15, label="150-600 Hz (tooth band of 375-1500 rpm)")
    fig.colorbar(sc, ax=ax, label="interior kinetic-energy share (blue: housing mode)")
    ax.set_xticks(np.arange(len(names)))
    ax.set_xticklabels(names, rotation=25, ha="right", fontsize=8)
    ax.set_ylim(0, MODES_LISTED_HZ)
    ax.set_ylabel("coupled mode (Hz)")
    ax.set_title(f"coupled modes to {MODES_LISTED_HZ / 1e3:g} kHz")
    ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
