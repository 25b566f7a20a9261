"""What the first coupled modes of test-gearbox-runup (212 and 367 Hz, set A, ball, 2000 N m) are, what sets their
frequencies, and how the mesh_force speed law (L_WA and T_housing = L_v - L_bore, 250-1500 rev/min) depends on
where the first one sits (issue 28; docs/runup.md "The transfer split" and "Which modes make which peak").

1. energies: per mode of the coupled reduced system (the Ritz space of the run-up) the kinetic and strain energy of
   each part: the housing (its FE M, K on the housing part of the Ritz vectors), each shaft's beams, its gear body
   (the rigid discs), each bearing, the gear mesh spring, each drive line (quills and coupling inertias).  Every
   part's matrices are projected on the Ritz vectors (X_e^T A_e X_e on the part's nodes' rows); the housing's from
   the FE matrices; the shares of a mode are y^T A_part y / y^T A y (y: the mode in Ritz coordinates) and their
   sum against 1 is the check that no part is missing;
2. sensitivities d f / d ln p: (a) of a part's stiffness (all of its K x (1 + eps)): Rayleigh's quotient gives
   f/2 x (the part's strain energy share) exactly, checked by a finite difference of the re-analysed system
   (`RitzReduction.with_change` with dK = eps X_e^T K_e X_e); (b) of the assumed inputs (docs/source.md: shaft
   diameters 80 / 95 mm, the quill shafts, the coupling inertias; the FE bearings' stiffness; the mesh stiffness)
   by a +/- 2 % change of the drivetrain's coupling spec and a Rayleigh-Ritz re-analysis on the one basis
   (`housingfe.runup.chain.with_drivetrain`, as `housingfe uncertainty` and the studies do), modes tracked by MAC;
3. sweep: the input that moves f1 most, over a stated range, each variant's run-up on the default's source lines
   (the excitation held: only the transfer changes), printing f1 against the mesh_force slopes of L_WA, T, T_path,
   T_housing (total basis) and T_housing on the tooth band.

    PYTHONPATH=. /work/main/.venv/bin/python benchmarks/experiments/first_mode/first_mode.py [--out DIR] [--coarse] [--no-sweep]

Writes energies.csv, sensitivities.csv, sweep.csv, first_mode.png, run.json.  No default of the package changes.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "bearing_ranking"))
# Patched: a Drivetrain whose FE coupling spec is patched (the lumped source and the lines are the base's)
from runup_factors import Patched  # noqa: E402

TORQUE = 2000.0
ROUTE = "mesh_force"
EPS = 0.02                  # relative step of the finite differences
# the sweeps: the assumed input that moves f1 most (found in main; its factors: the assumed 95 mm wheel shaft from
# 57 to 152 mm, wider than any documented range, which docs/source.md does not give) and the wheel bearings' stiffness
# (the input that moves f1 most of all: Lim's matrices x 0.25 ... 8, so that f1 leaves the 250-1500 rpm tooth band)
SWEEP = (0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.25, 1.4, 1.6)
SWEEP_BEARINGS = (0.25, 0.5, 0.7, 1.0, 1.4, 2.0, 4.0, 8.0)


# ------------------------------------------------------------------------------------------------ parts
def part_matrices(model) -> dict:
    """{part name: (K_r, M_r)} (n x n, Ritz coordinates; None where the part has none) of every part of the coupled
    gearbox: "housing" (FE K, M on the housing part of each Ritz vector), "<shaft> shaft" (its Timoshenko beams),
    "<shaft> gear body" (its rigid discs), "bearing <name>", "gear mesh", "drive line <name>" (quill springs and
    the coupling inertia), "tie rod <i>"."""
    from housingfe.drivetrain import coupling as cp
    from housingfe.drivetrain.bore_loads import node_rows
    from housingfe.solvers import blocks

    st, red = model.structure, model.reduction
    vectors = red.vectors
    p = st.parts
    nodes = sorted({n for e in p.elements for n in e.nodes if n is not None}
                   | {f"{s}:{i}" for s, sh in p.shafts.items() for i in range(len(sh.nodes))})
    rows = node_rows(st, vectors, nodes)
    nv = len(vectors)

    def rows_of(names):
        return np.vstack([rows[n] if n is not None else np.zeros((6, nv)) for n in names])

    def proj(A, names):
        X = rows_of(names)
        return X.T @ np.asarray(A, float) @ X

    out = {}
    U = blocks.columns([st.fe_vector(q) for q in vectors])
    out["housing"] = (U.T @ blocks.mat_block(st.model.K, U), U.T @ blocks.mat_block(st.model.M, U))
    for s, sh in p.shafts.items():
        names = [f"{s}:{i}" for i in range(len(sh.nodes))]
        ks, ms = sh.matrices()
        md = np.zeros_like(ms)
        for node, disc in sh.discs.items():
            md[6 * node:6 * node + 6, 6 * node:6 * node + 6] += disc.mass_matrix(sh.axis)
        out[f"{s} shaft"] = (proj(ks, names), proj(ms - md, names))
        out[f"{s} gear body"] = (None, proj(md, names))
    for b, e in zip(st.spec.bearings, p.bearings):
        out[f"bearing {b.name}"] = (proj(e.K, e.nodes), None)
    for i, g in enumerate(p.gear_meshes):
        el = cp.gear_mesh_element(g, p.positions[g.a], p.positions[g.b])
        out["gear mesh" if i == 0 else f"gear mesh {i}"] = (proj(el.K, [g.a, g.b]), None)
    line_names = [d.name for d in st.spec.drive_lines]
    for e in p.drive_lines:
        name = next((n for n in line_names if n in e.nodes), "aux")
        k = f"drive line {name}"
        K0, M0 = out.get(k, (None, None))
        Ke = None if e.K is None else proj(e.K, e.nodes)
        Me = None if e.M is None else proj(e.M, e.nodes)
        out[k] = (_add(K0, Ke), _add(M0, Me))
    for i, e in enumerate(p.tie_rods):
        out[f"tie rod {i}"] = (proj(e.K, e.nodes), None if e.M is None else proj(e.M, e.nodes))
    return out


def _add(a, b):
    return b if a is None else (a if b is None else a + b)


def mode_energies(system, parts: dict, modes) -> tuple[list[dict], dict]:
    """Rows {mode, frequency_Hz, part, kinetic_share, strain_share} for the reduced modes `modes` (indices into
    system.frequencies_hz), and per mode the sums of the parts' shares (should be 1: no part missing)."""
    Ks = 0.5 * (system.Kr + system.Kr.T)
    Ms = 0.5 * (system.Mr + system.Mr.T)
    rows, sums = [], {}
    for j in modes:
        y = system.Y[:, j]
        kt, ut = float(y @ Ms @ y), float(y @ Ks @ y)
        sk = su = 0.0
        for name, (K, M) in parts.items():
            k = float(y @ (0.5 * (M + M.T)) @ y) / kt if M is not None else 0.0
            u = float(y @ (0.5 * (K + K.T)) @ y) / ut if K is not None else 0.0
            sk, su = sk + k, su + u
            rows.append({"mode": int(j), "frequency_Hz": float(system.frequencies_hz[j]), "part": name,
                         "kinetic_share": k, "strain_share": u})
        sums[int(j)] = (sk, su)
    return rows, sums


