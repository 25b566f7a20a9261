"""Command line: `housingfe run|scenes|validate|bench|...`.

Heavy modules (dolfinx, PETSc, gmsh) are imported inside the command handlers, so `housingfe --help`,
`housingfe scenes` and the analytic commands start fast.  Modules of other concerns add their own
sub-commands through a `register_cli(subparsers)` function listed in `_EXTENSIONS`.
"""
from __future__ import annotations

import argparse
import importlib
import re
import sys

from housingfe.errors import InputError, PoolError, SolverError

# Modules that contribute sub-commands (each defines register_cli(subparsers)).
_EXTENSIONS = (
    "housingfe.bearings.cli",
    "housingfe.correlation.cli",
    "housingfe.drivetrain.misalignment",
    "housingfe.geometry.inspect",
    "housingfe.radiation",
    "housingfe.reference",
    "housingfe.source.cli",
    "housingfe.source.roosmalen.studies",
    "housingfe.studies.bearing_variants",
    "housingfe.studies.reduce",
    "housingfe.studies.design_variants",
    "housingfe.studies.runup_causes",
    "housingfe.studies.uncertainty",
)


def _cmd_scenes(args: argparse.Namespace) -> int:
    from housingfe import scenefile

    scenes = scenefile.builtin_scenes()
    width = max(map(len, scenes), default=0)      # the longest name (33 characters) ran into its description
    for name, description in scenes.items():
        print(f"{name:{width}s}  {description}")
    return 0


def _cmd_run(args: argparse.Namespace) -> int:
    from housingfe import run

    run.run_scene(args.scene, out_dir=args.out, overrides=args.set or [])
    return 0


def _cmd_validate(args: argparse.Namespace) -> int:
    from housingfe.verification import validate

    validate.main(out_dir=args.out, json_path=args.json, scenes=args.scenes, quick=args.quick,
                  results_dir=args.results, only=args.only,
                  bands=args.bands, workers=args.workers)
    return 0


def _cmd_bench(args: argparse.Namespace) -> int:
    from housingfe.benchmarks import _dispatch as bench

    only = [n.strip() for n in (args.only or "").split(",") if n.strip()]
    cases = [n.strip() for n in (args.cases or "").split(",") if n.strip()]
    # an empty list given is not "all of them": `--only ""` would start the whole suite (hours)
    for flag, given, names in (("--only", args.only, only), ("--cases", args.cases, cases)):
        if given is not None and not names:
            raise InputError(f"bench: {flag}: {given!r} names nothing; give comma-separated names")
    bench.main(args.which, out_dir=args.out, quick=args.quick, only=only or None, notes_only=args.notes,
               resume=args.resume, size_mm=args.size, cases=cases or None, rounds=args.rounds)
    return 0


def _cmd_mesh_picture(args: argparse.Namespace) -> int:
    from mpi4py import MPI

    from housingfe.fe.model import element_size
    from housingfe.geometry import build_mesh
    from housingfe.geometry.pictures import mesh_picture
    from housingfe.outputs import check_files_folder
    from housingfe.scene import load_housing_scene

    out = check_files_folder(args.out)
    scenes = {name: load_housing_scene(name)[0] for name in args.scenes}    # every scene checked before any mesh
    out.mkdir(parents=True, exist_ok=True)
    for name, scene in scenes.items():
        size = element_size(scene.mesh, scene.geometry, scene.analysis.f_max, scene.material.resolve())
        hm = build_mesh(scene.geometry, scene.mesh.element, size, scene.mesh.layers, MPI.COMM_SELF,
                        grading=scene.mesh.grading, layer_size=scene.mesh.layer_size)
        label = f"{scene.scene.name}: {hm.mesh.topology.index_map(3).size_global} {hm.element} cells, " \
                f"h = {size * 1e3:.1f} mm"
        mesh_picture(hm, out / f"{name}-mesh.png", label)
        print(out / f"{name}-mesh.png")
    return 0


def _register_extension(name: str, sub) -> None:
    """Add the sub-commands of one concern; a concern that is absent or broken costs only its own commands
    (its tests report the breakage), never the whole CLI."""
    try:
        module = importlib.import_module(name)
        register = getattr(module, "register_cli", None)
        if register is not None:
            register(sub)
    except ModuleNotFoundError as exc:
        if not (exc.name and name.startswith(exc.name)):
            print(f"housingfe: warning: commands of {name} unavailable: {exc}", file=sys.stderr)
    except Exception as exc:  # noqa: BLE001 - reported, not hidden
        print(f"housingfe: warning: commands of {name} unavailable: {exc}", file=sys.stderr)


