"""The run-up of `housingfe run` as a user gets it, for tests that compare a study's or a sampler's numbers with it."""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from tests.test_cli import housingfe


def cli_lwa_curves(scene: str, overrides, out: Path, radiation: str = "erp") -> dict[str, np.ndarray]:
    """Run `housingfe run scene --set ... --out out` (asserting exit 0) and return L_WA over speed [dB(A)] per
    route from its runup.csv, for the radiation model `radiation`."""
    proc = housingfe("run", scene, *[x for s in overrides for x in ("--set", s)], "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    rows = list(csv.DictReader(open(out / "runup.csv")))
    return {route: np.array([float(r["LwA_dB"]) for r in rows if r["route"] == route and r["radiation"] == radiation])
            for route in ("tf_omega", "mesh_force")}
