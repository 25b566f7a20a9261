"""`housingfe correlate` (computed vs measured modes: MAC, pairing, frequency errors, MAC picture, FRF
correlation; or export of our modes, point FRFs and geometry as UFF) and `housingfe update` (model updating
from an update spec, housingfe.correlation.updating)."""
from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np

from housingfe.errors import InputError


def register_cli(subparsers) -> None:
    p = subparsers.add_parser("correlate", help="measured (UFF 55 / CSV) vs computed modes: MAC, pairing, PNG; "
                                                "or --export our modes and FRFs as UFF")
    p.add_argument("scene", help="housing scene (built-in name or TOML path)")
    p.add_argument("--measured", default=None, metavar="FILE", help="measured modes: .uff/.unv (15/2411 + 55) or .csv")
    p.add_argument("--export", default=None, metavar="FILE.uff",
                   help="write our modes at --points surface points, their geometry and point FRFs as UFF")
    p.add_argument("--units", choices=("m", "mm", "cm", "in"), default=None,
                   help="unit of the measured coordinates where the file has no units dataset (UFF 164); "
                        "default m")
    p.add_argument("--points", type=int, default=36, help="--export: number of surface points (default 36)")
    p.add_argument("--f-max", type=float, default=None,
                   help="modes below this frequency (Hz; default 1.25 x the highest measured mode, or the scene's)")
    p.add_argument("--threshold", type=float, default=0.6, help="MAC threshold for a pair (default 0.6)")
    p.add_argument("--loss-factor", type=float, default=0.002, help="loss factor of the computed FRFs")
    p.add_argument("--out", default=None, help="result folder (default results/correlate-<scene>)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scene value (repeatable)")
    p.set_defaults(func=_cmd_correlate)

    p = subparsers.add_parser("update", help="fit scene parameters to measured / published modal data "
                                             "(bounded least squares; docs/correlation.md)")
    p.add_argument("spec", help="update spec (TOML): parameters, targets, search and confirmation meshes")
    p.add_argument("--out", default=None, help="result folder (default results/update-<name>)")
    p.add_argument("--no-resume", action="store_true",
                   help="do not re-use the evaluations an interrupted run left in <out>.partial/ (docs/progress.md)")
    p.set_defaults(func=_cmd_update)


def _cmd_update(args: argparse.Namespace) -> int:
    from mpi4py import MPI

    from housingfe.correlation.updating import load_update_spec, run_update
    from housingfe.outputs import reserve_output

    spec = load_update_spec(args.spec)
    out = args.out or f"results/update-{spec.name}"
    reserve_output(out, MPI.COMM_WORLD, inputs=[args.spec])     # before the 30-40 min of fitting
    try:
        run_update(spec, out, resume=not args.no_resume)
    except KeyboardInterrupt:       # errors stay one line; an interruption says what it kept
        import sys

        from housingfe.correlation.updating import checkpoint_path

        path = checkpoint_path(out)
        if path.is_file():
            kept = max(path.read_text(errors="replace").count("\n") - 1, 0)
            print(f"housingfe update: {kept} finished evaluation(s) kept in {path}; the same command resumes "
                  "from them", file=sys.stderr, flush=True)
        raise
    return 0


