"""The noise chain end to end: gear set + speed + torque -> L_v, L_W, L_WA over speed (van Roosmalen 1994, Ch. 5).

    model = build_gearbox_model(housing_model, drivetrain, f_lines_max=4000.0)   # once: coupled FE + Ritz basis
    source = drivetrain.source_model()                                           # the lumped source (Ch. 2)
    result = runup(model, source, speeds_rpm, torques_nm, routes=("tf_omega", "mesh_force"))
    other = with_drivetrain(model, test_gearbox("B"))                           # another set: same basis

Per run, once (`build_gearbox_model`): the housing coupled with the drivetrain's FE reduction (shafts, gears,
bearings as 6x6 matrices at star connections to the bores, the gear mesh), its complete modal basis to
basis_factor x the highest line, and a Ritz reduction (housingfe.response.reduced) on the unit loads the routes
need: a torque of 1 N m about the wheel axis at the wheel centre, a unit compressive pair along the gear-mesh
normal (the loads the gear-mesh element carries), and the moment pair of the shuttling moment (the mesh force's
point moved along the gear axis, `unit_loads`; applied with runup.mesh_moment = "shuttling"); with the sliding
friction on (runup.mesh_friction, `MESH_FRICTIONS`) also its four resultants' unit loads.  Per speed and torque: the source's operating point
(housingfe.source.roosmalen.operating), then each route's L_v per tooth harmonic, then each radiator's L_sigma and L_W.

Routes (`ROUTES`, a registry: `@register_route(name)`):

* "tf_omega" — the thesis' route, eq. 5.5: L_v(f_n) = L_omega(f_n) + TF_omega(f_n), with
  TF_omega = L_v - L_omega of the coupled model under the 1 N m wheel torque (Sec. 5.4), at every line.
* "mesh_force" — the source's dynamic mesh excitation applied coherently on the coupled model's gear mesh.  The
  coupled model already holds the mean mesh stiffness k_m, so the load is the part of the lumped mesh force that
  k_m does not carry: F_exc,n = F_n - k_m d_n (F_n: the dynamic mesh force S(t) d(t) + F_e(t), d_n: the mesh
  compression, both per harmonic from the harmonic balance; k_m: the mean of S(t)); with the lumped model's
  interior it reproduces the lumped response exactly (tests/runup/test_chain.py).  The source's bearing forces are
  NOT added: on the coupled model the shafts carry the mesh force to the bearings and bores themselves (adding the
  rigid-bore reactions would count them twice).  It also gives L_omega of the wheel on the flexible housing.

Amplitudes: the source's one-sided (peak) amplitudes A_n become rms phasors A_n / sqrt(2).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from housingfe import levels
from housingfe.drivetrain.bore_loads import (
    bore_loads,
    force_level_db,
    moment_level_db,
    structure_bearing_elements,
)
from housingfe.drivetrain.bore_loads import node_rows as _node_rows
from housingfe.drivetrain.description import FRICTION_LOADS
from housingfe.errors import InputError
from housingfe.radiation.power import area_level_db
from housingfe.response.observers import node_key
from housingfe.response.reduced import RitzReduction, modal_basis_summary
from housingfe.solvers import harmonic, modal
from housingfe.solvers.blas import single_thread

ROUTES: dict = {}


def register_route(name: str):
    """Decorator: register an excitation route `fn(model, lines) -> RouteResult` under `name`."""
    def add(fn):
        if name in ROUTES:
            raise ValueError(f"route {name!r} is registered twice")
        ROUTES[name] = fn
        return fn

    return add


# ------------------------------------------------------------------------------------------------ model
@dataclass
class GearboxModel:
    """The coupled gearbox of a run-up (see the module docstring): drivetrain (housingfe.drivetrain.description
    .Drivetrain), structure (CoupledInterior), basis (ModalBasis), reduction (RitzReduction on the loads
    "wheel_torque", "mesh" and "shuttle", and the friction loads where built with friction, `unit_loads`), radiators {name: Radiator}, wheel node and axis, the highest line (Hz), the
    interior energy share of each basis mode, timings (s)."""

    drivetrain: object
    housing_model: object
    structure: object
    basis: object
    reduction: RitzReduction
    radiators: dict
    wheel_node: str
    wheel_axis: np.ndarray
    f_lines_max: float
    interior_share: np.ndarray
    timings: dict = field(default_factory=dict)
    bores: list = field(default_factory=list)     # the bearings' housing bores (bore_matching summary rows)
    # speed-dependent bearings following the run-up's speed (`follow_speeds`, runup.bearing_speeds = "follow"):
    # {pinion speed rev/min: the model at that speed}; empty: this one model at every speed
    speed_models: dict = field(default_factory=dict)
    # {speed rev/min: the speed whose bearing matrices it holds} where the bearings cannot carry their load at the
    # speed itself (a fluid film below its speed limit), and why (the first refusal's message)
    held_speeds: dict = field(default_factory=dict)
    held_reason: str = ""
    # the reduction the speed models were made from (follow_speeds): another one here (dataclasses.replace of a
    # model following the speeds) would leave them on the old one, silently: refused in __post_init__
    followed_reduction: object = field(default=None, repr=False, compare=False)

    def __post_init__(self):
        if self.speed_models and self.followed_reduction is not self.reduction:
            raise RuntimeError("GearboxModel: a model following the run-up's speeds (follow_speeds) got another "
                               "reduction while its speed models keep the old one: use with_reduction(model, "
                               "reduction), which follows the speeds again on it")

    def at_speed(self, speed_rpm: float) -> "GearboxModel":
        """The model at a pinion speed (rev/min): with the bearings following the run-up's speed
        (`follow_speeds`) that speed's, else this model."""
        if not self.speed_models:
            return self
        model = self.speed_models.get(float(speed_rpm))
        if model is None:
            raise InputError(f"runup.bearing_speeds: the model follows the speeds "
                             f"{', '.join(f'{v:g}' for v in sorted(self.speed_models))} rev/min, not {speed_rpm:g}")
        return model

    @property
    def area(self) -> float:
        """Radiating surface (m^2)."""
        return self.reduction.area

    def summary(self) -> dict:
        """JSON-able facts: the modal basis used, the Ritz reduction, the radiating area."""
        out = modal_basis_summary(self.basis, self.reduction)
        n = self.basis.rigid_count
        out["interior_share"] = [float(x) for x in self.interior_share]
        out["interior_dominated_modes_hz"] = [float(f) for f, s in
                                              zip(self.basis.frequencies_hz[n:], self.interior_share) if s > 0.5]
        out["area_m2"] = self.area
        out["f_lines_max_hz"] = self.f_lines_max
        out["ritz_frequencies_hz"] = [float(x) for x in self.reduction.frequencies_hz]
        if self.bores:
            out["bores"] = self.bores
        return out


def unit_loads(structure, drivetrain, friction: bool = False) -> tuple[dict, str, np.ndarray]:
    """({"wheel_torque": 1 N m about the wheel axis at the wheel centre, "mesh": unit compressive pair along the
    FE mesh normal, "shuttle": the moment pair of 1 N m = F dw of the mesh force's point moved along the gear axis
    (Drivetrain.shuttle_node_loads: +(e_w x n) on the wheel, -(e_w x n) on the pinion, e_w the direction in which
    the mesh model's w grows)}, wheel node name, wheel axis) as coupled load vectors.  friction: also the unit
    loads of the four sliding-friction resultants (FRICTION_LOADS: "friction_force" 1 N, "friction_pinion_torque",
    "friction_wheel_torque", "friction_tilt" 1 N m; Drivetrain.friction_node_loads), only then: without friction
    the reduction has no static vectors of theirs."""
    wheel = f"wheel:{drivetrain.shaft_nodes('wheel')[1]['gear']}"
    axis = np.asarray(drivetrain.shaft("wheel").axis, float)
    axis /= np.linalg.norm(axis)
    torque = structure.node_load(wheel, "moment", axis, "runup.wheel_torque")
    mesh = structure.system.load(node_loads={k: np.real(v) for k, v in drivetrain.mesh_node_loads(1.0).items()})
    shuttle = structure.system.load(node_loads={k: np.real(v) for k, v in
                                                drivetrain.shuttle_node_loads(1.0).items()})
    loads = {"wheel_torque": torque, "mesh": mesh, "shuttle": shuttle}
    if friction:
        for resultant, name in FRICTION_LOADS.items():
            loads[name] = structure.system.load(node_loads=drivetrain.friction_node_loads(resultant))
    return loads, wheel, axis


