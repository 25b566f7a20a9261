"""Mesh misalignment from the drivetrain's FE interior on rigid bores (housingfe.drivetrain.misalignment): the
gear tilt of a shaft on two rigid pin supports against beam theory, and the run-up scene's switch."""
from dataclasses import replace

import numpy as np
import pytest

from housingfe.drivetrain.description import BearingSeat, test_gearbox
from housingfe.drivetrain.misalignment import MISALIGNMENT_MODELS, mesh_misalignment, static_gear_tilts
from housingfe.drivetrain.shafts import STEEL, CircularSection
from housingfe.errors import InputError

PIN = 1e14       # N/m: rigid translation, free tilt (a pin support)
SPANS = {"pinion": (-0.06, 0.12), "wheel": (-0.1075, 0.1075)}     # bearing positions from the gear centre, m


def _pinned(drivetrain):
    seats = tuple(BearingSeat(f"{shaft}_{side}", shaft, pos, f"bore_{shaft}_{side}", locating=side == "front",
                              stiffness=(PIN, PIN, PIN, 0.0, 0.0, 0.0))
                  for shaft, (front, back) in SPANS.items() for side, pos in (("front", front), ("back", back)))
    # the mean mesh stiffness (coupling_mesh_positions) is not used by the statics: 2 positions keep it fast
    return replace(drivetrain, bearings=seats, coupling_mesh_positions=2)


def _pin_theory(dt, theta_p, theta_w, forces, spans):
    """max over the two shafts of |theta - beam theory| / |beam theory| and the smallest |beam theory| (rad)."""
    loads = dt.mesh_node_loads(float(np.linalg.norm(forces.force_on_pinion)), forces)
    errors, sizes = [], []
    for name, theta in (("pinion", theta_p), ("wheel", theta_w)):
        line = dt.shaft(name)
        axis = np.asarray(line.axis, float) / np.linalg.norm(line.axis)
        load = np.real(loads[f"{name}:{dt.shaft_nodes(name)[1]['gear']}"])
        force, moment = load[:3] - (load[:3] @ axis) * axis, load[3:] - (load[3:] @ axis) * axis
        section = CircularSection(line.diameter)
        EI = STEEL.youngs_modulus * section.second_moment
        kGA = section.shear_factor(STEEL.poisson_ratio) * STEEL.shear_modulus * section.area
        a, b = -spans[name][0], spans[name][1]
        L = a + b
        expected = (np.cross(axis, force) * a * b * (b - a) / (3 * EI * L)
                    + moment * ((L * L - 3 * a * L + 3 * a * a) / (3 * EI * L) + 1 / (kGA * L)))
        errors.append(np.linalg.norm(theta - expected) / np.linalg.norm(expected))
        sizes.append(np.linalg.norm(expected))
    return max(errors), min(sizes)


def test_gear_tilt_on_pin_supports_is_beam_theory():
    """Shaft on two rigid pins (front at a before the gear, back at b after it, L = a + b) loaded at the gear by
    the mean tooth force: transverse force P and moment M (the axial component at the pitch radius).  The section
    rotation at the gear: P a b (b - a) / (3 E I L) about axis x P, plus M [(L^2 - 3 a L + 3 a^2) / (3 E I L)
    + 1 / (kappa G A L)] (Timoshenko: the constant shear force M / L of the moment load tilts the section by
    M / (kappa G A L); a point force's shear integrates to zero between the pins)."""
    dt = _pinned(test_gearbox("A"))
    error, size = _pin_theory(dt, *static_gear_tilts(dt), SPANS)
    assert error < 1e-4                  # pins of 1e14 N/m
    assert size > 1e-5                   # a real tilt (tens of urad), not a vanishing one


def test_gear_tilt_with_a_given_interior_spec_uses_it():
    """static_gear_tilts(drivetrain, spec=...) solves the given interior: the ball-bearing test gearbox with the
    interior of the same gearbox on rigid pins at its own bearing positions (+-0.1075 m) gives beam theory (the
    moment term alone, a = b: 24 urad), not the ball bearings' tilt (the wheel's 168 urad)."""
    spans = {"pinion": (-0.1075, 0.1075), "wheel": (-0.1075, 0.1075)}
    dt = test_gearbox("A")
    seats = tuple(BearingSeat(f"{shaft}_{side}", shaft, pos, f"bore_{shaft}_{side}", locating=side == "front",
                              stiffness=(PIN, PIN, PIN, 0.0, 0.0, 0.0))
                  for shaft, (front, back) in spans.items() for side, pos in (("front", front), ("back", back)))
    pinned = replace(dt, bearings=seats, coupling_mesh_positions=2).to_coupling_spec()
    error, size = _pin_theory(dt, *static_gear_tilts(dt, spec=pinned), spans)
    assert error < 1e-4
    assert size > 1e-6
    theta_p, theta_w, _ = static_gear_tilts(dt)         # its own ball bearings: far larger tilts
    assert np.linalg.norm(theta_w) > 5 * size           # 168 against 24 urad


