"""Writing the results of a housing scene: modes, forced response, sound power, summaries and pictures."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from housingfe.outputs import format_table, write_csv, write_json


def modal_summary_text(summary: dict) -> str:
    """The human-readable summary of a modal run (summary.txt and the terminal)."""
    f = summary["frequencies_hz"]
    resolution = summary.get("resolution")
    unrounded = summary.get("element_size_unrounded_m")
    derived = f" rounded down from {unrounded * 1e3:.7g} mm" if unrounded else ""
    tries = summary.get("element_size_tries") or []
    if len(tries) > 1:      # the derived size's mesh was refused by the quality rule: finer on the size ladder
        derived = (f", {len(tries) - 1} step(s) finer than the derived {tries[0]['size_m'] * 1e3:.4g} mm"
                   f"{derived} (sliver rule)")
    lines = [
        f"scene {summary['scene']}: {summary['description']}",
        f"{summary['dofs']} DOFs ({summary['element']}, element size {summary['element_size_m'] * 1e3:.4g} mm"
        f"{derived}, {summary['mpi_ranks']} MPI rank(s)), wall time {summary['wall_time_s']:.1f} s",
        f"{len(f)} elastic modes below {summary['f_max_hz']:g} Hz; "
        f"complete (of the discrete model): {summary['complete']} (inertia count "
        f"{summary['eigenvalues_below_f_max_by_inertia']} incl. {len(summary['rigid_body_frequencies_hz'])} "
        f"rigid-body modes)" + (f"; {_error_clause(resolution)}" if resolution else ""),
        *([ladder_line(tries)] if len(tries) > 1 else []),
        f"max relative residual {max(summary['residuals'], default=0.0):.1e}",
        f"mass {summary['mass_kg']:.3f} kg (geometry)"
        + (f", {summary['mass_from_rigid_modes_kg']:.3f} kg (rigid-body modes)"
           if summary["mass_from_rigid_modes_kg"] is not None else ""),
    ]
    lines += resolution_lines(resolution)
    if len(f):
        lines.append("elastic eigenfrequencies (Hz):")
        for i in range(0, len(f), 8):
            lines.append("  " + "  ".join(f"{v:8.2f}" for v in f[i:i + 8]))
    inner = summary.get("interior")
    if inner:
        lines.append(f"interior on rigid bores ({inner['rigid_bores_dofs']} DOFs, {inner['rigid_bores_mechanisms']} "
                     "mechanisms), Hz [share of strain energy in the bearings]:")
        lines.append("  " + "  ".join(f"{f:.1f} [{e:.2f}]" for f, e in
                                      zip(inner["rigid_bores_frequencies_hz"], inner["rigid_bores_bearing_energy"])))
        lines.append(f"coupled ({inner['coupled_dofs']} DOFs): {len(inner['coupled_interior_modes_hz'])} "
                     f"interior-dominated modes (interior kinetic energy > 50 %), {inner['coupled_housing_modes']} "
                     "housing-dominated; interior-dominated (mode number: Hz):")
        lines.append("  " + "  ".join(f"{n}: {f:.1f}" for n, f in zip(inner["coupled_interior_mode_numbers"],
                                                                     inner["coupled_interior_modes_hz"])))
    if summary.get("published"):
        lines.append("compared with published values:")
        lines.append(format_table(
            ["quantity", "ours", "published", "unit", "source"],
            [[r["quantity"], "-" if r["ours"] is None else r["ours"], r["published"], r["unit"], r["source"]]
             for r in summary["published"]]))
    return "\n".join(lines)


def ladder_line(tries: list[dict]) -> str:
    """The sizes a derived element size's mesh was tried at, with the share of the volume in slivers of each."""
    from housingfe.fe.model import MAX_SLIVER_VOLUME_FRACTION, MIN_ELEMENT_QUALITY

    def share(t):
        f = t.get("low_volume_fraction")
        return f"{f:.1e} of the volume in slivers" if f is not None else f"worst element {t['min']:.3f}"

    return (f"element sizes tried (a mesh passes with at most {MAX_SLIVER_VOLUME_FRACTION:g} of its volume in "
            f"elements below quality {MIN_ELEMENT_QUALITY:g}): ") + \
        "; ".join(f"{t['size_m'] * 1e3:.4g} mm: {t['elements']} elements, {share(t)}"
                  f"{' (used)' if t['passed'] else ''}" for t in tries)


