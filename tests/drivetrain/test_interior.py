"""The gearbox interior in housing scenes (housingfe.drivetrain.interior): interior-on-rigid-bores modes against beam
theory, mechanism counts, and the coupled forced response against the free gear train's analytic answer."""
import math

import numpy as np
import pytest

from housingfe.drivetrain.interior import CouplingSpec, rigid_bore_modes
from housingfe.drivetrain.shafts import CircularSection, RigidDisc
from housingfe.errors import InputError
from tests.conftest import load_scene

E, NU, RHO = 210e9, 0.3, 7850.0
L, D = 0.6, 0.04                 # a slender shaft (m): shear correction < 1 % on the first mode


def shaft_spec(extra=None, bearing_stiffness=1e12, spin=0.0):
    """One shaft along z on two stiff bearings at its ends (bores fixed)."""
    spec = {
        "bores": [{"name": "b0", "surface": "s0", "centre": [0, 0, 0], "axis": [0, 0, 1]},
                  {"name": "b1", "surface": "s1", "centre": [0, 0, L], "axis": [0, 0, 1]}],
        "shafts": [{"name": "s", "origin": [0, 0, 0], "axis": [0, 0, 1], "segments": [[L, D]],
                    "elements_per_segment": 24}],
        "bearings": [{"shaft_node": "s:0", "bore": "b0", "axis": [0, 0, 1],
                      "stiffness": [bearing_stiffness] * 3 + [0.0, 0.0, spin]},
                     {"shaft_node": "s:24", "bore": "b1", "axis": [0, 0, 1],
                      "stiffness": [bearing_stiffness] * 3 + [0.0, 0.0, spin]}],
    }
    spec.update(extra or {})
    return CouplingSpec.model_validate(spec)


CENTRES = {"b0": np.zeros(3), "b1": np.array([0.0, 0.0, L])}


def timoshenko_pinned(n: int) -> float:
    """Simply supported Timoshenko beam, bending mode n (Hz): rI rA/kGA w^4 - (rA + rI k^2 + EI rA k^2/kGA) w^2
    + EI k^4 = 0, k = n pi / L (lower root)."""
    sec = CircularSection(D)
    kn = n * math.pi / L
    EI, rA, rI = E * sec.second_moment, RHO * sec.area, RHO * sec.second_moment
    kGA = sec.shear_factor(NU) * E / (2 * (1 + NU)) * sec.area
    w2 = min(np.roots([rI * rA / kGA, -(rA + rI * kn**2 + EI * rA * kn**2 / kGA), EI * kn**4]).real)
    return math.sqrt(w2) / (2 * math.pi)


def test_shaft_on_rigid_bores_is_a_pinned_beam_with_a_free_spin():
    """On stiff bearings (no tilt stiffness) the shaft is a pinned-pinned Timoshenko beam, each bending mode
    twice (two planes); the spin about the axis is free (bearings never hold it): one mechanism."""
    r = rigid_bore_modes(shaft_spec(), CENTRES, 2000.0)
    f = r.frequencies_hz[r.mechanisms:]
    assert r.mechanisms == 1
    assert np.allclose(f[:2], timoshenko_pinned(1), rtol=1e-4) and np.allclose(f[2:4], timoshenko_pinned(2), rtol=1e-3)
    # stiff bearings store almost none of the bending energy
    assert r.bearing_energy[1:5].max() < 1e-3


def test_soft_bearings_give_the_rigid_shaft_modes():
    """On soft radial springs k a stiff shaft bounces at sqrt(2k/m) and rocks at sqrt(2k (L/2)^2 / I_d);
    its strain energy is then all in the bearings."""
    k = 1e4      # far below the first bending mode: the shaft's own flexibility is < 0.1 %
    r = rigid_bore_modes(shaft_spec(bearing_stiffness=k), CENTRES, 200.0)
    m = RHO * CircularSection(D).area * L
    i_d = m * L**2 / 12 + m * D**2 / 16
    bounce = math.sqrt(2 * k / m) / (2 * math.pi)
    rock = math.sqrt(2 * k * (L / 2) ** 2 / i_d) / (2 * math.pi)
    f = r.frequencies_hz[r.mechanisms:]
    assert np.allclose(np.sort(f[:5]), np.sort([bounce, bounce, bounce, rock, rock]), rtol=2e-3)
    assert r.bearing_energy[r.mechanisms:r.mechanisms + 5].min() > 0.998


