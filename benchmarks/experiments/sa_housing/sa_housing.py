"""Why self-aligning bearings' HOUSING term has opposite signs on the two routes of `housingfe study bearings`.

variant_terms.csv (gear set B, 2000 N m, mean over 800-1500 rev/min of the difference to ball bearings) gives the
self-aligning configuration T_housing = L_v - L_bore +9.74 dB on route tf_omega and -4.66 dB on mesh_force.  The
housing is the same FE model on both routes; this script measures where the difference sits:

1. per tooth harmonic n (per line, 800-1500 rev/min): L_v, L_bore (bearing forces on the bores), L_bore_moment and
   the per-line T_housing of both routes and configurations, and each harmonic's share of the totals' power (the
   total basis' T_housing,tot = L_v,tot - L_bore,tot is a difference of two power sums: it compares the harmonics
   that carry L_v with those that carry L_bore);
2. at chosen lines: the bore loads per bearing and component (Fx, Fy = axial, Fz, Mx, My, Mz; global axes, y the
   shaft axis) of both routes, and the housing's own transfer from the bore loads to the surface, A = H^H G H
   (H = V E^-1 from unit loads on the bore masters of the coupled model, as benchmarks/experiments/film_mount
   `bores`): its diagonal (the surface <v^2> per unit load of each component) and what the forces alone, the moments
   alone, each bearing alone and each direction alone give of the route's L_v;
3. one-factor variants (Rayleigh-Ritz re-analyses on the ball basis, on the ball's source lines): the ball matrices
   with their moment rows and columns zeroed (the thesis' FE stand-in, Sec. 5.8); the ball moments with the
   spherical rollers' translational block; the ball matrices without their radial-axial couplings k_xz, k_yz;
   the ball matrices with the spherical rollers' radial 2x2 block.

    PYTHONPATH=. /work/main/.venv/bin/python benchmarks/experiments/sa_housing/sa_housing.py [--out DIR] [--coarse] [--no-variants]

Writes harmonics.csv (part 1 per configuration, route, harmonic), load_parts.csv and tooth_line_curves.csv (per
load part: the routes and mesh_force's two loads alone), terms.csv (the study's terms per variant and
route), bore_loads.csv and housing_split.csv (part 2), sa_housing.png, run.json.  Nothing in the package is changed.
"""
from __future__ import annotations

import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

from housingfe.outputs import write_records

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "bearing_ranking"))
import common  # noqa: E402
from runup_factors import Patched, gear_set_b_args  # noqa: E402  (Patched: a Drivetrain with its FE bearings patched)

TORQUE = 2000.0
MEAN_RANGE = (800.0, 1500.0)
ROUTES = ("tf_omega", "mesh_force")
COMPONENTS = ("Fx", "Fy", "Fz", "Mx", "My", "Mz")
PROBE_SPEEDS = (800.0, 1000.0, 1200.0, 1400.0, 1500.0)


def zero_radial_axial(K):
    """K (bearing frame, z = shaft axis) without its radial-axial couplings k_xz, k_yz."""
    K = K.copy()
    K[0, 2] = K[2, 0] = K[1, 2] = K[2, 1] = 0.0
    return K


def radial_block_of(other_spec):
    """fn(name, K): the radial 2x2 block (x, y of the bearing frame) of the same bearing in other_spec, the rest kept."""
    other = common.bearing_matrices(other_spec)

    def fn(name, K):
        K = K.copy()
        K[:2, :2] = np.array(other[name][0], float)[:2, :2]
        return K
    return fn


def energy_db(x) -> float:
    x = np.asarray(x, float)
    return float(10 * np.log10(np.sum(10 ** (x / 10)))) if x.size else float("nan")