def mode_shapes(model, system, modes) -> list[dict]:
    """Rows per mode and interior node of the bearings and gears (shaft nodes, bore masters): the node's
    translations ux, uy, uz (global axes; y = the shaft axes) and rotations rx, ry, rz x 0.1 m (a tilt as the
    translation it makes 0.1 m away), each over the largest translation of any of these nodes in the mode."""
    from housingfe.drivetrain.bore_loads import node_rows

    st = model.structure
    p = st.parts
    nodes = []
    for e in p.bearings:
        nodes += [n for n in e.nodes if n is not None and n not in nodes]
    for g in p.gear_meshes:
        nodes += [n for n in (g.a, g.b) if n not in nodes]
    rows = node_rows(st, model.reduction.vectors, nodes)
    out = []
    for j in modes:
        y = system.Y[:, j]
        d = {n: rows[n] @ y for n in nodes}
        scale = max(np.max(np.abs(v[:3])) for v in d.values())
        for n in nodes:
            v = d[n] / scale
            role = "gear" if any(n in (g.a, g.b) for g in p.gear_meshes) else (
                "bore master" if ":" not in n else "bearing shaft node")
            out.append({"mode_Hz": float(system.frequencies_hz[j]), "node": n, "role": role,
                        **{k: float(v[i]) for i, k in enumerate(("ux", "uy", "uz"))},
                        **{k: float(0.1 * v[3 + i]) for i, k in enumerate(("rx_0.1m", "ry_0.1m", "rz_0.1m"))}})
    return out


