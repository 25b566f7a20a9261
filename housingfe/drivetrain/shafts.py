"""Shafts as Timoshenko beam elements (12 DOF: 6 per node) and rigid discs (gears), SI units.

Element: two nodes, DOFs per node (u_x, u_y, u_z, theta_x, theta_y, theta_z) in global axes.  In the local frame
(x' along the element) bending uses the interdependent interpolation of the Timoshenko beam (cubic deflection,
quadratic rotation, shear parameter Phi = 12 E I / (kappa G A L^2)), which is exact for end-loaded statics;
the stiffness is int EI theta'^2 + kappa G A (v' - theta)^2 and the consistent mass int rho A v^2 + rho I theta^2
(translational plus rotary inertia), both integrated exactly by Gauss quadrature.  Axial and torsion: linear.
For Phi -> 0 the element is the Euler–Bernoulli (Hermite) beam.  Shear correction factor of a (hollow) circular
section after Cowper (1966): kappa = 6 (1 + nu)(1 + m^2)^2 / ((7 + 6 nu)(1 + m^2)^2 + (20 + 12 nu) m^2),
m = d_inner / d_outer (solid: 6 (1 + nu) / (7 + 6 nu)).

A shaft is a chain of such elements along any direction (default +z, the bearing convention); stepped diameters
are a list of (length, outer diameter[, inner diameter]) segments.  Gears are rigid discs: mass m, polar inertia
I_p about the shaft axis and diametral inertia I_d about any transverse axis through the centre, lumped on a
node.  No gyroscopic terms (the thesis' vibration transfer is at the mean speed; add them later if needed).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from housingfe.errors import InputError
from housingfe.materials import LIBRARY, Material

DOFS_PER_NODE = 6


STEEL = LIBRARY["steel"]   # the housing's steel (housingfe.materials): one Material class for FE and beams



@dataclass(frozen=True)
class CircularSection:
    """(Hollow) circular cross-section; diameters in m."""
    outer_diameter: float
    inner_diameter: float = 0.0

    def __post_init__(self):
        if not (self.outer_diameter > 0 and 0 <= self.inner_diameter < self.outer_diameter):
            raise InputError(f"shaft section: outer {self.outer_diameter} m, inner {self.inner_diameter} m: "
                             "need 0 <= inner < outer")

    @property
    def area(self) -> float:
        """A [m^2]."""
        return math.pi / 4.0 * (self.outer_diameter**2 - self.inner_diameter**2)

    @property
    def second_moment(self) -> float:
        """I = I_y = I_z [m^4] about a diameter."""
        return math.pi / 64.0 * (self.outer_diameter**4 - self.inner_diameter**4)

    @property
    def polar_moment(self) -> float:
        """J = 2 I [m^4] (torsion constant of a circular tube)."""
        return 2.0 * self.second_moment

    def shear_factor(self, nu: float) -> float:
        """Cowper's shear correction factor kappa [-] of a (hollow) circular section."""
        m2 = (self.inner_diameter / self.outer_diameter) ** 2
        return 6.0 * (1 + nu) * (1 + m2) ** 2 / ((7 + 6 * nu) * (1 + m2) ** 2 + (20 + 12 * nu) * m2)


# --------------------------------------------------------------------------------------- one bending plane
def _bending_shape(xi: np.ndarray, length: float, phi: float) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                                         np.ndarray]:
    """Timoshenko interdependent shape functions for DOFs (v1, t1, v2, t2): N_v, N_t and their x-derivatives,
    each (len(xi), 4).  theta is the cross-section rotation, dv/dx - theta the shear strain."""
    L, c = length, 1.0 / (1.0 + phi)
    x2, x3 = xi**2, xi**3
    nv = c * np.stack([1 - 3 * x2 + 2 * x3 + phi * (1 - xi),
                       L * (xi - 2 * x2 + x3 + phi * (xi - x2) / 2),
                       3 * x2 - 2 * x3 + phi * xi,
                       L * (-x2 + x3 - phi * (xi - x2) / 2)], axis=1)
    dnv = c / L * np.stack([-6 * xi + 6 * x2 - phi,
                            L * (1 - 4 * xi + 3 * x2 + phi * (1 - 2 * xi) / 2),
                            6 * xi - 6 * x2 + phi,
                            L * (-2 * xi + 3 * x2 - phi * (1 - 2 * xi) / 2)], axis=1)
    nt = c * np.stack([6 / L * (x2 - xi),
                       1 - 4 * xi + 3 * x2 + phi * (1 - xi),
                       6 / L * (xi - x2),
                       -2 * xi + 3 * x2 + phi * xi], axis=1)
    dnt = c / L * np.stack([6 / L * (2 * xi - 1),
                            -4 + 6 * xi - phi,
                            6 / L * (1 - 2 * xi),
                            -2 + 6 * xi + phi], axis=1)
    return nv, dnv, nt, dnt