class _OneLineParser(argparse.ArgumentParser):
    """argparse prints its usage block before an error; the project's rule is one line naming the problem
    (and the sub-command's --help for the usage), exit 2."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # Python 3.11 takes "-1e4" for an option (only -123 and -1.5 count as negative numbers), so
        # `--load 0 -1e4 0 0 0` was "expected 5 arguments"; as from Python 3.13, -<digit> and -.<digit> are numbers
        self._negative_number_matcher = re.compile(r"-\.?\d")

    # under mpirun every rank parses the command line: ranks other than 0 keep --help and usage errors to
    # themselves (main sets it), so they are printed once
    quiet = False

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see `{self.prog} --help`)\n")

    def _print_message(self, message, file=None):
        if not self.quiet:
            super()._print_message(message, file)


def build_parser() -> argparse.ArgumentParser:
    parser = _OneLineParser(
        prog="housingfe", description="Gearbox noise: gear source, bearings, FE housing, radiation."
    )
    from housingfe import __version__

    # `housingfe --version` said "the following arguments are required: command"
    parser.add_argument("--version", action="version", version=f"housingfe {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("run", help="run the analyses a scene lists (built-in name or TOML path)")
    p.add_argument("scene", help="built-in scene name (see `housingfe scenes`) or path to a TOML file")
    p.add_argument("--out", default=None, help="result folder (default results/<scene>)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="override a scene value, e.g. --set mesh.size=0.015 (repeatable)")
    p.set_defaults(func=_cmd_run)

    p = sub.add_parser("scenes", help="list the built-in scenes")
    p.set_defaults(func=_cmd_scenes, mpi="serial")

    p = sub.add_parser("validate", help="our results next to the published ones")
    p.add_argument("scenes", nargs="*", help="restrict to these scenes")
    p.add_argument("--out", default="results/validate", help="folder for validate.csv / validate.md")
    p.add_argument("--json", default=None, metavar="FILE", help="also write the rows as JSON")
    p.add_argument("--quick", action="store_true",
                   help="the CI subset: small FE scenes and every row that needs no FE (docs/verification.md)")
    p.add_argument("--results", default=None, metavar="DIR",
                   help="folder of the cached FE results (default results/)")
    p.add_argument("--only", default=None, choices=("runup-checks",),
                   help="runup-checks: the check rows of issue 28 alone (checks.md; docs/runup.md)")
    p.add_argument("--bands", default=None, metavar="FILE",
                   help="JSON {check_id: [low, high]}: the model's uncertainty band of each check (checks.md)")
    p.add_argument("--workers", type=int, default=1, metavar="N",
                   help="stale FE computations run N at a time, each its own process (default 1)")
    p.set_defaults(func=_cmd_validate, mpi="refuse")

    p = sub.add_parser("bench", help="speed-against-error benchmarks (tables, CSV, PNG)")
    from housingfe.benchmarks._dispatch import available

    p.add_argument("which", help=f"which benchmark: {', '.join(available())}")
    p.add_argument("--out", default=None, help="result folder (default results/bench-<which>)")
    p.add_argument("--quick", action="store_true", help="small subset, for a smoke run")
    p.add_argument("--only", default=None, metavar="NAMES",
                   help="with `all`: re-run only these benchmarks (comma-separated) and replace their sections "
                        "of docs/benchmarks.md")
    p.add_argument("--resume", action="store_true",
                   help="re-use the runs an interrupted bench left in <out>.partial/ (docs/progress.md)")
    p.add_argument("--notes", action="store_true",
                   help="with `all`: run nothing; put the edited docs/benchmarks-notes.md into docs/benchmarks.md")
    p.add_argument("--size", type=float, default=None, metavar="MM",
                   help="element size in mm (benchmarks that take one: imported)")
    p.add_argument("--cases", default=None, metavar="NAMES",
                   help="run only these cases, comma-separated (benchmarks that take them: imported)")
    p.add_argument("--rounds", type=int, default=None, metavar="N",
                   help="interleaved rounds instead of the default (benchmarks that take them: imported)")
    p.set_defaults(func=_cmd_bench, mpi="refuse")

    p = sub.add_parser("mesh-picture", help="PNG of a scene's mesh coloured by feature (for the docs)")
    p.add_argument("scenes", nargs="+", help="built-in scene names or TOML paths")
    p.add_argument("--out", default="docs/img", help="folder for <scene>-mesh.png")
    p.set_defaults(func=_cmd_mesh_picture, mpi="serial")

    for name in _EXTENSIONS:
        _register_extension(name, sub)
    _describe_subcommands(parser)
    return parser


def _describe_subcommands(parser: argparse.ArgumentParser) -> None:
    """`housingfe CMD --help` says what CMD does: a sub-command registered with a help line but no description
    (argparse shows the help only in the parent's list) gets that line as its description, at every level."""
    for action in parser._actions:
        if not isinstance(action, argparse._SubParsersAction):
            continue
        helps = {choice.dest: choice.help for choice in action._choices_actions}
        for name, child in action.choices.items():
            if child.description is None and helps.get(name):
                line = helps[name]
                child.description = line[0].upper() + line[1:] + ("" if line.endswith(".") else ".")
            _describe_subcommands(child)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the `housingfe` console script; returns the process exit code.

    Under mpirun / srun with several ranks (docs/cluster.md): a command runs on every rank (the default: the FE
    commands are collective), or, if its parser sets `mpi="serial"`, on rank 0 alone while the others wait, or,
    with `mpi="refuse"` (drivers that start processes of their own), not at all: one line and exit 2.  An error
    stops every rank together (housingfe.ranks.stop_together): its line printed once, never one rank left
    waiting in a collective."""
    import logging
    import os

    from housingfe import ranks

    logging.disable(logging.INFO)  # FFCx/distutils report each JIT compile at INFO
    # PETSc traps SIGPIPE (and other signals) when it initialises: `housingfe describe mesh.toml | head` then ended
    # in "PETSC ERROR: Caught signal number 13 Broken Pipe" and MPI_ABORT (exit 59) instead of stopping quietly
    # (the BrokenPipeError below); set before any PETSc import, inherited by the worker processes
    petsc_options = os.environ.get("PETSC_OPTIONS", "")
    if "-no_signal_handler" not in petsc_options.split():
        os.environ["PETSC_OPTIONS"] = f"{petsc_options} -no_signal_handler".strip()
    comm = ranks.world()
    _OneLineParser.quiet = comm is not None and comm.rank != 0
    parser = build_parser()
    args = parser.parse_args(argv)
    mode = getattr(args, "mpi", "collective")
    try:
        out = getattr(args, "out", None)
        if out is not None and not str(out).strip():
            # `--out "$UNSET"` fell back to the default folder (replacing the result there)
            raise InputError(f"--out: {out!r} is an empty path; give a folder, or leave --out out for the default")
        from housingfe.progress import check_environment

        check_environment()        # a typo in HOUSINGFE_PROGRESS(_SECONDS) was ignored without a word
        if comm is not None and mode == "refuse":
            raise InputError(f"{args.command}: runs its cases in processes of its own (its MPI cases start their "
                             "own mpirun): start it without mpirun / srun")
        if comm is not None and mode == "serial":
            return ranks.on_rank_zero(lambda: _serial(args, comm), comm)
        return int(args.func(args) or 0)
    except PoolError as exc:
        # the pool's thread is blocked (in MPI_Comm_spawn, or on a dead worker's answer): a normal exit would join it
        # (and MPI_Finalize) for ever
        from housingfe import outputs

        outputs.release_all()
        print(f"housingfe: error: {exc}", file=sys.stderr, flush=True)
        sys.stdout.flush()
        os._exit(2)
    except InputError as exc:
        return ranks.stop_together(f"housingfe: error: {exc}", 2, comm)
    except SolverError as exc:
        return ranks.stop_together(f"housingfe: solver error: {exc}", 3, comm)
    except KeyboardInterrupt:
        print("housingfe: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader closed the pipe (`housingfe ... | head`): stop quietly, as other command-line tools do
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except Exception:
        if comm is None:
            raise
        import traceback

        traceback.print_exc()
        return ranks.stop_together(None, 1, comm)
    finally:
        from housingfe import outputs

        outputs.release_all()     # output places reserved by a command that stopped before writing


def _serial(args: argparse.Namespace, comm) -> int:
    """A serial command on rank 0 of several: say so once, then run it."""
    print(f"housingfe: note: `{args.command}` is serial: rank 0 runs it, the other {comm.size - 1} rank(s) wait "
          "(it needs no mpirun)", file=sys.stderr, flush=True)
    return int(args.func(args) or 0)


if __name__ == "__main__":
    raise SystemExit(main())
