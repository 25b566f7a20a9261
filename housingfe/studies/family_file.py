"""A family of design variants in a TOML file of the user's own: `housingfe study my_family.toml` (docs/design-variants.md,
"Your own family").

    name = "bearings-at-1500"           # optional (default: the file's stem): names <name>.csv, .md, .png
    scene = "test-gearbox-runup"        # a built-in run-up scene, or a run-up scene file (relative to this file)
    title = "..."                       # optional, heads the tables
    reference = "ball"                  # the key of the variant the differences are taken to
    source = "..."                      # optional: where the measured numbers come from
    notes = ["..."]                     # optional: what the comparison rests on
    set = ["runup.engagement=thesis-2d"]  # optional: overrides of the scene, as --set (not the keys a variant sets)
    [[variants]]
    key = "ball"                        # its name in the tables
    gear_set = "B"                      # optional (default: the scene's drivetrain.gear_set)
    bearings = "ball"                   # optional (default: the scene's drivetrain.bearings)
    torque_nm = 1500                    # optional, pinion torque N m (default: the scene's first runup.torques_nm)
    measured_mean_db = -5.1             # optional (not on the reference): the user's measured mean and s.d. of the
    measured_sd_db = 6.0                #   L_WA difference to the reference over 800-1500 rev/min, dB
    measured_max_dba = 92.3             # optional: the measured largest L_WA over the run-up, dB(A)
    [[torque_laws]]                     # optional: a measured torque law of variants that differ only in torque
    gear_set = "B"                      # optional (default: the scene's drivetrain.gear_set)
    bearings = "ball"                   # optional (default: the scene's drivetrain.bearings)
    from_nm = 1000                      # optional: the step's torques, N m, each a variant's of this gear set and
    to_nm = 2000                        #   bearings (default: their lowest and highest)
    measured_step_dba = 3.4             # the measured L_WA(to_nm) - L_WA(from_nm), mean over 800-1500 rev/min, dB(A)
    measured_slope_dba_per_doubling = 3.0   # and/or the measured slope, dB(A) per doubling of torque

`read_family_file` gives the fields of the `Family` and its `Variant`s that housingfe.studies.design_variants.family_of
makes of it (this module does not import that one: no import cycle), so a file family is run by the same machinery
as the built-in ones: every variant of the same layout re-uses one modal basis.  Everything a user can get wrong is
found here, before any folder or FE model is made, as an InputError "<file>: <key>: <what>": the gear sets and
bearing configurations are checked by the run-up scene's own validators (housingfe.runup.scene.DrivetrainSpec), the
torques by the gear pair's strength, each drivetrain's bearings by their loads, each measured torque law against
the variants (a gear set and bearings that some variant has, at two or more torques; from_nm and to_nm torques of
such variants; one law per gear set and bearings).
"""
from __future__ import annotations

from pathlib import Path
from typing import Optional

from pydantic import Field, NonNegativeFloat, PositiveFloat, field_validator

from housingfe.errors import InputError
from housingfe.scenefile import (
    SCENE_DIR,
    FolderName,
    _Strict,
    builtin_scenes,
    load_toml_file,
    parse_table,
    scene_name_problem,
)


class VariantEntry(_Strict):
    """One [[variants]] entry (units: N m, dB, dB(A))."""

    key: str
    gear_set: Optional[str] = None
    bearings: Optional[str] = None
    torque_nm: Optional[PositiveFloat] = Field(None, json_schema_extra={"unit": "N m"})
    measured_mean_db: Optional[float] = Field(None, json_schema_extra={"unit": "dB"})
    measured_sd_db: Optional[NonNegativeFloat] = Field(None, json_schema_extra={"unit": "dB"})
    measured_max_dba: Optional[float] = Field(None, json_schema_extra={"unit": "dB(A)"})

    @field_validator("key")
    @classmethod
    def _plain_key(cls, key):
        # the key heads table rows and names columns of <name>_runup.csv
        if not key.strip() or any(c in key for c in "|,\"") or any(ord(c) < 32 for c in key):
            raise ValueError(f"{key!r}: give a non-empty name without '|', ',', '\"' or control characters")
        return key


class TorqueLawEntry(_Strict):
    """One [[torque_laws]] entry: a measured torque law of the variants of one gear set and bearing configuration
    (units: N m, dB(A), dB(A) per doubling of torque)."""

    gear_set: Optional[str] = None
    bearings: Optional[str] = None
    from_nm: Optional[PositiveFloat] = Field(None, json_schema_extra={"unit": "N m"})
    to_nm: Optional[PositiveFloat] = Field(None, json_schema_extra={"unit": "N m"})
    measured_step_dba: Optional[float] = Field(None, json_schema_extra={"unit": "dB(A)"})
    measured_slope_dba_per_doubling: Optional[float] = Field(None, json_schema_extra={"unit": "dB(A)"})


