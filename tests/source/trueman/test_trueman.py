"""Trueman (1974) drive: published critical speeds, analytic TE cases, consistency of the global solve."""
from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from housingfe.errors import InputError
from housingfe.source.trueman import data
from housingfe.source.trueman import response as tr
from housingfe.source.trueman import run as trueman_run

INCH = data.INCH


def _rel(ours, published):
    return np.abs(np.asarray(ours) - np.asarray(published)) / np.asarray(published)


# ------------------------------------------------------------------ Table 6.1 and Sec. 6.9.1
TABLE_CASES = [
    ("standard A, solid gears", {}),
    ("type B", {"machine_type": "B", "bushed": True}),
    ("C with bushed gears", {"bushed": True}),
    ("A with 1/2 in drawshafts", {"drawshaft_mid_diameter": 0.5 * INCH}),
    ("A with drawroll inertia -50 %", {"drawroll_inertia_factor": 0.5}),
    ("A with coupling flexibility x100", {"coupling_flexibility_factor": 100.0}),
]


@pytest.mark.parametrize("name, kwargs", TABLE_CASES)
def test_table_6_1_critical_speeds_within_one_percent(name, kwargs):
    ours = tr.critical_speeds(tr.DriveConfig(name=name, **kwargs), count=5, max_rpm=6000)
    assert len(ours) == 5
    assert _rel(ours, data.TABLE_6_1_RPM[name]).max() < 0.01


def test_rig_single_critical_speed_2070():
    cfg = tr.DriveConfig(name="rig", boxes=4, drive="vs_drive")
    ours = tr.critical_speeds(cfg, count=5, max_rpm=4000, scan_step_rpm=100)
    assert len(ours) == 1                      # "only one critical speed in 0 - 4000 r.p.m."
    assert abs(ours[0] - 2070) / 2070 < 0.01


def test_critical_speeds_converged_in_drawshaft_elements():
    coarse = tr.critical_speeds(tr.DriveConfig(elements_per_section=3), count=5)
    fine = tr.critical_speeds(tr.DriveConfig(elements_per_section=12), count=5)
    assert _rel(coarse, fine).max() < 1e-3


# ------------------------------------------------------------------ two-inertia TE case
def _two_inertia(j1, j2, k, c=0.0):
    K = sp.csr_matrix(np.array([[k, -k], [-k, k]]))
    C = sp.csr_matrix(np.array([[c, -c], [-c, c]]))
    M = sp.csr_matrix(np.diag([j1, j2]))
    return tr.DriveModel(K=K, C=C, M=M, mesh_dofs=np.array([[0, 1]]), mesh_stiffness=np.array([k]),
                         mesh_damping=np.array([c]), mesh_labels=[(1, 1)])


def test_two_inertia_resonance_and_mesh_torque():
    j1, j2, k, e = 0.002, 0.0015, 1.7e5, 2e-3
    model = _two_inertia(j1, j2, k)
    wn = math.sqrt(k * (1 / j1 + 1 / j2))
    assert tr.natural_frequencies(model, 1)[0] == pytest.approx(wn, rel=1e-9)
    for w in (0.1 * wn, 0.9 * wn, 1.1 * wn, 5 * wn):
        analytic = k * e * w**2 / (wn**2 - w**2)        # T = k(theta1 - theta2 - e)
        assert tr.mesh_transfer(model, w)[0, 0] * e == pytest.approx(analytic, rel=1e-9)


def test_rigidly_held_gears_carry_k_times_te():
    k, e = 1.7e5, 2e-3
    model = _two_inertia(1e12, 1e12, k)                 # gears held by enormous inertias
    assert abs(tr.mesh_transfer(model, 300.0)[0, 0] * e) == pytest.approx(k * e, rel=1e-6)
    # the receptance form (eq. 5.6a) with zero gear receptances gives the same
    assert abs(tr.mesh_torque_from_receptances(e, 0.0, 0.0, k, 0.0, 300.0)) == pytest.approx(k * e)


