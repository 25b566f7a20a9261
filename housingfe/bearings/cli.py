"""`housingfe bearing`: one rolling bearing's deflection under a mean load and its 6x6 stiffness.

The bearing is a catalogue designation, a TOML file of internal geometry (`--geometry FILE`, a [bearing] table
with the keys of `rolling.GEOMETRY_KEYS`) or command-line flags (`--balls Z --ball-diameter M --pitch-diameter M
...`); flags override the values of a designation or a file.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from housingfe.errors import InputError
from housingfe.outputs import dumps_json

# flag -> (TOML key of rolling.GEOMETRY_KEYS, type, metavar, help)
_FLAGS = {
    "--kind": ("kind", str, "KIND", "ball (default), cylindrical_roller, tapered_roller or spherical_roller"),
    "--balls": ("elements", int, "Z", "number of balls (rolling elements) Z per row"),
    "--ball-diameter": ("element_diameter", float, "M", "ball (roller) diameter D_w [m]"),
    "--pitch-diameter": ("pitch_diameter", float, "M", "pitch diameter d_pw [m]"),
    "--conformity-inner": ("conformity_inner", float, "F", "inner groove conformity f_i = r_i / D_w [-], > 0.5"),
    "--conformity-outer": ("conformity_outer", float, "F", "outer groove conformity f_o = r_o / D_w [-], > 0.5"),
    "--radial-clearance": ("radial_clearance", float, "M",
                           "radial play of the centred rings = HALF the diametral clearance [m]"),
    "--contact-angle-deg": ("contact_angle_deg", float, "DEG", "unloaded contact angle [deg]"),
    "--roller-length": ("roller_length", float, "M", "effective roller length [m] (rollers)"),
    "--roller-profile": ("roller_profile", str, "PROFILE",
                         "straight (full line contact, default) or logarithmic (ISO/TS 16281 crowned rollers)"),
    "--youngs-modulus": ("youngs_modulus", float, "PA", "Young's modulus of rings and elements [Pa] (208e9)"),
    "--poisson-ratio": ("poisson_ratio", float, "NU", "Poisson ratio [-] (0.3)"),
}


def register(subparsers) -> None:
    """Add the `bearing` sub-command."""
    from housingfe.bearings.catalogue import designations

    p = subparsers.add_parser(
        "bearing", help="deflection and 6x6 stiffness of a rolling bearing under a mean load (van Roosmalen Ch. 3)",
        description="Deflection under the load (equilibrium solve), rolling-element loads, the 6x6 tangent "
                    "stiffness [K]_bm = dF/d(delta) and the secant stiffness F/delta (z = shaft axis; order x, y, "
                    "z, theta_x, theta_y, theta_z; N/m, N/rad, N m/rad).  The bearing: a catalogue designation ("
                    + ", ".join(designations()) + "), --geometry FILE.toml ([bearing] table: elements, "
                    "element_diameter, pitch_diameter, conformity_inner, conformity_outer, radial_clearance, "
                    "contact_angle_deg, ...; SI, angle in degrees) or the flags below; flags override.")
    p.add_argument("designation", nargs="?", default=None, help="catalogue designation, e.g. 'SKF 6312' or 6312")
    p.add_argument("--geometry", metavar="FILE.toml", default=None,
                   help="internal geometry as a TOML [bearing] table (keys: elements, element_diameter, pitch_diameter, ... as listed above, not the flag names; SI units)")
    for flag, (_, typ, metavar, text) in _FLAGS.items():
        p.add_argument(flag, type=typ, metavar=metavar, default=None, help=text)
    p.add_argument("--load", nargs=5, type=float, required=True, metavar=("FX", "FY", "FZ", "MX", "MY"),
                   help="mean load on the inner ring [N, N, N, N m, N m]")
    p.add_argument("--preload-axial", type=float, default=0.0, metavar="N",
                   help="axial preload added to FZ [N]")
    p.add_argument("--model", default=None, metavar="NAME",
                   help="a registered bearing model (housingfe.bearings.rolling.BEARING_MODELS: lim-ball, lim-roller, "
                        "sliced-roller, ...); default: lim-ball for balls, sliced-roller (thesis Sec. 3.3.2) for "
                        "rollers, self-aligning for spherical roller bearings")
    p.add_argument("--fixed-tilt", action="store_true",
                   help="hold the tilt at zero (shaft held by a second bearing); MX, MY are then outputs")
    p.add_argument("--json", action="store_true",
                   help="print JSON {displacement (deflection under the load), K (tangent), secant_stiffness, ...}")
    p.set_defaults(func=_cmd_bearing, mpi="serial")


def _geometry_table_from_file(path: str) -> dict:
    from housingfe.scenefile import load_toml_file

    data = load_toml_file(Path(path))
    unknown = sorted(set(data) - {"bearing"})
    if unknown:
        raise InputError(f"{path}: {unknown[0]}: unknown key (the file holds one [bearing] table)")
    if not isinstance(data.get("bearing"), dict):
        raise InputError(f"{path}: bearing: missing [bearing] table")
    return dict(data["bearing"])


def bearing_from_arguments(args: argparse.Namespace):
    """The RollingBearing a command line describes: designation, --geometry file and/or flags."""
    import dataclasses

    from housingfe.bearings.catalogue import lookup
    from housingfe.bearings.rolling import GEOMETRY_KEYS, bearing_from_table

    flags = {key: getattr(args, flag[2:].replace("-", "_")) for flag, (key, *_) in _FLAGS.items()}
    flags = {k: v for k, v in flags.items() if v is not None}
    flag_names = {key: flag for flag, (key, *_) in _FLAGS.items() if key in flags}   # errors name what was typed
    if args.designation is not None and args.geometry is not None:
        raise InputError("bearing: give a catalogue designation or --geometry, not both")
    if args.designation is not None:
        base = lookup(args.designation)
        if not flags:
            return base
        # flags override catalogue values: rebuild through the table so every value is checked the same way
        fields = {f.name: getattr(base, f.name) for f in dataclasses.fields(base)}
        table = {}
        for key, (name, _) in GEOMETRY_KEYS.items():
            value = fields[name]
            if value is None or (key == "roller_length" and base.kind == "ball"):
                continue
            table[key] = float(np.degrees(value)) if key == "contact_angle_deg" else value
        table.update(flags)
        where = f"bearing {base.designation} with overrides"
        result = bearing_from_table(table, where, flag_names)
        estimated = {k: v for k, v in base.estimated.items()
                     if not any(GEOMETRY_KEYS[f][0] == k for f in flags)}
        return dataclasses.replace(result, estimated=estimated)
    if args.geometry is not None:
        table = _geometry_table_from_file(args.geometry)
        table.update(flags)
        return bearing_from_table(table, f"{args.geometry}: bearing", flag_names)
    if not flags:
        raise InputError("bearing: give a catalogue designation, --geometry FILE.toml or the internal geometry "
                         "(--balls, --ball-diameter, --pitch-diameter, ...)")
    return bearing_from_table(flags, "bearing (command line)", flag_names)


def _cmd_bearing(args: argparse.Namespace) -> int:
    from housingfe.bearings import bearing_stiffness

    geometry = bearing_from_arguments(args)
    if args.model is not None:
        from housingfe.bearings.rolling import check_bearing_model

        try:
            check_bearing_model(args.model)
        except ValueError as exc:
            raise InputError(f"--model: {exc}") from None
    result = bearing_stiffness(geometry, args.load, model=args.model, preload_axial=args.preload_axial,
                               fixed_tilt=(0.0, 0.0) if args.fixed_tilt else None)
    if args.json:
        data = result.as_dict()
        data["estimated"] = geometry.estimated
        print(dumps_json(data, indent=2))
        return 0
    print(format_result(result, geometry.estimated))
    return 0


def _fmt(values) -> str:
    return "  ".join(f"{v:11.4g}" if v is not None else f"{'-':>11}" for v in values)


def format_result(result, estimated: dict) -> str:
    """Human-readable summary: load, deflection under it, element loads, tangent and secant stiffness."""
    from housingfe.bearings.rolling import DOF_NAMES

    if not np.all(np.isfinite(result.K)):
        raise InputError(f"{result.designation}: non-finite stiffness")
    lines = [f"{result.designation}  model {result.model}  ({result.iterations} Newton iterations)",
             "                                 " + "  ".join(f"{n:>11}" for n in DOF_NAMES[:5]),
             "load [N, N m]:                   " + _fmt(result.load[:5]),
             "deflection under the load        " + _fmt(result.displacement[:5]),
             "  [m, rad] (equilibrium solve)",
             "secant stiffness F/deflection    " + _fmt(result.secant_stiffness()),
             "  [N/m, N m/rad] (per DOF)",
             "element loads [N] at psi = 0, 360/Z, ... deg:",
             "  " + "  ".join(f"{v:.4g}" for v in result.element_loads),
             "tangent stiffness K = dF/d(deflection) at this load [N/m, N/rad, N m/rad]  (rows/columns "
             + ", ".join(DOF_NAMES) + "):"]
    for row in result.K:
        lines.append("  " + "  ".join(f"{v:11.4g}" for v in row))
    lines.append("K is for small vibrations about this load (the 6x6 used in the housing models).  The static "
                 "deflection is the one above: F/K would underestimate it (by 1/3 for a pure Hertz ball contact, "
                 "where K = 1.5 F/deflection).")
    if estimated:
        lines.append("estimated inputs: " + "; ".join(f"{k} = {v}" for k, v in estimated.items()))
    return "\n".join(lines)


def register_cli(subparsers) -> None:
    """Add `housingfe bearing ...` to the top-level CLI."""
    register(subparsers)