def bearing_pairs(structure) -> list:
    """Self-equilibrated unit force and moment pairs across every bearing (shaft node +, bore master -), six per
    bearing, and unit torques across each drive line's quills (about the shaft axis: shaft end +, coupling node -;
    on the coupling node alone for the far quill to ground; and on the aux gearbox node of a back-to-back loop), as
    coupled vectors: the static vectors that make a
    re-analysis with other bearing or quill stiffnesses (another torque, another configuration, the uncertainty's
    quill samples) accurate."""
    out = []
    for b in structure.spec.bearings:
        for i in range(6):
            e = np.zeros(6)
            e[i] = 1.0
            out.append(structure.system.load(node_loads={b.shaft_node: e, b.bore: -e}))
    for d in structure.spec.drive_lines:
        e = np.r_[np.zeros(3), structure.shaft_axis(d.shaft_node)]
        out.append(structure.system.load(node_loads={d.shaft_node: e, d.name: -e}))
        out.append(structure.system.load(node_loads={d.name: e}))
    aux = getattr(structure.spec, "aux_gearbox", None)
    if aux is not None:         # the back-to-back loop: with the coupling nodes' torques these span its far quills
        a = np.asarray(aux.axis, float) / np.linalg.norm(aux.axis)
        out.append(structure.system.load(node_loads={aux.name: np.r_[np.zeros(3), a]}))
    return out


@single_thread
def build_gearbox_model(housing_model, drivetrain, f_lines_max: float, *, damping_ratio: float = 0.04,
                        basis_factor: float = 1.5, radiators: dict | None = None,
                        surface: str = "outer", friction: bool = False) -> GearboxModel:
    """Couple `housing_model` (HousingModel with the bores of the drivetrain's bearings) with `drivetrain`, compute
    its complete modal basis to basis_factor x f_lines_max (Hz) and the Ritz reduction of the unit loads
    (`unit_loads`).
    damping_ratio: modal xi (Sec. 5.4: 0.04); radiators: {name: Radiator} (their extra points are kept);
    friction: the friction unit loads too (a run-up with runup.mesh_friction on, `has_friction_loads`)."""
    from housingfe.drivetrain.interior import build_interior

    t0 = time.perf_counter()
    radiators = dict(radiators or {})
    f_basis = basis_factor * f_lines_max
    structure = build_interior(housing_model, drivetrain.to_coupling_spec(), f_basis)
    t1 = time.perf_counter()
    basis = modal.modes(structure, f_basis)
    t2 = time.perf_counter()
    loads, wheel, axis = unit_loads(structure, drivetrain, friction)
    extra = {}
    for radiator in radiators.values():
        extra.update(radiator.extra_points(structure))
    damping = harmonic.Damping(lambda f: np.zeros(np.shape(f)), modal_ratio=damping_ratio)
    reduction = RitzReduction(basis, loads, damping, surface=surface, nodes=(wheel,), extra_points=extra,
                              static_vectors=bearing_pairs(structure))
    share = structure.interior_fraction(basis.vectors[basis.rigid_count:])
    t3 = time.perf_counter()
    timings = {**housing_model.timings, "coupling_s": t1 - t0, "basis_s": t2 - t1, "reduction_s": t3 - t2}
    return GearboxModel(drivetrain, housing_model, structure, basis, reduction, radiators, wheel, axis,
                        float(f_lines_max), share, timings)


@single_thread
def with_drivetrain(model: GearboxModel, drivetrain) -> GearboxModel:
    """The same housing and Ritz vectors with another drivetrain of the same layout (gear set, torque, bearings):
    its coupled K, M, C projected on the vectors (a Rayleigh-Ritz re-analysis, seconds instead of a new basis).
    The unit loads are the model's (with the friction loads where it has them)."""
    from housingfe.drivetrain.interior import build_interior

    t0 = time.perf_counter()
    if drivetrain.drive_line != model.drivetrain.drive_line:
        raise InputError(f"drivetrain: drive_line {drivetrain.drive_line!r} is not the model's "
                         f"({model.drivetrain.drive_line!r}): another set of DOFs, build a new gearbox model")
    structure = build_interior(model.housing_model, drivetrain.to_coupling_spec(),
                               model.basis.f_max)
    loads, wheel, axis = unit_loads(structure, drivetrain, has_friction_loads(model))
    if wheel != model.wheel_node:
        raise InputError("drivetrain: another shaft layout than the model's (the wheel node moved): build a new "
                         "gearbox model")
    reduction = model.reduction.reanalyse(structure, loads)
    # a model following the run-up's speed held its speeds' bearings: another drivetrain starts from its own
    return replace(model, drivetrain=drivetrain, structure=structure, reduction=reduction, speed_models={},
                   held_speeds={}, held_reason="", timings={**model.timings, "reanalysis_s": time.perf_counter() - t0})


# how speed-dependent bearings (fluid films, Drivetrain.speed_dependent_bearings) take the run-up's speed (scene key
# runup.bearing_speeds): "fixed" = at the one pinion speed drivetrain.bearing_speed_rpm for the whole run-up;
# "follow" = at each run-up speed (`follow_speeds`; the default).  Rolling-element bearings are the same either way
BEARING_SPEEDS = ("fixed", "follow")


class _SpeedSystem:
    """The base's CoupledSystem (DOF layout, loads, node displacements, M: independent of the bearings' K, C)
    without its K and C, which are the base speed's (`SpeedInterior`)."""

    STALE = frozenset({"K", "C", "symmetric"})

    def __init__(self, system, why):
        self._system, self._why = system, why

    def __getattr__(self, name):
        if name.startswith("__") or name in ("_system", "_why"):
            raise AttributeError(name)
        if name in self.STALE:
            raise RuntimeError(self._why(f"system.{name}"))
        return getattr(self._system, name)


class SpeedInterior:
    """The `structure` of a model at one run-up speed (`follow_speeds`): its `spec` and `parts` are the speed's
    (the bearing specs and elements at the speed, built anyway to project their change); geometry, DOF layout,
    loads, M, node displacements, the housing are the base model's, which do not depend on the bearings' K, C;
    the coupled K, C (and what depends on them: `symmetric`, the interior's modes on rigid bores `rigid`, the zero
    modes, `basis_stiffness`) are refused with a RuntimeError, because the base model's are those of its own bearing
    speed.

    Why not the speed's own CoupledInterior: its K, C are matrices of the whole coupled model (66 k DOFs), to be
    re-assembled or copied per speed: seconds and a matrix pair per speed, which is what `follow_speeds` exists to
    avoid (the run-up needs only the projected change).  A caller that needs them builds the speed's structure:
    `with_drivetrain(model, model.drivetrain)` on the speed's model (a re-analysis; seconds)."""

    STALE = frozenset({"K", "C", "symmetric", "rigid", "basis_stiffness", "expected_zero_modes",
                       "expected_mechanisms", "_basis_K"})

    def __init__(self, base, spec, parts, speed_rpm: float, base_speed_rpm: float):
        self._base = base
        self.spec, self.parts = spec, parts
        self.speed_rpm, self.base_speed_rpm = float(speed_rpm), float(base_speed_rpm)

    def _why(self, name: str) -> str:
        return (f"structure.{name} of the model at {self.speed_rpm:g} rev/min (follow_speeds, runup.bearing_speeds = "
                f"\"follow\") would be that of the bearings at {self.base_speed_rpm:g} rev/min: only its reduction, "
                f"spec and parts follow the speed; with_drivetrain(model, model.drivetrain) builds the structure at "
                f"the speed")

    @property
    def system(self):
        return _SpeedSystem(self._base.system, self._why)

    def __getattr__(self, name):
        if name.startswith("__") or name == "_base":
            raise AttributeError(name)
        if name in self.STALE:
            raise RuntimeError(self._why(name))
        return getattr(self._base, name)


