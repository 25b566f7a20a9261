"""Thesis Sec. 4.6: SKF 6312 / 6215 under 4000 N axial + 10000 N radial, against the printed matrices.

The internal geometry behind the printed matrices is not published (groove curvature, clearance, K_n), so the
check is: every printed entry that carries stiffness (|k| >= 1e5 in SI) has our sign and lies within a factor 3;
the entries the thesis prints as zero (pinion, 8 balls symmetric about the load) are zero to round-off, and
the small asymmetry terms of the 11-ball wheel bearing stay below 1 % of the diagonal."""
import numpy as np
import pytest

from housingfe.verification.bearing_rows import comparison_rows, printed_matrices, section_4_6


def test_printed_entries_sign_and_magnitude():
    rows = [r for r in comparison_rows() if abs(r[2]) >= 1e5]
    assert len(rows) == 17          # 8 pinion + 9 wheel entries
    for shaft, entry, printed, ours, ratio in rows:
        assert 1 / 3 < ratio < 3, (shaft, entry, printed, ours)


def test_zero_and_small_entries():
    ours = section_4_6()
    printed = printed_matrices()
    pin = ours["pinion"]
    zero = (printed["pinion"] == 0) & ~np.isnan(printed["pinion"])
    assert np.max(np.abs(pin[zero][:-1])) < 1e-9 * np.max(np.abs(pin))   # (5,5) is lost in print, (6,6) is 0
    wheel = ours["wheel"]
    scale = np.sqrt(np.outer(np.diag(wheel), np.diag(wheel)))[:5, :5]
    small = np.abs(printed["wheel"][:5, :5]) < 1e5
    assert np.all(np.abs(wheel[:5, :5][small]) < 1e-2 * scale[small])


def test_free_tilt_flips_the_printed_coupling_signs():
    # why the tilt is held: with Mx = My = 0 the ring tilts and k_yz, k_z,theta_x change sign
    free = {r[:2]: r[4] for r in comparison_rows(fixed_tilt=False)}
    assert free[("pinion", "k_y,z")] < 0 and free[("pinion", "k_z,theta_x")] < 0
    assert free[("pinion", "k_x,x")] == pytest.approx(0.85, abs=0.1)


def test_published_rows_for_validate():
    from housingfe.verification.bearing_rows import published_rows

    rows = published_rows()
    assert len(rows) == 23 + 4
    units = {r["quantity"].split()[-1]: r["unit"] for r in rows if "Sec. 4.6" in r["quantity"]}
    assert units["k_x,x"] == "N/m" and units["k_x,theta_y"] == "N/rad" and units["k_theta_x,theta_x"] == "N m/rad"
    assert all(r["source"].startswith("van Roosmalen 1994") for r in rows)
