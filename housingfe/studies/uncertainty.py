"""`housingfe uncertainty`: the spread of the run-up's answers over stated ranges of the inputs that are estimates
(issue 28, item 5).

A seeded Latin hypercube (scipy.stats.qmc.LatinHypercube) over the parameters of `PARAMETERS` — the bearings'
estimated internals, the assumed quill shafts and couplings of Appendix C's drive line, Appendix C's lumped source
parameters, the modal damping, the radiation model and the helices' slope deviation within DIN 3962 quality 5 —
each sample a re-analysis of the default chain (`housingfe run test-gearbox-runup`: the coupled source, the
misalignment under load, both routes):

* set A, ball bearings, at the scene's highest torque: max L_WA and its speed, the L_WA peak speeds nearest the
  measured resonance windows, the L_WA slope 250-1500 rev/min;
* with `families=("bearings",)` also gear set B with ball, angular contact, self-aligning and tapered roller
  bearings: each configuration's mean L_WA difference to ball over 800-1500 rev/min, its maximum, which one is
  quietest and whether the measured ranking holds (Sec. 5.8);
* "profile-corrections": gear sets B, C, D and uncorrected, and all five sets with the thesis replica's engagement
  thesis-2d; "double-helical": the double helical gearbox's scene (its own basis) with roller and fluid-film
  bearings at 500-2000 N m;
* and in every sample the issue-28 check rows of its runs ("checks"), made by the functions that make
  `housingfe validate`'s rows (default_chain_checks, study_checks): bands.json gives each check's 5-95 % band and
  in how many samples it passed (UncertaintyResult.check_bands).

No parameter changes the layout (the FE interior without its bearing matrices and mean mesh stiffness): the
bearings' internals change their 6x6 matrices, the drive line and Appendix C's parameters only the lumped source,
the damping the reduced system, the radiation model which of the computed curves is read, the helix deviation the
source's lead gap.  So each process computes ONE modal basis per layout (the scene's set A / ball model, ~30 s;
with the double-helical family that gearbox's too) and every configuration of every sample is a Rayleigh-Ritz
re-analysis on it (housingfe.runup.chain.with_drivetrain).

The wheel's locating side where the thesis does not state it (`SIDES`: the ball reference and the self-aligning
configuration, Sec. 5.8; housingfe.bearings.configurations.Configuration.wheel_side_uncertain) is a discrete input:
front or back, 1/2 each, per sample and configuration (`wheel_locating_<configuration>`), each drawn from a stream
of its own so that every other input of a seed stays as without it.  It moves no DOF either: a sample's other side
is a re-analysis on the same basis (as `housingfe study bearings --set drivetrain.wheel_locating=back`).  A scene
with an explicit drivetrain.wheel_locating ("front" / "back") fixes it.

Two inputs are opt-in (only with --range; `OPT_IN`, each drawn from a stream of its own so that every seed's other
inputs stay as without it).  `floating_axial_ratio`: the floating bearings' mean axial load as a fraction of their
radial load (drivetrain.floating_axial_ratio; a re-analysis on the sample's basis, like the wheel's side; not applied
to the double helical family's cylindrical roller and fluid-film bearings, which carry none); with a ratio != 0 each
sample says per configuration what its floating bearings held and which rings slid (`floating_cells`, samples.csv
columns; the summary counts the samples in which each configuration's rings slid: `floating_slid_line`).  The one
exception to the one basis per layout is the other, `mount_stiffness_N_per_m`, which stands the housing on an elastic
frame.  The fixed feet's Ritz vectors hold no rigid-body motion, so a sample with a mount builds a housing model and bases of its
own on the elastic feet (`mount_overrides`), every family of the sample runs on them, and a process drops them when
the next sample brings another mount (`_mount_pool`).

Samples are spread over processes by mpi4py.futures (MPIPoolExecutor, workers spawned; engine "processes":
concurrent.futures.ProcessPoolExecutor with spawned processes where MPI spawn is unavailable).  A worker that dies
stops the run with one line (`_pool`, `_results`: the pool's workers on this host are watched).  A sample's answer
does not depend on the process that computed it (each builds the same basis): 1 and 2 workers give the same
numbers (tests/studies/test_uncertainty.py).

Python API (the quantity names are those of `UncertaintyResult.quantities`, docs/uncertainty.md):

    result = run_uncertainty("test-gearbox-runup", n_samples=8, seed=1, workers=1)
    p5, p50, p95 = result.band("max_lwa_dBA")                 # default route (mesh_force if computed)
    result.band("tf_omega/slope_dBA_per_doubling")
    result.fraction("measured_ranking_holds")                 # share of samples (bearings family)
"""
from __future__ import annotations

import argparse
import contextlib
import functools
import json
import math
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from housingfe.errors import InputError
from housingfe.studies.chain_session import MEAN_RANGE_RPM, difference_stats

DEFAULT_SCENE = "test-gearbox-runup"
BEARING_FAMILY = ("ball", "angular_contact", "self_aligning", "tapered_roller")   # gear set B, Sec. 5.8
# the design-variant families a sample can add (housingfe.studies.design_variants); the default stays bearings
FAMILIES = ("bearings", "profile-corrections", "double-helical")
DEFAULT_FAMILIES = ("bearings",)
REPLICA_ENGAGEMENT = "thesis-2d"         # the thesis replica's engagement shock (the replica checks of issue 28)
# the quasi-static excitation checks (28.excitation.envelope.<set>) are computed on the aligned gear pairs alone:
# none of PARAMETERS acts on them (the helix deviations act on the run's lead gap, the rest on the dynamics)
EXCITATION_NOTE = ("no sampled input acts on this (the quasi-static excitation of the aligned gear pair; the helix "
                   "deviations act on the run-up's lead gap, every other input on the dynamics or the radiation)")
ENGINES = ("mpi", "processes")
# the measured L_WA / L_v resonance windows of set A (housingfe.runup.checks.MEASURED_PEAKS_RPM)
PEAK_WINDOWS_RPM = ((450.0, 450.0), (850.0, 950.0), (1300.0, 1350.0))


# ------------------------------------------------------------------------------------------------ parameters
@dataclass(frozen=True)
class Parameter:
    """An estimated input: its range [low, high] (distribution "uniform" or "loguniform"; "choice": one of the
    scene's radiation models, equally likely; "side": a bearing side, front or back, equally likely), the value the
    chain uses (`nominal`, None: the scene's), unit, what it acts on, and where the range comes from."""

    name: str
    distribution: str
    low: float
    high: float
    nominal: float | None
    unit: str
    acts_on: str
    source: str


def helix_slope_tolerance(diameter_m: float, face_width_m: float, quality: int = 5) -> float:
    """f_Hbeta (m): the helix slope deviation tolerance of ISO 1328-1:1995 (eq. for quality 5, 0.07 sqrt(d) +
    0.45 sqrt(b) + 3.0 um with d, b in mm, times 2^((Q - 5) / 2)), unrounded.  DIN 3962-2 (the thesis' standard,
    App. F: quality 5) tabulates f_Hbeta by face width in classes of the same size; the ISO formula stands in for
    the table, which is not at hand."""
    d, b = diameter_m * 1e3, face_width_m * 1e3
    return (0.07 * math.sqrt(d) + 0.45 * math.sqrt(b) + 3.0) * 2.0 ** ((quality - 5) / 2.0) * 1e-6


PARAMETERS: dict[str, Parameter] = {p.name: p for p in (
    Parameter("damping_ratio", "loguniform", 0.02, 0.08, None, "-", "modal damping of the coupled gearbox",
              "estimate, x/÷2 around the thesis' 0.04 (Sec. 5.4: 'an averaged result of measured modal damping "
              "factors of a few FRFs'); Sec. 4.5 measured 0.014 for one mode and strongly mode-dependent damping"),
    Parameter("radiation", "choice", 0.0, 1.0, None, "-", "radiation model (sigma) read for L_W",
              "the scene's radiation models, equally likely (test-gearbox-runup: sigma = 1 'erp', Föller's "
              "plate model); the thesis used sigma = 1 (Ch. 5)"),
    Parameter("clearance_position", "uniform", 0.0, 1.0, 0.5, "-",
              "FE bearings: radial clearance within ISO 5753-1 Group N",
              "catalogue rule: mid-range of Group N (housingfe/bearings/catalogue.py); the fitted bearings' class "
              "is not stated: the whole Group N range"),
    Parameter("groove_inner", "uniform", 0.51, 0.53, 0.52, "-", "FE ball bearings: inner groove curvature f_i",
              "estimate, ±0.01 around Harris' typical 0.52 (SKF does not publish it)"),
    Parameter("groove_outer", "uniform", 0.52, 0.54, 0.53, "-", "FE ball bearings: outer groove curvature f_o",
              "estimate, ±0.01 around Harris' typical 0.53"),
    Parameter("spherical_contact_angle_deg", "uniform", 7.0, 11.0, 9.0, "deg",
              "FE self-aligning (spherical roller) bearings: contact angle",
              "estimate, ±2 deg around 9 deg (from a typical SKF factor e = 0.24; 21316 CC / 22219 CC not checked)"),
    Parameter("tapered_e_scale", "uniform", 0.85, 1.15, 1.0, "-",
              "FE tapered roller bearings: factor on the calculation factor e (contact angle)",
              "estimate, ±15 %: e of 30316 J2 / 30219 J2 recalled, not checked against the catalogue"),
    Parameter("quill_diameter_scale", "uniform", 0.8, 1.25, 1.0, "-",
              "source: diameters of the four torsion shafts to motor and brake (App. C shafts 1-4)",
              "estimate, -20/+25 %: the diameters are assumed (docs/source.md; App. C's table is lost)"),
    Parameter("quill_length_scale", "loguniform", 0.5, 2.0, 1.0, "-",
              "source: lengths of the four torsion shafts",
              "estimate, x/÷2: 'long, torsionally weak shafts', lengths assumed (docs/source.md)"),
    Parameter("coupling_inertia_scale", "loguniform", 0.5, 2.0, 1.0, "-",
              "source: the two coupling inertias (App. C DOFs 13, 14)", "estimate, x/÷2: assumed 0.02 / 0.05 kg m^2"),
    Parameter("lumped_bearing_span_m", "uniform", 0.045, 0.075, 0.06, "m",
              "source: bearing to gear face (Fig. 2.6) in the lumped model and its shaft bending",
              "estimate, ±25 % around the assumed 60 mm (the FE seats are at 107.5 mm from the gear centre)"),
    Parameter("appendix_c_bearing_scale", "loguniform", 0.7, 1.4, 1.0, "-",
              "source: Appendix C's bearing diagonal of the lumped model",
              "estimate, x/÷1.4: printed for one load and used for every configuration and torque; the FE "
              "bearings' stiffness changes by about this much between configurations (docs/bearings.md)"),
    Parameter("source_loss_factor", "loguniform", 0.05, 0.2, 0.1, "-",
              "source: loss factor of the lumped model's modes",
              "estimate, x/÷2: Sec. 2.5 'varied quite a lot between the resonant frequencies'; 0.1 averaged"),
    Parameter("helix_deviation_pinion", "uniform", -1.0, 1.0, 0.0, "f_Hbeta",
              "source: the pinion's helix slope deviation, added to the lead gap",
              "DIN 3962 quality 5 (App. F): ±f_Hbeta (ISO 1328-1 formula, `helix_slope_tolerance`)"),
    Parameter("helix_deviation_wheel", "uniform", -1.0, 1.0, 0.0, "f_Hbeta",
              "source: the wheel's helix slope deviation, added to the lead gap",
              "DIN 3962 quality 5 (App. F): ±f_Hbeta"),
    Parameter("mount_stiffness_N_per_m", "loguniform", 1e8, 1e10, None, "N/m",
              "housing: total vertical stiffness K_v of an elastic frame under the feet (the housing's supports.0 "
              "made elastic, k_n = K_v / its area, k_t = k_n / 3); opt-in: drawn only with --range, else the "
              "scene's fixed feet (each sample then builds its own housing model and basis)",
              "estimate: the thesis says only 'the gearbox stands on a frame' (Ch. 5), stiffness not given; a "
              "steel frame under the 169 kg gearbox: 1e8 N/m puts its six mount modes at 48-146 Hz, 1e9 at "
              "130-382 Hz, from 3e9 they mix with the housing's (benchmarks/experiments/frame_mount)"),
    Parameter("floating_axial_ratio", "uniform", -0.2, 0.2, None, "-",
              "FE bearings and the source's misalignment: the floating bearings' mean axial load / their radial "
              "load (drivetrain.floating_axial_ratio, the locating bearings taking the reaction; > 0: the shaft "
              "pushes them away from the locating bearing); opt-in: drawn only with --range, else the scene's "
              "(0: no axial load); not applied to floating bearings that carry none (cylindrical roller, fluid film)",
              "estimate: a floating ring sticks in its bore (benchmarks/experiments/floating_axial) and keeps "
              "whatever the assembly and the shaft's thermal growth left, up to +-mu F_r; greased cast iron on steel "
              "mu = 0.13-0.21: +-0.2"),
)}


