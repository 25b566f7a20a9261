"""Assembly of Trueman's (1974) branched torsional drive as one global system (SI units).

All rotations are referred to DRAWROLL speed, as in the thesis (Sec. 5.3, Fig. 5.4): a layshaft inertia J
becomes J / SRAT^2 and a layshaft stiffness k becomes k / SRAT^2 (SRAT = drawshaft / layshaft speed);
drawshaft-side items (bronze and steel gears, crossed and parallel meshes, drawshafts, drawrolls) are used
as given.  Damping coefficients are used as given (not rescaled), as the thesis's program does.

Topology of one drawbox (inferred from the thesis's subroutines, confirmed by Table 6.1):

    prev --coupling-- J1 --k2-- J2 --k3-- ... J7 --k8-- J8 --coupling-- next box
                             |          (branches at J2 .. J7, mesh positions 1..6)
    branch: Jn --crossed mesh-- bronze gear --parallel mesh (TE)-- steel gear
            each gear --[rubber bush]-- drawshaft (3 uniform sections) -- drawroll

Drawshafts are discretised by linear torsion finite elements with consistent mass (their own first
clamped-clamped mode is near 6 kHz, far above the 0-100 Hz range of interest, so a few elements per section
converge; see tests).  The first box is driven from the headstock / rig drive through one box coupling; the
tail end is free.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from housingfe.errors import InputError
from housingfe.source.trueman import data

MESH_POSITIONS = 6          # drawroll-pair branches per drawbox


@dataclass(frozen=True)
class DriveConfig:
    """One machine configuration (Trueman's main-program inputs and modification factors).

    name: label used in outputs
    machine_type: "A" (Types A & C data) or "B" (Types B & E data), Appendix B
    boxes: number of drawboxes NBM (10 for machines, 4 for the rig)
    bushed: rubber-bushed drawshaft gears (FXBSH, DXBSH of Appendix B)
    bush_damping_factor: multiplies DXBSH (0 gives the "zero bush damping" variant of Fig. 6.20)
    drawshaft_mid_diameter: diameter of the 11 in drawshaft section [m]; None keeps 1.225 in
    drawroll_inertia_factor: multiplies AJ(11)
    coupling_flexibility_factor: divides the box-coupling stiffness AK(1) = AK(9) (FCTRR)
    mesh_flexibility_factor: divides both mesh stiffnesses AK(10), AK(11) (FRGTX)
    drive: "headstock" (a large equivalent inertia, Types A/B) or "vs_drive" (the rig, Appendix H)
    headstock_inertia: drawroll-referred headstock inertia [kg m^2] (not recoverable from the text;
        Table 6.1 is insensitive to it above ~300 lbf in s^2)
    elements_per_section: finite elements per uniform drawshaft section
    damping_scale: multiplies every damper (1 = Appendix B)
    mesh_damping_factor: multiplies the two mesh dampers FFD(10), FFD(11) (Sec. 6.5 sensitivity)
    drawroll_damping_factor: multiplies the drawroll dampers AJD(11) (Sec. 6.5 sensitivity)
    """

    name: str = "standard A, solid gears"
    machine_type: str = "A"
    boxes: int = 10
    bushed: bool = False
    bush_damping_factor: float = 1.0
    drawshaft_mid_diameter: float | None = None
    drawroll_inertia_factor: float = 1.0
    coupling_flexibility_factor: float = 1.0
    mesh_flexibility_factor: float = 1.0
    drive: str = "headstock"
    headstock_inertia: float = 1.0e4 * data.LBF_IN
    elements_per_section: int = 3
    damping_scale: float = 1.0
    mesh_damping_factor: float = 1.0
    drawroll_damping_factor: float = 1.0

    def __post_init__(self):
        where = f"configuration {self.name!r}"
        if self.machine_type not in data.MACHINE_DATA_IMPERIAL:
            raise InputError(f"{where}: machine_type: must be 'A' or 'B', got {self.machine_type!r}")
        if self.drive not in ("headstock", "vs_drive"):
            raise InputError(f"{where}: drive: must be 'headstock' or 'vs_drive', got {self.drive!r}")
        if self.boxes < 1:
            raise InputError(f"{where}: boxes: must be >= 1")
        if self.elements_per_section < 1:
            raise InputError(f"{where}: elements_per_section: must be >= 1")
        for key in ("drawroll_inertia_factor", "coupling_flexibility_factor", "mesh_flexibility_factor",
                    "headstock_inertia"):
            if not getattr(self, key) > 0:
                raise InputError(f"{where}: {key}: must be > 0")
        for key in ("bush_damping_factor", "damping_scale", "mesh_damping_factor", "drawroll_damping_factor"):
            if getattr(self, key) < 0:
                raise InputError(f"{where}: {key}: must be >= 0")
        if self.drawshaft_mid_diameter is not None and not self.drawshaft_mid_diameter > 0:
            raise InputError(f"{where}: drawshaft_mid_diameter: must be > 0")

    @property
    def speed_dependent(self) -> bool:
        """True when the matrices depend on the running speed (the rig's variable-speed drive)."""
        return self.drive == "vs_drive"


@dataclass
class DriveModel:
    """Assembled undamped/damped matrices of one configuration at one speed (SI, drawroll-referred).

    K [N m/rad], C [N m s/rad], M [kg m^2]: sparse symmetric n x n.
    mesh_dofs: (n_mesh, 2) DOF indices (bronze gear, steel gear) of every parallel helical mesh, ordered
        box 1 position 1 ... box NBM position 6.
    mesh_stiffness [N m/rad], mesh_damping [N m s/rad]: per mesh.
    mesh_labels: (box, position), both 1-based.
    """

    K: sp.csr_matrix
    C: sp.csr_matrix
    M: sp.csr_matrix
    mesh_dofs: np.ndarray
    mesh_stiffness: np.ndarray
    mesh_damping: np.ndarray
    mesh_labels: list[tuple[int, int]] = field(default_factory=list)

    @property
    def n_dof(self) -> int:
        """Number of degrees of freedom."""
        return self.K.shape[0]

    def dynamic_stiffness(self, omega: float) -> sp.csc_matrix:
        """Z(omega) = K + j omega C - omega^2 M  [N m/rad], omega in rad/s."""
        return (self.K + 1j * omega * self.C - omega**2 * self.M).tocsc()


class _Assembler:
    """Collects torsional nodes, springs, dampers and shaft elements as sparse triplets."""

    def __init__(self):
        self.n = 0
        self.k, self.c, self.m = [], [], []

    def node(self, inertia: float = 0.0, ground_damping: float = 0.0) -> int:
        i = self.n
        self.n += 1
        if inertia:
            self.m.append((i, i, inertia))
        if ground_damping:
            self.c.append((i, i, ground_damping))
        return i

    def _pair(self, target: list, i: int, j: int, value: float):
        target += [(i, i, value), (j, j, value), (i, j, -value), (j, i, -value)]

    def spring(self, i: int, j: int, stiffness: float, damping: float = 0.0):
        self._pair(self.k, i, j, stiffness)
        if damping:
            self._pair(self.c, i, j, damping)

    def shaft(self, start: int, length: float, diameter: float, n_el: int, shear_modulus: float,
              density: float) -> int:
        """Uniform shaft from node `start`, n_el linear elements; returns the far-end node."""
        polar = math.pi * diameter**4 / 32.0
        le = length / n_el
        k_el = shear_modulus * polar / le
        m_el = density * polar * le / 6.0          # consistent mass: m_el * [[2, 1], [1, 2]]
        a = start
        for _ in range(n_el):
            b = self.node()
            self.spring(a, b, k_el)
            self.m += [(a, a, 2 * m_el), (b, b, 2 * m_el), (a, b, m_el), (b, a, m_el)]
            a = b
        return a

    def matrices(self):
        def build(trip):
            if not trip:
                return sp.csr_matrix((self.n, self.n))
            r, c, v = zip(*trip)
            return sp.coo_matrix((v, (r, c)), shape=(self.n, self.n)).tocsr()
        return build(self.k), build(self.c), build(self.m)


def vs_drive_ratios(rpm: float, speed_ratio: float) -> dict:
    """Speed ratios of the rig's Kopp variator drive at drawroll speed `rpm` (Appendix H).

    Returns VSRAT = layshaft / motor speed, RATDB = disc / layshaft, RATRR = layshaft / variator output
    ring speed (all dimensionless).  The OCR of the disc-diameter formula is damaged; it is read as
    D = 1.414 V 2.7559 / (V + 1) / sqrt(1 + ((V - 1)/(V + 1))^2) with V = VSRAT (see docs/trueman.md)."""
    vs = data.VS_DRIVE_IMPERIAL
    layshaft_rpm = rpm / speed_ratio
    motor_rpm = vs["motor_speed_rpm"][0] + vs["motor_speed_rpm"][1] * rpm
    v = layshaft_rpm / motor_rpm
    c1, c2, c3 = vs["disc_constants"]
    disc = c1 * v * c2 / (v + 1.0) / math.sqrt(1.0 + ((v - 1.0) / (v + 1.0)) ** 2)
    ring_rpm = vs["output_speed_rpm"][0] + vs["output_speed_rpm"][1] * v
    return {"vsrat": v, "ratdb": disc / c3, "ratrr": layshaft_rpm / ring_rpm}


def _drive_node(asm: _Assembler, cfg: DriveConfig, d: dict, rpm: float | None) -> int:
    """Add the headstock (or rig drive) and return the node the first box coupling attaches to."""
    if cfg.drive == "headstock":
        return asm.node(cfg.headstock_inertia)
    if rpm is None or rpm <= 0:
        raise InputError(f"configuration {cfg.name!r}: drive: the rig drive needs a running speed > 0")
    vs = data.VS_DRIVE_IMPERIAL
    r = vs_drive_ratios(rpm, d["speed_ratio"])
    s2 = d["speed_ratio"] ** 2
    v2 = r["vsrat"] ** 2
    half = d["half_coupling_inertia"]
    j_motor = (vs["motor_inertia"] * data.LBF_IN + half) / (v2 * s2)
    jv = [j * data.LBF_IN for j in vs["unit_inertias"]]
    # variator unit referred to layshaft (output) speed, plus the two half couplings
    j_unit = jv[0] + jv[1] / r["ratdb"] ** 2 + jv[2] / r["ratrr"] ** 2 + jv[3] / v2
    j_out = (j_unit + half / v2 + half) / s2
    # a stiffness on the motor shaft referred to drawroll speed: k / (VSRAT SRAT)^2 (energy-consistent)
    k_motor = vs["motor_coupling_stiffness"] * data.LBF_IN / (v2 * s2)
    motor = asm.node(j_motor)
    out = asm.node(j_out)
    asm.spring(motor, out, k_motor)
    return out


def build_drive(cfg: DriveConfig, rpm: float | None = None) -> DriveModel:
    """Assemble the global torsional model of configuration `cfg` (at drawroll speed `rpm` [r.p.m.] for the
    speed-dependent rig drive; ignored otherwise)."""
    d = data.to_si(cfg.machine_type)
    s2 = d["speed_ratio"] ** 2
    damp = {k: v * cfg.damping_scale for k, v in d["damping"].items()}
    damp["crossed_mesh"] *= cfg.mesh_damping_factor
    damp["parallel_mesh"] *= cfg.mesh_damping_factor
    damp["drawroll"] *= cfg.drawroll_damping_factor
    k_coupling = d["coupling_stiffness"] / s2 / cfg.coupling_flexibility_factor
    sections = list(d["drawshaft_sections"])
    if cfg.drawshaft_mid_diameter is not None:
        sections[1] = (sections[1][0], cfg.drawshaft_mid_diameter)
    k_bush = d["bush_stiffness"]
    c_bush = d["bush_damping"] * cfg.bush_damping_factor * cfg.damping_scale

    asm = _Assembler()
    previous = _drive_node(asm, cfg, d, rpm)
    meshes, labels = [], []

    def drawshaft_line(gear: int):
        start = gear
        if cfg.bushed:
            start = asm.node()
            asm.spring(gear, start, k_bush, c_bush)
        for length, dia in sections:
            start = asm.shaft(start, length, dia, cfg.elements_per_section, d["shear_modulus"], d["density"])
        roll = start
        asm.m.append((roll, roll, d["drawroll_inertia"] * cfg.drawroll_inertia_factor))
        asm.c.append((roll, roll, damp["drawroll"]))

    for box in range(1, cfg.boxes + 1):
        lay_inertia = [d["half_coupling_inertia"], *d["layshaft_gear_inertia"], d["half_coupling_inertia"]]
        lay_damping = [damp["half_coupling"]] + [damp["layshaft_gear"]] * 6 + [damp["half_coupling"]]
        nodes = [asm.node(j / s2, c) for j, c in zip(lay_inertia, lay_damping)]
        asm.spring(previous, nodes[0], k_coupling, damp["coupling"])
        for i, k in enumerate(d["layshaft_stiffness"]):
            asm.spring(nodes[i], nodes[i + 1], k / s2)
        for pos in range(1, MESH_POSITIONS + 1):
            bronze = asm.node(d["bronze_gear_inertia"], damp["drawshaft_gear"])
            steel = asm.node(d["steel_gear_inertia"], damp["drawshaft_gear"])
            asm.spring(nodes[pos], bronze, d["crossed_mesh_stiffness"] / cfg.mesh_flexibility_factor,
                       damp["crossed_mesh"])
            asm.spring(bronze, steel, d["parallel_mesh_stiffness"] / cfg.mesh_flexibility_factor,
                       damp["parallel_mesh"])
            meshes.append((bronze, steel))
            labels.append((box, pos))
            drawshaft_line(bronze)
            drawshaft_line(steel)
        previous = nodes[-1]

    K, C, M = asm.matrices()
    n_mesh = len(meshes)
    return DriveModel(
        K=K, C=C, M=M,
        mesh_dofs=np.array(meshes, dtype=int),
        mesh_stiffness=np.full(n_mesh, d["parallel_mesh_stiffness"] / cfg.mesh_flexibility_factor),
        mesh_damping=np.full(n_mesh, damp["parallel_mesh"]),
        mesh_labels=labels,
    )
