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


def surface_picture(model, path: Path, label: str) -> None:
    """Render the named surfaces of a block model (housingfe.geometry.blocks.BlockModel) into a PNG at `path`: each
    boundary face coloured by its most specific surface name (the name with the fewest faces), every name written
    at its surface, the x, y, z axes at the origin, seen from the front-left-above and from the back-right-below.
    Built from the blocks without meshing (bores, cut by gmsh, are not drawn)."""
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import numpy as np
    import pyvista

    from housingfe.geometry.surfaces import boundary_faces, bounding_box

    faces = list(boundary_faces(model))
    names = [model.classify_face(c, n) for c, n, *_ in faces]
    counts: dict[str, int] = {}
    for ns in names:
        for name in ns:
            counts[name] = counts.get(name, 0) + 1
    # the most specific name of a face: the rarest of its names (outer_top before outer, bolt_3 before foot_bottom)
    label_of = [min(ns, key=lambda n: (counts[n], n)) if ns else "(untagged)" for ns in names]
    order = sorted(set(label_of))
    points, cells = [], []
    for (centre, normal, lo, hi, _), _name in zip(faces, label_of):
        axis = int(np.argmax(np.abs(normal)))
        u, v = [a for a in range(3) if a != axis]
        corners = []
        for du, dv in ((0, 0), (1, 0), (1, 1), (0, 1)):
            p = lo.copy()
            p[u] = hi[u] if du else lo[u]
            p[v] = hi[v] if dv else lo[v]
            corners.append(p)
        cells.append([4, *range(len(points), len(points) + 4)])
        points += corners
    mesh = pyvista.PolyData(np.array(points), np.hstack(cells))
    mesh.cell_data["surface"] = np.array([order.index(n) for n in label_of], dtype=float)
    lower, upper = bounding_box(model)
    span = float(np.max(upper - lower))
    # one label per name at the centre of its largest face, nudged outwards along that face's normal
    anchors, texts, normals = [], [], []
    for name in order:
        best = max((f for f, n in zip(faces, label_of) if n == name),
                   key=lambda f: np.prod([e for e in f[3] - f[2] if e > 0]))
        anchors.append(best[0] + best[1] * 0.02 * span)
        normals.append(best[1])
        texts.append(name)
    pyvista.OFF_SCREEN = True
    plotter = pyvista.Plotter(shape=(1, 2), off_screen=True, window_size=(1600, 700))
    centre = (lower + upper) / 2
    for col, view in enumerate(((-1.0, -1.6, 1.0), (1.2, 1.4, -0.8))):
        plotter.subplot(0, col)
        plotter.add_mesh(mesh, scalars="surface", cmap="tab20", show_edges=True, edge_color="grey", line_width=0.3,
                         show_scalar_bar=False, categories=True)
        # a name is written where its face looks towards the camera and nothing hides it (depth-tested labels)
        facing = [i for i, n in enumerate(normals) if np.dot(n, np.array(view)) > 0]
        plotter.add_point_labels(np.array([anchors[i] for i in facing]), [texts[i] for i in facing], font_size=11,
                                 point_size=6, shape_opacity=0.7, always_visible=False)
        for axis, colour in enumerate(("red", "green", "blue")):
            direction = np.zeros(3)
            direction[axis] = 0.25 * span
            plotter.add_mesh(pyvista.Arrow(start=(0.0, 0.0, 0.0), direction=direction, scale="auto"), color=colour)
        plotter.camera.position = tuple(centre + np.array(view) * 3 * span)
        plotter.camera.focal_point = tuple(centre)
        plotter.camera.up = (0.0, 0.0, 1.0)
        plotter.reset_camera()
        plotter.add_text(label if col == 0 else "from the back, below", font_size=10)
    plotter.screenshot(str(path))
    plotter.close()
