"""`housingfe bench runup`: time and error of the noise chain end to end (issue 14), on the test-gearbox-runup scene.

Sections (all on the scene's coupled gearbox: gear set A, ball bearings, 2000 N m, routes tf_omega and mesh_force,
radiators erp + Föller; --quick: a 50 mm housing mesh, 6 speeds, lines to 2 kHz, 1 repetition, direct solve at
1500 rpm only):

1. end to end, stage by stage: mesh (housing meshed for 4 kHz, assembly), coupling, modal basis (to 1.5 x 4 kHz),
   Ritz reduction, source (lumped model over speed, stiffness curve included), response (both routes), radiation;
2. the run-up alone once the basis exists (source lines + both routes + erp/Föller), repeated: min/median/max;
3. numerical sigma (Rayleigh integral plate by plate, the scene's [radiation] plates) timed separately: the Ritz
   reduction that keeps its facet points, its share of the run-up, and L_WA against erp / Föller;
4. reuse of the basis (chain.with_drivetrain: Rayleigh-Ritz re-analysis) for 1000 N m and for gear set B, against a
   fresh model (coupling + basis + reduction): time, lowest elastic frequencies, L_WA over speed;
5. the Ritz route against a DIRECT solve (housingfe.response.harmonic.harmonic_response, solver="direct") at a few
   speeds, all tooth-harmonic lines up to f_max, mesh_force route, both with hysteretic damping eta = 0.08 (the
   modal xi = 0.04 of the scene has no direct counterpart): L_v per line and per speed (energy sum of the lines).

Run with `housingfe bench runup [--quick]` or `python -m housingfe.benchmarks.runup [--quick] [out_dir]`.
Writes bench_runup.csv (the summary), bench_runup_split.csv, bench_runup_direct.csv (per line),
bench_runup_speed.csv (L_WA over speed of every variant) and bench_runup.png.
"""
from __future__ import annotations

import os
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from housingfe.outputs import atomic_output_dir, format_table, write_csv

SCENE = "test-gearbox-runup"
ETA_DIRECT = 0.08                  # hysteretic loss factor of the Ritz-vs-direct comparison
N_FREQUENCIES = 15                 # lowest elastic frequencies compared after a re-analysis
TARGET_RUNUP_S = 10.0              # issue 14: a 30-speed run-up once the basis exists
TARGET_END_TO_END_S = 120.0        # issue 14: end to end with sigma = 1 or Föller


def _energy_total(values_db) -> float:
    """Energy sum (dB) of levels (dB)."""
    return float(10.0 * np.log10(np.sum(10.0 ** (np.asarray(values_db, float) / 10.0))))


def _lwa_series(result, route: str, radiator: str, torque: float) -> np.ndarray:
    return result.series(route, radiator, torque, "LwA_dB")[1]


def _setup(quick: bool):
    """The scene, its housing scene, drivetrains and options (the --quick overrides applied)."""
    from housingfe.runup.scene import drivetrain_of, load_runup_scene
    from housingfe.scene import load_housing_scene

    # --quick: a coarse housing, 6 speeds, lines to 2 kHz (basis to 3 kHz) so that it runs in under a minute
    overrides = ['housing.set=["mesh.size=0.05"]', "runup.speed_min_rpm=250.0", "runup.speed_step_rpm=250.0",
                 "runup.f_max_hz=2000.0"] if quick else []
    scene, _ = load_runup_scene(SCENE, overrides)
    housing_scene, _ = load_housing_scene(scene.housing.scene, list(scene.housing.set))
    torque = max(scene.runup.torques_nm)
    return scene, housing_scene, drivetrain_of(scene.drivetrain, torque, scene.runup.drive_line_model), torque


