"""Sliding friction as a mesh excitation (issue 28): the friction resultants over one mesh period.

Besides the transmission error and the shuttling moment (housingfe.source.mesh_moments), the literature names the
sliding friction mu F_i at the contact points (Borner & Houser, SAE 961816, 1996; Vaishya & Singh, JSV 2001 --
cited from memory, not verified in the corpus).  The sliding velocity changes sign at the pitch point, so the
friction force on each flank reverses there; as the contact lines move through the plane of action the split of the
load between approach (s < s_P) and recess (s > s_P) changes at the tooth frequency.  Per unit friction coefficient
the resultants come with the stiffness curve (StiffnessCurve.unit_friction, from the same load distributions:
`housingfe.source.stiffness.friction_resultants`, whose docstring gives the directions and signs); `FrictionCurve`
scales them by a mean coefficient and gives their harmonics in S(t)'s convention (mesh_moments.one_sided_harmonics).

Like the TE from the face-width engagement, the friction force cancels at an integer overlap ratio with a uniform
load per unit length: the contact length on either side of the pitch line is then constant
(tests/source/test_mesh_friction.py).  The mean coefficient: `iso13989_mean_friction` (docs/source.md, "Sliding
friction").
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from housingfe.errors import InputError
from housingfe.source.mesh_moments import N_SAMPLES, one_sided_harmonics
from housingfe.source.stiffness import FRICTION_RESULTANTS, MeshModel, StiffnessCurve, friction_resultants

# the oil and flanks that `iso13989_run_friction` (the run-up's runup.mesh_friction = "iso13989") assumes: the thesis'
# test gearbox states neither for its gears; Shell Omala 150 at the viscosity the thesis' fluid-film bearings take
# (Sec. 3.5) and ground flanks of Ra 0.4 um (the central point of benchmarks/experiments/shuttling) -- assumed
ISO13989_VISCOSITY = 0.049          # Pa s
ISO13989_ROUGHNESS_RA = 0.4e-6      # m


@dataclass
class FrictionCurve:
    """Sliding-friction resultants over one mesh period at a mean friction coefficient mu [-].

    position: u / p_bt in [0, 1) [-]; force: friction force on the pinion along e_f (from the pinion centre to T1,
    normal to the plane of action; on the wheel the opposite) [N]; pinion_torque, wheel_torque: about each gear's
    rotation vector [N m] (levers s from T1 and L - s from T2); tilt_moment: the friction force's moment about the
    gear middle, along e_w x e_f on the pinion, opposite on the wheel [N m].  Signs:
    housingfe.source.stiffness.friction_resultants."""

    position: np.ndarray
    force: np.ndarray
    pinion_torque: np.ndarray
    wheel_torque: np.ndarray
    tilt_moment: np.ndarray
    mu: float

    @classmethod
    def of_curve(cls, curve: StiffnessCurve, mu: float) -> "FrictionCurve":
        """The friction resultants at coefficient mu [-] from the load distributions a stiffness curve recorded
        (StiffnessCurve.unit_friction: no second load distribution)."""
        if curve.unit_friction is None:
            raise InputError("mesh_friction: this stiffness curve has no friction resultants (made by hand?)")
        _check_mu(mu)
        return cls(curve.position, *(float(mu) * np.asarray(curve.unit_friction[k]) for k in FRICTION_RESULTANTS),
                   mu=float(mu))

    def mean(self, name: str) -> float:
        """Mean over the mesh period of resultant `name` (force N, torques and tilt_moment N m)."""
        return float(np.mean(getattr(self, name)))

    def harmonics(self, name: str, harmonics: int, n_samples: int = N_SAMPLES) -> np.ndarray:
        """(harmonics,) one-sided complex amplitudes, n = 1..harmonics, of resultant `name` ("force" [N],
        "pinion_torque", "wheel_torque", "tilt_moment" [N m]) in S(t)'s convention (mesh_moments)."""
        if name not in FRICTION_RESULTANTS:
            raise InputError(f"mesh_friction: {name!r} is not one of {', '.join(FRICTION_RESULTANTS)}")
        return one_sided_harmonics(self.position, getattr(self, name), harmonics, n_samples)


def _check_mu(mu: float) -> None:
    if not (math.isfinite(mu) and 0 <= mu < 1):
        raise InputError(f"mesh_friction: friction coefficient must be in [0, 1), got {mu}")


def friction_curve(model: MeshModel, total_force: float, mu: float, n_positions: int = 32) -> FrictionCurve:
    """The friction resultants of `MeshModel.load_distribution` at a total normal force [N] and coefficient mu [-]
    at n_positions mesh positions u = k p_bt / n_positions (those of `stiffness_curve`; a source with the stiffness
    curve takes `FrictionCurve.of_curve` instead)."""
    if not total_force > 0:
        raise InputError(f"mesh_friction: total force must be > 0 N, got {total_force}")
    _check_mu(mu)
    pbt = model.pair.transverse_base_pitch
    pos = np.arange(n_positions) / n_positions
    rows = []
    for x in pos:
        pts, F, _ = model.load_distribution(x * pbt, total_force)
        rows.append(friction_resultants(model.pair, pts, F, model.total_width, mu))
    return FrictionCurve(pos, *(np.array([r[k] for r in rows]) for k in FRICTION_RESULTANTS), mu=float(mu))


