"""What a scene can say, from the schema itself: `housingfe scene-reference` writes docs/scene-reference.md (every key
of every kind of scene with its type, unit, default and range; every geometry kind with its surfaces, origin, axes
and a picture), and `housingfe describe SCENE` prints what one scene builds (geometry, surfaces, points, bores,
loads, supports, the mesh and its estimated DOFs) without solving.

Both are generated from the pydantic models (housingfe.scene, housingfe.runup.scene, the source scenes) and the
geometry kinds' block models (housingfe.geometry.registry.GEOMETRY_KINDS), so they cannot drift from the code:
tests/test_reference.py regenerates the page and compares it with the committed one.  Field descriptions are the
schema's `description` or the comment beside the field in its class; units come from the field's
`json_schema_extra={"unit": ...}` or, failing that, from its name (UNIT_BY_SUFFIX, UNIT_BY_NAME); a numeric key
with neither is an error of the generator (so a new key cannot arrive without a unit).
"""
from __future__ import annotations

import argparse
import inspect
import re
import typing
from pathlib import Path

from pydantic import BaseModel

from housingfe.errors import InputError

# units from the name of a key: suffixes first (torque_Nm, speed_min_rpm, ...), then whole names
UNIT_BY_SUFFIX = {"_hz": "Hz", "_rpm": "rev/min", "_nm": "N m", "_mm": "mm", "_kgm2": "kg m^2", "_db": "dB",
                  "_deg": "deg", "_rad": "rad", "_s": "s", "_m": "m", "_n": "N", "_pa": "Pa", "_kg": "kg",
                  "_thickness": "m", "_width": "m", "_size": "m", "_diameter": "m", "_offset": "m",
                  "_ratio": "-", "_ratios": "-", "_factor": "-", "_stiffness": "N/m", "_um": "µm", "_kw": "kW",
                  "_kg_m3": "kg/m^3", "_kg_m2": "kg m^2", "_n_per_m": "N/m", "_coefficient": "-",
                  "_modification": "-", "_scale": "-"}
UNIT_BY_NAME = {
    # lengths and coordinates (m)
    **dict.fromkeys(["length", "width", "height", "thickness", "radius", "diameter", "size", "point", "origin",
                     "centre", "x", "y", "z", "a", "b", "h", "below", "above", "margin", "x_start", "spacing",
                     "split_height", "segments", "position", "offset"], "m"),
    # frequencies (Hz)
    **dict.fromkeys(["f_max", "f_min", "df", "frequencies"], "Hz"),
    # dimensionless numbers and counts
    **dict.fromkeys(["poisson_ratio", "loss_factor", "grading", "elements_per_wavelength", "tolerance",
                     "degree", "layers", "count", "mode_pictures", "sample_points", "harmonics", "teeth", "rows",
                     "elements", "elements_per_segment", "node", "bolts_per_foot", "speed_steps", "slices",
                     "stiffness_positions", "torque_configuration", "direction", "axis", "values", "fixity", "zeta",
                     "z_min", "z_max", "points", "seed", "machines", "boxes", "elements_per_section", "speeds"],
                    "-"),
    "density": "kg/m^3", "youngs_modulus": "Pa", "normal_stiffness": "N/m^3", "tangential_stiffness": "N/m^3",
    "total_normal_stiffness": "N/m", "total_tangential_stiffness": "N/m",
}
_CONSTRAINTS = {"gt": ">", "ge": ">=", "lt": "<", "le": "<="}


# ------------------------------------------------------------------------------------------------ the schema
def _field_comments(cls) -> dict[str, str]:
    """Comment lines above a field (and a comment after it) in the class source: name -> text."""
    out: dict[str, str] = {}
    for klass in reversed(cls.__mro__):
        if not (isinstance(klass, type) and issubclass(klass, BaseModel)) or klass is BaseModel:
            continue
        try:
            lines = inspect.getsource(klass).splitlines()
        except (OSError, TypeError):
            continue
        pending: list[str] = []
        for line in lines[1:]:
            stripped = line.strip()
            if line.startswith("    #") and not line.startswith("     "):
                pending.append(stripped.lstrip("#").strip())
                continue
            match = re.match(r"^    (\w+)\s*:", line)
            if match:
                after = line.split("  # ", 1)[1].strip() if "  # " in line else ""
                text = " ".join(pending + ([after] if after else []))
                if text:
                    out[match.group(1)] = text
            pending = []
    return out