def track(system0, system1, j) -> int:
    """The mode of system1 most like mode j of system0 (MAC on the base's mass matrix; same Ritz vectors)."""
    Ms = 0.5 * (system0.Mr + system0.Mr.T)
    y = system0.Y[:, j]
    mac = (y @ Ms @ system1.Y) ** 2 / ((y @ Ms @ y) * np.einsum("ij,ik,kj->j", system1.Y, Ms, system1.Y))
    return int(np.argmax(mac))


def rayleigh_sensitivity(system, K_part, j) -> float:
    """d f_j / d ln k (Hz) for all of a part's stiffness x k: f_j / 2 x (its strain energy share) (Rayleigh's
    quotient on a mass-normalised mode; exact for the symmetric reduced eigenproblem)."""
    y = system.Y[:, j]
    Ks = 0.5 * (system.Kr + system.Kr.T)
    return 0.5 * float(system.frequencies_hz[j]) * float(y @ (0.5 * (K_part + K_part.T)) @ y) / float(y @ Ks @ y)


def fd_stiffness_sensitivity(reduction, K_part, j, eps=EPS) -> float:
    """The same by a central finite difference of the re-analysed system (with_change, dK = +/- eps K_part)."""
    s0 = reduction.system
    f = []
    for e in (eps, -eps):
        s1 = reduction.with_change(e * K_part).system
        f.append(float(s1.frequencies_hz[track(s0, s1, j)]))
    return (f[0] - f[1]) / (math.log1p(eps) - math.log1p(-eps))


# ------------------------------------------------------------------------------------------------ inputs
def scale_shaft_diameters(shaft: str, factor: float):
    """patch: every segment diameter (outer, inner) of one FE shaft x factor (its beams' K and M; the gear body
    discs kept)."""
    def patch(spec):
        shafts = [s.model_copy(update={"segments": [[seg[0]] + [d * factor for d in seg[1:]] for seg in s.segments]})
                  if s.name == shaft else s for s in spec.shafts]
        return spec.model_copy(update={"shafts": shafts})
    return patch


def scale_bearings(factor: float, names=None):
    """patch: the FE bearings' K (6x6, all of it) x factor (C kept), all or those in `names`."""
    def patch(spec):
        new = []
        for b in spec.bearings:
            if names is not None and b.name not in names:
                new.append(b)
                continue
            K, C = b.matrices()
            new.append(b.model_copy(update={
                "designation": None, "load": None, "model": None, "fixed_tilt": None, "stiffness": None,
                "stiffness_matrix": (factor * np.asarray(K, float)).tolist(),
                "damping_matrix": None if C is None else np.asarray(C, float).tolist()}))
        return spec.model_copy(update={"bearings": new})
    return patch


def scale_mesh(factor: float):
    def patch(spec):
        return spec.model_copy(update={"gear_meshes": [g.model_copy(update={"stiffness": g.stiffness * factor})
                                                       for g in spec.gear_meshes]})
    return patch


