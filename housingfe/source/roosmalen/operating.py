"""The source as a stage: `SourceModel.operating_point(speed_rpm, torque_nm) -> Excitation`.

A SourceModel is van Roosmalen's lumped source model (housingfe.source.roosmalen.dynamics: 14 DOFs on rigid bores, the
time-varying mesh stiffness S(t) of housingfe.source.stiffness and the engagement shock F_e(t), steady state by
harmonic balance), built from a gear pair with its corrections and the lumped reduction of a drivetrain
(housingfe.drivetrain.description.Drivetrain.to_lumped, or a gearset-* scene).  It computes exactly what
`housingfe source gearset-*` computes (housingfe.source.roosmalen.run.run_scene), per operating point, and hands the
housing side what it needs: per harmonic n of the tooth frequency the complex dynamic mesh force and transmission
error, the bearing forces and moments (housingfe.source.roosmalen.dynamics.BearingSpectra) and L_omega of the wheel.

Amplitude convention (as everywhere in housingfe.source): one-sided complex amplitudes A_n of n f_tooth,
x(t) = x_mean + Re(sum_n A_n exp(i 2 pi n f_tooth t)).
"""
from __future__ import annotations

import copy
import math
import numbers
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from housingfe.errors import InputError
from housingfe.levels import OMEGA0, level
from housingfe.source.gears import GearPair
from housingfe.source.misalignment import check_model as check_misalignment
from housingfe.source.misalignment import lumped_misalignment
from housingfe.source.roosmalen import dynamics as dyn
from housingfe.source.stiffness import Corrections, MeshModel, ShaftBending

# the run-up range of the thesis' measurements (Sec. 5.3) and of the gearset-* scenes
SPEED_RANGE_RPM = (50.0, 1500.0)


@dataclass
class Excitation:
    """The source at one operating point (SI units; one-sided complex amplitudes per harmonic n = 1..H of the
    tooth frequency, see the module docstring).

    harmonic (H,); frequency_hz (H,); mesh_force (H,) [N]: dynamic normal mesh force S(t) d(t) + F_e(t);
    transmission_error (H,) [m]: the mesh compression d = h^T q along the flank normal (the dynamic transmission
    error); mean_mesh_force [N] and mean_compression [m]: their mean values; bearings: BearingSpectra (loads
    (4, 6, H) [N, N m] the shafts exert on the housing at the bearings, names, z); L_omega (H,) [dB re
    omega0 = 5e-8 rad/s]: narrow-band level of the wheel's angular velocity per line; L_omega_tooth_band [dB]: in
    the 1/3 octave that contains the tooth frequency (what `housingfe source` reports)."""

    speed_rpm: float
    torque_nm: float
    tooth_frequency_hz: float
    harmonic: np.ndarray
    frequency_hz: np.ndarray
    mesh_force: np.ndarray
    transmission_error: np.ndarray
    mean_mesh_force: float
    mean_compression: float
    bearings: dyn.BearingSpectra
    L_omega: np.ndarray
    L_omega_tooth_band: float
    state: dyn.SteadyState

    @property
    def bearing_forces(self) -> np.ndarray:
        """(n_bearings, 3, H) complex forces Fx, Fy, Fz [N] on the housing at the bearings."""
        return self.bearings.loads[:, :3]

    @property
    def bearing_moments(self) -> np.ndarray:
        """(n_bearings, 3, H) complex moments Mx, My, Mz [N m] on the housing at the bearings (zero: the lumped
        model's tilt reactions are split over the two bearings of a shaft as force couples)."""
        return self.bearings.loads[:, 3:]


