"""How much the predicted tooth-harmonic excitation owes to the helix's cancellation near an integer overlap ratio
(issue 28; docs/source.md "How fragile the cancellation at an integer overlap ratio is").

The face-width engagement (dynamics.engagement_force_face_width) spreads the engagement shock over the face: for a
uniform load and constant mesh stiffness harmonic n of the transverse shock is multiplied by |sinc(n eps_beta)|,
which vanishes at every integer eps_beta.  Gear set A (eps_beta = 1.026) sits next to that zero.  Van Roosmalen
(1994, Sec. 2.4) reports that Lachenmaier's noise measurements did not confirm the belief that an integer overlap
ratio minimises noise, only that the sound power falls as eps_beta grows.

The envelope bound replaces the sinc by its envelope: the quasi-static excitation k_m (d - mean d),
d = (F - F_e) / S(t), of the same slice model with every slice of a contact line in phase (zero helix stagger: the
transverse, spur-equivalent shock with the same load share and flank gaps), harmonic n multiplied by
min(1, 1 / (pi n eps_beta)).  It is a bound and a sensitivity (what the helix would leave if it reduced each
harmonic only by the envelope of its sinc), not a model adopted.  The engagement option "envelope-bound"
(dynamics.engagement_force_envelope_bound: the shock whose quasi-static excitation is this bound at every harmonic)
carries it through the chain, e.g. `housingfe run test-gearbox-runup --set runup.engagement=envelope-bound`; the
run-up summary prints its maxima beside the default's when the note below triggers.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from housingfe.source.gears import GearPair
from housingfe.source.roosmalen import dynamics as dyn
from housingfe.source.roosmalen.dynamics import envelope_factor  # noqa: F401  (min(1, 1/(pi n eps_beta)), re-exported)
from housingfe.source.stiffness import Corrections

NEAR_INTEGER = 0.1        # |eps_beta - round(eps_beta)| at or under this, round(eps_beta) >= 1: "near an integer"


def harmonic_amplitudes(samples: np.ndarray, harmonics: int) -> np.ndarray:
    """One-sided amplitudes of harmonics n = 1..harmonics of uniformly spaced samples over one period."""
    x = np.asarray(samples, dtype=float)
    return 2.0 * np.abs(np.fft.rfft(x)[1:harmonics + 1]) / x.size


def quasi_static_excitation(S: np.ndarray, shock: np.ndarray, normal_force: float,
                            mean_stiffness: float | None = None) -> np.ndarray:
    """k_m (d - mean d) [N], d = (F - F_e) / S(t) the quasi-static mesh compression (as
    housingfe.source.roosmalen.studies.excitation_spectrum); k_m = mean_stiffness [N/m], default mean(S)."""
    S = np.asarray(S, dtype=float)
    k_m = float(np.mean(S)) if mean_stiffness is None else float(mean_stiffness)
    d = (normal_force - np.asarray(shock, dtype=float)) / S
    return k_m * (d - d.mean())


def in_phase_shock(pair: GearPair, corrections: Corrections, S: np.ndarray, normal_force: float,
                   load_share: np.ndarray | None = None, origin: float = 0.0) -> np.ndarray:
    """F_e [N] of the face-width slice model with zero helix stagger (every slice of a contact line at the same roll
    position; same load share and flank gaps): the spur-equivalent shock the envelope bound starts from."""
    return dyn.engagement_force_face_width(pair, corrections, S, normal_force, load_share=load_share, origin=origin,
                                           helix_stagger=False)


@dataclass
class EnvelopeBound:
    """Per harmonic n = 1..H: quasi-static excitation amplitudes [N] of the face-width model (`face_width`), of the
    in-phase slice model (`in_phase`) and the bound `in_phase * envelope`; `sinc` = |sinc(n eps_beta)|,
    `envelope` = min(1, 1 / (pi n eps_beta)); mean_stiffness k_m [N/m] (TE = excitation / k_m)."""

    eps_beta: float
    harmonic: np.ndarray
    face_width: np.ndarray
    in_phase: np.ndarray
    envelope: np.ndarray
    sinc: np.ndarray
    mean_stiffness: float

    @property
    def bound(self) -> np.ndarray:
        return self.in_phase * self.envelope

    @property
    def above_dB(self) -> np.ndarray:
        """20 lg(bound / face-width excitation) per harmonic [dB]."""
        return 20.0 * np.log10(self.bound / self.face_width)


def envelope_bound(pair: GearPair, corrections: Corrections, S: np.ndarray, normal_force: float, shock: np.ndarray,
                   load_share: np.ndarray | None = None, mean_stiffness: float | None = None,
                   harmonics: int = 3) -> EnvelopeBound:
    """The envelope bound (module docstring) beside the face-width model's excitation; `shock` = the face-width
    F_e [N] on the same samples as S [N/m]; normal_force F [N]; load_share as for engagement_force_face_width."""
    n = np.arange(1, harmonics + 1)
    eps_b = pair.overlap_ratio
    fw = harmonic_amplitudes(quasi_static_excitation(S, shock, normal_force, mean_stiffness), harmonics)
    flat = in_phase_shock(pair, corrections, S, normal_force, load_share)
    ip = harmonic_amplitudes(quasi_static_excitation(S, flat, normal_force, mean_stiffness), harmonics)
    k_m = float(np.mean(S)) if mean_stiffness is None else float(mean_stiffness)
    return EnvelopeBound(eps_beta=eps_b, harmonic=n, face_width=fw, in_phase=ip, envelope=envelope_factor(n, eps_b),
                         sinc=np.abs(np.sinc(n * eps_b)), mean_stiffness=k_m)


def near_integer(eps_beta: float, tolerance: float = NEAR_INTEGER) -> bool:
    """eps_beta within `tolerance` of a non-zero integer."""
    k = round(eps_beta)
    return k >= 1 and abs(eps_beta - k) <= tolerance


def cancellation_note(pair: GearPair, corrections: Corrections, point) -> str | None:
    """One summary line when the face-width engagement meets an overlap ratio near a non-zero integer (else None).
    point: a housingfe.source.roosmalen.run.OperatingPoint (engagement, S, shock, normal_force, load_share, curve,
    torque)."""
    eps_b = pair.overlap_ratio
    if point.engagement != "face-width" or not near_integer(eps_b):
        return None
    if getattr(point, "transmission_error", None) is not None:     # a TE from a file, not the face-width model
        return None
    b = envelope_bound(pair, corrections, point.S, point.normal_force, point.shock, point.load_share,
                       point.curve.mean, harmonics=1)
    return (f"NOTE: overlap ratio {eps_b:.3f} is near an integer: the face-width engagement's tooth-harmonic "
            f"excitation sits at the helix's cancellation (|sinc(eps_beta)| = {b.sinc[0]:.3f}); measurements "
            f"(Lachenmaier, cited by van Roosmalen 1994 Sec. 2.4) did not find the noise minimum at integer "
            f"eps_beta; the envelope bound min(1, 1/(pi n eps_beta)) lies {b.above_dB[0]:+.1f} dB above at n = 1, "
            f"{point.torque:g} N m (docs/source.md, 'How fragile the cancellation at an integer overlap ratio is')")
