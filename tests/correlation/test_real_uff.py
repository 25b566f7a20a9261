"""Universal files written by other programs (pyuff's test data, tests/data/uff/README.md): the units dataset 164
of each is honoured, whatever its code, and a user's --units that contradicts it is refused."""
from pathlib import Path

import numpy as np
import pytest

from housingfe.correlation.uff import read_uff
from housingfe.errors import InputError

DATA = Path(__file__).parents[1] / "data" / "uff"


def test_mm_file_with_164_code_5_is_read_in_metres():
    """heat_engine_housing.uff: 164 code 5 (mm, length factor 1000), node 1 written as (-171.18, 103.64, 138.48)."""
    d = read_uff(DATA / "heat_engine_housing.uff")
    assert len(d.nodes.ids) == 10                 # the 2411 dataset holds 10 nodes
    assert np.allclose(d.nodes.xyz[0], [-0.1711755676269531, 0.1036403427124023, 0.1384829101562500], rtol=1e-12)
    assert np.ptp(d.nodes.xyz, axis=0).max() < 0.05        # a few cm of housing, not tens of metres
    with pytest.raises(InputError, match="contradicts the file's units dataset 164"):
        read_uff(DATA / "heat_engine_housing.uff", "m")


def test_testlab_file_with_user_defined_164_in_metres():
    """LMS Test.Lab export: 164 code 9 (user defined) with length factor 1: coordinates stay as written (m)."""
    d = read_uff(DATA / "testlab_161_164_18_15_82.uff")
    assert np.allclose(d.nodes.xyz[:3], [[-2.4, -0.95, 0.0], [-2.6, 2.05, 0.0], [2.6, 2.05, 0.0]], rtol=1e-12)