@single_thread
def follow_speeds(model: GearboxModel, speeds_rpm) -> GearboxModel:
    """`model` with its speed-dependent bearings (fluid films: Drivetrain.speed_dependent_bearings) at each pinion
    speed of `speeds_rpm` (rev/min; the wheel's at z1/z2 of it, turning the other way): per speed the drivetrain's
    bearing matrices K, C (Drivetrain.configuration_matrices at bearing_speed_rpm = the speed) and a Rayleigh-Ritz
    re-analysis on the same Ritz vectors, as `with_drivetrain` would do it, but projecting only the change of the
    bearing elements: sum over bearings of X_e^T (A_e(speed) - A_e(model)) X_e, X_e the Ritz vectors' rows at the
    bearing's shaft node and bore master (the coupled matrices are P^T A P, so this is the same projection, on 12
    rows per bearing instead of the coupled matrices).  The result holds them in `speed_models` (`at_speed`);
    the routes, the coupled source and peak_contributions solve each line on its speed's model.

    Below the speed at which a film carries its load (the Reynolds solution needs an eccentricity ratio above 0.98,
    housingfe.bearings.fluid_film), a speed holds the matrices of the nearest run-up speed that carries it
    (`held_speeds`, `held_reason`; the film there is stiffer and more damped than the held matrices say).  No
    speed that carries it: InputError.  A model without speed-dependent bearings is returned as it is (no
    re-analysis)."""
    from housingfe.drivetrain.interior import parts

    dt = model.drivetrain
    if not dt.speed_dependent_bearings:
        return model
    t0 = time.perf_counter()
    base = replace(model, speed_models={}, held_speeds={}, held_reason="")
    structure = model.structure
    old = structure.parts.bearings
    specs, refused = {}, {}
    for s in sorted({float(v) for v in speeds_rpm}):
        at = replace(dt, bearing_speed_rpm=s)
        try:
            specs[s] = (at, at.to_coupling_spec())
        except InputError as exc:
            refused[s] = str(exc)
    if not specs:
        first = next(iter(refused.values()))
        raise InputError(f"runup.bearing_speeds: \"follow\": the bearings carry their load at none of the run-up's "
                         f"speeds ({first})")
    t_matrices = time.perf_counter() - t0
    nodes = sorted({n for e in old for n in e.nodes})
    rows = _node_rows(structure, model.reduction.vectors, nodes)
    t_rows = time.perf_counter() - t0 - t_matrices
    models = {}
    for s, (at, spec) in specs.items():
        if s == float(dt.bearing_speed_rpm):
            models[s] = replace(base, drivetrain=at)
            continue
        speed_parts = parts(spec, structure.centres)
        new = speed_parts.bearings
        n = len(model.reduction.vectors)
        dK, dC = np.zeros((n, n)), np.zeros((n, n))
        for e_old, e_new in zip(old, new):
            if e_old.nodes != e_new.nodes:
                raise InputError("runup.bearing_speeds: the bearings moved between speeds: build a new gearbox model")
            X = np.vstack([rows[node] for node in e_old.nodes])
            dK += X.T @ (e_new.K - e_old.K) @ X
            if e_old.C is not None or e_new.C is not None:
                c_old = np.zeros_like(e_new.K) if e_old.C is None else e_old.C
                c_new = np.zeros_like(e_old.K) if e_new.C is None else e_new.C
                dC += X.T @ (c_new - c_old) @ X
        # the structure: the speed's spec and bearing elements, the base's coupled K, C refused (SpeedInterior)
        speed_structure = SpeedInterior(structure, spec, speed_parts, s, dt.bearing_speed_rpm)
        models[s] = replace(base, drivetrain=at, structure=speed_structure,
                            basis=replace(model.basis, structure=speed_structure),
                            reduction=model.reduction.with_change(dK, dC, speed_structure))
    valid = np.array(sorted(models))
    held = {}
    for s in refused:
        near = float(valid[np.argmin(np.abs(valid - s))])
        models[s] = models[near]
        held[s] = near
    # bearing_matrices_s: the films' K, C per speed (Reynolds equation); ritz_rows_s: the Ritz vectors at the
    # bearings' nodes (once); the rest is the per-speed projection and the reduced systems' modes
    timings = {**model.timings, "speed_reanalysis_s": time.perf_counter() - t0, "bearing_matrices_s": t_matrices,
               "ritz_rows_s": t_rows, "speed_models": len(specs)}
    reason = next(iter(refused.values()), "")
    return replace(model, speed_models=models, held_speeds=held, held_reason=reason, timings=timings,
                   followed_reduction=model.reduction)


def with_reduction(model: GearboxModel, reduction: RitzReduction) -> GearboxModel:
    """`model` with another reduction of the same structure (another damping, a truncated basis, more kept
    points); a model following the run-up's speeds (`follow_speeds`) follows the same speeds again on it, so the
    per-speed models hold the new reduction too."""
    speeds = sorted(model.speed_models)
    out = replace(model, reduction=reduction, speed_models={}, held_speeds={}, held_reason="",
                  followed_reduction=None)
    return follow_speeds(out, speeds) if speeds else out


def held_speed_note(model: GearboxModel, torque: float) -> str:
    """One line on the speeds whose bearings hold another speed's matrices (`follow_speeds`), or ""."""
    if not model.held_speeds:
        return ""
    speeds = sorted(model.held_speeds)
    at = sorted(set(model.held_speeds.values()))
    why = model.held_reason.split(": ")[-1].removesuffix("; not carried") if model.held_reason else "no film"
    return (f"  bearings following the speed at {torque:g} N m: not carried at {', '.join(f'{s:g}' for s in speeds)} "
            f"rev/min ({why}); these speeds hold the matrices of {', '.join(f'{s:g}' for s in at)} rev/min "
            "(runup.json bearing_speeds.held)")


def line_coefficients(model: GearboxModel, frequency, speed, amplitudes: dict) -> np.ndarray:
    """(vectors, lines) Ritz coordinates of the response to the loads' complex rms `amplitudes` (name -> number or
    array per line) at the lines' frequencies (Hz), each line solved on the model at its pinion speed `speed`
    (rev/min; GearboxModel.at_speed: the bearings following the run-up's speed) or, without speed models, all on
    `model` (RitzReduction.coefficients)."""
    f = np.asarray(frequency, float)
    if not model.speed_models:
        return model.reduction.coefficients(f, amplitudes)
    speed = np.broadcast_to(np.asarray(speed, float), f.shape)
    c = np.zeros((len(model.reduction.vectors), len(f)), complex)
    for s in np.unique(speed):
        at = np.flatnonzero(speed == s)
        part = {k: (np.asarray(v)[at] if np.ndim(v) else v) for k, v in amplitudes.items()}
        c[:, at] = model.at_speed(s).reduction.coefficients(f[at], part)
    return c


def has_friction_loads(model: GearboxModel) -> bool:
    """Whether the model's Ritz reduction holds the friction unit loads (`build_gearbox_model(friction=True)`)."""
    return all(name in model.reduction.names for name in FRICTION_LOADS.values())


