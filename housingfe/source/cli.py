"""`housingfe source <scene> [--out DIR]`: run a gear source model scene.

The scene is a built-in name (housingfe/scenes/<name>.toml) or a path to a TOML file with
[scene] kind = "source" and a [source] table whose `model` picks the implementation:
  "roosmalen" -> housingfe.source.roosmalen.run.run_scene   (van Roosmalen 1994, Ch. 2)
  "fukuma"    -> housingfe.source.fukuma.run.run_scene     (Fukuma et al. 1973)
  "trueman"   -> housingfe.source.trueman.run.run_scene    (Trueman 1974)
each called as run_scene(scene: dict, scene_path: str, out_dir: pathlib.Path) with out_dir an already
created temporary folder that replaces the result folder (default results/<scene name>) on success.
"""
from __future__ import annotations

import argparse
import importlib
from pathlib import Path

from housingfe.errors import InputError
from housingfe.scenefile import read_scene_dict, scene_name_problem

MODELS = {
    "roosmalen": "housingfe.source.roosmalen.run",
    "fukuma": "housingfe.source.fukuma.run",
    "trueman": "housingfe.source.trueman.run",
}


def load_scene(name_or_path: str) -> tuple[dict, Path]:
    """Parse and check the common part of a source scene: [scene] kind = "source", [source] model."""
    scene, path = read_scene_dict(name_or_path)   # the same name lookup and TOML errors as `housingfe run`
    info = scene.get("scene")
    if not isinstance(info, dict):
        raise InputError(f"{path}: scene: missing [scene] table")
    if info.get("kind") != "source":
        raise InputError(f"{path}: scene.kind: {info.get('kind')!r} is not 'source' (run it with `housingfe run`)")
    source = scene.get("source")
    if not isinstance(source, dict):
        raise InputError(f"{path}: source: missing [source] table (scene.kind = \"source\" is a gear source scene for "
                         "`housingfe source`; a housing scene has kind = \"housing\")")
    model = source.get("model")
    if model not in MODELS:
        raise InputError(f"{path}: source.model: {model!r} is not one of {', '.join(MODELS)}")
    return scene, path


def run(name_or_path: str, out: str | None = None) -> Path:
    """Run a source scene and return the result folder."""
    from housingfe.outputs import atomic_output_dir, reserve_output

    scene, path = load_scene(name_or_path)
    model = scene["source"]["model"]
    try:
        module = importlib.import_module(MODELS[model])
    except ModuleNotFoundError as exc:
        if exc.name == MODELS[model]:
            raise InputError(f"{path}: source.model: {model!r} is not available in this installation") from None
        raise
    name = scene["scene"].get("name", path.stem)
    problem = scene_name_problem(name)
    if problem is not None:
        raise InputError(f"{path}: scene.name: {problem}")
    out_dir = Path(out) if out else Path("results") / name
    reserve_output(out_dir, inputs=[path])
    with atomic_output_dir(out_dir) as tmp:
        module.run_scene(scene, str(path), tmp)
    print(f"results in {out_dir}")
    return out_dir


def _cmd_source(args: argparse.Namespace) -> int:
    run(args.scene, args.out)
    return 0


def register_cli(subparsers) -> None:
    """Add `housingfe source <scene> [--out DIR]`."""
    p = subparsers.add_parser("source", help="gear excitation source: stiffness, L_omega, bearing spectra")
    p.add_argument("scene", help="built-in source scene (e.g. gearset-A) or path to a TOML file")
    p.add_argument("--out", default=None, help="result folder (default results/<scene name>)")
    p.set_defaults(func=_cmd_source, mpi="serial")
