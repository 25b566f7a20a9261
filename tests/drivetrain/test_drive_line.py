"""The test rig's drive line in the FE reduction (Drivetrain.drive_line = "quill-shafts"): the same quill shafts and
coupling inertias as the lumped source model, coupling nodes with one torsional DOF (u = P q: translations zero,
rotation along the axis), the gear train's free rotation gone, its rig torsion mode against a hand-built
three-inertia chain, a torsion node on an oblique axis against statics and a two-inertia chain, and 1 against 2 MPI
ranks."""
import json
import math
import shutil
from dataclasses import replace

import numpy as np
import pytest
import scipy.linalg as sl

from housingfe.drivetrain import coupling as cp
from housingfe.drivetrain.description import DRIVE_LINES, GEAR_SETS, test_gearbox
from housingfe.drivetrain.interior import (
    DriveLineSpec,
    drive_line_elements,
    free_housing_mechanisms,
    rigid_bore_modes,
)
from housingfe.drivetrain.shafts import RigidDisc, Shaft
from housingfe.errors import InputError
from housingfe.scene import build_model_from_scene
from housingfe.solvers import modal
from tests.conftest import load_scene, mumps_solve
from tests.drivetrain.torsion_by_hand import base_ratio, gear_train_polar, near_quill_stiffness
from tests.two_ranks import module_result


def _with_drive_line(gear_set="A", drive_line="quill-shafts"):
    return replace(test_gearbox(gear_set), drive_line=drive_line)


def _seat_centres(dt) -> dict:
    """Bore centres of the FE reduction without a housing: the bearing seats on the shaft lines (m)."""
    return {s.name: dt.shaft(s.shaft).point(s.position) for s in dt.bearings}


@pytest.mark.parametrize("gear_set", list(GEAR_SETS))
def test_both_reductions_have_the_same_drive_line(gear_set):
    """Torsional stiffnesses and coupling inertias of the FE drive line equal the lumped model's (shafts 1-4 of
    Appendix C, DOFs 13, 14) in its topology, and the stiffness is pi G d^4 / (32 l) by hand."""
    dt = _with_drive_line(gear_set)
    lumped = dt.to_lumped()[0]
    k1, k2, k3, k4 = lumped.torsion_stiffness
    spec = dt.to_coupling_spec()
    lines = {d.shaft_node.split(":")[0]: d for d in spec.drive_lines}
    assert set(lines) == {"pinion", "wheel"}
    # pinion -k2- coupling (J13) -k1- held far end; wheel -k3- coupling (J14) -k4- ground (dynamics.assemble)
    for name, near, inertia, far in (("pinion", k2, lumped.coupling_inertia[0], k1),
                                     ("wheel", k3, lumped.coupling_inertia[1], k4)):
        d = lines[name]
        assert (d.near_stiffness, d.inertia, d.far_stiffness) == (near, inertia, far)
        assert d.shaft_node == f"{name}:0"                        # the shaft's front end node
    pair = dt.gears.pair
    G = pair.youngs_modulus / (2 * (1 + pair.poisson_ratio))
    q = dt.quill_shafts[0]                                        # Ø40 x 1.5 m to the motor
    assert k1 == pytest.approx(math.pi * G * q.diameter**4 / (32 * q.length), rel=1e-14)
    assert not replace(dt, drive_line="none").to_coupling_spec().drive_lines


def test_unknown_drive_line_is_an_input_error():
    with pytest.raises(InputError, match="drive_line: 'quills' is not one of " + ", ".join(DRIVE_LINES)):
        _with_drive_line(drive_line="quills")


def test_drive_line_removes_the_free_rotation():
    """On rigid bores the gear train's rigid rotation is the one mechanism without the drive line and none with
    it; on a free rigid housing 6 + 1 zero modes become 5 (the far quills are grounded: they hold the gear train's
    rotation and, through the mesh and bearings, the housing's rotation about the shafts)."""
    counts = {}
    for drive_line in ("none", "quill-shafts"):
        dt = _with_drive_line(drive_line=drive_line)
        spec, centres = dt.to_coupling_spec(), _seat_centres(dt)
        counts[drive_line] = (rigid_bore_modes(spec, centres, 1000.0).mechanisms,
                              free_housing_mechanisms(spec, centres))
    assert counts == {"none": (1, 7), "quill-shafts": (0, 5)}