def scale_drive_lines(field_names, factor: float):
    def patch(spec):
        return spec.model_copy(update={"drive_lines": [d.model_copy(update={k: getattr(d, k) * factor
                                                                             for k in field_names})
                                                       for d in spec.drive_lines]})
    return patch


def input_patches(spec) -> dict:
    """{input name: (patch factory factor -> patch, what it is, status)} of the candidate inputs."""
    out = {}
    for s in spec.shafts:
        out[f"{s.name} shaft diameters"] = (lambda f, n=s.name: scale_shaft_diameters(n, f),
                                            "every segment diameter of the FE shaft",
                                            "assumed (docs/source.md: pinion shaft 80 mm, wheel shaft 95 mm)")
    out["bearing stiffness (all four)"] = (scale_bearings, "the FE bearings' 6x6 K",
                                           "model (Lim's / catalogue, clearance and grooves estimated)")
    for shaft in ("pinion", "wheel"):
        names = [b.name for b in spec.bearings if b.name.startswith(shaft)]
        out[f"bearing stiffness ({shaft})"] = (lambda f, n=tuple(names): scale_bearings(f, n),
                                               f"the FE bearings' K of {', '.join(names)}", "as above")
    out["mesh stiffness"] = (scale_mesh, "mean mesh stiffness", "ISO 6336 / the source's mean, computed")
    if spec.drive_lines:
        out["quill stiffness (all)"] = (lambda f: scale_drive_lines(("near_stiffness", "far_stiffness"), f),
                                        "the quill torsion springs", "assumed (docs/source.md: torsion shafts 1-4)")
        out["coupling inertias"] = (lambda f: scale_drive_lines(("inertia",), f), "the coupling inertias",
                                    "assumed (docs/source.md: 0.02 / 0.05 kg m^2)")
    return out