class FamilyFileSpec(_Strict):
    """The family file (module docstring)."""

    name: Optional[FolderName] = None
    scene: str
    title: str = ""
    reference: str
    source: str = ""
    notes: list[str] = []
    set: list[str] = []
    variants: list[VariantEntry]
    torque_laws: list[TorqueLawEntry] = []

    @field_validator("variants")
    @classmethod
    def _two_or_more(cls, variants):
        if len(variants) < 2:
            raise ValueError(f"{len(variants)} given: a family needs the reference and at least one variant to "
                             "compare with it")
        return variants


def _known(model) -> list[str]:
    return list(model.model_fields)


def _unknown_key(data: dict, path: Path) -> None:
    """InputError naming the first unknown key and listing the known ones (a misspelt key would otherwise read as a
    missing one, or be refused without saying what was meant)."""
    for key in data:
        if key not in FamilyFileSpec.model_fields:
            raise InputError(f"{path}: {key}: unknown key (known: {', '.join(_known(FamilyFileSpec))})")
    variants = data.get("variants")
    for i, entry in enumerate(variants if isinstance(variants, list) else []):
        for key in entry if isinstance(entry, dict) else ():
            if key not in VariantEntry.model_fields:
                raise InputError(f"{path}: variants.{i}.{key}: unknown key (known: {', '.join(_known(VariantEntry))})")
    laws = data.get("torque_laws")
    for i, entry in enumerate(laws if isinstance(laws, list) else []):
        for key in entry if isinstance(entry, dict) else ():
            if key not in TorqueLawEntry.model_fields:
                raise InputError(f"{path}: torque_laws.{i}.{key}: unknown key (known: "
                                 f"{', '.join(_known(TorqueLawEntry))})")
    for required in ("scene", "reference"):
        if required not in data:
            what = ("the run-up scene the variants run on (a built-in name such as test-gearbox-runup, or a "
                    "file)" if required == "scene" else "the key of the variant the differences are taken to")
            raise InputError(f"{path}: {required}: missing: give {what}")
    if "variants" not in data:
        raise InputError(f"{path}: variants: missing: give [[variants]] entries (key, gear_set, bearings, torque_nm)")


def _scene_ref(value: str, path: Path) -> str:
    """The scene as the run-up machinery takes it: a file beside the family file (or absolute), else a built-in
    run-up scene name; InputError if it is neither or not a run-up scene."""
    builtin = builtin_scenes()
    runups = [n for n in builtin if _kind(SCENE_DIR / f"{n}.toml") == "runup"]
    candidate = Path(value).expanduser()
    if not candidate.is_absolute():
        candidate = path.parent / candidate
    if candidate.is_file():
        kind, ref = _kind(candidate), str(candidate)
    elif value in builtin:
        kind, ref = _kind(SCENE_DIR / f"{value}.toml"), value
    else:
        raise InputError(f"{path}: scene: {value!r}: no such file ({candidate}) nor built-in scene (built-in run-up "
                         f"scenes: {', '.join(runups)})")
    if kind != "runup":
        raise InputError(f"{path}: scene: {value!r} is a {kind or 'kind-less'} scene, not a run-up scene "
                         f"(kind = \"runup\"; built-in: {', '.join(runups)})")
    return ref


def _kind(scene_path: Path):
    data = load_toml_file(scene_path)
    info = data.get("scene")
    return info.get("kind") if isinstance(info, dict) else None


