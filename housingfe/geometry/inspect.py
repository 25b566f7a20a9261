"""`housingfe inspect FILE`: what a user needs to know about a CAD file before writing a scene.

Reads the file as the `cad` geometry kind does (housingfe.geometry.cad.read_cad: import, unit check, solids
joined, the face analysis) and prints the solids, bounding box, volume and mass with a chosen material, the
candidate bores (concave cylindrical faces grouped by axis line and radius: centre, axis, radius, length), the
largest flat faces (candidate feet and bolt faces), and the thinnest wall estimate.  Writes a PNG with the
candidates labelled (B1, B2, ... bores; F1, F2, ... flat faces) and a scene skeleton (TOML) whose selectors
are those candidates, which the user edits and runs with `housingfe run`.
"""
from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from housingfe.errors import InputError

FLAT_SHOWN = 6          # the largest plane groups listed
FLAT_IN_SKELETON = 3    # and written into the skeleton as surface selectors
BORES_SHOWN = 12        # the largest candidate bores listed, labelled and written into the skeleton


def inspect_cad(path: Path, units: str = "mm", material: str = "steel", out_dir: Path | None = None,
                picture: bool = True) -> dict:
    """Read and describe a CAD file; write <stem>-inspect.png and <stem>-scene.toml into out_dir (default: the
    file's folder).  Returns the report (lengths in m, areas m^2, volume m^3, mass kg) with the paths."""
    from housingfe.geometry.cad import CAD_SUFFIXES, gmsh_session, read_cad
    from housingfe.geometry.selectors import bore_candidates, flat_candidates
    from housingfe.materials import LIBRARY
    from housingfe.outputs import check_files_folder

    path = Path(path)
    if material not in LIBRARY:
        raise InputError(f"--material: {material!r} is not in the library ({', '.join(LIBRARY)})")
    if path.is_dir():
        raise InputError(f"{path}: is a folder, not a CAD file")
    if not path.is_file():
        raise InputError(f"{path}: no such file")
    if path.suffix.lower() not in CAD_SUFFIXES:
        raise InputError(f"{path}: not a CAD file by its name (expected {', '.join(CAD_SUFFIXES)})")
    out = check_files_folder(out_dir if out_dir is not None else path.parent)
    t0 = time.perf_counter()
    with gmsh_session():
        facts = read_cad(path, units, key=None)
    read_s = time.perf_counter() - t0
    tol = 1e-4 * max(1.0, float(np.linalg.norm(facts.hi - facts.lo)))
    all_bores = bore_candidates(facts.faces, tol)     # largest radius first
    bores = all_bores[:BORES_SHOWN]
    # feet and bolt faces are on the outer skin: the inside of a wall is no candidate
    flats = flat_candidates([f for f in facts.faces if f.tag in facts.outer], tol)[:FLAT_SHOWN]
    density = LIBRARY[material].density
    report = {"file": str(path), "units": units, "solids": facts.solids, "volumes": len(facts.volumes),
              "min": facts.lo, "max": facts.hi, "volume_m3": facts.volume, "material": material,
              "density": density, "mass_kg": density * facts.volume, "centroid": facts.centroid,
              "thin_wall_m": facts.thin_wall, "thinnest_ray_m": facts.thinnest_ray, "bores": bores,
              "bore_count": len(all_bores),
              "flats": flats, "notes": facts.notes, "read_s": read_s}
    skeleton = out / f"{path.stem}-scene.toml"
    text = scene_skeleton(report, os.path.relpath(path.resolve(), out.resolve()), material)
    if skeleton.exists() and _read_or_none(skeleton) != text:
        # the skeleton is meant to be edited: an edited one is the user's scene, never replaced
        raise InputError(f"{skeleton}: exists and is not the skeleton inspect writes now (edited, or from other "
                         "inputs); inspect does not overwrite it: rename or delete it, or give another --out")
    try:
        out.mkdir(parents=True, exist_ok=True)
        skeleton.write_text(text)
    except OSError as exc:
        raise InputError(f"{out}: --out: cannot write the skeleton there ({exc.strerror})") from None
    report["skeleton"] = skeleton
    if picture:
        png = out / f"{path.stem}-inspect.png"
        candidates_picture(facts, bores, flats, png, path.name)
        report["picture"] = png
    report["total_s"] = time.perf_counter() - t0
    return report


