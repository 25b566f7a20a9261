"""Measured and computed modal data as universal files (UFF, via pyuff) and CSV mode tables.

A mode set is held per *channel*: one measured point and one unit direction (global x/y/z for a UFF 55 file,
any unit vector in a CSV table).  Shapes are (channels x modes), real or complex, in the units of the file
(only MAC-type, scale-free comparisons are made with them).  Coordinates are in m, frequencies in Hz.

Units: coordinates are converted to m by the file's units dataset 164 (SI = file value / its length factor:
1000 for mm) or, where the file has none, by the `units` a caller gives ("m", "mm", "cm", "in"; `housingfe
correlate --units`, an update target's `units`); a given unit that contradicts the file's 164 is an error.
Without either, coordinates are taken as m.  Shapes and FRF values stay in the file's units (MAC and FRAC are
scale-free).

UFF datasets used: 164 (units), 15 and 2411 (nodes), 55 (modes at nodes, 3 translations per node), 58 (FRFs, one
response/reference channel pair per dataset).  Writing uses the same datasets, so users' EMA tools read our
modes, point FRFs and geometry.
"""
from __future__ import annotations

import csv
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from housingfe.errors import InputError

_AXES = np.eye(3)
# metres per unit of length of a measured file's coordinates
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "in": 0.0254}
# UFF 164 units codes (1 SI, 2 BG foot, 3 MG metre, 4 BA foot, 5 MM, 6 CM, 7 IN, 8 GM mm, 9 user)
_UFF_UNITS_NAME = {1: "SI (m)", 2: "BG (ft)", 3: "MG (m)", 4: "BA (ft)", 5: "MM (mm)", 6: "CM (cm)", 7: "IN (in)",
                   8: "GM (mm)", 9: "user-defined"}
# UFF 58 direction codes: 1..3 = +x..+z, -1..-3 = -x..-z
_DIR_CODE = {1: _AXES[0], 2: _AXES[1], 3: _AXES[2], -1: -_AXES[0], -2: -_AXES[1], -3: -_AXES[2]}


@dataclass
class Nodes:
    """Measurement points: ids and coordinates (n, 3) in m."""

    ids: np.ndarray
    xyz: np.ndarray

    def coordinates(self, ids) -> np.ndarray:
        """Coordinates (m) of the given node ids; InputError for an id without coordinates."""
        index = {int(i): k for k, i in enumerate(self.ids)}
        missing = [int(i) for i in ids if int(i) not in index]
        if missing:
            raise InputError(f"node {missing[0]}: has no coordinates (no UFF 15/2411 entry)")
        return self.xyz[[index[int(i)] for i in ids]]


@dataclass
class ModeSet:
    """Mode shapes per channel.  frequencies_hz (modes,); node_ids, points (channels, 3) m, directions
    (channels, 3) unit vectors; shapes (channels, modes); damping: modal damping ratios (modes,) or None."""

    frequencies_hz: np.ndarray
    node_ids: np.ndarray
    points: np.ndarray
    directions: np.ndarray
    shapes: np.ndarray
    damping: np.ndarray | None = None
    source: str = ""

    @property
    def n_modes(self) -> int:
        return len(self.frequencies_hz)

    def drop_empty_channels(self) -> "ModeSet":
        """The same set without channels that are zero in every mode (directions a UFF 55 file did not
        measure)."""
        keep = np.any(np.abs(self.shapes) > 0, axis=1)
        return ModeSet(self.frequencies_hz, self.node_ids[keep], self.points[keep], self.directions[keep],
                       self.shapes[keep], self.damping, self.source)


@dataclass
class FRF:
    """One frequency response function: response node/direction over reference node/direction;
    frequencies (Hz) and complex values (units as in the file, e.g. m/s/N)."""

    response_node: int
    response_direction: np.ndarray
    reference_node: int
    reference_direction: np.ndarray
    frequencies_hz: np.ndarray
    values: np.ndarray
    label: str = ""


@dataclass
class UffData:
    """Everything read from one universal file."""

    nodes: Nodes | None
    modes: ModeSet | None
    frfs: list = field(default_factory=list)


# ------------------------------------------------------------------------------------------------ reading
def _sets(path: Path) -> list[dict]:
    import pyuff

    if not path.is_file():
        raise InputError(f"{path}: file not found")
    try:
        sets = pyuff.UFF(str(path)).read_sets()
    except Exception as exc:  # pyuff raises bare Exceptions, IndexErrors, ValueErrors on malformed files
        raise InputError(f"{path}: not a readable universal file ({type(exc).__name__}: {exc})") from None
    sets = [sets] if isinstance(sets, dict) else list(sets)
    if not sets:
        raise InputError(f"{path}: no UFF datasets in the file")
    with open(path, "rb") as fh:      # pyuff drops a last dataset cut short without a word (fewer modes)
        fh.seek(max(0, path.stat().st_size - 256))
        tail = fh.read().rstrip().splitlines()
    if not tail or tail[-1].strip() != b"-1":
        raise InputError(f"{path}: truncated: the file ends inside a dataset (no closing '    -1' line)")
    return sets


