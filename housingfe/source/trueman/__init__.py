"""Trueman's drive model: D. Trueman, *Gear error induced impact in a multiple take-off textile drive system
operating under light loading*, PhD thesis, Loughborough, 1974 (seed /work/shared/seeds/000_93b67f60ea77c9f7.txt;
docs/trueman.md, /work/shared/notes/trueman-1974-brief.md).

Computes the forced torsional response of a branched multi-mesh drive to transmission-error harmonics by the
dynamic stiffness method: critical speeds, and the dynamic mesh loads at every mesh over speed for random
production-error magnitudes and phases.

  `data`      Appendix B input data as printed (imperial), converted to SI once; Table 6.1 critical speeds
  `model`     assembly of the branched drive as one global system (`DriveConfig`, `build_drive`)
  `response`  natural frequencies, critical speeds, mesh transfer and mesh load envelopes
  `run`       scene schema, `run_scene` for `housingfe source trueman-*`, benchmark rows
"""
from housingfe.source.trueman.model import DriveConfig, DriveModel, build_drive
from housingfe.source.trueman.response import (
    critical_speeds,
    mesh_load_envelopes,
    mesh_torques,
    mesh_transfer,
    random_te,
)
from housingfe.source.trueman.run import TruemanScene, run_scene

__all__ = [
    "DriveConfig",
    "DriveModel",
    "TruemanScene",
    "build_drive",
    "critical_speeds",
    "mesh_load_envelopes",
    "mesh_torques",
    "mesh_transfer",
    "random_te",
    "run_scene",
]