def _side_parameters() -> dict[str, Parameter]:
    """wheel_locating_<configuration> for every configuration whose wheel's locating side the thesis leaves open
    (housingfe.bearings.configurations.Configuration.wheel_side_uncertain: ball, self_aligning)."""
    from housingfe.bearings.configurations import configurations

    return {f"wheel_locating_{name}": Parameter(
        f"wheel_locating_{name}", "side", 0.0, 1.0, None, "-",
        f"FE bearings and the source's misalignment: which of the wheel's bearings locates it axially with the "
        f"{name} configuration (drivetrain.wheel_locating; the pinion is located at its front)",
        f"the thesis does not say ({c.wheel_locating_source.removeprefix('not stated: ')}): front or back, equally "
        "likely; the deterministic run takes front") for name, c in configurations().items() if c.wheel_side_uncertain}


# The wheel's locating side where the text leaves it open: drawn in every run (a scene with an explicit
# drivetrain.wheel_locating fixes it), each from a stream of its own (`_SIDE_STREAM`), outside the Latin hypercube
# of the other inputs, so that adding it changed none of their draws for any seed.
SIDES: dict[str, str] = {name: name.removeprefix("wheel_locating_") for name in _side_parameters()}
PARAMETERS.update(_side_parameters())
_SIDE_STREAM = 0x73696465                # "side": the seed sequence (seed, stream + k) of the k-th side input

# Inputs drawn only when --range names them: the nominal of the mount is a model choice (the fixed feet), not a
# value in the range, and each of its samples needs a housing model and basis of its own.  They are drawn from a
# stream of their own (`_OPT_IN_STREAM`), so every other column of a seed is the same with or without them.
# The floating bearings' axial load is opt-in because the deterministic chain takes 0 (the middle of the range the
# rig allows) and the runs before it drew nothing for it; a sample of it is a re-analysis on the sample's basis.
MOUNT = "mount_stiffness_N_per_m"
FLOATING_AXIAL = "floating_axial_ratio"
OPT_IN = (MOUNT, FLOATING_AXIAL)         # the order fixes each one's stream: append, never reorder
_OPT_IN_STREAM = 0x6D6F756E74            # "mount": the seed sequence (seed, stream + k) of the k-th opt-in input
MOUNT_TANGENTIAL_RATIO = 1.0 / 3.0       # k_t / k_n, as the built-in scene box-supported-elastic (assumed)


# What each input can physically be (lower, lower included, upper, upper included, what it is): a --range outside
# it is refused when read.  Before, a clearance position of 5 (5 Group N ranges) or a negative shaft diameter scale
# ran to a result, and an impossible contact angle or span failed a minute later in a bearing or interior model
# without naming --range.  The helix deviation is in units of f_Hbeta of DIN 3962 / ISO 1328 quality 5; quality 12,
# the coarsest class, allows 2^(7/2) = 11.3 times that.
HELIX_QUALITY_12 = 2.0 ** 3.5
PHYSICAL_LIMITS: dict[str, tuple] = {
    "damping_ratio": (0.0, False, 1.0, False, "a modal damping ratio (0 < zeta < 1)"),
    "clearance_position": (0.0, True, 1.0, True, "a position within the Group N clearance range (0 ... 1)"),
    "groove_inner": (0.5, False, math.inf, False, "a groove conformity (f > 0.5: the groove larger than the ball)"),
    "groove_outer": (0.5, False, math.inf, False, "a groove conformity (f > 0.5: the groove larger than the ball)"),
    "spherical_contact_angle_deg": (0.0, True, 90.0, False, "a contact angle in [0, 90) deg"),
    "tapered_e_scale": (0.0, False, math.inf, False, "a factor > 0"),
    "quill_diameter_scale": (0.0, False, math.inf, False, "a factor > 0"),
    "quill_length_scale": (0.0, False, math.inf, False, "a factor > 0"),
    "coupling_inertia_scale": (0.0, False, math.inf, False, "a factor > 0"),
    "lumped_bearing_span_m": (0.0, False, math.inf, False, "a length > 0 m"),
    "appendix_c_bearing_scale": (0.0, False, math.inf, False, "a factor > 0"),
    "source_loss_factor": (0.0, False, 1.0, False, "a loss factor (0 < eta < 1)"),
    "helix_deviation_pinion": (-HELIX_QUALITY_12, True, HELIX_QUALITY_12, True,
                               f"at most ±{HELIX_QUALITY_12:.3g} f_Hbeta (quality 12, the coarsest class)"),
    "helix_deviation_wheel": (-HELIX_QUALITY_12, True, HELIX_QUALITY_12, True,
                              f"at most ±{HELIX_QUALITY_12:.3g} f_Hbeta (quality 12, the coarsest class)"),
    "mount_stiffness_N_per_m": (0.0, False, math.inf, False, "a stiffness > 0 N/m"),
    # housingfe.drivetrain.description.FLOATING_AXIAL_LIMIT: above any friction coefficient of a greased ring in a bore
    "floating_axial_ratio": (-0.3, True, 0.3, True, "within +-0.3 (a floating ring held by its friction in the bore, "
                             "mu = 0.13-0.21 greased)"),
}


def _physical(name: str, value: float) -> bool:
    lo, lo_in, hi, hi_in, _ = PHYSICAL_LIMITS[name]
    return (value >= lo if lo_in else value > lo) and (value <= hi if hi_in else value < hi)


def parse_ranges(items) -> dict[str, tuple]:
    """--range NAME=LOW:HIGH or NAME=VALUE (zero width) -> {name: (low, high)}; radiation=MODEL[,MODEL...] ->
    {"radiation": (models...)}.  Unknown names, unparsable or reversed ranges -> InputError."""
    out = {}
    for item in items or ():
        name, sep, text = str(item).partition("=")
        name = name.strip()
        if not sep:
            raise InputError(f"--range {item}: give NAME=LOW:HIGH or NAME=VALUE")
        if name not in PARAMETERS:
            raise InputError(f"--range {name}: unknown parameter (known: {', '.join(PARAMETERS)})")
        if name in out:       # the later one replaced the earlier without a word
            raise InputError(f"--range {name}: given twice ({name}={text.strip()} after an earlier --range {name})")
        if name == "radiation":
            out[name] = tuple(m.strip() for m in text.split(",") if m.strip())
            continue
        if name in SIDES:
            from housingfe.drivetrain.description import LOCATING_SIDES

            sides = tuple(dict.fromkeys(m.strip() for m in text.split(",") if m.strip()))
            bad = [m for m in sides if m not in LOCATING_SIDES] or ([] if sides else ["nothing"])
            if bad:
                raise InputError(f"--range {name}: {', '.join(bad)}: not a bearing side (give front, back or "
                                 "front,back)")
            out[name] = sides
            continue
        try:
            parts = [float(x) for x in text.split(":")]
        except ValueError:
            raise InputError(f"--range {name}: {text!r} is not LOW:HIGH or a number") from None
        if len(parts) not in (1, 2) or not all(math.isfinite(x) for x in parts):
            raise InputError(f"--range {name}: {text!r} is not LOW:HIGH or a number")
        lo, hi = (parts[0], parts[0]) if len(parts) == 1 else parts
        if lo > hi:
            raise InputError(f"--range {name}: low {lo:g} above high {hi:g}")
        if PARAMETERS[name].distribution == "loguniform" and lo <= 0:
            raise InputError(f"--range {name}: {lo:g}: must be > 0 (log-uniform)")
        for value in (lo, hi):
            if not _physical(name, value):
                raise InputError(f"--range {name}: {value:g}: must be {PHYSICAL_LIMITS[name][4]}")
        out[name] = (lo, hi)
    return out


def nominal_ranges(scene) -> dict[str, tuple]:
    """Every range at the value the chain uses (zero width): the deterministic run as an uncertainty run."""
    out = {}
    for p in PARAMETERS.values():
        if p.name in OPT_IN:               # not drawn: the scene as it is (the fixed feet)
            continue
        if p.name == "radiation":
            out[p.name] = (scene.radiation.models[0],)
        elif p.name in SIDES:              # the scene's side for the configuration ("configuration": front)
            from housingfe.drivetrain.description import wheel_locating_side

            out[p.name] = (wheel_locating_side(SIDES[p.name], scene.drivetrain.wheel_locating),)
        elif p.name == "damping_ratio":
            out[p.name] = (scene.runup.damping_ratio,) * 2
        else:
            out[p.name] = (p.nominal, p.nominal)
    return out


def draw_samples(scene, n_samples: int, seed: int, ranges: dict | None = None) -> list[dict]:
    """n_samples Latin-hypercube samples {parameter: value} (scipy.stats.qmc.LatinHypercube, `seed`) over the
    PARAMETERS' ranges with `ranges` overriding some ({name: (low, high)}; radiation: (models...)).  An OPT_IN
    input (the mount stiffness) is None (the scene's fixed feet) unless `ranges` names it; then it is drawn from a
    one-dimensional Latin hypercube of its own seeded stream, so every other input's values are those of the seed
    without it.  A side input (`SIDES`) is front or back, each with probability 1/2 (a one-dimensional Latin
    hypercube of its own stream, u < 1/2: front; so n samples hold n/2 of each, rounded), among the sides `ranges`
    gives; a scene with an explicit drivetrain.wheel_locating fixes it to that side."""
    from scipy.stats import qmc

    ranges = dict(ranges or {})
    names = [n for n in PARAMETERS if n not in OPT_IN and n not in SIDES]
    u = qmc.LatinHypercube(d=len(names), seed=int(seed)).random(int(n_samples))
    models = list(scene.radiation.models)
    samples = [{} for _ in range(int(n_samples))]
    for j, name in enumerate(names):
        p = PARAMETERS[name]
        if name == "radiation":
            pick = list(ranges.get(name, models))
            bad = [m for m in pick if m not in models]
            if bad or not pick:
                raise InputError(f"--range radiation: {', '.join(bad) or 'nothing'}: not a radiation model of the "
                                 f"scene (its models: {', '.join(models)})")
            for i in range(len(samples)):
                samples[i][name] = pick[min(int(u[i, j] * len(pick)), len(pick) - 1)]
            continue
        lo, hi = ranges.get(name, (p.low, p.high))
        for i in range(len(samples)):
            samples[i][name] = _value(p, lo, hi, u[i, j])
    for k, name in enumerate(OPT_IN):
        if name not in ranges:
            for s in samples:
                s[name] = None
            continue
        lo, hi = ranges[name]
        stream = np.random.default_rng([int(seed), _OPT_IN_STREAM + k])
        w = qmc.LatinHypercube(d=1, seed=stream).random(int(n_samples))[:, 0]
        for i in range(len(samples)):
            samples[i][name] = _value(PARAMETERS[name], lo, hi, w[i])
    for k, name in enumerate(SIDES):
        pick = side_choices(scene, name, ranges)
        stream = np.random.default_rng([int(seed), _SIDE_STREAM + k])
        w = qmc.LatinHypercube(d=1, seed=stream).random(int(n_samples))[:, 0]
        for i in range(len(samples)):
            samples[i][name] = pick[min(int(w[i] * len(pick)), len(pick) - 1)]
    return samples