# ------------------------------------------------------------------------------------------------ sections
def end_to_end(scene, housing_scene, drivetrain, torque, comm) -> dict:
    """Section 1: every stage of the run-up timed on its own (s); returns the model, source, lines, result."""
    from housingfe.runup.chain import build_gearbox_model, runup, source_lines
    from housingfe.runup.scene import housing_model_for, radiators_of

    spec = scene.runup
    t_start = time.perf_counter()
    t0 = time.perf_counter()
    housing_model = housing_model_for(housing_scene, spec.f_max_hz, comm)
    radiators = radiators_of(scene.radiation, housing_model)
    mesh_s = time.perf_counter() - t0
    mesh_split = dict(housing_model.timings)
    gm = build_gearbox_model(housing_model, drivetrain, spec.f_max_hz, damping_ratio=spec.damping_ratio,
                             basis_factor=spec.basis_factor, radiators=radiators, surface=spec.surface)
    t0 = time.perf_counter()
    source = drivetrain.source_model(harmonics=spec.harmonics, engagement=spec.engagement)
    lines, _ = source_lines(source, spec.speeds, [torque], spec.f_max_hz)
    source_s = time.perf_counter() - t0
    result = runup(gm, None, spec.speeds, [torque], routes=tuple(spec.routes), lines=lines)
    total_s = time.perf_counter() - t_start
    split = {"mesh": mesh_s, "coupling": gm.timings["coupling_s"], "basis": gm.timings["basis_s"],
             "Ritz reduction": gm.timings["reduction_s"], "source": source_s,
             "response": result.timings["response_s"], "radiation": result.timings["radiation_s"]}
    return {"model": gm, "housing_model": housing_model, "source": source, "lines": lines, "result": result,
            "split": split, "total_s": total_s, "mesh_split": mesh_split,
            "reduction_split": dict(gm.reduction.timings)}


def runup_alone(gm, source, scene, torque, repetitions: int) -> dict:
    """Section 2: the run-up (source lines + routes + radiators) on an existing model, repeated (s)."""
    from housingfe.runup.chain import runup

    spec = scene.runup
    walls, parts = [], []
    for _ in range(repetitions):
        t0 = time.perf_counter()
        res = runup(gm, source, spec.speeds, [torque], routes=tuple(spec.routes))
        walls.append(time.perf_counter() - t0)
        parts.append(res.timings)
    return {"walls": np.array(walls), "timings": parts, "lines": len(res.lines.frequency)}


def numerical_sigma(gm, scene, torque, lines) -> dict:
    """Section 3: a Ritz reduction that keeps the numerical radiator's facet points (same basis and loads), the
    30-speed run-up with erp, Föller and numerical; L_WA maxima per radiator."""
    from housingfe.radiation.radiators import RADIATORS
    from housingfe.response.reduced import RitzReduction
    from housingfe.runup.chain import bearing_pairs, runup, unit_loads, with_reduction

    spec = scene.runup
    t0 = time.perf_counter()
    numerical = RADIATORS["numerical"].from_spec(scene.radiation, gm.housing_model.housing,
                                                 gm.housing_model.material)
    extra = {}
    radiators = {**gm.radiators, "numerical": numerical}
    for radiator in radiators.values():
        extra.update(radiator.extra_points(gm.structure))
    points_s = time.perf_counter() - t0
    loads, wheel, _ = unit_loads(gm.structure, gm.drivetrain)
    t0 = time.perf_counter()
    reduction = RitzReduction(gm.basis, loads, gm.reduction.damping, surface=spec.surface, nodes=(wheel,),
                              extra_points=extra, static_vectors=bearing_pairs(gm.structure))
    reduction_s = time.perf_counter() - t0
    gm_num = with_reduction(replace(gm, radiators=radiators), reduction)
    t0 = time.perf_counter()
    res = runup(gm_num, None, spec.speeds, [torque], routes=tuple(spec.routes), lines=lines)
    wall = time.perf_counter() - t0
    maxima = {}
    for route in spec.routes:
        for rad in radiators:
            speeds, lwa = res.series(route, rad, torque, "LwA_dB")
            k = int(np.argmax(lwa))
            maxima[route, rad] = (float(lwa[k]), float(speeds[k]))
    return {"result": res, "points": int(len(numerical.points.weights)), "points_s": points_s,
            "reduction_s": reduction_s, "reduction_split": dict(reduction.timings), "runup_s": wall,
            "radiation_numerical_s": res.timings.get("radiation_numerical_s", float("nan")),
            "radiation_other_s": sum(v for k, v in res.timings.items()
                                     if k.startswith("radiation_") and k not in ("radiation_s",
                                                                                 "radiation_numerical_s")),
            "maxima": maxima, "lines": len(lines.frequency)}