def bending_matrices(length: float, EI: float, kGA: float, rhoA: float, rhoI: float
                     ) -> tuple[np.ndarray, np.ndarray]:
    """4x4 stiffness and consistent mass of one Timoshenko bending plane, DOFs (v1, theta1, v2, theta2) with
    theta = dv/dx in the Euler–Bernoulli limit.  Units: N/m, N, N m/rad and kg, kg m, kg m^2."""
    phi = 12.0 * EI / (kGA * length**2)
    gx, gw = np.polynomial.legendre.leggauss(4)        # exact for the degree-6 integrands
    xi = (gx + 1) / 2
    w = gw / 2 * length
    nv, dnv, nt, dnt = _bending_shape(xi, length, phi)
    gamma = dnv - nt
    k = EI * (dnt.T * w) @ dnt + kGA * (gamma.T * w) @ gamma
    m = rhoA * (nv.T * w) @ nv + rhoI * (nt.T * w) @ nt
    return k, m


# --------------------------------------------------------------------------------------- 12x12 element
# local DOF indices (node 1: 0..5, node 2: 6..11) of the two bending planes: (v, theta) pairs
_PLANE_XY = [1, 5, 7, 11]          # v = u_y, theta = theta_z (= +dv/dx)
_PLANE_XZ = [2, 4, 8, 10]          # w = u_z, theta = theta_y (= -dw/dx): sign flip on the rotations
_SIGN_XZ = np.array([1.0, -1.0, 1.0, -1.0])


def local_beam_matrices(length: float, section: CircularSection, material: Material
                        ) -> tuple[np.ndarray, np.ndarray]:
    """12x12 local stiffness [N/m, N/rad, N m/rad] and consistent mass [kg, kg m, kg m^2] of a Timoshenko beam
    along local x: axial, torsion, two bending planes with shear deformation and rotary inertia."""
    if not (length > 0):
        raise InputError(f"beam element length {length} m: must be > 0")
    E, G, rho = material.youngs_modulus, material.shear_modulus, material.density
    A, I, J = section.area, section.second_moment, section.polar_moment
    kga = section.shear_factor(material.poisson_ratio) * G * A
    k = np.zeros((12, 12))
    m = np.zeros((12, 12))
    bar = np.array([[1.0, -1.0], [-1.0, 1.0]])
    lumped_pair = np.array([[2.0, 1.0], [1.0, 2.0]]) / 6.0
    k[np.ix_([0, 6], [0, 6])] = E * A / length * bar
    m[np.ix_([0, 6], [0, 6])] = rho * A * length * lumped_pair
    k[np.ix_([3, 9], [3, 9])] = G * J / length * bar
    m[np.ix_([3, 9], [3, 9])] = rho * J * length * lumped_pair
    kb, mb = bending_matrices(length, E * I, kga, rho * A, rho * I)
    k[np.ix_(_PLANE_XY, _PLANE_XY)] = kb
    m[np.ix_(_PLANE_XY, _PLANE_XY)] = mb
    s = np.outer(_SIGN_XZ, _SIGN_XZ)
    k[np.ix_(_PLANE_XZ, _PLANE_XZ)] = kb * s
    m[np.ix_(_PLANE_XZ, _PLANE_XZ)] = mb * s
    return k, m


