"""Model updating: a bounded least-squares fit (scipy.optimize.least_squares, trust-region reflective) of
chosen scene parameters to measured or published modal data.

Every evaluation builds the models through the scene API (housingfe.scene.load_housing_scene with the
parameters as --set overrides, build_model_from_scene) and solves their modes (housingfe.solvers.modal.modes).
Residuals are relative and divided by the target's sigma (a relative standard deviation), so the cost is a
chi-square and the parameter covariance is (J^T J)^-1 of the scaled Jacobian.

Targets (kind):
  mass       the housing's mass (kg) from the rigid-body translation of a free scene: t^T M t
  frequency  the n-th elastic mode (Hz)
  count      the number of elastic modes below band_hz, as a smooth surrogate: ln(sqrt(f_N f_N+1) / band) is
             zero when the band edge lies midway (geometrically) between mode N and N+1; a count is an
             integer and would give a zero gradient
  close_pair two adjacent modes (Hz): the adjacent pair nearest to the published one; residual = the larger
             relative error of the two
  paired     measured modes (UFF/CSV): each measured mode paired with a computed one by MAC on the measured
             channels (pair_modes); residual = frequency error (+ (1 - MAC) / sigma_mac if use_mac)
Roles: "calibration" targets drive the fit, "holdout" targets are only evaluated before and after it.
"""
from __future__ import annotations

import contextlib
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Literal, Optional

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, PositiveFloat, model_validator

from housingfe.errors import InputError, SolverError
from housingfe.scenefile import FolderName


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class ParameterSpec(_Strict):
    """A fitted parameter: the dotted scene keys it sets (the same value in every scene that has the key),
    bounds and start in the keys' units (SI)."""

    name: str = Field(min_length=1)
    keys: list[str] = Field(min_length=1)
    lower: float
    upper: float
    start: float

    @model_validator(mode="after")
    def _check(self):
        if not self.lower < self.upper:
            raise ValueError("lower: must be below upper")
        if not self.lower <= self.start <= self.upper:
            raise ValueError("start: must lie within [lower, upper]")
        return self


class TargetSpec(_Strict):
    """One published or measured quantity (see the module docstring for the kinds)."""

    name: str = Field(min_length=1)
    scene: str = Field(min_length=1)
    kind: Literal["mass", "frequency", "count", "close_pair", "paired"]
    value: Optional[float | list[float]] = None
    sigma: PositiveFloat = 0.02            # relative standard deviation of the value
    role: Literal["calibration", "holdout"] = "calibration"
    mode: Optional[int] = Field(None, ge=1)           # frequency: 1 = first elastic mode
    band_hz: Optional[PositiveFloat] = None           # count
    measured: Optional[str] = None                    # paired: UFF or CSV file
    # paired: the unit of the measured coordinates where the file has no units dataset (UFF 164)
    units: Optional[Literal["m", "mm", "cm", "in"]] = None
    threshold: float = Field(0.6, ge=0.0, le=1.0)     # paired: MAC threshold
    use_mac: bool = False                             # paired: add (1 - MAC) / sigma_mac residuals
    sigma_mac: PositiveFloat = 0.1
    # paired: add (zeta_model / zeta_measured - 1) / sigma_damping for every paired mode with a measured modal
    # damping ratio (UFF 55); zeta_model from the scene's [damping] (eta / 2, xi, or the modal strain energy of
    # per-material loss factors), so damping keys can be fitted
    use_damping: bool = False
    sigma_damping: PositiveFloat = 0.2

    @model_validator(mode="after")
    def _check(self):
        need = {"mass": ["value"], "frequency": ["value", "mode"], "count": ["value", "band_hz"],
                "close_pair": ["value"], "paired": ["measured"]}[self.kind]
        for key in need:
            if getattr(self, key) is None:
                raise ValueError(f"{key}: required for a {self.kind} target")
        if self.kind == "close_pair" and not (isinstance(self.value, list) and len(self.value) == 2):
            raise ValueError("value: a close_pair target gives two frequencies [f1, f2] (Hz)")
        if self.kind in ("mass", "frequency", "count") and isinstance(self.value, list):
            raise ValueError(f"value: one number for a {self.kind} target")
        if self.kind in ("mass", "frequency") and not self.value > 0:
            raise ValueError(f"value: a {self.kind} must be positive")
        if self.kind == "count" and not (self.value >= 1 and float(self.value).is_integer()):
            raise ValueError("value: a mode count is a whole number >= 1")
        return self