def _strip_optional(ann):
    args = typing.get_args(ann)
    if typing.get_origin(ann) in (typing.Union, getattr(__import__("types"), "UnionType", None)) and \
            type(None) in args:
        rest = [a for a in args if a is not type(None)]
        return (rest[0] if len(rest) == 1 else typing.Union[tuple(rest)]), True
    return ann, False


def _constraints(metadata) -> list[str]:
    out = []
    for m in metadata:
        for attr, symbol in _CONSTRAINTS.items():
            value = getattr(m, attr, None)
            if value is not None:
                out.append(f"{symbol} {value:g}")
    return out


def _models_in(ann) -> list[type]:
    """The pydantic models an annotation holds (directly, in a list, a dict or a union)."""
    ann, _ = _strip_optional(ann)
    if isinstance(ann, type) and issubclass(ann, BaseModel):
        return [ann]
    out = []
    for arg in typing.get_args(ann):
        out += _models_in(arg)
    return out


def _type_text(ann) -> str:
    """A short type name: "float > 0", "list of 3 float", "one of "hex", "tet"", "table", ..."""
    ann, optional = _strip_optional(ann)
    origin, args = typing.get_origin(ann), typing.get_args(ann)
    if origin is typing.Annotated:
        base = _type_text(args[0])
        meta = []
        for m in args[1:]:
            meta += _constraints(getattr(m, "metadata", [m]))
        return f"{base} {', '.join(meta)}".strip()
    if origin is typing.Literal:
        return "one of " + ", ".join(f'"{a}"' if isinstance(a, str) else str(a) for a in args)
    if origin in (list, tuple):
        if origin is tuple and args and Ellipsis not in args:
            return f"{len(args)} × {_type_text(args[0])}"
        return f"list of {_type_text(args[0])}" if args else "list"
    if origin is dict:
        return f"table of {_type_text(args[1])}"
    if origin in (typing.Union, getattr(__import__("types"), "UnionType", None)):
        return " or ".join(_type_text(a) for a in args)
    if isinstance(ann, type) and issubclass(ann, BaseModel):
        return "table"
    if ann is bool:
        return "true/false"
    return getattr(ann, "__name__", str(ann))


def _is_numeric(ann) -> bool:
    ann, _ = _strip_optional(ann)
    origin, args = typing.get_origin(ann), typing.get_args(ann)
    if origin is typing.Annotated:
        return _is_numeric(args[0])
    if origin is typing.Literal:
        return all(isinstance(a, (int, float)) and not isinstance(a, bool) for a in args)
    if origin in (list, tuple, dict):
        return bool(args) and _is_numeric(args[-1] if origin is dict else args[0])
    if origin in (typing.Union, getattr(__import__("types"), "UnionType", None)):
        return any(_is_numeric(a) for a in args)
    return ann in (int, float)


def field_unit(cls, name: str, field) -> str:
    """The unit of a key: the field's json_schema_extra "unit", else by its name; "" for non-numeric keys;
    ValueError for a numeric key without one."""
    extra = field.json_schema_extra if isinstance(field.json_schema_extra, dict) else {}
    if "unit" in extra:
        return extra["unit"]
    if not _is_numeric(field.annotation):
        return ""
    low = name.lower()
    if low in UNIT_BY_NAME:
        return UNIT_BY_NAME[low]
    for suffix, unit in UNIT_BY_SUFFIX.items():
        if low.endswith(suffix):
            return unit
    raise ValueError(f"{cls.__module__}.{cls.__name__}.{name}: a number without a unit: add "
                     "json_schema_extra={'unit': ...} to its Field (or name it by the conventions of "
                     "housingfe.reference)")


def _default_text(field) -> str:
    if field.is_required():
        return "**required**"
    if field.default_factory is not None:
        value = field.default_factory()
    else:
        value = field.default
    if value is None:
        return "—"
    if isinstance(value, BaseModel):
        return "(its defaults)"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, (list, tuple)):
        if not value:
            return "[]"
        return "[" + ", ".join(f'"{v}"' if isinstance(v, str) else f"{v:g}" if isinstance(v, float) else str(v)
                               for v in value) + "]"
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