def element_rotation(p1, p2, reference=None) -> np.ndarray:
    """3x3 matrix whose rows are the local axes (x' from p1 to p2, y', z') in global coordinates.

    reference: a vector not parallel to the element that fixes y' (default global z, or global x for an element
    along z); irrelevant for circular sections except for the orientation of the local results."""
    p1, p2 = np.asarray(p1, float), np.asarray(p2, float)
    ex = p2 - p1
    length = np.linalg.norm(ex)
    if length == 0:
        raise InputError("beam element: both nodes at the same point")
    ex /= length
    if reference is None:
        reference = (0.0, 0.0, 1.0) if abs(ex[2]) < 0.9 else (1.0, 0.0, 0.0)
    ez = np.cross(ex, np.asarray(reference, float))
    if np.linalg.norm(ez) < 1e-9:
        raise InputError("beam element: reference vector parallel to the element")
    ez /= np.linalg.norm(ez)
    ey = np.cross(ez, ex)
    return np.vstack([ex, ey, ez])


def beam_element_matrices(p1, p2, section: CircularSection, material: Material = STEEL, reference=None
                          ) -> tuple[np.ndarray, np.ndarray]:
    """12x12 global stiffness and consistent mass of a Timoshenko beam from p1 to p2 (points in m)."""
    r = element_rotation(p1, p2, reference)
    t = np.kron(np.eye(4), r)
    k, m = local_beam_matrices(float(np.linalg.norm(np.subtract(p2, p1))), section, material)
    return t.T @ k @ t, t.T @ m @ t


# --------------------------------------------------------------------------------------- discs and shafts
@dataclass(frozen=True)
class RigidDisc:
    """Rigid disc (gear body): mass [kg], polar inertia I_p [kg m^2] about the shaft axis, diametral inertia I_d
    [kg m^2] about a transverse axis through its centre."""
    mass: float
    polar_inertia: float
    diametral_inertia: float

    def __post_init__(self):
        if not (self.mass >= 0 and self.polar_inertia >= 0 and self.diametral_inertia >= 0):
            raise InputError(f"rigid disc: mass {self.mass} kg, inertias {self.polar_inertia}, "
                             f"{self.diametral_inertia} kg m^2: must be >= 0")

    @classmethod
    def cylinder(cls, outer_diameter: float, width: float, inner_diameter: float = 0.0, rho: float = 7850.0):
        """Disc of a solid or bored cylinder (a gear blank of its pitch or mean diameter), SI units."""
        ro, ri = outer_diameter / 2, inner_diameter / 2
        if not (ro > ri >= 0 and width > 0):
            raise InputError(f"rigid disc: outer {outer_diameter} m, inner {inner_diameter} m, width {width} m")
        m = rho * math.pi * (ro**2 - ri**2) * width
        return cls(m, m * (ro**2 + ri**2) / 2, m * (3 * (ro**2 + ri**2) + width**2) / 12)

    def mass_matrix(self, axis) -> np.ndarray:
        """6x6 mass matrix on a node (global axes) for a shaft along `axis`."""
        a = np.asarray(axis, float) / np.linalg.norm(axis)
        out = np.zeros((6, 6))
        out[:3, :3] = self.mass * np.eye(3)
        out[3:, 3:] = self.diametral_inertia * np.eye(3) + (self.polar_inertia - self.diametral_inertia) * np.outer(a, a)
        return out