def harmonic_rows(name, res) -> list[dict]:
    """Part 1: per route and harmonic over MEAN_RANGE: mean of the per-line levels and T_housing, and the
    harmonic's share of the per-speed totals' power of L_v and of L_bore (mean over the speeds)."""
    ln = res.lines
    keep = (ln.speed >= MEAN_RANGE[0]) & (ln.speed <= MEAN_RANGE[1])
    rows = []
    for route in ROUTES:
        rr = res.routes[route]
        pts = np.unique(ln.point[keep])
        tot_v = {p: np.sum(10 ** (rr.L_v[ln.point == p] / 10)) for p in pts}
        tot_b = {p: np.sum(10 ** (rr.bore_force_db[ln.point == p] / 10)) for p in pts}
        for n in np.unique(ln.harmonic[keep]):
            at = np.flatnonzero(keep & (ln.harmonic == n))
            share_v = np.mean([10 ** (rr.L_v[k] / 10) / tot_v[ln.point[k]] for k in at])
            share_b = np.mean([10 ** (rr.bore_force_db[k] / 10) / tot_b[ln.point[k]] for k in at])
            rows.append({"config": name, "route": route, "harmonic": int(n),
                         "f_lo_Hz": float(ln.frequency[at].min()), "f_hi_Hz": float(ln.frequency[at].max()),
                         "excitation_dB": float(np.mean(rr.excitation_db[at])),
                         "L_v_dB": float(np.mean(rr.L_v[at])), "L_bore_dB": float(np.mean(rr.bore_force_db[at])),
                         "L_bore_moment_dB": float(np.mean(rr.bore_moment_db[at])),
                         "T_path_dB": float(np.mean(rr.bore_force_db[at] - rr.excitation_db[at])),
                         "T_housing_dB": float(np.mean(rr.L_v[at] - rr.bore_force_db[at])),
                         "share_of_Lv_total": float(share_v), "share_of_Lbore_total": float(share_b)})
    return rows


PARTS = ("tf_omega", "mesh_force", "mesh pair only", "shuttling moment only")


CURVES = {}      # (config, part) -> (speeds, T_housing, axial - radial) on the tooth line, for the figure


def load_part_rows(name, model, res) -> list[dict]:
    """Per load part (PARTS: the two routes, and the mesh_force route's two loads alone, each at its own amplitude
    of the run-up's lines) over MEAN_RANGE, on the tooth line (harmonic "1", mean of the per-line values) and on
    the per-speed totals ("total", mean over the speeds): L_v, L_bore, its axial (Fy) and radial (Fx, Fz) parts,
    L_bore_moment and T_housing = L_v - L_bore.  tf_omega scaled as the route scales it (to the source's L_omega)."""
    from housingfe import levels
    from housingfe.runup.chain import line_coefficients, route_bore_loads

    ln = res.lines
    keep = (ln.speed >= MEAN_RANGE[0]) & (ln.speed <= MEAN_RANGE[1])
    idx = np.flatnonzero(keep)
    f, sp = ln.frequency[idx], ln.speed[idx]
    amps = ln.mesh_amplitudes()
    sols = {}
    for part in PARTS:
        if part in ROUTES:
            rr = res.routes[part]
            c = rr.coefficients[:, idx]
            shift = (rr.L_v - rr.response.velocity_level_db)[idx]
        else:
            key = "mesh" if part == "mesh pair only" else "shuttle"
            a = {key: np.asarray(amps[key])[idx]}
            c = line_coefficients(model, f, sp, a)
            shift = np.zeros(len(idx))
        lv = model.reduction.response_of(f, c).velocity_level_db + shift
        bl = route_bore_loads(model, f, sp, c)

        def lev(sel):
            return levels.level(np.sum(np.abs(bl[..., sel]) ** 2, axis=(-2, -1)), levels.F0) + shift
        sols[part] = {"L_v": lv, "L_bore": lev([0, 1, 2]), "L_bore_axial": lev([1]), "L_bore_radial": lev([0, 2]),
                      "L_bore_moment": lev([3, 4, 5])}
    rows = []
    h = ln.harmonic[idx]
    pts = ln.point[idx]
    for part, d in sols.items():
        t = h == 1
        CURVES[name, part] = (sp[t], (d["L_v"] - d["L_bore"])[t], (d["L_bore_axial"] - d["L_bore_radial"])[t])
        for basis in ("1", "total"):
            row = {"config": name, "part": part, "harmonic": basis}
            for k, v in d.items():
                if basis == "1":
                    row[k + "_dB"] = float(np.mean(v[h == 1]))
                else:
                    row[k + "_dB"] = float(np.mean([energy_db(v[pts == p]) for p in np.unique(pts)]))
            if basis == "1":
                row["T_housing_dB"] = float(np.mean((d["L_v"] - d["L_bore"])[h == 1]))
            else:               # the study's total basis: per speed L_v,tot - L_bore,tot, then the mean
                row["T_housing_dB"] = float(np.mean([energy_db(d["L_v"][pts == p]) - energy_db(d["L_bore"][pts == p])
                                                     for p in np.unique(pts)]))
            row["axial_minus_radial_dB"] = row["L_bore_axial_dB"] - row["L_bore_radial_dB"]
            rows.append(row)
    return rows


