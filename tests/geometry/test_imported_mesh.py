"""A housing from a mesh file (geometry kind "mesh", housingfe.geometry.imported_mesh): round trips of the
built-in box meshes through Abaqus .inp, Nastran .bdf and gmsh .msh give the built-in modes to solver
round-off (1e-8 asserted; 1e-12 measured), in every cell type the reader takes (tet4, tet10, hex8, hex20 ->
hex27, hex27); node sets and physical surfaces become supports that give the built-in supported modes; two ranks
give the one-rank modes; bad files stop with one line naming the file and the key, exit 2, no result folder."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from housingfe import cli
from housingfe.errors import InputError
from housingfe.geometry.imported_mesh import read_mesh_file, write_mesh_file
from housingfe.scene import build_model_from_scene, load_housing_scene
from housingfe.solvers import modal
from tests.conftest import load_scene

F_MAX = {"hex": 2500.0, "tet": 10000.0}     # Hz: 16 elastic modes of the box, 11 of the block
ROUND_TRIP = 1e-8


def builtin(element: str, size: float, *extra):
    """The box-free scene (hexahedra) or, for tetrahedra, a steel block 300 x 200 x 40 mm (the box needs 35 mm
    tetrahedra, 34 k DOFs, to pass the element-quality check; the block has 11 elastic modes below 10 kHz at
    20 mm, 10 200 DOFs)."""
    if element == "tet":
        extra = ('geometry.kind="plate"', "geometry.a=0.3", "geometry.b=0.2", "geometry.h=0.04",
                 'material.name="steel"', "material.youngs_modulus=210e9", "material.density=7850.0") + extra
    return load_scene("nafems-fv12" if element == "tet" else "box-free", "mesh.degree=2", "mesh.grading=1",
                      f"mesh.size={size}", f'mesh.element="{element}"', f"analysis.modal.f_max={F_MAX[element]}",
                      *extra)


def mesh_scene(folder: Path, file: str, units: str = "mm", extra: str = "", f_max: float = 2500.0) -> Path:
    path = folder / f"{Path(file).stem}-{Path(file).suffix[1:]}.toml"
    path.write_text(f"""[scene]
