"""Bore masters on the bore's axis (housingfe.drivetrain.bore_axis): the cylinder fitted to a coarsely meshed tube's
bore has the tube's axis, radius and mid-length to round-off where the bounding box of the nodes is off; a tilted
tube; a half bore (split housing) whose bounding-box centre lies ~r/2 off the axis; a flat face is a flat seat
(centroid); a bore with its shoulder face is refused in one line; a bore tilted from its bearing's axis is refused;
the run-up's bore matching reads the same fit; 1 and 2 MPI ranks fit the same bore."""
from __future__ import annotations

import json
import math
import re
import shutil
from types import SimpleNamespace

import numpy as np
import pytest

from housingfe.drivetrain import bore_axis
from housingfe.errors import InputError
from tests.two_ranks import module_result

R_IN, R_OUT, LENGTH = 0.05, 0.07, 0.04          # tube (m)
SIZE = 0.06                                      # element size (m): 6 elements round the bore
ORIGIN = np.array([0.11, -0.02, 0.3])           # the axis starts here (m)
TILTED = np.array([1.0, 2.0, 3.0]) / math.sqrt(14.0)


def tube_model(comm, axis=(0.0, 0.0, 1.0), half: bool = False, spin_deg: float = 0.0, oil_hole: float = 0.0):
    """A thick tube (R_IN, R_OUT, LENGTH) from ORIGIN along `axis`, linear tets of SIZE (P1 geometry, as the
    housings' meshes), as the part of a housing model fit_bore reads (model.housing: mesh, facet tags, groups).
    half: only the half y' > 0 of the tube's own frame (a split housing's half bore).  Surface groups: "bore" (the
    inner cylinder), "end" (the annulus at the axis' start), "bore_and_end" (both), "seat" (half only: one of the
    two flat rectangles of the cut, from R_IN to R_OUT across the axis).  spin_deg: the tube turned about its own
    axis first (gmsh meshes a circle mirror-symmetric about its seam: turned, its vertices' box leaves the axis).
    oil_hole: radius (m) of a radial hole through the wall along +x', at mid-length."""
    import gmsh

    from housingfe.drivetrain.coupling import axis_frame
    from housingfe.geometry.blocks import distribute_gmsh_model
    from housingfe.geometry.mesh import HousingMesh

    c, s = math.cos(math.radians(spin_deg)), math.sin(math.radians(spin_deg))
    frame = axis_frame(axis) @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])   # columns: x', y', axis
    tags = {}
    if comm.rank == 0:
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("tube")
        occ = gmsh.model.occ
        # the tube along z at the origin, then turned and moved into place
        tube, _ = occ.cut([(3, occ.addCylinder(0, 0, 0, 0, 0, LENGTH, R_OUT))],
                          [(3, occ.addCylinder(0, 0, -0.01, 0, 0, LENGTH + 0.02, R_IN))])
        if oil_hole:
            hole = occ.addCylinder(0, 0, LENGTH / 2, R_OUT + 0.01, 0, 0, oil_hole)
            tube, _ = occ.cut(tube, [(3, hole)])
        if half:
            tube, _ = occ.intersect(tube, [(3, occ.addBox(-0.1, 0.0, -0.01, 0.2, 0.1, LENGTH + 0.02))])
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = frame, ORIGIN
        occ.affineTransform(tube, list(T[:3].ravel()))
        occ.synchronize()
        faces = {}
        for _, f in gmsh.model.getBoundary(tube, oriented=False):
            lo, hi = np.array(gmsh.model.getParametrizationBounds(2, f))
            uv = [lo + (hi - lo) * t for t in ((0.2, 0.3), (0.5, 0.5), (0.7, 0.9))]
            p = (np.array(gmsh.model.getValue(2, f, list(np.ravel(uv)))).reshape(-1, 3) - ORIGIN) @ frame  # tube frame
            radial, along = np.hypot(p[:, 0], p[:, 1]), p[:, 2]
            if np.allclose(radial, R_IN, atol=1e-9):
                key = "bore"
            elif np.allclose(radial, R_OUT, atol=1e-9):
                key = "outside"
            elif np.allclose(along, 0.0, atol=1e-9):
                key = "end"
            elif np.allclose(along, LENGTH, atol=1e-9):
                key = "far_end"
            else:           # a flat cut of the half tube (y' = 0), on the x' > 0 or x' < 0 side
                key = "seat" if (np.array(occ.getCenterOfMass(2, f)) - ORIGIN) @ frame[:, 0] > 0 else "other_seat"
            faces.setdefault(key, []).append(f)
        gmsh.model.addPhysicalGroup(3, [v for _, v in tube], 1)
        for i, (key, fs) in enumerate(sorted(faces.items()), start=1):
            gmsh.model.addPhysicalGroup(2, fs, i)
            tags[key] = [i]
        gmsh.option.setNumber("Mesh.MeshSizeMax", SIZE)
        gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
        gmsh.option.setNumber("Mesh.ElementOrder", 1)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)     # gmsh options are global: set all we rely on
        gmsh.option.setNumber("Mesh.MinimumCirclePoints", 7)
        gmsh.option.setNumber("Mesh.MinimumCurvePoints", 3)
        gmsh.option.setNumber("Mesh.Algorithm3D", 1)
        gmsh.model.mesh.setSize(gmsh.model.getEntities(0), SIZE)
        gmsh.model.mesh.generate(3)
    tags = comm.bcast(tags, root=0)
    mesh, cell_tags, facet_tags = distribute_gmsh_model(comm)
    tags["bore_and_end"] = tags["bore"] + tags["end"]
    housing = HousingMesh(mesh, cell_tags, facet_tags, {"tube": 1}, tags, 0.0, np.zeros(3), SIZE, "tet")
    return SimpleNamespace(housing=housing)