def reuse(gm, scene, label: str, drivetrain, source, torque, base_source_s: float | None = None) -> dict:
    """Section 4: re-analysis on the model's Ritz vectors against a fresh model for another drivetrain."""
    from housingfe.runup.chain import build_gearbox_model, runup, source_lines, with_drivetrain

    spec = scene.runup
    t0 = time.perf_counter()
    m_re = with_drivetrain(gm, drivetrain)
    re_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    fresh = build_gearbox_model(gm.housing_model, drivetrain, spec.f_max_hz, damping_ratio=spec.damping_ratio,
                                basis_factor=spec.basis_factor, radiators=gm.radiators, surface=spec.surface)
    fresh_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    lines, _ = source_lines(source, spec.speeds, [torque], spec.f_max_hz)
    source_s = time.perf_counter() - t0
    res_re = runup(m_re, None, spec.speeds, [torque], routes=tuple(spec.routes), lines=lines)
    res_fresh = runup(fresh, None, spec.speeds, [torque], routes=tuple(spec.routes), lines=lines)
    n = fresh.basis.rigid_count
    exact = fresh.basis.frequencies_hz[n:n + N_FREQUENCIES]
    approx = m_re.reduction.frequencies_hz[n:n + len(exact)]
    freq_err = float(np.max(np.abs(approx / exact - 1.0)))
    lwa = {}
    for route in spec.routes:
        for rad in gm.radiators:
            a = _lwa_series(res_re, route, rad, torque)
            b = _lwa_series(res_fresh, route, rad, torque)
            lwa[route, rad] = float(np.max(np.abs(a - b)))
    lv_line = max(float(np.max(np.abs(res_re.routes[r].L_v - res_fresh.routes[r].L_v))) for r in spec.routes)
    return {"label": label, "torque": torque, "reanalysis_s": re_s, "fresh_s": fresh_s,
            "fresh_split": {k: fresh.timings[k] for k in ("coupling_s", "basis_s", "reduction_s")},
            "source_s": source_s, "freq_err": freq_err, "freq_worst_hz": float(exact[np.argmax(np.abs(
                approx / exact - 1.0))]), "n_freq": len(exact), "lwa": lwa, "lv_line": lv_line,
            "res_re": res_re, "res_fresh": res_fresh}