class UpdateSpec(_Strict):
    """An updating problem: parameters, targets, overrides used during the search (e.g. a coarse mesh) and
    in the confirmation (default: none, the scenes' own mesh)."""

    name: FolderName = "update"     # the default result folder is results/update-<name>: a plain folder name
    parameters: list[ParameterSpec] = Field(min_length=1)
    targets: list[TargetSpec] = Field(min_length=1)
    # scene -> overrides of every evaluation (search and confirmation), before the parameters: a parameter may set a
    # key these introduce, e.g. ["regions.rim.name=steel", "regions.rim.youngs_modulus=2.1e11"] lets the rim's
    # modulus be a parameter
    scene_overrides: dict[str, list[str]] = {}
    search_overrides: dict[str, list[str]] = {}    # scene -> overrides during the search
    confirm_overrides: dict[str, list[str]] = {}   # scene -> overrides of the confirmation run
    mesh_correction: bool = True    # scale the search predictions by (confirm / search) at the start point
    multistart: list[dict[str, float]] = []        # further start points (parameter name -> value)
    max_evaluations: int = Field(60, ge=1)
    fd_step: PositiveFloat = 0.02   # forward-difference step, fraction of each parameter's range

    @model_validator(mode="after")
    def _check(self):
        # checked here, on reading the spec: the fit found them only after its first solves, or never
        for what, items in (("parameters", self.parameters), ("targets", self.targets)):
            seen = set()
            for i, item in enumerate(items):
                if item.name in seen:
                    raise ValueError(f"{what}.{i}.name: {item.name!r} is used twice (the names identify "
                                     f"the {what} in the results)")
                seen.add(item.name)
        bounds = {p.name: (p.lower, p.upper) for p in self.parameters}
        for k, start in enumerate(self.multistart):
            for name, value in start.items():
                if name not in bounds:
                    raise ValueError(f"multistart.{k}.{name}: not a parameter name ({', '.join(bounds)})")
                lower, upper = bounds[name]
                if not lower <= value <= upper:
                    raise ValueError(f"multistart.{k}.{name}: {value:g} must lie within [lower, upper] = "
                                     f"[{lower:g}, {upper:g}]")
        scenes = {t.scene for t in self.targets}
        for what in ("scene_overrides", "search_overrides", "confirm_overrides"):
            for scene in getattr(self, what):
                if scene not in scenes:
                    # a misspelt scene's overrides were silently never applied (e.g. the coarse search mesh)
                    raise ValueError(f"{what}.{scene}: no target uses this scene (targets' scenes: "
                                     f"{', '.join(sorted(scenes))})")
        return self


def load_update_spec(path: str) -> UpdateSpec:
    """Read an updating spec (TOML); InputError naming the file and key."""
    import tomllib

    from housingfe.scenefile import parse_table

    p = Path(path)
    if not p.is_file():
        raise InputError(f"{path}: update spec not found")
    try:
        with open(p, "rb") as fh:
            data = tomllib.load(fh)
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: malformed TOML: {exc}") from None
    spec = parse_table(UpdateSpec, data, path)
    return resolve_measured_paths(spec, p.parent)


def resolve_measured_paths(spec: UpdateSpec, base) -> UpdateSpec:
    """Measured files relative to the spec's folder."""
    targets = []
    for t in spec.targets:
        if t.measured is not None and not Path(t.measured).is_absolute():
            t = t.model_copy(update={"measured": str(Path(base) / t.measured)})
        targets.append(t)
    return spec.model_copy(update={"targets": targets})


# ------------------------------------------------------------------------------------------ evaluation
@dataclass
class SceneResult:
    """Modes of one scene at one parameter set: elastic frequencies (Hz), rigid-body mode count, mass (kg, free
    scenes), the elastic modes sampled on each paired target's measured channels (target name -> ModeSet),
    the viscous damping ratio of each elastic mode that the scene's [damping] gives (-).
    The FE model and basis are not kept: a search makes hundreds of them."""

    frequencies_hz: np.ndarray
    rigid_count: int
    mass_kg: float | None
    sampled: dict
    dofs: int
    seconds: float
    f_max: float = 0.0
    damping_ratios: np.ndarray | None = None


def check_parameter_keys(spec: UpdateSpec) -> None:
    """InputError "<scene>: <key>: ..." for a parameter key that no scene of the spec defines (a parameter
    overrides an existing value; a misspelt key would otherwise add a new one)."""
    from housingfe.scene import load_housing_scene

    scenes = {t.scene for t in spec.targets}
    data = {s: _scene_data(spec, s) for s in scenes}
    for s in sorted(scenes):       # every override checked before the first solve, not at the first one using it
        for what in ("search_overrides", "confirm_overrides"):
            try:
                load_housing_scene(s, list(spec.scene_overrides.get(s, [])) + list(getattr(spec, what).get(s, [])))
            except InputError as exc:
                raise InputError(f"{what}.{s}: {exc}") from None
    for p in spec.parameters:
        for key in p.keys:
            if not any(_present(d, key) for d in data.values()):
                raise InputError(f"{', '.join(sorted(scenes))}: {key}: unknown parameter key "
                                 f"(parameter {p.name!r}: no scene of the spec has it)")


def _scene_data(spec: UpdateSpec, scene: str) -> dict:
    """A scene's TOML data with the spec's scene_overrides for it applied."""
    from housingfe.scenefile import apply_overrides, read_scene_dict

    data, _ = read_scene_dict(scene)
    return apply_overrides(data, spec.scene_overrides.get(scene, []), source=f"scene_overrides.{scene}")


def _present(data: dict, key: str) -> bool:
    node = data
    for part in key.split("."):
        if not isinstance(node, dict) or part not in node:
            return False
        node = node[part]
    return True


