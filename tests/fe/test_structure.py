"""The Structure protocol (housingfe.fe.structure): the bare housing and the housing coupled with an interior
both satisfy it, and the stage housingfe.solvers.modal.modes works on either: 6 zero modes of a free plate, the
six spring-mass modes of a stiff block on a 6x6 spring (analytic), the zero-mode check."""
import numpy as np
import pytest

from housingfe.errors import SolverError
from housingfe.fe.structure import Structure
from housingfe.scene import build_model_from_scene
from housingfe.solvers import modal
from tests.conftest import load_scene

PLATE = ["geometry.a=0.3", "geometry.b=0.2", "geometry.h=0.005", "mesh.size=0.05", "analysis.modal.f_max=1500.0"]


@pytest.fixture(scope="module")
def free_plate(comm):
    return build_model_from_scene(load_scene("nafems-fv12", *PLATE), comm)


def test_housing_model_is_a_structure_and_modes_finds_six_zero_modes(free_plate):
    assert isinstance(free_plate, Structure)
    assert free_plate.C is None and free_plate.expected_zero_modes == 6
    basis = modal.modes(free_plate, 1500.0)
    assert basis.structure is free_plate
    assert basis.rigid_count == 6 and basis.complete
    assert basis.frequencies_hz[6] > 10.0          # the first elastic mode of a 0.3 x 0.2 x 0.005 plate: ~100 Hz
    # the same eigenvalues as the matrix-level solver
    ref = modal.solve_modes(free_plate.K, free_plate.M, 1500.0)
    assert np.allclose(basis.frequencies_hz[6:], ref.frequencies_hz[6:], rtol=1e-9)


def test_modes_checks_the_expected_zero_mode_count(free_plate):
    class Clamped:      # the plate, claiming to be supported so that no zero mode is expected
        K, M, C = free_plate.K, free_plate.M, None
        expected_zero_modes = 0

    with pytest.raises(SolverError, match="must have 0 rigid-body / mechanism modes, found 6"):
        modal.modes(Clamped(), 1500.0)
    assert modal.modes(Clamped(), 1500.0, check=False).rigid_count == 6


def test_explicit_build_model_equals_the_scene_entry_point(comm, free_plate):
    from housingfe.fe.model import build_model

    scene = load_scene("nafems-fv12", *PLATE)
    model = build_model(scene.geometry, scene.material.resolve(), scene.mesh, scene.analysis.f_max, comm,
                        regions=scene.regions, supports=scene.supports)
    assert model.scene is None and model.dofs == free_plate.dofs
    assert model.K.norm() == pytest.approx(free_plate.K.norm(), rel=1e-12)
    assert model.M.norm() == pytest.approx(free_plate.M.norm(), rel=1e-12)


def test_housing_load_vector_and_to_housing(free_plate):
    scene = load_scene("nafems-fv12", *PLATE, 'loads=[{name="p", kind="force", surface="top", '
                       'point=[0.07, 0.05, 0.005], direction=[0,0,-1]}]')
    f = free_plate.load_vector(scene.loads[0])
    # a unit force: the z-components of the load vector sum to -1 N
    assert f.sum() == pytest.approx(-1.0, rel=1e-10)
    assert free_plate.to_housing(f) is f


def test_coupled_interior_is_a_structure_with_the_spring_mass_modes(comm):
    """A block 100x stiffer than steel on a 6x6 spring to ground through an RBE3 bore master: the coupled
    structure has one zero mode (a bearing frees the spin about its axis, z), and its next five modes are the
    analytic spring-mass modes with no torsional stiffness.  (Its
    expected_zero_modes says 6: CoupledInterior counts the housing's rigid-body modes whenever the housing has no
    supports, a bearing to ground included; hence check=False here.)"""
    from housingfe.drivetrain.interior import build_interior
    from tests.drivetrain.test_coupling import BOTTOM_CENTRE, K_SPRING, block_scene, rigid_block_frequencies

    block = build_model_from_scene(block_scene(2.1e13), comm)
    spec = {"bores": [{"name": "bore", "surface": "bottom", "centre": list(BOTTOM_CENTRE), "kind": "rbe3"}],
            "bearings": [{"shaft_node": "bore", "stiffness": np.diag(K_SPRING).tolist()}]}
    interior = build_interior(block, spec, 200.0)
    assert isinstance(interior, Structure)
    assert interior.expected_zero_modes == interior.expected_mechanisms()
    assert interior.dofs == interior.system.size
    assert interior.housing is block.housing and interior.V is block.V
    basis = modal.modes(interior, 200.0, check=False)
    assert basis.rigid_count == 1
    spin_free = K_SPRING.copy()
    spin_free[5, 5] = 0.0
    exact = np.sort(np.nan_to_num(rigid_block_frequencies(spin_free, BOTTOM_CENTRE)))[1:]
    assert np.allclose(basis.frequencies_hz[1:6], exact, rtol=1e-4)
    u = basis.to_housing().vectors[0]
    assert u.getSize() == block.K.getSize()[0]
    assert np.allclose(u.getArray(), interior.fe_vector(basis.vectors[0]).getArray())