name = "imported"
kind = "housing"
[geometry]
kind = "mesh"
file = "{file}"
units = "{units}"
{extra}
[mesh]
degree = 2
[analysis.modal]
f_max = {f_max}
[output]
mode_pictures = 0
paraview = false
pictures = false
""")
    return path


def frequencies(model):
    return modal.solve_modes(model.K, model.M, model.scene.analysis.modal.f_max).frequencies_hz


def assert_same_modes(f_import, f_builtin):
    assert len(f_import) == len(f_builtin) > 6 + 10
    elastic = slice(6, None)
    assert np.max(np.abs(f_import[elastic] / f_builtin[elastic] - 1)) < ROUND_TRIP


@pytest.mark.parametrize("element,size,files", [
    ("tet", 0.02, [("box.inp", None), ("box10.bdf", 2)]),                      # tet4 in mm, tet10
    ("hex", 0.06, [("box.bdf", None), ("box20.inp", 2), ("box27.msh", 2)]),      # hex8, hex20 -> hex27, hex27
])
def test_round_trip_gives_the_built_in_modes(comm, tmp_path, element, size, files):
    """Built-in box mesh -> file (coordinates in mm) -> kind "mesh": the same volume and modes; the quadratic
    variants carry straight-edge mid-nodes, so any node-order error would distort the cells and show."""
    model = build_model_from_scene(builtin(element, size), comm)
    reference = frequencies(model)
    for name, order in files:
        write_mesh_file(model.housing, tmp_path / name, units="mm", order=order)
        imported = build_model_from_scene(load_housing_scene(str(mesh_scene(tmp_path, name, f_max=F_MAX[element])))[0], comm)
        assert imported.dofs == model.dofs, name
        assert imported.housing.volume == pytest.approx(model.housing.volume, rel=1e-12)
        assert np.allclose(imported.housing.centroid, model.housing.centroid, rtol=0, atol=1e-12)
        assert_same_modes(frequencies(imported), reference)


def _small_field_rbe2(eid: int, independent: int, grids) -> str:
    """An RBE2 card in small (8-character) fixed field with "+" continuations, as Nastran pre-processors write."""
    fields = [str(eid), str(independent), "123456"] + [str(g) for g in grids]
    lines, first = [], fields[:8]
    lines.append("RBE2    " + "".join(f"{f:<8s}" for f in first) + "+C1")
    rest = fields[8:]
    for k in range(0, len(rest), 8):
        lines.append("+C1     " + "".join(f"{f:<8s}" for f in rest[k:k + 8]) + ("+C1" if k + 8 < len(rest) else ""))
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("suffix", [".inp", ".msh", ".bdf"])
def test_sets_become_named_surfaces_and_supports(comm, tmp_path, suffix):
    """Abaqus node sets, gmsh physical surfaces and Nastran SET1 / RBE2 dependent grids named in
    [[geometry.surfaces]] / [[geometry.bores]] become facet groups with the built-in facets; supports on them give
    the built-in supported box's modes."""
    supports = ['supports=[{surface="bolt_1", kind="fixed"}, {surface="bolt_5", kind="fixed"}]']
    model = build_model_from_scene(builtin("hex", 0.06, *supports), comm)
    path = write_mesh_file(model.housing, tmp_path / f"box{suffix}", units="m", node_sets=["bolt_1", "bolt_5"])
    sets = {"bolt_1": "bolt_1", "bolt_5": "bolt_5"}
    if suffix == ".bdf":        # SET1 1 = bolt_1 (written); bolt_5 as the dependent grids of an RBE2 spider
        text = path.read_text()
        head, body = text.split("$ SET1 2: bolt_5\n")
        grids = [int(g) for line in body.split("ENDDATA")[0].splitlines() for g in line.split(",")[1:] if g]
        grids = grids[1:]       # the SID
        path.write_text(head + _small_field_rbe2(99, grids[0], grids) + "ENDDATA\n")
        sets = {"bolt_1": "SET1_1", "bolt_5": "RBE2_99"}
    extra = (f'[[geometry.bores]]\nname = "bolt_1"\nset = "{sets["bolt_1"]}"\n'
             f'[[geometry.surfaces]]\nname = "bolt_5"\nset = "{sets["bolt_5"]}"\n'
             '[[supports]]\nsurface = "bolt_1"\nkind = "fixed"\n[[supports]]\nsurface = "bolt_5"\nkind = "fixed"\n')
    scene = load_housing_scene(str(mesh_scene(tmp_path, f"box{suffix}", units="m", extra=extra)))[0]
    imported = build_model_from_scene(scene, comm)
    for name in ("bolt_1", "bolt_5"):
        assert len(imported.housing.facets(name)) == len(model.housing.facets(name)) > 0
    outer = imported.housing.facets("outer")
    n_boundary = len(np.unique(np.concatenate([model.housing.facet_tags.find(v)
                                               for v in np.unique(model.housing.facet_tags.values)])))
    assert len(outer) == n_boundary
    f_builtin = frequencies(model)
    f_import = frequencies(imported)
    assert len(f_import) == len(f_builtin) and f_builtin[0] > 100.0       # supported: no rigid modes
    assert np.max(np.abs(f_import / f_builtin - 1)) < ROUND_TRIP


def test_nastran_set_cards_in_every_field_format(tmp_path):
    """SET1 (with THRU) and RBE2 in free, small and large field with continuations; CP != 0 is refused."""
    from housingfe.geometry.imported_mesh import _nastran_node_sets

    path = tmp_path / "sets.bdf"
    path.write_text("BEGIN BULK\n"
                    "SET1,7,1,2,5,THRU,8\n"
                    "SET1    8       20      THRU    23      30                              +S\n"
                    "+S      31      32\n"
                    "RBE2*   11              100             123456          40              *R\n"
                    "*R      41              42\n"
                    "RBE2,12,100,123456,50,51,,,,\n+,52,1.0e-5\n"
                    "ENDDATA\n")
    assert _nastran_node_sets(path) == {"SET1_7": [1, 2, 5, 6, 7, 8], "SET1_8": [20, 21, 22, 23, 30, 31, 32],
                                        "RBE2_11": [40, 41, 42], "RBE2_12": [50, 51, 52]}
    local = tmp_path / "local.bdf"
    local.write_text("BEGIN BULK\nGRID,1,,0.,0.,0.\nGRID,2,1,100.,0.,0.\nGRID,3,,0.,100.,0.\nGRID,4,,0.,0.,100.\n"
                     "CTETRA,1,1,1,2,3,4\nENDDATA\n")
    with pytest.raises(InputError, match="local.bdf: geometry.file: GRID cards with a coordinate system CP other"):
        read_mesh_file(local, "mm")


