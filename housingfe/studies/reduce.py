"""`housingfe reduce SCENE --cutoff HZ --out DIR`: the Craig–Bampton reduced housing of a scene
(housingfe.drivetrain.reduction) written for system tools: reduced.npz, reduced.bdf (Nastran DMIG KAAX/MAAX),
summary.json; with --check also check.csv (the full model's modes with the masters tied against the reduced
model's, and the time of each).

Masters (one per bore, rbe2): --master SURFACE (repeatable) or, by default, the scene's [coupling] bores, the
bores of a "mesh" geometry ([[geometry.bores]]), the bore selectors of a "cad" geometry (bore_<name>), or each
bearing seat of a "gearbox" geometry (bore_<name>_front / _back).  A master sits on the axis of the cylinder fitted to
its surface, mid-length, or at the centroid of a flat surface (housingfe.drivetrain.bore_axis)."""
from __future__ import annotations

import argparse
import json
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from housingfe.errors import InputError


def register_cli(subparsers) -> None:
    """Add `housingfe reduce SCENE --cutoff HZ [--master SURFACE]... [--out DIR] [--check] [--set KEY=VALUE]`."""
    p = subparsers.add_parser("reduce", help="Craig-Bampton reduced housing at its bore masters (npz + Nastran "
                                             "DMIG) for system tools")
    p.add_argument("scene", help="housing scene (built-in name or TOML path)")
    p.add_argument("--cutoff", type=float, required=True, help="fixed-interface modes below this frequency (Hz)")
    p.add_argument("--master", action="append", metavar="SURFACE",
                   help="a housing surface tied to a 6-DOF master (repeatable; default: the scene's bores)")
    p.add_argument("--out", default=None, help="result folder (default results/reduce-<scene>)")
    p.add_argument("--check", action="store_true",
                   help="also solve the full model (masters tied, free) to the cut-off and compare (check.csv)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scene value (repeatable)")
    p.set_defaults(func=_cmd)


def _cmd(args: argparse.Namespace) -> int:
    run_reduce(args.scene, args.cutoff, masters=args.master, out_dir=args.out, overrides=args.set or [],
               check=args.check)
    return 0


def scene_masters(scene, model, surfaces: list[str] | None) -> list:
    """The masters (housingfe.drivetrain.reduction.Master) of a scene: the given surfaces, else the scene's bores
    (see the module docstring); InputError naming the key when a surface is unknown or none are found."""
    from housingfe.drivetrain.interior import bore_centres
    from housingfe.drivetrain.reduction import Master

    known = model.housing.facet_groups
    if surfaces:
        out = []
        for s in surfaces:
            if s not in known:
                raise InputError(f"--master: no surface {s!r} (known: {', '.join(sorted(known))})")
            out.append(Master(s, s, _bore_centre(model, s, "--master")))
        return out
    if scene.coupling is not None and scene.coupling.bores:
        centres = bore_centres(model, scene.coupling)
        return [Master(b.name, b.surface, centres[b.name]) for b in scene.coupling.bores]
    geometry = scene.geometry
    names = []
    if geometry.kind == "mesh":
        names = [b.name for b in geometry.bores]
    elif geometry.kind == "cad":        # a bore selector's faces are the surface bore_<name>
        names = [f"bore_{b.name}" for b in geometry.bores]
    elif geometry.kind == "gearbox":
        names = [f"bore_{b.name}_{side}" for b in geometry.bores for side in ("front", "back")]
    if not names:
        raise InputError("--master: the scene has no bores ([coupling] bores, [[geometry.bores]]); give the "
                         "master surfaces with --master SURFACE")
    return [Master(n, n, _bore_centre(model, n, "geometry.bores")) for n in names]


def _bore_centre(model, surface: str, key: str) -> np.ndarray:
    """A master's position (m): on the axis of the surface's fitted cylinder, mid-length, or the centroid of a
    flat surface (housingfe.drivetrain.bore_axis, as the coupling's bore masters); InputError naming `key`."""
    from housingfe.drivetrain.bore_axis import fit_bore

    try:
        return fit_bore(model, surface).centre
    except InputError as exc:
        raise InputError(f"{key}: {exc}") from None


def check_cutoff_resolved(scene, cutoff_hz: float) -> None:
    """InputError before meshing when the scene's mesh (sized for its analysis.f_max) is far too coarse for
    modes up to the cut-off (housingfe.fe.resolution; mesh.allow_coarse lets it run).  A cut-off far above what
    the mesh resolves asked the eigensolver for (nearly) every mode of the model: it failed after meshing."""
    from housingfe.fe.model import element_size
    from housingfe.fe.resolution import check_resolution, walls_of

    if cutoff_hz <= scene.analysis.f_max or walls_of(scene.geometry) is None:
        return      # below f_max the model's own check holds; an imported mesh's resolution is not assessed
    material = scene.material.resolve()
    size = element_size(scene.mesh, scene.geometry, scene.analysis.f_max, material)
    try:
        check_resolution(scene.geometry, scene.mesh, size, cutoff_hz, material)
    except InputError as exc:
        raise InputError(f"--cutoff: {cutoff_hz:g} Hz is above what the scene's mesh resolves "
                         f"(analysis.f_max {scene.analysis.f_max:g} Hz): {exc}") from None


