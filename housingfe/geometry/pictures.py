"""Pictures of housing meshes for the documentation: the surface mesh coloured by feature (cell group),
seen from the front and from the back.  `python -m housingfe.geometry.pictures <scene>... --out DIR`
writes DIR/<scene>-mesh.png (off-screen, pyvista)."""
from __future__ import annotations

import argparse
import os
from pathlib import Path


def mesh_picture(scene_name: str, path: Path) -> None:
    """Render the scene's mesh (at its default size) coloured by cell group into a PNG at `path`."""
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import numpy as np
    import pyvista
    from dolfinx import plot
    from mpi4py import MPI

    from housingfe.fe.model import element_size
    from housingfe.geometry import build_mesh
    from housingfe.scene import load_housing_scene

    scene, _ = load_housing_scene(scene_name)
    size = element_size(scene.mesh, scene.geometry, scene.analysis.f_max, scene.material.resolve())
    hm = build_mesh(scene.geometry, scene.mesh.element, size, scene.mesh.layers, MPI.COMM_SELF)
    topology, cell_types, x = plot.create_vtk_mesh(hm.mesh, hm.mesh.topology.dim)
    grid = pyvista.UnstructuredGrid(topology, cell_types, x)
    n_cells = hm.mesh.topology.index_map(3).size_local
    group = np.zeros(n_cells)
    names = sorted(hm.cell_groups)
    for i, name in enumerate(names):
        group[hm.cell_tags.find(hm.cell_groups[name])] = i
    grid.cell_data["feature"] = group
    pyvista.OFF_SCREEN = True
    plotter = pyvista.Plotter(shape=(1, 2), off_screen=True, window_size=(1400, 560))
    for col, view in enumerate(((-1.0, -1.6, 1.0), (1.2, 1.4, -1.0))):
        plotter.subplot(0, col)
        plotter.add_mesh(grid, scalars="feature", show_edges=True, edge_color="black", line_width=0.3,
                         cmap="tab20", show_scalar_bar=False)
        plotter.camera_position = "iso"
        plotter.camera.position = tuple(np.array(view) * 1.0)
        plotter.camera.focal_point = tuple(np.asarray(hm.centroid))
        plotter.camera.up = (0.0, 0.0, 1.0)
        plotter.reset_camera()
        label = f"{scene.scene.name}: {hm.mesh.topology.index_map(3).size_global} {hm.element} cells, h = " \
                f"{size * 1e3:.1f} mm" if col == 0 else "from the back"
        plotter.add_text(label, font_size=10)
    plotter.screenshot(str(path))
    plotter.close()


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("scenes", nargs="+")
    parser.add_argument("--out", default="docs/img")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name in args.scenes:
        mesh_picture(name, out / f"{name}-mesh.png")
        print(out / f"{name}-mesh.png")


if __name__ == "__main__":
    main()