def ritz_vs_direct(gm, source, scene, torque, speeds) -> dict:
    """Section 5: mesh_force route with hysteretic eta on the Ritz reduction (same basis, unit loads and static
    vectors as the model) against the direct solve of the coupled structure, line by line."""
    from housingfe.response.harmonic import Load, harmonic_response, loss_factor
    from housingfe.response.reduced import RitzReduction
    from housingfe.runup.chain import bearing_pairs, source_lines, unit_loads

    spec = scene.runup
    loads, wheel, _ = unit_loads(gm.structure, gm.drivetrain)
    t0 = time.perf_counter()
    reduction = RitzReduction(gm.basis, loads, loss_factor(ETA_DIRECT), surface=spec.surface, nodes=(wheel,),
                              static_vectors=bearing_pairs(gm.structure))
    reduction_s = time.perf_counter() - t0
    rows, ritz_s, direct_s = [], 0.0, 0.0
    for speed in speeds:
        lines, _ = source_lines(source, [speed], [torque], spec.f_max_hz)
        f, amps = lines.frequency, lines.mesh_excitation
        t0 = time.perf_counter()
        lv_ritz = reduction.evaluate(f, {"mesh": amps}).velocity_level_db
        t_ritz = time.perf_counter() - t0
        t0 = time.perf_counter()
        # one speed per call: the lines of one speed have distinct frequencies, so the table spectrum is exact
        direct = harmonic_response(gm.structure, Load("mesh", loads["mesh"], spectrum=(f, amps)),
                                   loss_factor(ETA_DIRECT), f, surface=spec.surface, solver="direct")
        lv_direct = np.asarray(direct.velocity_level_db, float)
        t_direct = time.perf_counter() - t0
        ritz_s += t_ritz
        direct_s += t_direct
        for k in range(len(f)):
            rows.append({"speed_rpm": float(speed), "harmonic": int(lines.harmonic[k]), "frequency_hz": float(f[k]),
                         "Lv_ritz_dB": float(lv_ritz[k]), "Lv_direct_dB": float(lv_direct[k]),
                         "error_dB": float(lv_ritz[k] - lv_direct[k])})
    per_speed = []
    for speed in speeds:
        sel = [r for r in rows if r["speed_rpm"] == float(speed)]
        a = _energy_total([r["Lv_ritz_dB"] for r in sel])
        b = _energy_total([r["Lv_direct_dB"] for r in sel])
        per_speed.append({"speed_rpm": float(speed), "lines": len(sel),
                          "max_line_error_dB": float(max(abs(r["error_dB"]) for r in sel)),
                          "Lv_total_ritz_dB": a, "Lv_total_direct_dB": b, "total_error_dB": a - b})
    n = len(rows)
    return {"rows": rows, "per_speed": per_speed, "reduction_s": reduction_s, "ritz_per_line_s": ritz_s / n,
            "direct_per_line_s": direct_s / n, "lines": n, "dofs": int(gm.structure.dofs)}