def box_centre_offset(model, surface, axis):
    """Distance (m) of the bounding-box centre of the surface's vertices from the tube's axis."""
    x, _, _ = bore_axis.surface_geometry(model, surface)
    c = (x.min(axis=0) + x.max(axis=0)) / 2 - ORIGIN
    return float(np.linalg.norm(c - (c @ axis) * axis))


@pytest.fixture(scope="module")
def tube(comm):
    return tube_model(comm, spin_deg=20.0)


@pytest.fixture(scope="module")
def tilted_tube(comm):
    return tube_model(comm, TILTED, spin_deg=20.0)


@pytest.fixture(scope="module")
def half_tube(comm):
    return tube_model(comm, half=True)


def check_on_axis(fit, axis):
    """The fit is the tube's bore: axis, radius, centre = the axis point at mid-length, to 1e-6 of the radius."""
    axis = np.asarray(axis, float)
    assert fit.kind == "cylinder"
    assert fit.tilt_deg(axis) < 1e-6
    assert abs(fit.radius - R_IN) < 1e-6 * R_IN
    assert np.linalg.norm(fit.centre - (ORIGIN + LENGTH / 2 * axis)) < 1e-6 * R_IN
    assert abs(fit.length - LENGTH) < 1e-9 and fit.rms < 1e-6 * R_IN


def test_a_coarse_bore_fits_on_its_axis_where_the_bounding_box_is_off(tube):
    z = np.array([0.0, 0.0, 1.0])
    fit = bore_axis.fit_bore(tube, "bore")
    check_on_axis(fit, z)
    assert box_centre_offset(tube, "bore", z) > 1e-3 * R_IN        # 6 elements round: the box is lopsided
    assert fit.summary()["radius_m"] == pytest.approx(R_IN, rel=1e-6)


def test_a_tilted_bore(tilted_tube):
    """Axis (1, 2, 3)/sqrt(14): fitted from the normals' start to round-off (the vertices' box is centred here too:
    the meshed tube is point-symmetric about its centre)."""
    fit = bore_axis.fit_bore(tilted_tube, "bore")
    check_on_axis(fit, TILTED)
    assert fit.axis[np.argmax(np.abs(fit.axis))] > 0       # the sense: largest component positive