def side_choices(scene, name: str, ranges: dict | None = None) -> tuple:
    """The sides a side input (`SIDES`) is drawn from, equally likely: those `ranges` gives, else the scene's
    explicit drivetrain.wheel_locating ("front" / "back": fixed), else ("front", "back")."""
    explicit = scene.drivetrain.wheel_locating
    return tuple((ranges or {}).get(name, (explicit,) if explicit != "configuration" else ("front", "back")))


def _value(p: Parameter, lo: float, hi: float, u: float) -> float:
    """The value of a numeric parameter at the unit-interval point u of its range [lo, hi]."""
    if lo == hi:
        return float(lo)
    if p.distribution == "loguniform":
        return float(lo * (hi / lo) ** u)
    return float(lo + (hi - lo) * u)


# ------------------------------------------------------------------------------------------------ one sample
_STATE: dict = {}      # per process: (scene, overrides) -> _Base (the housing model and the basis)
_POOL: list = []       # per process: the one ModelPool its sessions share (the housing model where it is the same)


@dataclass
class _Base:
    session: object
    model: object          # GearboxModel of the scene's drivetrain at the highest torque (its bearings not following the speeds)
    surfaces: dict         # bearing -> housing bore (bore matching)
    setup_s: float


def _base(scene_name: str, overrides: tuple, comm, pool=None) -> _Base:
    """The process's base of a scene with --set `overrides` (built on first use): its ChainSession and the coupled
    model at the highest torque.  pool: the ModelPool its session shares (default the process's one, _POOL)."""
    key = json.dumps([scene_name, list(overrides)])
    if key not in _STATE:
        from housingfe.drivetrain.bore_matching import match_bores
        from housingfe.studies.chain_session import ChainSession, ModelPool

        if pool is None:
            if not _POOL:
                _POOL.append(ModelPool())
            pool = _POOL[0]
        t0 = time.perf_counter()
        session = ChainSession.from_scene(scene_name, list(overrides), comm=comm, pool=pool)
        spec = session.scene.drivetrain
        dt = session.drivetrain(spec.gear_set, spec.bearings, max(session.spec.torques_nm))
        housing = session.housing()
        ref = session.scene.housing
        try:
            surfaces = match_bores(housing, dt, ref.bores, ref.match, ref.bore_tolerance)
        except InputError as exc:
            raise InputError(f"{session.scene_path}: {exc}") from None
        # not followed: the samples only re-analyse it (`_runs`: with_drivetrain, then each follows the speeds on
        # its own drivetrain), so fluid films followed here would be Reynolds solves for nothing
        model = session.model(dt.with_bores(surfaces), "uncertainty base", follow=False)
        _STATE[key] = _Base(session, model, surfaces, time.perf_counter() - t0)
    return _STATE[key]


# per process: the one mount whose bases _STATE holds now ({"value": K_v N/m, "pool": its ModelPool, "keys": its
# _STATE keys}).  A sample of another mount drops them before building its own, so a process holds at most one
# mount's housing model and bases beside the fixed feet's (a zero-width mount range reuses them from sample to sample).
_MOUNT: dict = {}


@functools.lru_cache(maxsize=16)
def _support_of(scene_name: str, overrides: tuple) -> tuple:
    """(the run-up scene's housing.set, the housing's supports.0 surface) of a scene with --set `overrides`;
    InputError naming the housing scene when it has no support."""
    from housingfe.runup.scene import load_runup_scene
    from housingfe.scene import load_housing_scene

    scene, _ = load_runup_scene(scene_name, list(overrides))
    housing, hpath = load_housing_scene(scene.housing.scene, list(scene.housing.set))
    if not housing.supports:
        raise InputError(f"{hpath}: supports: none; --range {MOUNT} puts supports.0 on an elastic frame")
    return tuple(scene.housing.set), housing.supports[0].surface


def mount_overrides(scene_name: str, overrides: tuple, stiffness: float) -> tuple:
    """The run-up scene's --set `overrides` plus one `housing.set` that stands the housing on an elastic frame of
    total vertical stiffness `stiffness` (N/m): the housing's supports.0 (test-gearbox: foot_bottom, 0.0735 m^2)
    made elastic with total_normal_stiffness = stiffness and total_tangential_stiffness = stiffness / 3
    (MOUNT_TANGENTIAL_RATIO), which the model spreads over the surface's area on the mesh (so an imported housing
    stands on a frame too), appended to the scene's own housing.set so that e.g. a coarser mesh given there stays.
    The same springs as `housing_sets` of benchmarks/experiments/frame_mount/frame_mount.py (there per unit area,
    K_v / 0.0735 m^2).  InputError (one line) when the housing has no support."""
    own, _ = _support_of(scene_name, tuple(overrides))
    kv = float(stiffness)
    sets = list(own) + ["supports.0.kind=elastic", f"supports.0.total_normal_stiffness={kv!r}",
                        f"supports.0.total_tangential_stiffness={kv * MOUNT_TANGENTIAL_RATIO!r}"]
    return tuple(overrides) + (f"housing.set={json.dumps(sets)}",)


def check_mount(scene_name: str, overrides, ranges: dict | None, families: tuple) -> None:
    """InputError (one line) when --range names the mount but a scene of the run cannot stand on a frame."""
    if ranges and MOUNT in ranges:
        from housingfe.studies.design_variants import family_of

        scenes = [scene_name] + ([family_of("double-helical").scene] if "double-helical" in families else [])
        for name in scenes:
            mount_overrides(name, tuple(overrides), ranges[MOUNT][1])


def _mount_pool(stiffness: float, comm):
    """The ModelPool of the mount `stiffness` (N/m) in this process; the previous mount's bases are dropped first."""
    from housingfe.studies.chain_session import ModelPool

    if _MOUNT.get("value") != stiffness:
        if _MOUNT:
            import gc

            from housingfe.drivetrain import coupling

            # PETSc parks dropped objects per communicator (release_petsc_garbage) and the housing's matrices live
            # on its mesh's own (duplicated) communicator, which the next mount's coupling never cleans: without
            # this every mount left its housing model and bases behind (~200 MB per sample, coarse mesh); its
            # housing fields on yet another one, its function space's (release_fe_garbage: ~6-12 MB per basis).
            # Two scenes of a mount (--family all) share one housing model (ModelPool): each model is cleaned once,
            # through a probe that keeps its communicator alive (the K's own handle dangles once the cleanup has
            # freed the last object on it: cleaning through it twice segfaulted), in the same order on every rank
            # (the cleanups are collective; a set's order is not).
            probes, spaces, seen = [], [], set()
            for key in sorted(_MOUNT["keys"]):
                base = _STATE.pop(key, None)
                model = None if base is None else base.session.housing_model
                if model is not None and id(model) not in seen:
                    seen.add(id(model))
                    probes.append(coupling.hold_petsc_comm(model.K.getComm()))
                    spaces.append(model.V)
                del base, model
            _MOUNT.clear()
            gc.collect()
            for probe in probes:
                coupling.release_petsc_garbage(probe.getComm())
                probe.destroy()
            del probes
            coupling.release_petsc_garbage(comm)
            for V in spaces:
                coupling.release_fe_garbage(V)
            del spaces
            gc.collect()
        _MOUNT.update({"value": stiffness, "pool": ModelPool(), "keys": set()})
    return _MOUNT["pool"]


def _sample_base(scene_name: str, overrides: tuple, values: dict, comm) -> tuple:
    """(base, setup wall s, setup CPU s) of a scene for one sample: the shared base (fixed feet) or, with a mount
    value, the base of the housing on that mount (its own housing model and basis)."""
    mount = values.get(MOUNT)
    pool = None
    if mount is not None:
        pool = _mount_pool(mount, comm)
        overrides = mount_overrides(scene_name, tuple(overrides), mount)
    key = json.dumps([scene_name, list(overrides)])
    fresh = key not in _STATE
    c0 = time.process_time()
    base = _base(scene_name, tuple(overrides), comm, pool)
    if mount is not None:
        _MOUNT["keys"].add(key)
    return base, (base.setup_s if fresh else 0.0), (time.process_time() - c0 if fresh else 0.0)


@functools.lru_cache(maxsize=None)
def floating_bearings_carry_axial(bearings: str) -> bool:
    """Whether the floating bearings of a bearing configuration carry an axial load (drivetrain.floating_axial_ratio
    acts on them): not a fluid film's nor a cylindrical roller bearing's (the double helical family)."""
    from dataclasses import replace

    from housingfe.drivetrain.description import test_gearbox

    return not replace(test_gearbox("A", bearings), floating_axial_ratio=0.1).floating_axial_problem()


def perturbed_drivetrain(base: _Base, values: dict, gear_set: str, bearings: str, torque: float):
    """The test gearbox of the scene with gear set, bearings and torque, the sample's wheel locating side for those
    bearings (SIDES; else the scene's), the sample's floating bearings' axial load ratio where it was drawn and the
    floating bearings carry one (else the scene's), and the sample's drive line and Appendix C parameters (the FE
    bearings' internals act through housingfe.bearings.catalogue.estimated_internals while the matrices are
    computed).  Neither the side nor the ratio moves a DOF: a re-analysis on the sample's basis."""
    from dataclasses import replace

    from housingfe.runup.scene import drivetrain_of

    update = {"gear_set": gear_set, "bearings": bearings}
    ratio = values.get(FLOATING_AXIAL)
    if ratio is not None and floating_bearings_carry_axial(bearings):      # drawn (--range) and applicable
        update["floating_axial_ratio"] = float(ratio)
    side = values.get(f"wheel_locating_{bearings}")
    if side is not None:                # the sample's side where the thesis states none (SIDES)
        update["wheel_locating"] = side
    spec = base.session.scene.drivetrain.model_copy(update=update)
    dt = drivetrain_of(spec, float(torque), base.session.scene.runup.drive_line_model).with_bores(base.surfaces)
    changes = {}
    sd, sl = values["quill_diameter_scale"], values["quill_length_scale"]
    if (sd, sl) != (1.0, 1.0):
        changes["quill_shafts"] = tuple(replace(q, diameter=q.diameter * sd, length=q.length * sl)
                                        for q in dt.quill_shafts)
    if values["coupling_inertia_scale"] != 1.0:
        changes["couplings"] = tuple(replace(c, inertia=c.inertia * values["coupling_inertia_scale"])
                                     for c in dt.couplings)
    span = values["lumped_bearing_span_m"]
    if span != 0.06:
        changes["lumped_bearing_spans"] = {"pinion": (span, span), "wheel": (span, span)}
    if values["appendix_c_bearing_scale"] != 1.0:
        changes["lumped_bearing_stiffness"] = {k: tuple(x * values["appendix_c_bearing_scale"] for x in v)
                                               for k, v in dt.lumped_bearings().items()}
    if values["source_loss_factor"] != dt.loss_factor:
        changes["loss_factor"] = values["source_loss_factor"]
    return replace(dt, **changes) if changes else dt


