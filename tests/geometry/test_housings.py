"""The housing library: reconstructions against Appendix E, exact tags and volumes, round bores on their
axes, supports ordered by constraint, joint layer converging to the monolithic joint."""
import math

import numpy as np
import pytest
import ufl
from dolfinx import fem
from dolfinx.cpp.mesh import entities_to_geometry

from housingfe.geometry.housings import appendix_e_plates, appendix_e_total_area
from housingfe.verification.published import thesis
from tests.conftest import load_scene

# The Appendix E table prints 3 significant digits (e.g. 0.0177 m2, 0.532 m): half a unit in the last digit
# is up to 0.3 %; the reconstruction fits the plates to each other too (one top length serves the top and
# the front perimeters), which costs up to 0.7 % (top area 0.0548 vs 0.0544).  Tolerance: 1 %.
APPENDIX_E_TOLERANCE = 0.01


def _table(name):
    return {p[0]: (p[2], p[3]) for p in thesis()["radiation"][name]["plates"]}


def test_gearbox_model_plates_match_appendix_e():
    ours = appendix_e_plates(load_scene("gearbox-model").geometry)
    table = _table("scale_model")
    assert set(ours) == set(table)
    for plate, (S, U) in table.items():
        assert ours[plate][0] == pytest.approx(S, rel=APPENDIX_E_TOLERANCE), f"{plate} area"
        assert ours[plate][1] == pytest.approx(U, rel=APPENDIX_E_TOLERANCE), f"{plate} perimeter"
    table_total = sum(c * S for _, c, S, *_ in thesis()["radiation"]["scale_model"]["plates"])
    assert appendix_e_total_area(load_scene("gearbox-model").geometry) == pytest.approx(table_total, rel=0.01)


def test_test_gearbox_plates_match_appendix_e_except_thin_front_plates():
    """The full-size table is not consistent with one box: its thin front plates' perimeters imply a 0.52 m
    wide front, its top a 0.49 m long housing.  The top is kept; front up/low then come out smaller."""
    ours = appendix_e_plates(load_scene("test-gearbox").geometry)
    table = _table("test_gearbox")
    for plate in ("top", "side up", "side low", "front"):
        S, U = table[plate]
        assert ours[plate][0] == pytest.approx(S, rel=APPENDIX_E_TOLERANCE), plate
        assert ours[plate][1] == pytest.approx(U, rel=APPENDIX_E_TOLERANCE), plate
    for plate in ("front up", "front low"):
        S, U = table[plate]
        implied_front_width = (U / 2 + math.sqrt((U / 2) ** 2 - 4 * S)) / 2   # rectangle with this S and U
        assert implied_front_width == pytest.approx(0.52, abs=0.005)
        assert 0.80 < ours[plate][0] / S < 0.86                            # the documented shortfall


@pytest.fixture(scope="module")
def gearbox_mesh(comm):
    from housingfe.geometry import build_mesh

    return build_mesh(load_scene("gearbox-model").geometry, "tet", 0.03, 1, comm)


def _area(hm, name, comm):
    ds = ufl.Measure("ds", domain=hm.mesh, subdomain_data=hm.facet_tags)
    return comm.allreduce(fem.assemble_scalar(fem.form(1.0 * ds(hm.facet_tag_values(name)))))


def test_gearbox_tags_present_and_exact(gearbox_mesh, comm):
    hm = gearbox_mesh
    g = load_scene("gearbox-model").geometry
    cells = {"top", "front_up", "front_low", "back_up", "back_low", "side_up_left", "side_low_left",
             "side_up_right", "side_low_right", "bearing_plate_front", "bearing_plate_back", "rim",
             "foot_front", "foot_back"}
    assert cells == set(hm.cell_groups)
    for name in cells:
        assert comm.allreduce(len(hm.cell_tags.find(hm.cell_groups[name]))) > 0, name
    surfaces = ["outer", "inner", "foot_bottom", "foot_bolts", "excitation_point", "bores"] + \
               [f"bore_{b}_{s}" for b in ("pinion", "wheel") for s in ("front", "back")] + \
               [f"foot_bolt_{n}" for n in range(1, 7)] + [f"outer_{c}" for c in cells]
    for name in surfaces:
        assert comm.allreduce(len(hm.facets(name))) > 0, name
    # plane faces are exact: top (its upper face and its four 8 mm edges), feet contact, patches
    top = g.length * g.width + 2 * (g.length + g.width) * g.wall_thickness
    assert _area(hm, "outer_top", comm) == pytest.approx(top, rel=1e-10)
    assert _area(hm, "foot_bottom", comm) == pytest.approx(2 * g.length * g.feet.width, rel=1e-10)
    assert _area(hm, "foot_bolt_1", comm) == pytest.approx(g.feet.bolt_patch_size**2, rel=1e-10)
    assert _area(hm, "excitation_point", comm) == pytest.approx(g.excitation_patch_size**2, rel=1e-10)
    # free feet radiate: the contact face is part of "outer"
    outer = set(hm.facets("outer"))
    assert set(hm.facets("foot_bottom")) <= outer
    assert not set(hm.facets("bores")) & outer


