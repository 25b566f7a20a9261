"""The back-to-back rig loop in the FE reduction (Drivetrain.drive_line = "back-to-back"): the far quills end on the
auxiliary gearbox (one torsion node: its pinion's angle phi, its wheel at -phi / ratio) instead of ground, the motor
on its pinion shaft holds the loop's rigid rotation.  Checked against a torsional chain written here from scratch
(rigid gears, quill springs, the two ratios: a 4x4 eigenproblem in the parts' own angles), against the energy of
one far quill by hand, and by the zero-mode counts."""
import math
from dataclasses import replace

import numpy as np
import pytest
import scipy.linalg as sl

from housingfe.drivetrain import coupling as cp
from housingfe.drivetrain.description import AUX_TEETH, MOTOR_ROTOR_INERTIA, test_gearbox
from housingfe.drivetrain.interior import (
    AuxGearboxSpec,
    DriveLineSpec,
    aux_gearbox_elements,
    drive_line_elements,
    free_housing_mechanisms,
    rigid_bore_modes,
)
from housingfe.errors import InputError
from tests.drivetrain.torsion_by_hand import base_ratio, gear_train_polar, near_quill_stiffness


def _loop(gear_set="A", **aux):
    dt = test_gearbox(gear_set)
    return replace(dt, drive_line="back-to-back", aux_gearbox=replace(dt.aux_gearbox, **aux))


def _seat_centres(dt) -> dict:
    return {s.name: dt.shaft(s.shaft).point(s.position) for s in dt.bearings}


def test_aux_gearbox_is_the_scaled_test_pair_with_the_motor():
    """The assumed aux gearbox: the test gear bodies (mean of tip and root diameter, face width, steel) scaled by
    19/24 and 57/72 at the same module and face width, polar inertia pi rho d^4 b / 32 by hand; the motor rotor on
    the pinion; the wheel reflected by (57/19)^2 = 9; and the spec written only for "back-to-back"."""
    dt = test_gearbox("A")
    pair = dt.gears.pair
    assert AUX_TEETH == (19, 57) and pair.teeth == (24, 72)
    hand = []
    for g, z in enumerate(AUX_TEETH):
        d = 0.5 * (pair.tip_diameter[g] + pair.root_diameter[g]) * z / pair.teeth[g]
        hand.append(7850.0 * math.pi * d**4 * pair.face_width[g] / 32)
    aux = dt.aux_gearbox
    assert (aux.pinion_inertia, aux.wheel_inertia) == pytest.approx(hand, rel=1e-12)
    assert aux.ratio == 3.0
    assert aux.inertia_at_pinion() == pytest.approx(hand[0] + MOTOR_ROTOR_INERTIA + hand[1] / 9, rel=1e-12)
    # the motor's hold: pole pairs x pull-out torque = 2 x 2.5 x 20 kW / (1500 rev/min)
    assert aux.motor_stiffness == pytest.approx(2 * 2.5 * 20e3 / (1500 * 2 * math.pi / 60), rel=1e-12)
    spec = _loop().to_coupling_spec()
    assert spec.aux_gearbox.pinion_line == "coupling_motor" and spec.aux_gearbox.wheel_line == "coupling_brake"
    for drive_line in ("quill-shafts", "none"):
        assert replace(dt, drive_line=drive_line).to_coupling_spec().aux_gearbox is None


def test_back_to_back_needs_an_aux_gearbox():
    with pytest.raises(InputError, match="drive_line: 'back-to-back' needs the rig's auxiliary gearbox"):
        replace(test_gearbox("A"), drive_line="back-to-back", aux_gearbox=None)


