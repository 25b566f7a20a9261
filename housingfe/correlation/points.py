"""Computed mode shapes at measured channels: each measured point is snapped to the nearest point of the
housing's surface (housingfe.response.observers.locate_response_points), and the FE displacement there is
projected on the channel's direction (PointEvaluator).  Same result on every MPI rank."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from housingfe.correlation.uff import ModeSet
from housingfe.errors import InputError
from housingfe.response.observers import PointEvaluator, SamplePoints, locate_response_points
from housingfe.scene import ResponsePointSpec


@dataclass
class Channels:
    """Measured channels snapped to the model: snapped points (m), unit directions, snapping distances (m)."""

    points: np.ndarray
    directions: np.ndarray
    distances: np.ndarray


def snap_channels(housing, points: np.ndarray, directions: np.ndarray, *, surface: str | None = None,
                  tolerance: float | None = None, source: str = "measured") -> Channels:
    """Snap channel points (m) to the housing surface (all tagged surfaces, or `surface`); InputError naming
    the channel when a point lies farther than `tolerance` (default one element size)."""
    pts = np.asarray(points, float).reshape(-1, 3)
    unique, inverse = np.unique(np.round(pts, 9), axis=0, return_inverse=True)
    specs = [ResponsePointSpec(name=f"p{k}", point=list(map(float, p)), surface=surface, tolerance=tolerance)
             for k, p in enumerate(unique)]
    try:
        located = locate_response_points(housing, specs)
    except InputError as exc:
        msg = str(exc).split(": ", 1)[-1]
        raise InputError(f"{source}: measured point: {msg}") from None
    snapped = np.array([rp.point for rp in located])[inverse.ravel()]
    dist = np.array([rp.distance for rp in located])[inverse.ravel()]
    d = np.asarray(directions, float).reshape(-1, 3)
    return Channels(snapped, d / np.linalg.norm(d, axis=1)[:, None], dist)


class ChannelSampler:
    """Evaluates FE fields (PETSc Vecs of the housing space V) on a fixed set of channels."""

    def __init__(self, V, channels: Channels):
        self.channels = channels
        self.evaluator = PointEvaluator(V, SamplePoints(channels.points, channels.directions,
                                                        np.ones(len(channels.points))))

    def sample(self, vectors) -> np.ndarray:
        """(channels x len(vectors)) displacement components along the channel directions (m per unit)."""
        return np.column_stack([self.evaluator.normal_values(v) for v in vectors]) if len(vectors) else \
            np.zeros((len(self.channels.points), 0))


def computed_modes_at(basis, measured: ModeSet, *, elastic_only: bool = True, surface: str | None = None,
                      tolerance: float | None = None) -> ModeSet:
    """The modes of a housingfe.solvers.modal.ModalBasis sampled on the channels of a measured ModeSet (same
    point ids, snapped points, directions); elastic modes only unless elastic_only is False."""
    structure = basis.structure
    try:
        channels = snap_channels(structure.housing, measured.points, measured.directions, surface=surface,
                                 tolerance=tolerance, source=measured.source or "measured")
    except InputError as exc:
        raise InputError(f"{exc}{unit_hint(structure.housing, measured.points, surface, tolerance)}") from None
    start = basis.rigid_count if elastic_only else 0
    vectors = [structure.to_housing(x) for x in basis.vectors[start:]]
    shapes = ChannelSampler(structure.V, channels).sample(vectors)
    return ModeSet(basis.frequencies_hz[start:].copy(), measured.node_ids.copy(), channels.points,
                   channels.directions, shapes, None, "computed")


def modal_receptance(shapes_response: np.ndarray, shapes_reference: np.ndarray, frequencies_hz: np.ndarray,
                     lines_hz: np.ndarray, loss_factor: float = 0.002) -> np.ndarray:
    """Point receptances (m/N, complex rms phasors, e^{iwt}) by modal superposition of mass-normalised elastic
    modes sampled at channels: H_ij(f) = sum_r phi_ir phi_jr / (w_r^2 (1 + i eta) - w^2).  shapes_*:
    (channels x modes) in m/sqrt(kg); returns (response channels, reference channels, lines).  Truncated
    (no residual flexibility of the modes above the basis): for correlation inside the basis' band."""
    wr2 = (2 * np.pi * np.asarray(frequencies_hz, float)) ** 2
    w2 = (2 * np.pi * np.asarray(lines_hz, float)) ** 2
    den = wr2[None, :] * (1 + 1j * loss_factor) - w2[:, None]            # (lines, modes)
    return np.einsum("ir,jr,fr->ijf", shapes_response, shapes_reference, 1.0 / den)


# What a measured file's coordinates may have been written in when they were read as m: factor to m
UNIT_GUESSES = (("mm", 1e-3), ("cm", 1e-2), ("in", 0.0254))


def unit_hint(housing, points: np.ndarray, surface: str | None = None, tolerance: float | None = None) -> str:
    """"; the points fit the surface if read in mm (--units mm)" when the measured points (m, as read), scaled
    by one of UNIT_GUESSES, all lie within `tolerance` (default one element size) of the surface; else the
    largest distances (m) under each guess.  Identical on every rank."""
    from housingfe.response.observers import _surface_triangles, closest_point_on_triangles

    names = [surface] if surface is not None else sorted(housing.facet_groups)
    tris, _ = _surface_triangles(housing, names)
    tol = tolerance if tolerance is not None else housing.element_size
    pts = np.unique(np.round(np.asarray(points, float).reshape(-1, 3), 9), axis=0)
    worst = {}
    for unit, factor in UNIT_GUESSES:
        worst[unit] = max(float(closest_point_on_triangles(p * factor, tris)[1].min()) for p in pts)
    fits = [u for u, d in worst.items() if d <= tol]
    if fits:
        return f"; the points fit the surface if read in {fits[0]} (--units {fits[0]})"
    far = ", ".join(f"{u}: {d:.3g} m" for u, d in worst.items())
    return f"; read in other units they would lie up to ({far}) from it: check the coordinates"