# ------------------------------------------------------------------------------------------------ lines
@dataclass
class Lines:
    """Every tooth-harmonic line of a run-up (arrays of equal length, one entry per line): torque (N m), speed
    (rev/min), harmonic n, frequency (Hz), L_omega (dB re 5e-8 rad/s, the source's narrow-band level of the wheel),
    mesh_excitation (complex rms N, F_n - k_m d_n), point (index of the operating point);  per operating point:
    points = [(torque, speed, tooth frequency Hz, L_omega in the tooth band dB, k_m N/m)]."""

    torque: np.ndarray
    speed: np.ndarray
    harmonic: np.ndarray
    frequency: np.ndarray
    L_omega: np.ndarray
    mesh_excitation: np.ndarray
    point: np.ndarray
    points: list
    # which receptance the source's harmonic balance used (SOURCE_RECEPTANCES).  With "coupled": mesh_excitation
    # comes from the balance on the coupled gearbox and L_omega_flexible is the wheel's level on it per line;
    # L_omega and points stay the rigid-bore source's (the input of the thesis' route tf_omega, eq. 5.5)
    receptance: str = "rigid-bores"
    L_omega_flexible: np.ndarray | None = None
    # the shuttling moment per line (complex rms N m on the unit load "shuttle": F times harmonic n of the mesh
    # load's axial centre of pressure, MESH_MOMENTS); None: not applied (mesh_moment = "none")
    shuttle_moment: np.ndarray | None = None
    # the sliding friction per line: {friction unit load name (FRICTION_LOADS): complex rms N or N m} and the mean
    # friction coefficient of each line [-] (`friction_lines`); None: not applied (mesh_friction = "none")
    friction: dict | None = None
    friction_mu: np.ndarray | None = None
    # which lines are incoherent (True: an expected line of gears as made, housingfe.runup.as_made, whose energy adds
    # to the others'); None: every line is a periodic tooth harmonic, one per harmonic and operating point.  With it,
    # a harmonic n names the lines in the 1/3-octave band of n f_tooth (the periodic line and the sidebands beside it)
    incoherent: np.ndarray | None = None

    def mesh_amplitudes(self) -> dict:
        """{unit load name: complex rms amplitude per line} of the mesh excitation the mesh_force route applies:
        "mesh" (N), "shuttle" (N m) where the shuttling moment is on, the friction loads where friction is on."""
        out = {"mesh": self.mesh_excitation}
        if self.shuttle_moment is not None:
            out["shuttle"] = self.shuttle_moment
        if self.friction is not None:
            out.update(self.friction)
        return out


# the mesh moment applied with the mesh excitation on the coupled model (scene key runup.mesh_moment): "shuttling" =
# the moment of the mesh force whose centre of pressure moves axially over the face as the contact lines move
# (housingfe.source.mesh_moments; docs/source.md "The shuttling moment (issue 28)"), "none" = the force alone
MESH_MOMENTS = ("shuttling", "none")
DEFAULT_MESH_MOMENT = "shuttling"


def _check_mesh_moment(mesh_moment: str) -> None:
    if mesh_moment not in MESH_MOMENTS:
        raise InputError(f"mesh_moment: {mesh_moment!r} is not one of {', '.join(MESH_MOMENTS)}")


def shuttle_moments(source, torque_nm: float, harmonics: np.ndarray) -> np.ndarray:
    """The shuttling moment M_n = F W_n / sqrt(2) (complex rms, N m) at the tooth harmonics n (array of ints >= 1):
    F the transmitted normal force [N] at the pinion torque [N m], W_n the one-sided harmonic n of the moment arm
    w_c + tan(beta_b) s_c [m] of the mesh load's centre of pressure (SourceModel.centre_of_pressure: the load
    distributions of the source's stiffness curve, same time origin as S(t) and F_e(t); CentreOfPressure
    .moment_arm_harmonics; no s term for a double helical pair, whose halves' terms cancel; the unit load applies
    F as its resultant, cos(beta_b) F along the transverse line of action there, Drivetrain.shuttle_node_loads).  The
    s term is small (at most 2.4 N m against 98-157 N m of the axial term at n = 1 for sets A-D at 2000 N m,
    benchmarks/experiments/shuttling) but lies on the same axis, so it is kept.  The amplitude of the unit load
    "shuttle" (`unit_loads`).

    First order: applied on the coupled model holding the mean mesh stiffness, this is exact superposition of the
    constant force's moving point; the product of the stiffness ripple with the moment's own mesh deflection is
    dropped (docs/source.md, "The shuttling moment (issue 28)")."""
    from housingfe.source.stiffness import normal_force_from_torque

    n = np.asarray(harmonics, int)
    pair = source.pair
    tan_bb = 0.0 if pair.kind == "double_helical" else math.tan(pair.base_helix_angle)
    arm = source.centre_of_pressure(float(torque_nm)).moment_arm_harmonics(tan_bb, int(n.max()) if n.size else 1)
    F = normal_force_from_torque(source.pair, float(torque_nm))
    return F * arm[n - 1] / math.sqrt(2.0)


# the sliding friction applied with the mesh excitation on the coupled model (scene key runup.mesh_friction): "none",
# "iso13989" = a mean coefficient per operating point from ISO/TR 13989-1 (housingfe.source.mesh_friction
# .iso13989_run_friction; the formula quoted from memory, not verified against the standard), or a number = a fixed
# mean coefficient in MESH_FRICTION_RANGE (exclusive).  Default "none": the ISO formula is not verified
MESH_FRICTIONS = ("none", "iso13989")
DEFAULT_MESH_FRICTION = "none"
MESH_FRICTION_RANGE = (0.0, 0.3)


def check_mesh_friction(value) -> str | float:
    """The runup.mesh_friction setting as the chain takes it ("none", "iso13989" or a float), or InputError
    "mesh_friction: ..." (a number outside MESH_FRICTION_RANGE, another word)."""
    lo, hi = MESH_FRICTION_RANGE
    if isinstance(value, str) and value in MESH_FRICTIONS:
        return value
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        mu = float(value)
        if math.isfinite(mu) and lo < mu < hi:
            return mu
        raise InputError(f"mesh_friction: a mean friction coefficient must lie between {lo:g} and {hi:g} "
                         f"(exclusive), got {value!r}")
    raise InputError(f"mesh_friction: {value!r} is not one of {', '.join(MESH_FRICTIONS)} or a mean friction "
                     f"coefficient between {lo:g} and {hi:g}")


def friction_lines(source, lines: Lines, mesh_friction) -> tuple[dict, np.ndarray]:
    """({friction unit load name: complex rms amplitude per line}, mean friction coefficient per line [-]) of the
    sliding friction at `lines`' torques, speeds and harmonics: mu = the fixed coefficient, or with "iso13989"
    housingfe.source.mesh_friction.iso13989_run_friction at each line's torque and speed; the amplitude of
    resultant r is harmonic n of SourceModel.friction_curve(torque, mu) / sqrt(2) (the load distributions of the
    source's stiffness curve, S(t)'s time origin: coherent with the mesh excitation and the shuttling moment).
    First order, like the shuttling moment: friction does not enter the source's harmonic balance."""
    from housingfe.source.mesh_friction import iso13989_run_friction

    mesh_friction = check_mesh_friction(mesh_friction)
    out = {name: np.zeros(len(lines.frequency), complex) for name in FRICTION_LOADS.values()}
    mu_line = np.zeros(len(lines.frequency))
    H = int(lines.harmonic.max()) if lines.harmonic.size else 1
    reference = {}          # per torque: (mu, {resultant: harmonics}) of its first point; linear in mu
    for torque, speed, *_ in lines.points:
        at = (lines.torque == torque) & (lines.speed == speed)
        mu = (iso13989_run_friction(source.pair, torque, speed) if mesh_friction == "iso13989"
              else float(mesh_friction))
        if torque not in reference:
            curve = source.friction_curve(torque, mu)
            reference[torque] = (mu, {r: curve.harmonics(r, H) for r in FRICTION_LOADS})
        mu_ref, harmonics = reference[torque]
        n = lines.harmonic[at]
        for resultant, name in FRICTION_LOADS.items():
            out[name][at] = harmonics[resultant][n - 1] * (mu / mu_ref) / math.sqrt(2.0)
        mu_line[at] = mu
    return out, mu_line