class SourceModel:
    """Lumped source model of one gear set (see the module docstring).

    pair, corrections: the gears; interior, geometry: the lumped reduction (LumpedInterior, ShaftGeometry);
    mesh_model: the MeshModel of the mesh stiffness (default: from pair, corrections and geometry with n_slices,
    torque_configuration); stiffness_positions: mesh positions per base pitch; harmonics: H of the harmonic
    balance; speed_range_rpm: the supported pinion speeds (rev/min).  misalignment: the mesh misalignment under
    load (housingfe.source.misalignment) in the stiffness curve and the face-width load share: "none" (aligned
    gears), "lumped" (the static tilt of this model's own 14-DOF interior) or a function torque [N m] ->
    MeshModel.lead_gap [m/m] (e.g. housingfe.drivetrain.misalignment.lead_gap_law).  transmission_error: a TE the
    user brings (housingfe.source.transmission_error.TransmissionError, e.g. `transmission_error.read("te.csv")`)
    instead of the engagement model, at every torque within its torques; None (default) = the engagement model."""

    def __init__(self, pair: GearPair, corrections: Corrections, interior: dyn.LumpedInterior,
                 geometry: dyn.ShaftGeometry, *, mesh_model: MeshModel | None = None, n_slices: int = 24,
                 torque_configuration: int = 2, stiffness_positions: int = dyn.DEFAULT_STIFFNESS_POSITIONS, harmonics: int = 30,
                 speed_range_rpm: tuple[float, float] = SPEED_RANGE_RPM, engagement: str = dyn.DEFAULT_ENGAGEMENT,
                 misalignment="none", transmission_error=None):
        self.pair, self.corrections, self.interior, self.geometry = pair, corrections, interior, geometry
        # a TE the user brings (housingfe.source.transmission_error.TransmissionError) replaces the engagement model
        self.transmission_error = transmission_error
        self.mesh_model = mesh_model or MeshModel(
            pair, shafts=(ShaftBending(*geometry.pinion_spans, geometry.pinion_shaft_diameter),
                          ShaftBending(*geometry.wheel_spans, geometry.wheel_shaft_diameter)),
            corrections=corrections, n_slices=n_slices, torque_configuration=torque_configuration)
        self.stiffness_positions = int(stiffness_positions)
        self.harmonics = int(harmonics)
        self.speed_range_rpm = (float(speed_range_rpm[0]), float(speed_range_rpm[1]))
        if engagement not in dyn.ENGAGEMENT_MODELS:
            raise InputError(f"engagement: {engagement!r} is not one of {', '.join(dyn.ENGAGEMENT_MODELS)}")
        self.engagement = engagement
        if not callable(misalignment):
            check_misalignment(misalignment)
        self.misalignment = misalignment
        self._points: dict[float, object] = {}

    @classmethod
    def from_scene(cls, scene: str | Path) -> "SourceModel":
        """The model of a roosmalen source scene (built-in name such as "gearset-A", or a TOML path), with the
        scene's harmonics, stiffness positions and speed range."""
        from housingfe.scenefile import read_scene_dict
        from housingfe.source.roosmalen import run as roosmalen

        data, path = read_scene_dict(str(scene))
        table = roosmalen.parse(data, str(path))
        pair, corr, geometry, interior, model = roosmalen.build(table, str(path))
        te = None
        if table.transmission_error:
            from housingfe.source.transmission_error import read

            te = read(table.transmission_error)
        return cls(pair, corr, interior, geometry, mesh_model=model, stiffness_positions=table.stiffness_positions,
                   harmonics=table.harmonics, speed_range_rpm=(table.speed_min_rpm, table.speed_max_rpm),
                   engagement=table.engagement, transmission_error=te)

    def _point(self, torque: float):
        """Stiffness curve, matrices, shock and preload at a torque (cached: they do not depend on speed)."""
        from housingfe.source.roosmalen.run import OperatingPoint

        if torque not in self._points:
            self._points[torque] = OperatingPoint(self.pair, self.corrections, self.interior, self.mesh_model,
                                                  torque, self.stiffness_positions, engagement=self.engagement,
                                                  lead_gap=self.lead_gap(torque),
                                                  transmission_error=self.transmission_error)
        return self._points[torque]

    def prepared(self, torques_nm) -> dict:
        """{torque [N m]: operating point} (stiffness curve, load share, matrices, shock: what every speed at a
        torque reuses) at these pinion torques, computed now; `adopt` takes them into another copy of this model (a
        run-up computes them in a forked process while its FE model is built)."""
        return {float(t): self._point(float(t)) for t in torques_nm}

    def adopt(self, points: dict) -> None:
        """Take operating points of `prepared` (of a model with the same gears, interior, engagement and
        misalignment) as this model's own."""
        self._points.update(points)

    def lead_gap(self, torque_nm: float) -> float:
        """MeshModel.lead_gap [m/m] of the misalignment at a pinion torque [N m] (0 for "none")."""
        if callable(self.misalignment):
            return float(self.misalignment(float(torque_nm)))
        if self.misalignment == "none":
            return 0.0
        return self.misalignment_at(torque_nm).lead_gap

    def misalignment_at(self, torque_nm: float):
        """The "lumped" Misalignment (housingfe.source.misalignment) of this model at a pinion torque [N m]."""
        from housingfe.source.stiffness import normal_force_from_torque, stiffness_curve

        curve = stiffness_curve(self.mesh_model, normal_force_from_torque(self.pair, float(torque_nm)),
                                self.stiffness_positions)
        mats = dyn.assemble(self.pair, self.interior, curve.mean)
        return lumped_misalignment(self.pair, mats, dyn.preload_force(mats, float(torque_nm)), float(torque_nm),
                                   self.mesh_model.total_width)

    def operating_point(self, speed_rpm: float, torque_nm: float) -> Excitation:
        """The excitation at a pinion speed (rev/min, within speed_range_rpm) and pinion torque (N m, > 0)."""
        lo, hi = self.speed_range_rpm
        if not (isinstance(speed_rpm, numbers.Real) and math.isfinite(speed_rpm)) or speed_rpm <= 0:
            raise InputError(f"operating_point: speed_rpm: {speed_rpm!r} must be a finite number > 0 rev/min")
        if not lo <= speed_rpm <= hi:
            raise InputError(f"operating_point: speed_rpm: {speed_rpm:g} rev/min is outside the supported range "
                             f"{lo:g}..{hi:g} rev/min")
        if not (isinstance(torque_nm, numbers.Real) and math.isfinite(torque_nm)) or torque_nm <= 0:
            raise InputError(f"operating_point: torque_nm: {torque_nm!r} must be a finite number > 0 N m (the "
                             "mesh stiffness is computed at the loaded tooth deflection; an unloaded mesh is not "
                             "supported)")
        problem = self.pair.torque_problem(float(torque_nm))
        if problem is not None:
            raise InputError(f"operating_point: torque_nm: {problem}")
        op = self._point(float(torque_nm))
        st = op.steady_state(self.pair, float(speed_rpm), self.harmonics)
        h = op.mats.h
        d = st.Q @ h                                    # two-sided harmonics of the mesh compression
        f, te = st.one_sided(d)
        _, force = st.one_sided(st.mesh_force)
        _, ms = st.wheel_velocity_mean_square()
        H = self.harmonics
        bearings = dyn.bearing_spectra(st, op.mats, self.interior, self.geometry, self.pair, float(speed_rpm),
                                       float(torque_nm))
        return Excitation(speed_rpm=float(speed_rpm), torque_nm=float(torque_nm),
                          tooth_frequency_hz=st.tooth_frequency, harmonic=st.harmonics[st.harmonics >= 1], frequency_hz=f,
                          mesh_force=force, transmission_error=te, mean_mesh_force=float(np.real(st.mesh_force[H])),
                          mean_compression=float(np.real(d[H])), bearings=bearings, L_omega=level(ms, OMEGA0),
                          L_omega_tooth_band=dyn.tooth_band_level(st), state=st)

    def with_engagement(self, engagement: str) -> "SourceModel":
        """The same source with another engagement shock model (housingfe.source.roosmalen.dynamics.ENGAGEMENT_MODELS,
        e.g. "envelope-bound"); the operating points computed so far keep their stiffness curve, load share and
        matrices and only recompute F_e (OperatingPoint.with_engagement), so a re-run costs the harmonic balances."""
        if engagement not in dyn.ENGAGEMENT_MODELS:
            raise InputError(f"engagement: {engagement!r} is not one of {', '.join(dyn.ENGAGEMENT_MODELS)}")
        other = copy.copy(self)
        other.engagement = engagement
        other.transmission_error = None
        other._points = {t: op.with_engagement(self.pair, self.corrections, engagement) for t, op in self._points.items()}
        return other

    def with_transmission_error(self, transmission_error) -> "SourceModel":
        """The same source driven by a TE the user brings (housingfe.source.transmission_error.TransmissionError)
        instead of its engagement model; the operating points computed so far at torques the TE covers keep their
        stiffness curves and matrices and only recompute F_e (OperatingPoint.with_transmission_error); the others
        are dropped (asking for them is then the TE's InputError, as for a torque never computed)."""
        other = copy.copy(self)
        other.transmission_error = transmission_error
        other._points = {t: op.with_transmission_error(transmission_error) for t, op in self._points.items()
                         if transmission_error.torque_problem(t) is None}
        return other

    def overlap_note(self, torque_nm: float) -> str | None:
        """The summary line of housingfe.source.roosmalen.overlap.cancellation_note at a pinion torque [N m]: the
        face-width engagement's excitation at the helix's cancellation (overlap ratio within 0.1 of a non-zero
        integer) and how far the envelope bound lies above it at n = 1; None otherwise."""
        from housingfe.source.roosmalen.overlap import cancellation_note

        return cancellation_note(self.pair, self.corrections, self._point(float(torque_nm)))

    def centre_of_pressure(self, torque_nm: float):
        """The centre of pressure of the mesh load over one mesh period at a pinion torque [N m]
        (housingfe.source.mesh_moments.CentreOfPressure: w_c, s_c [m] at the stiffness curve's positions, the load
        distributions of the operating point's stiffness curve reused; its harmonics share S(t)'s time origin)."""
        from housingfe.source.mesh_moments import CentreOfPressure

        return CentreOfPressure.of_curve(self._point(float(torque_nm)).curve)

    def friction_curve(self, torque_nm: float, mu: float):
        """The sliding-friction resultants over one mesh period at a pinion torque [N m] and mean friction
        coefficient mu [-] (housingfe.source.mesh_friction.FrictionCurve: from the load distributions of the
        operating point's stiffness curve; its harmonics share S(t)'s time origin)."""
        from housingfe.source.mesh_friction import FrictionCurve

        return FrictionCurve.of_curve(self._point(float(torque_nm)).curve, mu)

    def quasi_static_transmission_error(self, torque_nm: float, count: int) -> np.ndarray:
        """One-sided complex amplitudes [m] of harmonics 1..count of the quasi-static transmission error
        e = d_qs - mean d_qs, d_qs = (F - F_e) / S(t), at a pinion torque [N m]: what the source's excitation is
        (k_m e below the mesh mode), in the phase convention of housingfe.source.transmission_error (the file
        format it reads and writes)."""
        from housingfe.source.transmission_error import harmonics_of

        op = self._point(float(torque_nm))
        return harmonics_of(dyn.quasi_static_compression(op.S, op.shock, op.normal_force), count)

    def mesh_stiffness(self, torque_nm: float) -> tuple[np.ndarray, np.ndarray]:
        """(S samples over one mesh period [N/m], F_e samples [N]) at a torque, uniformly spaced (the inputs of
        the harmonic balance)."""
        op = self._point(float(torque_nm))
        return op.S, op.shock
