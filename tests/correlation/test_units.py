"""Measured data in real units: UFF dataset 164 converts coordinates to m, `units` (--units, an update target's
`units`) does where a file has none, a contradiction is an error, and measured points far from the surface say
which unit would fit.  End to end on the coarse box: our own modes exported, rewritten in mm with and without
164, correlated back (MAC 1 on the paired modes)."""
import numpy as np
import pytest

from housingfe.cli import main
from housingfe.correlation.uff import ModeSet, Nodes, read_measured_modes, read_uff, write_uff
from housingfe.errors import InputError

BOX = ["--set", "mesh.degree=2", "--set", "mesh.size=0.06", "--set", "mesh.grading=1", "--set",
       'mesh.element="hex"']


def _nodes_and_modes():
    nodes = Nodes(np.array([3, 7]), np.array([[0.1625, -0.05, 0.125], [-0.2, 0.11, 0.004]]))
    shapes = np.arange(1.0, 7.0)[:, None] * np.array([[1.0, -0.5]])
    return nodes, ModeSet(np.array([650.0, 900.0]), np.repeat(nodes.ids, 3), np.repeat(nodes.xyz, 3, axis=0),
                          np.tile(np.eye(3), (2, 1)), shapes, np.zeros(2))


@pytest.mark.parametrize("with_164", [True, False])
def test_164_in_mm_or_given_units_give_metres(tmp_path, with_164):
    nodes, modes = _nodes_and_modes()
    path = tmp_path / "ema.uff"
    write_uff(path, nodes, modes, units="mm", units_dataset=with_164)
    raw = read_uff(path).nodes.xyz
    assert np.allclose(raw, nodes.xyz * (1.0 if with_164 else 1e3), rtol=1e-12)    # without 164: read as m
    assert np.allclose(read_measured_modes(path, "mm").points[::3], nodes.xyz, rtol=1e-12)
    if with_164:
        with pytest.raises(InputError, match=r"ema.uff: --units: in contradicts the file's units dataset 164 "
                                             r"\(MM \(mm\), 0.001 m per unit\)"):
            read_uff(path, "in")


def test_csv_table_in_given_units(tmp_path):
    path = tmp_path / "modes.csv"
    path.write_text("mode,frequency_hz,point,x,y,z,dx,dy,dz,value\n1,100.0,1,1.0,0,2.0,0,0,1,1.0\n")
    assert np.allclose(read_measured_modes(path, "in").points[0], [0.0254, 0.0, 0.0508], rtol=1e-12)


def test_correlate_in_mm_says_which_unit_fits_and_runs_with_it(tmp_path, capsys):
    """Our modes at 12 surface points, written in mm: without 164 correlate refuses with the unit that fits;
    with --units mm, or with a 164 dataset, it pairs the modes at MAC 1."""
    exported = tmp_path / "ours.uff"
    assert main(["correlate", "box-free", "--export", str(exported), "--points", "12", *BOX,
                 "--set", "analysis.modal.f_max=1500.0"]) == 0
    data = read_uff(exported)
    assert data.nodes is not None and data.modes.n_modes >= 4
    modes = read_measured_modes(exported)
    modes = ModeSet(modes.frequencies_hz[:4], modes.node_ids, modes.points, modes.directions, modes.shapes[:, :4],
                    None)
    bare, with_164 = tmp_path / "mm.uff", tmp_path / "mm164.uff"
    write_uff(bare, data.nodes, modes, units="mm", units_dataset=False)
    write_uff(with_164, data.nodes, modes, units="mm")
    capsys.readouterr()

    out = tmp_path / "refused"
    assert main(["correlate", "box-free", "--measured", str(bare), "--out", str(out), *BOX]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(bare) in err, err
    assert "the points fit the surface if read in mm (--units mm)" in err, err
    assert not out.exists()

    for path, extra in ((bare, ["--units", "mm"]), (with_164, [])):
        out = tmp_path / f"ok-{path.stem}"
        assert main(["correlate", "box-free", "--measured", str(path), "--out", str(out), *extra, *BOX]) == 0
        pairs = np.genfromtxt(out / "pairs.csv", delimiter=",", names=True)
        assert len(pairs) == 4
        assert np.all(pairs["mac"] > 0.999) and np.all(np.abs(pairs["error_percent"]) < 1e-3)