def _cmd_correlate(args: argparse.Namespace) -> int:
    if (args.measured is None) == (args.export is None):
        raise InputError("correlate: give exactly one of --measured FILE or --export FILE.uff")
    if not 0.0 <= args.threshold <= 1.0:
        raise InputError(f"--threshold: {args.threshold} is not in [0, 1]")
    if args.points < 1:
        raise InputError(f"--points: {args.points} must be at least 1")
    if args.f_max is not None and not (args.f_max > 0 and np.isfinite(args.f_max)):
        raise InputError(f"--f-max: {args.f_max:g} Hz must be a finite positive frequency")
    if not 0.0 <= args.loss_factor < 1.0:
        raise InputError(f"--loss-factor: {args.loss_factor:g} is not in [0, 1)")
    if args.export is not None:
        if args.out is not None:    # it was ignored: the modes were solved and only FILE.uff written
            raise InputError(f"--out: {args.out}: applies to --measured (its result folder); --export writes the one "
                             f"file {args.export}")
        check_export_path(args.export)
    from mpi4py import MPI

    from housingfe.correlation import uff
    from housingfe.outputs import reserve_output
    from housingfe.scene import build_model_from_scene, load_housing_scene
    from housingfe.solvers.modal import modes

    if args.units is not None and args.measured is None:
        raise InputError("--units: applies to --measured files only (exports are written in m with UFF 164)")
    measured = uff.read_measured_modes(args.measured, args.units) if args.measured else None
    scene, scene_path = load_housing_scene(args.scene, args.set or [])
    if measured is not None:     # the folder written at the end: checked and locked before the solve
        reserve_output(args.out or f"results/correlate-{Path(args.scene).stem}", MPI.COMM_WORLD,
                       inputs=[scene_path, args.measured])
    f_max = args.f_max or (1.25 * float(measured.frequencies_hz.max()) if measured is not None
                           else scene.analysis.f_max)
    model = build_model_from_scene(scene, MPI.COMM_WORLD)
    if args.export is not None:       # more points than the outer surface has facets: refused before the solve
        from housingfe.response.observers import sample_points

        sample_points(model.housing, "outer", args.points, key="--points")
    basis = modes(model, f_max)
    name = Path(args.scene).stem
    out_dir = args.out or f"results/correlate-{name}"
    if measured is not None:
        correlate_measured(basis, measured, out_dir, args.threshold, args.loss_factor, args.measured, args.units)
    else:
        export_uff(basis, args.export, args.points, args.loss_factor)
    return 0


def check_export_path(path: str) -> None:
    """InputError, before the solve, unless `path` can be written as a file: not a folder, in an existing
    folder."""
    target = Path(path)
    if target.is_dir():
        raise InputError(f"{path}: --export: is a folder; give a file name, e.g. {target / 'modes.uff'}")
    folder = target.parent
    if not folder.is_dir():
        raise InputError(f"{path}: --export: {folder} is not an existing folder")
    if not os.access(folder, os.W_OK):
        raise InputError(f"{path}: --export: cannot write in {folder}")


def correlate_measured(basis, measured, out_dir, threshold: float, loss_factor: float, source: str,
                       units: str | None = None) -> None:
    """MAC, pairing and frequency-error table of measured vs computed modes; FRAC of the measured FRFs of a
    UFF file against modal receptances at the same channels.  Writes pairs.csv, mac.csv, mac.png,
    computed.uff (our modes on the measured nodes) and frf.csv (if FRFs were measured) atomically."""
    from mpi4py import MPI

    from housingfe.correlation import uff
    from housingfe.correlation.mac import frac, mac, mac_png, pair_modes
    from housingfe.correlation.points import computed_modes_at
    from housingfe.outputs import atomic_output_dir, write_csv

    comm = MPI.COMM_WORLD
    say = print if comm.rank == 0 else (lambda *a, **k: None)
    comp = computed_modes_at(basis, measured)
    m = mac(measured.shapes, comp.shapes)
    pairing = pair_modes(m, measured.frequencies_hz, comp.frequencies_hz, threshold, frequency_weight=0.5)
    if not pairing.pairs:
        raise InputError(f"{source}: no measured mode pairs with a computed one at MAC >= {threshold:g} "
                         f"(best MAC {m.max():.2f}); check units, coordinates and directions of the channels")
    say(pairing.format())
    say(f"channels: {len(measured.node_ids)} (snapping distance max {np.max(np.linalg.norm(comp.points - measured.points, axis=1)) * 1e3:.2f} mm)")
    frf_rows = []
    if Path(source).suffix.lower() != ".csv":
        data = uff.read_uff(source, units)
        if data.frfs and data.nodes is not None:
            frf_rows = _frf_correlation(basis, data, loss_factor, frac)
            for row in frf_rows:
                say(f"FRF {row[0]}:{row[1]} / {row[2]}:{row[3]}  FRAC {row[4]:.3f}")
    with atomic_output_dir(out_dir, comm) as out:
        if comm.rank == 0:
            write_csv(out / "pairs.csv", ["measured", "f_measured_hz", "computed", "f_computed_hz", "error_percent",
                                          "mac"], pairing.table())
            write_csv(out / "mac.csv", ["measured \\ computed"] + [f"{f:.2f}" for f in comp.frequencies_hz],
                      [[f"{f:.2f}", *row] for f, row in zip(measured.frequencies_hz, m)])
            mac_png(m, out / "mac.png", measured.frequencies_hz, comp.frequencies_hz, pairing,
                    title=f"MAC: {Path(source).name} vs computed")
            nodes = _nodes_of(measured, comp)
            uff.write_uff(out / "computed.uff", nodes, comp)
            if frf_rows:
                write_csv(out / "frf.csv", ["response_node", "response_dir", "reference_node", "reference_dir", "frac"],
                          frf_rows)
    say(f"written {out_dir}")