def helix_lead_gap(drivetrain, values: dict) -> float:
    """The lead gap (m/m, MeshModel.lead_gap) of the sample's helix slope deviations: f_Hbeta of each gear
    (`helix_slope_tolerance` at its pitch diameter and face width) times the sample's fraction, measured in the
    transverse plane along the base tangent, so cos(beta_b) along the flank normal, per m of face width; the two
    gears' deviations add (the signs are symmetric in the ranges)."""
    pair = drivetrain.gears.pair
    d = pair.pitch_diameter
    b = pair.face_width
    cb = math.cos(pair.base_helix_angle)
    gap = 0.0
    for i, key in enumerate(("helix_deviation_pinion", "helix_deviation_wheel")):
        gap += values[key] * helix_slope_tolerance(float(d[i]), float(b[i])) / float(b[i])
    return cb * gap


def _misalignment(base: _Base, drivetrain, values: dict):
    """The source's misalignment: the scene's model (as `housingfe run`) plus the helix deviations' lead gap."""
    spec = base.session.spec
    model = spec.misalignment_model
    extra = helix_lead_gap(drivetrain, values)
    if model == "rigid-bores":
        from housingfe.drivetrain.misalignment import lead_gap_law

        law = lead_gap_law(drivetrain, "rigid-bores")
    elif model == "coupled":
        from housingfe.drivetrain.misalignment import coupled_misalignment

        gap = coupled_misalignment(base.session.housing(), drivetrain).lead_gap

        def law(torque: float) -> float:
            return gap
    elif model == "lumped":
        probe = drivetrain.source_model(misalignment="lumped", harmonics=spec.harmonics, engagement=spec.engagement)
        law = probe.lead_gap
    else:
        law = None
    if extra == 0.0:
        return "none" if law is None else law
    if law is None:
        return lambda torque: extra
    return lambda torque: law(torque) + extra


def _internals(values: dict) -> dict:
    """A sample's estimated bearing internals (housingfe.bearings.catalogue.estimated_internals' keywords)."""
    return {k: values[k] for k in ("clearance_position", "groove_inner", "groove_outer", "spherical_contact_angle_deg",
                                   "tapered_e_scale")}


def floating_label(gear_set: str, bearings: str, torque: float, top: float) -> str:
    """How a sample's result files name a configuration's floating bearings: "<gear set>_<bearings>", with
    "_<torque>Nm" at a torque other than the scene's highest `top` (N m)."""
    return f"{gear_set}_{bearings}" + ("" if float(torque) == float(top) else f"_{float(torque):g}Nm")


def floating_cells(base: _Base, values: dict, gear_set: str, bearings: str, torque: float, top: float) -> dict:
    """What one configuration's floating bearings hold in one sample, as samples.csv cells named
    "<floating_label>_<column>" (housingfe.studies.design_variants.floating_report_cells: requested and held axial
    load per shaft, N, and which rings slid): the statics of the sample's drivetrain (its ratio, wheel side) with its
    estimated internals in effect, which move where a directional locating bearing lifts off
    (Drivetrain.floating_axial_report).  {} where the floating bearings hold no axial load (ratio 0, or none carried)."""
    from housingfe.bearings.catalogue import estimated_internals
    from housingfe.studies.design_variants import floating_report_cells

    with estimated_internals(**_internals(values)):
        report = perturbed_drivetrain(base, values, gear_set, bearings, torque).floating_axial_report()
    if not report:
        return {}
    label = floating_label(gear_set, bearings, torque, top)
    return {f"{label}_{k}": v for k, v in floating_report_cells(report).items()}


# the samples.csv column (floating_cells) naming the shafts whose floating ring slid, after the configuration's label
SLID_SUFFIX = "_floating_rings_slid"


def _runs(base: _Base, values: dict, gear_set: str, bearings: str, torque: float | None = None,
          engagements: tuple = (None,)) -> tuple:
    """(coupled model, {engagement: RunupResult}) of one configuration in one sample: one Rayleigh-Ritz
    re-analysis on the process's basis, then per engagement shock (None: the scene's) the coupled source and the
    run-up at `torque` (N m; default the scene's highest)."""
    from dataclasses import replace

    from housingfe.bearings.catalogue import estimated_internals
    from housingfe.runup.chain import run_source, runup, with_drivetrain
    from housingfe.solvers import harmonic

    spec = base.session.spec
    torque = max(spec.torques_nm) if torque is None else float(torque)
    with estimated_internals(**_internals(values)):
        dt = perturbed_drivetrain(base, values, gear_set, bearings, torque)
        start = base.model
        if values["damping_ratio"] != spec.damping_ratio:
            damping = harmonic.Damping(lambda f: np.zeros(np.shape(f)), modal_ratio=values["damping_ratio"])
            start = replace(start, reduction=start.reduction.with_damping(damping))
        model = base.session.follow(with_drivetrain(start, dt))     # runup.bearing_speeds = "follow": per speed
        misalignment = _misalignment(base, dt, values)
        results = {}
        for engagement in engagements:
            source = dt.source_model(harmonics=spec.harmonics, engagement=engagement or spec.engagement,
                                     misalignment=misalignment)
            lines, _ = run_source(model, source, spec.speeds, [torque], spec.f_max_hz, spec.source_receptance,
                                  spec.mesh_moment_model, spec.mesh_friction)
            results[engagement] = runup(model, None, spec.speeds, [torque], routes=tuple(spec.routes), lines=lines)
    return model, results


def _series(base: _Base, res, torque: float | None = None) -> dict:
    """{(route, radiation): (speeds rev/min, L_WA dB(A))} of a run-up result."""
    spec = base.session.spec
    torque = max(spec.torques_nm) if torque is None else float(torque)
    return {(route, rad): res.series(route, rad, torque, "LwA_dB")
            for route in spec.routes for rad in base.session.scene.radiation.models}


def _curves(base: _Base, values: dict, gear_set: str, bearings: str) -> dict:
    """{(route, radiation): (speeds rev/min, L_WA dB(A))} of one configuration in one sample."""
    _, results = _runs(base, values, gear_set, bearings)
    return _series(base, results[None])


def _peak_metrics(speeds, lwa) -> dict:
    from housingfe.runup.checks import PEAK_TOLERANCE_RPM, peaks, speed_law_slope

    found = peaks(speeds, lwa)
    out = {"max_lwa_dBA": float(np.max(lwa)), "max_lwa_speed_rpm": float(speeds[int(np.argmax(lwa))]),
           "slope_dBA_per_doubling": float(speed_law_slope(speeds, lwa)),
           "lwa_peaks_rpm": " ".join(f"{s:g}" for s in found)}
    hits = 0
    for lo, hi in PEAK_WINDOWS_RPM:
        dist = [max(lo - s, s - hi, 0.0) for s in found]
        key = f"peak_speed_{lo:g}" + ("" if lo == hi else f"_{hi:g}") + "_rpm"
        out[key] = float(found[int(np.argmin(dist))]) if found else float("nan")
        hits += bool(dist) and min(dist) <= PEAK_TOLERANCE_RPM
    out["peaks_in_measured_windows"] = float(hits)
    return out


def measured_bearing_means() -> dict[str, float]:
    """Measured mean L_W differences to ball bearings over 800-1500 rev/min (Sec. 5.8, dB; ball 0)."""
    from housingfe.studies.design_variants import families

    return {v.key: (0.0 if v.key == "ball" else v.measured_mean) for v in families()["bearings"].variants}


def check_values(rows) -> dict:
    """{check_id: {"ours": number or text, "passed": "yes"/"no"/""}} of the issue-28 check rows among `rows`
    (housingfe.verification.checks): what a sample keeps of each check row."""
    from housingfe.verification.checks import is_check

    out = {}
    for r in rows:
        if is_check(r):
            ours = r["ours"]
            if isinstance(ours, (bool, np.bool_)):
                ours = str(ours)
            elif isinstance(ours, (int, float, np.integer, np.floating)):
                ours = float(ours)
            out[r["check_id"]] = {"ours": ours, "passed": r.get("passed", "")}
    return out


def _scene_read_with(scene, radiation: str):
    """The run-up scene with `radiation` as its first radiation model (the one its checks read)."""
    models = [radiation] + [m for m in scene.radiation.models if m != radiation]
    return scene.model_copy(update={"radiation": scene.radiation.model_copy(update={"models": models})})


def default_chain_checks(base: _Base, model, res, radiation: str) -> dict:
    """The checks of the default run-up on one sample's run of set A (check_values): the very functions that make
    `housingfe validate`'s rows from `housingfe run`'s result — housingfe.runup.checks.evaluate (max L_WA, speed
    law, L_omega on the flexible housing at 500/1000/1500 rpm and its resonance; tagged by
    validate.run_check_rows) and runup_checks_rows.chain_rows (the harmonic of the maximum, the peaks in the
    measured windows, no peak by n >= 3, the tooth-band shares of L_omega, L_v, L_W) — read for the sample's
    radiation model."""
    from housingfe.runup import checks as run_checks
    from housingfe.verification import runup_checks_rows, validate

    scene = _scene_read_with(base.session.scene, radiation)
    torque = max(base.session.spec.torques_nm)
    found, contributions = run_checks.evaluate(scene, {torque: (model, res)}, model)
    rows = validate.run_check_rows("sample", found)
    rows += runup_checks_rows.chain_rows("sample", radiation, res.totals, res.harmonic_rows(), contributions)
    return check_values(rows)


def study_data(family: str, engagement: str, radiation: str, routes: tuple, curves: dict) -> dict:
    """A design-variant family's comparison (study.json's content: rows, rankings, torque law) from one sample's
    curves {variant key: {route: (speeds rev/min, L_WA dB(A))}}, made by housingfe.studies.design_variants'
    own compare / rankings / torque_law."""
    from housingfe.studies.design_variants import (
        StudyResult,
        VariantRun,
        compare,
        family_of,
        rankings,
        torque_law,
    )

    fam = family_of(family)
    runs = {v.key: VariantRun(v, curves[v.key], "re-analysed", 0.0, 0.0) for v in fam.variants}
    result = StudyResult(fam, engagement, radiation, tuple(routes), runs)
    result.rows = compare(result)
    result.rankings = rankings(result)
    result.torque_law = torque_law(result)
    return {"family": fam.name, "engagement": engagement, "radiation": radiation, "reference": fam.reference,
            "source": fam.source, "rows": result.rows, "rankings": result.rankings, "torque_law": result.torque_law}


def study_checks(data: dict) -> dict:
    """The check rows of a study's data (check_values of housingfe.verification.study_rows.study_rows and, for the
    thesis replica's profile corrections, runup_checks_rows.replica_rows_of)."""
    from housingfe.verification import runup_checks_rows, study_rows

    rows = study_rows.study_rows(data)
    if data["family"] == "profile-corrections" and data["engagement"] == REPLICA_ENGAGEMENT:
        rows += runup_checks_rows.replica_rows_of(data)
    return check_values(rows)