def main(argv=None):
    from housingfe.runup import slopes
    from housingfe.runup.chain import with_drivetrain
    from housingfe.studies.chain_session import ChainSession

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", default="/tmp/firstmode-exp")
    p.add_argument("--coarse", action="store_true", help="60 mm housing mesh, lines to 1.5 kHz (a quick look)")
    p.add_argument("--no-sweep", action="store_true")
    args = p.parse_args(argv)
    overrides = ['housing.set=["mesh.size=0.06"]', "runup.f_max_hz=1500.0"] if args.coarse else []
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0, load0 = time.perf_counter(), os.getloadavg()
    timings = {}
    session = ChainSession.from_scene("test-gearbox-runup", overrides)
    sc = session.scene.drivetrain
    dt = session.drivetrain(sc.gear_set, sc.bearings, TORQUE)
    model = session.model(dt, label="base")
    timings["model_s"] = time.perf_counter() - t0
    t = time.perf_counter()
    base = session.runup(model, TORQUE)
    timings["runup_s"] = time.perf_counter() - t
    rad = session.radiation

    def law(res):
        d = slopes.decompose(res, ROUTE, rad, TORQUE, "total").slopes
        tb = slopes.decompose(res, ROUTE, rad, TORQUE, "tooth_band").slopes
        return {"L_WA": d["L_WA"], "excitation": d["excitation"], "transfer": d["transfer"],
                "T_path": d["transfer_path"], "T_housing": d["transfer_housing"],
                "L_WA_tooth_band": tb["L_WA"], "T_housing_tooth_band": tb["transfer_housing"]}
    base_law = law(base)
    print("base", {k: round(v, 2) for k, v in base_law.items()}, flush=True)

    # 1. energies
    t = time.perf_counter()
    red = model.reduction
    system = red.system
    parts = part_matrices(model)
    fr = system.frequencies_hz
    modes = [int(j) for j in np.flatnonzero((fr > 100) & (fr < 620))]
    erows, sums = mode_energies(system, parts, modes)
    timings["energies_s"] = time.perf_counter() - t
    for j in modes:
        top = sorted((r for r in erows if r["mode"] == j), key=lambda r: -(r["kinetic_share"] + r["strain_share"]))
        print(f"mode {fr[j]:.1f} Hz sums T {sums[j][0]:.4f} U {sums[j][1]:.4f}: " + "; ".join(
            f"{r['part']} T {r['kinetic_share']:.3f} U {r['strain_share']:.3f}" for r in top[:6]), flush=True)
    _write(out / "energies.csv", erows)
    shapes = mode_shapes(model, system, modes[:2])
    _write(out / "shapes.csv", shapes)
    for r in shapes:
        print("shape", {k: (round(v, 3) if isinstance(v, float) else v) for k, v in r.items()}, flush=True)
    f1 = modes[0]
    watch = modes[:2]          # the 212 and 367 Hz modes

    # 2. sensitivities
    t = time.perf_counter()
    srows = []
    for j in watch:
        for name, (K, M) in parts.items():
            if K is None:
                continue
            srows.append({"mode_Hz": float(fr[j]), "input": f"{name}: stiffness", "kind": "part stiffness",
                          "status": "", "df_dlnp_Hz": rayleigh_sensitivity(system, K, j),
                          "df_dlnp_fd_Hz": fd_stiffness_sensitivity(red, K, j)})
        _, M = parts["housing"]
        y = system.Y[:, j]
        srows.append({"mode_Hz": float(fr[j]), "input": "housing: density", "kind": "part mass",
                      "status": "", "df_dlnp_Hz": -0.5 * float(fr[j]) * float(y @ M @ y) / float(
                          y @ (0.5 * (system.Mr + system.Mr.T)) @ y), "df_dlnp_fd_Hz": float("nan")})
    spec = dt.to_coupling_spec()
    patches = input_patches(spec)
    for name, (factory, what, status) in patches.items():
        f = {}
        for e in (EPS, -EPS):
            m1 = with_drivetrain(model, Patched(dt, factory(1 + e)))
            f[e] = m1.reduction.system
        for j in watch:
            fp = float(f[EPS].frequencies_hz[track(system, f[EPS], j)])
            fm = float(f[-EPS].frequencies_hz[track(system, f[-EPS], j)])
            srows.append({"mode_Hz": float(fr[j]), "input": name, "kind": what, "status": status,
                          "df_dlnp_Hz": (fp - fm) / (math.log1p(EPS) - math.log1p(-EPS)),
                          "df_dlnp_fd_Hz": float("nan")})
    timings["sensitivities_s"] = time.perf_counter() - t
    _write(out / "sensitivities.csv", srows)
    for r in srows:
        print(f"sens {r['mode_Hz']:.1f} Hz {r['input']}: {r['df_dlnp_Hz']:+.2f} Hz (fd {r['df_dlnp_fd_Hz']:+.2f})",
              flush=True)

    # 3. sweep of the assumed input that moves f1 most
    t = time.perf_counter()
    assumed = [r for r in srows if r["mode_Hz"] == float(fr[f1]) and r["status"].startswith("assumed")]
    pick = max(assumed, key=lambda r: abs(r["df_dlnp_Hz"]))["input"]
    sweep = []
    if not args.no_sweep:
        for name, factors in ((pick, SWEEP), ("bearing stiffness (wheel)", SWEEP_BEARINGS)):
            factory = patches[name][0]
            for s in factors:
                m1 = model if s == 1.0 else with_drivetrain(model, Patched(dt, factory(s)))
                res = base if s == 1.0 else session.runup(m1, TORQUE, lines=base.lines)
                s1 = m1.reduction.system
                row = {"input": name, "factor": s, "f1_Hz": float(s1.frequencies_hz[track(system, s1, f1)]),
                       "f2_Hz": float(s1.frequencies_hz[track(system, s1, watch[1])]),
                       **{f"slope_{k}": v for k, v in law(res).items()}}
                sweep.append(row)
                print("sweep", {k: (round(v, 2) if isinstance(v, float) else v) for k, v in row.items()}, flush=True)
        _write(out / "sweep.csv", sweep)
    timings["sweep_s"] = time.perf_counter() - t
    # what a stiffness-controlled (+6.02) or a flat (0) housing term would give with the other terms as they are
    what_if = {"L_WA_base": base_law["L_WA"], "T_housing_base": base_law["T_housing"],
               "L_WA_if_T_housing_stiffness_controlled": base_law["L_WA"] - base_law["T_housing"] + 20 * math.log10(2),
               "L_WA_if_T_housing_flat": base_law["L_WA"] - base_law["T_housing"]}
    print("what-if", {k: round(v, 2) for k, v in what_if.items()})
    _plot(out / "first_mode.png", erows, [fr[j] for j in watch], sweep, base_law)
    wall = time.perf_counter() - t0
    json.dump({"coarse": args.coarse, "overrides": overrides, "torque_nm": TORQUE, "route": ROUTE,
               "radiation": rad, "base_slopes": base_law, "what_if": what_if, "sweep_input": pick,
               "energy_sums": {f"{fr[j]:.1f}": sums[j] for j in modes},
               "modes_100_620_hz": [round(float(fr[j]), 1) for j in modes],
               "interior_share_basis": [round(float(x), 3) for x in model.interior_share[:12]],
               "wall_s": wall, "timings_s": timings, "loadavg_start": load0, "loadavg_end": os.getloadavg()},
              open(out / "run.json", "w"), indent=1)
    print(f"wall {wall:.0f} s; wrote {out}")
    return {"energies": erows, "sums": sums, "sensitivities": srows, "sweep": sweep, "what_if": what_if,
            "base": base_law, "modes": [float(fr[j]) for j in modes]}


