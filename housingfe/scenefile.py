"""Scene files: a built-in scene by name or a TOML path, read, overridden with --set, validated with pydantic into one
message naming the file and the key.  Shared by every kind of scene (housing, source, ...); the housing scene's own
schema is housingfe.scene."""
from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Annotated, Literal

from pydantic import AfterValidator, BaseModel, ConfigDict, ValidationError

from housingfe.errors import InputError

SCENE_DIR = Path(__file__).parent / "scenes"


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


def scene_name_problem(name) -> str | None:
    """Why `name` cannot be a scene name, or None.  The name is the default result folder results/<name>: it must
    be one plain folder name, so that an empty or path-like name can never make results/ itself, or a place
    outside it, the output (issue 27)."""
    if not isinstance(name, str):
        return f"{name!r} is not a string"
    if not name.strip() or name in (".", "..") or name.startswith(".") or any(c in name for c in "/\\") \
            or any(ord(c) < 32 for c in name):
        return (f"{name!r} cannot name the result folder results/<name>: give a non-empty name without '/', "
                "'\\', control characters or a leading '.'")
    return None


def _plain_folder_name(name: str) -> str:
    problem = scene_name_problem(name)
    if problem is not None:
        raise ValueError(problem)
    return name


# a str field that names a result folder (scene names, update names): scene_name_problem as its validator
FolderName = Annotated[str, AfterValidator(_plain_folder_name)]


class SceneInfo(_Strict):
    name: FolderName  # names the result folder (results/<name> unless --out is given) and the reports
    kind: Literal["housing", "source", "runup"]  # which schema the rest of the file follows
    description: str = ""  # one line, shown by `housingfe scenes`


def builtin_scenes() -> dict[str, str]:
    """Names and one-line descriptions of the built-in scenes."""
    out = {}
    for path in sorted(SCENE_DIR.glob("*.toml")):
        with open(path, "rb") as fh:
            info = tomllib.load(fh).get("scene", {})
        out[path.stem] = info.get("description", "")
    return out


def resolve_scene_path(name_or_path: str) -> Path:
    """Path of a built-in scene name or of a TOML file; InputError if neither exists."""
    path = Path(name_or_path)
    if path.suffix == ".toml" or path.exists():
        if not path.is_file():
            raise InputError(f"{name_or_path}: scene file not found")
        return path
    builtin = SCENE_DIR / f"{name_or_path}.toml"
    if builtin.is_file():
        return builtin
    raise InputError(f"{name_or_path}: no such scene (built-in: {', '.join(builtin_scenes())})")


def load_toml_file(path: Path) -> dict:
    """Parse a TOML file.  A UTF-8 byte-order mark (Windows editors write one) is skipped; a UTF-16/32 file is
    named as such.  InputError "<path>: ..." on unreadable, non-UTF-8 or malformed text."""
    try:
        raw = Path(path).read_bytes()
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc.strerror}") from None
    for bom, encoding in ((b"\xff\xfe\x00\x00", "UTF-32"), (b"\x00\x00\xfe\xff", "UTF-32"),
                          (b"\xff\xfe", "UTF-16"), (b"\xfe\xff", "UTF-16")):
        if raw.startswith(bom):
            raise InputError(f"{path}: starts with a {encoding} byte-order mark: a scene is UTF-8 text "
                             "(save it as UTF-8)")
    try:
        text = raw.decode("utf-8-sig")   # utf-8-sig: a leading UTF-8 byte-order mark is dropped
    except UnicodeDecodeError as exc:
        raise InputError(f"{path}: not a UTF-8 text file (byte {exc.start}); a scene is TOML text") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: malformed TOML: {exc}") from None


def read_scene_dict(name_or_path: str) -> tuple[dict, Path]:
    """Parse a scene TOML into a dict; InputError naming the file on unreadable or malformed TOML."""
    path = resolve_scene_path(name_or_path)
    return load_toml_file(path), path