@single_thread
def source_lines(source, speeds_rpm, torques_nm, f_lines_max: float,
                 mesh_moment: str = DEFAULT_MESH_MOMENT, mesh_friction=DEFAULT_MESH_FRICTION) -> tuple[Lines, float]:
    """The source's lines up to f_lines_max (Hz) at every speed (rev/min) and torque (N m); also the time (s).
    mesh_moment (MESH_MOMENTS): "shuttling" adds the shuttling moment per line (Lines.shuttle_moment,
    `shuttle_moments`) for the mesh_force route; mesh_friction (`check_mesh_friction`): other than "none" adds the
    sliding friction per line (Lines.friction, `friction_lines`); the rigid-bore source's own L_omega contains
    neither."""
    _check_mesh_moment(mesh_moment)
    mesh_friction = check_mesh_friction(mesh_friction)
    t0 = time.perf_counter()
    cols = {k: [] for k in ("torque", "speed", "harmonic", "frequency", "L_omega", "mesh_excitation", "point")}
    points = []
    for torque in torques_nm:
        k_m = float(np.mean(source.mesh_stiffness(float(torque))[0]))
        for speed in speeds_rpm:
            exc = source.operating_point(float(speed), float(torque))
            keep = exc.frequency_hz <= f_lines_max * (1 + 1e-12)
            n = int(keep.sum())
            cols["torque"] += [float(torque)] * n
            cols["speed"] += [float(speed)] * n
            cols["harmonic"] += list(exc.harmonic[keep])
            cols["frequency"] += list(exc.frequency_hz[keep])
            cols["L_omega"] += list(exc.L_omega[keep])
            cols["mesh_excitation"] += list((exc.mesh_force[keep] - k_m * exc.transmission_error[keep])
                                            / math.sqrt(2.0))
            cols["point"] += [len(points)] * n
            points.append((float(torque), float(speed), float(exc.tooth_frequency_hz),
                           float(exc.L_omega_tooth_band), k_m))
    lines = Lines(*(np.array(cols[k], dtype=complex if k == "mesh_excitation" else float)
                    for k in ("torque", "speed", "harmonic", "frequency", "L_omega", "mesh_excitation", "point")),
                  points)
    lines.harmonic = lines.harmonic.astype(int)
    lines.point = lines.point.astype(int)
    if mesh_moment == "shuttling":
        moment = np.zeros(len(lines.frequency), complex)
        for torque in torques_nm:
            at = lines.torque == float(torque)
            moment[at] = shuttle_moments(source, float(torque), lines.harmonic[at])
        lines.shuttle_moment = moment
    if mesh_friction != "none":
        lines.friction, lines.friction_mu = friction_lines(source, lines, mesh_friction)
    return lines, time.perf_counter() - t0


# ------------------------------------------------------------------------------------------ source on the housing
# the receptance around the mesh in the source's harmonic balance (scene key runup.source_receptance): the coupled
# gearbox (housing, bearings, shafts, gear bodies; the Ritz reduction) or the lumped interior on rigid bores (Ch. 2)
SOURCE_RECEPTANCES = ("coupled", "rigid-bores")
DEFAULT_SOURCE_RECEPTANCE = "coupled"


def mesh_reference_stiffness(model: GearboxModel) -> float:
    """The mean mesh stiffness k_ref (N/m) that the coupled model's gear-mesh element holds, per unit of the "mesh"
    unit load's own compression (the normal force and approach, as S(t) of the source): the element's stiffness along
    its unit direction divided by GearForces.resultant^2 (1; cos^2(beta_b) for a double helical set, whose element
    holds S cos^2(beta_b) along the transverse line of action and whose unit load is the resultant cos(beta_b) l of a
    unit normal force: the element's energy k_t delta_t^2 / 2 with delta_t = delta_n / cos(beta_b) is S delta_n^2 / 2)."""
    meshes = model.structure.spec.gear_meshes
    if len(meshes) != 1:
        raise InputError(f"source_receptance: the coupled source needs one gear mesh, the model has {len(meshes)}")
    return float(meshes[0].stiffness) / model.drivetrain.gear_forces().resultant ** 2


def mesh_receptance(model: GearboxModel, frequencies_hz) -> np.ndarray:
    """g(f) = h^T H(f) h (m/N) of the coupled model (holding its mean mesh stiffness) at the gear mesh: the mesh
    compression per unit compressive mesh-force pair, from the Ritz reduction (the modal basis with its static
    correction; the reduction's damping), batched over the frequencies (Hz, > 0).  At f = 0 the value is
    1 / k_ref exactly without a drive line (`coupled_source_lines`): the gears turn freely apart from the mesh, so
    only the mesh spring resists a static mesh compression; with the drive line (runup.drive_line) the quill shafts
    resist it too (`static_mesh_receptance`)."""
    red = model.reduction
    j = red.names.index("mesh")
    # the reduction remembers the solve: a re-run with another engagement shock reuses it (engagement_rerun)
    return red.system.Fr[:, j] @ red.unit_coordinates(frequencies_hz, "mesh")


# g(0) of a model with a drive line: the Ritz solve at this frequency (Hz).  The reduction holds the static
# vector of the mesh load, so this is the static receptance to (f / f_rig)^2 ~ 1e-10 (rig mode ~76 Hz), and a free
# housing's rigid modes, on which the self-equilibrated mesh pair does no work, stay out of it
STATIC_RECEPTANCE_HZ = 1e-3


def static_mesh_receptance(model: GearboxModel) -> float:
    """g(0) (m/N): the coupled model's static mesh compression per unit compressive mesh-force pair.  Without a
    drive line exactly 1 / k_ref (the gears turn freely apart from the mesh); with one (the quill shafts to motor
    and brake, housingfe.drivetrain.interior.DriveLineSpec) less: a static mesh-force pair also twists the loop
    through the quills, as the lumped source's g(0) does (dynamics.lumped_receptance)."""
    k_ref = mesh_reference_stiffness(model)
    if not model.structure.spec.drive_lines:
        return 1.0 / k_ref
    return float(np.real(mesh_receptance(model, [STATIC_RECEPTANCE_HZ])[0]))


