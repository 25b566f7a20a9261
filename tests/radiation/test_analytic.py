"""Analytic radiators against textbook values (van Roosmalen 1994, eq. 4.6-4.10)."""
import numpy as np
import pytest
from scipy.special import spherical_jn, spherical_yn

from housingfe.errors import InputError
from housingfe.radiation import analytic


def test_sphere_sigma_half_at_ka_one():
    # eq. 4.9 at f = f_s (kR = 1)
    assert analytic.sphere_sigma(1.0) == pytest.approx(0.5, abs=1e-12)


def test_sphere_sigma_is_monopole_impedance():
    # sigma of a pulsating sphere = Re(z_0)/(rho c), z_0 = i rho c h0(ka)/h0'(ka) (spherical Hankel)
    ka = np.array([0.1, 0.3, 1.0, 2.0, 5.0])
    h = spherical_jn(0, ka) + 1j * spherical_yn(0, ka)
    dh = spherical_jn(0, ka, True) + 1j * spherical_yn(0, ka, True)
    assert analytic.sphere_sigma(ka) == pytest.approx((1j * h / dh).real, rel=1e-12)


def test_sphere_power_eq_4_6_one_db_below_max_at_twice_fs():
    # Sec. 4.7 property 2: at f = 2 f_s the power is 1.0 dB below 2 pi rho c R^2 v_R^2
    R, v = 0.2, 1e-3
    fs = analytic.sphere_transition_frequency(R)
    p = analytic.sphere_power(R, 2 * fs, velocity_peak_m_s=v)
    p_max = 2 * np.pi * analytic.AIR_DENSITY * analytic.SPEED_OF_SOUND * R**2 * v**2
    assert 10 * np.log10(p / p_max) == pytest.approx(-0.97, abs=0.01)


def test_sphere_power_rms_and_peak_conventions():
    # the same number read as rms carries twice the power of it read as peak (P ~ v^2, v_rms = v_peak/sqrt 2)
    R, v, f = 0.1, 2e-3, np.array([50.0, 500.0, 5000.0])
    as_rms = analytic.sphere_power(R, f, velocity_rms_m_s=v)
    as_peak = analytic.sphere_power(R, f, velocity_peak_m_s=v)
    assert as_peak == pytest.approx(as_rms / 2, rel=1e-12)
    assert analytic.sphere_power(R, f, velocity_peak_m_s=v * np.sqrt(2)) == pytest.approx(as_rms, rel=1e-12)


def test_sphere_power_is_the_breathing_sphere_field():
    # p(a) = rho c v_hat i ka / (1 + i ka) on a sphere of radius a (exp(+i omega t)); P = 1/2 Re(p v_hat*) 4 pi a^2
    rho, c, a, v_hat = 1.2, 344.0, 0.15, 3e-3
    f = np.array([20.0, 200.0, 364.99, 2000.0])
    ka = 2 * np.pi * f / c * a
    p_surface = rho * c * v_hat * 1j * ka / (1 + 1j * ka)
    P = 0.5 * (p_surface * np.conj(v_hat)).real * 4 * np.pi * a**2
    assert analytic.sphere_power(a, f, velocity_peak_m_s=v_hat, rho=rho, c=c) == pytest.approx(P, rel=1e-12)
    assert analytic.sphere_power(a, f, velocity_rms_m_s=v_hat / np.sqrt(2), rho=rho, c=c) == pytest.approx(
        P, rel=1e-12)


def test_sphere_power_needs_exactly_one_convention():
    with pytest.raises(InputError, match="velocity_rms_m_s"):
        analytic.sphere_power(0.1, 100.0)
    with pytest.raises(InputError, match="velocity_rms_m_s"):
        analytic.sphere_power(0.1, 100.0, velocity_rms_m_s=1.0, velocity_peak_m_s=1.0)
    with pytest.raises(TypeError):  # never positional: the convention must be named
        analytic.sphere_power(0.1, 1.0, 100.0)