def terms_rows(name, res, ref, radiation) -> list[dict]:
    """The study's terms (housingfe.studies.variant_terms) of a configuration against ball."""
    from housingfe.studies.variant_terms import decompose_difference, term_curves

    rows = []
    for route in ROUTES:
        a, b = term_curves(res, route, radiation, TORQUE), term_curves(ref, route, radiation, TORQUE)
        d = decompose_difference(a[0], a[1], b[0], b[1])
        rows.append({"config": name, "route": route, "dL_WA_dB": d["mean_diff_dB"],
                     "d_excitation_dB": d["d_excitation_dB"], "d_T_path_dB": d["d_transfer_path_dB"],
                     "d_T_housing_dB": d["d_transfer_housing_dB"], "d_A_weighting_dB": d["d_A_weighting_dB"]})
    return rows


def housing_transfer(model, k_speed, frequency, elements):
    """(A, E-check) at one line: the housing's own transfer from the 6 x bearings bore loads to the surface,
    A = H^H G H with H = V E^-1 (V: the coupled reduced system's solutions to unit loads on the bore masters' DOFs,
    E = I + the bearings' own loads on the bores in V: the housing sees applied + bearing loads)."""
    from housingfe.drivetrain.bore_loads import bore_loads

    mv = model.at_speed(k_speed)
    s = mv.reduction.system
    w = 2 * math.pi * frequency
    Z = s.Kr + 1j * w * (s.Cr + (s.D if s.D is not None else 0)) - w * w * s.Mr
    B = np.vstack([e.X[6:12] for e in elements])                       # (6 nb, vectors)
    V = np.linalg.solve(Z, B.T.astype(complex))
    loads = bore_loads(elements, frequency, V)                          # (6 nb cols, nb, 6)
    E = np.eye(B.shape[0]) + loads.reshape(B.shape[0], -1).T
    H = V @ np.linalg.inv(E)
    G = mv.reduction.reduced.gram
    return np.conj(H.T) @ G @ H, G


def split_rows(name, model, res, elements, bore_names) -> tuple[list, list]:
    """Part 2 at the lines of PROBE_SPEEDS, harmonics 1-2 and each probe speed's strongest L_v harmonic per route."""
    ln = res.lines
    G = None
    load_rows, split = [], []
    for sp in PROBE_SPEEDS:
        at = np.flatnonzero(ln.speed == sp)
        picks = {1, 2}
        for route in ROUTES:
            picks.add(int(ln.harmonic[at[np.argmax(res.routes[route].L_v[at])]]))
        for k in at[np.isin(ln.harmonic[at], sorted(picks))]:
            f = float(ln.frequency[k])
            A, G = housing_transfer(model, sp, f, elements)
            nb = len(elements)
            is_f = np.tile(np.arange(6) < 3, nb)
            diag = np.real(np.diag(A))
            for route in ROUTES:
                rr = res.routes[route]
                c = rr.coefficients[:, k]
                h = rr.bore_loads[k].reshape(-1)
                shift = rr.L_v[k] - rr.response.velocity_level_db[k]      # tf_omega: to the source's L_omega
                lv = float(np.real(np.conj(c) @ G @ c))

                def part(mask):
                    hh = np.where(mask, h, 0)
                    q = float(np.real(np.conj(hh) @ A @ hh))
                    return rr.L_v[k] + 10 * np.log10(q / lv) if q > 0 else float("-inf")

                row = {"config": name, "route": route, "speed_rpm": sp, "harmonic": int(ln.harmonic[k]),
                       "frequency_Hz": f, "L_v_dB": float(rr.L_v[k]),
                       "L_v_from_bore_loads_dB": part(np.ones(len(h), bool)),
                       "forces_only_dB": part(is_f), "moments_only_dB": part(~is_f),
                       "forces_incoherent_dB": float(rr.L_v[k] + 10 * np.log10(
                           np.sum(np.abs(h[is_f]) ** 2 * diag[is_f]) / lv)),
                       "L_bore_dB": float(rr.bore_force_db[k]), "L_bore_moment_dB": float(rr.bore_moment_db[k])}
                for b, bn in enumerate(bore_names):
                    m = np.zeros(len(h), bool)
                    m[6 * b:6 * b + 6] = True
                    row[f"{bn}_only_dB"] = part(m)
                for j, comp in enumerate(COMPONENTS):
                    m = np.zeros(len(h), bool)
                    m[j::6] = True
                    row[f"{comp}_only_dB"] = part(m)
                split.append(row)
                for b, bn in enumerate(bore_names):
                    for j, comp in enumerate(COMPONENTS):
                        hv = h[6 * b + j]
                        load_rows.append({"config": name, "route": route, "speed_rpm": sp,
                                          "harmonic": int(ln.harmonic[k]), "frequency_Hz": f, "bearing": bn,
                                          "component": comp,
                                          "level_dB": float(20 * np.log10(max(abs(hv), 1e-30)) + shift),
                                          "phase_deg": float(np.degrees(np.angle(hv))),
                                          # the surface <v^2> per unit load of this component alone (dB re
                                          # 5e-8 m/s per N or N m): the housing's mobility, the same on both routes
                                          "housing_Lv_per_unit_dB": float(rr.response.velocity_level_db[k] + 10 * np.log10(
                                              diag[6 * b + j] / lv))})
    return load_rows, split