def _error_clause(resolution: dict) -> str:
    err, bound = resolution["estimated_error_near_f_max"], resolution["error_bound_near_f_max"]
    if err is None:
        return f"discretisation error not estimated ({resolution['element_family']} elements are not calibrated)"
    # finer than every calibration point with >= 1 % error: the bound (or 1 %) is all the data say
    typical = f"< {_percent(min(bound, 0.01))}" if resolution["below_calibration"] else _percent(err)
    return (f"estimated discretisation error near f_max {typical} (bound {_percent(bound)}"
            + (", extrapolated" if resolution["extrapolated"] else "") + ")")


def _percent(err: float) -> str:
    return "> 100 %" if err > 1.0 else f"~{err * 100:.2g} %"


def resolution_text(resolution: dict) -> str:
    """One line: elements and node spacings per bending wavelength of the worst wall at f_max, the other walls'
    elements per wavelength, and the estimated error of the modes near f_max (housingfe.fe.resolution)."""
    w = next(w for w in resolution["walls"] if w["name"] == resolution["worst_wall"])
    others = [f"{x['name']} {x['elements_per_wavelength']:.3g}" for x in resolution["walls"] if x is not w]
    return (f"resolution at {resolution['f_max_hz']:g} Hz ({resolution['status']}): "
            f"{w['elements_per_wavelength']:.3g} {resolution['element_family']} elements "
            f"({w['nodes_per_wavelength']:.3g} node spacings) per bending wavelength of the {w['name']} "
            f"({w['thickness_m'] * 1e3:.3g} mm thick, lambda_b {w['bending_wavelength_m'] * 1e3:.3g} mm, longest "
            f"element edge there {w.get('element_size_m', resolution['element_size_m']) * 1e3:.3g} mm)"
            + (f"; other walls: {', '.join(others)} elements per wavelength" if others else "")
            + f"; {_error_clause(resolution)}")


def resolution_lines(resolution: dict | None) -> list[str]:
    """The resolution line and its warnings (empty without a resolution)."""
    if not resolution:
        return []
    return [resolution_text(resolution)] + [f"WARNING: {w}" for w in resolution["warnings"]]


def write_modal_outputs(folder: Path, model, result, summary: dict, comm, output) -> None:
    """modes.json, summary.txt, modes.xdmf (ParaView) and PNG pictures into `folder` (collective); `output` says
    which (paraview, pictures, mode_pictures: a housingfe.scene.OutputSpec or anything with those attributes)."""
    if output.paraview:
        write_modes_xdmf(folder / "modes.xdmf", model, result, comm)
    # the shapes of every rank's part of the mesh, gathered on rank 0 for the picture (collective; modes.png was
    # left out on more than one rank)
    shapes = mode_shapes_on_rank_zero(model, result, output.mode_pictures, comm) \
        if output.pictures and output.mode_pictures else None
    if comm.rank != 0:
        return
    write_json(folder / "modes.json", summary)
    (folder / "summary.txt").write_text(modal_summary_text(summary) + "\n")
    if output.pictures:
        plot_frequencies(folder / "frequencies.png", summary)
        if shapes is not None:
            plot_mode_shapes(folder / "modes.png", shapes)


def write_modes_xdmf(path: Path, model, result, comm) -> None:
    """Mode shapes interpolated to vertex values, one 'time' step per mode (step = mode number)."""
    from dolfinx import fem, io

    mesh = model.V.mesh
    V1 = fem.VectorFunctionSpace(mesh, ("Lagrange", 1))
    uh, u1 = fem.Function(model.V), fem.Function(V1, name="mode")
    with io.XDMFFile(comm, str(path), "w") as xdmf:
        xdmf.write_mesh(mesh)
        for i, x in enumerate(result.vectors):
            x.copy(uh.vector)
            uh.x.scatter_forward()
            u1.interpolate(uh)
            xdmf.write_function(u1, float(i + 1))