def run_reduce(scene_name: str, cutoff_hz: float, *, masters=None, out_dir=None, overrides=(), check=False) -> Path:
    """Build the scene's housing model, reduce it (craig_bampton) and write the result folder atomically;
    returns its path."""
    from mpi4py import MPI

    import housingfe
    from housingfe.drivetrain import coupling as cp
    from housingfe.drivetrain.reduction import craig_bampton, write_dmig, write_npz
    from housingfe.outputs import atomic_output_dir, reserve_output, write_csv
    from housingfe.scene import build_model_from_scene, load_housing_scene
    from housingfe.solvers.modal import solve_modes

    if not (cutoff_hz > 0 and np.isfinite(cutoff_hz)):     # inf built the model, then never finished
        raise InputError(f"--cutoff: {cutoff_hz} Hz must be a finite positive frequency")
    comm = MPI.COMM_WORLD
    say = print if comm.rank == 0 else (lambda *a, **k: None)
    scene, path = load_housing_scene(scene_name, list(overrides))
    check_cutoff_resolved(scene, cutoff_hz)
    out_dir = Path(out_dir or f"results/reduce-{Path(scene_name).stem}")
    reserve_output(out_dir, comm, inputs=[path])     # a bad or busy output place stops here, before the model
    t0 = time.perf_counter()
    model = build_model_from_scene(scene, comm)
    t_model = time.perf_counter() - t0
    chosen = scene_masters(scene, model, masters)
    reduced = craig_bampton(model, chosen, cutoff_hz)
    reduced.provenance.update({
        "scene": str(Path(path).resolve()), "scene_name": scene.scene.name, "housingfe": housingfe.__version__,
        "mesh": getattr(scene.geometry, "file", f"built-in {scene.geometry.kind} geometry, mesh "
                                                f"{scene.mesh.element} degree {scene.mesh.degree}"),
        "cutoff_hz": f"{cutoff_hz:g}", "created_utc": datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "masters": ", ".join(f"{m.name} ({m.surface})" for m in reduced.masters)})
    say(f"{model.dofs:,} DOFs -> {reduced.n_modes} fixed-interface modes below {cutoff_hz:g} Hz + "
        f"{6 * len(reduced.masters)} master DOFs ({len(reduced.masters)} masters); reduction "
        f"{reduced.timings['reduction_s']:.2f} s")

    rows = []
    if check:
        t1 = time.perf_counter()
        system = cp.couple(model, [cp.BoreConnection(m.name, m.surface, tuple(m.position)) for m in reduced.masters])
        full = solve_modes(system.K, system.M, cutoff_hz).frequencies_hz
        t_full = time.perf_counter() - t1
        red = reduced.frequencies_with()
        for k, f in enumerate(full):
            fr = red[k] if k < len(red) else float("nan")
            err = (fr / f - 1) * 100 if f > 1e-3 * cutoff_hz else float("nan")
            rows.append([k + 1, f"{f:.4f}", f"{fr:.4f}", f"{err:.4f}" if np.isfinite(err) else ""])
        elastic = [(f, float(r[3])) for f, r in zip(full, rows) if r[3]]
        worst = max((abs(e) for f, e in elastic if f < cutoff_hz / 2), default=0.0)
        reduced.timings["full_modal_s"] = t_full
        say(f"check: full model (masters tied, free) {len(full)} modes below {cutoff_hz:g} Hz in {t_full:.2f} s; "
            f"reduced vs full below {cutoff_hz / 2:g} Hz: max {worst:.3f} %")
    with atomic_output_dir(out_dir, comm) as out:
        if comm.rank == 0:
            write_npz(reduced, out / "reduced.npz")
            write_dmig(reduced, out / "reduced.bdf")
            summary = {"fe_dofs": model.dofs, "reduced_dofs": int(len(reduced.K)), "cutoff_hz": cutoff_hz,
                       "fixed_interface_hz": reduced.frequencies_hz.tolist(),
                       "masters": [{"name": m.name, "surface": m.surface, "xyz_m": list(map(float, m.position)),
                                    "grid": 9_000_001 + i} for i, m in enumerate(reduced.masters)],
                       "timings_s": {"model_s": t_model, **reduced.timings}, "provenance": reduced.provenance}
            (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
            if rows:
                write_csv(out / "check.csv", ["mode", "full_hz", "reduced_hz", "error_percent"], rows)
    say(f"written {out_dir}")
    return out_dir