@single_thread
def coupled_source_lines(model: GearboxModel, source, speeds_rpm, torques_nm, f_lines_max: float, *,
                         first_order: bool = False, harmonics: int | None = None,
                         mesh_moment: str = DEFAULT_MESH_MOMENT,
                         mesh_friction=DEFAULT_MESH_FRICTION) -> tuple[Lines, float]:
    """The source's lines (`source_lines`, the rigid-bore source's L_omega kept for the tf_omega route) with the
    mesh excitation from the harmonic balance of the time-varying mesh solved on the coupled gearbox instead of the
    rigid-bore lumped interior (housingfe.source.roosmalen.dynamics.mesh_harmonic_balance
    with the coupled model's mesh receptance, `mesh_receptance`): S(t) and F_e(t) of `source` at each torque, the
    coupled model's mean mesh stiffness k_ref, its static state (the transmitted normal force F: b_0 = F / k_ref, the
    mesh carries F whatever else the torque loop holds; g(0) = `static_mesh_receptance`, 1 / k_ref without a drive
    line).  mesh_excitation is W_n - k_ref d_n (what the mesh_force route applies); L_omega_flexible is
    the wheel's level on the coupled model (what the mesh_force route's L_omega_coupled then is, too).  model: the
    GearboxModel at the torque (one torque per model: another torque changes the bearings, `with_drivetrain`).  first_order: the mean-stiffness solve (quasi-static transmission
    error on the mean system).  harmonics: H of the balance (default: the source's).  mesh_moment (MESH_MOMENTS):
    "shuttling" applies the shuttling moment (`shuttle_moments`) with the mesh excitation, in L_omega_flexible too;
    mesh_friction (`check_mesh_friction`) the sliding friction likewise (`friction_lines`; the model must hold the
    friction loads, `build_gearbox_model(friction=True)`).  Returns (Lines, seconds)."""
    from housingfe.source.roosmalen.dynamics import mesh_harmonic_balance
    from housingfe.source.stiffness import normal_force_from_torque

    t0 = time.perf_counter()
    H = int(harmonics or source.harmonics)
    k_ref = mesh_reference_stiffness(model)
    g0 = {float(v): static_mesh_receptance(model.at_speed(v)) for v in speeds_rpm}
    rigid, _ = source_lines(source, speeds_rpm, torques_nm, f_lines_max, mesh_moment, mesh_friction)
    cols = {k: [] for k in ("frequency", "mesh_excitation")}
    for torque in torques_nm:
        S, shock = source.mesh_stiffness(float(torque))
        F = normal_force_from_torque(source.pair, float(torque))
        f_t = np.array([source.pair.tooth_frequency(float(v)) for v in speeds_rpm])
        nn = np.arange(1, H + 1)
        if model.speed_models:          # each speed on its own bearings (follow_speeds)
            g = np.array([mesh_receptance(model.at_speed(v), f_t[i] * nn) for i, v in enumerate(speeds_rpm)])
        else:
            g = mesh_receptance(model, (f_t[:, None] * nn[None, :]).ravel()).reshape(len(f_t), H)
        for i in range(len(f_t)):
            rec = np.concatenate([[g0[float(speeds_rpm[i])]], g[i]])
            st = mesh_harmonic_balance(rec, F / k_ref, S, shock, k_ref, f_t[i], first_order=first_order)
            f, exc = st.one_sided(st.excitation)
            keep = f <= f_lines_max * (1 + 1e-12)
            cols["frequency"] += list(f[keep])
            cols["mesh_excitation"] += list(exc[keep] / math.sqrt(2.0))
    freq = np.array(cols["frequency"], float)
    if freq.shape != rigid.frequency.shape or not np.allclose(freq, rigid.frequency, rtol=1e-12):
        raise InputError("source_receptance: the coupled and the rigid-bore source have different lines")
    mesh_exc = np.array(cols["mesh_excitation"], complex)
    # the wheel's rotation from its kept node values alone (the surface quantities are the routes' business)
    lines = replace(rigid, mesh_excitation=mesh_exc, receptance="coupled")
    c = line_coefficients(model, freq, lines.speed, lines.mesh_amplitudes())
    node = model.reduction.reduced.points[node_key(model.wheel_node)]
    rot = (model.wheel_axis / np.linalg.norm(model.wheel_axis)) @ (node[3:6] @ c)
    lines.L_omega_flexible = levels.level(np.abs(2 * math.pi * freq * rot) ** 2, levels.OMEGA0)
    return lines, time.perf_counter() - t0


def run_source(model: GearboxModel, source, speeds_rpm, torques_nm, f_lines_max: float,
               receptance: str = DEFAULT_SOURCE_RECEPTANCE, mesh_moment: str = DEFAULT_MESH_MOMENT,
               mesh_friction=DEFAULT_MESH_FRICTION) -> tuple[Lines, float]:
    """The source's lines with the receptance of `receptance` (SOURCE_RECEPTANCES): `coupled_source_lines` or
    `source_lines` (the rigid-bore lumped source); mesh_moment (MESH_MOMENTS) and mesh_friction
    (`check_mesh_friction`) applied with the mesh excitation."""
    if check_mesh_friction(mesh_friction) != "none" and not has_friction_loads(model):
        raise InputError("mesh_friction: the gearbox model has no friction unit loads (build it with friction=True)")
    if receptance == "coupled":
        return coupled_source_lines(model, source, speeds_rpm, torques_nm, f_lines_max, mesh_moment=mesh_moment,
                                    mesh_friction=mesh_friction)
    if receptance == "rigid-bores":
        return source_lines(source, speeds_rpm, torques_nm, f_lines_max, mesh_moment, mesh_friction)
    raise InputError(f"source_receptance: {receptance!r} is not one of {', '.join(SOURCE_RECEPTANCES)}")


def engagement_rerun(models: dict, source, engagement: str, speeds_rpm, f_lines_max: float,
                     receptance: str = DEFAULT_SOURCE_RECEPTANCE, routes=("tf_omega", "mesh_force"),
                     mesh_moment: str = DEFAULT_MESH_MOMENT,
                     mesh_friction=DEFAULT_MESH_FRICTION) -> tuple[dict, float]:
    """The run-up once more with another engagement shock (housingfe.source.roosmalen.dynamics.ENGAGEMENT_MODELS) on
    the SAME coupled models {torque N m: GearboxModel} (no new mesh, basis or reduction): the source's operating
    points keep their stiffness curves, load shares and matrices (SourceModel.with_engagement), so this costs the
    source's harmonic balances and the routes' reduced solves.  Returns ({torque: RunupResult}, seconds)."""
    t0 = time.perf_counter()
    other = source.with_engagement(engagement)
    out = {}
    for torque, model in models.items():
        lines, _ = run_source(model, other, speeds_rpm, [float(torque)], f_lines_max, receptance, mesh_moment,
                              mesh_friction)
        out[torque] = runup(model, None, speeds_rpm, [float(torque)], routes=tuple(routes), lines=lines)
    return out, time.perf_counter() - t0


def te_sensitivity(models: dict, source, harmonics, speeds_rpm, f_lines_max: float,
                   receptance: str = DEFAULT_SOURCE_RECEPTANCE, routes=("tf_omega", "mesh_force")) -> tuple[dict, float]:
    """The run-up per micrometre of transmission error: on the SAME coupled models {torque N m: GearboxModel}, the
    source driven by 1 um of quasi-static TE at one tooth harmonic n alone (a one-line
    housingfe.source.transmission_error.TransmissionError on the model's S(t)), for each n of `harmonics`, without
    the mesh moment and the friction (they do not scale with the TE).  The chain is linear in the TE, so a TE of
    a um at harmonic n gives the line's levels + 20 lg(a); what the gearbox makes of a TE (source dynamics, path,
    housing, radiation), apart from the TE itself: the designer's TE target, and the source/transfer split of a
    measured level.  Returns ({torque: {n: RunupResult}}, seconds)."""
    from housingfe.source.transmission_error import TransmissionError

    t0 = time.perf_counter()
    out = {}
    for torque, model in models.items():
        out[torque] = {}
        for n in harmonics:
            unit = TransmissionError(np.array([float(torque)]), np.array([int(n)]), np.array([[1e-6 + 0j]]),
                                     source=f"1 um at harmonic {int(n)}")
            lines, _ = run_source(model, source.with_transmission_error(unit), speeds_rpm, [float(torque)],
                                  f_lines_max, receptance, "none", "none")
            out[torque][int(n)] = runup(model, None, speeds_rpm, [float(torque)], routes=tuple(routes), lines=lines)
    return out, time.perf_counter() - t0