def _rig_chain_hz(dt) -> float:
    """The rig's torsion mode by hand: the gear train rigid (pinion + wheel reflected through the base radius
    ratio; each as gear body + its whole FE shaft, solid cylinders), each near quill in series with its FE shaft's
    torsion from the gear to the shaft end (G pi d^4 / 32 / 0.14 m), the couplings' inertias, far quills to ground:
    three inertias on a spring chain."""
    polar = gear_train_polar(dt)
    ratio = base_ratio(dt)
    parts = dt.drive_line_parts()

    def near(name):
        return near_quill_stiffness(dt, name)

    kp, kw = near("pinion"), near("wheel") / ratio**2
    kpf, kwf = parts["pinion"][2], parts["wheel"][2] / ratio**2
    M = np.diag([parts["pinion"][1], polar["pinion"] + polar["wheel"] / ratio**2, parts["wheel"][1] / ratio**2])
    K = np.array([[kpf + kp, -kp, 0.0], [-kp, kp + kw, -kw], [0.0, -kw, kw + kwf]])
    return float(np.sqrt(sl.eigh(K, M, eigvals_only=True)[0]) / (2 * math.pi))


def test_rig_torsion_mode_on_rigid_bores_is_the_spring_chain():
    """The lowest mode of the interior with the drive line (rigid bores) is the rig's torsion mode of the hand-built
    chain (`_rig_chain_hz`, ~75.8 Hz for set A) within 0.5 %: what the chain leaves out (mesh, bearing and gear
    compliance, the shafts' distributed inertia) is at that level."""
    dt = _with_drive_line()
    f = rigid_bore_modes(dt.to_coupling_spec(), _seat_centres(dt), 1000.0).frequencies_hz
    expected = _rig_chain_hz(dt)
    assert 70.0 < expected < 80.0
    assert f[0] == pytest.approx(expected, rel=5e-3)


@pytest.fixture(scope="module")
def gearbox_housing(comm):
    from housingfe.runup.scene import housing_model_for
    from housingfe.scene import load_housing_scene

    hs, _ = load_housing_scene("test-gearbox", ["mesh.size=0.06"])
    return housing_model_for(hs, 600.0, comm)


def test_coupled_gearbox_has_the_rig_mode_instead_of_a_zero_mode(gearbox_housing):
    """On the test gearbox housing (feet held): one zero mode (the gear train's rotation) without the drive line,
    none with it, and its lowest mode is the rig's torsion mode of the spring chain within 0.5 %; the
    completeness check of the modal solver (expected zero modes) holds for both."""
    from housingfe.drivetrain.interior import build_interior

    found = {}
    for drive_line in ("none", "quill-shafts"):
        structure = build_interior(gearbox_housing, _with_drive_line(drive_line=drive_line).to_coupling_spec(), 600.0)
        basis = modal.modes(structure, 600.0)           # raises unless the zero-mode count is the expected one
        found[drive_line] = (structure.expected_zero_modes, basis.rigid_count, basis.frequencies_hz)
    assert found["none"][:2] == (1, 1) and found["quill-shafts"][:2] == (0, 0)
    f = found["quill-shafts"][2]
    assert f[0] == pytest.approx(_rig_chain_hz(_with_drive_line()), rel=5e-3)
    assert found["none"][2][1] > 200.0                  # nothing else below 200 Hz: the rig mode is the new one


# ------------------------------------------------------------------------------- a torsion node on a block
A, B, H = 0.2, 0.1, 0.05
AXIS = np.array([1.0, 2.0, 3.0]) / math.sqrt(14.0)          # oblique: every rotation component of the node is used
K_NEAR, K_FAR, J_COUPLING = 2.0e3, 5.0e3, 2.0e-3            # N m/rad, kg m^2
DISC = RigidDisc.cylinder(0.12, 0.04)


@pytest.fixture(scope="module")
def block(comm):
    scene = load_scene("nafems-fv12", f"geometry.a={A}", f"geometry.b={B}", f"geometry.h={H}", "mesh.size=0.05",
                       "material.youngs_modulus=2.1e11", "material.density=7850.0", "analysis.modal.f_max=200.0")
    return build_model_from_scene(scene, comm)