def read_family_file(file: str | Path, controlled: tuple) -> dict:
    """Read a family file (module docstring): the keyword arguments of design_variants.Family, with "variants" a
    list of the keyword arguments of design_variants.Variant (torque in N m, levels in dB / dB(A)).  controlled:
    the scene keys a variant sets (refused in the file's `set`).  InputError "<file>: <key>: <what>" on any
    problem."""
    from housingfe.runup.scene import DrivetrainSpec, drivetrain_of, load_runup_scene

    path = Path(file)
    if not path.is_file():
        raise InputError(f"{file}: no such family file")
    data = load_toml_file(path)
    _unknown_key(data, path)
    spec = parse_table(FamilyFileSpec, data, path)
    keys = [v.key for v in spec.variants]
    for i, key in enumerate(keys):
        if key in keys[:i]:
            raise InputError(f"{path}: variants.{i}.key: {key!r} is also variants.{keys.index(key)}.key: each "
                             "variant needs a key of its own")
    if spec.reference not in keys:
        raise InputError(f"{path}: reference: {spec.reference!r} is not a variant key (variants: {', '.join(keys)})")
    for item in spec.set:
        key = item.split("=", 1)[0].strip()
        if any(key == c or key.startswith(c + ".") for c in controlled):
            raise InputError(f"{path}: set: {key}: each variant sets it (gear_set, bearings, torque_nm)")
    scene_ref = _scene_ref(spec.scene, path)
    try:
        scene, _ = load_runup_scene(scene_ref)
    except InputError as exc:
        raise InputError(f"{path}: scene: {exc}") from None
    if spec.set:
        try:
            scene, _ = load_runup_scene(scene_ref, list(spec.set))
        except InputError as exc:
            raise InputError(f"{path}: set: {exc}") from None
    base = scene.drivetrain.model_dump()
    variants = []
    for i, v in enumerate(spec.variants):
        where = f"variants.{i}."
        if v.key == spec.reference and (v.measured_mean_db is not None or v.measured_sd_db is not None):
            raise InputError(f"{path}: {where}measured_mean_db: the reference's difference to itself is 0 (give "
                             "measured means and s.d. on the other variants)")
        drive = parse_table(DrivetrainSpec, {**base, **({"gear_set": v.gear_set} if v.gear_set is not None else {}),
                                             **({"bearings": v.bearings} if v.bearings is not None else {})}, path, where)
        torque = float(v.torque_nm if v.torque_nm is not None else scene.runup.torques_nm[0])
        dt = drivetrain_of(drive, torque, scene.runup.drive_line_model)
        problem = dt.gears.pair.torque_problem(torque)
        if problem is not None:
            raise InputError(f"{path}: {where}torque_nm: {problem}")
        try:
            dt.to_coupling_spec()            # the bearings at their loads: one that cannot carry its load stops here
        except InputError as exc:
            raise InputError(f"{path}: {where.rstrip('.')} ({v.key}): {exc}") from None
        variants.append({"key": v.key, "gear_set": drive.gear_set, "bearings": drive.bearings, "torque": torque,
                         "measured_mean": v.measured_mean_db, "measured_sd": v.measured_sd_db,
                         "measured_max": v.measured_max_dba})
    torque_laws = _torque_laws(spec, variants, base, path)
    name = spec.name or path.stem
    problem = scene_name_problem(name)
    if problem is not None:             # a stem such as ".fam" names no result file
        raise InputError(f"{path}: name: the file's stem {problem}; give name = \"...\"")
    return {"name": name, "scene": scene_ref,
            "title": spec.title or f"{name}: {len(variants)} variants on {spec.scene}", "variants": variants,
            "reference": spec.reference,
            "source": spec.source or f"the family file {path.name} (measured values as given there)",
            "notes": tuple(spec.notes), "controlled": tuple(controlled), "overrides": tuple(spec.set), "path": path,
            "torque_laws": torque_laws}


def _torque_laws(spec: FamilyFileSpec, variants: list, drivetrain: dict, path: Path) -> list[dict]:
    """The [[torque_laws]] entries as keyword arguments of design_variants.MeasuredTorqueLaw (torques N m, step
    dB(A), slope dB(A) per doubling), checked against the variants (`variants`: as read_family_file makes them;
    `drivetrain`: the scene's, for the defaults)."""
    torques: dict = {}
    for v in variants:
        torques.setdefault((v["gear_set"], v["bearings"]), set()).add(v["torque"])
    out, seen = [], {}
    for i, law in enumerate(spec.torque_laws):
        where = f"torque_laws.{i}"
        gear_set = law.gear_set if law.gear_set is not None else drivetrain["gear_set"]
        bearings = law.bearings if law.bearings is not None else drivetrain["bearings"]
        group = f"gear set {gear_set!r} and bearings {bearings!r}"
        if (gear_set, bearings) not in torques:
            have = "; ".join(f"{g}/{b}" for g, b in torques)
            key = "bearings" if any(g == gear_set for g, _ in torques) else "gear_set"
            raise InputError(f"{path}: {where}.{key}: no variant has {group} (the variants' gear set/bearings: "
                             f"{have})")
        run = sorted(torques[gear_set, bearings])
        listed = ", ".join(f"{t:g}" for t in run)
        if len(run) < 2:
            raise InputError(f"{path}: {where}: the variants with {group} are at one torque ({listed} N m): a torque "
                             "law needs variants at two or more torques that differ in nothing else")
        if (gear_set, bearings) in seen:
            raise InputError(f"{path}: {where}: {group} has a torque law already (torque_laws."
                             f"{seen[gear_set, bearings]})")
        seen[gear_set, bearings] = i
        for key, value in (("from_nm", law.from_nm), ("to_nm", law.to_nm)):
            if value is not None and float(value) not in run:
                raise InputError(f"{path}: {where}.{key}: {value:g} N m: no variant with {group} runs at it (their "
                                 f"torques: {listed} N m)")
        low = float(law.from_nm) if law.from_nm is not None else run[0]
        high = float(law.to_nm) if law.to_nm is not None else run[-1]
        if high <= low:
            raise InputError(f"{path}: {where}.to_nm: {high:g} N m: give a torque above from_nm ({low:g} N m)")
        if law.measured_step_dba is None and law.measured_slope_dba_per_doubling is None:
            raise InputError(f"{path}: {where}.measured_step_dba: missing: give measured_step_dba (dB(A), "
                             "L_WA(to_nm) - L_WA(from_nm), mean over 800-1500 rev/min) and/or "
                             "measured_slope_dba_per_doubling")
        out.append({"gear_set": gear_set, "bearings": bearings, "from_nm": low, "to_nm": high,
                    "measured_step": law.measured_step_dba, "measured_slope": law.measured_slope_dba_per_doubling})
    return out
