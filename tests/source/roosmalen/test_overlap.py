"""The envelope bound of the face-width excitation near an integer overlap ratio (housingfe.source.roosmalen.overlap,
issue 28) and the summary line that reports it.

Limits: the in-phase slice model (helix stagger zero) of a helical pair is the transverse-section shock (Eq. 2.62
with eps_alpha) sample by sample; for eps_beta = 0 the bound is the face-width model itself; for a uniform load
and constant S the face-width harmonics are transverse x |sinc(n eps_beta)| and the bound transverse x
min(1, 1/(pi n eps_beta)), so the bound lies above them, by 20 lg(envelope / |sinc|) near an integer."""
import math
import os
import subprocess
import sys
import tomllib
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import housingfe
import housingfe.errors
from housingfe.source.gears import GearPair
from housingfe.source.roosmalen import dynamics as dyn
from housingfe.source.roosmalen import overlap as ov
from housingfe.source.stiffness import Corrections

REF = tomllib.loads((Path(housingfe.__file__).parent / "data" / "roosmalen1994.toml").read_text())["gears"]
PAIR = GearPair.from_table(REF["single_helical"])
SET_A = Corrections.from_table(REF["profile_corrections"]["A"])
SCENES = Path(housingfe.__file__).parent / "scenes"
K_MEAN = 1.1e9
FORCE = 40e3
N = np.arange(1, 16)


def _spur_pair():
    table = dict(REF["single_helical"], helix_angle_deg=0.0, kind="spur")
    return GearPair.from_table({k: v for k, v in table.items() if k in (
        "module_mm", "teeth", "pressure_angle_deg", "helix_angle_deg", "addendum_modification", "face_width_mm",
        "centre_distance_mm", "addendum_coefficient", "dedendum_coefficient", "rack_tip_radius_factor", "kind")})


def _stiffness_wave(n=256, rel_amp=0.2):
    t = np.arange(n) / n
    return K_MEAN * (1 + rel_amp * np.cos(2 * math.pi * t) + 0.3 * rel_amp * np.sin(4 * math.pi * t))


def test_envelope_factor():
    assert np.array_equal(ov.envelope_factor(N, 0.0), np.ones(15))
    # eps_beta -> 0: the envelope is 1 for every n < 1 / (pi eps_beta)
    assert np.array_equal(ov.envelope_factor(N, 0.02), np.ones(15))
    np.testing.assert_allclose(ov.envelope_factor(N, 1.026), 1 / (math.pi * N * 1.026), rtol=1e-15)
    x = np.linspace(0.01, 20, 4001)          # it is the envelope: |sinc(x)| <= min(1, 1/(pi x)), touching it
    assert np.all(np.abs(np.sinc(x)) <= ov.envelope_factor(x, 1.0) + 1e-15)
    assert ov.envelope_factor(np.array([2.5]), 1.0)[0] == pytest.approx(abs(np.sinc(2.5)), rel=1e-12)


@pytest.mark.parametrize("load_share", [None, np.linspace(0.7, 1.3, 24)[None, :]])
def test_in_phase_slices_of_a_helical_pair_are_the_transverse_shock(load_share):
    """Zero helix stagger: every slice of a contact line sits at the same roll position, so with profile-only
    corrections (tip reliefs, the same at every w) the slices sum to one transverse pair of Eq. 2.62 with
    eps_alpha, sample by sample, for a time-varying S and any load share across the face."""
    S = _stiffness_wave()
    A = PAIR.path_of_contact[0]
    ref = dyn.engagement_force(PAIR, SET_A, S, FORCE, contact_ratio=PAIR.transverse_contact_ratio)
    ours = ov.in_phase_shock(PAIR, SET_A, S, FORCE, load_share=load_share, origin=A)
    np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-9 * np.ptp(ref))
    # and the helix (default stagger) does change it: the test can tell the two apart
    staggered = dyn.engagement_force_face_width(PAIR, SET_A, S, FORCE, load_share=load_share, origin=A)
    assert np.ptp(ref - staggered) > 0.3 * np.ptp(ref)