@dataclass
class Shaft:
    """A straight shaft of Timoshenko elements: nodes (n, 3) [m], elements (i, j, section), discs {node: disc},
    supports {node: 6x6 stiffness to ground}."""
    nodes: np.ndarray
    elements: list
    material: Material = STEEL
    discs: dict = field(default_factory=dict)
    supports: dict = field(default_factory=dict)

    @classmethod
    def stepped(cls, segments, material: Material = STEEL, origin=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0),
                elements_per_segment: int | list[int] = 4) -> Shaft:
        """Shaft from segments [(length, outer_d[, inner_d]), ...] [m] laid end to end from `origin` along `axis`.

        Each segment is split into elements_per_segment equal elements (an int or one int per segment)."""
        if not segments:
            raise InputError("shaft: no segments")
        a = np.asarray(axis, float)
        if np.linalg.norm(a) == 0:
            raise InputError("shaft: axis is the zero vector")
        a = a / np.linalg.norm(a)
        counts = ([elements_per_segment] * len(segments) if isinstance(elements_per_segment, int)
                  else list(elements_per_segment))
        if len(counts) != len(segments) or min(counts) < 1:
            raise InputError("shaft: elements_per_segment must be >= 1 for every segment")
        s, positions, elements = 0.0, [0.0], []
        for (seg, count) in zip(segments, counts):
            length, *diameters = seg
            if not length > 0:
                raise InputError(f"shaft: segment length {length} m must be > 0")
            section = CircularSection(*diameters)
            for _ in range(count):
                s += length / count
                positions.append(s)
                elements.append((len(positions) - 2, len(positions) - 1, section))
        nodes = np.asarray(origin, float)[None, :] + np.asarray(positions)[:, None] * a[None, :]
        return cls(nodes=nodes, elements=elements, material=material)

    @property
    def axis(self) -> np.ndarray:
        """Unit vector from the first to the last node."""
        d = self.nodes[-1] - self.nodes[0]
        return d / np.linalg.norm(d)

    @property
    def n_dofs(self) -> int:
        return DOFS_PER_NODE * len(self.nodes)

    def node_at(self, position: float) -> int:
        """Index of the node nearest to the axial coordinate `position` [m] from the first node."""
        s = (self.nodes - self.nodes[0]) @ self.axis
        return int(np.argmin(np.abs(s - position)))

    def add_disc(self, node: int, disc: RigidDisc) -> None:
        """Lump a rigid disc (gear) on a node (adds to one already there)."""
        if not (0 <= node < len(self.nodes)):
            raise InputError(f"shaft: disc node {node} out of range 0..{len(self.nodes) - 1}")
        old = self.discs.get(node)
        if old is not None:
            disc = RigidDisc(old.mass + disc.mass, old.polar_inertia + disc.polar_inertia,
                             old.diametral_inertia + disc.diametral_inertia)
        self.discs[node] = disc

    def add_support(self, node: int, stiffness) -> None:
        """Connect a node to ground (a rigid housing) through a 6x6 stiffness in global axes, e.g. a bearing's
        `transform_stiffness(result.K, R)` [N/m, N/rad, N m/rad]; adds to one already there."""
        k = np.asarray(stiffness, float)
        if k.shape != (6, 6) or not np.all(np.isfinite(k)):
            raise InputError(f"shaft: support stiffness on node {node}: need a finite 6x6 matrix")
        if not (0 <= node < len(self.nodes)):
            raise InputError(f"shaft: support node {node} out of range 0..{len(self.nodes) - 1}")
        self.supports[node] = self.supports.get(node, np.zeros((6, 6))) + k

    def matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """Global stiffness K and mass M (dense, n_dofs x n_dofs; DOF 6*node + (ux, uy, uz, tx, ty, tz))."""
        n = self.n_dofs
        k, m = np.zeros((n, n)), np.zeros((n, n))
        for i, j, section in self.elements:
            ke, me = beam_element_matrices(self.nodes[i], self.nodes[j], section, self.material)
            idx = np.r_[6 * i:6 * i + 6, 6 * j:6 * j + 6]
            k[np.ix_(idx, idx)] += ke
            m[np.ix_(idx, idx)] += me
        for node, disc in self.discs.items():
            idx = slice(6 * node, 6 * node + 6)
            m[idx, idx] += disc.mass_matrix(self.axis)
        for node, k_support in self.supports.items():
            idx = slice(6 * node, 6 * node + 6)
            k[idx, idx] += k_support
        return k, m


def dof(node: int, component: int) -> int:
    """Global DOF index of a node's component (0..5 = ux, uy, uz, theta_x, theta_y, theta_z)."""
    return DOFS_PER_NODE * node + component