# ------------------------------------------------------------------------------------------------ routes
@dataclass
class RouteResult:
    """One route on every line: L_v (dB re 5e-8 m/s) per line, the response (LoadResponse, for the numerical
    radiator), the Ritz coordinates (vectors, lines), L_omega of the wheel on the coupled model per line (dB re
    5e-8 rad/s), TF_omega per line (dB) where the route has it; the route's excitation level per line (dB) and
    what it and the transfer L_v - excitation are (names with units; housingfe.runup.slopes splits the speed law
    into these terms)."""

    name: str
    L_v: np.ndarray
    response: object
    coefficients: np.ndarray
    L_omega_coupled: np.ndarray
    tf_omega: np.ndarray | None = None
    excitation_db: np.ndarray | None = None
    excitation_name: str = ""
    transfer_name: str = ""
    # the loads the bearings put on the bore masters per line (`route_bore_loads`, set by `runup`): complex rms
    # (lines, bearings, 6) of `coefficients` (N, N m); and their force / moment levels scaled as L_v is (dB re 1 N,
    # 1 N m: tf_omega's coefficients are the response to 1 N m, its L_v scaled to the source's L_omega), which split
    # the transfer into the path (mesh -> bores) and the housing (bores -> surface), housingfe.runup.slopes
    bore_loads: np.ndarray | None = None
    bore_force_db: np.ndarray | None = None
    bore_moment_db: np.ndarray | None = None


def route_bore_loads(model: GearboxModel, frequency, speed, coefficients, elements: dict | None = None) -> np.ndarray:
    """The loads the bearings put on their bore masters at a route's Ritz solutions (RouteResult.coefficients,
    (vectors, lines)) at the lines' frequencies (Hz) and pinion speeds (rev/min): complex (lines, bearings, 6) in
    the coefficients' convention (rms), Fx Fy Fz (N), Mx My Mz (N m) about the master, bearings in the order of
    structure.parts.bearings (those to ground left out); housingfe.drivetrain.bore_loads.bore_loads per line, on the
    bearings of the line's speed model (GearboxModel.at_speed: the films following the run-up's speed).
    elements: {speed model id: BearingElement list} to reuse between routes (filled here)."""
    f = np.asarray(frequency, float)
    c = np.asarray(coefficients)
    memo = {} if elements is None else elements
    rows = memo.get("rows")
    if rows is None:        # the Ritz vectors' rows at the bearings' nodes: the same for every speed model
        rows = memo["rows"] = structure_bearing_elements(model.structure, model.reduction.vectors)

    def elements_at(m):
        if id(m) not in memo:
            memo[id(m)] = [replace(r, K=np.asarray(e.K, float), C=(np.zeros((12, 12)) if e.C is None
                                                                    else np.asarray(e.C, float)))
                           for r, e in zip(rows, [e for e in m.structure.parts.bearings
                                                   if len(e.nodes) == 2 and None not in e.nodes])]
        return memo[id(m)]

    if not model.speed_models:
        return bore_loads(elements_at(model), f, c)
    speed = np.broadcast_to(np.asarray(speed, float), f.shape)
    out = np.zeros((len(f), len(rows), 6), complex)
    for s in np.unique(speed):
        at = np.flatnonzero(speed == s)
        out[at] = bore_loads(elements_at(model.at_speed(s)), f[at], c[:, at])
    return out


def _wheel_omega_level(model: GearboxModel, response, frequency) -> np.ndarray:
    rot = model.reduction.node_rotation(response, model.wheel_node, model.wheel_axis)
    return levels.level(np.abs(2 * math.pi * np.asarray(frequency) * rot) ** 2, levels.OMEGA0)


@register_route("tf_omega")
def tf_omega_route(model: GearboxModel, lines: Lines) -> RouteResult:
    """Eq. 5.5: L_v = L_omega (source) + TF_omega, TF_omega = L_v - L_omega of the coupled model under 1 N m at the
    wheel centre, at every line."""
    f = lines.frequency
    c = line_coefficients(model, f, lines.speed, {"wheel_torque": 1.0})
    resp = model.reduction.response_of(f, c)
    tf = resp.velocity_level_db - _wheel_omega_level(model, resp, f)
    # the wheel's L_omega on this route is the source's (the route's input): no coupled value of its own
    return RouteResult("tf_omega", lines.L_omega + tf, resp, c, np.full(len(f), np.nan), tf, lines.L_omega,
                       "L_omega of the source (dB re 5e-8 rad/s)", "TF_omega = L_v - L_omega (dB)")


@register_route("mesh_force")
def mesh_force_route(model: GearboxModel, lines: Lines) -> RouteResult:
    """The mesh excitation F_n - k_m d_n (complex rms, N) on the coupled model's gear mesh, at every line, with the
    shuttling moment (Lines.shuttle_moment, N m) and the sliding friction (Lines.friction) where they are on.  The
    excitation level stays L_F of the force: with the moment or friction on, the transfer L_v - L_F holds their
    share (the names say so)."""
    f = lines.frequency
    c = line_coefficients(model, f, lines.speed, lines.mesh_amplitudes())
    resp = model.reduction.response_of(f, c)
    L_F = levels.level(np.abs(lines.mesh_excitation) ** 2, levels.F0)
    extra = " and ".join(what for what, on in (("the shuttling moment", lines.shuttle_moment is not None),
                                                ("the sliding friction", lines.friction is not None)) if on)
    if not extra:
        names = ("L_F, mesh excitation F_n - k_m d_n (dB re 1 N)", "L_v - L_F (dB re 5e-8 m/s per N)")
    else:
        verb = "are" if " and " in extra else "is"
        names = (f"L_F, mesh excitation F_n - k_m d_n (dB re 1 N; {extra} applied with it {verb} not in "
                 "this level)", f"L_v - L_F (dB re 5e-8 m/s per N; includes the response to {extra})")
    return RouteResult("mesh_force", resp.velocity_level_db, resp, c, _wheel_omega_level(model, resp, f),
                       excitation_db=L_F, excitation_name=names[0], transfer_name=names[1])


# ------------------------------------------------------------------------------------------------ run-up
@dataclass
class RunupResult:
    """A run-up: lines (Lines), per route its RouteResult, per (route, radiator) L_sigma and L_W per line (dB),
    totals per operating point (`totals`, a list of row dicts), the model facts and timings (s)."""

    lines: Lines
    routes: dict
    L_sigma: dict
    L_W: dict
    area_level_db: float
    radiators: list
    totals: list
    timings: dict

    def harmonic_rows(self) -> list[dict]:
        """One row per route, radiator and line (runup_harmonics.csv; with incoherent lines, Lines.incoherent, a
        "line" of "periodic" or "sideband")."""
        rows = []
        ln = self.lines
        a_w = levels.a_weighting_db(ln.frequency)
        for route, rr in self.routes.items():
            for rad in self.radiators:
                Lw = self.L_W[route, rad]
                for k in range(len(ln.frequency)):
                    rows.append({"route": route, "radiation": rad, "torque_nm": ln.torque[k],
                                 "speed_rpm": ln.speed[k], "harmonic": int(ln.harmonic[k]),
                                 "frequency_hz": ln.frequency[k], "L_omega_dB": ln.L_omega[k],
                                 "TF_omega_dB": rr.tf_omega[k] if rr.tf_omega is not None else float("nan"),
                                 "L_omega_coupled_dB": rr.L_omega_coupled[k], "Lv_dB": rr.L_v[k],
                                 "L_sigma_dB": self.L_sigma[route, rad][k], "Lw_dB": Lw[k],
                                 "LwA_dB": Lw[k] + a_w[k]})
                    if ln.incoherent is not None:
                        rows[-1]["line"] = "sideband" if ln.incoherent[k] else "periodic"
        return rows

    def series(self, route: str, radiation: str, torque: float, key: str) -> tuple[np.ndarray, np.ndarray]:
        """(speeds rev/min, values) of a total (`key` of a totals row) over speed at one torque."""
        rows = [r for r in self.totals if r["route"] == route and r["radiation"] == radiation
                and r["torque_nm"] == torque]
        return np.array([r["speed_rpm"] for r in rows]), np.array([r[key] for r in rows])