def test_spur_pair_bound_is_the_face_width_model():
    """eps_beta = 0: envelope 1 and no stagger to remove, so the bound equals the face-width excitation."""
    spur = _spur_pair()
    S = _stiffness_wave()
    shock = dyn.engagement_force_face_width(spur, SET_A, S, FORCE)
    b = ov.envelope_bound(spur, SET_A, S, FORCE, shock, harmonics=15)
    assert b.eps_beta == 0.0 and np.array_equal(b.envelope, np.ones(15))
    np.testing.assert_allclose(b.bound, b.face_width, rtol=0, atol=1e-9 * b.face_width[0])


@pytest.mark.parametrize("face_mm", [25.0, 62.0, 66.0, 85.0])
def test_bound_lies_above_the_uniform_face_width_amplitude(face_mm):
    """Uniform load, constant S: the face-width excitation is transverse x |sinc(n eps_beta)| and the bound
    transverse x min(1, 1/(pi n eps_beta)) (256 slices: 3e-4 of the tooth line, see test_dynamics)."""
    pair = replace(PAIR, face_width=(face_mm * 1e-3, face_mm * 1e-3))
    S = np.full(2048, K_MEAN)
    shock = dyn.engagement_force_face_width(pair, SET_A, S, FORCE)
    b = ov.envelope_bound(pair, SET_A, S, FORCE, shock, harmonics=15)
    transverse = ov.harmonic_amplitudes(dyn.engagement_force(pair, SET_A, S, FORCE,
                                                             contact_ratio=pair.transverse_contact_ratio), 15)
    tol = 2e-3 * transverse[0]
    # (the in-phase shock starts at roll position 0, Eq. 2.62 at A: the sampling grid differs by a fraction of a step)
    np.testing.assert_allclose(b.bound, transverse * ov.envelope_factor(N, pair.overlap_ratio), rtol=0, atol=tol)
    np.testing.assert_allclose(b.face_width, transverse * np.abs(np.sinc(N * pair.overlap_ratio)), rtol=0, atol=tol)
    assert np.all(b.bound >= b.face_width - tol)
    np.testing.assert_allclose(b.sinc, np.abs(np.sinc(N * pair.overlap_ratio)), rtol=1e-12)


def test_bound_near_an_integer_overlap_ratio_is_the_envelope_over_the_sinc():
    """eps_beta = 1.026 (set A's 62 mm), uniform load, constant S: at n = 1 the bound lies 20 lg(1/(pi eps_beta) /
    |sinc(eps_beta)|) = 21.9 dB above the face-width excitation."""
    pair = replace(PAIR, face_width=(0.062, 0.062))
    S = np.full(2048, K_MEAN)
    b = ov.envelope_bound(pair, SET_A, S, FORCE, dyn.engagement_force_face_width(pair, SET_A, S, FORCE))
    eps = pair.overlap_ratio
    expected = 20 * math.log10(1 / (math.pi * eps) / abs(math.sin(math.pi * eps) / (math.pi * eps)))
    assert b.above_dB[0] == pytest.approx(expected, abs=0.1)
    assert expected == pytest.approx(21.9, abs=0.1)