def test_bores_are_concentric_with_their_axes(gearbox_mesh, comm):
    """Every vertex of a bore face lies on the bore's cylinder (gmsh puts boundary nodes on the geometry);
    the bore surface area is the cylinder's, less the faceting of a straight-sided tet mesh."""
    hm = gearbox_mesh
    g = load_scene("gearbox-model").geometry
    mesh = hm.mesh
    f2v = mesh.topology.connectivity(2, 0)
    for bore in g.bores:
        for side in ("front", "back"):
            facets = hm.facets(f"bore_{bore.name}_{side}")
            vertices = np.unique(np.concatenate([f2v.links(f) for f in facets])).astype(np.int32)
            nodes = entities_to_geometry(mesh._mesh, 0, vertices, False).ravel()
            xyz = mesh.geometry.x[nodes]
            radius = np.hypot(xyz[:, 0] - bore.x, xyz[:, 2] - g.split_height)
            assert np.allclose(radius, bore.diameter / 2, atol=1e-7), (bore.name, side)
            area = _area(hm, f"bore_{bore.name}_{side}", comm)
            length = g.bearing_plate.thickness
            assert 0.97 < area / (math.pi * bore.diameter * length) <= 1.0 + 1e-9


def test_mesh_volume_matches_exact_volume(gearbox_mesh, comm):
    """The FE mesh (OCC geometry, meshed) against the block model's exact volume (cells minus cylinders).
    Straight-sided tets inscribe the bores' circles, so the mesh has slightly more material."""
    hm = gearbox_mesh
    vol = comm.allreduce(fem.assemble_scalar(fem.form(1.0 * ufl.dx(domain=hm.mesh))))
    g = load_scene("gearbox-model").geometry
    bore_volume = sum(2 * math.pi * (b.diameter / 2) ** 2 * g.bearing_plate.thickness for b in g.bores)
    assert 0.0 <= vol - hm.volume < 0.03 * bore_volume


def test_rim_adds_its_volume():
    from housingfe.geometry.mesh import block_model_for

    g = load_scene("gearbox-model").geometry
    without = load_scene("gearbox-model-norim").geometry
    L, W, t = g.length, g.width, g.wall_thickness
    r, h = g.rim.width, g.rim.height
    ring = ((L + 2 * r) * (W + 2 * r) - L * W) * h
    # where the rim meets the bearing plates (standing out 30 mm, the rim's width) it adds nothing
    proud = g.bearing_plate.thickness - t
    overlap = 2 * g.bearing_plate.width * min(r, proud) * h
    assert block_model_for(g).volume() - block_model_for(without).volume() == pytest.approx(ring - overlap,
                                                                                            rel=1e-12)


def test_bad_bore_names_the_parameter():
    from housingfe.errors import InputError

    with pytest.raises(InputError, match="bores: bore 'wheel' leaves a ligament"):
        load_scene("gearbox-model", "geometry.bores=[{name='pinion', x=-0.108, diameter=0.130}, "
                                    "{name='wheel', x=0.052, diameter=0.170}]")


def _frequencies(scene_name, *overrides):
    from mpi4py import MPI

    from housingfe.scene import build_model_from_scene
    from housingfe.solvers import modal

    scene = load_scene(scene_name, *overrides)
    model = build_model_from_scene(scene, MPI.COMM_WORLD)
    result = modal.solve_modes(model.K, model.M, scene.analysis.modal.f_max)
    return result.frequencies_hz[result.rigid_count:]


def test_more_constraint_never_lowers_a_frequency():
    """Courant-Fischer: adding constraints (BC 1 -> 2 -> 3) or springs cannot lower the k-th eigenvalue."""
    coarse = ("mesh.size=0.05", "analysis.modal.f_max=2500.0")
    f1 = _frequencies("box-supported-bc1", *coarse)
    f2 = _frequencies("box-supported-bc2", *coarse)
    f3 = _frequencies("box-supported", *coarse)
    fe = _frequencies("box-supported-elastic", *coarse)
    assert len(f1) >= len(f2) >= len(f3) >= 3
    n = len(f3)
    assert np.all(f1[:n] <= f2[:n] * (1 + 1e-8))
    assert np.all(f2[:n] <= f3[:n] * (1 + 1e-8))
    # the elastic foundation lies between the bolts alone and the fully fixed flange
    assert np.all(f1[:n] <= fe[:n] * (1 + 1e-8)) and np.all(fe[:n] <= f3[:n] * (1 + 1e-8))