class SceneEvaluator:
    """Builds and solves the spec's scenes for a parameter vector; caches by (values, overrides)."""

    def __init__(self, spec: UpdateSpec, comm=None, log: Callable[[str], None] | None = None, isolate: bool = True):
        from mpi4py import MPI

        self.spec = spec
        self.comm = comm or MPI.COMM_WORLD
        self.log = log or (lambda s: None)
        self.cache: dict = {}
        self.checkpoint = None          # housingfe.checkpoint.Checkpoint: every fresh solve is appended
        self.restored: dict = {}        # solves of an interrupted run (from the checkpoint), used in order
        self.resumed_used = 0
        self.fresh_solves = 0
        self.progress = None            # housingfe.progress.Progress counting solves (see counting())
        self.seconds: list[float] = []
        self.f_last: dict[str, float] = {}
        self.isolate, self.pool = isolate, None
        scenes = sorted({t.scene for t in spec.targets})
        self.scene_data = {s: _scene_data(spec, s) for s in scenes}
        self.measured = {}
        for i, t in enumerate(spec.targets):
            if t.kind == "paired":
                from housingfe.correlation.uff import read_measured_modes

                self.measured[t.name] = read_measured_modes(t.measured, t.units, f"targets.{i}.units")

    def overrides(self, scene: str, values: np.ndarray, extra: list[str]) -> list[str]:
        """The --set overrides of one evaluation: the spec's scene_overrides, `extra` (search or confirmation
        mesh), then the parameters."""
        out = list(self.spec.scene_overrides.get(scene, [])) + list(extra)
        for p, v in zip(self.spec.parameters, values):
            for key in p.keys:
                if _present(self.scene_data[scene], key):
                    out.append(f"{key}={float(v)!r}")
        return out

    def f_needed(self, scene: str) -> tuple[int, float]:
        """(elastic modes needed, first f_max guess in Hz) for a scene's targets."""
        n, f = 1, 0.0
        for t in self.spec.targets:
            if t.scene != scene:
                continue
            if t.kind == "frequency":
                n, f = max(n, t.mode), max(f, 1.3 * t.value)
            elif t.kind == "count":
                n, f = max(n, int(round(t.value)) + 1), max(f, 1.15 * t.band_hz)
            elif t.kind == "close_pair":
                n, f = max(n, 2), max(f, 1.3 * max(t.value))
            elif t.kind == "paired":
                fm = self.measured[t.name].frequencies_hz
                n, f = max(n, len(fm)), max(f, 1.3 * float(fm.max()))
        return n, f or 1000.0

    def solve(self, scene: str, values: np.ndarray, extra: list[str]) -> SceneResult:
        """Modes (and mass, sampled shapes) of one scene at parameter values (physical units) with extra
        overrides; cached.  On one rank the FE work runs in a worker process that is replaced every
        WORKER_TASKS solves: building a model leaves ~50 MB per build behind in the process (measured on the
        coarse box, gc.collect() does not return it), which a search of hundreds of builds cannot afford."""
        key = (scene, tuple(np.round(values, 12)), tuple(extra))
        if key in self.cache:
            return self.cache[key]
        if key in self.restored:
            # a solve an interrupted run finished: it updates the state as the fresh solve did then (f_last), so
            # the resumed search takes the same path
            result = self.restored.pop(key)
            self.resumed_used += 1
            self.f_last[scene] = result.f_max
            self.seconds.append(result.seconds)
            self.cache[key] = result
            if self.progress is not None:
                self.progress.update(note=f"{Path(scene).stem} (resumed)", resumed=True)
            return result
        n, f_guess = self.f_needed(scene)
        f_max = max(f_guess, self.f_last.get(scene, 0.0))
        need_mass = any(t.kind == "mass" and t.scene == scene for t in self.spec.targets)
        measured = {t.name: self.measured[t.name] for t in self.spec.targets if t.kind == "paired" and t.scene == scene}
        need_damping = any(t.kind == "paired" and t.use_damping and t.scene == scene for t in self.spec.targets)
        args = (scene, self.overrides(scene, values, extra), n, f_max, need_mass, measured)
        if self.comm.size == 1 and self.isolate:
            if self.pool is None:
                from housingfe.correlation.worker import Worker

                self.pool = Worker(WORKER_TASKS, module=__name__)
            result = self.pool.call("solve_scene", *args, None, need_damping)
        else:
            result = solve_scene(*args, comm=self.comm, need_damping=need_damping)
        self.f_last[scene] = result.f_max
        self.seconds.append(result.seconds)
        self.cache[key] = result
        self.fresh_solves += 1
        if self.checkpoint is not None:
            self.checkpoint.append({"key": _encode(list(key)), "result": _encode(result)})
        if self.progress is not None:
            self.progress.update(note=f"{Path(scene).stem}, {result.dofs} DOFs, {result.seconds:.1f} s")
        return result

    @contextlib.contextmanager
    def counting(self, label: str, at_most: int):
        """Progress (housingfe.progress) of the scene solves made inside the block, at most `at_most` (cached
        ones are not solves)."""
        from housingfe.progress import Progress

        self.progress = Progress(label, at_most, "scene solves", at_most=True, comm=self.comm)
        try:
            yield self.progress
        finally:
            self.progress.close()
            self.progress = None

    def resume_from(self, checkpoint) -> int:
        """Use the solves recorded in a checkpoint (housingfe.checkpoint.Checkpoint) instead of solving them
        again, and record every new solve in it; returns the number of solves restored."""
        for rec in checkpoint.records:
            scene, values, extra = _decode(rec["key"])
            self.restored[(scene, tuple(values), tuple(extra))] = _decode(rec["result"])
        self.checkpoint = checkpoint
        return len(self.restored)

    def close(self) -> None:
        if self.pool is not None:
            self.pool.close()
            self.pool = None


