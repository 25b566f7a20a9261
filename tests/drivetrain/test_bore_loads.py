"""The loads a bearing puts on its bore master (housingfe.drivetrain.bore_loads), on one bearing element with an
analytic answer: a shaft node moved by delta against a held bore master pulls the bore along with K delta
(spring force on b = +K (u_a - u_b), housingfe.drivetrain.coupling.spring), plus i omega C delta with damping, and
the rigid arm from the master to the shaft node (offset r) adds the moment r x F about the master."""
import math

import numpy as np
import pytest

from housingfe.drivetrain import coupling as cp
from housingfe.drivetrain.bore_loads import bearing_elements, bore_loads, force_level_db, moment_level_db


def _element(offset):
    K6 = np.diag([2.0e8, 3.0e8, 5.0e7, 1.0e5, 2.0e5, 0.0])
    C6 = np.diag([4.0e3, 1.0e3, 2.0e3, 0.0, 0.0, 0.0])
    e = cp.spring("shaft:3", "bore_a", K6, C6, offset=offset)
    rows = {"shaft:3": np.hstack([np.eye(6), np.zeros((6, 6))]), "bore_a": np.hstack([np.zeros((6, 6)), np.eye(6)])}
    return bearing_elements([e, cp.spring("shaft:9", None, K6)], rows), K6, C6      # the grounded one is left out


def test_a_shaft_displacement_pulls_the_bore_along():
    offset = np.array([0.0, 0.002, -0.001])
    els, K6, C6 = _element(offset)
    assert len(els) == 1 and els[0].bore == "bore_a"
    delta = np.array([1e-6, -2e-6, 0.5e-6])
    c = np.r_[delta, np.zeros(3), np.zeros(6)]          # the shaft node moves, the bore master is held
    f = 250.0
    load = bore_loads(els, f, c)
    F = (K6[:3, :3] + 1j * 2 * math.pi * f * C6[:3, :3]) @ delta
    np.testing.assert_allclose(load[0, :3], F, rtol=1e-12)
    np.testing.assert_allclose(load[0, 3:], np.cross(offset, F), rtol=1e-12, atol=1e-18)
    # the same with the bore moved the other way: the load depends on the relative motion only
    np.testing.assert_allclose(bore_loads(els, f, np.r_[np.zeros(6), -delta, np.zeros(3)])[0, :3], F, rtol=1e-12)
    # several lines at once, levels: 10 lg sum |F|^2 (dB re 1 N), 10 lg sum |M|^2 (dB re 1 N m)
    many = bore_loads(els, [f, f], np.column_stack([c, 2 * c]))
    assert many.shape == (2, 1, 6)
    L = force_level_db(many)
    assert L[0] == pytest.approx(10 * math.log10(np.sum(np.abs(F) ** 2)), abs=1e-9)
    assert L[1] - L[0] == pytest.approx(20 * math.log10(2.0), abs=1e-9)
    assert moment_level_db(many)[0] == pytest.approx(10 * math.log10(np.sum(np.abs(np.cross(offset, F)) ** 2)),
                                                     abs=1e-9)