def length_scale(path: Path, sets: list[dict], units: str | None = None, key: str = "--units") -> float:
    """Metres per unit of the file's coordinates: from its units dataset 164 (SI = value / length factor), else
    from `units` (LENGTH_UNITS), else 1.  InputError naming the file and `key` when both are given and differ."""
    if units is not None and units not in LENGTH_UNITS:
        raise InputError(f"{path}: {key}: unknown unit {units!r} (one of {', '.join(LENGTH_UNITS)})")
    given = LENGTH_UNITS[units] if units is not None else None
    unit_sets = [s for s in sets if s.get("type") == 164]
    if not unit_sets:
        return given if given is not None else 1.0
    factor = float(unit_sets[0].get("length", 1.0) or 1.0)
    if not np.isfinite(factor) or factor <= 0:
        raise InputError(f"{path}: UFF 164: length factor {factor} is not a positive number")
    scale = 1.0 / factor
    if given is not None and abs(given / scale - 1) > 1e-6:
        code = int(unit_sets[0].get("units_code", 9) or 9)
        raise InputError(f"{path}: {key}: {units} contradicts the file's units dataset 164 "
                         f"({_UFF_UNITS_NAME.get(code, code)}, {scale:g} m per unit); drop {key} or fix the file")
    return scale


def read_uff(path: str | Path, units: str | None = None, key: str = "--units") -> UffData:
    """Read nodes (15/2411), modes (55, analysis type 2/3: normal or complex modes) and FRFs (58) from a
    universal file, coordinates in m (see length_scale: the file's 164, else `units`, else m).  Nodes are
    needed to place the mode channels; InputError naming the file otherwise."""
    path = Path(path)
    sets = _sets(path)
    scale = length_scale(path, sets, units, key)
    nodes = None
    node_sets = [s for s in sets if s.get("type") in (15, 2411)]
    if node_sets:
        ids = np.concatenate([np.asarray(s["node_nums"], int) for s in node_sets])
        xyz = np.concatenate([np.column_stack([s["x"], s["y"], s["z"]]) for s in node_sets])
        nodes = Nodes(ids, xyz.astype(float) * scale)
    mode_sets = [s for s in sets if s.get("type") == 55]
    modes = None
    if mode_sets:
        if nodes is None:
            raise InputError(f"{path}: UFF 55 modes but no UFF 15/2411 nodes to place them")
        modes = _modes_from_55(path, mode_sets, nodes)
    frfs = [_frf_from_58(s) for s in sets if s.get("type") == 58]
    if modes is None and not frfs and nodes is None:
        found = sorted({s.get("type") for s in sets})
        raise InputError(f"{path}: no UFF 15/2411/55/58 datasets (found types {found})")
    return UffData(nodes, modes, frfs)


def _modes_from_55(path: Path, sets: list[dict], nodes: Nodes) -> ModeSet:
    ids = np.asarray(sets[0]["node_nums"], int)
    freqs, shapes, damping = [], [], []
    for k, s in enumerate(sets):
        if not np.array_equal(np.asarray(s["node_nums"], int), ids):
            raise InputError(f"{path}: UFF 55 dataset {k + 1}: other nodes than the first mode set")
        comps = [np.asarray(s[f"r{i}"]) for i in (1, 2, 3)]
        shapes.append(np.column_stack(comps).reshape(-1))      # node-major: (n1 x, n1 y, n1 z, n2 x, ...)
        if "freq" in s:
            freqs.append(float(s["freq"]))
            damping.append(float(s.get("modal_damp_vis", 0.0)))
        elif "eig" in s:                                       # complex mode: lambda = -zeta w + i w_d
            lam = complex(s["eig"])
            freqs.append(abs(lam) / (2 * np.pi))
            damping.append(-lam.real / max(abs(lam), 1e-300))
        else:
            raise InputError(f"{path}: UFF 55 dataset {k + 1}: neither freq nor eig given")
    xyz = nodes.coordinates(ids)
    return ModeSet(np.array(freqs), np.repeat(ids, 3), np.repeat(xyz, 3, axis=0), np.tile(_AXES, (len(ids), 1)),
                   np.column_stack(shapes), np.array(damping), str(path)).drop_empty_channels()