def test_a_half_bore_fits_where_the_bounding_box_is_r_over_2_off(half_tube):
    z = np.array([0.0, 0.0, 1.0])
    fit = bore_axis.fit_bore(half_tube, "bore")
    check_on_axis(fit, z)
    # the box of a half circle: x from -r to r, y' from 0 to r -> its centre r/2 off the axis
    assert box_centre_offset(half_tube, "bore", z) == pytest.approx(R_IN / 2, rel=0.05)


def test_an_oil_hole_leaves_the_fit_on_the_axis(comm):
    """A 15 mm radial hole through the wall at mid-length: the bore surface loses a patch and its weights are uneven,
    the fit stays on the axis to round-off (the remaining vertices still lie on the cylinder).  (The box centre stays
    too: the bore's ends keep their extreme vertices.)"""
    model = tube_model(comm, oil_hole=0.015)
    check_on_axis(bore_axis.fit_bore(model, "bore"), np.array([0.0, 0.0, 1.0]))


def test_a_flat_face_is_a_seat_at_its_centroid(half_tube):
    """A flat surface has no axis: the master goes to its centre of area and the axis is its normal."""
    fit = bore_axis.fit_bore(half_tube, "seat")
    assert fit.kind == "flat" and math.isnan(fit.radius) and fit.summary()["radius_m"] is None
    centroid = ORIGIN + np.array([(R_IN + R_OUT) / 2, 0.0, LENGTH / 2])     # the cut rectangle's centre
    assert np.linalg.norm(fit.centre - centroid) < 1e-12
    assert fit.tilt_deg((0.0, 1.0, 0.0)) < 1e-6 and fit.rms < 1e-12
    _, w, _ = bore_axis.surface_geometry(half_tube, "seat")
    assert w.sum() == pytest.approx((R_OUT - R_IN) * LENGTH, rel=1e-12)     # the weights: the rectangle's area


def test_a_curved_surface_that_is_no_cylinder_is_refused_in_one_line(tube):
    """The bore with its end face: the best cylinder deviates by far more than faceting would."""
    with pytest.raises(InputError, match=r"^surface 'bore_and_end' is not a cylindrical bore: the best cylinder "
                                         r"\(radius .* leaves an rms deviation of .* of the radius \(at most 5%\)"
                       ) as err:
        bore_axis.fit_bore(tube, "bore_and_end")
    assert "\n" not in str(err.value)


def test_bore_matching_sees_the_coupling_s_cylinder(tilted_tube, tube, half_tube):
    """The run-up's bore matching (bore_matching.bore_shape) reads the same fit as the coupling: the tilted tube's
    axis, radius, mid-length centre and length to round-off, equal to fit_bore's; a flat seat is its plane (no
    radius, no extent); a bore with its end face is refused in one line under housing.bores."""
    from housingfe.drivetrain.bore_matching import bore_shape

    b, fit = bore_shape(tilted_tube, "t", "bore"), bore_axis.fit_bore(tilted_tube, "bore")
    assert np.array_equal(b.axis, fit.axis) and np.array_equal(b.centre, fit.centre) and b.radius == fit.radius
    assert abs(float(b.axis @ TILTED) - 1.0) < 1e-12 and abs(b.radius - R_IN) < 1e-9
    assert np.linalg.norm(b.centre - (ORIGIN + LENGTH / 2 * TILTED)) < 1e-9
    assert b.s_hi == -b.s_lo and abs(2 * b.s_hi - LENGTH) < 1e-9 and b.deviation < 1e-9
    seat = bore_shape(half_tube, "seat", "seat")
    assert math.isnan(seat.radius) and seat.s_lo == seat.s_hi == 0.0 and abs(seat.axis[1] - 1.0) < 1e-9
    with pytest.raises(InputError, match=r"^housing.bores: bore 'A': surface 'bore_and_end' is not a cylindrical "
                                         r"bore: the best cylinder") as err:
        bore_shape(tube, "A", "bore_and_end")
    assert "\n" not in str(err.value)


