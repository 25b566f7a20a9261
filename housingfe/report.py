"""Writing results: atomic output folders, JSON/CSV helpers, human-readable summaries."""
from __future__ import annotations

import contextlib
import csv
import json
import os
import shutil
from pathlib import Path
from typing import Iterable, Iterator, Sequence


@contextlib.contextmanager
def atomic_output_dir(out_dir: str | os.PathLike, comm=None) -> Iterator[Path]:
    """Yield a temporary folder beside `out_dir`; on success it replaces `out_dir`, on any error it is
    removed, so a result folder that exists is always complete.  With an MPI communicator every rank gets
    the same folder (rank 0 creates and renames it); without one the caller is the only writer."""
    out = Path(out_dir)
    rank = comm.rank if comm is not None else 0
    tmp = out.parent / f".{out.name}.tmp-{os.getpid()}"
    if comm is not None:
        tmp = comm.bcast(tmp, root=0)
    if rank == 0:
        out.parent.mkdir(parents=True, exist_ok=True)
        if tmp.exists():
            shutil.rmtree(tmp)
        tmp.mkdir()
    if comm is not None:
        comm.barrier()
    try:
        yield tmp
        if comm is not None:
            comm.barrier()
    except BaseException:
        if rank == 0:
            shutil.rmtree(tmp, ignore_errors=True)
        raise
    if rank == 0:
        if out.exists():
            shutil.rmtree(out)
        os.replace(tmp, out)


def write_json(path: Path, data) -> None:
    """Write `data` as indented JSON (numpy scalars and arrays converted)."""
    def default(o):
        if hasattr(o, "tolist"):
            return o.tolist()
        raise TypeError(f"not JSON serialisable: {type(o)}")

    path.write_text(json.dumps(data, indent=2, default=default) + "\n")


def write_csv(path: Path, header: Sequence[str], rows: Iterable[Sequence]) -> None:
    """Write rows under a header line as CSV."""
    with open(path, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(header)
        for row in rows:
            writer.writerow(row)


def format_table(header: Sequence[str], rows: Sequence[Sequence], floatfmt: str = "{:.4g}") -> str:
    """A plain-text table with aligned columns (for terminals and summary.txt)."""
    cells = [[str(h) for h in header]]
    for row in rows:
        cells.append([floatfmt.format(v) if isinstance(v, float) else str(v) for v in row])
    widths = [max(len(r[i]) for r in cells) for i in range(len(header))]
    lines = ["  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in cells]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


# ------------------------------------------------------------------------------------------ modal results
def modal_summary_text(summary: dict) -> str:
    """The human-readable summary of a modal run (summary.txt and the terminal)."""
    f = summary["frequencies_hz"]
    lines = [
        f"scene {summary['scene']}: {summary['description']}",
        f"{summary['dofs']} DOFs ({summary['element']}, element size {summary['element_size_m'] * 1e3:.1f} mm, "
        f"{summary['mpi_ranks']} MPI rank(s)), wall time {summary['wall_time_s']:.1f} s",
        f"{len(f)} elastic modes below {summary['f_max_hz']:g} Hz; "
        f"complete: {summary['complete']} (inertia count {summary['eigenvalues_below_f_max_by_inertia']} "
        f"incl. {len(summary['rigid_body_frequencies_hz'])} rigid-body modes)",
        f"max relative residual {max(summary['residuals'], default=0.0):.1e}",
        f"mass {summary['mass_kg']:.3f} kg (geometry)"
        + (f", {summary['mass_from_rigid_modes_kg']:.3f} kg (rigid-body modes)"
           if summary["mass_from_rigid_modes_kg"] is not None else ""),
    ]
    if len(f):
        lines.append("elastic eigenfrequencies (Hz):")
        for i in range(0, len(f), 8):
            lines.append("  " + "  ".join(f"{v:8.2f}" for v in f[i:i + 8]))
    if summary.get("published"):
        lines.append("compared with published values:")
        lines.append(format_table(
            ["quantity", "ours", "published", "unit", "source"],
            [[r["quantity"], r["ours"], r["published"], r["unit"], r["source"]] for r in summary["published"]]))
    return "\n".join(lines)


def write_modal_outputs(folder: Path, model, result, summary: dict, comm) -> None:
    """modes.json, summary.txt, modes.xdmf (ParaView) and PNG pictures into `folder` (collective)."""
    scene = model.scene
    if scene.output.paraview:
        write_modes_xdmf(folder / "modes.xdmf", model, result, comm)
    if comm.rank != 0:
        return
    write_json(folder / "modes.json", summary)
    (folder / "summary.txt").write_text(modal_summary_text(summary) + "\n")
    if scene.output.pictures:
        plot_frequencies(folder / "frequencies.png", summary)
        if comm.size == 1 and scene.output.mode_pictures:
            plot_mode_shapes(folder / "modes.png", model, result, scene.output.mode_pictures)


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


def plot_mode_shapes(path: Path, model, result, count: int) -> None:
    """Off-screen picture of the first elastic mode shapes (pyvista, deformed surface coloured by |u|)."""
    import os

    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import numpy as np
    import pyvista
    from dolfinx import fem, plot

    pyvista.OFF_SCREEN = True
    n_rigid = result.rigid_count
    modes = list(range(n_rigid, min(n_rigid + count, len(result.vectors))))
    if not modes:
        return
    mesh = model.V.mesh
    V1 = fem.VectorFunctionSpace(mesh, ("Lagrange", 1))
    topology, cell_types, x = plot.create_vtk_mesh(V1)
    size = float(np.ptp(x, axis=0).max())
    uh, u1 = fem.Function(model.V), fem.Function(V1)
    cols = min(3, len(modes))
    rows = (len(modes) + cols - 1) // cols
    plotter = pyvista.Plotter(shape=(rows, cols), off_screen=True, window_size=(420 * cols, 340 * rows))
    freqs = result.frequencies_hz
    for k, i in enumerate(modes):
        result.vectors[i].copy(uh.vector)
        uh.x.scatter_forward()
        u1.interpolate(uh)
        full = pyvista.UnstructuredGrid(topology, cell_types, x)
        u = u1.x.array.reshape(-1, 3)
        full.point_data["u"] = u
        full.point_data["|u|"] = np.linalg.norm(u, axis=1)
        surface = full.extract_surface(algorithm="dataset_surface")
        warped = surface.warp_by_vector("u", factor=0.06 * size / max(np.abs(u).max(), 1e-30))
        plotter.subplot(k // cols, k % cols)
        plotter.add_mesh(warped, scalars="|u|", show_scalar_bar=False, cmap="viridis")
        plotter.add_text(f"mode {k + 1}: {freqs[i]:.1f} Hz", font_size=10)
        plotter.view_isometric()
    plotter.screenshot(str(path))
    plotter.close()