def _read_or_none(path: Path) -> str | None:
    try:
        return path.read_text()
    except (OSError, UnicodeDecodeError):
        return None


def _v(x) -> str:
    # nanometre rounding: -1.4e-17 from the CAD kernel's arithmetic is 0
    return "[" + ", ".join(f"{round(float(c), 9) + 0.0:.6g}" for c in x) + "]"


def scene_skeleton(report: dict, file: str, material: str) -> str:
    """A housing scene (TOML) for the inspected file: the candidate bores and the largest flat faces as
    selectors, free-free modes to 2 kHz; comments say what to edit."""
    stem = Path(file).stem
    lines = [
        "# Scene skeleton written by `housingfe inspect`: edit the names, keep the selectors you need, then",
        f"#   housingfe run {stem}-scene.toml",
        "# All lengths in m (the CAD file's own unit is geometry.units).",
        "[scene]",
        f'name = "{stem}"',
        'kind = "housing"',
        f'description = "{Path(file).name} imported from CAD"',
        "",
        "[geometry]",
        'kind = "cad"',
        f'file = "{file}"          # relative to this scene file',
        f'units = "{report["units"]}"',
        f"# thinnest wall found: {report['thin_wall_m'] * 1e3:.3g} mm (it sets the element size); to override:",
        f"# thickness = {report['thin_wall_m']:.4g}",
    ]
    for n, bore in enumerate(report["bores"], start=1):
        lines += ["", f"[[geometry.bores]]          # B{n}: length {bore['length'] * 1e3:.4g} mm",
                  f'name = "B{n}"', f"axis = {_v(bore['axis'])}", f"centre = {_v(bore['centre'])}",
                  f"radius = {bore['radius']:.6g}"]
    for n, flat in enumerate(report["flats"][:FLAT_IN_SKELETON], start=1):
        lines += ["", f"[[geometry.surfaces]]       # F{n}: {flat['area'] * 1e4:.4g} cm^2",
                  f'name = "F{n}"',
                  f"plane = {{ point = {_v(flat['point'])}, normal = {_v(flat['normal'])} }}"]
    lines += ["", "[material]", f'name = "{material}"', "",
              "[mesh]", 'element = "tet"', "degree = 2", "elements_per_wavelength = 6.0", "",
              "[analysis.modal]", "f_max = 2000.0           # Hz", "",
              "# a supported housing: uncomment (else free-free)",
              "# [[supports]]", '# surface = "F1"', '# kind = "fixed"', ""]
    return "\n".join(lines)


def summary_text(report: dict) -> str:
    """The printed report."""
    lo, hi = report["min"], report["max"]
    size = (hi - lo) * 1e3
    lines = [f"{report['file']}: {report['solids']} solid(s)" +
             (f" ({'; '.join(report['notes'])})" if report["notes"] else ""),
             f"bounding box {_v(lo)} .. {_v(hi)} m ({size[0]:.4g} x {size[1]:.4g} x {size[2]:.4g} mm, "
             f"units = \"{report['units']}\")",
             f"volume {report['volume_m3']:.6g} m^3, mass {report['mass_kg']:.5g} kg ({report['material']}, "
             f"{report['density']:g} kg/m^3), centre of mass {_v(report['centroid'])} m",
             f"thinnest wall {report['thin_wall_m'] * 1e3:.3g} mm (2 % area quantile of inward ray lengths; "
             f"shortest ray {report['thinnest_ray_m'] * 1e3:.3g} mm)",
             f"candidate bores (concave cylindrical faces by axis): {report['bore_count']}"
             + (f", the {len(report['bores'])} largest shown" if report["bore_count"] > len(report["bores"]) else "")]
    for n, b in enumerate(report["bores"], start=1):
        lines.append(f"  B{n}: centre {_v(b['centre'])} m, axis {_v(b['axis'])}, radius {b['radius'] * 1e3:.4g} mm, "
                     f"length {b['length'] * 1e3:.4g} mm, {len(b['tags'])} face(s)")
    lines.append(f"largest flat faces (candidate feet / bolt faces), grouped by plane: {len(report['flats'])} shown")
    for n, f in enumerate(report["flats"], start=1):
        lines.append(f"  F{n}: outward normal {_v(f['normal'])}, point {_v(f['point'])} m, "
                     f"area {f['area'] * 1e4:.4g} cm^2, extent {_v(f['min'])} .. {_v(f['max'])} m")
    if "picture" in report:
        lines.append(f"picture: {report['picture']}")
    lines.append(f"scene skeleton: {report['skeleton']}")
    lines.append(f"read and analysed in {report['read_s']:.1f} s, total {report['total_s']:.1f} s")
    return "\n".join(lines)