# ------------------------------------------------------------------ the engagement option "envelope-bound"
@pytest.mark.parametrize("load_share", [None, np.linspace(0.7, 1.3, 24)[None, :]])
def test_envelope_bound_engagement_has_the_bound_as_its_quasi_static_excitation(load_share):
    """Set A's gears and corrections (eps_beta 1.026), a time-varying S: the quasi-static excitation k_m (d - mean d)
    of engagement "envelope-bound" is, harmonic by harmonic, the documented bound (in-phase excitation x
    min(1, 1/(pi n eps_beta))), to rounding.  The scaled quantity is the compression, not the shock: scaling the
    in-phase shock's harmonics instead leaves F / S(t) unscaled and misses the bound by more than 1 dB at n = 1."""
    S = _stiffness_wave()
    shock = dyn.engagement_shock("envelope-bound", PAIR, SET_A, S, FORCE, load_share)
    face_width = dyn.engagement_shock("face-width", PAIR, SET_A, S, FORCE, load_share)
    b = ov.envelope_bound(PAIR, SET_A, S, FORCE, face_width, load_share, K_MEAN, harmonics=3)
    ours = ov.harmonic_amplitudes(ov.quasi_static_excitation(S, shock, FORCE, K_MEAN), 3)
    np.testing.assert_allclose(ours, b.bound, rtol=1e-12)
    assert np.all(b.above_dB > 5.0)                  # and it is not the face-width excitation
    # its mean compression is the in-phase model's (the static state is kept)
    flat = ov.in_phase_shock(PAIR, SET_A, S, FORCE, load_share)
    assert np.mean(dyn.quasi_static_compression(S, shock, FORCE)) == pytest.approx(
        np.mean(dyn.quasi_static_compression(S, flat, FORCE)), rel=1e-12)
    c = np.fft.rfft(flat)
    c[1:] *= ov.envelope_factor(np.arange(1, c.size), PAIR.overlap_ratio)
    shock_scaled = ov.harmonic_amplitudes(ov.quasi_static_excitation(S, np.fft.irfft(c, S.size), FORCE, K_MEAN), 1)
    assert abs(20 * math.log10(shock_scaled[0] / b.bound[0])) > 1.0


def test_envelope_bound_engagement_of_a_spur_pair_is_face_width():
    """eps_beta = 0: envelope 1, no stagger: the option is the face-width shock (to rounding)."""
    spur = _spur_pair()
    S = _stiffness_wave()
    share = np.linspace(0.8, 1.2, 16)[None, :]
    ref = dyn.engagement_shock("face-width", spur, SET_A, S, FORCE, share)
    ours = dyn.engagement_shock("envelope-bound", spur, SET_A, S, FORCE, share)
    np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-9 * np.ptp(ref))


def test_with_engagement_is_a_new_operating_point_with_that_engagement():
    """SourceModel.with_engagement reuses the stiffness curve, load share and matrices and recomputes F_e only: the
    same shock and steady state as a source built with that engagement (set A, a coarse stiffness curve)."""
    from housingfe.scenefile import read_scene_dict
    from housingfe.source.roosmalen import run as rs
    from housingfe.source.roosmalen.operating import SourceModel

    data, path = read_scene_dict(str(SCENES / "gearset-A.toml"))
    table = rs.parse(data, str(path))
    pair, corr, geometry, interior, model = rs.build(table, str(path))
    model = replace(model, n_slices=6)

    def source(engagement):
        return SourceModel(pair, corr, interior, geometry, mesh_model=model, stiffness_positions=6, harmonics=8,
                           engagement=engagement)

    default = source("face-width")
    default.operating_point(1000.0, 2000.0)
    other, fresh = default.with_engagement("envelope-bound"), source("envelope-bound")
    assert other.engagement == "envelope-bound" and default.engagement == "face-width"
    np.testing.assert_array_equal(other.mesh_stiffness(2000.0)[1], fresh.mesh_stiffness(2000.0)[1])
    np.testing.assert_array_equal(other.operating_point(1000.0, 2000.0).mesh_force,
                                  fresh.operating_point(1000.0, 2000.0).mesh_force)
    assert not np.array_equal(default.mesh_stiffness(2000.0)[1], other.mesh_stiffness(2000.0)[1])
    with pytest.raises(housingfe.errors.InputError, match="engagement: 'envelope-bund' is not one of"):
        default.with_engagement("envelope-bund")


def test_near_integer():
    assert ov.near_integer(1.026) and ov.near_integer(0.95) and ov.near_integer(2.08)
    assert not ov.near_integer(1.139) and not ov.near_integer(0.5) and not ov.near_integer(0.05)
    assert not ov.near_integer(0.0)