def apply_overrides(data: dict, overrides: list[str], source: str = "--set") -> dict:
    """Apply KEY=VALUE overrides: dotted keys, TOML values (bare words are strings).  A number in the key picks an
    entry of an array of tables, counted from 0, as in the error messages: `loads.0.amplitude=2` sets the
    amplitude of the first [[loads]] entry.  A table that does not exist yet is created; an array entry is not."""
    for item in overrides:
        if "=" not in item:
            raise InputError(f"{source}: {item!r} is not KEY=VALUE")
        key, raw = item.split("=", 1)
        key = key.strip()
        if not all(part.strip() for part in key.split(".")):
            raise InputError(f"{source}: {item!r}: empty key (give a dotted key such as mesh.size)")
        if "[" in key:
            raise InputError(f"{source}: {key}: write array entries with a dotted index from 0, e.g. "
                             "loads.0.amplitude=2 for the first [[loads]] entry")
        try:
            value = tomllib.loads(f"v = {raw}")["v"]
        except tomllib.TOMLDecodeError:
            value = raw
        node = data
        parts = [part.strip() for part in key.split(".")]
        for depth, part in enumerate(parts):
            where = ".".join(parts[:depth])
            last = depth == len(parts) - 1
            if isinstance(node, list):
                if not part.isdigit():
                    raise InputError(f"{source}: {key}: {where} is an array: give an index from 0 "
                                     f"({where}.0.…), not {part!r}")
                if int(part) >= len(node):
                    raise InputError(f"{source}: {key}: index {part} is out of range: {where} has "
                                     f"{len(node)} entr{'y' if len(node) == 1 else 'ies'}"
                                     + (f" (0 to {len(node) - 1})" if node else ""))
                if last:
                    node[int(part)] = value
                else:
                    node = node[int(part)]
                continue
            if not isinstance(node, dict):
                raise InputError(f"{source}: {key}: {where} is not a table")
            if last:
                node[part] = value
            else:
                node = node.setdefault(part, {})
    return data


def naming_the_override(exc: InputError, overrides: list[str] | None, source: str = "--set") -> InputError:
    """The error of a scene check, with " (from --set KEY=VALUE)" added when the key it names came from an override:
    `housingfe run box-free --set mesh.sise=0.01` named only the built-in scene file, which holds no such key."""
    message = str(exc)
    for item in overrides or []:
        key = item.split("=", 1)[0].strip()
        if key and (f": {key}:" in message or f": {key}." in message):
            return InputError(f"{message} (from {source} {item})")
    return exc