class _SampleRuns:
    """One sample's configurations, each run once however many families need it: {(scene, gear set, bearings,
    torque, engagement): {route: (speeds, L_WA)}} for the sample's radiation model; the engagements of one
    configuration share its re-analysis."""

    def __init__(self, values: dict):
        self.values = values
        self.curves: dict = {}
        self.failed: dict = {}
        self.floating: dict = {}        # samples.csv cells of the configurations' floating bearings (floating_cells)

    def note_floating(self, base: _Base, gear_set: str, bearings: str, torque: float) -> None:
        """Keep what a configuration that ran holds in its floating bearings (floating_cells; nothing at ratio 0)."""
        self.floating.update(floating_cells(base, self.values, gear_set, bearings, torque,
                                            max(base.session.spec.torques_nm)))

    def get(self, base: _Base, gear_set: str, bearings: str, torque: float | None = None,
            engagements: tuple = (None,)) -> dict | None:
        """{engagement: {route: (speeds, L_WA)}}, None when the configuration cannot run (InputError, e.g. a
        bearing of the sample that cannot carry its load; the reason in `failed`)."""
        scene = base.session.scene.scene.name
        torque = max(base.session.spec.torques_nm) if torque is None else float(torque)
        key = (scene, gear_set, bearings, torque)
        if key in self.failed:
            return None
        missing = tuple(e for e in engagements if key + (e,) not in self.curves)
        if missing:
            try:
                _, results = _runs(base, self.values, gear_set, bearings, torque, missing)
            except InputError as exc:
                self.failed[key] = str(exc)
                return None
            self.note_floating(base, gear_set, bearings, torque)
            rad = self.values["radiation"]
            if rad not in base.session.scene.radiation.models:      # another scene's radiation models
                rad = base.session.scene.radiation.models[0]
            for e, res in results.items():
                self.curves[key + (e,)] = {route: res.series(route, rad, torque, "LwA_dB")
                                           for route in base.session.spec.routes}
        return {e: self.curves[key + (e,)] for e in engagements}


def _family_checks(family: str, base: _Base, runs: _SampleRuns, engagement: str | None = None) -> dict:
    """The check values of one design-variant family in one sample (every variant a configuration of `runs`);
    {} when a variant could not run."""
    from housingfe.studies.design_variants import family_of

    fam = family_of(family)
    curves = {}
    for v in fam.variants:
        got = runs.get(base, v.gear_set, v.bearings, v.torque, (engagement,))
        if got is None:
            return {}
        curves[v.key] = got[engagement]
    spec = base.session.spec
    return study_checks(study_data(family, engagement or spec.engagement, runs.values["radiation"],
                                   tuple(spec.routes), curves))


def evaluate_sample(scene_name: str, overrides: tuple, values: dict, families: tuple = DEFAULT_FAMILIES,
                    worker: bool = False) -> dict:
    """The metrics of one sample (see the module docstring), {"route/quantity": value}, "checks" (the issue-28
    check rows of this sample's runs, check_values: {check_id: {"ours", "passed"}}), "seconds" (its wall time,
    without the process's bases), "setup_s" and "setup_cpu_s" (the bases, wall and CPU, when this sample built
    them: with a mount value (`MOUNT`) every new mount's housing model and bases), "mount" (whether the sample
    stands on a frame) and "rss_mb" (the process's resident memory after the sample).  A sample with a mount value
    runs every configuration of every family on the housing on that frame (`mount_overrides`).  With
    drivetrain.floating_axial_ratio != 0 also each configuration's floating bearings' held loads (floating_cells).
    worker: the call runs in a pool process (its FE on MPI.COMM_SELF)."""
    from mpi4py import MPI

    comm = MPI.COMM_SELF if worker else MPI.COMM_WORLD
    base, setup, setup_cpu = _sample_base(scene_name, tuple(overrides), values, comm)
    t0, c0 = time.perf_counter(), time.process_time()
    scene = base.session.scene
    rad = values["radiation"]
    out = {}
    runs = _SampleRuns(values)
    engagements = (None, REPLICA_ENGAGEMENT) if "profile-corrections" in families else (None,)
    model_a, results_a = _runs(base, values, scene.drivetrain.gear_set, scene.drivetrain.bearings, None, engagements)
    torque = max(base.session.spec.torques_nm)
    runs.note_floating(base, scene.drivetrain.gear_set, scene.drivetrain.bearings, torque)
    for e, res in results_a.items():       # set A, ball, top torque: the default chain and the families' set A
        runs.curves[(scene.scene.name, scene.drivetrain.gear_set, scene.drivetrain.bearings, torque, e)] = {
            route: res.series(route, rad, torque, "LwA_dB") for route in base.session.spec.routes}
    checks = default_chain_checks(base, model_a, results_a[None], rad)
    del model_a, results_a
    out["seconds_set_a"] = time.perf_counter() - t0        # with set A's thesis-2d source (profile-corrections)
    for route in base.session.spec.routes:
        s, lwa = runs.curves[(scene.scene.name, scene.drivetrain.gear_set, scene.drivetrain.bearings, torque,
                              None)][route]
        for k, v in _peak_metrics(s, lwa).items():
            out[f"{route}/{k}"] = v
        out[f"{route}/lwa_curve_dBA"] = [float(x) for x in lwa]
    if "bearings" in families:
        measured = measured_bearing_means()
        order_measured = sorted(measured, key=measured.get)
        curves = {}
        for b in BEARING_FAMILY:
            got = runs.get(base, "B", b)
            if got is not None:
                curves[b] = got[None]
        failed = {k[2]: why for k, why in runs.failed.items() if k[1] == "B"}
        out["failed"] = "; ".join(f"{b}: {why}" for b, why in failed.items())
        nan = float("nan")
        for route in base.session.spec.routes:
            means = {}
            l_ref = curves["ball"][route][1] if "ball" in curves else None
            for b in BEARING_FAMILY:
                if b not in curves:
                    means[b] = nan
                    out[f"{route}/max_lwa_B_{b}_dBA"] = nan
                else:
                    s, lwa = curves[b][route]
                    means[b] = 0.0 if b == "ball" else (difference_stats(s, lwa, l_ref)[0] if l_ref is not None
                                                        else nan)
                    out[f"{route}/max_lwa_B_{b}_dBA"] = float(np.max(lwa))
                if b != "ball":
                    out[f"{route}/variant_mean_{b}_dB"] = means[b]
            if failed:
                out[f"{route}/quietest"] = "failed"
                out[f"{route}/measured_ranking_holds"] = nan
                out[f"{route}/self_aligning_quieter_than_ball"] = nan
                continue
            ours = sorted(means, key=means.get)
            out[f"{route}/quietest"] = ours[0]
            out[f"{route}/measured_ranking_holds"] = float(ours == order_measured)
            out[f"{route}/self_aligning_quieter_than_ball"] = float(means["self_aligning"] < 0.0)
        checks.update(_family_checks("bearings", base, runs))
    if "bearings" in families:
        out["seconds_bearings"] = time.perf_counter() - t0 - out["seconds_set_a"]
    if "profile-corrections" in families:
        t1 = time.perf_counter()
        checks.update(_family_checks("profile-corrections", base, runs))
        checks.update(_family_checks("profile-corrections", base, runs, REPLICA_ENGAGEMENT))
        out["seconds_profile-corrections"] = time.perf_counter() - t1
    if "double-helical" in families:
        from housingfe.studies.design_variants import family_of

        dh_scene = family_of("double-helical").scene
        t1, c1 = time.perf_counter(), time.process_time()
        dh, dh_setup, dh_cpu = _sample_base(dh_scene, tuple(overrides), values, comm)
        if dh_setup:                    # its basis is setup, not the sample's cost
            setup += dh_setup
            setup_cpu += dh_cpu
            t0 += time.perf_counter() - t1
            c0 += time.process_time() - c1
        t2 = time.perf_counter()
        checks.update(_family_checks("double-helical", dh, runs))
        out["seconds_double-helical"] = time.perf_counter() - t2
    if runs.failed and not out.get("failed"):
        out["failed"] = "; ".join(f"{k[1]}/{k[2]}@{k[3]:g}: {why}" for k, why in runs.failed.items())
    out.update(runs.floating)              # with drivetrain.floating_axial_ratio != 0 only (floating_cells)
    out["checks"] = checks
    out["seconds"] = time.perf_counter() - t0
    out["cpu_s"] = time.process_time() - c0          # the machine is shared: CPU time is the steadier measure
    out["setup_s"] = setup
    out["setup_cpu_s"] = setup_cpu
    out["mount"] = values.get(MOUNT) is not None
    out["rss_mb"] = _rss_mb()
    out["pid"] = os.getpid()
    return out


def _rss_mb() -> float:
    """Resident memory of this process (MB), from /proc (NaN where there is none)."""
    try:
        with open("/proc/self/statm") as fh:
            return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 1e6
    except (OSError, ValueError, IndexError):
        return float("nan")


def evaluate_batch(batch, worker: bool = True) -> list[dict]:
    """evaluate_sample for each (scene, overrides, values, families) of `batch`, in order (one pool task)."""
    return [evaluate_sample(*a, worker=worker) for a in batch]


# ------------------------------------------------------------------------------------------------ the run
# No cap on the samples per process: a cap of 30 re-analyses per process guarded against ~0.1 GB left behind per
# re-analysis; since housingfe.drivetrain.coupling.release_petsc_garbage the resident memory stays flat (1293.7 MB
# after each of 40 set-A samples in one process on the scene's mesh, docs/uncertainty.md).


