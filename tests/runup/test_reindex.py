"""The pinion turned against the wheel on set A (housingfe.runup.reindex; thesis Sec. 5.6, Fig. 5.12): a full pinion
revolution changes nothing; a line's level through the band weights is the closed form of its amplitude and the
receptance; and the runout pitch model, whose pinion and wheel lines never share an order, moves the level less over
speed than independent pitch steps."""
import math

import numpy as np
import pytest

from housingfe import levels
from housingfe.errors import InputError
from housingfe.runup import reindex


def test_a_full_pinion_revolution_is_the_identity():
    """Turned by 24 (and 48) teeth the same teeth meet as before: every draw's difference is zero at every speed."""
    results, _ = reindex.turned_pinion(draws=2, shifts=(24, 48), pitch_models=("independent", "runout"))
    assert list(results) == ["independent", "runout"]
    for r in results.values():
        assert r.draws == 2 and r.shifts == (24, 48)
        assert np.max(np.abs(r.mean_db)) < 1e-9 and np.max(np.abs(r.sd_db)) < 1e-9


def test_band_weights_give_a_line_its_closed_form_level():
    """One line of amplitude a [m] at the tooth order 72 through a receptance R [(rad/s)/m]: L_omega =
    20 lg(R a / sqrt(2) / omega_0) in the tooth band and in the bands of harmonics 1-8, plus A(f_tooth) A-weighted;
    a line at order 36 (half the tooth frequency) is in none of them; a line at 2 x 72 in the bands only."""
    orders = np.arange(0.0, 577.0)
    R, a = 0.8, 1e-6
    speeds = np.array([500.0, 1300.0])
    W = reindex.weights_per_speed(orders, 0.4, 72, lambda f: np.full(np.shape(f), R), speeds)
    assert W.shape == (3, 2, orders.size)
    line = np.zeros(orders.size)
    line[72] = a**2
    L = 10 * np.log10(W @ line / levels.OMEGA0**2)
    expected = 20 * math.log10(R * a / math.sqrt(2) / levels.OMEGA0)
    assert L[0] == pytest.approx([expected] * 2, abs=1e-9)
    assert L[1] == pytest.approx([expected] * 2, abs=1e-9)
    assert L[2] == pytest.approx(expected + levels.a_weighting_db(0.4 * speeds), abs=1e-9)
    assert np.all(W[:, :, 36] == 0)
    assert np.all(W[0, :, 144] == 0) and np.all(W[1, :, 144] > 0)


def test_runout_moves_the_level_less_over_speed_than_independent_pitch():
    results, _ = reindex.turned_pinion(draws=4, pitch_models=("independent", "runout"))
    assert np.median(results["runout"].sd_db) < np.median(results["independent"].sd_db)
    assert np.all(results["runout"].sd_db > 0)                  # the flanks' cross terms still move it


def test_bad_arguments_are_one_clear_error():
    with pytest.raises(InputError, match="kind"):
        reindex.turned_pinion(draws=1, kind="L_W")
    with pytest.raises(InputError, match="draws"):
        reindex.turned_pinion(draws=0)
    with pytest.raises(InputError, match="positions"):
        reindex.set_a(positions=33)