def test_double_helical_gears_between_equal_bearings_do_not_tilt():
    """No axial force and each gear centred between two equally loaded, equal bearings: no tilt, no gap."""
    drivetrain = replace(test_gearbox("double_helical", "cylindrical_roller", 2000.0), coupling_mesh_positions=2)
    result = mesh_misalignment(drivetrain, "rigid-bores")
    assert abs(result.gamma) < 1e-12 and result.gap_across_face < 1e-15


def test_misalignment_models_and_the_runup_switch():
    from housingfe.runup.scene import load_runup_scene

    assert set(MISALIGNMENT_MODELS) == {"none", "lumped", "rigid-bores"}
    with pytest.raises(InputError, match="misalignment"):
        mesh_misalignment(test_gearbox("A"), "housing")
    scene, _ = load_runup_scene("test-gearbox-runup")
    assert scene.runup.misalignment_model == "rigid-bores"          # the physical default
    scene, _ = load_runup_scene("test-gearbox-runup", ["runup.engagement=thesis-2d"])
    assert scene.runup.misalignment_model == "none"                 # the thesis' replica stays aligned
    with pytest.raises(InputError, match="misalignment"):
        load_runup_scene("test-gearbox-runup", ["runup.misalignment=tilted"])


def test_coupled_misalignment_on_a_stiff_housing_is_the_rigid_bore_one():
    """The coupled solve (interior on the housing FE, one MUMPS solve) with the housing 1000x stiffer than steel:
    the bores stand still and the tilt in the plane of action is the rigid-bore one (to the housing's residual
    compliance)."""
    from mpi4py import MPI

    from housingfe.drivetrain.misalignment import coupled_misalignment
    from housingfe.runup.scene import housing_model_for
    from housingfe.scene import load_housing_scene

    scene, _ = load_housing_scene("test-gearbox", ["material.youngs_modulus=2.1e14", "mesh.size=0.04"])
    model = housing_model_for(scene, 300.0, MPI.COMM_WORLD)
    drivetrain = replace(test_gearbox("A"), coupling_mesh_positions=2)
    coupled = coupled_misalignment(model, drivetrain)
    rigid = mesh_misalignment(drivetrain, "rigid-bores")
    assert coupled.gamma == pytest.approx(rigid.gamma, rel=1e-3)
    assert abs(rigid.gamma) > 5e-5


def _housingfe(*args):
    import os
    import subprocess
    import sys
    from pathlib import Path

    exe = Path(sys.executable).with_name("housingfe")
    return subprocess.run([str(exe), *args], capture_output=True, text=True, timeout=300,
                          env=dict(os.environ, OPENBLAS_NUM_THREADS="1"), check=False)


def test_misalignment_command(tmp_path):
    """`housingfe misalignment`: gamma per gear set and torque in a CSV; a bad gear set is one line, exit 2, no
    folder."""
    import csv

    out = tmp_path / "mis"
    bad = _housingfe("misalignment", "--gear-sets", "Z", "--out", str(out))
    assert bad.returncode == 2 and bad.stderr.startswith("housingfe: error: ") and "'Z'" in bad.stderr
    assert len(bad.stderr.strip().splitlines()) == 1 and not out.exists()
    ok = _housingfe("misalignment", "--gear-sets", "A", "--torques", "2000", "--models", "none", "rigid-bores",
                    "--out", str(out))
    assert ok.returncode == 0, ok.stderr
    rows = list(csv.DictReader(open(out / "misalignment.csv")))
    assert [r["model"] for r in rows] == ["none", "rigid-bores"]
    assert float(rows[0]["gamma_urad"]) == 0.0
    rigid = mesh_misalignment(replace(test_gearbox("A"), coupling_mesh_positions=2), "rigid-bores")
    assert float(rows[1]["gamma_urad"]) == pytest.approx(rigid.gamma * 1e6, rel=1e-9)
    assert float(rows[1]["contact_loss"]) == 0.0 and float(rows[1]["excitation_n1_N"]) > 0
