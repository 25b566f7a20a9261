"""A transmission error from a file (housingfe.source.transmission_error) as the source's excitation."""
import math

import numpy as np
import pytest

from housingfe.errors import InputError
from housingfe.levels import OMEGA0, level
from housingfe.source import transmission_error as tem
from housingfe.source.roosmalen import dynamics as dyn
from housingfe.source.roosmalen.operating import SourceModel


def _file(tmp_path, text, name="te.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_samples_are_the_cosine_series_the_file_states_and_harmonics_of_inverts_them(tmp_path):
    te = tem.read(_file(tmp_path, "# a comment\ntorque_Nm,harmonic,amplitude_um,phase_deg\n"
                                  "100,1,2.0,30\n100,3,0.5,-90\n"))
    t = np.arange(64) / 64
    expected = 2e-6 * np.cos(2 * np.pi * t + math.radians(30)) + 0.5e-6 * np.cos(6 * np.pi * t - math.pi / 2)
    e = te.samples(100.0, 64)
    assert np.max(np.abs(e - expected)) < 1e-18
    a = tem.harmonics_of(e, 4)
    assert np.allclose(a, [2e-6 * np.exp(1j * math.radians(30)), 0, 0.5e-6 * np.exp(-0.5j * math.pi), 0], atol=1e-18)


def test_write_then_read_gives_the_same_amplitudes_and_units_convert(tmp_path):
    a = np.array([[1.5e-6 * np.exp(0.3j), 0.2e-6 * np.exp(-2.0j)], [3.0e-6 * np.exp(1.1j), 0.1e-6]])
    tem.write(tmp_path / "w.csv", [1000.0, 2000.0], [1, 2], a, comment="test")
    te = tem.read(tmp_path / "w.csv")
    assert te.torques.tolist() == [1000.0, 2000.0] and te.harmonics.tolist() == [1, 2]
    assert np.allclose(te.amplitudes, a, rtol=1e-7, atol=1e-15)
    mm = tem.read(_file(tmp_path, "torque_Nm,harmonic,amplitude_mm,phase_rad\n50,1,0.002,0.5\n", "mm.csv"))
    assert np.isclose(mm.amplitudes[0, 0], 2e-6 * np.exp(0.5j))
    no_phase = tem.read(_file(tmp_path, "harmonic,torque_Nm,amplitude_m\n1,50,1e-6\n", "p.csv"))
    assert no_phase.amplitudes[0, 0] == 1e-6


def test_torques_between_the_files_are_interpolated_and_outside_refused(tmp_path):
    te = tem.read(_file(tmp_path, "torque_Nm,harmonic,amplitude_um,phase_deg\n"
                                  "1000,1,1.0,0\n3000,1,3.0,90\n"))
    assert np.isclose(te.at(2000.0)[0], 0.5e-6 + 1.5e-6j)
    assert np.isclose(te.at(1000.0)[0], 1e-6) and np.isclose(te.at(3000.0)[0], 3e-6j)
    for torque in (999.0, 3000.5):
        with pytest.raises(InputError, match=r"te\.csv: has no transmission error at .* N m \(it gives 1000\.\.3000"):
            te.at(torque)
    single = tem.read(_file(tmp_path, "torque_Nm,harmonic,amplitude_um\n2000,1,1.0\n", "one.csv"))
    assert single.at(2000.0 * (1 + 1e-12))[0] == 1e-6
    with pytest.raises(InputError, match="it gives 2000 N m"):
        single.at(2100.0)


@pytest.mark.parametrize("text, message", [
    ("torque_Nm,harmonic,amplitude_um,phase\n2000,1,1,0\n", r"line 1: unknown column 'phase'"),
    ("torque_Nm,amplitude_um\n2000,1\n", r"no column 'harmonic'"),
    ("torque_Nm,harmonic,amplitude_um,amplitude_mm\n2000,1,1,1\n", "exactly one amplitude column"),
    ("torque_Nm,harmonic,amplitude_um\n2000,1,-1\n", r"line 2: amplitude_um: -1 is negative"),
    ("torque_Nm,harmonic,amplitude_um\n2000,0,1\n", r"line 2: harmonic: 0 is not a harmonic number"),
    ("torque_Nm,harmonic,amplitude_um\n2000,1.5,1\n", r"harmonic: 1.5 is not"),
    ("torque_Nm,harmonic,amplitude_um\n-5,1,1\n", r"torque_Nm: -5 is not a positive torque"),
    ("torque_Nm,harmonic,amplitude_um\n2000,1,1\n2000,1,2\n", r"line 3: harmonic 1 at 2000 N m is given twice"),
    ("torque_Nm,harmonic,amplitude_um\n2000,1,1\n\n# gap\n1000,2,1\n", "every torque must list the same harmonics"),
    ("torque_Nm,harmonic,amplitude_um\n2000,1,abc\n", r"amplitude_um: 'abc' is not a number"),
    ("torque_Nm,harmonic,amplitude_um\n2000,1,nan\n", "is not a finite number"),
    ("torque_Nm,harmonic,amplitude_um\n2000,1\n", r"line 2: 2 values for 3 columns"),
    ("torque_Nm,harmonic,amplitude_m\n2000,1,2.5\n", r"implausible .* check the unit in the column name"),
    ("# only a comment\n", "no rows"),
    ("torque_Nm,harmonic,amplitude_um\n", "no rows after the header"),
    # above the source's 256 samples per mesh period: refused by the source after meshing; 1e300 an OverflowError
    ("torque_Nm,harmonic,amplitude_um\n2000,128,1\n", r"line 2: harmonic: 128 is above the highest harmonic the "
                                                      r"source resolves \(127"),
    ("torque_Nm,harmonic,amplitude_um\n2000,1e300,1\n", r"line 2: harmonic: 1e\+300 is above"),
])
def test_a_bad_file_is_one_message_naming_the_file_and_line(tmp_path, text, message):
    path = _file(tmp_path, text)
    with pytest.raises(InputError, match=message) as info:
        tem.read(path)
    assert str(info.value).startswith(f"{path}:")


def test_a_missing_or_binary_file_is_named(tmp_path):
    with pytest.raises(InputError, match=r"nothing\.csv: cannot read the transmission error file"):
        tem.read(tmp_path / "nothing.csv")
    (tmp_path / "bin.csv").write_bytes(b"\xff\xfe\x00\x81")
    with pytest.raises(InputError, match=r"bin\.csv: cannot read"):
        tem.read(tmp_path / "bin.csv")


def test_the_shock_from_a_te_has_that_te_as_its_quasi_static_compression():
    t = np.arange(256) / 256
    S = 1.0e9 * (1 + 0.05 * np.cos(2 * np.pi * t) + 0.02 * np.sin(6 * np.pi * t))
    e = 1e-6 * np.cos(2 * np.pi * t + 0.4) + 0.3e-6 * np.sin(4 * np.pi * t)
    F = 4.0e4
    shock = dyn.engagement_force_from_transmission_error(S, F, e)
    d = dyn.quasi_static_compression(S, shock, F)
    assert np.max(np.abs(d - d.mean() - e)) < 1e-18
    assert np.isclose(d.mean(), np.mean(F / S), rtol=1e-12)


@pytest.fixture(scope="module")
def gearset_a():
    return SourceModel.from_scene("gearset-A")


def test_the_models_own_te_through_a_file_gives_the_models_l_omega(gearset_a, tmp_path):
    """The source with the quasi-static TE of its own engagement model, written and read back, is the same source:
    the construction loses only the harmonics above those written (60 of 256 samples)."""
    a = gearset_a.quasi_static_transmission_error(2000.0, 60)
    assert 0.3e-6 < abs(a[0]) < 1.0e-6             # the face-width model's ~0.56 um (docs/source.md)
    tem.write(tmp_path / "own.csv", [2000.0], range(1, 61), [a])
    from_file = SourceModel.from_scene("gearset-A")
    from_file.transmission_error = tem.read(tmp_path / "own.csv")
    for rpm in (500.0, 1000.0, 1500.0):
        ours, theirs = gearset_a.operating_point(rpm, 2000.0), from_file.operating_point(rpm, 2000.0)
        assert abs(ours.L_omega_tooth_band - theirs.L_omega_tooth_band) < 1e-4
        assert np.max(np.abs(ours.L_omega - theirs.L_omega)) < 0.01
    assert from_file.overlap_note(2000.0) is None          # the file's TE is not at the helix's cancellation


def test_a_one_micrometre_te_gives_the_mean_stiffness_receptances_l_omega(gearset_a, tmp_path):
    """A pure tooth-frequency TE of 1 um: the wheel's L_omega at the tooth line is that of the mean-stiffness lumped
    system loaded by k_m e along the mesh normal (the first-order solve), to the stiffness ripple's coupling of
    harmonics (measured: < 0.004 dB); independent of the source's harmonic balance."""
    src = SourceModel.from_scene("gearset-A")
    src.transmission_error = tem.read(_file(tmp_path, "torque_Nm,harmonic,amplitude_um\n2000,1,1.0\n"))
    op = src._point(2000.0)
    mats = op.mats
    km, h = mats.mean_mesh_stiffness, mats.h
    K = mats.K0 + km * np.outer(h, h)
    for rpm in (500.0, 1000.0, 1500.0):
        w = 2 * math.pi * src.pair.tooth_frequency(rpm)
        q = np.linalg.solve(K - w ** 2 * mats.M + 1j * w * mats.D, h * km * 1e-6)
        expected = level(abs(w * q[dyn.WHEEL_THETA_Z]) ** 2 / 2, OMEGA0)
        ours = src.operating_point(rpm, 2000.0).L_omega[0]
        assert abs(ours - expected) < 0.05, (rpm, ours, expected)


def test_a_source_scene_takes_the_file_beside_it_and_refuses_torques_outside_it(tmp_path):
    """[source] transmission_error: relative to the scene file; source.torque_Nm and torque_run_Nm must lie within
    the file's torques; SourceModel.from_scene drives the source with it (the model's own TE fed back: the same
    tooth-band L_omega)."""
    from pathlib import Path

    import housingfe

    text = (Path(housingfe.__file__).parent / "scenes" / "gearset-A.toml").read_text()
    own = SourceModel.from_scene("gearset-A")
    tem.write(tmp_path / "te.csv", [2000.0], range(1, 61), [own.quasi_static_transmission_error(2000.0, 60)])
    scene = tmp_path / "a.toml"
    scene.write_text(text.replace("[source]\n", '[source]\ntransmission_error = "te.csv"\n', 1))
    with pytest.raises(InputError, match=r"a.toml: source.transmission_error: .*te.csv: has no transmission error at "
                                         r"400 N m .*\(torque_run_Nm; set it within the file's torques\)"):
        SourceModel.from_scene(str(scene))
    scene.write_text(text.replace("[source]\n", '[source]\ntransmission_error = "te.csv"\n', 1)
                     .replace("torque_run_Nm = [400.0, 800.0, 1200.0, 1600.0, 2000.0]", "torque_run_Nm = [2000.0]"))
    from_file = SourceModel.from_scene(str(scene))
    assert from_file.transmission_error is not None and from_file.transmission_error.source.endswith("te.csv")
    for rpm in (500.0, 1500.0):
        assert abs(from_file.operating_point(rpm, 2000.0).L_omega_tooth_band
                   - own.operating_point(rpm, 2000.0).L_omega_tooth_band) < 1e-4
    scene.write_text(text.replace("[source]\n", '[source]\ntransmission_error = "te.csv"\nengagement = "thesis-2d"\n', 1)
                     .replace("torque_run_Nm = [400.0, 800.0, 1200.0, 1600.0, 2000.0]", "torque_run_Nm = [2000.0]"))
    with pytest.raises(InputError, match="the file replaces the engagement model"):
        SourceModel.from_scene(str(scene))


def test_a_source_scene_refuses_a_file_whose_harmonics_all_lie_above_its_harmonic_balance(tmp_path):
    """source.harmonics = 30 keeps the shock's harmonics 1..30: a file of harmonic 31 alone excited nothing (it ran to
    a result, L_omega of the stiffness ripple alone); 30 is the last one that acts, and 127 the last one read."""
    from pathlib import Path

    import housingfe

    text = (Path(housingfe.__file__).parent / "scenes" / "gearset-A.toml").read_text()
    scene = tmp_path / "a.toml"
    scene.write_text(text.replace("[source]\n", '[source]\ntransmission_error = "te.csv"\n', 1)
                     .replace("torque_run_Nm = [400.0, 800.0, 1200.0, 1600.0, 2000.0]", "torque_run_Nm = [2000.0]"))
    assert "harmonics = 30\n" in text
    _file(tmp_path, "torque_Nm,harmonic,amplitude_um\n2000,31,0.5\n")
    with pytest.raises(InputError, match=r"a.toml: source.transmission_error: .*te.csv: its lowest harmonic 31 is "
                                         r"above harmonics = 30"):
        SourceModel.from_scene(str(scene))
    _file(tmp_path, "torque_Nm,harmonic,amplitude_um\n2000,30,0.5\n2000,127,0.1\n")
    assert SourceModel.from_scene(str(scene)).transmission_error.harmonics.tolist() == [30, 127]


def test_with_a_te_at_one_torque_the_other_torques_points_are_dropped_not_an_error(gearset_a):
    """A source whose operating points were computed at 1000 and 2000 N m, driven by a TE given at 2000 N m only (as
    runup.te_sensitivity does per torque of a multi-torque run-up): 2000 N m works, 1000 N m is the TE's error."""
    gearset_a.prepared([1000.0, 2000.0])
    unit = tem.TransmissionError(np.array([2000.0]), np.array([1]), np.array([[1e-6 + 0j]]), source="unit")
    driven = gearset_a.with_transmission_error(unit)
    assert np.isfinite(driven.operating_point(500.0, 2000.0).L_omega_tooth_band)
    with pytest.raises(InputError, match="unit: has no transmission error at 1000 N m"):
        driven.operating_point(500.0, 1000.0)