def _frf_from_58(s: dict) -> FRF:
    x = np.asarray(s["x"], float)
    return FRF(int(s.get("rsp_node", 0)), _DIR_CODE.get(int(s.get("rsp_dir", 3)), _AXES[2]),
               int(s.get("ref_node", 0)), _DIR_CODE.get(int(s.get("ref_dir", 3)), _AXES[2]),
               x, np.asarray(s["data"]), str(s.get("id1", "")))


CSV_COLUMNS = ("mode", "frequency_hz", "point", "x", "y", "z", "dx", "dy", "dz", "value")


def read_mode_csv(path: str | Path, units: str | None = None, key: str = "--units") -> ModeSet:
    """A mode table in long form, one row per mode and channel, columns
    mode, frequency_hz, point, x, y, z (m, or in `units`), dx, dy, dz (direction, normalised here), value (shape
    component).
    Every mode must give the same channels.  InputError naming the file, row and column on bad input."""
    path = Path(path)
    scale = length_scale(path, [], units, key)
    if not path.is_file():
        raise InputError(f"{path}: file not found")
    try:
        with open(path, newline="", encoding="utf-8-sig") as fh:      # a spreadsheet's "CSV UTF-8" has a BOM
            rows = list(csv.DictReader(fh))
    except (UnicodeDecodeError, csv.Error) as exc:
        raise InputError(f"{path}: not a CSV text file ({exc})") from None
    if not rows:
        raise InputError(f"{path}: empty mode table")
    missing = [c for c in CSV_COLUMNS if c not in rows[0]]
    if missing:
        raise InputError(f"{path}: column {missing[0]!r} missing (need {', '.join(CSV_COLUMNS)})")
    table: dict[int, dict] = {}
    channels: dict[tuple, tuple] = {}
    for r, row in enumerate(rows, start=2):
        try:
            mode = int(row["mode"])
            f = float(row["frequency_hz"])
            pt = (float(row["x"]) * scale, float(row["y"]) * scale, float(row["z"]) * scale)
            d = np.array([float(row["dx"]), float(row["dy"]), float(row["dz"])])
            value = complex(row["value"].replace(" ", "").replace("i", "j"))
        except (TypeError, ValueError) as exc:
            raise InputError(f"{path}: row {r}: {exc}") from None
        if not np.isfinite(f) or f < 0 or not np.linalg.norm(d) > 0:
            raise InputError(f"{path}: row {r}: frequency_hz must be >= 0 and (dx, dy, dz) non-zero")
        key = (row["point"].strip(), *np.round(d / np.linalg.norm(d), 9))
        channels.setdefault(key, (pt, d / np.linalg.norm(d)))
        entry = table.setdefault(mode, {"f": f, "values": {}})
        if key in entry["values"]:        # the later value replaced the earlier without a word
            direction = ", ".join(row[c].strip() for c in ("dx", "dy", "dz"))
            raise InputError(f"{path}: row {r}: mode {mode}, point {key[0]}, direction ({direction}) is given twice")
        entry["values"][key] = value
    keys = list(channels)
    for mode, entry in table.items():
        if set(entry["values"]) != set(keys):
            raise InputError(f"{path}: mode {mode}: gives {len(entry['values'])} channels, the table has {len(keys)}")
    order = sorted(table, key=lambda m: table[m]["f"])
    shapes = np.array([[table[m]["values"][k] for m in order] for k in keys])
    if np.all(shapes.imag == 0):
        shapes = shapes.real
    ids = np.array([_point_id(k[0], i) for i, k in enumerate(keys)])
    return ModeSet(np.array([table[m]["f"] for m in order]), ids, np.array([channels[k][0] for k in keys]),
                   np.array([channels[k][1] for k in keys]), shapes, None, str(path))


def _point_id(name: str, fallback: int) -> int:
    try:
        return int(name)
    except ValueError:
        return fallback + 1


def read_measured_modes(path: str | Path, units: str | None = None, key: str = "--units") -> ModeSet:
    """Measured modes from a UFF (.uff/.unv, datasets 15/2411 + 55, 164 honoured) or a CSV mode table (.csv);
    units: the coordinates' unit where the file does not say (LENGTH_UNITS), named `key` in messages."""
    path = Path(path)
    if path.suffix.lower() == ".csv":
        return read_mode_csv(path, units, key)
    data = read_uff(path, units, key)
    if data.modes is None:
        raise InputError(f"{path}: no UFF 55 mode shapes in the file")
    return data.modes


