"""Pictures of housing meshes for the documentation: the surface mesh coloured by feature (cell group),
seen from the front and from the back (off-screen, pyvista).  `housingfe mesh-picture <scene>... --out DIR`
writes DIR/<scene>-mesh.png."""
from __future__ import annotations

import os
from pathlib import Path


def mesh_picture(hm, path: Path, label: str) -> None:
    """Render a HousingMesh `hm` coloured by cell group into a PNG at `path`, `label` above the front view."""
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import numpy as np
    import pyvista
    from dolfinx import plot
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
        plotter.add_text(label if col == 0 else "from the back", font_size=10)
    plotter.screenshot(str(path))
    plotter.close()