# ------------------------------------------------------------------------------------------------ output
def _plot(path: Path, e2e: dict, num: dict, reuses: list, rvd: dict, scene, torque) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(13, 9))
    ax = axes[0, 0]
    left = 0.0
    colours = plt.cm.tab10(np.arange(len(e2e["split"])))
    for (name, secs), c in zip(e2e["split"].items(), colours):
        ax.barh([0], [secs], left=left, color=c, label=f"{name} {secs:.1f} s")
        left += secs
    ax.set_yticks([])
    ax.set_xlabel("wall time [s]")
    ax.set_title(f"end to end {e2e['total_s']:.0f} s (stages)")
    ax.legend(fontsize=7, loc="upper right")
    ax = axes[0, 1]
    for speed in sorted({r["speed_rpm"] for r in rvd["rows"]}):
        sel = [r for r in rvd["rows"] if r["speed_rpm"] == speed]
        ax.plot([r["frequency_hz"] for r in sel], [r["error_dB"] for r in sel], "o-", ms=3, label=f"{speed:g} rpm")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlabel("line frequency [Hz]")
    ax.set_ylabel("L_v Ritz - direct [dB]")
    ax.set_title(f"mesh_force route, eta = {ETA_DIRECT:g}: Ritz vs direct per line")
    ax.legend(fontsize=7)
    ax = axes[1, 0]
    res = num["result"]
    route = scene.runup.routes[-1]
    for rad in res.radiators:
        s, v = res.series(route, rad, torque, "LwA_dB")
        ax.plot(s, v, label=f"{route}, {rad}")
    ax.set_xlabel("pinion speed [rpm]")
    ax.set_ylabel("L_WA [dB(A) re 1 pW]")
    ax.set_title("radiators side by side")
    ax.legend(fontsize=7)
    ax = axes[1, 1]
    for r in reuses:
        for route in scene.runup.routes:
            s, a = r["res_re"].series(route, "erp", r["torque"], "LwA_dB")
            _, b = r["res_fresh"].series(route, "erp", r["torque"], "LwA_dB")
            ax.plot(s, a - b, label=f"{r['label']}, {route}")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlabel("pinion speed [rpm]")
    ax.set_ylabel("L_WA re-analysed - fresh [dB]")
    ax.set_title("reuse of the basis (Rayleigh-Ritz) vs a fresh model")
    ax.legend(fontsize=7)
    fig.suptitle("housingfe bench runup: test-gearbox-runup")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(out_dir: Path, quick: bool) -> None:
    """Run the run-up benchmark; print the tables and write the CSVs and bench_runup.png."""
    from mpi4py import MPI

    from housingfe.runup.scene import drivetrain_of

    comm = MPI.COMM_WORLD
    load_before = os.getloadavg()
    t_bench = time.perf_counter()
    scene, housing_scene, drivetrain, torque = _setup(quick)
    spec = scene.runup
    repetitions = 1 if quick else 3
    direct_speeds = [1500.0] if quick else [500.0, 1000.0, 1500.0]

    from housingfe.progress import Progress

    # the sections of the table (docs/progress.md: every long command says how far it is)
    progress = Progress("bench runup", 6, "sections", comm=comm)
    e2e = end_to_end(scene, housing_scene, drivetrain, torque, comm)
    gm = e2e["model"]
    progress.update(note=f"end to end, {e2e['total_s']:.1f} s")
    alone = runup_alone(gm, e2e["source"], scene, torque, repetitions)
    progress.update(note="run-up alone")
    num = numerical_sigma(gm, scene, torque, e2e["lines"])
    progress.update(note="numerical sigma")
    other_torque = 1000.0
    reuses = [reuse(gm, scene, f"{other_torque:g} N m", drivetrain_of(scene.drivetrain, other_torque, spec.drive_line_model),
                    e2e["source"], other_torque)]
    progress.update(note=f"re-analysis at {other_torque:g} N m")
    spec_b = scene.drivetrain.model_copy(update={"gear_set": "B"})
    dt_b = drivetrain_of(spec_b, torque, spec.drive_line_model)
    t0 = time.perf_counter()
    source_b = dt_b.source_model(harmonics=spec.harmonics, engagement=spec.engagement)
    source_b_s = time.perf_counter() - t0
    reuses.append(reuse(gm, scene, "gear set B", dt_b, source_b, torque))
    reuses[-1]["source_s"] += source_b_s
    progress.update(note="re-analysis for gear set B")
    rvd = ritz_vs_direct(gm, e2e["source"], scene, torque, direct_speeds)
    progress.update(note=f"Ritz vs direct at {len(direct_speeds)} speed(s)")
    progress.close()
    load_after = os.getloadavg()
    bench_s = time.perf_counter() - t_bench
    if comm.rank != 0:
        return

    n_lines = len(e2e["lines"].frequency)
    n_speeds = len(spec.speeds)
    routes = ", ".join(spec.routes)
    rads = "+".join(gm.radiators)
    max_total_err = max(abs(p["total_error_dB"]) for p in rvd["per_speed"])
    max_line_err = max(p["max_line_error_dB"] for p in rvd["per_speed"])
    basis = gm.basis
    rows = []

    def row(section, case, wall, error, unit, note):
        rows.append([section, case, float(wall) if wall is not None else "-", float(error) if error is not None else "-", unit, note])

    sp, ms = e2e["split"], e2e["mesh_split"]
    row("1 end to end", f"mesh (housing for {spec.f_max_hz:g} Hz + assembly)", sp["mesh"], None, "",
        f"gmsh {ms.get('mesh_s', float('nan')):.1f} s, assembly {ms.get('assembly_s', float('nan')):.1f} s")
    row("1 end to end", "coupling (drivetrain on the bores)", sp["coupling"], None, "", "")
    row("1 end to end", f"modal basis ({len(basis.eigenvalues)} modes to {basis.f_max:g} Hz)", sp["basis"], None, "",
        f"{int(gm.structure.dofs)} DOFs, complete={bool(basis.complete)}")
    rs = e2e["reduction_split"]
    row("1 end to end", f"Ritz reduction ({len(gm.reduction.vectors)} vectors)", sp["Ritz reduction"], None, "",
        f"vectors {rs['ritz_vectors_s']:.1f} s, surface {rs['surface_reduction_s']:.1f} s, "
        f"projection {rs['projection_s']:.2f} s")
    row("1 end to end", f"source ({n_speeds} speeds, {n_lines} lines)", sp["source"], None, "",
        "stiffness curve included")
    row("1 end to end", f"response ({routes})", sp["response"], None, "", f"{n_lines} lines per route")
    row("1 end to end", f"radiation ({rads})", sp["radiation"], None, "", "")
    row("1 end to end", "total end to end", e2e["total_s"], max_total_err, "dB",
        f"target < {TARGET_END_TO_END_S:g} s: {'met' if e2e['total_s'] < TARGET_END_TO_END_S else 'NOT met'}; "
        "error: |L_v total| Ritz vs direct (sec. 5)")
    w = alone["walls"]
    row("2 run-up alone", f"{n_speeds}-speed run-up, min of {len(w)}", w.min(), None, "",
        f"source + {routes} + {rads}; target < {TARGET_RUNUP_S:g} s: "
        f"{'met' if np.median(w) < TARGET_RUNUP_S else 'NOT met'}")
    row("2 run-up alone", f"{n_speeds}-speed run-up, median of {len(w)}", float(np.median(w)), None, "",
        "stiffness curve cached from sec. 1")
    row("2 run-up alone", f"{n_speeds}-speed run-up, max of {len(w)}", w.max(), None, "", "")
    t_last = alone["timings"][-1]
    row("2 run-up alone", "  of which source / response / radiation (last)", None, None, "",
        f"{t_last.get('source_s', 0.0):.2f} / {t_last['response_s']:.2f} / {t_last['radiation_s']:.3f} s")
    mx = num["maxima"]
    nrs = num["reduction_split"]
    row("3 numerical sigma", f"Ritz reduction keeping {num['points']} facet points", num["reduction_s"], None, "",
        f"surface part {nrs['surface_reduction_s']:.1f} s vs {rs['surface_reduction_s']:.1f} s without "
        f"(+{nrs['surface_reduction_s'] - rs['surface_reduction_s']:.1f} s); points {num['points_s']:.2f} s")
    for route in spec.routes:
        d_erp = mx[route, "numerical"][0] - mx[route, "erp"][0]
        d_fol = mx[route, "numerical"][0] - mx[route, "foller"][0] if (route, "foller") in mx else float("nan")
        row("3 numerical sigma", f"max L_WA numerical - erp, {route}", None, d_erp, "dB",
            f"numerical {mx[route, 'numerical'][0]:.1f} dB(A) at {mx[route, 'numerical'][1]:g} rpm, "
            f"erp {mx[route, 'erp'][0]:.1f} at {mx[route, 'erp'][1]:g} rpm")
        row("3 numerical sigma", f"max L_WA numerical - foller, {route}", None, d_fol, "dB",
            f"foller {mx[route, 'foller'][0]:.1f} dB(A) at {mx[route, 'foller'][1]:g} rpm")
    row("3 numerical sigma", f"{n_speeds}-speed run-up with numerical sigma", num["runup_s"], None, "",
        f"numerical sigma {num['radiation_numerical_s']:.1f} s of it, erp+Föller {num['radiation_other_s']:.3f} s")
    for r in reuses:
        fs = r["fresh_split"]
        worst_lwa = max(r["lwa"].values())
        row("4 reuse", f"{r['label']}: re-analysis (Rayleigh-Ritz)", r["reanalysis_s"], r["freq_err"], "rel.",
            f"lowest {r['n_freq']} elastic f vs fresh basis (worst near {r['freq_worst_hz']:.0f} Hz); "
            "time incl. coupling")
        row("4 reuse", f"{r['label']}: fresh model", r["fresh_s"], None, "",
            f"coupling {fs['coupling_s']:.1f} + basis {fs['basis_s']:.1f} + reduction {fs['reduction_s']:.1f} s")
        row("4 reuse", f"{r['label']}: L_WA re-analysed vs fresh", r["source_s"], worst_lwa, "dB",
            f"max |dB| over speed, all routes and radiators; per line L_v {r['lv_line']:.2g} dB; time: source")
    row("5 Ritz vs direct", f"Ritz eta={ETA_DIRECT:g}, per line ({rvd['lines']} lines)", rvd["ritz_per_line_s"],
        max_line_err, "dB", f"max |L_v| per line; reduction built once in {rvd['reduction_s']:.1f} s")
    row("5 Ritz vs direct", "direct (MUMPS, 2x2 real block), per line", rvd["direct_per_line_s"], None, "",
        f"{rvd['dofs']} DOFs; speeds {', '.join(f'{s:g}' for s in direct_speeds)} rpm")
    row("5 Ritz vs direct", "Ritz vs direct, L_v total per speed", rvd["ritz_per_line_s"] * rvd["lines"],
        max_total_err, "dB", "max over speeds of |energy sum of the lines|")

    header = ["section", "case", "wall_s", "error", "unit", "note"]
    print(f"housingfe bench runup ({'quick' if quick else 'full'}): {SCENE}, {MPI.COMM_WORLD.size} MPI rank(s), "
          f"{os.cpu_count()} cores, torque {torque:g} N m, {n_speeds} speeds "
          f"{spec.speeds.min():g}-{spec.speeds.max():g} rpm, lines to {spec.f_max_hz:g} Hz")
    print(format_table(header, rows, floatfmt="{:.3g}"))
    print()
    ps_header = ["speed_rpm", "lines", "max_line_error_dB", "Lv_total_ritz_dB", "Lv_total_direct_dB",
                 "total_error_dB"]
    print(f"Ritz vs direct, mesh_force route, eta = {ETA_DIRECT:g} "
          f"(time per line: Ritz {rvd['ritz_per_line_s'] * 1e3:.2f} ms, direct {rvd['direct_per_line_s']:.2f} s):")
    print(format_table(ps_header, [[p[k] for k in ps_header] for p in rvd["per_speed"]], floatfmt="{:.3g}"))
    shared = not (load_before[0] < 0.5 and load_after[0] < 1.5)
    print(f"load average (1, 5, 15 min) before {load_before[0]:.2f} {load_before[1]:.2f} {load_before[2]:.2f}, "
          f"after {load_after[0]:.2f} {load_after[1]:.2f} {load_after[2]:.2f}: "
          + ("timings taken on a SHARED machine (other jobs running): treat them as upper bounds"
             if shared else "machine otherwise idle"))
    print(f"benchmark wall time {bench_s:.0f} s")

    with atomic_output_dir(out_dir) as tmp:
        write_csv(tmp / "bench_runup.csv", header, rows)
        write_csv(tmp / "bench_runup_split.csv", ["stage", "wall_s"],
                  [[k, v] for k, v in e2e["split"].items()] + [["total", e2e["total_s"]]])
        d_header = ["speed_rpm", "harmonic", "frequency_hz", "Lv_ritz_dB", "Lv_direct_dB", "error_dB"]
        write_csv(tmp / "bench_runup_direct.csv", d_header, [[r[k] for k in d_header] for r in rvd["rows"]])
        series = []
        for variant, res, tq in ([("base", num["result"], torque)]
                                 + [(f"{r['label']} re-analysed", r["res_re"], r["torque"]) for r in reuses]
                                 + [(f"{r['label']} fresh", r["res_fresh"], r["torque"]) for r in reuses]):
            for t in res.totals:
                series.append([variant, t["route"], t["radiation"], tq, t["speed_rpm"], t["LwA_dB"], t["Lv_dB"]])
        write_csv(tmp / "bench_runup_speed.csv",
                  ["variant", "route", "radiation", "torque_nm", "speed_rpm", "LwA_dB", "Lv_dB"], series)
        write_csv(tmp / "bench_runup_load.csv", ["when", "load_1min", "load_5min", "load_15min"],
                  [["before", *load_before], ["after", *load_after]])
        _plot(tmp / "bench_runup.png", e2e, num, reuses, rvd, scene, torque)
    print(f"results: {out_dir}/")


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--quick"]
    main(Path(args[0]) if args else Path("results/bench-runup"), quick="--quick" in sys.argv)