def _write(path, rows):
    from housingfe.outputs import write_csv

    if rows:
        write_csv(path, list(rows[0]), ([f"{v:.6g}" if isinstance(v, float) else v for v in r.values()] for r in rows))


def _plot(path, erows, watch_hz, sweep, base_law):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(14, 4.8))
    ax = axes[0]
    parts = sorted({r["part"] for r in erows})
    width = 0.38
    for i, f in enumerate(watch_hz):
        rr = {r["part"]: r for r in erows if abs(r["frequency_Hz"] - f) < 1e-6}
        x = np.arange(len(parts))
        ax.bar(x + (i - 0.5) * width, [rr[p]["kinetic_share"] for p in parts], width / 2,
               label=f"{f:.0f} Hz kinetic")
        ax.bar(x + (i - 0.5) * width + width / 2, [rr[p]["strain_share"] for p in parts], width / 2,
               label=f"{f:.0f} Hz strain", hatch="//")
    ax.set_xticks(np.arange(len(parts)))
    ax.set_xticklabels(parts, rotation=60, ha="right", fontsize=7)
    ax.set_ylabel("share of the mode's energy")
    ax.legend(fontsize=7)
    ax.set_title("the first coupled modes: energy per part")
    ax = axes[1]
    for name, marker in zip(dict.fromkeys(r["input"] for r in sweep), ("o", "s")):
        rr = [r for r in sweep if r["input"] == name]
        f1 = [r["f1_Hz"] for r in rr]
        ax.plot(f1, [r["slope_L_WA"] for r in rr], "k-" + marker, label=f"L_WA, {name}")
        ax.plot(f1, [r["slope_T_housing"] for r in rr], "r--" + marker, label=f"T_housing, {name}")
        ax.plot(f1, [r["slope_T_housing_tooth_band"] for r in rr], "m:" + marker, ms=3,
                label=f"T_housing tooth band, {name}")
    if sweep:
        ax.axhspan(4, 8, color="g", alpha=0.15, label="measured L_WA 6 +/- 2")
        ax.axhline(20 * math.log10(2), color="grey", ls=":", label="stiffness control +6.02")
        ax.set_xscale("log")
        ax.set_xlabel("first coupled mode f1 (Hz)")
        ax.set_ylabel("mesh_force slope 250-1500 rpm (dB/doubling)")
        ax.set_title(f"what-if sweeps (default: {base_law['L_WA']:.2f} dB(A) per doubling)")
        ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