def test_mechanisms_gear_mesh_and_tie_rod():
    """Two shafts: two free spins; a gear mesh links them (one gear-train rotation); a tie rod clamped to both
    locks the spins (the rod bends): no mechanism."""
    second = {"name": "t", "origin": [0.2, 0, 0], "axis": [0, 0, 1], "segments": [[L, D]], "elements_per_segment": 24}
    bores = [{"name": "c0", "surface": "s2", "centre": [0.2, 0, 0], "axis": [0, 0, 1]},
             {"name": "c1", "surface": "s3", "centre": [0.2, 0, L], "axis": [0, 0, 1]}]
    bearings = [{"shaft_node": "t:0", "bore": "c0", "axis": [0, 0, 1], "stiffness": [1e9, 1e9, 1e9, 0, 0, 0]},
                {"shaft_node": "t:24", "bore": "c1", "axis": [0, 0, 1], "stiffness": [1e9, 1e9, 1e9, 0, 0, 0]}]
    base = shaft_spec().model_dump()
    two = dict(base, shafts=base["shafts"] + [second], bores=base["bores"] + bores,
               bearings=base["bearings"] + bearings)
    centres = {**CENTRES, "c0": np.array([0.2, 0, 0]), "c1": np.array([0.2, 0, L])}
    assert rigid_bore_modes(CouplingSpec.model_validate(two), centres, 500.0).mechanisms == 2
    mesh = {"a": "s:12", "b": "t:12", "stiffness": 1e9, "point": [0.05, 0, L / 2], "direction": [0, 1, 0]}
    assert rigid_bore_modes(CouplingSpec.model_validate(dict(two, gear_meshes=[mesh])), centres, 500.0).mechanisms == 1
    rod = {"a": "s:12", "b": "t:12", "diameter": 0.01, "rigid_end_a": D / 2, "rigid_end_b": D / 2}
    assert rigid_bore_modes(CouplingSpec.model_validate(dict(two, tie_rods=[rod])), centres, 500.0).mechanisms == 0


def test_bad_interior_input():
    with pytest.raises(InputError, match="coupling.bearings.0.shaft_node"):
        from housingfe.drivetrain.interior import parts

        bad = shaft_spec().model_dump()
        bad["bearings"][0]["shaft_node"] = "s:99"
        parts(CouplingSpec.model_validate(bad), CENTRES)
    with pytest.raises(InputError, match="rigid ends"):
        rod = {"a": "s:0", "b": "s:24", "diameter": 0.01, "rigid_end_a": 0.4, "rigid_end_b": 0.3}
        rigid_bore_modes(shaft_spec({"tie_rods": [rod]}), CENTRES, 100.0)
    from housingfe.scene import HousingScene
    from housingfe.scenefile import parse_table, read_scene_dict

    data, path = read_scene_dict("box-free-frf")
    data["loads"] = [{"name": "t", "kind": "moment", "node": "x:1", "direction": [0, 0, 1]}]
    with pytest.raises(InputError, match="loads: a node load needs a"):
        parse_table(HousingScene, data, path)


@pytest.fixture(scope="module")
def gearbox_low(comm):
    """test-gearbox-interior on its own mesh at three low lines, modal solver."""
    from housingfe.drivetrain.interior import build_interior
    from housingfe.response import forced as forced_response
    from housingfe.scene import build_model_from_scene

    scene = load_scene("test-gearbox-interior", "analysis.harmonic.f_min=20.0", "analysis.harmonic.f_max=30.0",
                       "analysis.harmonic.df=5.0")
    model = build_model_from_scene(scene, comm)
    interior = build_interior(model, scene.coupling, 1500.0)
    return scene, interior, forced_response.run(interior, scene.analysis.harmonic, scene.loads, scene.damping)


def test_wheel_torque_turns_the_free_gear_train(gearbox_low):
    """Far below the first elastic mode a torque T at the wheel spins the gear train as a rigid body: the
    wheel's angular velocity is T / (omega J), J = J_wheel + u^2 J_pinion (u = 3, pitch radii 150 / 50 mm;
    shaft and disc polar inertias), so L_omega follows from the inertias alone."""
    scene, interior, forced = gearbox_low
    assert interior.rigid.mechanisms == 1
    polar = {}
    for s in scene.coupling.shafts:
        length = sum(seg[0] for seg in s.segments)
        j = RHO * math.pi * s.segments[0][1] ** 4 / 32 * length
        for d in s.discs:
            j += RigidDisc.cylinder(d.outer_diameter, d.width, d.inner_diameter).polar_inertia
        polar[s.name] = j
    j_eq = polar["wheel"] + 3.0**2 * polar["pinion"]
    r = forced.responses["modal+residual"][0]
    omega = np.sqrt(r.extras["omega_mean_square"])
    expected = 1.0 / (2 * math.pi * r.frequencies * j_eq)
    assert np.allclose(omega, expected, rtol=5e-3)