def _nodes_of(measured, comp):
    from housingfe.correlation.uff import Nodes

    ids, first = np.unique(measured.node_ids, return_index=True)
    return Nodes(ids, comp.points[first])


def _frf_correlation(basis, data, loss_factor: float, frac) -> list:
    from housingfe.correlation.points import ChannelSampler, modal_receptance, snap_channels

    structure = basis.structure
    rows = []
    start = basis.rigid_count
    vectors = [structure.to_housing(x) for x in basis.vectors[start:]]
    for frf in data.frfs:
        pts = data.nodes.coordinates([frf.response_node, frf.reference_node])
        ch = snap_channels(structure.housing, pts, np.array([frf.response_direction, frf.reference_direction]))
        shapes = ChannelSampler(structure.V, ch).sample(vectors)
        h = modal_receptance(shapes[:1], shapes[1:], basis.frequencies_hz[start:], frf.frequencies_hz, loss_factor)[0, 0]
        rows.append((frf.response_node, _axis(frf.response_direction), frf.reference_node,
                     _axis(frf.reference_direction), frac(frf.values, h)))
    return rows


def _axis(d) -> str:
    k = int(np.argmax(np.abs(d)))
    return ("+" if d[k] > 0 else "-") + "xyz"[k]


def export_uff(basis, path: str, count: int, loss_factor: float) -> None:
    """Our elastic modes at `count` area-weighted points of the outer surface (x, y, z channels per point),
    the points as UFF 2411 nodes, and the point receptances (m/N) of every channel to a force at point 1
    along its dominant normal axis, 400 lines up to the basis' f_max, as UFF 58."""
    from housingfe.correlation import uff
    from housingfe.correlation.points import Channels, ChannelSampler, modal_receptance
    from housingfe.response.observers import sample_points

    structure = basis.structure
    samples = sample_points(structure.housing, "outer", count, key="--points")
    n = len(samples.points)
    pts = np.repeat(samples.points, 3, axis=0)
    dirs = np.tile(np.eye(3), (n, 1))
    start = basis.rigid_count
    vectors = [structure.to_housing(x) for x in basis.vectors[start:]]
    shapes = ChannelSampler(structure.V, Channels(pts, dirs, np.zeros(len(pts)))).sample(vectors)
    ids = np.arange(1, n + 1)
    modes = uff.ModeSet(basis.frequencies_hz[start:], np.repeat(ids, 3), pts, dirs, shapes,
                        np.full(len(vectors), loss_factor / 2), "computed")
    ref_axis = int(np.argmax(np.abs(samples.normals[0])))
    ref_dir = np.eye(3)[ref_axis] * np.sign(samples.normals[0][ref_axis])
    ref = ChannelSampler(structure.V, Channels(samples.points[:1], ref_dir[None, :], np.zeros(1))).sample(vectors)
    lines = np.linspace(basis.f_max / 400, basis.f_max, 400)
    H = modal_receptance(shapes, ref, modes.frequencies_hz, lines, loss_factor)[:, 0, :]
    frfs = [uff.FRF(int(ids[c // 3]), dirs[c], 1, ref_dir, lines, H[c], f"H {ids[c // 3]}{'xyz'[c % 3]}/1")
            for c in range(len(pts))]
    from mpi4py import MPI

    if MPI.COMM_WORLD.rank == 0:
        uff.write_uff(path, uff.Nodes(ids, samples.points), modes, frfs)
        print(f"written {path}: {n} nodes, {modes.n_modes} modes up to {basis.f_max:g} Hz, {len(frfs)} FRFs (m/N)")