def test_the_coupling_refuses_a_bore_tilted_from_its_bearing(tube):
    """interior.bore_fits: the fitted axis against the axis of the bearing the bore carries (and the bore's own
    axis where the scene gives one); 0.5 deg passes, 2 deg is an error naming the bore, the axes and the angle."""
    from housingfe.drivetrain.interior import CouplingSpec, bore_centres, bore_fits

    def spec(bearing_deg, bore_axis_deg=None):
        tilt = lambda deg: (math.sin(math.radians(deg)), 0.0, math.cos(math.radians(deg)))   # noqa: E731
        bore = {"name": "b", "surface": "bore"}
        if bore_axis_deg is not None:
            bore["axis"] = tilt(bore_axis_deg)
        return CouplingSpec.model_validate({"bores": [bore], "bearings": [
            {"name": "front", "shaft_node": "s:0", "bore": "b", "axis": tilt(bearing_deg), "stiffness": [1e8] * 6}]})

    fits = bore_fits(tube, spec(0.5))
    assert fits["b"].kind == "cylinder"
    assert np.linalg.norm(bore_centres(tube, spec(0.5), fits)["b"] - (ORIGIN + [0, 0, LENGTH / 2])) < 1e-6 * R_IN
    with pytest.raises(InputError, match=r"^coupling.bores.0 \(b\): the bore surface 'bore' runs along \(0, 0, 1\), "
                                         r"2 deg from the axis \(0.0349, 0, 0.9994\) of bearing 'front' \(at most "
                                         r"1 deg\)$"):
        bore_fits(tube, spec(2.0))
    with pytest.raises(InputError, match=r"^coupling.bores.0 \(b\): .* 3 deg from its axis"):
        bore_fits(tube, spec(0.0, bore_axis_deg=3.0))
    given = spec(2.0).model_copy(update={"bores": [spec(2.0).bores[0].model_copy(update={"centre": (0, 0, 0)})]})
    assert bore_fits(tube, given) == {"b": None}          # a given centre: used as given, nothing fitted


def test_the_cli_refuses_a_curved_bore_that_is_no_cylinder(tmp_path):
    """`housingfe run` with a bore on the housing's inner surface (flat walls facing every way): one line naming the
    file, the key and the surface, exit 2, no result folder."""
    import os
    import subprocess
    import sys

    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    out = tmp_path / "result"
    proc = subprocess.run([sys.executable, "-m", "housingfe", "run", "test-gearbox-interior", "--set", "mesh.size=0.06",
                           "--set", 'coupling.bores.0.surface="inner"', "--out", str(out)],
                          capture_output=True, text=True, env=env, timeout=300)
    assert proc.returncode == 2, proc.stderr
    errors = [line for line in proc.stderr.splitlines() if line.startswith("housingfe: error:")]
    assert len(errors) == 1 and "Traceback" not in proc.stderr
    assert re.match(r"housingfe: error: .*test-gearbox-interior.toml: coupling.bores.0.surface: surface 'inner' is "
                    r"not a cylindrical bore: the best cylinder .* of the radius \(at most 5%\)", errors[0]), errors[0]
    assert not out.exists()