WORKER_TASKS = 20


def _encode(obj):
    """A SceneResult (with its ModeSets and arrays) as JSON-able data that _decode turns back into equal objects
    (floats exactly: JSON keeps Python's shortest round-trip repr)."""
    import dataclasses

    if isinstance(obj, np.ndarray):
        if np.iscomplexobj(obj):
            return {"__complex__": [_encode(obj.real), _encode(obj.imag)]}
        return {"__array__": obj.tolist(), "dtype": obj.dtype.str, "shape": list(obj.shape)}
    if dataclasses.is_dataclass(obj):
        return {"__dataclass__": f"{type(obj).__module__}:{type(obj).__qualname__}",
                "fields": {f.name: _encode(getattr(obj, f.name)) for f in dataclasses.fields(obj)}}
    if isinstance(obj, dict):
        return {"__dict__": {k: _encode(v) for k, v in obj.items()}}
    if isinstance(obj, (list, tuple)):
        return [_encode(v) for v in obj]
    if isinstance(obj, np.generic):
        return obj.item()
    return obj


_DECODABLE = {"housingfe.correlation.updating:SceneResult", "housingfe.correlation.uff:ModeSet"}


def _decode(data):
    """The inverse of _encode (only the dataclasses of _DECODABLE)."""
    import importlib

    if isinstance(data, list):
        return [_decode(v) for v in data]
    if not isinstance(data, dict):
        return data
    if "__array__" in data:
        return np.array(data["__array__"], dtype=np.dtype(data["dtype"])).reshape(data["shape"])
    if "__complex__" in data:
        re, im = (_decode(v) for v in data["__complex__"])
        return re + 1j * im
    if "__dict__" in data:
        return {k: _decode(v) for k, v in data["__dict__"].items()}
    if "__dataclass__" in data:
        if data["__dataclass__"] not in _DECODABLE:
            raise ValueError(f"checkpoint: unexpected record type {data['__dataclass__']}")
        module, name = data["__dataclass__"].split(":")
        cls = getattr(importlib.import_module(module), name)
        return cls(**{k: _decode(v) for k, v in data["fields"].items()})
    raise ValueError("checkpoint: unexpected record")


def solve_scene(scene: str, overrides: list[str], n: int, f_max: float, need_mass: bool, measured: dict,
                comm=None, need_damping: bool = False) -> SceneResult:
    """Build a scene with overrides and solve at least n elastic modes (f_max raised until there are n);
    the mass (kg) from the rigid x-translation t^T M t if need_mass; the modes sampled on the channels of
    each measured ModeSet (name -> ModeSet)."""
    from mpi4py import MPI

    from housingfe.correlation.points import computed_modes_at
    from housingfe.scene import build_model_from_scene, load_housing_scene
    from housingfe.solvers.modal import modes

    t0 = time.perf_counter()
    sc, _ = load_housing_scene(scene, overrides)
    model = build_model_from_scene(sc, comm or MPI.COMM_WORLD)
    for _ in range(8):
        basis = modes(model, f_max)
        freqs = basis.frequencies_hz[basis.rigid_count:]
        if len(freqs) >= n:
            break
        # modal density of plates is about constant: scale f_max to the count still missing
        f_max *= min(3.0, max(1.2, 1.1 * (n + 2) / max(len(freqs), 1)))
    else:
        raise SolverError(f"{scene}: fewer than {n} elastic modes below {f_max:.0f} Hz")
    sampled = {name: computed_modes_at(basis, m) for name, m in measured.items()}
    mass = None
    if need_mass:
        t = model.rigid_body_vectors()[0]
        y = t.duplicate()
        model.M.mult(t, y)
        mass = float(t.dot(y))
    zeta = modal_damping_ratios(sc.damping, model, basis) if need_damping else None
    return SceneResult(freqs, basis.rigid_count, mass, sampled, model.dofs, time.perf_counter() - t0, f_max, zeta)


