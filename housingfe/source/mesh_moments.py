"""The shuttling moment: the mesh force's centre of pressure moving over the face as the mesh turns.

As the gears turn, the contact lines move across the plane of action, so the centre of pressure of the mesh load
moves axially (w) and along the line of action (s).  With a constant total normal force F the moment of that force
about each gear centre then fluctuates at the tooth frequency (Borner & Houser, "Friction and bending moments as
gear noise excitations", SAE 961816, 1996; Velex & Maatar, JSV 191(5), 1996 -- cited from memory, not verified in
the corpus).  Unlike the transmission error it does not cancel at an integer overlap ratio: with a uniform load per
unit contact length at eps_beta = 1 the total contact length is constant while its axial centroid moves as the
average of a sawtooth over the path of contact, first harmonic b |sin(pi eps_alpha)| / (pi^2 eps_alpha) [m]
(docs/source.md, "The shuttling moment (issue 28)"; tests/source/test_mesh_moments.py).

Convention (as `housingfe.source.stiffness.stiffness_curve` and the harmonic balance of
housingfe.source.roosmalen.dynamics): mesh position u = p_bt t / T_mesh, the time origin at u = 0; one-sided complex
amplitudes A_n of n f_tooth, x(t) = x_mean + Re(sum_n A_n exp(i 2 pi n f_tooth t)), from the same periodic linear
interpolation of the positions' samples onto `N_SAMPLES` instants that S(t) and F_e(t) use
(housingfe.source.roosmalen.run.OperatingPoint), so the arm's phase is that of the stiffness and the shock.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from housingfe.errors import InputError
from housingfe.source.stiffness import MeshModel, StiffnessCurve, load_centre

N_SAMPLES = 256        # the instants per mesh period of S(t) and F_e(t) in OperatingPoint


@dataclass
class CentreOfPressure:
    """The centre of pressure of the mesh load over one mesh period.  position: u / p_bt in [0, 1) [-];
    total_force: the normal force carried at each position [N]; axial_centre: w_c [m] over the gear (MeshModel's
    w, from its face w = 0); line_centre: s_c [m] along the transverse line of action from T1."""

    position: np.ndarray
    total_force: np.ndarray
    axial_centre: np.ndarray
    line_centre: np.ndarray

    @classmethod
    def of_curve(cls, curve: StiffnessCurve) -> "CentreOfPressure":
        """The centre of pressure a stiffness curve recorded at its positions (no second load distribution)."""
        if curve.axial_centre is None:
            raise InputError("mesh_moments: this stiffness curve has no centre of pressure (made by hand?)")
        return cls(curve.position, np.full(curve.position.size, curve.total_force), curve.axial_centre,
                   curve.line_centre)

    def axial_arm_harmonics(self, harmonics: int, n_samples: int = N_SAMPLES) -> np.ndarray:
        """(harmonics,) one-sided complex amplitudes [m] of w_c, n = 1..harmonics (module docstring)."""
        return one_sided_harmonics(self.position, self.axial_centre, harmonics, n_samples)

    def line_arm_harmonics(self, harmonics: int, n_samples: int = N_SAMPLES) -> np.ndarray:
        """(harmonics,) one-sided complex amplitudes [m] of s_c, n = 1..harmonics."""
        return one_sided_harmonics(self.position, self.line_centre, harmonics, n_samples)

    def moment_arm_harmonics(self, tan_base_helix: float, harmonics: int, n_samples: int = N_SAMPLES) -> np.ndarray:
        """(harmonics,) one-sided complex amplitudes [m] of the moment arm w_c + tan(beta_b) s_c.

        A force F n (n = cos(beta_b) d + sin(beta_b) a in the plane of action, d along growing s) whose point moves
        by ds along d and dw along the direction e_w in which w grows (e_w = -a for the MeshModel's hand:
        housingfe.drivetrain.description.Drivetrain.mesh_face_direction) changes its moment by
        F (dw + tan(beta_b) ds) (e_w x n): the shift along the contact line is what counts, the shift along n's
        own line gives none.  tan_base_helix: tan(beta_b) of the normal the moment is applied with (0 for a
        double helical pair, whose halves' terms cancel)."""
        arm = self.axial_centre + float(tan_base_helix) * self.line_centre
        return one_sided_harmonics(self.position, arm, harmonics, n_samples)


def one_sided_harmonics(position: np.ndarray, values: np.ndarray, harmonics: int,
                        n_samples: int = N_SAMPLES) -> np.ndarray:
    """One-sided complex amplitudes 2 X_n, n = 1..harmonics, of a periodic signal given at positions in [0, 1) of
    its period, linearly interpolated (periodically) onto n_samples instants as S(t) is; zero at and beyond the
    Nyquist limit.  Units: those of values."""
    t = np.arange(n_samples) / n_samples
    x = np.interp(t, np.asarray(position, float), np.asarray(values, float), period=1.0)
    X = np.fft.fft(x) / n_samples
    n = np.arange(1, int(harmonics) + 1)
    return np.where(n < n_samples / 2, 2 * X[np.minimum(n, n_samples - 1)], 0.0)


def centre_of_pressure_curve(model: MeshModel, total_force: float, n_positions: int = 32) -> CentreOfPressure:
    """The centre of pressure of `MeshModel.load_distribution` at a total normal force [N] at n_positions mesh
    positions u = k p_bt / n_positions (those of `stiffness_curve`).  A source that has the stiffness curve already
    takes `CentreOfPressure.of_curve` instead (the same numbers, no second load distribution)."""
    if not total_force > 0:
        raise InputError(f"mesh_moments: total force must be > 0 N, got {total_force}")
    pbt = model.pair.transverse_base_pitch
    pos = np.arange(n_positions) / n_positions
    rows = []
    for x in pos:
        pts, F, _ = model.load_distribution(x * pbt, total_force)
        rows.append(load_centre(pts, F))
    total, w_c, s_c = (np.array(c) for c in zip(*rows))
    return CentreOfPressure(pos, total, w_c, s_c)