def block_case(model) -> dict:
    """A short stiff shaft on an oblique axis with a disc at its end node 0, on a bearing (spin free) to a bore on
    the block's bottom, the block on a 6x6 spring to ground; the drive line from shaft node 0: its torsional
    modes and a static torque about the axis at node 0."""
    shaft = Shaft.stepped([(0.05, 0.06)], origin=(A / 2, B / 2, -0.2), axis=tuple(AXIS), elements_per_segment=2)
    shaft.add_disc(0, DISC)
    con = cp.BoreConnection("bore", "bottom", (A / 2, B / 2, 0.0), (0, 0, 1), "rbe2")
    line = DriveLineSpec(name="coupling", shaft_node="s:0", near_stiffness=K_NEAR, inertia=J_COUPLING,
                         far_stiffness=K_FAR)
    elements = [cp.spring("bore", None, np.diag([1e6, 2e6, 3e6, 1e4, 2e4, 0.5e4])),
                cp.bearing("s:1", "bore", np.diag([1e7, 1e7, 1e7, 1e4, 1e4, 0.0]), tuple(AXIS)),
                *drive_line_elements(line, AXIS)]
    system = cp.couple(model, [con], elements, shafts={"s": shaft},
                       torsion_nodes={"coupling": (shaft.nodes[0], AXIS)})
    out = {"ranks": model.V.mesh.comm.size, "size": system.size,
           "frequencies": modal.solve_modes(system.K, system.M, 2000.0).frequencies_hz.tolist()}
    torque = 10.0
    q = mumps_solve(system.K, system.load(node_loads={"s:0": np.r_[np.zeros(3), torque * AXIS]}))
    out["coupling"] = system.node_displacement(q, "coupling").tolist()
    out["shaft_end"] = system.node_displacement(q, "s:0").tolist()
    return out


def test_torsion_node_is_one_rotation_along_its_axis(block):
    """The coupling node of a drive line on an oblique shaft: under a static torque T about the axis at the shaft
    end its displacement is exactly (0, 0, 0, a T / k_far) and the shaft end turns by T (1/k_near + 1/k_far) (the
    bearing leaves the spin free, the block does not turn about a); the system has ONE DOF more than without the
    drive line; two of its modes are the two-inertia chain (disc + shaft, coupling) on the two springs, the shaft
    torsionally rigid by comparison (GJ/L ~1e7 N m/rad against 2e3)."""
    out = block_case(block)
    torque = 10.0
    assert np.allclose(out["coupling"], np.r_[np.zeros(3), torque / K_FAR * AXIS], rtol=0, atol=1e-12)
    spin = np.asarray(out["shaft_end"])[3:] @ AXIS
    assert spin == pytest.approx(torque * (1 / K_NEAR + 1 / K_FAR), rel=1e-9)
    shaft = Shaft.stepped([(0.05, 0.06)], origin=(A / 2, B / 2, -0.2), axis=tuple(AXIS), elements_per_segment=2)
    m = shaft.matrices()[1]
    e = np.zeros(m.shape[0])
    for i in range(len(shaft.nodes)):
        e[6 * i + 3:6 * i + 6] = AXIS
    j_shaft = DISC.polar_inertia + e @ m @ e            # rigid rotation of shaft + disc about the axis
    K = np.array([[K_NEAR, -K_NEAR], [-K_NEAR, K_NEAR + K_FAR]])
    chain = np.sqrt(sl.eigh(K, np.diag([j_shaft, J_COUPLING]), eigvals_only=True)) / (2 * math.pi)
    f = np.asarray(out["frequencies"])
    for target in chain:
        assert np.min(np.abs(f / target - 1)) < 1e-4, (target, f)


def test_two_ranks_give_the_serial_answer(block):
    """The torsion node (on the last rank's extra DOFs) gives the one-rank frequencies and static rotation on 2."""
    one = block_case(block)
    if not shutil.which("mpirun"):
        pytest.skip("mpirun not installed")
    two = module_result("tests.drivetrain.test_drive_line")
    assert two["ranks"] == 2 and two["size"] == one["size"]
    assert len(two["frequencies"]) == len(one["frequencies"])
    assert np.max(np.abs(np.divide(two["frequencies"], one["frequencies"]) - 1)) < 1e-8
    for key in ("coupling", "shaft_end"):
        assert np.linalg.norm(np.subtract(two[key], one[key])) < 1e-8 * np.linalg.norm(one[key]), key


if __name__ == "__main__":       # mpirun -n 2 python -m tests.drivetrain.test_drive_line: the 2-rank half above
    from mpi4py import MPI

    scene = load_scene("nafems-fv12", f"geometry.a={A}", f"geometry.b={B}", f"geometry.h={H}", "mesh.size=0.05",
                       "material.youngs_modulus=2.1e11", "material.density=7850.0", "analysis.modal.f_max=200.0")
    result = block_case(build_model_from_scene(scene, MPI.COMM_WORLD))
    if MPI.COMM_WORLD.rank == 0:
        print(json.dumps(result))
