"""Scene files: a built-in scene by name or a TOML path, read, overridden with --set, validated with pydantic into one
message naming the file and the key.  Shared by every kind of scene (housing, source, ...); the housing scene's own
schema is housingfe.scene."""
from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, ValidationError

from housingfe.errors import InputError

SCENE_DIR = Path(__file__).parent / "scenes"


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class SceneInfo(_Strict):
    name: str
    kind: Literal["housing", "source", "runup"]
    description: str = ""


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


def read_scene_dict(name_or_path: str) -> tuple[dict, Path]:
    """Parse a scene TOML into a dict; InputError naming the file on unreadable or malformed TOML."""
    path = resolve_scene_path(name_or_path)
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh), path
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: malformed TOML: {exc}") from None
    except UnicodeDecodeError as exc:
        raise InputError(f"{path}: not a UTF-8 text file (byte {exc.start}); a scene is TOML text") from None
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc.strerror}") from None


def apply_overrides(data: dict, overrides: list[str], source: str = "--set") -> dict:
    """Apply KEY=VALUE overrides (dotted keys, TOML values; bare words are strings)."""
    for item in overrides:
        if "=" not in item:
            raise InputError(f"{source}: {item!r} is not KEY=VALUE")
        key, raw = item.split("=", 1)
        if not all(part.strip() for part in key.split(".")):
            raise InputError(f"{source}: {item!r}: empty key (give a dotted key such as mesh.size)")
        try:
            value = tomllib.loads(f"v = {raw}")["v"]
        except tomllib.TOMLDecodeError:
            value = raw
        node = data
        parts = key.strip().split(".")
        for part in parts[:-1]:
            node = node.setdefault(part, {})
            if not isinstance(node, dict):
                raise InputError(f"{source}: {key}: {part} is not a table")
        node[parts[-1]] = value
    return data


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


def _first_error(exc: ValidationError) -> str:
    # a misspelt key also shows up as a missing one: name the unknown key, it is the cause
    errors = sorted(exc.errors(), key=lambda e: e["type"] != "extra_forbidden")
    err = errors[0]
    # pydantic puts the discriminator value of a union (geometry.<kind>.key) into the location: drop it
    loc_parts = list(err["loc"])
    if len(loc_parts) > 1 and loc_parts[0] == "geometry":
        del loc_parts[1]
    loc = ".".join(str(p) for p in loc_parts)
    msg = err["msg"]
    if err["type"] == "extra_forbidden":
        msg = "unknown key"
    elif msg.startswith("Value error, "):
        msg = msg[len("Value error, "):]
        # our validators name the key first ("key: problem"): attach it to the location
        if ": " in msg:
            key, rest = msg.split(": ", 1)
            if key.replace("_", "").isalnum():
                return f"{loc + '.' if loc else ''}{key}: {rest}"
    extra = "" if len(exc.errors()) == 1 else f" (and {len(exc.errors()) - 1} more)"
    return f"{loc}: {msg}{extra}" if loc else f"{msg}{extra}"