def test_one_speed_of_sound_and_air_density():
    """c and rho of air are defined once (housingfe.levels, the thesis' symbols list); no module hard-codes
    another value as a default, an assignment or a keyword argument."""
    import ast
    from pathlib import Path

    import housingfe
    from housingfe import levels
    from housingfe.data import thesis

    table = thesis()
    assert levels.SPEED_OF_SOUND == table["references"]["c_air_m_per_s"] == 344.0
    assert levels.AIR_DENSITY == table["references"]["rho_air_kg_per_m3"] == 1.2
    assert analytic.SPEED_OF_SOUND is levels.SPEED_OF_SOUND and analytic.AIR_DENSITY is levels.AIR_DENSITY

    c_names = {"c", "c0", "c_air", "speed_of_sound", "sound_speed", "SPEED_OF_SOUND"}
    rho_names = {"rho", "rho_air", "rho0", "air_density", "AIR_DENSITY"}

    def suspicious(name, node):
        if not isinstance(node, ast.Constant) or not isinstance(node.value, (int, float)) \
                or isinstance(node.value, bool):
            return False
        return (name in c_names and 300 <= node.value <= 400) or (name in rho_names and 0.5 < node.value < 2)

    offenders = []
    root = Path(housingfe.__file__).parent
    for path in sorted(root.rglob("*.py")):
        if path.name == "levels.py" and path.parent == root:
            continue
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            pairs = []
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
                args = node.args
                positional = args.posonlyargs + args.args
                pairs += zip([a.arg for a in positional[len(positional) - len(args.defaults):]], args.defaults)
                pairs += [(a.arg, d) for a, d in zip(args.kwonlyargs, args.kw_defaults) if d is not None]
            elif isinstance(node, ast.Assign):
                pairs += [(t.id, node.value) for t in node.targets if isinstance(t, ast.Name)]
            elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name) and node.value:
                pairs.append((node.target.id, node.value))
            elif isinstance(node, ast.keyword) and node.arg:
                pairs.append((node.arg, node.value))
            offenders += [f"{path.relative_to(root)}:{v.lineno} {n} = {v.value}" for n, v in pairs
                          if suspicious(n, v)]
    assert not offenders, offenders


def test_piston_sigma_published_values():
    assert analytic.piston_sigma(2.0) == pytest.approx(1.033, abs=5e-4)
    # low-frequency limit (ka)^2/2 and high-frequency limit 1
    assert analytic.piston_sigma(0.01) == pytest.approx(0.5e-4, rel=1e-3)
    assert analytic.piston_sigma(0.0) == 0.0
    assert analytic.piston_sigma(200.0) == pytest.approx(1.0, abs=2e-3)


def test_piston_transition_frequency_equals_sphere_for_a_equal_R_sqrt2():
    # eq. 4.10: f_p = f_s when a = R sqrt(2)
    R = 0.1
    a = R * np.sqrt(2)
    assert analytic.piston_transition_frequency(np.pi * a**2) == pytest.approx(
        analytic.sphere_transition_frequency(R), rel=1e-12)


@pytest.mark.parametrize("E, rho, nu", [(210e9, 7850.0, 0.3), (70e9, 2700.0, 0.33)])
def test_plate_critical_frequency_matches_12_over_h_for_steel_and_aluminium(E, rho, nu):
    h = 0.008
    fc = analytic.plate_critical_frequency(h, E, rho, nu)
    assert fc == pytest.approx(12.0 / h, rel=0.02)


def test_plate_critical_frequency_other_material_differs_from_rule():
    # cast iron (E = 110 GPa, rho = 7200, nu = 0.26): f_c h = 16.1 m/s by hand, 34 % above the steel rule
    fc = analytic.plate_critical_frequency(0.01, 110e9, 7200.0, 0.26)
    assert fc * 0.01 == pytest.approx(16.1, abs=0.05)


def test_erp_is_rho_c_S_v2():
    assert analytic.equivalent_radiated_power(1e-6, 2.0, rho=1.2, c=340.0) == pytest.approx(8.16e-4)


@pytest.mark.parametrize("call", [
    lambda: analytic.sphere_power(-1.0, 100.0, velocity_rms_m_s=1.0),
    lambda: analytic.sphere_power(1.0, 100.0, velocity_peak_m_s=-1.0),
    lambda: analytic.plate_critical_frequency(0.0, 210e9, 7850, 0.3),
    lambda: analytic.plate_critical_frequency(0.01, 210e9, 7850, 0.6),
    lambda: analytic.piston_sigma(-1.0),
    lambda: analytic.equivalent_radiated_power(1.0, -2.0),
])
def test_non_physical_input_raises_input_error(call):
    with pytest.raises(InputError):
        call()


def test_sphere_modal_resistance_dipole_closed_form():
    ka = np.array([0.1, 0.5, 1.0, 2.0, 5.0])
    assert analytic.sphere_modal_resistance(1, ka) == pytest.approx(ka**4 / (4 + ka**4), rel=1e-10)


def test_sphere_cap_series_limits():
    ka = np.array([0.1, 1.0, 3.0, 5.0])
    # the whole sphere vibrating is the pulsating sphere (eq. 4.9)
    assert analytic.sphere_cap_sigma(ka, np.pi) == pytest.approx(analytic.sphere_sigma(ka), rel=1e-10)
    # kR << 1: a monopole of volume velocity v S_cap, sigma -> k^2 S_cap / (4 pi) (R = 1)
    theta0 = np.pi / 3
    s_cap = 2 * np.pi * (1 - np.cos(theta0))
    assert analytic.sphere_cap_sigma(0.01, theta0) == pytest.approx(0.01**2 * s_cap / (4 * np.pi), rel=1e-3)
    # a small cap at high frequency radiates like a baffled piston of the same area (sigma -> 1)
    assert analytic.sphere_cap_sigma(40.0, 0.2) == pytest.approx(1.0, abs=0.03)