@dataclass
class UncertaintyResult:
    """Samples (parameter values) and their metrics, in sample order; routes; the default route of `band`;
    speeds of the L_WA curves; families run; timings (s) and the engine used."""

    scene: str
    seed: int
    samples: list
    metrics: list
    routes: tuple
    speeds: np.ndarray
    families: tuple
    ranges: dict
    engine: str
    workers: int
    timings: dict = field(default_factory=dict)

    @classmethod
    def load(cls, folder) -> "UncertaintyResult":
        """The result of an earlier `housingfe uncertainty` run from its folder (uncertainty.json): the bands
        without re-running the samples."""
        path = Path(folder) / "uncertainty.json"
        if not path.is_file():
            raise InputError(f"{path}: no uncertainty result there (run `housingfe uncertainty --out {folder}`)")
        d = json.loads(path.read_text())
        metrics = [{k: (float("nan") if v is None and "/" in k and not k.endswith("quietest") else v)
                    for k, v in m.items()} for m in d["metrics"]]
        routes = tuple(dict.fromkeys(k.split("/", 1)[0] for k in metrics[0] if "/" in k))
        return cls(d["scene"], d["seed"], d["samples"], metrics, routes, np.asarray(d["speeds_rpm"], float),
                   tuple(d["families"]), {k: tuple(v) for k, v in d["ranges"].items()}, d["engine"], d["workers"],
                   d["timings_s"])

    @property
    def default_route(self) -> str:
        return "mesh_force" if "mesh_force" in self.routes else self.routes[0]

    def _key(self, quantity: str, route: str | None) -> str:
        if "/" in quantity:
            return quantity
        return f"{route or self.default_route}/{quantity}"

    def values(self, quantity: str, route: str | None = None) -> np.ndarray:
        """The per-sample values of a quantity ("name" on the default route, or "route/name")."""
        key = self._key(quantity, route)
        if not self.metrics or key not in self.metrics[0]:
            raise KeyError(f"{key}: not a quantity of this run (known: {', '.join(self.quantities)})")
        return np.array([m[key] for m in self.metrics], float)

    def band(self, quantity: str, route: str | None = None) -> tuple[float, float, float]:
        """(5th percentile, median, 95th percentile) of a quantity over the samples (NaN-aware: a peak speed is
        NaN in a sample without any L_WA peak)."""
        v = self.values(quantity, route)
        if np.all(np.isnan(v)):
            return (float("nan"),) * 3
        p5, p50, p95 = np.nanpercentile(v, [5.0, 50.0, 95.0])
        return float(p5), float(p50), float(p95)

    def check_ids(self) -> list[str]:
        """The check_ids of the issue-28 check rows the samples computed (metrics' "checks"), in first-seen order."""
        return list(dict.fromkeys(c for m in self.metrics for c in (m.get("checks") or {})))

    def check_passes(self, check_id: str) -> tuple[int, int]:
        """(k, n): the check passed in k of the n samples that computed and judged it (passed "yes" / "no")."""
        got = [(m.get("checks") or {}).get(check_id) for m in self.metrics]
        judged = [g["passed"] for g in got if g and g.get("passed") in ("yes", "no")]
        return sum(p == "yes" for p in judged), len(judged)

    def check_values(self, check_id: str) -> np.ndarray:
        """The per-sample numeric `ours` of a check (NaN where a sample did not compute it or it is not a number)."""
        out = []
        for m in self.metrics:
            g = (m.get("checks") or {}).get(check_id)
            v = g.get("ours") if g else None
            out.append(float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else float("nan"))
        return np.array(out, float)

    def check_bands(self) -> dict[str, dict]:
        """{check_id: {"band": [p5, p95] or None, "passes": k or None, "samples": n, "note": text}} for every
        issue-28 check row of `housingfe validate` this run computed per sample: the 5-95 % band of the check's
        own number (`ours`) where it is one, and in how many of the n samples that judged it the check passed; the
        excitation envelope checks with the note that no sampled input acts on them.  A run written before the
        samples carried their check rows (no "checks" in its metrics) gives the bands of its quantities under the
        check_ids of their rows (max L_WA, speed law, the bearing means).  The content of bands.json
        (housingfe.verification.checks.BANDS_FORMAT), read by `housingfe validate --bands`."""
        from housingfe.source.roosmalen.studies import SPECTRUM_SCENES

        n_all = len(self.metrics)
        out = {}
        for check_id in self.check_ids():
            v = self.check_values(check_id)
            v = v[np.isfinite(v)]
            band = [float(x) for x in np.percentile(v, [5.0, 95.0])] if v.size else None
            k, n = self.check_passes(check_id)
            have = sum(check_id in (m.get("checks") or {}) for m in self.metrics)
            note = "" if have == n_all else f"computed in {have} of {n_all} samples"
            out[check_id] = {"band": band, "passes": k if n else None, "samples": n, "note": note}
        if not out:
            for route in self.routes:
                pairs = [(f"28.default.max_lwa.{route}", "max_lwa_dBA"),
                         (f"28.speed_law.{route}", "slope_dBA_per_doubling")]
                pairs += [(f"28.variants.mean.bearings.{b}.{route}", f"variant_mean_{b}_dB")
                          for b in BEARING_FAMILY[1:]]
                for check_id, quantity in pairs:
                    try:
                        p5, _, p95 = self.band(quantity, route)
                    except KeyError:            # a quantity of a family this run did not include
                        continue
                    if np.isfinite(p5) and np.isfinite(p95):
                        out[check_id] = {"band": [p5, p95], "passes": None, "samples": n_all, "note": ""}
        for scene in SPECTRUM_SCENES:
            out[f"28.excitation.envelope.{scene.removeprefix('gearset-')}"] = {
                "band": None, "passes": None, "samples": n_all, "note": EXCITATION_NOTE}
        return out

    def inside(self, quantity: str, value: float, route: str | None = None) -> bool:
        """Whether `value` lies inside the 5-95 % band of `quantity`."""
        p5, _, p95 = self.band(quantity, route)
        return bool(p5 <= value <= p95)

    def fraction(self, quantity: str, route: str | None = None) -> float:
        """Share of the samples in which a yes/no quantity (1/0) holds."""
        v = self.values(quantity, route)
        return float(np.mean(v[np.isfinite(v)])) if np.any(np.isfinite(v)) else float("nan")

    def quietest_fractions(self, route: str | None = None) -> dict[str, float]:
        """{configuration: share of samples in which it is the quietest} (bearings family)."""
        key = self._key("quietest", route)
        got = [m[key] for m in self.metrics if m[key] != "failed"]
        return {b: (got.count(b) / len(got) if got else float("nan")) for b in BEARING_FAMILY}

    def driver(self, quantity: str, route: str | None = None) -> dict:
        """{"driver": the input whose Spearman rank correlation with the quantity is largest in size,
        "driver_rho": that correlation} over the samples (numeric inputs; "" with fewer than 5 finite samples or
        no spread).  With n samples, |rho| below about 2/sqrt(n) is noise."""
        from scipy.stats import spearmanr

        v = self.values(quantity, route)
        keep = np.isfinite(v)
        best = ("", float("nan"))
        if keep.sum() >= 5 and np.ptp(v[keep]) > 0:
            for name in PARAMETERS:
                x = np.array([s.get(name) for s in self.samples], dtype=object)[keep]
                if any(a is None for a in x):         # an opt-in input not drawn (or an older run's samples)
                    continue
                if name in SIDES:                     # rho > 0: the wheel located at the back raises it
                    x = np.array([a == "back" for a in x], float)
                elif name == "radiation":
                    x = np.array([str(a) == str(x[0]) for a in x], float)
                x = x.astype(float)
                if np.ptp(x) == 0:
                    continue
                rho = float(spearmanr(x, v[keep])[0])
                if np.isfinite(rho) and (not best[0] or abs(rho) > abs(best[1])):
                    best = (name, rho)
        return {"driver": best[0], "driver_rho": best[1]}

    @property
    def quantities(self) -> list[str]:
        """The numeric quantities "route/name" of the run (band / values)."""
        m = self.metrics[0] if self.metrics else {}
        return [k for k, v in m.items() if "/" in k and isinstance(v, float)]

    @property
    def cost_per_sample_s(self) -> float:
        """Mean wall time of a sample (s) in its process, without the process's one basis."""
        return float(np.mean([m["seconds"] for m in self.metrics]))

    def summary_rows(self) -> list[dict]:
        """One row per quantity and route: p5, median, p95, samples; fractions for the yes/no quantities."""
        rows = []
        for key in self.quantities:
            route, name = key.split("/", 1)
            v = self.values(key)
            yes_no = name in ("measured_ranking_holds", "self_aligning_quieter_than_ball")
            p5, p50, p95 = self.band(key)
            rows.append({"route": route, "quantity": name, "p5": p5, "median": p50, "p95": p95,
                         "fraction": self.fraction(key) if yes_no else None,
                         "samples": int(np.sum(np.isfinite(v))), **self.driver(key)})
        if "bearings" in self.families:
            for route in self.routes:
                for b, share in self.quietest_fractions(route).items():
                    rows.append({"route": route, "quantity": f"quietest_{b}", "p5": None, "median": None,
                                 "p95": None, "fraction": share, "samples": len(self.metrics), "driver": "",
                                 "driver_rho": None})
        return rows


# s an mpi4py.futures pool may take to start its workers (spawned Python processes importing mpi4py: ~1-2 s here)
POOL_START_S = 120.0
# s between checks, while waiting on a pool's samples, that its workers on this host are still alive
POLL_S = 0.5


@contextlib.contextmanager
def _pool(engine: str, workers: int):
    """A started pool of `workers` processes (engine "mpi": mpi4py.futures; "processes": concurrent.futures) whose
    workers note their pid, host and current samples in a folder (_note), so that `_results` can tell a worker
    that died.  On an error the pool is not waited for here (a dead mpi4py.futures worker leaves the pool's thread
    waiting for ever: the CLI ends the process, see PoolError)."""
    import shutil
    import tempfile

    folder = tempfile.mkdtemp(prefix="housingfe-pool-")
    try:
        ex = _executor(engine, workers, folder)
        try:
            yield ex, folder
        except BaseException:
            ex.shutdown(wait=False, cancel_futures=True)
            raise
        ex.shutdown(wait=True)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def _executor(engine: str, workers: int, folder: str):
    if engine == "mpi":
        from mpi4py.futures import MPIPoolExecutor

        # a singleton MPI process has one slot: spawning more needs oversubscription (Open MPI 4)
        return _started(MPIPoolExecutor(max_workers=workers, mpi_info={"map_by": ":OVERSUBSCRIBE"},
                                        initializer=_worker_start, initargs=(folder,)), workers)
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    return ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"),
                               initializer=_worker_start, initargs=(folder,))


def _started(ex, workers: int):
    """The mpi4py.futures pool `ex` once its workers answer (they are spawned together, and every worker has run
    its initializer before the first task runs: one answer means all are up); PoolError if they do not within
    POOL_START_S.  A worker that cannot be executed, exits at once or never calls MPI_Init left the command
    waiting for ever (2026-11-27: mpi4py 3.1.4, Open MPI 4), the pool's thread blocked in MPI_Comm_spawn; one
    such hang was seen at spawn (docs/uncertainty.md)."""
    import concurrent.futures

    from housingfe.errors import PoolError

    try:
        ex.submit(os.getpid).result(timeout=POOL_START_S)
    except concurrent.futures.TimeoutError:
        ex.shutdown(wait=False, cancel_futures=True)
        raise PoolError(f"uncertainty: the mpi4py.futures pool of {workers} worker(s) did not start within "
                        f"{POOL_START_S:g} s (MPI_Comm_spawn); try --engine processes") from None
    return ex


def _worker_start(folder: str) -> None:
    """A pool worker's initializer: start PETSc and note the worker (_note).  PETSc starts collectively on the
    mpi4py.futures workers' COMM_WORLD: when it started in the first sample, a worker whose sample failed before
    it left the others blocked in PetscInitialize, and the command waiting for ever (2026-11-27)."""
    from petsc4py import PETSc  # noqa: F401

    _note(folder, ())


def _note(folder: str, numbers) -> None:
    """In a worker: write `folder/<pid>` = this host and the sample numbers (1-based) it runs now.  A worker on
    another host has no such folder (or another machine's): it is not watched."""
    import socket

    try:
        Path(folder, str(os.getpid())).write_text(f"{socket.gethostname()}\n{' '.join(map(str, numbers))}\n")
    except OSError:
        pass


def _task(folder: str, numbers, batch) -> list[dict]:
    """One pool task: note the samples `numbers` of `batch`, evaluate_batch, note that none runs."""
    _note(folder, numbers)
    done = evaluate_batch(batch, worker=True)
    _note(folder, ())
    return done


def _local_workers(folder: str) -> dict:
    """{pid: sample numbers it runs (text)} of the workers on this host that noted themselves in `folder`."""
    import socket

    host, found = socket.gethostname(), {}
    for f in Path(folder).iterdir():
        try:
            where, numbers = (f.read_text().split("\n") + [""])[:2]
        except OSError:
            continue
        if where == host:
            found[int(f.name)] = numbers.split()
    return found