def modal_damping_ratios(spec, structure, basis) -> np.ndarray:
    """Viscous damping ratio (-) of each elastic mode of a basis under a scene's DampingSpec: xi as given; a
    loss factor eta(f) as eta / 2 at the mode's frequency (equal loss per cycle at resonance); per-material loss
    factors (damping matrix D) by the modal strain energy, xi_k = phi_k^T D phi_k / (2 lambda_k) for
    mass-normalised phi_k."""
    from housingfe.response.forced import damping_model

    damping = damping_model(spec, structure)
    freqs = basis.frequencies_hz[basis.rigid_count:]
    xi = damping.ratios(len(freqs))
    if xi is not None:
        return np.asarray(xi, float)
    if damping.D is None:
        return 0.5 * np.asarray(damping.hysteretic(freqs), float)
    out = []
    y = basis.vectors[0].duplicate()
    for lam, x in zip(basis.eigenvalues[basis.rigid_count:], basis.vectors[basis.rigid_count:]):
        damping.D.mult(x, y)
        out.append(float(x.dot(y)) / (2.0 * lam))
    return np.array(out)


def _nearest_pair(freqs: np.ndarray, pair: list[float]) -> tuple[float, float]:
    if len(freqs) < 2:
        return float("nan"), float("nan")
    f1, f2 = freqs[:-1], freqs[1:]
    err = np.maximum(np.abs(np.log(f1 / pair[0])), np.abs(np.log(f2 / pair[1])))
    k = int(np.argmin(err))
    return float(f1[k]), float(f2[k])


@dataclass
class TargetValue:
    """A target evaluated: residuals (scaled), the model's value for display, the published value."""

    name: str
    role: str
    residuals: np.ndarray
    model: object
    published: object


def evaluate_targets(evaluator: SceneEvaluator, values: np.ndarray, extra: dict[str, list[str]],
                     roles=("calibration",), correction: dict | None = None) -> list[TargetValue]:
    """Evaluate the targets of the given roles at one parameter vector (physical units).  `correction`:
    target name -> factor on the model frequencies/mass (the search-mesh correction)."""
    from housingfe.correlation.mac import mac, pair_modes

    out = []
    for t in evaluator.spec.targets:
        if t.role not in roles:
            continue
        r = evaluator.solve(t.scene, values, extra.get(t.scene, []))
        c = (correction or {}).get(t.name, 1.0)
        f = r.frequencies_hz * c
        if t.kind == "mass":
            if r.mass_kg is None or r.rigid_count != 6:
                raise InputError(f"targets.{t.name}: a mass target needs a free-free scene ({t.scene} is supported)")
            m = r.mass_kg * c
            out.append(TargetValue(t.name, t.role, np.array([(m / t.value - 1) / t.sigma]), m, t.value))
        elif t.kind == "frequency":
            fm = f[t.mode - 1]
            out.append(TargetValue(t.name, t.role, np.array([(fm / t.value - 1) / t.sigma]), fm, t.value))
        elif t.kind == "count":
            n = int(round(t.value))
            surrogate = math.log(math.sqrt(f[n - 1] * f[n]) / t.band_hz)
            count = int(np.sum(f < t.band_hz))
            out.append(TargetValue(t.name, t.role, np.array([surrogate / t.sigma]),
                                   {"count": count, f"f{n}": float(f[n - 1]), f"f{n + 1}": float(f[n])}, n))
        elif t.kind == "close_pair":
            p = _nearest_pair(f, t.value)
            err = max(abs(p[0] / t.value[0] - 1), abs(p[1] / t.value[1] - 1))
            out.append(TargetValue(t.name, t.role, np.array([err / t.sigma]), p, tuple(t.value)))
        else:
            meas = evaluator.measured[t.name]
            comp = r.sampled[t.name]
            comp_f = comp.frequencies_hz * c
            m = mac(meas.shapes, comp.shapes)
            pairing = pair_modes(m, meas.frequencies_hz, comp_f, t.threshold, frequency_weight=0.5)
            by_meas = {p.measured: p for p in pairing.pairs}
            res = []
            for i, fm_i in enumerate(meas.frequencies_hz):
                p = by_meas.get(i)
                j = p.computed if p is not None else int(np.argmax(m[i]))
                res.append((comp_f[j] / fm_i - 1) / t.sigma)
                if t.use_mac:
                    res.append((1 - m[i, j]) / t.sigma_mac)
                if t.use_damping and meas.damping is not None and meas.damping[i] > 0:
                    res.append((r.damping_ratios[j] / meas.damping[i] - 1) / t.sigma_damping)
            out.append(TargetValue(t.name, t.role, np.array(res), pairing, meas.frequencies_hz))
    return out


# ------------------------------------------------------------------------------------------ the fit
@dataclass
class UpdateResult:
    """A finished fit: parameters (physical units), their standard deviations from the Jacobian, the
    scaled Jacobian (residuals per unit parameter), history of (evaluation, cost, parameters) (cache hits
    included), seconds per fresh model evaluation (all calibration scenes built and solved once)."""

    names: list
    start: np.ndarray
    values: np.ndarray
    std: np.ndarray
    covariance: np.ndarray
    jacobian: np.ndarray
    residual_names: list
    cost: float
    history: list = field(default_factory=list)
    evaluations: int = 0
    seconds_per_evaluation: float = float("nan")
    status: str = ""
    correction: dict = field(default_factory=dict)