def plot_frequencies(path: Path, summary: dict) -> None:
    """Cumulative mode count against frequency, with the published values where the scene has them."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    f = np.asarray(summary["frequencies_hz"])
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.step(np.r_[0, f], np.arange(len(f) + 1), where="post", label=f"housingfe ({summary['element']})")
    for r in summary.get("published", []):
        q = r["quantity"]
        if q.startswith("elastic modes below"):
            f_lim = float(q.split()[3])
            ax.plot([f_lim], [r["published"]], "s", ms=8, label=f"{q}: {r['published']}")
        elif q.startswith("first elastic mode"):
            ax.plot([r["published"]], [1], "o", ms=8, label=f"{q}: {r['published']} Hz")
        elif q.startswith("elastic mode "):
            n = int(q.split()[-1])
            ax.plot([r["published"]], [n], "x", color="k", label="reference" if n == 1 else None)
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("number of elastic modes below")
    ax.set_title(f"{summary['scene']}: {len(f)} elastic modes below {summary['f_max_hz']:g} Hz")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def mode_shapes_on_rank_zero(model, result, count: int, comm) -> dict | None:
    """The first `count` elastic mode shapes of `result` as vertex (P1) fields on the whole mesh, gathered on rank 0
    (collective; None on the other ranks and when there is no elastic mode): {"topology", "cell_types", "points",
    "shapes": [(title, u (points, 3))]} for plot_mode_shapes.  Each rank sends its own cells, in global vertex
    numbers, so the grid is the same on any number of ranks."""
    import numpy as np
    from dolfinx import fem, plot

    n_rigid = result.rigid_count
    modes = list(range(n_rigid, min(n_rigid + count, len(result.vectors))))
    if not modes:
        return None
    mesh = model.V.mesh
    V1 = fem.VectorFunctionSpace(mesh, ("Lagrange", 1))
    topology, cell_types, x = plot.create_vtk_mesh(V1)
    index_map = V1.dofmap.index_map
    global_ids = index_map.local_to_global(np.arange(index_map.size_local + index_map.num_ghosts, dtype=np.int32))
    owned = mesh.topology.index_map(mesh.topology.dim).size_local      # the first cells; the rest are ghosts
    cells = topology.reshape(len(cell_types), -1)[:owned].copy()         # [n, v_1..v_n] per cell, one cell type
    cells[:, 1:] = global_ids[cells[:, 1:]]
    parts = comm.gather((cells, cell_types[:owned], global_ids, x), root=0)
    uh, u1 = fem.Function(model.V), fem.Function(V1)
    fields = []
    for i in modes:
        result.vectors[i].copy(uh.vector)
        uh.x.scatter_forward()
        u1.interpolate(uh)
        fields.append(comm.gather(u1.x.array.reshape(-1, 3).copy(), root=0))
    if comm.rank != 0:
        return None
    n_points = index_map.size_global
    points = np.zeros((n_points, 3))
    for _, _, ids, xs in parts:
        points[ids] = xs
    shapes = []
    for k, (i, per_rank) in enumerate(zip(modes, fields)):
        u = np.zeros((n_points, 3))
        for (_, _, ids, _), values in zip(parts, per_rank):
            u[ids] = values
        shapes.append((f"mode {k + 1}: {result.frequencies_hz[i]:.1f} Hz", u))
    return {"topology": np.concatenate([c.ravel() for c, _, _, _ in parts]),
            "cell_types": np.concatenate([t for _, t, _, _ in parts]), "points": points, "shapes": shapes}


def plot_mode_shapes(path: Path, shapes: dict) -> None:
    """Off-screen picture of mode shapes (mode_shapes_on_rank_zero's dict; pyvista, deformed surface coloured by
    |u|)."""
    import os

    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import numpy as np
    import pyvista

    pyvista.OFF_SCREEN = True
    topology, cell_types, x = shapes["topology"], shapes["cell_types"], shapes["points"]
    size = float(np.ptp(x, axis=0).max())
    count = len(shapes["shapes"])
    cols = min(3, count)
    rows = (count + cols - 1) // cols
    plotter = pyvista.Plotter(shape=(rows, cols), off_screen=True, window_size=(420 * cols, 340 * rows))
    for k, (title, u) in enumerate(shapes["shapes"]):
        full = pyvista.UnstructuredGrid(topology, cell_types, x)
        full.point_data["u"] = u
        full.point_data["|u|"] = np.linalg.norm(u, axis=1)
        surface = full.extract_surface(algorithm="dataset_surface")
        warped = surface.warp_by_vector("u", factor=0.06 * size / max(np.abs(u).max(), 1e-30))
        plotter.subplot(k // cols, k % cols)
        plotter.add_mesh(warped, scalars="|u|", show_scalar_bar=False, cmap="viridis")
        plotter.add_text(title, font_size=10)
        plotter.view_isometric()
    plotter.screenshot(str(path))
    plotter.close()


# --------------------------------------------------------------------------------------- harmonic results
def _band_rows(forced):
    """(load, band nominal, band centre, {solver: (Lv, TF)}, {N: TF_points}, lines) for every band that holds
    at least one line (a band without lines has no level and is left out: see band_note)."""
    from housingfe import levels as lv
    from housingfe.response.observers import band_levels, band_line_counts, transfer_band_levels

    spec = forced.spec
    rows = []
    solvers = list(forced.responses)
    main = solvers[-1] if "direct" not in solvers else solvers[0]
    for j, lc in enumerate(forced.loads):
        per_solver = {}
        bands = None
        for s in solvers:
            r = forced.responses[s][j]
            bands, L, TF = transfer_band_levels(r, max(spec.f_min, 10.0), spec.f_max)
            per_solver[s] = (L, TF)
        r = forced.responses[main][j]
        points = {}
        for N, ms in r.point_mean_square_velocity.items():
            _, Lp = band_levels(r.frequencies, ms * r.amplitude**2, max(spec.f_min, 10.0), spec.f_max, lv.V0)
            points[N] = Lp - per_solver[main][0] + per_solver[main][1]
        counts = band_line_counts(r.frequencies, bands)
        for b in np.flatnonzero(counts > 0):
            rows.append((lc.name, bands.nominal[b], bands.center[b], {s: (v[0][b], v[1][b]) for s, v in per_solver.items()},
                         {N: p[b] for N, p in points.items()}, int(counts[b])))
    return rows, solvers


def band_note(forced) -> str | None:
    """Why a 1/3-octave band or a line is missing from bands.csv (None when nothing is): bands narrower than
    df that hold no line, lines below the lowest band (10 Hz) or beyond the highest."""
    from housingfe import levels as lv
    from housingfe.response.observers import band_line_counts

    spec = forced.spec
    f = spec.frequencies
    bands = lv.third_octave_bands(max(spec.f_min, 10.0), spec.f_max)
    counts = band_line_counts(f, bands)
    if not len(bands.center):
        return (f"no 1/3-octave band: bands start at 10 Hz (lower edge 8.91 Hz) and the lines end at {f[-1]:g} Hz; "
                "bands.csv and octave_bands.csv are empty, frf.csv and points.csv hold the lines")
    notes = []
    empty = bands.nominal[counts == 0]
    if len(empty):
        notes.append(f"1/3-octave band(s) {', '.join(f'{v:g}' for v in empty)} Hz hold no line (df = {spec.df:g} Hz "
                     "is wider than the band there): left out of bands.csv")
    lo, hi = bands.lower[0], bands.upper[-1]
    below, above = f[f < lo], f[f >= hi]
    if len(below):
        notes.append(f"{len(below)} line(s) ({', '.join(f'{v:g}' for v in below[:5])}{' ...' if len(below) > 5 else ''}"
                     f" Hz) lie below the lowest band ({bands.nominal[0]:g} Hz, lower edge {lo:.3g} Hz; bands start "
                     "at 10 Hz): in frf.csv, in no band")
    if len(above):
        notes.append(f"{len(above)} line(s) above {hi:.4g} Hz (upper edge of the highest band whose centre is "
                     f"<= f_max) are in no band")
    return "; ".join(notes) or None


def octave_rows(forced, solver: str) -> list:
    """Octave-band (IEC 61260, base 10) L_v and TF of every load case: energy sums of the lines."""
    from housingfe import levels as lv

    spec = forced.spec
    bands = lv.fractional_octave_bands(max(spec.f_min, 10.0), spec.f_max, 1)
    rows = []
    for r in forced.responses[solver]:
        f = r.frequencies
        ms = lv.band_sum(f, r.mean_square_velocity * r.amplitude**2, bands)
        load = lv.band_sum(f, r.amplitude**2, bands)
        with np.errstate(divide="ignore", invalid="ignore"):
            Lv = lv.level(ms, lv.V0)
            tf = Lv - lv.level(load, 1.0)
        lines = lv.band_sum(f, np.ones_like(f), bands).astype(int)
        rows += [[r.name, bands.nominal[b], bands.center[b], Lv[b], tf[b], solver, lines[b]]
                 for b in range(len(bands.center)) if lines[b] > 0 and load[b] > 0]
    return rows


def band_comparison(forced, reference: str = "direct") -> dict:
    """Per solver: max |band TF - reference band TF| (dB) over all load cases and bands, and the rows."""
    rows, solvers = _band_rows(forced)
    out = {}
    if reference not in solvers:
        return out
    for s in solvers:
        if s == reference:
            continue
        diffs = [r[3][s][1] - r[3][reference][1] for r in rows if np.isfinite(r[3][reference][1])]
        if not diffs:     # no band holds a line
            continue
        out[s] = {"max_abs_dB": float(np.max(np.abs(diffs))), "mean_dB": float(np.mean(diffs))}
    return out


def harmonic_summary_text(forced) -> str:
    """Human-readable summary of the forced response."""
    spec = forced.spec
    lines = [f"forced response: {len(forced.loads)} load case(s), {forced.facts['frequencies']} lines "
             f"{spec.f_min:g}..{spec.f_max:g} Hz (df = {spec.df:g} Hz), surface {spec.surface} "
             f"S = {forced.facts['surface_area_m2']:.4f} m^2; solvers: {', '.join(forced.responses)}"]
    lines.append("timings: " + ", ".join(f"{k} {v:.2f} s" for k, v in forced.timings.items()))
    for s, d in band_comparison(forced).items():
        lines.append(f"{s} vs direct: max |band TF difference| {d['max_abs_dB']:.2f} dB, mean {d['mean_dB']:+.2f} dB")
    rows, solvers = _band_rows(forced)
    main = solvers[0]
    header = ["load", "band Hz"] + [f"TF {s} dB" for s in solvers]
    table = [[r[0], f"{r[1]:g}"] + [round(float(r[3][s][1]), 2) for s in solvers] for r in rows]
    lines.append(f"1/3-octave TF (dB re {main}):")
    lines.append(format_table(header, table))
    note = band_note(forced)
    if note:
        lines.append("note: " + note)
    for rp in forced.response_points:
        lines.append(f"response point {rp.name}: {(np.round(rp.point, 4) + 0.0).tolist()} m on surface {rp.surface} "
                     f"(snapped {rp.distance * 1e3:.2f} mm), directions {', '.join(rp.labels)}: points.csv")
    for ds in forced.deflection_shapes[:1]:
        lines.append(f"operating deflection shapes ({ds.solver}) at "
                     f"{', '.join(sorted({f'{d.frequency:g}' for d in forced.deflection_shapes}))} Hz: ods_<load>.xdmf")
    if forced.angular_velocity_node:
        lines.append(f"TF_omega = L_v - L_omega, omega about the shaft axis at {forced.angular_velocity_node} "
                     "(eq. 5.5), 1/3-octave bands:")
        lines.append(format_table(["load", "solver", "band Hz", "TF_omega dB"],
                                  [[r[0], r[1], f"{r[2]:g}", round(float(r[4]), 2)] for r in tf_omega_band_rows(forced)]))
    return "\n".join(lines)


def write_harmonic_outputs(folder: Path, model, forced, comm, *, scene_name: str, pictures: bool) -> None:
    """frf.csv, bands.csv, receptance.csv, points.csv, harmonic.json, TF plots (if `pictures`), operating deflection
    shapes (ods_<load>.xdmf); `scene_name` labels harmonic.json."""
    ods_files = write_deflection_shapes(folder, model, forced, comm) if forced.deflection_shapes else {}
    if comm.rank != 0:
        return
    counts = sorted(forced.observer.samples)
    frf = []
    for s, resps in forced.responses.items():
        for r in resps:
            for k, f in enumerate(r.frequencies):
                frf.append([r.name, s, f, r.velocity_level_db[k], r.transfer_db[k]]
                           + [float(_db(r.point_mean_square_velocity[N][k])) for N in counts])
    write_csv(folder / "frf.csv", ["load_case", "solver", "frequency_hz", "Lv_dB", "TF_dB"]
              + [f"TF_points{N}_dB" for N in counts], frf)
    rows, solvers = _band_rows(forced)
    header = ["load_case", "band_nominal_hz", "band_center_hz", "lines", "Lv_dB", "TF_dB", "solver"]
    header += [f"TF_{s}_dB" for s in solvers[1:]] + [f"TF_points{N}_dB" for N in counts]
    write_csv(folder / "bands.csv", header,
              [[r[0], r[1], r[2], r[5], r[3][solvers[0]][0], r[3][solvers[0]][1], solvers[0]]
               + [r[3][s][1] for s in solvers[1:]] + [r[4][N] for N in counts] for r in rows])
    write_csv(folder / "octave_bands.csv", ["load_case", "band_nominal_hz", "band_center_hz", "Lv_dB", "TF_dB",
                                            "solver", "lines"], octave_rows(forced, solvers[0]))
    if forced.response_points:
        from housingfe.response.forced import POINT_COLUMNS, point_rows

        write_csv(folder / "points.csv", POINT_COLUMNS, point_rows(forced))
    main = forced.responses[solvers[0]]
    rec = []
    for i, ri in enumerate(main):
        for j, lj in enumerate(forced.loads):
            for k, f in enumerate(ri.frequencies):
                h = ri.receptance[j, k]
                rec.append([lj.name, ri.name, f, h.real, h.imag, abs(h)])
    write_csv(folder / "receptance.csv", ["response_at", "load_case", "frequency_hz", "real", "imag", "abs"], rec)
    resolution = model.resolution.as_dict() if getattr(model, "resolution", None) is not None else None
    write_json(folder / "harmonic.json", {
        "scene": scene_name, "solvers": solvers, "timings_s": forced.timings, **forced.facts,
        "resolution": resolution,
        "band_comparison_vs_direct": band_comparison(forced),
        "sample_points": {N: {"points_m": s.points, "weights_m2": s.weights}
                          for N, s in forced.observer.samples.items()},
        "load_cases": [{"name": lc.name, "kind": lc.kind, "patch_area_m2": lc.patch_area, "centre_m": lc.centre}
                       for lc in forced.loads],
        "band_note": band_note(forced),
        "response_points": [{"name": rp.name, "requested_m": rp.requested, "snapped_m": rp.point,
                             "snap_distance_m": rp.distance, "surface": rp.surface, "outward_normal": rp.normal,
                             "directions": dict(zip(rp.labels, rp.directions.tolist()))}
                            for rp in forced.response_points],
        "deflection_shapes": {
            "files": ods_files, "solver": forced.deflection_shapes[0].solver if forced.deflection_shapes else None,
            "frequencies_hz": sorted({d.frequency for d in forced.deflection_shapes}),
            "fields": "displacement_re, displacement_im (m, rms phasor for the load's amplitude, e^{i omega t}), "
                      "displacement_abs (m, |u|); time = frequency (Hz)"}})
    (folder / "summary_forced.txt").write_text(harmonic_summary_text(forced) + "\n"
                                               + "".join(line + "\n" for line in resolution_lines(resolution)))
    if forced.angular_velocity_node:
        write_csv(folder / "tf_omega.csv", ["load_case", "solver", "frequency_hz", "L_omega_dB", "TF_omega_dB"],
                  tf_omega_rows(forced))
        write_csv(folder / "tf_omega_bands.csv", ["load_case", "solver", "band_nominal_hz", "band_center_hz",
                                                  "TF_omega_dB"], tf_omega_band_rows(forced))
    if pictures:
        plot_transfer_functions(folder / "tf_bands.png", forced, rows, solvers)
    if forced.sound_power:
        write_sound_power(folder, forced, pictures, scene_name)


def tf_omega_rows(forced) -> list:
    """Narrow-band TF_omega = L_v - L_omega (eq. 5.5) of every load case and solver."""
    return [[r.name, solver, f, r.extras["L_omega_dB"][k], r.extras["TF_omega_dB"][k]]
            for solver, resps in forced.responses.items() for r in resps for k, f in enumerate(r.frequencies)]


def tf_omega_band_rows(forced) -> list:
    """1/3-octave TF_omega: band L_v minus band L_omega (energy sums of the lines in each band)."""
    from housingfe import levels
    from housingfe.response.observers import band_levels

    out = []
    for solver, resps in forced.responses.items():
        for r in resps:
            f = r.frequencies
            f_lo = max(f[0], 10.0)
            bands, lv = band_levels(f, r.mean_square_velocity, f_lo, f[-1], levels.V0)
            _, lw = band_levels(f, r.extras["omega_mean_square"], f_lo, f[-1], levels.OMEGA0)
            out += [[r.name, solver, n, c, v - w] for n, c, v, w in zip(bands.nominal, bands.center, lv, lw)
                    if np.isfinite(v - w)]
    return out


def _db(ms):
    from housingfe import levels

    return levels.level(np.asarray(ms), levels.V0)


def plot_transfer_functions(path: Path, forced, rows, solvers) -> None:
    """Per load case: TF per 1/3-octave band (bars, like the thesis' Fig. 4.5) and narrow band."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    n = len(forced.loads)
    fig, axes = plt.subplots(n, 2, figsize=(12, 3.6 * n), squeeze=False)
    for j, lc in enumerate(forced.loads):
        ax = axes[j, 0]
        sel = [r for r in rows if r[0] == lc.name]
        x = np.arange(len(sel))
        width = 0.8 / len(solvers)
        for k, s in enumerate(solvers):
            ax.bar(x + k * width, [r[3][s][1] for r in sel], width, label=s)
        ax.set_xticks(x + 0.4 - width / 2, [f"{r[1]:g}" for r in sel], rotation=90, fontsize=7)
        ax.set_ylabel("TF (dB)")
        ax.set_title(f"{lc.name}: 1/3-octave TF")
        ax.legend(fontsize=7)
        if sel:
            ax.set_ylim(np.nanmin([r[3][s][1] for r in sel for s in solvers]) - 10, None)
        else:      # no band holds a line (all lines below 10 Hz): say so instead of an empty frame
            ax.text(0.5, 0.5, "no 1/3-octave band holds a line", ha="center", transform=ax.transAxes)
        ax = axes[j, 1]
        for s in solvers:
            r = forced.responses[s][j]
            ax.plot(r.frequencies, r.transfer_db, lw=0.8, label=s)
        ax.set_xlabel("frequency (Hz)")
        ax.set_ylabel("TF (dB re v0/F0)")
        ax.set_title(f"{lc.name}: narrow band")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_deflection_shapes(folder: Path, model, forced, comm) -> dict:
    """Operating deflection shapes, one XDMF file per load case (ods_<load>.xdmf), one time step per line with
    time = frequency (Hz): displacement_re and displacement_im (vertex values, m, rms phasor for the load's
    amplitude and spectrum, u(t) = Re((re + i im) e^{i omega t}) sqrt 2) and displacement_abs = |u| (m).
    Returns {load: file name} (collective)."""
    import re

    import ufl
    from dolfinx import fem, io

    mesh = model.V.mesh
    V1 = fem.VectorFunctionSpace(mesh, ("Lagrange", 1))
    S1 = fem.FunctionSpace(mesh, ("Lagrange", 1))
    uh = fem.Function(model.V)
    ure, uim = fem.Function(V1, name="displacement_re"), fem.Function(V1, name="displacement_im")
    uabs = fem.Function(S1, name="displacement_abs")
    magnitude = fem.Expression(ufl.sqrt(ufl.inner(ure, ure) + ufl.inner(uim, uim)),
                               S1.element.interpolation_points())
    files = {}
    for lc in forced.loads:
        name = re.sub(r"[^A-Za-z0-9_.-]+", "_", lc.name)
        while f"ods_{name}.xdmf" in files.values():
            name += "_"
        files[lc.name] = f"ods_{name}.xdmf"
        with io.XDMFFile(comm, str(folder / files[lc.name]), "w") as xdmf:
            xdmf.write_mesh(mesh)
            for ds in (d for d in forced.deflection_shapes if d.load == lc.name):
                for vec, out in ((ds.real, ure), (ds.imag, uim)):
                    vec.copy(uh.vector)
                    uh.x.scatter_forward()
                    out.interpolate(uh)
                uabs.interpolate(magnitude)
                for fn in (ure, uim, uabs):
                    xdmf.write_function(fn, ds.frequency)
    return files


# ------------------------------------------------------------------------------------------ sound power
def sound_power_rows(forced) -> list:
    """Rows of sound_power.csv: per load case, every line and every 1/3-octave band (and the totals)."""
    from housingfe import levels
    from housingfe.response.observers import band_levels, band_line_counts

    rows = []
    solver = next(iter(forced.responses))
    for sp, resp in zip(forced.sound_power, forced.responses[solver]):
        s = sp.spectrum
        LS = 10 * np.log10(forced.observer.area)
        for k, f in enumerate(s.frequencies_hz):
            rows.append([sp.load_case, sp.model, "line", f, resp.velocity_level_db[k], sp.radiation_index_db[k],
                         s.L_W_db[k], s.L_W_db[k] + float(levels.a_weighting_db(f))])
        _, Lv_band = band_levels(resp.frequencies, resp.mean_square_velocity * resp.amplitude**2,
                                 s.bands.nominal.min(), s.bands.nominal.max(), levels.V0)
        lines = band_line_counts(resp.frequencies, s.bands)
        for b in np.flatnonzero(lines > 0):    # a band without lines has no level (band_note says which)
            rows.append([sp.load_case, sp.model, "band", s.bands.nominal[b], Lv_band[b],
                         s.band_L_W_db[b] - Lv_band[b] - LS, s.band_L_W_db[b], s.band_L_WA_db[b]])
        rows.append([sp.load_case, sp.model, "total", "", "", "", s.total_L_W_db, s.total_L_WA_db])
    return rows


def write_sound_power(folder: Path, forced, pictures: bool, scene_name: str = "") -> None:
    """sound_power.csv and, with pictures, sound_power.png: the radiation index L_sigma = 10 lg sigma (dB) per
    line and L_W (dB re 1 pW) per 1/3-octave band of each load case, for the load's amplitude and spectrum as the
    scene gives them, titled with the scene, the radiation model and the radiating area."""
    rows = sound_power_rows(forced)
    if forced.sound_power[0].foller is not None:
        write_json(folder / "foller.json", forced.sound_power[0].foller)
    write_csv(folder / "sound_power.csv", ["load_case", "model", "kind", "band_center_hz", "Lv_dB",
                                          "Lsigma_dB", "Lw_dB", "LwA_dB"], rows)
    if not pictures:
        return
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    units = {"force": "N", "moment": "N m", "pressure": "Pa"}
    kinds = {lc.name: lc.kind for lc in forced.loads}
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(12, 4.6))
    for sp in forced.sound_power:
        unit = units.get(kinds.get(sp.load_case), "")
        a1.semilogx(sp.spectrum.frequencies_hz, sp.radiation_index_db, lw=0.8, label=f"{sp.load_case} ({sp.model})")
        a2.plot(np.arange(len(sp.spectrum.bands.nominal)), sp.spectrum.band_L_W_db, "o-", ms=3,
                label=f"{sp.load_case} ({kinds.get(sp.load_case, 'load')}{', ' + unit if unit else ''} rms): total "
                      f"{sp.spectrum.total_L_W_db:.1f} dB, {sp.spectrum.total_L_WA_db:.1f} dB(A)")
    nominal = forced.sound_power[0].spectrum.bands.nominal
    a2.set_xticks(np.arange(len(nominal)), [f"{v:g}" for v in nominal], rotation=90, fontsize=7)
    a1.set_title("radiation index per line", fontsize=9)
    a1.set_xlabel("frequency (Hz)")
    a1.set_ylabel("L_sigma = 10 lg sigma (dB)")
    a1.grid(alpha=0.3, which="both")
    a1.legend(fontsize=7)
    a2.set_title("sound power per 1/3-octave band, for the scene's load amplitude and spectrum", fontsize=9)
    a2.set_xlabel("1/3-octave band centre frequency (Hz)")
    a2.set_ylabel("L_W (dB re 1 pW)")
    a2.grid(alpha=0.3)
    a2.legend(fontsize=7)
    models = sorted({sp.model for sp in forced.sound_power})
    fig.suptitle(f"{scene_name + ': ' if scene_name else ''}sound power L_W = L_v + 10 lg(S/S0) + L_sigma, "
                 f"radiation model {', '.join(models)}, radiating surface S = {forced.observer.area:.3g} m^2",
                 fontsize=10)
    fig.tight_layout()
    # the labels also as PNG text, for readers (and tests) that cannot see the picture
    fig.savefig(folder / "sound_power.png", dpi=110, metadata={
        "Title": fig._suptitle.get_text(),
        "Description": " | ".join(f"{ax.get_title()}: x {ax.get_xlabel()}, y {ax.get_ylabel()}" for ax in (a1, a2))})
    plt.close(fig)