def test_thesis_propagation_step_is_not_physical():
    """Layshaft inertia J_L --crossed mesh k_c-- massless bronze gear --mesh k_m (TE)-- steel inertia J_S.
    Analytic: the crossed-mesh torque equals the mesh torque (massless gear),
    T = k_eq e w^2 / (w_n^2 - w^2), k_eq = k_c k_m / (k_c + k_m), w_n^2 = k_eq (1/J_L + 1/J_S).
    The thesis's listing instead injects theta_B = T_D / K4 (K4 = mesh in series with the steel side)
    into the layshaft branch: T_c = K196 theta_B with K196 = k_c in series with the layshaft side."""
    jl, js, kc, km, e = 0.02, 0.00175, 1.74e5, 1.74e5, 2.1e-3
    K = sp.csr_matrix(np.array([[kc, -kc, 0], [-kc, kc + km, -km], [0, -km, km]]))
    M = sp.csr_matrix(np.diag([jl, 0.0, js]))
    model = tr.DriveModel(K=K, C=sp.csr_matrix((3, 3)), M=M, mesh_dofs=np.array([[1, 2]]),
                          mesh_stiffness=np.array([km]), mesh_damping=np.array([0.0]))
    keq = kc * km / (kc + km)
    wn = math.sqrt(keq * (1 / jl + 1 / js))
    for w in (0.05 * wn, 0.3 * wn, 2.0 * wn):
        analytic = keq * e * w**2 / (wn**2 - w**2)
        # global solve: mesh torque, and crossed-mesh torque from the displacements
        rhs = np.array([0.0, km * e, -km * e], dtype=complex)
        x = np.linalg.solve((K - w**2 * M).toarray(), rhs)
        t_mesh = km * (x[1] - x[2] - e)
        t_crossed = kc * (x[0] - x[1])
        assert t_mesh == pytest.approx(analytic, rel=1e-9)
        assert tr.mesh_transfer(model, w)[0, 0] * e == pytest.approx(analytic, rel=1e-9)
        assert t_crossed == pytest.approx(analytic, rel=1e-9)
        # eq. 5.6a direct term (receptances of each gear side without the mesh) is exact too
        h_bronze = 1.0 / kc + 1.0 / (-w**2 * jl)          # bronze root looking into the layshaft
        h_steel = 1.0 / (-w**2 * js)
        assert tr.mesh_torque_from_receptances(e, h_bronze, h_steel, km, 0.0, w) == pytest.approx(analytic)
        # the thesis's propagation step
        k4 = 1.0 / (1.0 / km + h_steel)
        k196 = 1.0 / (1.0 / kc + 1.0 / (-w**2 * jl))
        t_thesis = k196 * (analytic / k4)
        if w < wn:
            assert abs(t_thesis) > 3.0 * abs(analytic)     # inflated: tends to (J_L / J_S) T at low speed
    # the library's factor K_B / K_4 (global model, mesh removed) is the same scaling
    w = 0.3 * wn
    k4 = 1.0 / (1.0 / km + 1.0 / (-w**2 * js))
    k196 = 1.0 / (1.0 / kc + 1.0 / (-w**2 * jl))
    assert tr.thesis_propagation_factors(model, w)[0] == pytest.approx(k196 / k4, rel=1e-9)
    low = 0.05 * wn
    k4 = 1.0 / (1.0 / km + 1.0 / (-low**2 * js))
    k196 = 1.0 / (1.0 / kc + 1.0 / (-low**2 * jl))
    assert abs(k196 / k4) == pytest.approx(jl / js, rel=0.02)