def candidates_picture(facts, bores: list[dict], flats: list[dict], path: Path, label: str) -> None:
    """The coarse boundary triangulation off-screen (pyvista): bores red, candidate flat faces blue, the rest
    grey; labels B<n> and F<n> at the candidates."""
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import pyvista

    tris, owner = facts.triangles, facts.owner
    n = len(tris)
    cells = np.hstack([np.full((n, 1), 3), np.arange(3 * n).reshape(n, 3)]).ravel()
    surface = pyvista.PolyData(tris.reshape(-1, 3), cells)
    role = np.zeros(n)
    for flat in flats:
        role[np.isin(owner, flat["tags"])] = 1
    for bore in bores:
        role[np.isin(owner, bore["tags"])] = 2
    surface.cell_data["role"] = role
    pyvista.OFF_SCREEN = True
    # 1000 x 430 px: the software renderer (Mesa llvmpipe) takes ~0.3 s less than for 1400 x 600, labels legible
    plotter = pyvista.Plotter(shape=(1, 2), off_screen=True, window_size=(1000, 430))
    centre = 0.5 * (facts.lo + facts.hi)
    points = [b["centre"] for b in bores] + [f["point"] for f in flats]
    names = [f"B{i}" for i in range(1, len(bores) + 1)] + [f"F{i}" for i in range(1, len(flats) + 1)]
    for col, view in enumerate(((-1.0, -1.6, 1.0), (1.2, 1.4, -1.0))):
        plotter.subplot(0, col)
        plotter.add_mesh(surface, scalars="role", cmap=["lightgrey", "steelblue", "firebrick"], clim=(0, 2),
                         show_edges=False, show_scalar_bar=False)
        if points:
            plotter.add_point_labels(np.asarray(points), names, font_size=14, point_size=8,
                                     always_visible=True, shape_opacity=0.6)
        plotter.camera.focal_point = tuple(centre)
        plotter.camera.position = tuple(centre + np.array(view))
        plotter.camera.up = (0.0, 0.0, 1.0)
        plotter.reset_camera()
        plotter.add_text(label if col == 0 else "from the back (red: bores B, blue: flat faces F)", font_size=10)
    plotter.screenshot(str(path))
    plotter.close()


def _cmd_inspect(args: argparse.Namespace) -> int:
    report = inspect_cad(Path(args.file), units=args.units, material=args.material,
                         out_dir=Path(args.out) if args.out else None, picture=not args.no_picture)
    print(summary_text(report))
    return 0


def register_cli(subparsers) -> None:
    """`housingfe inspect FILE [--units mm] [--material steel] [--out DIR]`."""
    p = subparsers.add_parser("inspect", help="describe a CAD file (STEP/IGES/BREP) and write a scene skeleton")
    p.add_argument("file", help="STEP, IGES or BREP file")
    p.add_argument("--units", choices=("mm", "m"), default="mm",
                   help="unit of the coordinates gmsh reads (STEP/IGES: mm, OpenCASCADE converts; default mm)")
    p.add_argument("--material", default="steel", help="library material for the mass (default steel)")
    p.add_argument("--out", default=None, help="folder for <stem>-inspect.png and <stem>-scene.toml "
                                                "(default: the file's folder)")
    p.add_argument("--no-picture", action="store_true", help="skip the PNG")
    p.set_defaults(func=_cmd_inspect, mpi="serial")
