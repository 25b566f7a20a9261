"""Shared by the bearing-ranking experiments: one-factor changes of the FE interior's bearing matrices and bores.

Every variant is a function of a CouplingSpec (housingfe.drivetrain.interior) returning another one; nothing in
the package is changed.  Bearing matrices are taken in each bearing's own frame (z = shaft axis; DOFs x, y, z,
theta_x, theta_y, theta_z), as `BearingSpec.matrices()` returns them.
"""
from __future__ import annotations

import numpy as np

MOMENT = [3, 4]            # theta_x, theta_y rows/columns of a bearing matrix
TRANSLATION = [0, 1, 2]


def bearing_matrices(spec) -> dict:
    """{bearing name: (K, C)} of a coupling spec (designations resolved at their loads)."""
    return {b.name: b.matrices() for b in spec.bearings}


def with_bearing_matrices(spec, fn):
    """The spec with every bearing's K replaced by fn(name, K) (C kept)."""
    new = []
    for b in spec.bearings:
        K, C = b.matrices()
        new.append(b.model_copy(update={
            "designation": None, "load": None, "model": None, "fixed_tilt": None, "stiffness": None,
            "stiffness_matrix": np.asarray(fn(b.name, np.array(K, float)), float).tolist(),
            "damping_matrix": None if C is None else np.asarray(C, float).tolist()}))
    return spec.model_copy(update={"bearings": new})


def scale_moments(factor: float):
    """K -> S K S, S = 1 on translations, sqrt(factor) on the tilts: k_theta,theta x factor, the force-tilt coupling
    x sqrt(factor) (stays positive semi-definite); factor 0 is the thesis' 'ball bearings with zero moment
    stiffness' (moment rows and columns zeroed, Sec. 5.8)."""
    def fn(name, K):
        s = np.ones(6)
        s[MOMENT] = np.sqrt(factor)
        return s[:, None] * K * s[None, :]
    return fn


def scale_translations(factor: float):
    """K -> S K S with sqrt(factor) on x, y, z: the radial and axial stiffness x factor."""
    def fn(name, K):
        s = np.ones(6)
        s[TRANSLATION] = np.sqrt(factor)
        return s[:, None] * K * s[None, :]
    return fn


def translations_of(other_spec):
    """Replace each bearing's translational block (x, y, z) by that of the same bearing in other_spec, the moment
    rows/columns kept."""
    other = bearing_matrices(other_spec)

    def fn(name, K):
        K = K.copy()
        Ko = np.array(other[name][0], float)
        K[np.ix_(TRANSLATION, TRANSLATION)] = Ko[np.ix_(TRANSLATION, TRANSLATION)]
        return K
    return fn


def with_bores(spec, kind: str, rod_stiffness: float | None = None):
    """Every bore master of the spec tied by `kind` (rbe2 | rbe3 | star with rod_stiffness N/m per rod)."""
    return spec.model_copy(update={"bores": [b.model_copy(update={"kind": kind, "rod_stiffness": rod_stiffness})
                                             for b in spec.bores]})


def with_mesh_stiffness(spec, factor: float):
    """The gear mesh stiffness x factor (0: the wheel shaft alone, no pinion behind the mesh)."""
    return spec.model_copy(update={"gear_meshes": [m.model_copy(update={"stiffness": m.stiffness * factor})
                                                   for m in spec.gear_meshes]})


def diagonals(spec) -> dict:
    """{bearing: diagonal of K} for the README tables."""
    return {name: np.diag(K) for name, (K, _) in bearing_matrices(spec).items()}