def test_a_gmsh_file_with_physical_groups(tmp_path, comm):
    """A .msh 4.1 written by gmsh itself (10-node tetrahedra of a 300 x 200 x 40 mm block, physical volume and
    a physical surface "BOTTOM"): exact volume, the named surface's and the skin's exact areas, regions by the
    physical volume's name."""
    import gmsh
    import ufl
    from dolfinx import fem

    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("block")
        v = gmsh.model.occ.addBox(0, 0, 0, 300, 200, 40)
        gmsh.model.occ.synchronize()
        bottom = [t for _, t in gmsh.model.getBoundary([(3, v)], oriented=False)
                  if abs(gmsh.model.occ.getCenterOfMass(2, t)[2]) < 1e-9]
        gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, [v]), "solid")
        gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, bottom), "BOTTOM")
        gmsh.option.setNumber("Mesh.MeshSizeMax", 20.0)
        gmsh.option.setNumber("Mesh.ElementOrder", 2)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.model.mesh.generate(3)
        gmsh.write(str(tmp_path / "block.msh"))
    finally:
        gmsh.finalize()
    extra = '[[geometry.surfaces]]\nname = "bottom"\nset = "BOTTOM"\n'
    model = build_model_from_scene(load_housing_scene(str(mesh_scene(tmp_path, "block.msh", extra=extra)))[0], comm)
    housing = model.housing
    assert housing.volume == pytest.approx(0.3 * 0.2 * 0.04, rel=1e-12)
    assert np.allclose(housing.centroid, [0.15, 0.1, 0.02], rtol=0, atol=1e-12)
    assert "solid" in housing.cell_groups and "tetra10" in housing.quality["mesher"]
    ds = ufl.Measure("ds", domain=housing.mesh, subdomain_data=housing.facet_tags)
    area = {n: comm.allreduce(fem.assemble_scalar(fem.form(fem.Constant(housing.mesh, 1.0)
                                                           * ds(housing.facet_tag_values(n)))))
            for n in ("bottom", "outer")}
    assert area["bottom"] == pytest.approx(0.06, rel=1e-12)
    assert area["outer"] == pytest.approx(2 * (0.06 + 0.012 + 0.008), rel=1e-12)


def test_units_are_honoured_and_checked(tmp_path, comm):
    """The same file declared in mm is 1000 x smaller than in m; a size implausible for the unit says which
    unit fits."""
    model = build_model_from_scene(builtin("hex", 0.06), comm)
    write_mesh_file(model.housing, tmp_path / "box.inp", units="mm")
    mm = read_mesh_file(tmp_path / "box.inp", "mm")
    assert np.ptp(mm.points[:, 0]) == pytest.approx(0.325 + 2 * 0.073, rel=1e-12)
    with pytest.raises(InputError, match=r"box.inp: geometry.units: the mesh is 471 m across in m.*"
                                         r"read in mm it is 0.471 m: set geometry.units = \"mm\""):
        read_mesh_file(tmp_path / "box.inp", "m")


# ------------------------------------------------------------------------------------------------- MPI
def mpi_modes(scene_path: str, comm) -> dict:
    model = build_model_from_scene(load_housing_scene(scene_path)[0], comm)
    return {"dofs": model.dofs, "f": frequencies(model).tolist(), "volume": model.housing.volume,
            "outer": comm.allreduce(len(model.housing.facets("outer")))}


@pytest.mark.mpi
def test_two_ranks_give_the_one_rank_modes(comm, tmp_path):
    if not shutil.which("mpirun"):
        pytest.skip("mpirun not installed")
    model = build_model_from_scene(builtin("tet", 0.02), comm)
    write_mesh_file(model.housing, tmp_path / "box.inp", units="mm", order=2)
    scene = str(mesh_scene(tmp_path, "box.inp", f_max=F_MAX["tet"]))
    one = mpi_modes(scene, comm)
    env = {**os.environ, "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OPENBLAS_NUM_THREADS": "1"}
    proc = subprocess.run([shutil.which("mpirun"), "-n", "2", sys.executable, "-m",
                           "tests.geometry.test_imported_mesh", scene], capture_output=True, text=True, env=env,
                          timeout=300, cwd=Path(__file__).parents[2])
    assert proc.returncode == 0, proc.stderr
    two = json.loads(proc.stdout.strip().splitlines()[-1])
    assert two["dofs"] == one["dofs"] and two["outer"] >= one["outer"]     # ghost facets count on both ranks
    assert two["volume"] == pytest.approx(one["volume"], rel=1e-12)
    assert_same_modes(np.array(two["f"]), np.array(one["f"]))