def _energy_sum(values_db: np.ndarray, groups: np.ndarray, n_groups: int) -> np.ndarray:
    power = np.zeros(n_groups)
    np.add.at(power, groups, 10.0 ** (np.asarray(values_db) / 10.0))
    with np.errstate(divide="ignore"):
        return 10.0 * np.log10(power)


def runup(model: GearboxModel, source, speeds_rpm, torques_nm, *, routes=("tf_omega", "mesh_force"),
          lines: Lines | None = None) -> RunupResult:
    """L_v, L_W and L_WA per tooth harmonic and in total at every speed (rev/min) and torque (N m) for every route
    (ROUTES) and radiator of the model.  source: housingfe.source.roosmalen.operating.SourceModel (or `lines` computed
    before, e.g. to reuse them across gear-set models)."""
    unknown = [r for r in routes if r not in ROUTES]
    if unknown:
        raise InputError(f"runup.routes: {', '.join(unknown)} unknown (known: {', '.join(ROUTES)})")
    timings = {}
    if lines is None:
        lines, timings["source_s"] = source_lines(source, speeds_rpm, torques_nm, model.f_lines_max)
    t0 = time.perf_counter()
    results = {name: ROUTES[name](model, lines) for name in routes}
    timings["response_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    elements = {}
    for rr in results.values():     # the bearings' loads on the bores, scaled as the route's L_v is
        rr.bore_loads = route_bore_loads(model, lines.frequency, lines.speed, rr.coefficients, elements)
        shift = rr.L_v - rr.response.velocity_level_db
        rr.bore_force_db = force_level_db(rr.bore_loads) + shift
        rr.bore_moment_db = moment_level_db(rr.bore_loads) + shift
    timings["bore_loads_s"] = time.perf_counter() - t0
    L_S = area_level_db(model.area)
    f = lines.frequency
    a_w = levels.a_weighting_db(f)
    L_sigma, L_W = {}, {}
    t0 = time.perf_counter()
    for name, rr in results.items():
        for rad_name, radiator in model.radiators.items():
            t1 = time.perf_counter()
            L_sigma[name, rad_name] = np.asarray(radiator.radiation_index_db(rr.response), float)
            L_W[name, rad_name] = rr.L_v + L_S + L_sigma[name, rad_name]
            timings[f"radiation_{rad_name}_s"] = timings.get(f"radiation_{rad_name}_s", 0.0) + time.perf_counter() - t1
    timings["radiation_s"] = time.perf_counter() - t0
    n_points = len(lines.points)
    totals = []
    for name, rr in results.items():
        Lv_tot = _energy_sum(rr.L_v, lines.point, n_points)
        Lw_c = _energy_sum(rr.L_omega_coupled, lines.point, n_points)
        first = {p: k for k, p in reversed(list(enumerate(lines.point)))}
        for rad_name in model.radiators:
            Lw_tot = _energy_sum(L_W[name, rad_name], lines.point, n_points)
            LwA_tot = _energy_sum(L_W[name, rad_name] + a_w, lines.point, n_points)
            for p, (torque, speed, f_t, L_om, k_m) in enumerate(lines.points):
                totals.append({"route": name, "radiation": rad_name, "torque_nm": torque, "speed_rpm": speed,
                               "tooth_frequency_hz": f_t, "L_omega_dB": L_om,
                               "L_omega_coupled_dB": float(rr.L_omega_coupled[first[p]]),
                               "L_omega_coupled_all_dB": float(Lw_c[p]),
                               "Lv_tooth_dB": float(rr.L_v[first[p]]), "Lv_dB": float(Lv_tot[p]),
                               "Lw_dB": float(Lw_tot[p]), "LwA_dB": float(LwA_tot[p]),
                               "harmonics": int(np.sum(lines.point == p))})
    return RunupResult(lines, results, L_sigma, L_W, L_S, list(model.radiators), totals, timings)


def peak_contributions(model: GearboxModel, result: RunupResult, route: str, point: int, top: int = 3) -> dict:
    """Which modes make operating point `point` (index into lines.points) on a route: the harmonic whose line
    carries the most A-weighted power (first radiator), and the modes with the largest shares of <v^2> on that
    line: {"harmonic", "frequency_hz", "share_of_LwA", "modes": [(frequency Hz, share of <v^2>, interior energy
    share of the nearest basis mode)]}.  Shares sum to 1 over all modes; a share above 1 is partly cancelled by
    modes of negative share (out of phase).  With incoherent lines (Lines.incoherent: gears as made folded into the
    totals) the harmonic is the one whose 1/3-octave band carries the most A-weighted power, its modes' shares the
    <v^2>-weighted mean over the band's lines, and "lines" their number (`_band_contributions`)."""
    ln = result.lines
    idx = np.flatnonzero(ln.point == point)
    rad = result.radiators[0]
    lwa = result.L_W[route, rad][idx] + levels.a_weighting_db(ln.frequency[idx])
    power = 10.0 ** (lwa / 10.0)
    if ln.incoherent is not None:       # gears as made: the harmonic's 1/3-octave band, its lines energy-summed
        return _band_contributions(model, result, route, idx, power, top)
    k = int(idx[np.argmax(lwa)])
    # the modes of the model at the point's speed (bearings following the run-up's speed: GearboxModel.at_speed)
    freqs, share = model.at_speed(ln.speed[k]).reduction.modal_contributions(
        ln.frequency[k], result.routes[route].coefficients[:, k])
    n = model.basis.rigid_count
    elastic = model.basis.frequencies_hz[n:]
    order = np.argsort(-share)[:top]
    modes = []
    for i in order:
        j = int(np.argmin(np.abs(elastic - freqs[i]))) if len(elastic) else 0
        modes.append((float(freqs[i]), float(share[i]),
                      float(model.interior_share[j]) if len(elastic) else float("nan")))
    return {"harmonic": int(ln.harmonic[k]), "frequency_hz": float(ln.frequency[k]),
            "share_of_LwA": float(power.max() / power.sum()), "modes": modes}


def _band_contributions(model: GearboxModel, result: RunupResult, route: str, idx: np.ndarray, power: np.ndarray,
                        top: int) -> dict:
    """peak_contributions of an operating point whose lines include incoherent ones (Lines.incoherent): the
    harmonic n whose lines (the periodic line n f_tooth and the sidebands in its 1/3-octave band) carry the most
    A-weighted power together, "frequency_hz" its strongest line, and each mode's share of the band's <v^2>: the
    lines' shares weighted by their <v^2> (incoherent lines: mean squares add)."""
    ln = result.lines
    h = ln.harmonic[idx]
    harmonics, group = np.unique(h, return_inverse=True)
    band_power = np.bincount(group, weights=power)
    g = int(np.argmax(band_power))
    members = idx[group == g]
    v2 = 10.0 ** (result.routes[route].L_v[members] / 10.0)
    share = None
    for k, w in zip(members, v2):
        freqs, s = model.at_speed(ln.speed[k]).reduction.modal_contributions(
            ln.frequency[k], result.routes[route].coefficients[:, k])
        share = w * s if share is None else share + w * s
    share = share / v2.sum() if v2.sum() > 0 else share
    strongest = int(members[np.argmax(power[group == g])])
    n = model.basis.rigid_count
    elastic = model.basis.frequencies_hz[n:]
    modes = []
    for i in np.argsort(-share)[:top]:
        j = int(np.argmin(np.abs(elastic - freqs[i]))) if len(elastic) else 0
        modes.append((float(freqs[i]), float(share[i]),
                      float(model.interior_share[j]) if len(elastic) else float("nan")))
    return {"harmonic": int(harmonics[g]), "frequency_hz": float(ln.frequency[strongest]),
            "share_of_LwA": float(band_power[g] / power.sum()), "modes": modes, "lines": int(members.size)}