# ------------------------------------------------------------------ receptance form == global solve
def test_receptance_formula_equals_global_solve_in_full_machine():
    cfg = tr.DriveConfig(boxes=3)
    model = tr.build_drive(cfg)
    w = float(tr.rpm_to_omega(2355.0))
    H = tr.mesh_transfer(model, w)
    j = 7                                              # box 2, position 2
    a, b = model.mesh_dofs[j]
    km, cm = model.mesh_stiffness[j], model.mesh_damping[j]
    kbar = km + 1j * w * cm
    z = model.dynamic_stiffness(w).toarray()
    z[a, a] -= kbar
    z[b, b] -= kbar
    z[a, b] += kbar
    z[b, a] += kbar
    unit = np.zeros((model.n_dof, 2), dtype=complex)
    unit[a, 0] = unit[b, 1] = 1.0
    h = np.linalg.solve(z, unit)
    t = tr.mesh_torque_from_receptances(1.0, h[a, 0], h[b, 1], km, cm, w, h_ab=h[a, 1])
    assert t == pytest.approx(H[j, j], rel=1e-8)
    # and a direct dense solve of the same assembled system with all meshes excited at once
    te = tr.random_te(1, len(model.mesh_dofs), seed=3)[0]
    rhs = np.zeros(model.n_dof, dtype=complex)
    kb = model.mesh_stiffness + 1j * w * model.mesh_damping
    np.add.at(rhs, model.mesh_dofs[:, 0], kb * te)
    np.add.at(rhs, model.mesh_dofs[:, 1], -kb * te)
    x = np.linalg.solve(model.dynamic_stiffness(w).toarray(), rhs)
    direct = kb * (x[model.mesh_dofs[:, 0]] - x[model.mesh_dofs[:, 1]] - te)
    np.testing.assert_allclose(H @ te, direct, rtol=1e-8, atol=1e-12 * np.abs(direct).max())


# ------------------------------------------------------------------ distributed drawshaft
def test_fe_drawshaft_matches_exact_distributed_shaft():
    """Gear-end dynamic stiffness of one drawshaft + drawroll: FE chain vs. three exact transfers."""
    d = data.to_si("A")
    w = float(tr.rpm_to_omega(4000.0)) * 20            # well above the running range, where FE errors show
    k = -w**2 * d["drawroll_inertia"] + 1j * w * d["damping"]["drawroll"]
    for length, dia in reversed(d["drawshaft_sections"]):
        k = tr.shaft_end_stiffness(k, w, length, dia, d["shear_modulus"], d["density"])
    # FE: condense a chain gear(0) ... drawroll
    from housingfe.source.trueman.model import _Assembler
    asm = _Assembler()
    start = gear = asm.node()
    for length, dia in d["drawshaft_sections"]:
        start = asm.shaft(start, length, dia, 40, d["shear_modulus"], d["density"])
    asm.m.append((start, start, d["drawroll_inertia"]))
    asm.c.append((start, start, d["damping"]["drawroll"]))
    K, C, M = (m.toarray() for m in asm.matrices())
    z = K + 1j * w * C - w**2 * M
    f = np.zeros(z.shape[0], dtype=complex)
    f[gear] = 1.0
    k_fe = 1.0 / np.linalg.solve(z, f)[gear]
    assert k_fe == pytest.approx(k, rel=1e-3)


# ------------------------------------------------------------------ Monte-Carlo reproducibility
def test_random_te_reproducible_and_bounded():
    a = tr.random_te(100, 60, seed=42)
    b = tr.random_te(100, 60, seed=42)
    c = tr.random_te(100, 60, seed=43)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)
    assert np.abs(a).max() <= data.TE_AMPLITUDE_MAX_RAD
    # uniform amplitude on [0, ERR): mean ERR/2 within 4 standard errors
    assert abs(np.abs(a).mean() - data.TE_AMPLITUDE_MAX_RAD / 2) < 4 * data.TE_AMPLITUDE_MAX_RAD / math.sqrt(
        12 * a.size)