# ------------------------------------------------------------------------------------------------ writing
def write_uff(path: str | Path, nodes: Nodes, modes: ModeSet | None = None, frfs: list | None = None,
              description: str = "housingfe", units: str = "m", units_dataset: bool = True) -> None:
    """Write units (UFF 164, unless units_dataset is False), nodes (UFF 2411; coordinates given in m, written in
    `units`: "m" or "mm"), modes (UFF 55, normal modes, 3 translations per node: channels along x, y, z at nodes
    of `nodes`) and FRFs (UFF 58) to one universal file, replacing it."""
    import pyuff

    if units not in ("m", "mm"):
        raise InputError(f"write_uff: units {units!r}: write m or mm")
    xyz = nodes.xyz / LENGTH_UNITS[units]
    sets = []
    if units_dataset:       # 164: SI = file value / length factor; code 1 = SI (m, N), 5 = MM (mm, mN)
        mm = units == "mm"
        sets.append(pyuff.prepare_164(units_code=5 if mm else 1, units_description="mm" if mm else "SI",
                                      temp_mode=2, length=1000.0 if mm else 1.0, force=1000.0 if mm else 1.0,
                                      temp=1.0, temp_offset=273.15))
    sets.append(pyuff.prepare_2411(node_nums=np.asarray(nodes.ids, int), def_cs=np.ones(len(nodes.ids), int),
                                   disp_cs=np.ones(len(nodes.ids), int), color=np.ones(len(nodes.ids), int),
                                   x=xyz[:, 0], y=xyz[:, 1], z=xyz[:, 2]))
    if modes is not None:
        per_node = _node_components(modes, nodes)
        for k, f in enumerate(modes.frequencies_hz):
            comp = per_node[:, :, k]
            complex_shape = np.iscomplexobj(comp)
            sets.append(pyuff.prepare_55(
                id1=description, id2=f"mode {k + 1}", id3="", id4="", id5="", model_type=1,
                analysis_type=2, data_ch=2, spec_data_type=8, data_type=5 if complex_shape else 2,
                n_data_per_node=3, r1=comp[:, 0], r2=comp[:, 1], r3=comp[:, 2], load_case=1, mode_n=k + 1,
                freq=float(f), modal_m=1.0, modal_damp_vis=float(modes.damping[k]) if modes.damping is not None
                else 0.0, modal_damp_his=0.0, node_nums=np.asarray(nodes.ids, int)))
    for k, frf in enumerate(frfs or []):
        df = np.diff(frf.frequencies_hz)
        even = len(df) > 0 and np.allclose(df, df[0], rtol=1e-9)
        sets.append(pyuff.prepare_58(
            id1=frf.label or f"FRF {k + 1}", id2="", id3="", id4="", id5="", func_type=4, ver_num=0,
            load_case_id=0, rsp_ent_name="housingfe", rsp_node=int(frf.response_node),
            rsp_dir=_dir_code(frf.response_direction), ref_ent_name="housingfe", ref_node=int(frf.reference_node),
            ref_dir=_dir_code(frf.reference_direction), ord_data_type=6, num_pts=len(frf.frequencies_hz),
            abscissa_spacing=1 if even else 0, abscissa_min=float(frf.frequencies_hz[0]),
            abscissa_inc=float(df[0]) if even else 0.0, abscissa_spec_data_type=18,
            ordinate_spec_data_type=12, orddenom_spec_data_type=13, data=np.asarray(frf.values, complex),
            x=np.asarray(frf.frequencies_hz, float)))
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    if tmp.exists():
        tmp.unlink()
    try:
        pyuff.UFF(str(tmp)).write_sets(sets, mode="add")
        tmp.replace(path)
    except BaseException:
        tmp.unlink(missing_ok=True)     # no half-written file left beside the one asked for
        raise


def _dir_code(d: np.ndarray) -> int:
    d = np.asarray(d, float)
    k = int(np.argmax(np.abs(d)))
    if not np.isclose(abs(d[k]), 1.0, atol=1e-9):
        raise InputError(f"UFF 58: direction {d.tolist()} is not a global axis")
    return int(np.sign(d[k])) * (k + 1)


def _node_components(modes: ModeSet, nodes: Nodes) -> np.ndarray:
    """(nodes, 3, modes) translations from per-channel shapes; a channel along a non-axis direction is
    split into its x/y/z parts (exact when every node carries three orthogonal channels)."""
    index = {int(i): k for k, i in enumerate(nodes.ids)}
    out = np.zeros((len(nodes.ids), 3, modes.n_modes), dtype=np.result_type(modes.shapes, float))
    for c, nid in enumerate(modes.node_ids):
        if int(nid) not in index:
            raise InputError(f"mode channel {c}: node {int(nid)} is not among the nodes written")
        out[index[int(nid)]] += modes.directions[c][:, None] * modes.shapes[c][None, :]
    return out
