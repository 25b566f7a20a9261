"""UFF and CSV: round trip of nodes, modes and FRFs; bad files are one-line InputErrors naming the file."""
import numpy as np
import pytest

from housingfe.correlation.uff import (
    FRF,
    ModeSet,
    Nodes,
    read_measured_modes,
    read_mode_csv,
    read_uff,
    write_uff,
)
from housingfe.errors import InputError


def _modes(rng, n_nodes=6, n_modes=4, dtype=float):
    ids = np.arange(11, 11 + n_nodes)
    xyz = rng.uniform(-0.2, 0.2, (n_nodes, 3))
    shapes = rng.standard_normal((3 * n_nodes, n_modes)).astype(dtype)
    if dtype is complex:
        shapes = shapes + 1j * rng.standard_normal(shapes.shape)
    return Nodes(ids, xyz), ModeSet(np.sort(rng.uniform(100, 4000, n_modes)), np.repeat(ids, 3),
                                    np.repeat(xyz, 3, axis=0), np.tile(np.eye(3), (n_nodes, 1)), shapes,
                                    np.linspace(0.001, 0.004, n_modes))


@pytest.mark.parametrize("dtype", [float, complex])
def test_uff_round_trip(tmp_path, dtype):
    rng = np.random.default_rng(5)
    nodes, modes = _modes(rng, dtype=dtype)
    f = np.arange(5.0, 2000.0, 5.0)
    frfs = [FRF(12, np.array([0, 0, 1.0]), 11, np.array([-1.0, 0, 0]), f, 1 / (1e6 - (2 * np.pi * f) ** 2 + 1e3j), "H"),
            FRF(13, np.array([0, 1.0, 0]), 11, np.array([-1.0, 0, 0]), np.array([1.0, 3.0, 7.0]),
                np.array([1 + 2j, 3 - 1j, 0.5j]))]   # uneven lines
    path = tmp_path / "ema.uff"
    write_uff(path, nodes, modes, frfs)
    back = read_uff(path)
    assert np.array_equal(back.nodes.ids, nodes.ids)
    assert np.allclose(back.nodes.xyz, nodes.xyz, rtol=1e-12, atol=1e-14)
    # UFF 55 stores 6 significant digits (E13.5)
    assert np.allclose(back.modes.frequencies_hz, modes.frequencies_hz, rtol=1e-5)
    assert np.allclose(back.modes.shapes, modes.shapes, rtol=1e-5, atol=1e-5 * np.abs(modes.shapes).max())
    assert np.allclose(back.modes.points, modes.points) and np.allclose(back.modes.directions, modes.directions)
    assert np.allclose(back.modes.damping, modes.damping, rtol=1e-5)
    for a, b in zip(back.frfs, frfs):
        assert (a.response_node, a.reference_node) == (b.response_node, b.reference_node)
        assert np.allclose(a.response_direction, b.response_direction)
        assert np.allclose(a.reference_direction, b.reference_direction)
        assert np.allclose(a.frequencies_hz, b.frequencies_hz, rtol=1e-6)
        assert np.allclose(a.values, b.values, rtol=1e-6)


def test_unmeasured_directions_are_dropped(tmp_path):
    rng = np.random.default_rng(6)
    nodes, modes = _modes(rng)
    modes.shapes[0::3] = 0.0                      # x never measured
    write_uff(tmp_path / "z.uff", nodes, modes)
    back = read_measured_modes(tmp_path / "z.uff")
    assert len(back.node_ids) == 2 * len(nodes.ids)
    assert not np.any(np.abs(back.directions[:, 0]) > 0)


def test_csv_mode_table(tmp_path):
    text = "mode,frequency_hz,point,x,y,z,dx,dy,dz,value\n"
    for mode, f in ((2, 900.0), (1, 641.0)):
        for p, (x, d) in enumerate(((0.1, "0,0,2"), (0.2, "0,0,1"), (0.2, "1,0,0"))):
            text += f"{mode},{f},{p + 1},{x},0.05,0.125,{d},{mode * (p + 1)}\n"
    (tmp_path / "m.csv").write_text(text)
    m = read_mode_csv(tmp_path / "m.csv")
    assert np.allclose(m.frequencies_hz, [641.0, 900.0])            # sorted by frequency
    assert np.allclose(m.shapes, [[1, 2], [2, 4], [3, 6]])
    assert np.allclose(m.directions[0], [0, 0, 1])                   # normalised


@pytest.mark.parametrize("content,match", [
    (b"this is not a universal file\n", "not a readable universal file|no UFF"),
    (b"    -1\n    55\ngarbage\n    -1\n", "not a readable universal file|no UFF"),
])
def test_unreadable_uff_is_one_line_input_error(tmp_path, content, match):
    path = tmp_path / "bad.uff"
    path.write_bytes(content)
    with pytest.raises(InputError, match=match) as exc:
        read_measured_modes(path)
    assert str(path) in str(exc.value) and "\n" not in str(exc.value)


def test_missing_file_and_bad_csv(tmp_path):
    with pytest.raises(InputError, match="not found"):
        read_measured_modes(tmp_path / "none.uff")
    (tmp_path / "b.csv").write_text("mode,frequency_hz,point,x,y,z,dx,dy,dz,value\n1,abc,1,0,0,0,0,0,1,1\n")
    with pytest.raises(InputError, match=r"b.csv: row 2"):
        read_mode_csv(tmp_path / "b.csv")
    (tmp_path / "c.csv").write_text("mode,frequency_hz,point\n1,2,3\n")
    with pytest.raises(InputError, match="column 'x' missing"):
        read_mode_csv(tmp_path / "c.csv")


def test_truncated_uff_bom_csv_and_repeated_channel(tmp_path):
    """A universal file cut inside its last dataset gave the modes before the cut without a word (pyuff drops the
    open dataset: 1 of 4 modes at half the file); a CSV saved with a byte-order mark (a spreadsheet's "CSV UTF-8")
    was "column 'mode' missing"; a channel given twice for one mode kept the later value silently."""
    nodes, modes = _modes(np.random.default_rng(5))
    write_uff(tmp_path / "ema.uff", nodes, modes, [])
    raw = (tmp_path / "ema.uff").read_bytes()
    assert len(read_measured_modes(tmp_path / "ema.uff").frequencies_hz) == 4
    for cut in (len(raw) // 2, len(raw) - 8):
        (tmp_path / "cut.uff").write_bytes(raw[:cut])
        with pytest.raises(InputError, match=r"cut.uff: truncated: the file ends inside a dataset"):
            read_measured_modes(tmp_path / "cut.uff")
    header = "mode,frequency_hz,point,x,y,z,dx,dy,dz,value\n"
    (tmp_path / "bom.csv").write_bytes(("\ufeff" + header + "1,641,1,0,0,0,0,0,1,0.5\n").encode())
    bom = read_measured_modes(tmp_path / "bom.csv")
    assert bom.frequencies_hz.tolist() == [641.0] and bom.shapes.tolist() == [[0.5]]
    (tmp_path / "twice.csv").write_text(header + "1,641,1,0,0,0,0,0,1,0.5\n1,641,1,0,0,0,0,0,1,0.7\n")
    with pytest.raises(InputError, match=r"twice.csv: row 3: mode 1, point 1, direction \(0, 0, 1\) is given twice"):
        read_measured_modes(tmp_path / "twice.csv")