@pytest.mark.parametrize("line, factor", [("c_p", 1.0), ("c_w", -1.0 / 3.0)])
def test_far_quill_energy_is_the_twist_through_the_aux_pair(line, factor):
    """On an oblique axis: the far quill's element stores k/2 (phi_coupling - factor phi_aux)^2 for any 6-DOF
    motions of its two nodes (a rotation vector theta counts by its component along the axis), factor 1 on the aux
    pinion and -1/3 on the aux wheel (an external pair turns the other way)."""
    axis = np.array([1.0, -2.0, 2.0]) / 3.0
    k = 3.7e4
    d = DriveLineSpec(name=line, shaft_node="s:0", near_stiffness=1e5, inertia=0.1, far_stiffness=k)
    aux = AuxGearboxSpec(name="aux", axis=tuple(axis), pinion_line="c_p", wheel_line="c_w", ratio=3.0, inertia=0.2,
                         ground_stiffness=500.0)
    far = drive_line_elements(d, axis, ("aux", aux.far_factor(line)))[-1]
    assert far.nodes == (line, "aux")
    rng = np.random.default_rng(1)
    for _ in range(5):
        q = rng.normal(size=12)
        twist = q[3:6] @ axis - factor * (q[9:12] @ axis)
        assert 0.5 * q @ far.K @ q == pytest.approx(0.5 * k * twist**2, rel=1e-12)
    mass, hold = aux_gearbox_elements(aux, axis)
    assert mass.M[3:, 3:] == pytest.approx(0.2 * np.outer(axis, axis), rel=1e-12)
    assert hold.nodes == ("aux",) and hold.K[3:, 3:] == pytest.approx(500.0 * np.outer(axis, axis), rel=1e-12)


def loop_chain_hz(dt) -> np.ndarray:
    """The rig's torsional modes by hand: angles x = (coupling at the pinion quill, test pinion, coupling at the wheel
    quill, aux pinion), each part's own rotation about the (common) shaft axis.  Rigid gears: the test wheel turns by
    -theta_p / i (i = base radius ratio), the aux wheel by -phi / 3.  Springs as twist vectors b (energy k/2 (b.x)^2):
    near quills in series with their FE shaft's torsion from the gear to the front end (0.14 m), far quills from the
    couplings to the aux pinion / aux wheel, the motor from the aux pinion to ground.  Inertias: couplings, gear train
    (pinion + wheel / i^2, gear bodies with their whole FE shafts as solid cylinders), aux gearbox with the motor."""
    polar = gear_train_polar(dt)
    i = base_ratio(dt)
    quills = dt.drive_line_parts()
    aux = dt.aux_gearbox

    def near(name):
        return near_quill_stiffness(dt, name)

    springs = [(near("pinion"), [-1.0, 1.0, 0.0, 0.0]),              # theta_p - phi_cp
               (quills["pinion"][2], [1.0, 0.0, 0.0, -1.0]),          # phi_cp - phi_aux
               (near("wheel"), [0.0, -1.0 / i, -1.0, 0.0]),           # theta_w - phi_cw, theta_w = -theta_p / i
               (quills["wheel"][2], [0.0, 0.0, 1.0, 1.0 / aux.ratio]),  # phi_cw - (-phi_aux / 3)
               (aux.motor_stiffness, [0.0, 0.0, 0.0, 1.0])]
    K = sum(k * np.outer(b, b) for k, b in springs)
    M = np.diag([quills["pinion"][1], polar["pinion"] + polar["wheel"] / i**2, quills["wheel"][1],
                 aux.pinion_inertia + aux.motor_inertia + aux.wheel_inertia / aux.ratio**2])
    return np.sqrt(np.clip(sl.eigh(K, M, eigvals_only=True), 0.0, None)) / (2 * math.pi)


@pytest.mark.parametrize("aux", [{}, {"motor_stiffness": 0.0}, {"motor_inertia": 0.075, "pinion_inertia": 1e-3},
                                 {"motor_inertia": 0.3, "wheel_inertia": 0.3}])