def _variant_scene(tmp_path, comm, **harmonic):
    """test-gearbox-interior with hysteretic damping (eta = 0.08, the same in every solver) and the given
    harmonic settings: (scene, model)."""
    import tomllib

    from housingfe.scene import build_model_from_scene, load_housing_scene
    from housingfe.scenefile import SCENE_DIR

    with open(SCENE_DIR / "test-gearbox-interior.toml", "rb") as fh:
        data = tomllib.load(fh)
    data["damping"] = {"loss_factor": 0.08}
    data["analysis"]["harmonic"].update(harmonic)
    path = tmp_path / "scene.toml"
    path.write_text(_toml(data))
    scene, _ = load_housing_scene(str(path))
    return scene, build_model_from_scene(scene, comm)


def test_coupled_modal_matches_direct(comm, tmp_path):
    """The ball-bearing gearbox through modal superposition (+ residual) and the direct solver: surface TF and
    TF_omega agree on lines around the first housing modes."""
    from housingfe.drivetrain.interior import build_interior
    from housingfe.response import forced as forced_response

    scene, model = _variant_scene(tmp_path, comm, f_min=300.0, f_max=600.0, df=100.0, solver="both",
                                  modal_basis_factor=3.0)
    interior = build_interior(model, scene.coupling, 1800.0)
    forced = forced_response.run(interior, scene.analysis.harmonic, scene.loads, scene.damping)
    m, d = forced.responses["modal+residual"][0], forced.responses["direct"][0]
    assert np.max(np.abs(m.transfer_db - d.transfer_db)) < 0.05
    assert np.max(np.abs(m.extras["TF_omega_dB"] - d.extras["TF_omega_dB"])) < 0.05


def test_projected_solver_with_a_journal_bearing_matches_a_dense_solve(comm):
    """A stiff block on a journal bearing (Ocvirk: non-symmetric K, cross-coupled C) plus a 6x6 spring: the
    projected solver (modes of the nearest PSD stand-in + residual vector, full K and C projected) against a
    dense complex solve of (K + i w C - w^2 M) q = f, at lines between and near the spring-mass modes."""
    from types import SimpleNamespace

    from housingfe.bearings import JournalBearing, short_bearing_coefficients
    from housingfe.drivetrain import coupling as cp
    from housingfe.drivetrain.interior import nearest_psd
    from housingfe.scene import build_model_from_scene
    from housingfe.solvers import harmonic, modal
    from tests.drivetrain.test_coupling import BOTTOM_CENTRE, K_SPRING, block_scene

    block = build_model_from_scene(block_scene(2.1e13), comm)
    film = short_bearing_coefficients(JournalBearing(0.05, 0.025, 50e-6, 0.02), 300.0, (0.0, -1000.0))
    con = cp.BoreConnection("bore", "bottom", BOTTOM_CENTRE, (0, 0, 1), "rbe3")
    system = cp.couple(block, [con], [cp.bearing("bore", None, K_SPRING + film.K, (0, 0, 1), film.C)])
    stand_in = cp.couple(block, [con], [cp.bearing("bore", None, nearest_psd(K_SPRING + film.K), (0, 0, 1))])
    modes = modal.solve_modes(stand_in.K, stand_in.M, 2000.0)
    f = system.load(node_loads={"bore": [0.0, 0.3, 1.0, 0.0, 0.0, 0.0]})
    freqs = np.array([40.0, 75.0, 120.0, 300.0])
    res = harmonic.projected(system.K, system.M, modes, [SimpleNamespace(vector=f)], freqs,
                             harmonic.Damping(eta=lambda x: np.full(np.shape(x), 0.02)),
                             lambda vecs: np.array([v.getArray().copy() for v in vecs]), C=system.C,
                             K_sym=stand_in.K)
    n = system.size
    K, M, C = (A.getValues(range(n), range(n)) for A in (system.K, system.M, system.C))
    blk = res.blocks[0][0]
    u = blk.reduced.T @ blk.coeffs
    for k, fr in enumerate(freqs):
        w = 2 * math.pi * fr
        ref = np.linalg.solve(K * (1 + 0.02j) + 1j * w * C - w * w * M, f.getArray())
        assert np.linalg.norm(u[:, k] - ref) < 1e-4 * np.linalg.norm(ref), fr


def _toml(data, prefix=""):
    """A minimal TOML writer for the scene dicts of these tests (tables, arrays of tables, scalars, lists)."""
    import json

    lines, tables = [], []
    for k, v in data.items():
        if isinstance(v, dict):
            tables.append((k, v))
        elif isinstance(v, list) and v and isinstance(v[0], dict):
            tables.append((k, v))
        else:
            lines.append(f"{k} = {json.dumps(v)}")
    out = "\n".join(lines) + "\n"
    for k, v in tables:
        name = f"{prefix}{k}"
        if isinstance(v, dict):
            out += f"\n[{name}]\n" + _toml(v, name + ".")
        else:
            for item in v:
                out += f"\n[[{name}]]\n" + _toml(item, name + ".")
    return out
