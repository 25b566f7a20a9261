"""MAC, cross-orthogonality, pairing: exact properties (no FE)."""
import numpy as np
import pytest

from housingfe.correlation.mac import cross_orthogonality, frac, mac, mac_png, pair_modes
from housingfe.errors import InputError


def test_mac_of_a_mode_with_itself_is_one_and_scale_free():
    rng = np.random.default_rng(1)
    phi = rng.standard_normal((20, 4))
    m = mac(phi, phi * np.array([2.0, -0.5, 3j, 1e-6]))   # any complex scale
    assert np.allclose(np.diag(m), 1.0, atol=1e-12)
    assert np.all(m <= 1.0 + 1e-12) and np.all(m >= 0.0)


def test_mac_of_orthogonal_shapes_is_zero():
    q, _ = np.linalg.qr(np.random.default_rng(2).standard_normal((12, 5)))
    m = mac(q, q)
    assert np.allclose(m, np.eye(5), atol=1e-12)


def test_cross_orthogonality_with_mass_matrix():
    # generalized eigenvectors of (K, M) are M-orthogonal although not orthogonal: CO = identity, MAC is not
    from scipy.linalg import eigh

    rng = np.random.default_rng(3)
    a = rng.standard_normal((8, 8))
    K = a @ a.T + 8 * np.eye(8)
    M = np.diag(rng.uniform(0.5, 3.0, 8))
    _, phi = eigh(K, M)
    co = cross_orthogonality(phi, phi * 7.0, M)
    assert np.allclose(np.abs(co), np.eye(8), atol=1e-10)
    assert np.max(mac(phi, phi) - np.eye(8)) > 1e-3        # plain MAC sees the mass-weighted shapes as coupled


def test_pairing_finds_the_permutation_and_lists_unpaired():
    rng = np.random.default_rng(4)
    phi = rng.standard_normal((30, 6))
    perm = [2, 0, 1, 5, 3]                                    # measured i = computed perm[i]
    meas = phi[:, perm] + 0.05 * rng.standard_normal((30, 5))
    fc = np.array([100.0, 150.0, 200.0, 260.0, 300.0, 333.0])
    p = pair_modes(mac(meas, phi), fc[perm] * 1.02, fc, threshold=0.8)
    assert [(q.measured, q.computed) for q in p.pairs] == list(enumerate(perm))
    assert p.unpaired_computed == [4] and p.unpaired_measured == []
    assert all(abs(q.error + 0.02 / 1.02) < 1e-12 for q in p.pairs)


def test_pairing_threshold_drops_weak_pairs():
    m = np.array([[0.95, 0.1], [0.2, 0.3]])
    p = pair_modes(m, [100.0, 200.0], [101.0, 190.0], threshold=0.6)
    assert [(q.measured, q.computed) for q in p.pairs] == [(0, 0)]
    assert p.unpaired_measured == [1] and p.unpaired_computed == [1]


def test_mismatched_channels_is_input_error():
    with pytest.raises(InputError, match="channels"):
        mac(np.ones((3, 2)), np.ones((4, 2)))


def test_frac_and_png(tmp_path):
    f = np.linspace(10, 100, 50)
    h = 1.0 / (50.0 ** 2 - f ** 2 + 20j * f)
    assert frac(h, 3j * h) == pytest.approx(1.0, abs=1e-12)
    assert frac(h, 1.0 / (70.0 ** 2 - f ** 2 + 20j * f)) < 0.5
    m = np.eye(3)
    path = mac_png(m, tmp_path / "mac.png", [1, 2, 3], [1, 2, 3], pair_modes(m, [1, 2, 3], [1, 2, 3]))
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