def test_monte_carlo_envelopes_identical_for_same_seed():
    cfg = tr.DriveConfig(boxes=2)
    rpm = [1500.0, 2355.0]
    te = tr.random_te(20, 12, seed=7)
    e1 = tr.mesh_load_envelopes(cfg, rpm, te)
    e2 = tr.mesh_load_envelopes(cfg, rpm, tr.random_te(20, 12, seed=7))
    for key in ("min", "mean", "max"):
        assert np.array_equal(e1[key], e2[key])
    assert np.all(e1["min"] <= e1["mean"]) and np.all(e1["mean"] <= e1["max"])


def test_bad_configuration_raises_input_error():
    with pytest.raises(InputError, match="machine_type"):
        tr.DriveConfig(machine_type="Z")
    with pytest.raises(InputError, match="coupling_flexibility_factor"):
        tr.DriveConfig(coupling_flexibility_factor=-1.0)


# ------------------------------------------------------------------ geometry, scenes
def test_table_2_1_pitch_diameters_from_shared_gear_geometry():
    from housingfe.source.gears import GearPair

    for teeth, published_in in ((29, 3.4177), (25, 2.9463), (20, 2.3570)):
        helix = math.radians(45.0)
        pair = GearPair(module=INCH / 12, teeth=(teeth, 20), pressure_angle=math.radians(20), helix_angle=helix,
                        profile_shift=(0.0, 0.0), face_width=(0.02, 0.02),
                        centre_distance=(teeth + 20) / 2 * INCH / 12 / math.cos(helix))
        assert pair.pitch_diameter[0] / INCH == pytest.approx(published_in, abs=6e-5)


def _load_scene(name):
    import tomllib
    from pathlib import Path

    path = Path(tr.__file__).parents[2] / "scenes" / f"{name}.toml"
    return tomllib.loads(path.read_text()), str(path)


def test_run_scene_type_b_writes_critical_speeds_and_envelopes(tmp_path):
    import csv
    import json

    scene, path = _load_scene("trueman-type-b")
    scene["forced"]["speeds"] = 7            # keep the test fast
    scene["forced"]["machines"] = 10
    trueman_run.run_scene(scene, path, tmp_path)
    crit = json.loads((tmp_path / "critical_speeds.json").read_text())
    assert _rel(crit["type B"], data.TABLE_6_1_RPM["type B"]).max() < 0.01
    rows = list(csv.DictReader(io.StringIO((tmp_path / "mesh_load_envelopes.csv").read_text())))
    assert len(rows) == 7 * 60
    for r in rows:
        assert float(r["min_Nm"]) <= float(r["mean_Nm"]) <= float(r["max_Nm"])
    # every separation flag really has a dynamic torque above the mean transmitted torque
    flags = list(csv.DictReader(io.StringIO((tmp_path / "separation_flags.csv").read_text())))
    for r in flags:
        assert float(r["max_dynamic_Nm"]) > float(r["mean_transmitted_Nm"])
        assert int(r["machines_exceeding"]) >= 1
    # ... and no operating point above the mean torque is missed
    limit = scene["forced"]["mean_mesh_torque_Nm"]
    assert len(flags) == sum(float(r["max_Nm"]) > limit for r in rows)
    assert len(flags) > 0                    # Type B at 1000-4000 r.p.m. separates somewhere (5 lbf in)
    assert (tmp_path / "mesh_load_envelopes.png").stat().st_size > 1000


@pytest.mark.parametrize("mutate, key", [
    (lambda s: s["machine"].update(typo=1), "machine.typo"),
    (lambda s: s["configurations"][0].update(drawroll_inertia_factor=-0.5), "drawroll_inertia_factor"),
    (lambda s: s["forced"].update(configuration="nope"), "configuration"),
])
def test_bad_scene_raises_input_error_naming_file_and_key(mutate, key):
    scene, path = _load_scene("trueman-type-b")
    mutate(scene)
    with pytest.raises(InputError, match=key) as info:
        trueman_run.run_scene(scene, path, Path("/nonexistent"))
    assert str(info.value).startswith(path)
