"""The CalculiX decks of `housingfe bench modal`: CalculiX solves the very mesh housingfe solves (the ratio at
<= 1 % compares solvers on one discretisation), with 20-node bricks for C3D20R and linear ones for C3D8I."""
import re

import pytest

from housingfe.benchmarks.modal import write_calculix_deck


def _elements(deck: str) -> list[list[int]]:
    body = deck.split("*ELEMENT", 1)[1].split("*MATERIAL", 1)[0]
    rows = [line for line in body.splitlines()[1:] if line.strip() and not line.startswith("*")]
    # gmsh writes long element rows over two lines (a trailing comma continues the row)
    joined = re.sub(r",\s*\n", ",", "\n".join(rows)).splitlines()
    return [[int(v) for v in row.split(",") if v.strip()] for row in joined]


@pytest.mark.parametrize("case, dofs, nodes_per_element", [
    # housingfe's S2R on these meshes: 39 588 and 31 926 DOFs (bench modal; tests/fe/test_element_families.py)
    ({"ccx_type": "C3D20R", "size": 0.030, "layers": 3}, 39588, 20),
    ({"ccx_type": "C3D20R", "size": 0.030, "layers": 1, "layer_size": 0.004, "grading": 0.5}, 31926, 20),
    ({"ccx_type": "C3D8I", "size": 0.015, "layers": 3}, 27780, 8),
])
def test_calculix_gets_the_mesh_housingfe_solves(tmp_path, case, dofs, nodes_per_element):
    n_nodes, n_elements = write_calculix_deck({"element": "hex", **case}, tmp_path / "box.inp")
    assert 3 * n_nodes == dofs
    elements = _elements((tmp_path / "box.inp").read_text())
    assert len(elements) == n_elements
    assert {len(e) - 1 for e in elements} == {nodes_per_element}     # element id, then its nodes
    assert f"TYPE={case['ccx_type']}" in (tmp_path / "box.inp").read_text()
