"""`housingfe bearing DESIGNATION --load FX FY FZ MX MY [--json]`: one bearing's mean point and 6x6 stiffness."""
from __future__ import annotations

import argparse
import json

import numpy as np

from housingfe.errors import InputError


def register(subparsers) -> None:
    """Add the `bearing` sub-command."""
    from housingfe.bearings.catalogue import designations

    p = subparsers.add_parser(
        "bearing", help="6x6 stiffness of a rolling bearing under a mean load (van Roosmalen Ch. 3)",
        description="Mean displacement, rolling-element loads and the 6x6 stiffness [K]_bm (z = shaft axis; "
                    "order x, y, z, theta_x, theta_y, theta_z; N/m, N/rad, N m/rad). Catalogue: "
                    + ", ".join(designations()))
    p.add_argument("designation", help="catalogue designation, e.g. 'SKF 6312' or 6312")
    p.add_argument("--load", nargs=5, type=float, required=True, metavar=("FX", "FY", "FZ", "MX", "MY"),
                   help="mean load on the inner ring [N, N, N, N m, N m]")
    p.add_argument("--preload-axial", type=float, default=0.0, metavar="N",
                   help="axial preload added to FZ [N]")
    p.add_argument("--model", default=None,
                   choices=["lim-ball", "lim-roller", "sliced-roller", "sliced-roller-thesis", "self-aligning"],
                   help="default: lim-ball for balls, sliced-roller (thesis Sec. 3.3.2) for rollers, "
                        "self-aligning for spherical roller bearings")
    p.add_argument("--fixed-tilt", action="store_true",
                   help="hold the tilt at zero (shaft held by a second bearing); MX, MY are then outputs")
    p.add_argument("--json", action="store_true", help="print JSON {K, displacement, element_loads, ...}")
    p.set_defaults(func=_cmd_bearing)


def _cmd_bearing(args: argparse.Namespace) -> int:
    from housingfe.bearings import bearing_stiffness, lookup

    geometry = lookup(args.designation)
    result = bearing_stiffness(geometry, args.load, model=args.model, preload_axial=args.preload_axial,
                               fixed_tilt=(0.0, 0.0) if args.fixed_tilt else None)
    if args.json:
        data = result.as_dict()
        data["estimated"] = geometry.estimated
        print(json.dumps(data, indent=2))
        return 0
    print(format_result(result, geometry.estimated))
    return 0


def format_result(result, estimated: dict) -> str:
    """Human-readable summary: operating point, element loads and the 6x6 matrix."""
    from housingfe.bearings.rolling import DOF_NAMES

    if not np.all(np.isfinite(result.K)):
        raise InputError(f"{result.designation}: non-finite stiffness")
    lines = [f"{result.designation}  model {result.model}  ({result.iterations} Newton iterations)",
             "load [N, N m]:          " + "  ".join(f"{v:11.4g}" for v in result.load[:5]),
             "displacement [m, rad]:  " + "  ".join(f"{v:11.4g}" for v in result.displacement[:5]),
             "element loads [N] at psi = 0, 360/Z, ... deg:",
             "  " + "  ".join(f"{v:.4g}" for v in result.element_loads),
             "K [N/m, N/rad, N m/rad]  (rows/columns " + ", ".join(DOF_NAMES) + "):"]
    for row in result.K:
        lines.append("  " + "  ".join(f"{v:11.4g}" for v in row))
    if estimated:
        lines.append("estimated inputs: " + "; ".join(f"{k} = {v}" for k, v in estimated.items()))
    return "\n".join(lines)