def _range_text(field) -> str:
    parts = _constraints(field.metadata)
    lo = next((m.min_length for m in field.metadata if getattr(m, "min_length", None) is not None), None)
    hi = next((m.max_length for m in field.metadata if getattr(m, "max_length", None) is not None), None)
    if lo is not None or hi is not None:
        what = "characters" if _strip_optional(field.annotation)[0] is str else "entries"
        if lo == hi:
            parts.append(f"exactly {lo} {what}")
        elif lo == 1 and hi is None:
            parts.append("not empty")
        else:
            parts += ([f"at least {lo} {what}"] if lo is not None else []) + \
                     ([f"at most {hi} {what}"] if hi is not None else [])
    for m in field.metadata:
        pattern = getattr(m, "pattern", None)
        if pattern:
            parts.append(f"matches `{pattern}`")
    return ", ".join(parts)


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def _doc(cls) -> str:
    doc = inspect.getdoc(cls) or ""
    if cls.__doc__ is None or doc.startswith(("Usage docs:", "A base class")):
        return ""
    return " ".join(doc.split())


def model_sections(cls, path: str, array: bool = False, seen: set | None = None,
                   heading: str | None = None, with_doc: bool = True) -> list[str]:
    """Markdown sections of a pydantic model at TOML `path` (array: an array of tables [[path]]) and of the
    models inside it, depth first."""
    seen = set() if seen is None else seen
    comments = _field_comments(cls)
    title = heading or (f"[[{path}]]" if array else f"[{path}]" if path else "top level")
    lines = [f"#### `{title}`", ""]
    doc = _doc(cls) if with_doc else ""
    if doc:
        lines += [doc, ""]
    lines += ["| key | type | unit | default | range | what |", "|---|---|---|---|---|---|"]
    nested = []
    for name, field in cls.model_fields.items():
        unit = field_unit(cls, name, field)
        what = field.description or comments.get(name, "")
        models = _models_in(field.annotation)
        sub = f"{path}.{name}" if path else name
        if models:
            ann, _ = _strip_optional(field.annotation)
            is_list = typing.get_origin(ann) in (list, tuple)
            is_dict = typing.get_origin(ann) is dict
            if len(models) > 1 and name == "geometry":
                what = (what + " " if what else "") + "one table per kind, see [Geometry kinds](#geometry-kinds)"
            elif is_dict:
                what = (what + " " if what else "") + f"see `[{sub}.<name>]`"
            else:
                what = (what + " " if what else "") + f"see `{'[[' if is_list else '['}{sub}{']]' if is_list else ']'}`"
            if name != "geometry":
                for model in models:
                    if (model, sub) not in seen:
                        seen.add((model, sub))
                        nested.append((model, f"{sub}.<name>" if is_dict else sub, is_list))
        type_text = "table (one of the geometry kinds)" if name == "geometry" else _type_text(field.annotation)
        lines.append("| " + " | ".join(_cell(x) for x in (f"`{name}`", type_text, unit,
                                                            _default_text(field), _range_text(field), what)) + " |")
    lines.append("")
    for model, sub, is_list in nested:
        lines += model_sections(model, sub, is_list, seen)
    return lines


# ------------------------------------------------------------------------------------------------ geometry kinds
def _example_scenes() -> dict[str, str]:
    """Geometry kind -> the first built-in housing scene of that kind (its dimensions illustrate the kind)."""
    from housingfe.scenefile import SCENE_DIR, load_toml_file

    out: dict[str, str] = {}
    for path in sorted(SCENE_DIR.glob("*.toml")):
        data = load_toml_file(path)
        kind = data.get("geometry", {}).get("kind") if isinstance(data.get("geometry"), dict) else None
        if kind and data.get("scene", {}).get("kind", "housing") == "housing":
            # the shortest name is the plainest scene of its kind (box-free, not box-free-frf)
            if kind not in out or (len(path.stem), path.stem) < (len(out[kind]), out[kind]):
                out[kind] = path.stem
    return out


def _coordinates_note(spec_cls) -> str:
    """The "Coordinates: ..." paragraph of the kind module's docstring (the builder's own statement of its
    origin and axes)."""
    doc = inspect.getdoc(inspect.getmodule(spec_cls)) or ""
    for para in doc.split("\n\n"):
        if "Coordinates" in para or "coordinates" in para.split(".")[0] or "occupies" in para:
            return " ".join(para.split())
    return ""