def _residual_names(targets: list[TargetValue]) -> list[str]:
    names = []
    for tv in targets:
        names += [tv.name] if len(tv.residuals) == 1 else [f"{tv.name}[{k}]" for k in range(len(tv.residuals))]
    return names


def fit(evaluator: SceneEvaluator, start: np.ndarray | None = None, *, correction: dict | None = None,
        label: str = "update") -> UpdateResult:
    """Bounded least squares of the calibration residuals over the spec's parameters from `start`
    (default: each parameter's start), forward-difference Jacobian with step fd_step x range; the search
    uses search_overrides (a coarse mesh) and the search-mesh `correction`.  Progress (evaluations of at most
    max_evaluations, elapsed, estimate) on stderr under `label` (housingfe.progress)."""
    from scipy.optimize import least_squares

    from housingfe.progress import Progress

    spec = evaluator.spec
    lo = np.array([p.lower for p in spec.parameters])
    hi = np.array([p.upper for p in spec.parameters])
    x0 = np.array([p.start for p in spec.parameters]) if start is None else np.asarray(start, float)
    span = hi - lo
    history: list = []
    names_holder: list = []
    n_eval = [0]
    t_start = time.perf_counter()
    solves_before = len(evaluator.seconds)

    best = [np.inf, None]

    def residuals(u, budget=True):
        if budget and n_eval[0] >= spec.max_evaluations:
            raise _BudgetSpent
        x = lo + u * span
        fresh, resumed = evaluator.fresh_solves, evaluator.resumed_used
        tvs = evaluate_targets(evaluator, x, spec.search_overrides, ("calibration",), correction)
        if not names_holder:
            names_holder.extend(_residual_names(tvs))
        r = np.concatenate([tv.residuals for tv in tvs])
        n_eval[0] += 1
        history.append((n_eval[0], 0.5 * float(r @ r), x.copy()))
        if 0.5 * float(r @ r) < best[0]:
            best[:] = [0.5 * float(r @ r), u.copy()]
        progress.write(f"eval {n_eval[0]:3d}  cost {0.5 * float(r @ r):10.4g}  x = "
                       + ", ".join(f"{p.name}={v:.5g}" for p, v in zip(spec.parameters, x)), evaluator.log)
        if budget:
            # an evaluation without a fresh solve (all cached, or from the checkpoint) does not time the ones
            # still to come
            no_solve = evaluator.fresh_solves == fresh
            from_checkpoint = no_solve and evaluator.resumed_used > resumed
            progress.update(note=f"cost {0.5 * float(r @ r):.4g}" + (", resumed" if from_checkpoint else ""),
                            resumed=no_solve)
        return r

    h = spec.fd_step

    def jacobian(u, budget=True):
        r0 = residuals(u, budget)
        J = np.empty((len(r0), len(u)))
        for k in range(len(u)):
            du = h if u[k] + h <= 1.0 else -h      # step back at the upper bound
            v = u.copy()
            v[k] += du
            J[:, k] = (residuals(v, budget) - r0) / du
        return J

    u0 = (x0 - lo) / span
    progress = Progress(label, spec.max_evaluations, "evaluations", at_most=True, comm=evaluator.comm)
    try:
        sol = least_squares(residuals, u0, jac=jacobian, bounds=(0.0, 1.0), method="trf", x_scale=1.0,
                            max_nfev=spec.max_evaluations, xtol=1e-4, ftol=1e-6)
        u_best, message = sol.x, sol.message
        if best[0] < 0.5 * float(sol.fun @ sol.fun):
            u_best = best[1]
    except _BudgetSpent:
        u_best, message = best[1], f"stopped after max_evaluations = {spec.max_evaluations} model evaluations"
    finally:
        progress.close()
    cost = float(best[0]) if u_best is best[1] else None
    J = jacobian(u_best, budget=False)     # the sensitivities at the answer (cached where already computed)
    r = residuals(u_best, budget=False)
    cost = 0.5 * float(r @ r) if cost is None else cost
    Jp = J / span[None, :]                            # residuals per physical unit
    try:
        cov = np.linalg.inv(Jp.T @ Jp)
    except np.linalg.LinAlgError:
        cov = np.full((len(x0), len(x0)), np.inf)
    elapsed = time.perf_counter() - t_start
    # per model evaluation that was not a cache hit (each solves every calibration scene once)
    scenes = len({t.scene for t in spec.targets if t.role == "calibration"})
    fresh = max((len(evaluator.seconds) - solves_before) / max(scenes, 1), 1.0)
    return UpdateResult([p.name for p in spec.parameters], x0, lo + u_best * span, np.sqrt(np.abs(np.diag(cov))),
                        cov, Jp, names_holder, cost, history, n_eval[0],
                        elapsed / fresh, message, dict(correction or {}))


class _BudgetSpent(Exception):
    """The spec's max_evaluations model evaluations are used up (least_squares' max_nfev does not count the
    Jacobian's evaluations)."""