def test_the_test_gearbox_masters_sit_on_its_shaft_lines(tmp_path):
    """`housingfe run test-gearbox-interior` at 60 mm elements: harmonic.json records each bore's fit; the masters lie
    on the geometry's bore axes (x = -0.126 / 0.074 m, z = 0.2 m), mid-plate (y = -+0.1075 m), radius 85 mm, where the
    bounding boxes of the coarse front bores were 0.29 and 0.42 mm off."""
    import os
    import subprocess
    import sys

    out = tmp_path / "result"
    proc = subprocess.run([sys.executable, "-m", "housingfe", "run", "test-gearbox-interior", "--set", "mesh.size=0.06",
                           "--out", str(out)], capture_output=True, text=True,
                          env={**os.environ, "OPENBLAS_NUM_THREADS": "1"}, timeout=300)
    assert proc.returncode == 0, proc.stderr
    bores = json.loads((out / "harmonic.json").read_text())["bores"]
    box_offsets = {}
    for name, bore in bores.items():
        shaft, side = name.split("_")
        nominal = np.array([-0.126 if shaft == "pinion" else 0.074, -0.1075 if side == "front" else 0.1075, 0.2])
        assert bore["kind"] == "cylinder" and np.linalg.norm(np.subtract(bore["centre_m"], nominal)) < 1e-9, name
        assert abs(bore["axis"][1] - 1.0) < 1e-12 and bore["radius_m"] == pytest.approx(0.085, abs=1e-9)
        box = np.subtract(bore["box_centre_m"], nominal)
        box_offsets[name] = math.hypot(box[0], box[2])
    assert box_offsets["pinion_front"] == pytest.approx(0.29e-3, abs=0.01e-3)
    assert box_offsets["wheel_front"] == pytest.approx(0.42e-3, abs=0.01e-3)


def mpi_case(comm) -> dict:
    """The fits of the half and the tilted tube's surfaces (what 1 and 2 ranks must agree on)."""
    from housingfe.drivetrain.bore_matching import bore_shape

    out = {"ranks": comm.size}
    for name, model in (("half", tube_model(comm, half=True)), ("tilted", tube_model(comm, TILTED, spin_deg=20.0))):
        for surface in ("bore", "seat") if name == "half" else ("bore",):
            fit = bore_axis.fit_bore(model, surface)
            value = [float(v) for v in (*fit.centre, *fit.axis, 0.0 if math.isnan(fit.radius) else fit.radius)]
            out[f"{name}_{surface}"] = value
            out[f"{name}_{surface}_same_on_all_ranks"] = all(v == value for v in comm.allgather(value))
        shape = bore_shape(model, "b", "bore")           # the run-up's bore matching: the same fit
        out[f"{name}_shape"] = [float(v) for v in (*shape.centre, *shape.axis, shape.radius, shape.s_hi)]
        out[f"{name}_owned_bore_vertices"] = comm.allgather(owned_vertices(model, "bore"))
    return out


def owned_vertices(model, surface) -> int:
    """The surface's mesh vertices this rank owns (the fit gathers them from every rank)."""
    from dolfinx import fem

    V1 = fem.FunctionSpace(model.housing.mesh, ("CG", 1))
    nodes = fem.locate_dofs_topological(V1, 2, model.housing.facets(surface))
    return int(np.sum(nodes < V1.dofmap.index_map.size_local))


def test_two_ranks_fit_the_serial_bore(comm):
    if comm.size > 1 or not shutil.which("mpirun"):
        pytest.skip("runs from a one-rank session with mpirun installed")
    one = mpi_case(comm)
    two = module_result("tests.drivetrain.test_bore_axis")
    assert two["ranks"] == 2
    for name in ("half", "tilted"):     # each bore split between the ranks, every vertex owned once
        assert min(two[f"{name}_owned_bore_vertices"]) > 0
        assert sum(two[f"{name}_owned_bore_vertices"]) == sum(one[f"{name}_owned_bore_vertices"])
    for key in ("half_bore", "half_seat", "tilted_bore"):
        assert two[f"{key}_same_on_all_ranks"]
        assert np.max(np.abs(np.subtract(two[key], one[key]))) < 1e-12, key
    for key in ("half_shape", "tilted_shape"):
        assert np.max(np.abs(np.subtract(two[key], one[key]))) < 1e-12, key


if __name__ == "__main__":       # mpirun -n 2 python -m tests.drivetrain.test_bore_axis: the 2-rank half above
    from mpi4py import MPI

    result = mpi_case(MPI.COMM_WORLD)
    if MPI.COMM_WORLD.rank == 0:
        print(json.dumps(result))