def test_stiff_joint_layer_converges_to_monolithic():
    """A joint layer of the flange material is the monolithic joint (only the mesh differs); a softer layer
    lowers every frequency (K decreases, M unchanged).  The layer mesh is built once, both layer materials
    are assembled on it."""
    from mpi4py import MPI

    from housingfe.fe.model import material_field
    from housingfe.scene import build_model_from_scene
    from housingfe.solvers import elasticity, modal

    coarse = ("mesh.size=0.06", "analysis.modal.f_max=1600.0", "regions.joint.density=7850.0")
    mono = _frequencies("box-halves", *coarse[:2])
    steel_scene = load_scene("box-halves-gasket", *coarse, "regions.joint.youngs_modulus=210e9")
    model = build_model_from_scene(steel_scene, MPI.COMM_WORLD)
    steel = modal.solve_modes(model.K, model.M, 1600.0)
    soft_scene = load_scene("box-halves-gasket", *coarse, "regions.joint.youngs_modulus=1e8")
    K, M = elasticity.assemble_stiffness_mass(model.V, material_field(soft_scene.regions, model.housing,
                                                                      soft_scene.material.resolve()), [], [])
    soft = modal.solve_modes(K, M, 1600.0)
    steel_f = steel.frequencies_hz[6:]
    soft_f = soft.frequencies_hz[6:]
    n = min(len(mono), 6)
    assert n >= 4 and steel.rigid_count == soft.rigid_count == 6
    assert np.allclose(steel_f[:n], mono[:n], rtol=3e-3)
    assert np.all(soft_f[:n] < steel_f[:n])


def test_feet_on_a_base_do_not_radiate(comm):
    """test-gearbox: feet bolted to the base, so their contact faces and bolt patches leave `outer`."""
    from housingfe.geometry import build_mesh

    g = load_scene("test-gearbox").geometry
    hm = build_mesh(g, "tet", 0.04, 1, comm)
    outer = set(hm.facets("outer"))
    assert len(hm.facets("foot_bottom")) > 0 and not set(hm.facets("foot_bottom")) & outer
    assert _area(hm, "foot_bottom", comm) == pytest.approx(2 * g.length * g.feet.width, rel=1e-10)
    assert len(hm.facets("foot_bolts")) > 0 and set(hm.facets("foot_bolts")) <= set(hm.facets("foot_bottom"))


def test_covers_close_the_bores(comm):
    """Square covers: exact added volume, their outer faces radiate, the disc of each cover that closes a
    bore looks into the housing (inner), no face between cover and plate is left unglued."""
    from housingfe.geometry import build_mesh
    from housingfe.geometry.mesh import block_model_for

    g = load_scene("gearbox-model", "geometry.covers={thickness=0.008, margin=0.010}").geometry
    g0 = load_scene("gearbox-model").geometry
    side = g.bores[0].diameter + 2 * g.covers.margin
    assert block_model_for(g).volume() - block_model_for(g0).volume() == pytest.approx(
        4 * side**2 * g.covers.thickness, rel=1e-12)
    hm = build_mesh(g, "tet", 0.03, 1, comm)
    cover_outer = side**2 + 4 * side * g.covers.thickness
    for name in ("pinion", "wheel"):
        for s in ("front", "back"):
            assert _area(hm, f"outer_cover_{name}_{s}", comm) == pytest.approx(cover_outer, rel=1e-10)
    hm0 = build_mesh(g0, "tet", 0.03, 1, comm)
    discs = sum(2 * math.pi * (b.diameter / 2) ** 2 for b in g.bores)
    # the discs are inscribed polygons in a straight-sided tet mesh: a few per cent less than the circles
    assert 0.95 * discs < _area(hm, "inner", comm) - _area(hm0, "inner", comm) <= discs * (1 + 1e-9)
    # everything else of the housing radiates as before, plus the covers, less the bearing plate faces
    # they cover (square minus disc each; the open model's holes are polygons, slightly smaller than discs)
    covered = 4 * (side**2 - math.pi * (g.bores[0].diameter / 2) ** 2)
    expected_outer = _area(hm0, "outer", comm) + 4 * cover_outer - covered
    assert 0.0 <= expected_outer - _area(hm, "outer", comm) < 0.05 * discs


def test_rib_adds_its_volume_and_is_tagged(comm):
    """A rib welded on top of the gearbox model adds exactly its volume and gets its own outer tag; a
    floating rib is rejected with the key named."""
    from housingfe.errors import InputError
    from housingfe.geometry import block_model_for
    from housingfe.scene import load_housing_scene

    base, _ = load_housing_scene("gearbox-model")
    rib = 'geometry.ribs=[{name="top", x=[-0.15, 0.15], y=[-0.004, 0.004], z=[0.301, 0.331]}]'
    ribbed, _ = load_housing_scene("gearbox-model", [rib])
    added = block_model_for(ribbed.geometry).volume() - block_model_for(base.geometry).volume()
    assert added == pytest.approx(0.30 * 0.008 * 0.030, rel=1e-9)
    from housingfe.geometry import build_mesh

    hm = build_mesh(ribbed.geometry, "tet", 0.05, 1, comm)
    assert "outer_rib_top" in hm.facet_groups
    with pytest.raises(InputError, match="ribs"):
        load_housing_scene("gearbox-model", ['geometry.ribs=[{name="x", x=[0, 0.1], y=[0, 0.01], z=[0.5, 0.6]}]'])