def iso13989_mean_friction(load_per_width: float, sum_velocity: float, reduced_radius: float, viscosity: float,
                           roughness_ra: float, pinion_diameter: float, helical_load_factor: float = 1.0,
                           lubricant_factor: float = 1.0) -> float:
    """Mean coefficient of friction of the mesh [-] after ISO/TR 13989-1:2000 (flash temperature method; quoted
    from memory, not verified in the corpus):

        mu_mC = 0.045 (w_Bt K_Bgamma / (v_SigmaC rho_redC))^0.2 eta_oil^-0.05 X_R X_L,  X_R = 3.8 (Ra / d_1)^0.25

    in the standard's units, converted here from SI: load_per_width w_Bt = K_A K_v K_Hbeta K_Halpha F_t / b [N/m]
    (-> N/mm); sum_velocity v_SigmaC = 2 v_t sin(alpha_wt), the sum of the rolling velocities at the pitch point
    [m/s]; reduced_radius rho_redC = u / (1 + u)^2 a sin(alpha_wt) / cos(beta_b) [m] (-> mm); viscosity eta_oil,
    dynamic at the oil temperature [Pa s] (-> mPa s); roughness_ra Ra = (Ra1 + Ra2) / 2 [m] (-> um);
    pinion_diameter d_1 [m] (-> mm); helical_load_factor K_Bgamma (`iso13989_helical_load_factor`);
    lubricant_factor X_L (1 for mineral oil).  The standard caps v_SigmaC at 50 m/s."""
    for name, v in (("load_per_width", load_per_width), ("sum_velocity", sum_velocity),
                    ("reduced_radius", reduced_radius), ("viscosity", viscosity), ("roughness_ra", roughness_ra),
                    ("pinion_diameter", pinion_diameter)):
        if not (math.isfinite(v) and v > 0):
            raise InputError(f"mesh_friction: {name} must be > 0, got {v}")
    w = load_per_width * 1e-3
    v = min(sum_velocity, 50.0)
    rho = reduced_radius * 1e3
    x_r = 3.8 * (roughness_ra * 1e6 / (pinion_diameter * 1e3)) ** 0.25
    return 0.045 * (w * helical_load_factor / (v * rho)) ** 0.2 * (viscosity * 1e3) ** -0.05 * x_r * lubricant_factor


def iso13989_helical_load_factor(total_contact_ratio: float) -> float:
    """K_Bgamma [-] of ISO/TR 13989-1 from eps_gamma = eps_alpha + eps_beta: 1 up to 2, then
    1 + 0.2 sqrt((eps_gamma - 2)(5 - eps_gamma)) up to 3.5, 1.3 beyond (from memory, as `iso13989_mean_friction`)."""
    e = float(total_contact_ratio)
    if e <= 2.0:
        return 1.0
    if e < 3.5:
        return 1.0 + 0.2 * math.sqrt((e - 2.0) * (5.0 - e))
    return 1.3


def mesh_mean_friction(pair, pinion_torque: float, pinion_speed_rpm: float, viscosity: float,
                       roughness_ra: float, lubricant_factor: float = 1.0) -> float:
    """`iso13989_mean_friction` [-] of a GearPair at a pinion torque [N m] and speed [rpm], with the oil's dynamic
    viscosity [Pa s] and the flanks' mean roughness Ra [m]: F_t = 2 T_1 / d_1 on the reference circle over the
    total face width, all load factors K_A K_v K_Hbeta K_Halpha = 1 (the nominal load), v_t = omega_1 d_1 / 2,
    rho_redC from the operating centre distance, eps_gamma = eps_alpha + eps_beta."""
    if not (pinion_torque > 0 and pinion_speed_rpm > 0):
        raise InputError("mesh_friction: pinion torque and speed must be > 0")
    d1 = float(pair.pitch_diameter[0])
    u = pair.teeth[1] / pair.teeth[0]
    alpha_wt = pair.operating_pressure_angle
    v_t = pinion_speed_rpm * 2 * math.pi / 60 * d1 / 2
    rho = u / (1 + u) ** 2 * pair.centre_distance * math.sin(alpha_wt) / math.cos(pair.base_helix_angle)
    k_b = iso13989_helical_load_factor(pair.transverse_contact_ratio + pair.overlap_ratio)
    return iso13989_mean_friction(2 * pinion_torque / d1 / pair.total_contact_width, 2 * v_t * math.sin(alpha_wt),
                                  rho, viscosity, roughness_ra, d1, k_b, lubricant_factor)


def iso13989_run_friction(pair, pinion_torque: float, pinion_speed_rpm: float) -> float:
    """`mesh_mean_friction` [-] at a pinion torque [N m] and speed [rpm] with the assumed oil and flanks
    (ISO13989_VISCOSITY, ISO13989_ROUGHNESS_RA): the run-up's runup.mesh_friction = "iso13989".  The formula is
    quoted from memory (`iso13989_mean_friction`), not verified against the standard's text."""
    return mesh_mean_friction(pair, pinion_torque, pinion_speed_rpm, ISO13989_VISCOSITY, ISO13989_ROUGHNESS_RA)