def main(argv=None):
    from housingfe.runup.chain import with_drivetrain
    from housingfe.studies.chain_session import ChainSession

    argv = sys.argv[1:] if argv is None else list(argv)
    no_variants = "--no-variants" in argv                 # ball and self-aligning only
    args, overrides = gear_set_b_args(__doc__, "/tmp/sahousing-exp", [a for a in argv if a != "--no-variants"],
                                      extra=('radiation.models=["erp"]',))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0, load0 = time.perf_counter(), os.getloadavg()
    timings = {}
    session = ChainSession.from_scene("test-gearbox-runup", overrides)
    ball = session.drivetrain("B", "ball", TORQUE)
    sa = session.drivetrain("B", "self_aligning", TORQUE)
    sa_spec = sa.to_coupling_spec()
    configs = {"ball": ball, "self_aligning": sa}
    if not no_variants:
        configs["ball_zero_moment"] = Patched(ball, lambda s: common.with_bearing_matrices(
            s, common.scale_moments(0.0)))
        configs["ball_moments_sa_translations"] = Patched(ball, lambda s: common.with_bearing_matrices(
            s, common.translations_of(sa_spec)))
        configs["ball_no_radial_axial_coupling"] = Patched(ball, lambda s: common.with_bearing_matrices(
            s, lambda n, K: zero_radial_axial(K)))
        configs["ball_with_sa_radial_block"] = Patched(ball, lambda s: common.with_bearing_matrices(
            s, radial_block_of(sa_spec)))
    results, models = {}, {}
    for name, dt in configs.items():
        t = time.perf_counter()
        if name in ("ball", "self_aligning"):
            models[name] = session.model(dt, label=name)
        else:
            models[name] = with_drivetrain(models["ball"], dt)
        # the variants (Patched: no dataclass, so no misalignment law of their own) run on the ball's lines: the
        # same excitation, only the transfer differs
        results[name] = session.runup(models[name], TORQUE, lines=None if name in ("ball", "self_aligning")
                                      else results["ball"].lines)
        timings[f"{name}_s"] = time.perf_counter() - t
        print(f"{name}: {timings[f'{name}_s']:.1f} s", flush=True)
    radiation = session.radiation

    terms = [r for name in configs if name != "ball"
             for r in terms_rows(name, results[name], results["ball"], radiation)]
    write_records(out / "terms.csv", terms)
    for r in terms:
        print("terms", {k: (round(v, 2) if isinstance(v, float) else v) for k, v in r.items()}, flush=True)
    harm = [r for name in configs for r in harmonic_rows(name, results[name])]
    write_records(out / "harmonics.csv", harm)
    parts = [r for name in configs for r in load_part_rows(name, models[name], results[name])]
    write_records(out / "load_parts.csv", parts)
    write_records(out / "tooth_line_curves.csv", [
        {"config": cfg, "part": part, "speed_rpm": float(c[0][i]), "T_housing_dB": float(c[1][i]),
         "axial_minus_radial_dB": float(c[2][i])} for (cfg, part), c in CURVES.items() for i in range(len(c[0]))])
    for r in parts:
        if r["harmonic"] == "1":
            print("part", {k: (round(v, 2) if isinstance(v, float) else v) for k, v in r.items()}, flush=True)

    t = time.perf_counter()
    from housingfe.drivetrain.bore_loads import structure_bearing_elements

    load_rows, split = [], []
    for name in ("ball", "self_aligning"):
        m = models[name]
        els = structure_bearing_elements(m.structure, m.reduction.vectors)
        bore_names = [e.bore for e in els]
        a, b = split_rows(name, m, results[name], els, bore_names)
        load_rows += a
        split += b
    timings["split_s"] = time.perf_counter() - t
    write_records(out / "bore_loads.csv", load_rows)
    write_records(out / "housing_split.csv", split)
    _plot(out / "sa_housing.png", load_rows)
    modes = {}
    for name, m in models.items():
        fr = m.reduction.frequencies_hz
        modes[name] = {"below_1_hz": int(np.sum(fr < 1.0)),
                       "in_100_1600_hz": [round(float(x), 1) for x in fr[(fr > 100) & (fr < 1600)]]}
        print(name, "modes below 1 Hz:", modes[name]["below_1_hz"], "100-1600 Hz:", modes[name]["in_100_1600_hz"])
    coupling = []
    for name in ("ball", "self_aligning"):
        for b in configs[name].to_coupling_spec().bearings:
            K = np.array(b.matrices()[0], float)     # bearing frame: z = shaft axis
            coupling.append({"config": name, "bearing": b.name, "k_xx": K[0, 0], "k_yy": K[1, 1], "k_zz_axial": K[2, 2],
                             "k_xz": K[0, 2], "k_yz": K[1, 2],
                             "radial_axial_ratio": float(np.hypot(K[0, 2], K[1, 2]) / max(K[0, 0], K[1, 1]))})
    write_records(out / "bearing_coupling.csv", coupling)
    for r in coupling:
        print("K", {k: (f"{v:.3g}" if isinstance(v, float) else v) for k, v in r.items()})
    wall = time.perf_counter() - t0
    json.dump({"modes": modes, "coarse": args.coarse, "overrides": overrides, "wall_s": wall, "timings_s": timings,
               "loadavg_start": load0, "loadavg_end": os.getloadavg(),
               "spec": {"source_receptance": session.spec.source_receptance,
                        "misalignment": session.spec.misalignment_model,
                        "mesh_moment": session.spec.mesh_moment_model, "engagement": session.spec.engagement,
                        "f_max_hz": session.spec.f_max_hz}},
              open(out / "run.json", "w"), indent=1)
    print(f"wall {wall:.0f} s; wrote {out}")
    return 0