def test_loop_modes_on_rigid_bores_are_the_torsional_chain(aux):
    """The interior with the loop on rigid bores: its two lowest modes (the motor's hold of the rig's rotation,
    ~8 Hz, and the loop's torsion, ~92 Hz for set A) are the hand-built chain's (`loop_chain_hz`) within 0.5 % (what
    the chain leaves out: mesh, bearing and gear compliance, the shafts' distributed inertia), also with other aux
    and motor inertias; with the motor's hold off the rotation is the interior's one mechanism."""
    dt = _loop(**aux)
    modes = rigid_bore_modes(dt.to_coupling_spec(), _seat_centres(dt), 1000.0)
    chain = loop_chain_hz(dt)
    free = aux.get("motor_stiffness") == 0.0
    assert modes.mechanisms == (1 if free else 0)
    if free:
        assert chain[0] < 1e-6 * chain[1]
    else:
        assert 3.0 < chain[0] < 15.0
        assert modes.frequencies_hz[0] == pytest.approx(chain[0], rel=5e-3)
    assert 80.0 < chain[1] < 120.0
    assert modes.frequencies_hz[1] == pytest.approx(chain[1], rel=5e-3)


def test_the_loop_is_stiffer_than_the_grounded_quills():
    """Closing the loop puts the aux side's inertia in series with the test side's: the rig's torsion mode rises
    above the grounded quills' (75.7 Hz), towards it as the aux inertia grows (a grounded far end is an infinite
    one).  The chain shows the limit: an aux gearbox 1000x heavier gives the grounded frequency within 1 %."""
    dt = test_gearbox("A")
    grounded = rigid_bore_modes(replace(dt, drive_line="quill-shafts").to_coupling_spec(), _seat_centres(dt),
                                1000.0).frequencies_hz[0]
    loop = rigid_bore_modes(_loop().to_coupling_spec(), _seat_centres(dt), 1000.0).frequencies_hz[1]
    assert loop > grounded * 1.1
    heavy = loop_chain_hz(_loop(motor_inertia=150.0, motor_stiffness=0.0))[1]
    assert heavy == pytest.approx(grounded, rel=1e-2)


def test_loop_zero_modes_on_a_free_housing():
    """On a free rigid housing: 5 zero modes with the motor's hold (the aux gearbox stands on the floor: like the
    grounded quills it holds the housing's rotation about the shafts through the gears), 6 without it (the rig's
    rotation is one more)."""
    counts = [free_housing_mechanisms(dt.to_coupling_spec(), _seat_centres(dt))
              for dt in (_loop(), _loop(motor_stiffness=0.0))]
    assert counts == [5, 6]


@pytest.fixture(scope="module")
def gearbox_housing(comm):
    from housingfe.runup.scene import housing_model_for
    from housingfe.scene import load_housing_scene

    hs, _ = load_housing_scene("test-gearbox", ["mesh.size=0.06"])
    return housing_model_for(hs, 600.0, comm)


def test_coupled_gearbox_with_the_loop(gearbox_housing):
    """On the test gearbox housing (feet held) the coupled model with the loop has no zero mode (the completeness
    check of the modal solver holds) and its two lowest modes are the chain's within 0.5 %."""
    from housingfe.drivetrain.interior import build_interior
    from housingfe.solvers import modal

    dt = _loop()
    structure = build_interior(gearbox_housing, dt.to_coupling_spec(), 600.0)
    basis = modal.modes(structure, 600.0)
    assert structure.expected_zero_modes == 0 and basis.rigid_count == 0
    chain = loop_chain_hz(dt)
    assert basis.frequencies_hz[:2] == pytest.approx(chain[:2], rel=5e-3)
    assert basis.frequencies_hz[2] > 200.0


def test_coupling_elements_are_unchanged_without_the_loop():
    """"quill-shafts" keeps its far quill to ground (one node, the torsion block): the element list of a drive line
    without `far` is the one it was."""
    axis = np.array([0.0, 1.0, 0.0])
    d = DriveLineSpec(name="c", shaft_node="s:0", near_stiffness=2.0, inertia=0.5, far_stiffness=3.0)
    near, mass, far = drive_line_elements(d, axis)
    assert far.nodes == ("c",) and far.K[4, 4] == 3.0 and np.count_nonzero(far.K) == 1
    assert isinstance(near, cp.Element) and near.nodes == ("s:0", "c")