# ------------------------------------------------------------------------------------------------ bad input
def _bad(tmp_path, capsys, scene: Path, *match):
    out = tmp_path / "results"
    code = cli.main(["run", str(scene), "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert len(err.splitlines()) == 1 and err.startswith("housingfe: error: "), err
    for m in match:
        assert m in err, err
    assert not out.exists() and not list(tmp_path.glob("results.tmp*"))
    return err


def test_bad_mesh_files(tmp_path, capsys, comm):
    import meshio

    model = build_model_from_scene(builtin("hex", 0.06), comm)
    write_mesh_file(model.housing, tmp_path / "box.inp", units="mm", node_sets=["bolt_1"])
    # no volume cells: a surface mesh
    meshio.write(str(tmp_path / "skin.msh"), meshio.Mesh(np.eye(3) * 0.1, [("triangle", np.array([[0, 1, 2]]))]),
                 file_format="gmsh22", binary=False)
    capsys.readouterr()         # meshio's warnings while writing the test file
    _bad(tmp_path, capsys, mesh_scene(tmp_path, "skin.msh", "m"), "skin.msh: geometry.file: no volume cells")
    # a set name that does not exist
    extra = '[[geometry.bores]]\nname = "B1"\nset = "BORE1"\n'
    _bad(tmp_path, capsys, mesh_scene(tmp_path, "box.inp", extra=extra),
         "box.inp: geometry.bores.0.set: no node or surface set 'BORE1' in the file (it has: bolt_1)")
    # unknown and unreadable files
    _bad(tmp_path, capsys, mesh_scene(tmp_path, "missing.inp"), "missing.inp: geometry.file: mesh file not found")
    (tmp_path / "garbage.bdf").write_text("this is no bulk data\nGRID,1,,x,y\n")
    _bad(tmp_path, capsys, mesh_scene(tmp_path, "garbage.bdf"), "garbage.bdf: geometry.file: cannot read")
    (tmp_path / "photo.jpg").write_bytes(b"\xff\xd8\xff\xe0 not a mesh")
    _bad(tmp_path, capsys, mesh_scene(tmp_path, "photo.jpg"), "photo.jpg: geometry.file: cannot read")
    # mm read as m
    _bad(tmp_path, capsys, mesh_scene(tmp_path, "box.inp", "m"), "box.inp: geometry.units:",
         'set geometry.units = "mm"')


def test_a_gmsh_1_file_is_one_line_not_meshios_exit(tmp_path, capsys):
    """meshio reads a .msh as ANSYS, then gmsh; when both raise its ReadError it prints "Error: ..." and calls
    sys.exit(1): `housingfe run` ended with exit 1 and meshio's line instead of naming geometry.file."""
    (tmp_path / "old.msh").write_text("$NOD\n1\n1 0 0 0\n$ENDNOD\n$ELM\n0\n$ENDELM\n")     # gmsh 1.0: no $MeshFormat
    _bad(tmp_path, capsys, mesh_scene(tmp_path, "old.msh", "m"), "old.msh: geometry.file: cannot read as a mesh",
         "as either of ansys, gmsh")


def test_memory_guard_names_the_mesh_file(tmp_path, comm, monkeypatch):
    """The model-size guard counts the DOFs from the file's vertices, edges, faces and cells (the box: 10 557 at
    Q2 from the linear and the quadratic file, 44 256 at Q3) and stops before building anything when that needs
    more memory than the machine has."""
    from housingfe.fe import model as model_module
    from housingfe.geometry.mesh import estimate_dofs

    model = build_model_from_scene(builtin("hex", 0.06), comm)
    write_mesh_file(model.housing, tmp_path / "box.inp", units="mm", order=2)
    write_mesh_file(model.housing, tmp_path / "box8.inp", units="mm")
    scene = load_housing_scene(str(mesh_scene(tmp_path, "box.inp")))[0]
    linear = load_housing_scene(str(mesh_scene(tmp_path, "box8.inp")))[0]
    assert estimate_dofs(scene.geometry, "hex", 2, 0.0, 1) == estimate_dofs(linear.geometry, "hex", 2, 0.0, 1) \
        == model.dofs
    q3 = build_model_from_scene(builtin("hex", 0.06, "mesh.degree=3"), comm)
    assert estimate_dofs(linear.geometry, "hex", 3, 0.0, 1) == q3.dofs
    monkeypatch.setattr(model_module, "available_memory_bytes", lambda: (int(0.2e9), int(1e9)))
    with pytest.raises(InputError, match=r"box.inp: mesh.degree: model too large: ~10,557 DOFs at degree 2 "
                                         r".*set mesh.allow_large = true"):
        build_model_from_scene(scene, comm)


if __name__ == "__main__":       # mpirun -n 2 python -m tests.geometry.test_imported_mesh SCENE: the 2-rank half
    from mpi4py import MPI

    result = mpi_modes(sys.argv[1], MPI.COMM_WORLD)
    if MPI.COMM_WORLD.rank == 0:
        print(json.dumps(result))