def _natural(name: str):
    return [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", name)]


def surface_rows(model) -> list[list[str]]:
    """[name, area m^2, faces, features] of every named surface of a block model, in name order."""
    from housingfe.geometry.surfaces import named_surfaces

    rows = []
    for name, s in sorted(named_surfaces(model).items(), key=lambda kv: _natural(kv[0])):
        rows.append([name, f"{s.area:.4g}", ", ".join(sorted(s.normals)), ", ".join(sorted(s.features))])
    return rows


def geometry_sections(img_dir: str = "img") -> list[str]:
    from housingfe.geometry.registry import GEOMETRY_KINDS
    from housingfe.geometry.surfaces import bounding_box
    from housingfe.scene import load_housing_scene

    examples = _example_scenes()
    lines = ["## Geometry kinds", "",
             "`[geometry] kind = \"...\"` picks one of these; every kind has its own keys.  The surface names are "
             "what `supports`, `loads`, `radiation.plates`, `analysis.harmonic.surface` and `coupling.bores` "
             "refer to.  Areas and bounding boxes are those of the example scene named (bores are not cut out of "
             "the plate areas); `housingfe describe <your scene>` prints them for your dimensions.", ""]
    for kind, registered in GEOMETRY_KINDS.items():
        spec = registered.spec
        lines += [f"### `kind = \"{kind}\"`", ""]
        doc = _doc(spec)
        if doc:
            lines += [doc, ""]
        note = _coordinates_note(spec)
        if note:
            lines += [f"**Origin and axes.** {note}", ""]
        lines += model_sections(spec, "geometry", heading=f'[geometry] kind = "{kind}"', with_doc=False)
        if registered.mesh is not None:     # brings its own mesh: its surfaces are the file's sets
            lines += ["**Surfaces.** `outer` is the housing's outer skin; the other surfaces and the bores are named in "
                      "`[[geometry.surfaces]]` and `[[geometry.bores]]`: a mesh file's node sets or physical groups "
                      "(docs/imported-meshes.md), a CAD file's faces by geometric selectors (docs/cad.md; "
                      "`housingfe inspect FILE` lists the candidates).  The origin and axes are the file's.", ""]
            continue
        example = examples.get(kind)
        if example is None:
            lines += ["(no built-in scene of this kind to illustrate it)", ""]
            continue
        scene, _ = load_housing_scene(example)
        model = registered.build(scene.geometry)
        lo, hi = bounding_box(model)
        lines += [f"**Example: the built-in scene `{example}`** — material from x = {lo[0]:g} to {hi[0]:g} m, "
                  f"y = {lo[1]:g} to {hi[1]:g} m, z = {lo[2]:g} to {hi[2]:g} m.", "",
                  f"![surfaces of {example}]({img_dir}/geometry-{kind}.png)", "",
                  "| surface | area (m²) | outward normals | bounds the features |", "|---|---|---|---|"]
        lines += ["| " + " | ".join(_cell(c) for c in (f"`{r[0]}`", *r[1:])) + " |" for r in surface_rows(model)]
        if model.points:
            lines += ["", "Named points (m): " + "; ".join(
                f"`{name}` " + ", ".join("(" + ", ".join(f"{c:g}" for c in p) + ")" for p in pts)
                for name, pts in model.points.items())]
        lines.append("")
    return lines


def geometry_pictures(out_dir: Path) -> list[Path]:
    """docs/img/geometry-<kind>.png: the example scene of every geometry kind, surfaces coloured and named."""
    from housingfe.geometry.pictures import surface_picture
    from housingfe.geometry.registry import GEOMETRY_KINDS
    from housingfe.scene import load_housing_scene

    written = []
    for kind, example in _example_scenes().items():
        scene, _ = load_housing_scene(example)
        model = GEOMETRY_KINDS[kind].build(scene.geometry)
        path = out_dir / f"geometry-{kind}.png"
        surface_picture(model, path, f'kind = "{kind}" (scene {example}): named surfaces, x red, y green, z blue')
        written.append(path)
    return written


# ------------------------------------------------------------------------------------------------ the page
SCENE_ROOTS = (
    ("Housing scenes (`kind = \"housing\"`, `housingfe run`)", "housingfe.scene", "HousingScene", ""),
    ("Run-up scenes (`kind = \"runup\"`, `housingfe run`)", "housingfe.runup.scene", "RunupScene", ""),
    ("Source scenes, model \"roosmalen\" (`kind = \"source\"`, `housingfe source`)", "housingfe.source.roosmalen.run",
     "SourceTable", "source"),
    ("Source scenes, model \"fukuma\"", "housingfe.source.fukuma.run", "FukumaScene", ""),
    ("Source scenes, model \"trueman\"", "housingfe.source.trueman.run", "TruemanScene", ""),
)


def scene_reference(img_dir: str = "img") -> str:
    """The text of docs/scene-reference.md."""
    import importlib

    lines = ["# Scene reference", "",
             "<!-- generated by `housingfe scene-reference --out docs` from the scene schema; do not edit "
             "(tests/test_reference.py fails when it is out of date) -->", "",
             "A scene is a TOML file: `housingfe run my.toml`.  Every table forbids unknown keys, so a typo is an "
             "error naming the file and the key.  **All values are SI** (m, Pa, kg/m³, Hz, N) unless the key's "
             "name says otherwise (`_mm`, `_rpm`, `_deg`, `_Nm`); the *unit* column gives each key's unit, "
             "\"-\" for a plain number or count.  *required* keys have no default.", "",
             "Any value can be overridden on the command line: `--set mesh.size=0.02`, "
             "`--set analysis.modal.f_max=2000`; an entry of an array of tables (`[[loads]]`) by its index from "
             "0: `--set loads.0.amplitude=2`, `--set 'loads.0.point=[0.1, 0, 0.125]'`.  "
             "`housingfe describe my.toml` prints what a scene builds (surfaces, points, loads, mesh size and "
             "estimated DOFs) without solving.", "",
             "A first scene of one's own (a free 400 × 300 × 200 mm steel box with 10 mm walls, modes to 1 kHz):",
             "", "```toml",
             "[scene]", 'name = "my-box"', 'kind = "housing"', "",
             "[geometry]", 'kind = "box"', "length = 0.4", "width = 0.3", "height = 0.2", "wall_thickness = 0.010",
             "flange_thickness = 0.010", "flange_width = 0.03", "",
             "[material]", 'name = "steel"', "", "[analysis.modal]", "f_max = 1000.0", "```", "",
             "## Contents", ""]
    for title, *_ in SCENE_ROOTS:
        lines.append(f"- [{title}](#{_anchor(title)})")
    lines += ["- [Geometry kinds](#geometry-kinds)", "- [Materials](#materials)", ""]
    for title, module, name, prefix in SCENE_ROOTS:
        cls = getattr(importlib.import_module(module), name)
        lines += [f"## {title}", ""]
        doc = _doc(cls)
        if doc:
            lines += [doc, ""]
        if prefix:
            lines += ["`[scene]` as for every scene (name, kind = \"source\", description), then:", ""]
        lines += model_sections(cls, prefix)
    lines += geometry_sections(img_dir)
    lines += _materials_section()
    return "\n".join(lines).rstrip() + "\n"


def _materials_section() -> list[str]:
    from housingfe.materials import LIBRARY

    lines = ["## Materials", "", "`[material] name = ...` (and `[regions.<cell group>]`) takes a library material; "
             "its values can be overridden key by key.", "",
             "| name | Young's modulus (Pa) | Poisson ratio (-) | density (kg/m³) | loss factor (-) |",
             "|---|---|---|---|---|"]
    for name, m in LIBRARY.items():
        lines.append(f"| `{name}` | {m.youngs_modulus:.4g} | {m.poisson_ratio:g} | {m.density:g} | {m.loss_factor:g} |")
    return lines + [""]


def _anchor(title: str) -> str:
    text = re.sub(r"[^\w\- ]", "", title.lower())
    return text.replace(" ", "-")


def write_reference(out_dir: Path, pictures: bool = True) -> list[Path]:
    """Write <out_dir>/scene-reference.md and, with pictures, <out_dir>/img/geometry-<kind>.png; the paths."""
    from housingfe.outputs import check_files_folder

    out_dir = check_files_folder(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    page = out_dir / "scene-reference.md"
    page.write_text(scene_reference("img"))
    written = [page]
    if pictures:
        (out_dir / "img").mkdir(exist_ok=True)
        written += geometry_pictures(out_dir / "img")
    return written


# ------------------------------------------------------------------------------------------------ describe
def describe(name_or_path: str, overrides: list[str] | None = None, mesh_f_max: float | None = None) -> str:
    """What a housing scene builds, without meshing or solving: geometry kind and dimensions, bounding box,
    named surfaces (area, normals, features), points, bores, supports, loads, analyses, and the mesh (element
    size and the rule that set it, estimated DOFs and memory).  mesh_f_max (Hz): the frequency the mesh is made for,
    when another scene (a run-up) meshes this housing for its own range; default the scene's analyses."""
    from housingfe.fe.model import (
        DERIVED_SIZE_DIGITS,
        MEMORY_BASE_BYTES,
        MEMORY_PER_DOF_BYTES,
        derived_element_size,
        element_size,
        size_ladder,
    )
    from housingfe.geometry.mesh import estimate_dofs
    from housingfe.geometry.registry import block_model_for, own_mesh_kind
    from housingfe.geometry.surfaces import bounding_box
    from housingfe.outputs import format_table
    from housingfe.scene import load_housing_scene
    from housingfe.scenefile import read_scene_dict

    data, path = read_scene_dict(name_or_path)
    kind = data.get("scene", {}).get("kind", "housing") if isinstance(data.get("scene"), dict) else "housing"
    if kind == "runup":
        # a run-up scene's housing is a housing scene with overrides: describe that
        from housingfe.runup.scene import load_runup_scene

        runup, path = load_runup_scene(name_or_path, overrides)
        return (f"run-up scene {runup.scene.name} ({path}); its housing is the scene {runup.housing.scene}"
                + (f" with --set {' --set '.join(runup.housing.set)}" if runup.housing.set else "")
                + f", meshed for the run-up's highest line runup.f_max_hz = {runup.runup.f_max_hz:g} Hz:\n"
                + describe(runup.housing.scene, runup.housing.set, mesh_f_max=runup.runup.f_max_hz))
    if kind != "housing":
        raise InputError(f"{path}: scene.kind: describe knows housing and run-up scenes; this is a {kind} scene")
    scene, path = load_housing_scene(name_or_path, overrides)
    g = scene.geometry
    out = [f"scene {scene.scene.name} ({path}): {scene.scene.description}".rstrip(": "),
           f"geometry kind \"{g.kind}\" (lengths in m):"]
    dims = [(k, v) for k, v in g.model_dump().items() if k != "kind"]
    out += [f"  {k} = {_value_text(v)}" for k, v in dims]
    imported = own_mesh_kind(g) is not None
    if imported:
        # a CAD file or a mesh file: no block model; what the file holds and what the scene names in it
        try:
            lines, volume = _imported_geometry_lines(g)
        except InputError as exc:       # name the scene, as `housingfe run` does
            raise InputError(f"{path}: {exc}") from None
        out += lines
    else:
        model = block_model_for(g)
        volume = model.volume()
        lo, hi = bounding_box(model)
        out.append(f"material bounding box: x {lo[0]:g} .. {hi[0]:g}, y {lo[1]:g} .. {hi[1]:g}, z {lo[2]:g} .. "
                   f"{hi[2]:g} m; volume {volume:.4g} m^3, centroid ("
                   + ", ".join(f"{c:.4g}" if abs(c) > 1e-12 else "0" for c in model.centroid()) + ") m")
        note = _coordinates_note(type(g))
        if note:
            out.append(note)
        rows = surface_rows(model)
        out += ["", f"surfaces ({len(rows)}; use these names in supports, loads, radiation plates, coupling bores):",
                format_table(["surface", "area m^2", "outward normals", "bounds features"], rows)]
        if model.points:
            out += ["", "points (m):"]
            out += [f"  {name}: " + "; ".join("(" + ", ".join(f"{c:g}" for c in p) + ")" for p in pts)
                    for name, pts in model.points.items()]
        if model.bores:
            out += ["", "bores (m):"]
            out += [f"  {b.name}: axis {'xyz'[b.axis]} through ({', '.join(f'{c:g}' for c in b.centre)}), "
                    f"diameter {2 * b.radius:g}" + (f", also in {', '.join(b.groups)}" if b.groups else "")
                    for b in model.bores]
    if scene.supports:
        out += ["", "supports:"] + [f"  {s.kind} on {s.surface}" + (
            f" (normal {s.normal_stiffness:g} N/m^3)" if s.normal_stiffness else
            f" (normal {s.total_normal_stiffness:g} N/m in total)" if s.total_normal_stiffness else "")
            for s in scene.supports]
    else:
        out += ["", "supports: none (free: six rigid-body modes at 0 Hz)"]
    if scene.loads:
        units = {"force": "N", "moment": "N m", "pressure": "Pa"}
        out += ["", "loads (rms amplitudes):"]
        for ld in scene.loads:
            where = f"on {ld.surface}" if ld.surface else f"at node {ld.node}"
            at = f" at ({', '.join(f'{c:g}' for c in ld.point)}) m within {ld.radius:g} m" if ld.point else ""
            along = f" along ({', '.join(f'{c:g}' for c in ld.direction)})" if ld.direction else ""
            out.append(f"  {ld.name}: {ld.kind} {ld.amplitude:g} {units[ld.kind]} {where}{at}{along}"
                       + (" with a spectrum" if ld.spectrum else ""))
    a = scene.analysis
    out += ["", "analyses:"]
    if a.modal:
        out.append(f"  modal: every mode below {a.modal.f_max:g} Hz")
    if a.harmonic:
        h = a.harmonic
        out.append(f"  harmonic: {len(h.frequencies)} lines {h.f_min:g} .. {h.f_max:g} Hz (df {h.df:g} Hz), "
                   f"solver {h.solver}, observed surface {h.surface}")
    if scene.radiation:
        out.append(f"  radiation: model {scene.radiation.model}"
                   + (f", plates {', '.join(p.surface for p in scene.radiation.plates)}" if scene.radiation.plates
                      else ""))
    m = scene.mesh
    material = scene.material.resolve()
    f_mesh = a.f_max if mesh_f_max is None else mesh_f_max
    size = element_size(m, g, f_mesh, material)
    unrounded = derived_element_size(m, g, f_mesh, material)
    dofs = estimate_dofs(g, m.element, m.degree, size, m.layers, m.layer_size)
    memory = MEMORY_BASE_BYTES + MEMORY_PER_DOF_BYTES * dofs
    if g.min_thickness is None and m.size is None:      # a mesh file: its own cells
        out += ["", f"mesh: the file's cells, displacement degree {m.degree} (mesh.element, size and layers do not "
                    "apply to a mesh file)",
                f"  ~{dofs:,} DOFs (counted from the file), ~{memory / 1e9:.1f} GB"]
    else:
        rule = "mesh.size" if m.size is not None else (
            f"bending wavelength of the thinnest wall ({g.min_thickness * 1e3:g} mm"
            + (", estimated from the CAD file" if imported and getattr(g, "thickness", None) is None else "")
            + f") at {f_mesh:g} Hz / mesh.elements_per_wavelength = {m.elements_per_wavelength:g} = "
            f"{unrounded * 1e3:.7g} mm, rounded down to {DERIVED_SIZE_DIGITS} significant digits; only if that mesh "
            f"fails the quality rule, finer: {', '.join(format(s * 1e3, 'g') for s in size_ladder(size)[1:])} mm")
        layers = ("" if imported else ", " + (f"layer size {m.layer_size * 1e3:g} mm" if m.layer_size
                                             else f"{m.layers} layer(s)") + " through the walls")
        out += ["", f"mesh: {m.element} degree {m.degree}, element size {size * 1e3:.3g} mm ({rule}){layers}",
                f"  estimated ~{dofs:,} DOFs, ~{memory / 1e9:.1f} GB (housingfe.geometry.mesh.estimate_dofs: within "
                "10 % for hexes, a factor 3 for tets)"]
    out.append(f"material {material.name}: E = {material.youngs_modulus:.4g} Pa, nu = {material.poisson_ratio:g}, "
               f"rho = {material.density:g} kg/m^3; "
               + (f"mass ~{material.density * volume:.4g} kg" if volume is not None
                  else "mass: from the meshed volume (housingfe run reports it)"))
    return "\n".join(out)


def _imported_geometry_lines(g) -> tuple[list[str], float | None]:
    """describe's lines for a geometry that brings its own mesh (kind "cad" or "mesh"): what the file holds and
    the surfaces the scene names in it (checked as a run checks them: an unknown set or a selector that matches
    nothing stops with its key), and the volume (m^3) where it is known without meshing (CAD), else None."""
    import numpy as np

    from housingfe.outputs import format_table

    if g.kind == "cad":
        from housingfe.geometry.cad import cad_facts, face_groups

        facts = cad_facts(g)
        lo, hi = facts.lo, facts.hi
        area: dict[str, float] = {}
        kinds: dict[str, set] = {}
        groups = face_groups(g, facts)
        for face in facts.faces:
            for name in groups[face.tag]:
                area[name] = area.get(name, 0.0) + face.area
                kinds.setdefault(name, set()).add(face.kind)
        rows = [[n, f"{area[n]:.4g}", ", ".join(sorted(kinds[n]))] for n in sorted(area, key=_natural)]
        lines = [f"CAD file: {facts.solids} solid(s); bounding box x {lo[0]:.4g} .. {hi[0]:.4g}, y {lo[1]:.4g} .. "
                 f"{hi[1]:.4g}, z {lo[2]:.4g} .. {hi[2]:.4g} m; volume {facts.volume:.4g} m^3, centroid ("
                 + ", ".join(f"{c:.4g}" if abs(c) > 1e-12 else "0" for c in facts.centroid) + ") m; thinnest wall "
                 f"~{facts.thin_wall * 1e3:.3g} mm (`housingfe inspect` lists bores and flat faces)",
                 "", f"surfaces ({len(rows)}; use these names in supports, loads, radiation plates, coupling bores):",
                 format_table(["surface", "area m^2", "faces"], rows)]
        return lines, facts.volume
    from housingfe.geometry.imported_mesh import _groups, read_mesh_file

    mf = read_mesh_file(g.file, g.units)
    facet_groups, values, _ = _groups(mf, g, "geometry")
    pts = mf.points
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    corners = pts[mf.boundary]                      # (F, 3 or 4, 3): the boundary facets' corners
    tri = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    if corners.shape[1] == 4:                       # a quadrilateral: its two triangles (0, 1, 2) and (0, 2, 3)
        tri = tri + 0.5 * np.linalg.norm(np.cross(corners[:, 2] - corners[:, 0], corners[:, 3] - corners[:, 0]),
                                         axis=1)
    rows = []
    for name, tags in facet_groups.items():
        mask = np.isin(values, tags)
        rows.append([name, f"{tri[mask].sum():.4g}", f"{int(mask.sum())}"])
    sets = ", ".join(sorted(set(mf.node_sets) | set(mf.surface_sets))) or "none"
    lines = [f"mesh file: {len(mf.cells):,} {mf.source_cell} cells, {len(pts):,} nodes; bounding box x {lo[0]:.4g} .. "
             f"{hi[0]:.4g}, y {lo[1]:.4g} .. {hi[1]:.4g}, z {lo[2]:.4g} .. {hi[2]:.4g} m; median edge "
             f"{mf.element_size * 1e3:.3g} mm",
             f"node and surface sets in the file: {sets}",
             f"cell sets (for [regions]): {', '.join(sorted(mf.cell_sets)) or 'none'}",
             "", f"surfaces ({len(rows)}; use these names in supports, loads, radiation plates, coupling bores; "
                 "areas of the straight facets):",
             format_table(["surface", "area m^2", "facets"], rows)]
    return lines, None


def _value_text(v) -> str:
    if isinstance(v, float):
        return f"{v:g}"
    if isinstance(v, list) and v and isinstance(v[0], dict):
        return "; ".join(", ".join(f"{k}={_value_text(x)}" for k, x in d.items()) for d in v)
    if isinstance(v, dict):
        return ", ".join(f"{k}={_value_text(x)}" for k, x in v.items())
    return str(v)


# ------------------------------------------------------------------------------------------------ CLI
def _cmd_describe(args: argparse.Namespace) -> int:
    print(describe(args.scene, args.set or []))
    return 0


def _cmd_reference(args: argparse.Namespace) -> int:
    for path in write_reference(Path(args.out), pictures=not args.no_pictures):
        print(f"wrote {path}")
    return 0


def register_cli(subparsers) -> None:
    """Add `housingfe describe SCENE` and `housingfe scene-reference [--out DIR]`."""
    p = subparsers.add_parser("describe", help="what a housing scene builds (surfaces, points, loads, mesh, DOFs), "
                                               "without solving")
    p.add_argument("scene", help="built-in scene name or path to a TOML file")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scene value (repeatable)")
    p.set_defaults(func=_cmd_describe, mpi="serial")
    p = subparsers.add_parser("scene-reference", help="write docs/scene-reference.md (every scene key; geometry "
                                                      "kinds with surfaces and pictures) from the schema")
    p.add_argument("--out", default="docs", help="folder for scene-reference.md and img/geometry-<kind>.png "
                                                 "(default docs)")
    p.add_argument("--no-pictures", action="store_true", help="the page only")
    p.set_defaults(func=_cmd_reference, mpi="serial")


__all__ = ["describe", "field_unit", "scene_reference", "write_reference"]