def read_csv_rows(path, what: str, columns, columns_hint: str, example: str):
    """A CSV file the user brings (a transmission error, a measured run-up) for its reader: (sha256 of its bytes, the
    header's column names, the header's line number, [(line number, row of cells)] after it).  Blank lines and lines
    starting with '#' are skipped and a UTF-8 byte-order mark is taken.  InputError naming the file -- and the line
    -- when it cannot be read (`what`: "the transmission error file"), has no rows (`example`: the header to
    suggest), a column outside `columns` (`columns_hint` says which are known) or named twice, or a row whose count
    of values is not the header's."""
    import csv
    import hashlib
    import io

    path = Path(path)
    try:
        raw = path.read_bytes()
        text = raw.decode("utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else type(exc).__name__
        raise InputError(f"{path}: cannot read {what} ({reason})") from None
    lines = [(number, line) for number, line in enumerate(text.splitlines(), 1)
             if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise InputError(f"{path}: no rows ({example})")
    rows = list(csv.reader(io.StringIO("\n".join(line for _, line in lines))))
    header = [h.strip() for h in rows[0]]
    unknown = [h for h in header if h not in columns]
    if unknown:
        raise InputError(f"{path}: line {lines[0][0]}: unknown column {unknown[0]!r} ({columns_hint})")
    if len(set(header)) != len(header):
        raise InputError(f"{path}: line {lines[0][0]}: a column is named twice")
    body = []
    for (number, _), row in zip(lines[1:], rows[1:]):
        if len(row) != len(header):
            raise InputError(f"{path}: line {number}: {len(row)} values for {len(header)} columns")
        body.append((number, row))
    return hashlib.sha256(raw).hexdigest(), header, lines[0][0], body


def csv_number(where: str, column: str, cell: str) -> float:
    """A finite number from a CSV cell, or InputError "<where>: <column>: '<cell>' is not a (finite) number"."""
    try:
        value = float(cell)
    except ValueError:
        raise InputError(f"{where}: {column}: {cell.strip()!r} is not a number") from None
    if not math.isfinite(value):
        raise InputError(f"{where}: {column}: {value} is not a finite number")
    return value


def scene_file_key(value: str, info, read) -> str:
    """A file-valued scene key for a pydantic field validator: "" stays ""; else the absolute path -- relative to the
    scene file when the file is there, else to the current folder (a --set on a built-in scene) -- checked by
    `read(path)` (which raises InputError naming the file for what it cannot take: that becomes the validator's
    ValueError).  info: the validator's ValidationInfo, whose context holds the scene's path (parse_table)."""
    if not value:
        return ""
    scene_path = (info.context or {}).get("scene_path") if info is not None else None
    path = Path(value).expanduser()
    if not path.is_absolute() and scene_path is not None and (Path(scene_path).resolve().parent / path).is_file():
        path = Path(scene_path).resolve().parent / path
    path = path.resolve()
    try:
        read(path)
    except InputError as exc:
        raise ValueError(str(exc)) from None
    return str(path)


def parse_table(model_cls, data, path, prefix: str = ""):
    """model_cls.model_validate(data), or InputError "<path>: <prefix><key>: <problem>" naming the first bad
    key (an unknown key before the missing one it causes).  Shared by every kind of scene."""
    bad = _first_non_finite(data)
    if bad is not None:     # TOML allows inf and nan; pydantic would pass inf as a positive length
        raise InputError(f"{path}: {prefix}{bad[0]}: {bad[1]} is not a finite number")
    try:
        # the context lets file-valued keys (a mesh file) be given relative to the scene file
        return model_cls.model_validate(data, context={"scene_path": Path(path)})
    except ValidationError as exc:
        raise InputError(f"{path}: {prefix}{_first_error(exc)}") from None


def _first_non_finite(data, key: str = ""):
    """(dotted key, value) of the first inf or nan in a parsed scene, or None."""
    items = data.items() if isinstance(data, dict) else enumerate(data) if isinstance(data, list) else ()
    for k, v in items:
        sub = f"{key}.{k}" if key else str(k)
        if isinstance(v, float) and not math.isfinite(v):
            return sub, v
        found = _first_non_finite(v, sub)
        if found is not None:
            return found
    return None


def _location(err) -> str:
    # pydantic puts the discriminator value of a union (geometry.<kind>.key) into the location: drop it
    loc_parts = list(err["loc"])
    if len(loc_parts) > 1 and loc_parts[0] == "geometry":
        del loc_parts[1]
    return ".".join(str(p) for p in loc_parts)


def _first_error(exc: ValidationError) -> str:
    # a misspelt key also shows up as a missing one: name the unknown key, it is the cause
    errors = sorted(exc.errors(), key=lambda e: e["type"] != "extra_forbidden")
    err = errors[0]
    loc = _location(err)
    msg = err["msg"]
    if err["type"] == "extra_forbidden":
        msg = "unknown key"
    elif err["type"] == "missing":
        msg = "missing"
    elif msg.startswith("Value error, "):
        msg = msg[len("Value error, "):]
        # our validators name the key first ("key: problem"): attach it to the location
        if ": " in msg:
            key, rest = msg.split(": ", 1)
            if key.replace("_", "").isalnum():
                return f"{loc + '.' if loc else ''}{key}: {rest}"
    # every other key at fault by name (a union reports one value several times: each key once)
    missing, other = [], []
    for e in errors[1:]:
        where = _location(e)
        if where != loc and where not in missing + other:
            (missing if e["type"] == "missing" else other).append(where)
    extra = []
    if missing:
        extra.append("also missing: " + ", ".join(missing))
    if other:
        extra.append("also wrong: " + ", ".join(other))
    extra = f" ({'; '.join(extra)})" if extra else ""
    return f"{loc}: {msg}{extra}" if loc else f"{msg}{extra}"
