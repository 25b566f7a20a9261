"""Published input data shipped with the package (`roosmalen1994.toml`: the numbers of van Roosmalen's thesis).

A link that takes a model input from the thesis (gear data of Appendix F, fluid-film bearing data) reads it here;
the comparison of results with published numbers lives in housingfe.verification.
"""
from __future__ import annotations

import functools
import tomllib
from pathlib import Path

THESIS_FILE = Path(__file__).resolve().parent / "roosmalen1994.toml"


@functools.lru_cache(maxsize=1)
def thesis() -> dict:
    """The thesis' published numbers (housingfe/data/roosmalen1994.toml) as a dict (cached; do not modify)."""
    with open(THESIS_FILE, "rb") as fh:
        return tomllib.load(fh)