def _alive(pid: int) -> bool:
    """Process `pid` exists and is not a zombie (a dead child of this process not yet reaped)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return False


def _end(pid: int) -> None:
    import signal

    try:
        os.kill(pid, signal.SIGKILL)
    except OSError:
        pass


def _results(futures, ex, folder: str, engine: str):
    """Each future's result, in order; PoolError (one line) when a worker of the pool died: engine "mpi" checks
    every POLL_S that its workers on this host are alive (mpi4py.futures never notices a dead worker and waits for
    ever), engine "processes" learns it from concurrent.futures (BrokenProcessPool)."""
    import concurrent.futures
    from concurrent.futures.process import BrokenProcessPool

    for fut in futures:
        while True:
            try:
                yield fut.result(timeout=POLL_S if engine == "mpi" else None)
                break
            except concurrent.futures.TimeoutError:
                _check_mpi_workers(folder)
            except BrokenProcessPool:
                _broken_processes(ex, folder)
    if engine == "mpi":
        _check_mpi_workers(folder)                  # one that died idle would hang the pool's shutdown


def _check_mpi_workers(folder: str) -> None:
    """PoolError naming the pool's workers on this host that are gone, once the others are ended (Open MPI aborts
    their job, but they stayed up for seconds)."""
    from housingfe.errors import PoolError

    workers = _local_workers(folder)
    dead = {pid: "" for pid in workers if not _alive(pid)}
    if dead:
        for pid in workers:
            _end(pid)
        raise PoolError(_died("mpi4py.futures", dead, workers))


def _broken_processes(ex, folder: str) -> None:
    """InputError naming the worker(s) of the broken concurrent.futures pool `ex` that died of themselves: the
    pool ends the others with SIGTERM once it notices (its process objects: private, read if there)."""
    import signal

    procs = dict(getattr(ex, "_processes", None) or {})
    ex.shutdown(wait=True)                          # bounded: the broken pool joins its ended processes
    codes = {pid: p.exitcode for pid, p in procs.items() if p.exitcode is not None}
    own = {pid: c for pid, c in codes.items() if c != -signal.SIGTERM} or codes
    dead = {pid: f" (signal {-c})" if c < 0 else f" (exit code {c})" for pid, c in own.items()}
    # an ordinary exit: the pool is broken, not blocked (os._exit would leak its semaphores)
    if not dead:
        raise InputError("uncertainty: a worker of the concurrent.futures pool died (BrokenProcessPool); the run "
                         "stopped, nothing written")
    raise InputError(_died("concurrent.futures", dead, _local_workers(folder)))


def _died(pool: str, dead: dict, workers: dict) -> str:
    """The one line for the dead workers {pid: " (how)"} of `pool`, with the samples they ran (`workers`)."""
    what = [f"pid {pid}{' of the ' + pool + ' pool' if i == 0 else ''} died{how} "
            + (f"while running sample {', '.join(workers[pid])}" if workers.get(pid) else "between samples")
            for i, (pid, how) in enumerate(sorted(dead.items()))]
    return (f"uncertainty: worker {'; worker '.join(what)}; the run stopped, nothing written (killed for memory? "
            "try fewer --workers)")


def check_request(n_samples, seed, workers, families, engine) -> None:
    """InputError (one line) for a request that cannot run."""
    if not isinstance(n_samples, (int, np.integer)) or n_samples < 1:
        raise InputError(f"uncertainty: --samples: {n_samples}: must be a whole number >= 1")
    if not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InputError(f"uncertainty: --seed: {seed}: must be a whole number >= 0")
    if not isinstance(workers, (int, np.integer)) or workers < 1:
        raise InputError(f"uncertainty: --workers: {workers}: must be a whole number >= 1")
    bad = [f for f in families if f not in FAMILIES]
    if bad:
        raise InputError(f"uncertainty: --family {', '.join(bad)}: unknown (known: {', '.join(FAMILIES)}, all, none)")
    if engine not in ENGINES:
        raise InputError(f"uncertainty: --engine {engine}: unknown (known: {', '.join(ENGINES)})")


def run_uncertainty(scene: str = DEFAULT_SCENE, n_samples: int = 8, seed: int = 0, workers: int = 1, *,
                    ranges: dict | None = None, overrides=(), families: tuple = DEFAULT_FAMILIES, engine: str = "mpi",
                    samples_per_process: int | None = None, progress=None) -> UncertaintyResult:
    """Run `n_samples` seeded Latin-hypercube samples of the estimated inputs (PARAMETERS, `ranges` overriding:
    {name: (low, high)}, radiation: (models...)) through the run-up scene's chain (--set `overrides`) on `workers`
    processes (engine "mpi": mpi4py.futures; "processes": concurrent.futures) and return the UncertaintyResult.
    families: any of FAMILIES — "bearings" (gear set B with four bearing configurations), "profile-corrections"
    (sets B, C, D, uncorrected, and all five sets with the replica's engagement thesis-2d), "double-helical" (its
    own basis; two bearings at four torques); () = set A only (the cheap mode).  Each sample keeps the issue-28
    check rows of its runs (metrics "checks").  workers > 1: one pool, one task per sample, each process building
    its bases once; samples_per_process: instead batches of that many samples per process (a fresh process, and
    bases, per batch); workers == 1 (without a smaller samples_per_process) runs in this process.  Bad input
    -> InputError before any model is built."""
    from housingfe.runup.scene import load_runup_scene

    families = tuple(families)
    check_request(n_samples, seed, workers, families, engine)
    scene_obj, path = load_runup_scene(scene, list(overrides))
    if families and not np.any((scene_obj.runup.speeds >= MEAN_RANGE_RPM[0])
                                & (scene_obj.runup.speeds <= MEAN_RANGE_RPM[1])):
        raise InputError(f"{path}: runup speeds: none inside {MEAN_RANGE_RPM[0]:g}-{MEAN_RANGE_RPM[1]:g} rev/min "
                         "(the bearings family's mean differences)")
    check_mount(scene, overrides, ranges, families)
    samples = draw_samples(scene_obj, n_samples, seed, ranges)
    full = {**{p.name: (p.low, p.high) for p in PARAMETERS.values() if p.name not in OPT_IN},
            **{name: side_choices(scene_obj, name, ranges) for name in SIDES}, **(ranges or {})}
    say = progress or (lambda text: None)
    t0 = time.perf_counter()
    args = [(scene, tuple(overrides), s, families) for s in samples]
    if workers == 1 and (samples_per_process is None or n_samples <= samples_per_process):
        metrics = []
        for i, a in enumerate(args):
            metrics.append(evaluate_sample(*a))
            say(f"sample {i + 1}/{n_samples}: {metrics[-1]['seconds']:.1f} s")
        used = "serial"
    elif samples_per_process is None:
        # one pool of `workers` processes, one task per sample: a process keeps its bases (_STATE) from task to
        # task, and its resident memory stays flat (release_petsc_garbage; docs/uncertainty.md)
        used = "mpi4py.futures" if engine == "mpi" else "concurrent.futures"
        metrics = []
        with _pool(engine, min(workers, n_samples)) as (ex, folder):
            futures = [ex.submit(_task, folder, [i + 1], [a]) for i, a in enumerate(args)]
            for batch in _results(futures, ex, folder, engine):   # in sample order: the answer does not depend on the pool
                metrics += batch
                m = metrics[-1]
                say(f"sample {len(metrics)}/{n_samples}: {m['seconds']:.1f} s (process {m['pid']})")
    else:
        # batches of samples_per_process samples, at most `workers` batches per pool: the pool's processes end
        # after them and new ones build their bases again
        used = "mpi4py.futures" if engine == "mpi" else "concurrent.futures"
        numbers = list(range(1, len(args) + 1))
        batches = [(numbers[i:i + samples_per_process], args[i:i + samples_per_process])
                   for i in range(0, len(args), samples_per_process)]
        metrics = []
        for first in range(0, len(batches), workers):
            group = batches[first:first + workers]
            with _pool(engine, len(group)) as (ex, folder):
                futures = [ex.submit(_task, folder, nums, batch) for nums, batch in group]
                for batch in _results(futures, ex, folder, engine):   # in sample order
                    for m in batch:
                        metrics.append(m)
                        say(f"sample {len(metrics)}/{n_samples}: {m['seconds']:.1f} s (process {m['pid']})")
    wall = time.perf_counter() - t0
    # the fixed feet: one basis per process that built one; a mount: the bases of each new mount value
    setups = [m["setup_s"] for m in metrics if m["setup_s"] > 0 and not m.get("mount")]
    mounts = [m for m in metrics if m.get("mount") and m["setup_s"] > 0]
    timings = {"wall_s": wall, "per_sample_s": float(np.mean([m["seconds"] for m in metrics])),
               "per_sample_cpu_s": float(np.mean([m["cpu_s"] for m in metrics])),
               "basis_per_process_s": float(np.mean(setups)) if setups else 0.0,
               "processes": len({m["pid"] for m in metrics})}
    if mounts:
        timings["mount_bases_s"] = float(np.mean([m["setup_s"] for m in mounts]))
        timings["mount_bases_cpu_s"] = float(np.mean([m["setup_cpu_s"] for m in mounts]))
        timings["mount_bases_built"] = len(mounts)
    return UncertaintyResult(scene, int(seed), samples, metrics, tuple(scene_obj.runup.routes),
                             scene_obj.runup.speeds, families, full, used, int(workers), timings)


# ------------------------------------------------------------------------------------------------ outputs
def summary_text(result: UncertaintyResult) -> str:
    """The console / summary.txt table: median and 5-95 % band per quantity and route, fractions, cost."""
    from housingfe.outputs import format_table

    rows = []
    for r in result.summary_rows():
        if r["fraction"] is not None:
            rows.append([r["route"], r["quantity"], "", "", "", f"{r['fraction']:.2f}", _driver(r)])
        else:
            rows.append([r["route"], r["quantity"], _f(r["p5"]), _f(r["median"]), _f(r["p95"]), "", _driver(r)])
    t = result.timings
    head = (f"uncertainty {result.scene}: {len(result.samples)} Latin-hypercube samples, seed {result.seed}, "
            f"{result.workers} worker(s) ({result.engine}); families: {', '.join(result.families) or 'set A only'}")
    what = "set A" + (f" + families {', '.join(result.families)}" if result.families else "")
    if t.get("mount_bases_built"):
        bases = (f"{t['mount_bases_s']:.1f} s (CPU {t['mount_bases_cpu_s']:.1f} s) for the housing model and "
                 f"bases of each sample's mount ({t['mount_bases_built']} built, {t['processes']} process(es))")
    else:
        bases = (f"{t['basis_per_process_s']:.1f} s for the modal bases per process ({t['processes']} "
                 "process(es))")
    cost = (f"cost: {t['per_sample_s']:.1f} s per sample (CPU {t['per_sample_cpu_s']:.1f} s) ({what}), {bases}; "
            f"wall time {t['wall_s']:.1f} s")
    parts = [(k.removeprefix("seconds_"), [m[k] for m in result.metrics if k in m])
             for k in ("seconds_set_a", *(f"seconds_{f}" for f in FAMILIES))]
    parts = [f"{name} {np.mean(v):.1f} s" for name, v in parts if v]
    if parts:
        cost += "; per sample by family: " + ", ".join(parts)
    rss = [m.get("rss_mb") for m in result.metrics if isinstance(m.get("rss_mb"), float)]
    if rss:
        cost += f"; resident memory {min(rss):.0f}-{max(rss):.0f} MB after a sample"
    ids = result.check_ids()
    if ids:
        cost += f"\nissue-28 check rows computed per sample: {len(ids)} (bands.json, sample_checks.csv)"
    failed = [m["failed"] for m in result.metrics if m.get("failed")]
    notes = [f"{len(failed)} sample(s) with a configuration that could not run (NaN, left out of the bands): "
             + " | ".join(failed[:3])] if failed else []
    floating = floating_slid_line(result)
    table = format_table(["route", "quantity", "p5", "median", "p95", "fraction", "driver (Spearman rho)"], rows)
    return "\n".join([head, table, cost, f"driver: the input of largest |rank correlation|; with "
                      f"{len(result.samples)} samples |rho| < {2 / math.sqrt(max(len(result.samples), 1)):.2f} is noise",
                      *([floating] if floating else []), *notes])


def floating_slid_line(result: UncertaintyResult) -> str:
    """The summary's line counting, per configuration (floating_label), in how many of the samples that held an
    axial load in its floating bearings (drivetrain.floating_axial_ratio != 0) a ring slid, and which shafts':
    "floating rings slid: A_ball 0/12, B_angular_contact 7/12 (pinion 7, wheel 5), ..." ("" when none held one)."""
    counts: dict = {}
    for m in result.metrics:
        for key, slid in m.items():
            if key.endswith(SLID_SUFFIX):
                c = counts.setdefault(key.removesuffix(SLID_SUFFIX), {"slid": 0, "samples": 0})
                c["samples"] += 1
                c["slid"] += slid != "none"
                for shaft in ("" if slid == "none" else slid).split():
                    c[shaft] = c.get(shaft, 0) + 1
    if not counts:
        return ""
    parts = []
    for label, c in counts.items():
        shafts = {k: c[k] for k in sorted(c) if k not in ("slid", "samples")}
        parts.append(f"{label} {c['slid']}/{c['samples']}"
                     + (f" ({', '.join(f'{k} {v}' for k, v in shafts.items())})" if shafts else ""))
    return ("floating rings slid (drivetrain.floating_axial_ratio != 0; held loads per sample in samples.csv "
            "*_floating_*): " + ", ".join(parts))


def _driver(row) -> str:
    return f"{row['driver']} ({row['driver_rho']:+.2f})" if row.get("driver") else ""


def _f(x) -> str:
    return "nan" if x is None or not np.isfinite(x) else f"{x:.2f}"


SUMMARY_COLUMNS = ("route", "quantity", "p5", "median", "p95", "fraction", "samples", "driver", "driver_rho")


def write(folder: Path, result: UncertaintyResult) -> None:
    """samples.csv, sample_checks.csv (each sample's issue-28 check rows: ours, passed), summary.csv, summary.txt,
    uncertainty.png, uncertainty.json and bands.json (the check rows' bands and pass counts for `housingfe validate
    --bands`) in `folder`."""
    from housingfe.outputs import write_csv, write_json

    names = list(PARAMETERS)
    skip = {"pid", "setup_s", "setup_cpu_s", "checks"}
    keys = [k for k in result.metrics[0] if not k.endswith("lwa_curve_dBA") and k not in skip]
    keys += sorted({k for m in result.metrics for k in m} - set(keys) - skip
                   - {k for k in result.metrics[0] if k.endswith("lwa_curve_dBA")})
    write_csv(folder / "samples.csv", ["sample", *names, *keys],
              ([i, *("" if s.get(n) is None else s[n] for n in names), *(m.get(k, "") for k in keys)]
               for i, (s, m) in enumerate(zip(result.samples, result.metrics))))
    write_csv(folder / "sample_checks.csv", ["sample", "check_id", "ours", "passed"],
              ([i, c, v["ours"], v["passed"]] for i, m in enumerate(result.metrics)
               for c, v in (m.get("checks") or {}).items()))
    rows = result.summary_rows()
    write_csv(folder / "summary.csv", SUMMARY_COLUMNS, ([r[c] for c in SUMMARY_COLUMNS] for r in rows))
    (folder / "summary.txt").write_text(summary_text(result) + "\n")
    write_json(folder / "uncertainty.json", {
        "scene": result.scene, "seed": result.seed, "samples": result.samples,
        "ranges": {k: list(v) for k, v in result.ranges.items()},
        "parameters": {p.name: {"distribution": p.distribution, "low": p.low, "high": p.high,
                                "nominal": p.nominal, "unit": p.unit, "acts_on": p.acts_on, "source": p.source}
                       for p in PARAMETERS.values()},
        "families": list(result.families), "engine": result.engine, "workers": result.workers,
        "timings_s": result.timings, "summary": rows, "speeds_rpm": result.speeds,
        "metrics": [{k: v for k, v in m.items() if k != "pid"} for m in result.metrics]})
    from housingfe.verification.checks import BANDS_FORMAT

    write_json(folder / "bands.json", {"format": BANDS_FORMAT, "scene": result.scene, "seed": result.seed,
                                       "samples": len(result.samples), "families": list(result.families),
                                       "checks": result.check_bands()})
    plot(folder / "uncertainty.png", result)


def plot(path: Path, result: UncertaintyResult) -> None:
    """L_WA over speed (set A): median and 5-95 % band per route; the bearing configurations' mean differences
    (box per configuration, measured as markers)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(13, 5))
    ax = axes[0]
    for route in result.routes:
        curves = np.array([m[f"{route}/lwa_curve_dBA"] for m in result.metrics])
        p5, p50, p95 = np.percentile(curves, [5, 50, 95], axis=0)
        line, = ax.plot(result.speeds, p50, label=f"{route}: median")
        ax.fill_between(result.speeds, p5, p95, color=line.get_color(), alpha=0.25, label=f"{route}: 5-95 %")
    ax.set_xlabel("pinion speed [rev/min]")
    ax.set_ylabel("L_WA, set A, ball [dB(A)]")
    ax.set_title(f"{len(result.samples)} samples, seed {result.seed}", fontsize=10)
    ax.legend(fontsize=8)
    ax = axes[1]
    if "bearings" in result.families:
        others = [b for b in BEARING_FAMILY if b != "ball"]
        measured = measured_bearing_means()
        width = 0.8 / len(result.routes)
        for j, route in enumerate(result.routes):
            data = [result.values(f"variant_mean_{b}_dB", route) for b in others]
            data = [d[np.isfinite(d)] for d in data]
            box = ax.boxplot(data, positions=np.arange(len(others)) + j * width, widths=width * 0.8,
                             whis=(5, 95), showfliers=False, manage_ticks=False, patch_artist=True)
            for patch in box["boxes"]:
                patch.set_facecolor(f"C{j}")
                patch.set_alpha(0.5)
            ax.plot([], [], "s", color=f"C{j}", alpha=0.5, label=f"ours, {route}")
        ax.plot(np.arange(len(others)) + width * (len(result.routes) - 1) / 2, [measured[b] for b in others],
                "k<", ms=8, label="measured (Sec. 5.8)")
        ax.axhline(0.0, color="k", lw=0.6)
        ax.set_xticks(np.arange(len(others)) + width * (len(result.routes) - 1) / 2, others)
        ax.set_ylabel("L_WA - L_WA(ball), mean 800-1500 rpm, gear set B [dB]")
        ax.set_title("boxes: 25-75 %, median; whiskers 5-95 %", fontsize=10)
        ax.legend(fontsize=8)
    else:
        ax.axis("off")
    fig.suptitle(f"housingfe uncertainty {result.scene}")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def run_command(scene: str, n_samples: int, seed: int, workers: int, out_dir: str | None, ranges_items=(),
                overrides=(), families=DEFAULT_FAMILIES, engine: str = "mpi",
                samples_per_process: int | None = None) -> Path:
    """`housingfe uncertainty`: check the request, reserve the result folder, run, write atomically, print."""
    from mpi4py import MPI

    from housingfe import outputs
    from housingfe.runup.scene import load_runup_scene

    families = tuple(families)
    check_request(n_samples, seed, workers, families, engine)
    if samples_per_process is not None and samples_per_process < 1:
        raise InputError(f"uncertainty: --samples-per-process: {samples_per_process}: must be >= 1")
    ranges = parse_ranges(ranges_items)
    scene_obj, path = load_runup_scene(scene, list(overrides))
    draw_samples(scene_obj, 1, seed, ranges)                 # a bad radiation choice stops here
    check_mount(scene, overrides, ranges, families)          # a housing that cannot stand on a frame too
    out = Path(out_dir or f"results/uncertainty-{scene_obj.scene.name}")
    comm = MPI.COMM_WORLD
    outputs.reserve_output(out, comm, inputs=[path])
    result = run_uncertainty(scene, n_samples, seed, workers, ranges=ranges, overrides=overrides,
                             families=families, engine=engine, samples_per_process=samples_per_process,
                             progress=lambda t: print(t, flush=True))
    with outputs.atomic_output_dir(out, comm) as tmp:
        if comm.rank == 0:
            write(tmp, result)
    print(summary_text(result))
    print(f"results: {out}/")
    return out


def register_cli(subparsers) -> None:
    """Add `housingfe uncertainty [SCENE] --samples N --seed S [--workers K] [--out DIR] [--range NAME=LO:HI]
    [--family bearings|none] [--engine mpi|processes] [--set KEY=VALUE]`."""
    p = subparsers.add_parser("uncertainty", help="spread of the run-up's answers over the ranges of the "
                                                  "estimated inputs (seeded Latin hypercube; docs/uncertainty.md)")
    p.add_argument("scene", nargs="?", default=DEFAULT_SCENE, help=f"run-up scene (default {DEFAULT_SCENE})")
    p.add_argument("--samples", type=int, default=8, help="number of samples (default 8)")
    p.add_argument("--seed", type=int, default=0, help="seed of the Latin hypercube (default 0)")
    p.add_argument("--workers", type=int, default=1, help="processes (default 1; > 1: mpi4py.futures)")
    p.add_argument("--engine", default="mpi", help="pool for --workers > 1: mpi (mpi4py.futures, default) or "
                                                   "processes (concurrent.futures)")
    p.add_argument("--samples-per-process", type=int, default=None,
                   help="samples a process runs before a new one takes over and builds its bases again (default: "
                        "a worker's whole share)")
    p.add_argument("--out", default=None, help="result folder (default results/uncertainty-<scene>)")
    p.add_argument("--range", action="append", metavar="NAME=LOW:HIGH",
                   help="override a parameter's range (NAME=VALUE: fixed; radiation=erp[,foller]; "
                        "wheel_locating_<configuration>=front|back|front,back); names: "
                        + ", ".join(PARAMETERS))
    p.add_argument("--family", action="append", metavar="FAMILY",
                   help="variant families per sample, repeatable: bearings (default: gear set B with the four "
                        "bearing configurations), profile-corrections (sets B, C, D, uncorrected, and the thesis "
                        "replica's engagement thesis-2d for all five sets), double-helical (its own basis; roller "
                        "and fluid-film bearings at 500-2000 N m), all; none: set A only, the cheap mode")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a value of the run-up scene")
    p.set_defaults(func=_cmd)


def _cmd(args: argparse.Namespace) -> int:
    fams = args.family or list(DEFAULT_FAMILIES)
    fams = () if fams == ["none"] else FAMILIES if "all" in fams else tuple(dict.fromkeys(fams))
    run_command(args.scene, args.samples, args.seed, args.workers, args.out, args.range or (), args.set or (),
                fams, args.engine, args.samples_per_process)
    return 0
