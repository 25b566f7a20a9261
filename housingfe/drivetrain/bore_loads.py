"""The loads the bearings put on the housing's bores, from a coupled solution in Ritz coordinates (issue 28 item 3).

A bearing is a lumped element between a shaft node and its bore master (housingfe.drivetrain.coupling.bearing:
12x12 K_e, C_e in global axes, the master reaching the shaft node by a rigid arm).  At a coupled solution
u = X c (X: the Ritz vectors' rows at the element's two nodes, c: the solution's Ritz coordinates) the element
holds the nodes with the forces (K_e + i omega C_e) u_e; what it puts on the bore master is the negative of the
bore rows of that:

    f_bore = -[(K_e + i omega C_e) X_e c]_{6:12}        (Fx Fy Fz in N, Mx My Mz in N m, about the master)

These are the loads through which the housing sees the drivetrain (the mesh force, shafts, gear bodies and
bearings are the PATH; bore loads -> surface velocity the HOUSING).  The modal damping of the coupled model is a
property of its modes, not of the elements: the bearing loads here hold the elements' own K and C only.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from housingfe import levels


def node_rows(structure, vectors, nodes) -> dict:
    """{node name: (6, vectors) displacements (m, rad) of an extra (interior) node in each coupled vector}."""
    out = {n: np.empty((6, len(vectors))) for n in nodes}
    for j, q in enumerate(vectors):
        for n in nodes:
            out[n][:, j] = structure.system.node_displacement(q, n)
    return out


@dataclass
class BearingElement:
    """One bearing between shaft node `shaft_node` and bore master `bore`: its 12x12 K (N/m, N/rad, N m/rad) and C
    (N s/m ...; zeros without damping) in global axes, the shaft node's rows first, and X (12, vectors): the Ritz
    vectors' rows at the two nodes."""

    shaft_node: str
    bore: str
    K: np.ndarray
    C: np.ndarray
    X: np.ndarray


def bearing_elements(bearings, rows: dict) -> list[BearingElement]:
    """The bearing elements (Parts.bearings: housingfe.drivetrain.coupling.Element, nodes (shaft node, bore
    master)) with their rows `rows` ({node: (6, vectors)}, `node_rows`).  A bearing to ground (no bore master) puts
    nothing on the housing and is left out."""
    out = []
    for e in bearings:
        if len(e.nodes) != 2 or None in e.nodes:
            continue
        K = np.asarray(e.K, float)
        C = np.zeros_like(K) if e.C is None else np.asarray(e.C, float)
        if K.shape != (12, 12):
            raise ValueError(f"bearing {e.nodes}: expected a 12x12 element, got {K.shape}")
        out.append(BearingElement(e.nodes[0], e.nodes[1], K, C, np.vstack([rows[n] for n in e.nodes])))
    return out


def structure_bearing_elements(structure, vectors) -> list[BearingElement]:
    """`bearing_elements` of a coupled structure (CoupledInterior: its parts.bearings) on Ritz vectors."""
    els = structure.parts.bearings
    nodes = sorted({n for e in els for n in e.nodes if n is not None})
    return bearing_elements(els, node_rows(structure, vectors, nodes))


def bore_loads(elements, frequency_hz, coefficients, *, c_factor=None) -> np.ndarray:
    """The loads the bearings put on their bore masters (complex, same amplitude convention as `coefficients`, e.g.
    rms): shape (lines, bearings, 6) = (Fx, Fy, Fz in N, Mx, My, Mz in N m about the bore master) for
    coefficients (vectors, lines) at frequency_hz (a number or one per line, Hz); (bearings, 6) for one solution
    (vectors,).  f = -[(K_e + s C_e) X_e c]_{6:12} with s = i omega; c_factor replaces s (a number or one per line:
    e.g. a real omega turns C into a stiffness, an experiment's control)."""
    c = np.asarray(coefficients)
    one = c.ndim == 1
    c = c[:, None] if one else c
    n = c.shape[1]
    s = 1j * 2 * math.pi * np.broadcast_to(np.asarray(frequency_hz, float), (n,)) if c_factor is None \
        else np.broadcast_to(np.asarray(c_factor), (n,))
    out = np.zeros((n, len(elements), 6), complex)
    for b, e in enumerate(elements):
        u = e.X @ c                                              # (12, lines): the element's node displacements
        out[:, b, :] = -((e.K[6:12] @ u) + s[None, :] * (e.C[6:12] @ u)).T
    return out[0] if one else out


def force_level_db(loads) -> np.ndarray:
    """10 lg(sum over bearings and the three force components of |F|^2 / (1 N)^2) per line (dB re 1 N; rms loads
    give the rms level), loads (..., bearings, 6) from `bore_loads`."""
    loads = np.asarray(loads)
    return levels.level(np.sum(np.abs(loads[..., :3]) ** 2, axis=(-2, -1)), levels.F0)


def moment_level_db(loads) -> np.ndarray:
    """10 lg(sum over bearings and the three moment components of |M|^2 / (1 N m)^2) per line (dB re 1 N m)."""
    loads = np.asarray(loads)
    return levels.level(np.sum(np.abs(loads[..., 3:6]) ** 2, axis=(-2, -1)), 1.0)
