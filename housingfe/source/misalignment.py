"""Misalignment of the gear mesh under load, as the linear gap across the face that the load distribution sees.

Under the operating torque the mean tooth force tilts the two gears against each other (bearings, shafts, housing).
A relative rotation dtheta = theta_pinion - theta_wheel [rad] of two rigid gear bodies changes the mesh compression
c = n . (u_p + theta_p x r_p) - n . (u_w + theta_w x r_w) (n: unit contact normal, pointing from the pinion into the
wheel, the direction of the force on the wheel) along the face: moving the contact point by zeta along the unit axial
direction e_w changes c by zeta dtheta . (e_w x n).  The flank gap is minus the compression, so the lead gap of
`MeshModel.lead_gap` (m of gap along the flank normal per m of the face coordinate w) is

    lead_gap = - dtheta . (e_w x n),     e_w: the unit vector along which the MeshModel's w grows,

and since n = cos(beta_b) l -/+ sin(beta_b) e_w (l: the transverse line of action, pointing from T1 to T2),
e_w x n = cos(beta_b) e_w x l: only the relative tilt about the normal of the plane of action,
gamma = dtheta . (e_w x l) / |e_w x l| [rad] (the misalignment "in the plane of action" of ISO 6336-1's f_ma),
opens a gap: lead_gap = -cos(beta_b) gamma.  Constant parts (translations, rotations about other axes) only move
the mean approach.

Where e_w points: in the MeshModel the contact line of helix 0 runs s = s0 + w tan(beta_b), i.e. the contact
normal is n = cos(beta_b) l - sin(beta_b) e_w.  In the lumped model (housingfe.source.roosmalen.dynamics.mesh_direction,
n = (sin a cos bb, cos a cos bb, -sin bb)) that is e_w = +z; in the FE reduction of housingfe.drivetrain (n with
+sin(beta_b) along the shaft axis a) e_w = -a.  MeshModel's torque_configuration fixes the pinion torque at w = 0.

Models (`MISALIGNMENT_MODELS` of this layer; housingfe.drivetrain.misalignment adds the FE interior):
* "none": aligned gears (the thesis' load distribution, Sec. 2.3; what the chain did before);
* "lumped": the static mean state of the 14-DOF lumped model (Appendix C's bearing diagonal at the gear centres,
  the mean mesh stiffness with the tilt coupling of the axial force) under the operating torque.
The shafts' bending between rigid supports and the wheel-body torsion stay in the MeshModel (Sec. 2.2.3-2.2.4);
the misalignment adds what deflects the supports.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from housingfe.errors import InputError

MISALIGNMENT_MODELS = ("none", "lumped")


@dataclass(frozen=True)
class Misalignment:
    """The mesh misalignment of one operating point.  gamma [rad]: relative tilt pinion - wheel about the normal of
    the plane of action (e_w x l); lead_gap [m/m]: the MeshModel's linear gap slope (-cos(beta_b) gamma);
    gap_across_face [m]: |lead_gap| x the gear's total width; tilt_pinion, tilt_wheel (3,) [rad]: the rotation
    vectors of the two gear bodies in the model's frame; model: how it was computed; torque [N m]."""

    model: str
    torque: float
    gamma: float
    lead_gap: float
    gap_across_face: float
    tilt_pinion: tuple = (0.0, 0.0, 0.0)
    tilt_wheel: tuple = (0.0, 0.0, 0.0)

    def summary(self) -> dict:
        """JSON-able numbers (gamma in urad, gap in um)."""
        return {"model": self.model, "torque_nm": self.torque, "gamma_urad": self.gamma * 1e6,
                "lead_gap_um_per_m": self.lead_gap * 1e6, "gap_across_face_um": self.gap_across_face * 1e6}


def from_tilts(model: str, torque: float, theta_pinion, theta_wheel, face_axis, normal, total_width: float,
               base_helix_angle: float) -> Misalignment:
    """The Misalignment of two rigid-gear rotation vectors [rad] (any frame), with e_w = `face_axis` and the contact
    normal `normal` (force on the wheel; only its transverse part l is used, so the resultant normal of a double
    helical pair, which has none along the axis, will do) in that frame; total_width [m] of the gear over both
    helices; base_helix_angle [rad] of the pair: lead_gap = -cos(beta_b) gamma."""
    e_w = np.asarray(face_axis, float) / np.linalg.norm(face_axis)
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    d_theta = np.asarray(theta_pinion, float) - np.asarray(theta_wheel, float)
    transverse = n - (n @ e_w) * e_w
    m = np.cross(e_w, transverse)
    gamma = float(d_theta @ m / np.linalg.norm(m))
    lead_gap = -math.cos(base_helix_angle) * gamma
    return Misalignment(model, float(torque), gamma, lead_gap, abs(lead_gap) * total_width,
                        tuple(float(x) for x in theta_pinion), tuple(float(x) for x in theta_wheel))


def lumped_misalignment(pair, mats, preload: np.ndarray, torque: float, total_width: float) -> Misalignment:
    """The "lumped" misalignment: static mean state q = (K0 + k_m h h^T)^-1 f0 of the 14-DOF model
    (housingfe.source.roosmalen.dynamics: `mats` = assemble(...), `preload` = preload_force(mats, torque)).  Its gear tilts
    theta_x, theta_y (DOFs 3, 4 and 9, 10, ordinary right-handed rotations of the lumped frame; theta_z does not
    tilt) give gamma; e_w = +z of the lumped frame, n = the pinion's part of h."""
    K = mats.K0 + mats.mean_mesh_stiffness * np.outer(mats.h, mats.h)
    q = np.linalg.solve(K, preload)
    theta_p = np.array([q[3], q[4], 0.0])
    theta_w = np.array([q[9], q[10], 0.0])
    normal = mats.h[0:3]
    return from_tilts("lumped", torque, theta_p, theta_w, (0.0, 0.0, 1.0), normal, total_width,
                      pair.base_helix_angle)


def check_model(name: str, known=MISALIGNMENT_MODELS) -> str:
    """`name` if it is one of `known`, else InputError."""
    if name not in known:
        raise InputError(f"misalignment: {name!r} is not one of {', '.join(known)}")
    return name