def mesh_correction(evaluator: SceneEvaluator, x: np.ndarray) -> dict:
    """target name -> (value on the confirmation mesh) / (value on the search mesh) at x, for mass and
    frequency-like targets (the search then fits corrected coarse-mesh predictions)."""
    spec = evaluator.spec
    roles = ("calibration", "holdout")
    fine = evaluate_targets(evaluator, x, spec.confirm_overrides, roles)
    coarse = evaluate_targets(evaluator, x, spec.search_overrides, roles)
    out = {}
    for tf, tc, t in zip(fine, coarse, [t for t in spec.targets if t.role in roles]):
        if t.kind == "mass":
            out[t.name] = tf.model / tc.model
        elif t.kind == "frequency":
            out[t.name] = tf.model / tc.model
        elif t.kind == "count":
            n = int(round(t.value))
            out[t.name] = math.sqrt(tf.model[f"f{n}"] * tf.model[f"f{n + 1}"] /
                                    (tc.model[f"f{n}"] * tc.model[f"f{n + 1}"]))
    return out


# ------------------------------------------------------------------------------------------ the study
def _display(v) -> str:
    if isinstance(v, dict):
        return ", ".join(f"{k} {x:.4g}" if isinstance(x, float) else f"{k} {x}" for k, x in v.items())
    if isinstance(v, tuple):
        return "/".join(f"{x:.1f}" for x in v)
    if isinstance(v, float):
        return f"{v:.4g}"
    if hasattr(v, "pairs"):
        return f"{len(v.pairs)} paired, mean |df| {100 * v.mean_abs_error():.2f} %"
    return str(v)


def target_table(targets: list[TargetValue]) -> list[tuple]:
    """Rows (target, role, published, model, chi = scaled residual(s) rms)."""
    return [(tv.name, tv.role, _display(tv.published), _display(tv.model),
             f"{float(np.sqrt(np.mean(tv.residuals ** 2))):.3g}") for tv in targets]


def inputs_digest(spec: UpdateSpec, evaluator: SceneEvaluator) -> str:
    """The hash that names an update's inputs in its checkpoint: the spec, every scene's data (with the spec's
    scene_overrides), the measured files' bytes and the package version.  Files a scene refers to (none of the
    built-in geometry kinds does) are not part of it."""
    import hashlib

    import housingfe
    from housingfe.checkpoint import digest

    measured = {}
    for t in spec.targets:
        if t.measured is not None:
            with open(t.measured, "rb") as fh:
                measured[t.name] = hashlib.sha256(fh.read()).hexdigest()
    return digest({"spec": spec.model_dump(mode="json"), "scenes": evaluator.scene_data, "measured": measured,
                   "housingfe": housingfe.__version__})


def checkpoint_path(out_dir) -> Path:
    """Where `housingfe update --out OUT` keeps its finished evaluations: OUT.partial/evaluations.jsonl."""
    from housingfe.checkpoint import partial_dir

    return partial_dir(out_dir) / "evaluations.jsonl"


