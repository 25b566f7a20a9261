"""The gearbox interior of a housing scene: the `[coupling]` table -> bore masters, shafts, gears, bearings,
gear meshes and tie rods -> a coupled system (housingfe.drivetrain.coupling).

Validated like the rest of a scene (unknown keys are errors that name the key).  All values SI: m, N, N m,
N/m, N m/rad, rev/min only where the key says so.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated

import numpy as np
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    PositiveFloat,
    PositiveInt,
    field_validator,
    model_validator,
)

from housingfe.errors import InputError

# housingfe.drivetrain.coupling (PETSc) is imported inside the functions: validating a scene stays light.

Vector3 = tuple[float, float, float]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class BoreMasterSpec(_Strict):
    """A bore master: surface of the housing, centre (m; default: on the axis of the cylinder fitted to the surface,
    mid-length, or the centroid of a flat surface: housingfe.drivetrain.bore_axis), axis (checked against the
    fitted one where given), kind (rbe2 | rbe3 | star) and rod_stiffness (N/m per rod, star only)."""

    name: str
    surface: str
    centre: Vector3 | None = None
    axis: Vector3 = (0.0, 0.0, 1.0)
    kind: str = Field("rbe2", pattern="^(rbe2|rbe3|star)$")
    rod_stiffness: PositiveFloat | None = None


class DiscSpec(_Strict):
    """A gear as a rigid cylinder (m) on shaft node `node`."""

    node: int = Field(ge=0)
    outer_diameter: PositiveFloat
    width: PositiveFloat
    inner_diameter: float = Field(0.0, ge=0.0)


class ShaftSpec(_Strict):
    """A stepped Timoshenko shaft: segments [[length, outer_d(, inner_d)], ...] (m) from origin along axis."""

    name: str = Field(pattern=r"^[A-Za-z0-9_]+$")
    origin: Vector3
    axis: Vector3
    segments: list[list[float]]
    elements_per_segment: PositiveInt = 4
    discs: list[DiscSpec] = []


Matrix6 = list[Annotated[list[float], Field(min_length=6, max_length=6)]]


class BearingSpec(_Strict):
    """A bearing from a shaft node (e.g. "pinion:0") to a bore master (None: ground), in the bearing frame
    (z = shaft axis, rotated to global axes by `axis`; the spin row and column are always freed).  One of:
    designation (catalogue, with its mean `load` (Fx, Fy, Fz, Mx, My) in N, N m, and optionally the stiffness
    `model`), `stiffness` (6 diagonal values, N/m and N m/rad) or `stiffness_matrix` (6x6, may be
    non-symmetric, e.g. fluid film) with an optional `damping_matrix` (6x6, N s/m, N m s/rad).  `name` labels
    the bearing position in reports."""

    name: str | None = None
    shaft_node: str
    bore: str | None = None
    axis: Vector3 = (0.0, 0.0, 1.0)
    designation: str | None = None
    load: tuple[float, float, float, float, float] | None = Field(None, json_schema_extra={"unit": "N, N, N, N m, N m"})
    model: str | None = None     # a name in housingfe.bearings.rolling.BEARING_MODELS (checked below)
    # tilt (rad) held by the shaft instead of zero moments (a shaft on two bearings sets the tilt; see
    # housingfe.verification.bearing_rows)
    fixed_tilt: tuple[float, float] | None = Field(None, json_schema_extra={"unit": "rad"})
    stiffness: tuple[float, float, float, float, float, float] | None = Field(
        None, json_schema_extra={"unit": "N/m (x, y, z), N m/rad (rotations)"})
    stiffness_matrix: Matrix6 | None = Field(None, min_length=6, max_length=6,
                                             json_schema_extra={"unit": "N/m, N/rad, N m/rad"})
    damping_matrix: Matrix6 | None = Field(None, min_length=6, max_length=6,
                                           json_schema_extra={"unit": "N s/m, N m s/rad"})

    @model_validator(mode="after")
    def _one(self):
        given = [x is not None for x in (self.designation, self.stiffness, self.stiffness_matrix)]
        if sum(given) != 1:
            raise ValueError("give one of designation (+ load), stiffness or stiffness_matrix")
        if self.designation is not None and self.load is None:
            raise ValueError("load: required with a designation (N, N m)")
        if self.damping_matrix is not None and self.stiffness_matrix is None:
            raise ValueError("damping_matrix: only with stiffness_matrix")
        return self

    @field_validator("model")
    @classmethod
    def _registered_model(cls, name):
        from housingfe.bearings.rolling import check_bearing_model  # the registry of bearing models

        return name if name is None else check_bearing_model(name)

    @property
    def label(self) -> str:
        return self.name or f"{self.shaft_node}-{self.bore or 'ground'}"

    def matrices(self) -> tuple[np.ndarray, np.ndarray | None]:
        """(K, C) 6x6 in the bearing frame (N/m, N m/rad; N s/m); C None without damping."""
        if self.designation is not None:
            from housingfe.bearings import bearing_stiffness

            return bearing_stiffness(self.designation, self.load, model=self.model, fixed_tilt=self.fixed_tilt).K, None
        if self.stiffness is not None:
            return np.diag(self.stiffness), None
        C = None if self.damping_matrix is None else np.array(self.damping_matrix, float)
        return np.array(self.stiffness_matrix, float), C


class GearMeshSpec(_Strict):
    """Mesh stiffness (N/m) along the line of action `direction` through the contact `point` (m)."""

    a: str
    b: str
    stiffness: PositiveFloat = Field(json_schema_extra={"unit": "N/m"})
    point: Vector3
    direction: Vector3
    damping: float = Field(0.0, ge=0.0, json_schema_extra={"unit": "N s/m"})


class TieRodSpec(_Strict):
    """A solid round Timoshenko beam (steel, m) between two nodes.  rigid_end_a / rigid_end_b: lengths (m) from
    each node along the rod that are rigid (the part inside a shaft: the rod is clamped to the shaft's surface,
    not to its axis); the beam spans the rest."""

    a: str
    b: str
    diameter: PositiveFloat
    rigid_end_a: float = Field(0.0, ge=0.0, json_schema_extra={"unit": "m"})
    rigid_end_b: float = Field(0.0, ge=0.0, json_schema_extra={"unit": "m"})


class DriveLineSpec(_Strict):
    """The drive line beyond a shaft end (a test rig's quill shafts): from the shaft node `shaft_node` a torsion
    spring `near_stiffness` (N m/rad, the quill between the shaft and the coupling) to a coupling node `name` of
    polar inertia `inertia` (kg m^2), and from it a torsion spring `far_stiffness` (N m/rad, the quill to the
    motor / brake) to ground.  Torsion only, about the shaft's axis: a flexible coupling transmits torque and no
    lateral force or bending moment.  The coupling node is a torsion node (housingfe.drivetrain.coupling: one DOF,
    its rotation about the axis; u = 0, theta = axis phi as constraints of u_full = P q, no penalty values)."""

    name: str = Field(pattern=r"^[A-Za-z0-9_]+$")
    shaft_node: str
    near_stiffness: PositiveFloat = Field(json_schema_extra={"unit": "N m/rad"})
    inertia: PositiveFloat = Field(json_schema_extra={"unit": "kg m^2"})
    far_stiffness: PositiveFloat = Field(json_schema_extra={"unit": "N m/rad"})


class AuxGearboxSpec(_Strict):
    """The auxiliary gearbox that closes a back-to-back rig's loop (the thesis' test rig, Sec. 5.2): the far quills
    of the drive lines `pinion_line` and `wheel_line` end on its pinion and wheel instead of ground.  Its gears are
    rigid, so it is ONE torsion node `name` (housingfe.drivetrain.coupling torsion node, like a coupling): the
    rotation phi of its pinion about `axis`; its wheel turns by -phi / `ratio` about the same axis (the sense of an
    external pair, as the test pair's, so the loop closes).  `inertia`: everything that turns with it, at phi
    (kg m^2: pinion, motor rotor, wheel / ratio^2); `ground_stiffness`: a torsion spring from phi to ground (N m/rad;
    the drive motor's hold on the loop's rigid rotation; 0 leaves it free, one zero mode)."""

    name: str = Field(pattern=r"^[A-Za-z0-9_]+$")
    axis: Vector3
    pinion_line: str
    wheel_line: str
    ratio: PositiveFloat = Field(json_schema_extra={"unit": "-"})
    inertia: PositiveFloat = Field(json_schema_extra={"unit": "kg m^2"})
    ground_stiffness: float = Field(0.0, ge=0.0, json_schema_extra={"unit": "N m/rad"})

    def far_factor(self, line: str) -> float:
        """The far end's angle per unit phi of the drive line named `line`: 1 on the pinion, -1/ratio on the wheel."""
        return 1.0 if line == self.pinion_line else -1.0 / self.ratio


class CouplingSpec(_Strict):
    bores: list[BoreMasterSpec] = []
    shafts: list[ShaftSpec] = []
    bearings: list[BearingSpec] = []
    gear_meshes: list[GearMeshSpec] = []
    tie_rods: list[TieRodSpec] = []
    drive_lines: list[DriveLineSpec] = []
    aux_gearbox: AuxGearboxSpec | None = None


    @model_validator(mode="after")
    def _unique(self):
        names = [b.name for b in self.bores] + [s.name for s in self.shafts] + [d.name for d in self.drive_lines]
        if self.aux_gearbox is not None:
            names.append(self.aux_gearbox.name)
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ValueError(f"bores: names must be unique among bores, shafts, drive lines and the aux gearbox "
                             f"({', '.join(dup)})")
        aux = self.aux_gearbox
        if aux is not None:
            lines = [d.name for d in self.drive_lines]
            for key in ("pinion_line", "wheel_line"):
                if getattr(aux, key) not in lines:
                    raise ValueError(f"aux_gearbox.{key}: {getattr(aux, key)!r} is not a drive line (known: "
                                     f"{', '.join(lines) or 'none'})")
            if aux.pinion_line == aux.wheel_line:
                raise ValueError("aux_gearbox: pinion_line and wheel_line must be two drive lines")
        return self


# ------------------------------------------------------------------------------------------------ parts
@dataclass
class Parts:
    """The interior as housingfe.drivetrain.coupling inputs: connections, shafts {name: Shaft}, bearings (Elements;
    bearings[i] is that of spec.bearings[i]), gear meshes, tie rods (Elements)."""

    connections: list
    shafts: dict
    bearings: list
    gear_meshes: list
    tie_rods: list          # Elements (beam K, M between the two nodes, rigid ends included)
    positions: dict         # node name (bores, shaft nodes) -> position (m)
    drive_lines: list = field(default_factory=list)     # Elements: torsion springs and coupling inertias
    torsion_nodes: dict = field(default_factory=dict)   # coupling node name -> (position m, unit axis)

    @property
    def elements(self) -> list:
        return self.bearings + self.tie_rods + self.drive_lines

    def couple(self, model, extra_elements=(), gear_meshes=None):
        """housingfe.drivetrain.coupling.couple() of these parts (plus `extra_elements`; gear_meshes: these
        parts' own unless given)."""
        from housingfe.drivetrain import coupling as cp

        return cp.couple(model, self.connections, self.elements + list(extra_elements), self.shafts,
                         self.gear_meshes if gear_meshes is None else gear_meshes, torsion_nodes=self.torsion_nodes)


def _check(spec: CouplingSpec) -> CouplingSpec:
    if isinstance(spec, CouplingSpec):
        return spec
    from pydantic import ValidationError

    try:
        return CouplingSpec.model_validate(spec)
    except ValidationError as exc:
        err = exc.errors()[0]
        msg = err["msg"].removeprefix("Value error, ")
        raise InputError(f"coupling.{'.'.join(str(p) for p in err['loc'])}: {msg}") from None


def parts(spec: CouplingSpec, bore_centres: dict) -> Parts:
    """Build the coupling inputs; bore_centres: bore name -> centre (m) (given or measured on the mesh)."""
    from housingfe.drivetrain import coupling as cp
    from housingfe.drivetrain.shafts import RigidDisc, Shaft

    connections = [cp.BoreConnection(b.name, b.surface, tuple(bore_centres[b.name]), b.axis, b.kind,
                                     b.rod_stiffness) for b in spec.bores]
    shafts = {}
    for i, s in enumerate(spec.shafts):
        shaft = Shaft.stepped([tuple(seg) for seg in s.segments], origin=s.origin, axis=s.axis,
                              elements_per_segment=s.elements_per_segment)
        for d in s.discs:
            if d.node >= len(shaft.nodes):
                raise InputError(f"coupling.shafts.{i}.discs: node {d.node} out of range 0..{len(shaft.nodes) - 1}")
            shaft.add_disc(d.node, RigidDisc.cylinder(d.outer_diameter, d.width, d.inner_diameter))
        shafts[s.name] = shaft
    position = {**{n: np.asarray(x, float) for n, x in bore_centres.items()},
                **{f"{n}:{i}": x for n, sh in shafts.items() for i, x in enumerate(sh.nodes)}}
    known = set(bore_centres) | {f"{n}:{i}" for n, sh in shafts.items() for i in range(len(sh.nodes))}
    bearings = []
    for i, b in enumerate(spec.bearings):
        for key, node in (("shaft_node", b.shaft_node), ("bore", b.bore)):
            if node is not None and node not in known:
                raise InputError(f"coupling.bearings.{i}.{key}: unknown node {node!r} (shaft nodes are "
                                 f"'<shaft>:<index>', bores by name)")
        try:
            K, C = b.matrices()
        except InputError as exc:
            raise InputError(f"coupling.bearings.{i} ({b.label}): {exc}") from None
        # the bearing acts at the shaft node; the bore master (its centre measured on the mesh, off the nominal
        # shaft line by a fraction of an element on coarse bores) reaches it by a rigid arm (cp.spring)
        offset = None if b.bore is None else position[b.shaft_node] - position[b.bore]
        bearings.append(cp.bearing(b.shaft_node, b.bore, K, b.axis, C, offset=offset))
    for kind, items in (("gear_meshes", spec.gear_meshes), ("tie_rods", spec.tie_rods)):
        for i, g in enumerate(items):
            for key in ("a", "b"):
                if getattr(g, key) not in known:
                    raise InputError(f"coupling.{kind}.{i}.{key}: unknown node {getattr(g, key)!r}")
    meshes = [cp.GearMesh(g.a, g.b, g.stiffness, g.point, g.direction, g.damping) for g in spec.gear_meshes]
    rods = [tie_rod_element(t, position[t.a], position[t.b], f"coupling.tie_rods.{i}")
            for i, t in enumerate(spec.tie_rods)]
    lines, torsion = [], {}
    aux = spec.aux_gearbox
    for i, d in enumerate(spec.drive_lines):
        shaft = shafts.get(d.shaft_node.split(":")[0]) if ":" in d.shaft_node else None
        if shaft is None or d.shaft_node not in position:
            raise InputError(f"coupling.drive_lines.{i}.shaft_node: unknown shaft node {d.shaft_node!r} "
                             "('<shaft>:<index>')")
        axis = np.asarray(shaft.axis, float) / np.linalg.norm(shaft.axis)
        torsion[d.name] = (position[d.shaft_node], axis)
        far = (aux.name, aux.far_factor(d.name)) if aux is not None and d.name in (aux.pinion_line,
                                                                                  aux.wheel_line) else None
        lines += drive_line_elements(d, axis, far)
    if aux is not None:
        axis = np.asarray(aux.axis, float) / np.linalg.norm(aux.axis)
        # a torsion node's position only enters the rigid-body vectors, which hold no translation for it: the
        # pinion line's shaft end stands for the motor room
        pinion_line = next(d for d in spec.drive_lines if d.name == aux.pinion_line)
        torsion[aux.name] = (position[pinion_line.shaft_node], axis)
        lines += aux_gearbox_elements(aux, axis)
    return Parts(connections, shafts, bearings, meshes, rods, position, lines, torsion)


def torsion_block(value: float, axis) -> np.ndarray:
    """6x6 with value a a^T in the rotation block (a unit axis): a torsion spring's K6 (N m/rad) or a polar
    inertia's M6 (kg m^2) about the axis, nothing in the translations or the other rotations."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    out = np.zeros((6, 6))
    out[3:, 3:] = value * np.outer(a, a)
    return out


def drive_line_elements(d: DriveLineSpec, axis, far: tuple[str, float] | None = None) -> list:
    """The Elements of a drive line (DriveLineSpec): the near torsion spring shaft node - coupling node, the
    coupling's polar inertia, the far torsion spring coupling node - ground; far = (torsion node, factor): the far
    spring ends instead on a torsion node whose angle phi turns the far end by factor x phi (an aux gearbox,
    `aux_gearbox_elements`): energy k/2 (a.theta_coupling - factor phi)^2."""
    from housingfe.drivetrain import coupling as cp

    out = [cp.spring(d.shaft_node, d.name, torsion_block(d.near_stiffness, axis)),
           cp.point_mass(d.name, torsion_block(d.inertia, axis))]
    if far is None:
        return out + [cp.spring(d.name, None, torsion_block(d.far_stiffness, axis))]
    node, factor = far
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    b = np.concatenate([np.zeros(3), a, np.zeros(3), -factor * a])
    return out + [cp.Element((d.name, node), d.far_stiffness * np.outer(b, b))]


def aux_gearbox_elements(aux: AuxGearboxSpec, axis) -> list:
    """The aux gearbox's own Elements (AuxGearboxSpec): its polar inertia at phi and, if any, the torsion spring
    to ground (the motor); the far quills that end on it are the drive lines' (`drive_line_elements`)."""
    from housingfe.drivetrain import coupling as cp

    out = [cp.point_mass(aux.name, torsion_block(aux.inertia, axis))]
    if aux.ground_stiffness > 0:
        out.append(cp.spring(aux.name, None, torsion_block(aux.ground_stiffness, axis)))
    return out


def tie_rod_element(t: TieRodSpec, pa: np.ndarray, pb: np.ndarray, key: str):
    """The Element of a tie rod: a steel Timoshenko beam between the ends of its rigid parts, moved to the two
    nodes by rigid arms (u_end = u_node + theta_node x r), K = T^T k T, M = T^T m T."""
    from housingfe.drivetrain import coupling as cp
    from housingfe.drivetrain.shafts import STEEL, CircularSection, beam_element_matrices

    length = float(np.linalg.norm(pb - pa))
    if t.rigid_end_a + t.rigid_end_b >= length:
        raise InputError(f"{key}: rigid ends ({t.rigid_end_a} + {t.rigid_end_b} m) leave no rod "
                         f"between nodes {length:.4g} m apart")
    e = (pb - pa) / length
    ra, rb = t.rigid_end_a * e, -t.rigid_end_b * e
    k, m = beam_element_matrices(pa + ra, pb + rb, CircularSection(t.diameter), STEEL)
    T = np.zeros((12, 12))
    for i, r in enumerate((ra, rb)):
        T[6 * i:6 * i + 3, 6 * i:6 * i + 6] = cp.rigid_arm(r)
        T[6 * i + 3:6 * i + 6, 6 * i + 3:6 * i + 6] = np.eye(3)
    return cp.Element((t.a, t.b), T.T @ k @ T, T.T @ m @ T, None)


def bore_fits(model, spec: CouplingSpec) -> dict:
    """Bore name -> housingfe.drivetrain.bore_axis.BoreFit of its surface (None where the scene gives the centre):
    the master on the fitted cylinder's axis mid-length, or at the centroid of a flat seat (the rule:
    housingfe.drivetrain.bore_axis).  InputError naming the key for an unknown surface, a curved surface that is no
    cylinder, and a bore axis more than bore_axis.MAX_TILT_DEG from the axis of a bearing it carries (or from the
    bore's own `axis` where the scene gives one).  Collective."""
    from housingfe.drivetrain import bore_axis

    out = {}
    for i, b in enumerate(spec.bores):
        if b.surface not in model.housing.facet_groups:
            raise InputError(f"coupling.bores.{i}.surface: no surface {b.surface!r} "
                             f"(known: {', '.join(sorted(model.housing.facet_groups))})")
        if b.centre is not None:
            out[b.name] = None
            continue
        try:
            fit = bore_axis.fit_bore(model, b.surface)
        except InputError as exc:
            raise InputError(f"coupling.bores.{i}.surface: {exc}") from None
        if fit.kind == "cylinder":
            given = [(f"its axis {bore_axis.format_vector(b.axis)}", b.axis)] if "axis" in b.model_fields_set else []
            given += [(f"the axis {bore_axis.format_vector(c.axis)} of bearing {c.label!r}", c.axis)
                      for c in spec.bearings if c.bore == b.name]
            for what, axis in given:
                tilt = fit.tilt_deg(axis)
                if tilt > bore_axis.MAX_TILT_DEG:
                    raise InputError(f"coupling.bores.{i} ({b.name}): the bore surface {b.surface!r} runs along "
                                     f"{bore_axis.format_vector(fit.axis)}, {tilt:.3g} deg from {what} (at most "
                                     f"{bore_axis.MAX_TILT_DEG:g} deg)")
        out[b.name] = fit
    return out


def bore_centres(model, spec: CouplingSpec, fits: dict | None = None) -> dict:
    """Bore name -> centre (m): the given one, or that of the bore's fit (`bore_fits`; fits: its result, if
    already computed)."""
    fits = bore_fits(model, spec) if fits is None else fits
    return {b.name: np.asarray(b.centre if b.centre is not None else fits[b.name].centre, float) for b in spec.bores}


def couple_from_spec(model, spec: CouplingSpec | dict):
    """housingfe.drivetrain.coupling.couple() from a scene's [coupling] section (a CouplingSpec or the raw dict)."""
    spec = _check(spec)
    return parts(spec, bore_centres(model, spec)).couple(model)


# -------------------------------------------------------------------------------- interior on rigid bores
@dataclass
class RigidBoreModes:
    """Eigenmodes of the interior alone with every bore master held fixed (the thesis' check of Sec. 4.6).

    frequencies_hz: all modes below f_max, mechanisms (zero modes, e.g. a free gear-train rotation) first;
    bearing_energy: fraction of each mode's strain energy stored in the bearings (close to 1: the interior moves
    as a whole on its bearings; small: shafts / rods bend); mechanisms: number of zero modes."""

    frequencies_hz: np.ndarray
    bearing_energy: np.ndarray
    mechanisms: int
    dofs: int


def interior_matrices(spec: CouplingSpec, centres: dict, housing_body: bool = False):
    """Dense K, M (and the bearings' K alone) of the interior with the bore masters fixed (SI units).
    Returns (K, M, K_bearings, node names in DOF order).  Shaft nodes carry 6 DOFs each (global axes), then the
    drive lines' coupling nodes one each (their rotation about the shaft axis, named like the node).
    housing_body: the bore masters follow the rigid motion of one body instead (6 DOFs named "housing" first:
    u, theta about the origin; no mass): the interior on a free rigid housing."""
    from housingfe.drivetrain import coupling as cp

    p = parts(spec, centres)
    names = [f"{n}:{i}" for n, sh in p.shafts.items() for i in range(len(sh.nodes))] + list(p.torsion_nodes)
    if housing_body:
        names = ["housing"] + names
    index = {n: 6 * i for i, n in enumerate(names)}
    size = 6 * len(names)
    K, M, Kb = np.zeros((size, size)), np.zeros((size, size)), np.zeros((size, size))
    # a bore master's 6 DOFs as the housing body's: u_m = u + theta x c, theta_m = theta
    follow = {}
    if housing_body:
        for c in p.connections:
            T = np.eye(6)
            T[:3, 3:] = -cp.skew(np.asarray(c.centre, float))
            follow[c.name] = T

    def add(target, nodes, block):
        # rows/columns of fixed bore masters and of ground (None) are dropped
        maps = []
        for j, n in enumerate(nodes):
            if n in index:
                maps.append((j, index[n], np.eye(6)))
            elif n in follow:
                maps.append((j, index["housing"], follow[n]))
        for a, ia, Ta in maps:
            for b, ib, Tb in maps:
                target[ia:ia + 6, ib:ib + 6] += Ta.T @ block[6 * a:6 * a + 6, 6 * b:6 * b + 6] @ Tb

    for name, shaft in p.shafts.items():
        ks, ms = shaft.matrices()
        nodes = [f"{name}:{i}" for i in range(len(shaft.nodes))]
        add(K, nodes, ks)
        add(M, nodes, ms)
    for e in p.bearings:
        add(K, list(e.nodes), e.K)
        add(Kb, list(e.nodes), e.K)
    for e in p.drive_lines + p.tie_rods:
        for target, block in ((K, e.K), (M, e.M)):
            if block is not None:
                add(target, list(e.nodes), block)
    for g in p.gear_meshes:
        add(K, [g.a, g.b], cp.gear_mesh_element(g, p.positions[g.a], p.positions[g.b]).K)
    if p.torsion_nodes:     # a coupling node keeps its rotation about the axis: T maps it to the node's 6 DOFs
        T = np.zeros((size, size - 5 * len(p.torsion_nodes)))
        col = 0
        for n in names:
            i = index[n]
            if n in p.torsion_nodes:
                T[i + 3:i + 6, col] = p.torsion_nodes[n][1]
                col += 1
            else:
                T[i:i + 6, col:col + 6] = np.eye(6)
                col += 6
        K, M, Kb = (T.T @ A @ T for A in (K, M, Kb))
    return K, M, Kb, names


def free_housing_mechanisms(spec: CouplingSpec, centres: dict) -> int:
    """Zero-stiffness modes of the interior on a FREE rigid housing (`interior_matrices(housing_body=True)`): the
    zero modes a coupled model of a free housing has, since a zero-energy motion strains no part of the housing
    (it moves as a rigid body, and the bore masters with it: rbe2 / rbe3 / star reproduce rigid motions exactly).
    Without anything between the interior and ground this is 6 + the mechanisms on fixed bores; a grounded drive
    line (or a bearing to ground) restrains some of the housing's six.  A dense rank count of the Jacobi-scaled K
    (its symmetric part), a few hundred DOFs."""
    K = interior_matrices(_check(spec), centres, housing_body=True)[0]
    K = (K + K.T) / 2
    d = np.sqrt(np.abs(np.diag(K)))
    d[d == 0] = 1.0
    lam = np.linalg.eigvalsh(K / d[:, None] / d[None, :])
    return int(np.count_nonzero(lam < 1e-10 * lam.max()))


def rigid_bore_modes(spec: CouplingSpec, centres: dict, f_max: float) -> RigidBoreModes:
    """Modes of the interior on rigid bores below f_max (Hz), dense (a few hundred DOFs).  Uses the symmetric
    part of K (a non-symmetric fluid-film stiffness has complex modes; its symmetric part is reported)."""
    import scipy.linalg as sl

    from housingfe.solvers.modal import RIGID_FREQUENCY_RATIO

    K, M, Kb, _ = interior_matrices(_check(spec), centres)
    if not len(K):      # no shafts: bearings between bores and ground only, nothing moves on rigid bores
        return RigidBoreModes(np.zeros(0), np.zeros(0), 0, 0)
    K, Kb = (K + K.T) / 2, (Kb + Kb.T) / 2
    lam, vecs = sl.eigh(K, M, subset_by_value=(-np.inf, (2 * np.pi * f_max) ** 2))
    f = np.sqrt(np.clip(lam, 0.0, None)) / (2 * np.pi)
    rigid = f < RIGID_FREQUENCY_RATIO * f_max
    energy = np.array([v @ Kb @ v / (v @ K @ v) if not r else 0.0 for v, r in zip(vecs.T, rigid)])
    return RigidBoreModes(f, energy, int(rigid.sum()), K.shape[0])


# ------------------------------------------------------------------------------------------- coupled model
@dataclass
class CoupledInterior:
    """A housing model coupled with its interior: what the solvers (K, M, C) and the reports need.

    system: housingfe.drivetrain.coupling.CoupledSystem (independent DOFs q); parts: the built elements; rigid: the
    interior's modes on rigid bores; centres: bore centres (m); bores: bore name -> BoreFit (None: centre given;
    housingfe.drivetrain.bore_axis)."""

    model: object
    spec: CouplingSpec
    parts: Parts
    system: object
    rigid: RigidBoreModes
    centres: dict
    bores: dict = field(default_factory=dict)
    _basis_K: object = field(default=None, repr=False)   # built on first use (projected solver only)

    @property
    def K(self):
        return self.system.K

    @property
    def M(self):
        return self.system.M

    @property
    def C(self):
        return self.system.C

    # ---------------------------------------------- the Structure protocol (housingfe.fe.structure)
    @property
    def dofs(self) -> int:
        return self.system.size

    @property
    def expected_zero_modes(self) -> int:
        return self.expected_mechanisms()

    @property
    def housing(self):
        return self.model.housing

    @property
    def V(self):
        return self.model.V

    @property
    def symmetric(self) -> bool:
        """False with a non-symmetric bearing stiffness (fluid films)."""
        return self.system.symmetric

    def load_case(self, load, key: str | None = None):
        """The LoadCase (coupled vector, per unit amplitude) of a load spec: on a drivetrain node (load.node)
        or on a housing surface (mapped to the coupled DOFs)."""
        from housingfe.fe.loads import LoadCase

        if getattr(load, "node", None) is not None:
            vec = self.node_load(load.node, load.kind, load.direction, f"{key or 'loads'}.node")
            return LoadCase(load.name, load.kind, vec, load, 0.0, self.system.nodes[load.node][0])
        lc = self.model.load_case(load, key)
        lc.vector = self.system.load(fe_load=lc.vector)
        return lc

    def load_vector(self, load):
        """Coupled load vector (PETSc Vec, per unit amplitude) of a load spec."""
        return self.load_case(load).vector

    def to_housing(self, vec):
        """The housing displacement field of a coupled vector (= fe_vector)."""
        return self.fe_vector(vec)

    def rigid_body_vectors(self) -> list:
        """The six exact rigid-body motions (translations, rotations about the origin) in the coupled DOFs."""
        return self.system.rigid_body_vectors(self.model.V)

    def node_displacement(self, q, node: str) -> np.ndarray:
        """Six displacement components (m, rad) of an interior node in the coupled vector q."""
        return self.system.node_displacement(q, node)

    def material_damping_matrix(self):
        """Per-material loss factors are not mapped to the coupled DOFs: None without them, else InputError."""
        if self.model.material_damping_matrix() is not None:
            raise InputError("damping: per-material loss factors are not mapped to the coupled model yet; give "
                             "damping.loss_factor or damping.modal_damping_ratio")
        return None

    def basis_stiffness(self):
        """A symmetric positive semi-definite stand-in for K, for the modal basis of the projected solver: every
        bearing matrix replaced by the nearest PSD matrix to its symmetric part (fluid films have a non-symmetric
        K whose symmetric part can be indefinite).  Same DOFs as K, built once."""
        if self._basis_K is None:
            bearings = [b.model_copy(update={"designation": None, "load": None, "model": None, "fixed_tilt": None,
                                             "stiffness": None, "damping_matrix": None,
                                             "stiffness_matrix": nearest_psd(b.matrices()[0]).tolist()})
                        for b in self.spec.bearings]
            self._basis_K = parts(self.spec.model_copy(update={"bearings": bearings}), self.centres).couple(
                self.model).K
        return self._basis_K

    def expected_mechanisms(self) -> int:
        """Zero modes the coupled model must have: on a held housing the interior's own mechanisms on fixed bores;
        on a free one the zero modes of the interior on a free rigid housing (`free_housing_mechanisms`: the six
        rigid-body motions plus the interior's mechanisms, fewer where a drive line ties the gears to ground).
        Dense rank counts."""
        if not self.model.rigid_modes_expected:
            return self.rigid.mechanisms
        if not self.spec.drive_lines and all(b.bore is not None for b in self.spec.bearings):
            return self.model.rigid_modes_expected + self.rigid.mechanisms     # nothing to ground: independent
        return free_housing_mechanisms(self.spec, self.centres)

    def fe_vector(self, q):
        """The housing displacement (PETSc Vec on model.V) of a coupled vector q."""
        return self.system.fe_vector(q, self.model.V)

    def fe_modes(self, result):
        """A ModalResult whose vectors are the housing parts of the coupled modes (for the housing reports)."""
        import dataclasses

        return dataclasses.replace(result, vectors=[self.fe_vector(q) for q in result.vectors])

    def interior_fraction(self, vectors) -> np.ndarray:
        """Share of each mass-normalised coupled mode's kinetic energy in the interior (shafts, gears, rods):
        1 - u_fe^T M_fe u_fe."""
        from housingfe.solvers import blocks

        if not len(vectors):
            return np.zeros(0)
        comm = self.system.M.getComm()
        Q = blocks.columns(vectors)
        U = blocks.columns([self.fe_vector(q) for q in vectors])
        housing = np.einsum("ij,ij->j", U, blocks.mat_block(self.model.M, U))
        total = np.einsum("ij,ij->j", Q, blocks.mat_block(self.system.M, Q))
        if comm.getSize() > 1:
            housing, total = comm.tompi4py().allreduce(np.array([housing, total]))
        return 1.0 - housing / total

    def shaft_axis(self, node: str) -> np.ndarray:
        """Unit axis of the shaft a node "<shaft>:<i>" belongs to."""
        shaft = self.parts.shafts.get(node.split(":")[0]) if ":" in node else None
        if shaft is None:
            raise InputError(f"{node!r} is not a shaft node ('<shaft>:<index>'; shafts: "
                             f"{', '.join(self.parts.shafts) or 'none'})")
        return shaft.axis

    def node_load(self, node: str, kind: str, direction, key: str):
        """Coupled load vector of a unit force (N) or moment (N m) along `direction` on an extra node."""
        if node not in self.system.nodes:
            raise InputError(f"{key}: unknown node {node!r} (known: shaft nodes '<shaft>:<index>', bores "
                             f"{', '.join(self.centres) or 'none'})")
        d = np.asarray(direction, float) / np.linalg.norm(direction)
        value = np.zeros(6)
        value[(0 if kind == "force" else 3):(3 if kind == "force" else 6)] = d
        return self.system.load(node_loads={node: value})


def nearest_psd(K: np.ndarray) -> np.ndarray:
    """The symmetric positive semi-definite matrix nearest (Frobenius) to K: clip the negative eigenvalues of its
    symmetric part."""
    lam, vec = np.linalg.eigh((K + K.T) / 2)
    return (vec * np.clip(lam, 0.0, None)) @ vec.T


def build_interior(model, spec: CouplingSpec, f_max: float) -> CoupledInterior:
    """Couple a HousingModel with the interior of its scene; modes of the interior on rigid bores below f_max."""
    import time

    t0 = time.perf_counter()
    spec = _check(spec)
    fits = bore_fits(model, spec)
    centres = bore_centres(model, spec, fits)
    p = parts(spec, centres)
    system = p.couple(model)
    rigid = rigid_bore_modes(spec, centres, f_max)
    model.timings["coupling_s"] = time.perf_counter() - t0
    return CoupledInterior(model, spec, p, system, rigid, centres, fits)