def _plot(path, load_rows):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(17, 4.8))
    ax = axes[0]
    for comp, colour in zip(("Fx", "Fy", "Fz"), ("tab:blue", "tab:red", "tab:green")):
        for cfg, style in (("ball", "o-"), ("self_aligning", "x--")):
            pts = sorted({(float(r["frequency_Hz"]), float(r["housing_Lv_per_unit_dB"])) for r in load_rows
                          if r["config"] == cfg and r["component"] == comp and r["route"] == "tf_omega"
                          and r["bearing"] == "pinion_front" and r["harmonic"] in (1, 2)})
            ax.plot([p[0] for p in pts], [p[1] for p in pts], style, color=colour, ms=4,
                    label=f"{comp} ({'axial' if comp == 'Fy' else 'radial'}), {cfg}")
    ax.set_xscale("log")
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("housing L_v per 1 N at the pinion_front bore (dB re 5e-8 m/s)")
    ax.set_title("the housing's answer per unit bore force (A_jj), harmonics 1-2")
    ax.legend(fontsize=7)
    colours = {"tf_omega": "tab:purple", "mesh_force": "k", "mesh pair only": "tab:orange",
               "shuttling moment only": "tab:cyan"}
    for ax, j, what in ((axes[1], 1, "T_housing = L_v - L_bore, tooth line (dB)"),
                        (axes[2], 2, "axial - radial bore force level, tooth line (dB)")):
        for (cfg, part), c in CURVES.items():
            if cfg not in ("ball", "self_aligning"):
                continue
            style = ("o" if cfg == "ball" else "x") if part == "tf_omega" else ("-" if cfg == "ball" else "--")
            ax.plot(c[0], c[j], style, color=colours[part], ms=5, label=f"{part}, {cfg}")
        ax.set_xlabel("pinion speed (rev/min)")
        ax.set_ylabel(what)
        ax.legend(fontsize=6)
    fig.suptitle("gear set B, 2000 N m: self-aligning (dashed) vs ball (solid); tf_omega = the mesh pair's bore "
                 "pattern, mesh_force's bore forces = the shuttling moment's", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    raise SystemExit(main())