def run_update(spec: UpdateSpec, out_dir, *, comm=None, echo: Callable[[str], None] = print,
               resume: bool = True) -> dict:
    """The whole study: targets before (start, confirmation mesh), a fit from every start point on the search
    mesh (with the mesh correction), a refit after refreshing the correction at the best point, targets after
    (confirmation mesh), identifiability (scaled Jacobian, parameter standard deviations, correlation).
    Writes update.json, history.csv, targets.csv and convergence.png atomically into out_dir (None: nothing
    written); returns the summary dict.
    With out_dir, every scene solve is checkpointed to checkpoint_path(out_dir) as it finishes; a re-run after
    an interruption re-uses the solves of a checkpoint with the same inputs (resume=False: starts afresh) and
    takes the same path to the same answer.  The checkpoint is deleted once out_dir was written."""
    from housingfe.checkpoint import Checkpoint
    from housingfe.outputs import atomic_output_dir, format_table, write_csv, write_json

    check_parameter_keys(spec)
    evaluator = SceneEvaluator(spec, comm, log=echo)
    checkpoint = None
    if out_dir is not None:
        path = checkpoint_path(out_dir)
        checkpoint = Checkpoint(path, inputs_digest(spec, evaluator), resume=resume, comm=evaluator.comm,
                                what=f"housingfe update {spec.name}: scene solves")
        restored = evaluator.resume_from(checkpoint)
        if restored:
            echo(f"resuming: {restored} evaluations (scene solves) from {path}")
        elif checkpoint.status == "other-inputs":
            echo(f"note: {path} belongs to other inputs (spec, scenes or version changed); starting afresh")
        elif checkpoint.status == "ignored":
            echo(f"note: --no-resume: the evaluations in {path} are not used; starting afresh")
    names = [p.name for p in spec.parameters]
    x0 = np.array([p.start for p in spec.parameters])
    roles = ("calibration", "holdout")
    differs = any(spec.search_overrides.get(s, []) != spec.confirm_overrides.get(s, [])
                  for s in evaluator.scene_data)
    n_scenes = len(evaluator.scene_data)
    with evaluator.counting("update setup", n_scenes * (2 if spec.mesh_correction and differs else 1)):
        correction = mesh_correction(evaluator, x0) if (spec.mesh_correction and differs) else {}
        echo(f"mesh correction at the start: { {k: round(v, 4) for k, v in correction.items()} }")
        before = evaluate_targets(evaluator, x0, spec.confirm_overrides, roles)
    starts = [x0] + [np.array([float(ms.get(n, p.start)) for n, p in zip(names, spec.parameters)])
                     for ms in spec.multistart]
    for k, ms in enumerate(spec.multistart):
        unknown = set(ms) - set(names)
        if unknown:
            raise InputError(f"multistart.{k}: {sorted(unknown)[0]}: not a parameter name ({', '.join(names)})")
    fits = []
    for k, s in enumerate(starts):
        echo(f"--- start {k + 1}/{len(starts)}: " + ", ".join(f"{n}={v:.4g}" for n, v in zip(names, s)))
        fits.append(fit(evaluator, s, correction=correction, label=f"update start {k + 1}/{len(starts)}"))
        echo(f"    -> cost {fits[-1].cost:.4g}: " + ", ".join(f"{n}={v:.5g}" for n, v in zip(names, fits[-1].values)))
    best = min(fits, key=lambda r: r.cost)
    if correction:
        with evaluator.counting("update correction at the best point", 2 * n_scenes):
            correction = mesh_correction(evaluator, best.values)
        echo(f"mesh correction at the best point: { {k: round(v, 4) for k, v in correction.items()} }")
        best = fit(evaluator, best.values, correction=correction, label="update refit")
        echo("    refit -> cost {:.4g}: ".format(best.cost) + ", ".join(f"{n}={v:.5g}" for n, v in zip(names, best.values)))
    with evaluator.counting("update confirmation", n_scenes):
        after = evaluate_targets(evaluator, best.values, spec.confirm_overrides, roles)
    evaluator.close()
    cal = lambda tvs, role: float(sum(0.5 * float(tv.residuals @ tv.residuals) for tv in tvs if tv.role == role))
    summary = {
        "name": spec.name,
        "parameters": names,
        "start": x0.tolist(),
        "identified": best.values.tolist(),
        "std": best.std.tolist(),
        "correlation": (best.covariance / np.outer(best.std, best.std)).tolist() if np.all(np.isfinite(best.std)) else None,
        "jacobian_scaled_per_unit": best.jacobian.tolist(),
        "residual_names": best.residual_names,
        "fits": [{"start": f.start.tolist(), "values": f.values.tolist(), "cost": f.cost, "evaluations": f.evaluations,
                  "status": f.status} for f in fits],
        "cost_before": {"calibration": cal(before, "calibration"), "holdout": cal(before, "holdout")},
        "cost_after": {"calibration": cal(after, "calibration"), "holdout": cal(after, "holdout")},
        "before": target_table(before),
        "after": target_table(after),
        "seconds_per_scene_solve_median": float(np.median(evaluator.seconds)) if evaluator.seconds else None,
        "scene_solves": len(evaluator.seconds),
        "scene_solves_resumed": evaluator.resumed_used,     # taken from the checkpoint of an interrupted run
        "seconds_per_evaluation": best.seconds_per_evaluation,
        "mesh_correction": correction,
    }
    header = ["target", "role", "published", "model", "|chi|"]
    echo("\nbefore (start, confirmation mesh):\n" + format_table(header, summary["before"]))
    echo("\nafter (identified, confirmation mesh):\n" + format_table(header, summary["after"]))
    echo("\nparameters: " + ", ".join(f"{n} = {v:.5g} +- {s:.2g}" for n, v, s in zip(names, best.values, best.std)))
    echo(f"cost calibration {summary['cost_before']['calibration']:.4g} -> {summary['cost_after']['calibration']:.4g}, "
         f"holdout {summary['cost_before']['holdout']:.4g} -> {summary['cost_after']['holdout']:.4g}; "
         f"{summary['scene_solves']} scene solves, median {summary['seconds_per_scene_solve_median']:.2f} s")
    if out_dir is None:
        return summary
    with atomic_output_dir(out_dir, evaluator.comm) as out:
        if evaluator.comm.rank == 0:
            write_json(out / "update.json", summary)
            write_csv(out / "history.csv", ["fit", "evaluation", "cost"] + names,
                      [(k, e, c, *x) for k, f in enumerate(fits) for e, c, x in f.history])
            write_csv(out / "targets.csv", ["when"] + header,
                      [("before", *r) for r in summary["before"]] + [("after", *r) for r in summary["after"]])
            _convergence_png(fits, out / "convergence.png")
    checkpoint.remove()
    echo(f"results: {out_dir}/")
    return summary


def _convergence_png(fits: list[UpdateResult], path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 3.2), dpi=110)
    for k, f in enumerate(fits):
        ax.semilogy([e for e, _, _ in f.history], [max(c, 1e-12) for _, c, _ in f.history], ".-", label=f"start {k + 1}")
    ax.set_xlabel("evaluation")
    ax.set_ylabel("cost 0.5 sum chi^2")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