def test_no_note_for_spur_far_from_integer_or_thesis_2d():
    """The note is only for the face-width engagement at eps_beta within 0.1 of a non-zero integer (the point is
    not touched otherwise, so a bare namespace stands in for it)."""
    point = SimpleNamespace(engagement="face-width")
    assert ov.cancellation_note(_spur_pair(), SET_A, point) is None
    assert ov.cancellation_note(replace(PAIR, face_width=(0.045, 0.045)), SET_A, point) is None   # eps_beta 0.74
    near = replace(PAIR, face_width=(0.062, 0.062))
    assert ov.near_integer(near.overlap_ratio)
    assert ov.cancellation_note(near, SET_A, SimpleNamespace(engagement="thesis-2d")) is None


def _trimmed_scene(tmp_path: Path, name: str, extra: dict) -> Path:
    """gearset-A with 2 speeds, one torque and 16 stiffness positions (seconds), plus `extra` keys of [source]."""
    text = (SCENES / "gearset-A.toml").read_text()
    values = {"speed_steps": "2", "torque_run_Nm": "[2000.0]", "spectrum_speeds_rpm": "[1500.0]",
              "stiffness_positions": "16", **extra}
    for key, value in values.items():
        lines = [ln for ln in text.splitlines() if ln.startswith(f"{key} =")]
        if lines:
            text = text.replace(lines[0], f"{key} = {value}")
        else:
            text = text.replace("[source.gears]", f"{key} = {value}\n[source.gears]")
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return path


def _source(scene: Path, out: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    return subprocess.run([sys.executable, "-m", "housingfe", "source", str(scene), "--out", str(out)],
                          capture_output=True, text=True, env=env, timeout=300)


def test_source_summary_notes_the_cancellation_for_set_a_only(tmp_path):
    """`housingfe source` on set A (eps_beta 1.026, face-width): one NOTE line with |sinc(eps_beta)| and the bound's
    dB above the default, in the printed report and in summary.txt; with thesis-2d engagement no note."""
    out = tmp_path / "a"
    proc = _source(_trimmed_scene(tmp_path, "a", {}), out)
    assert proc.returncode == 0, proc.stderr
    summary = (out / "summary.txt").read_text()
    notes = [ln for ln in summary.splitlines() if ln.startswith("NOTE: overlap ratio")]
    assert len(notes) == 1 and notes[0] in proc.stdout
    eps = 62.0 * math.sin(math.radians(12.0)) / (math.pi * 4.0)          # Appendix F: b = 62 mm, beta 12, m_n 4
    assert f"overlap ratio {eps:.3f}" in notes[0]
    assert f"|sinc(eps_beta)| = {abs(math.sin(math.pi * eps)) / (math.pi * eps):.3f}" in notes[0]
    assert "Lachenmaier" in notes[0]
    above = float(notes[0].split("lies ")[1].split(" dB")[0])
    assert 0.0 < above < 20 * math.log10(1 / abs(math.sin(math.pi * eps)))   # above the default, under env/|sinc|
    out2 = tmp_path / "b"
    proc = _source(_trimmed_scene(tmp_path, "b", {"engagement": '"thesis-2d"'}), out2)
    assert proc.returncode == 0, proc.stderr
    assert "NOTE: overlap ratio" not in (out2 / "summary.txt").read_text() + proc.stdout
    # the bound as the engagement option: no note (it is not the default's cancellation), and the tooth band lies
    # above the default's (its excitation at n = 1 lies `above` dB higher)
    out3 = tmp_path / "c"
    proc = _source(_trimmed_scene(tmp_path, "c", {"engagement": '"envelope-bound"'}), out3)
    assert proc.returncode == 0, proc.stderr
    assert "NOTE: overlap ratio" not in (out3 / "summary.txt").read_text() + proc.stdout

    def tooth_band(folder):
        return [float(ln.split(",")[3]) for ln in (folder / "runup.csv").read_text().splitlines()[1:]]

    assert all(b > a + 5.0 for a, b in zip(tooth_band(out), tooth_band(out3)))
