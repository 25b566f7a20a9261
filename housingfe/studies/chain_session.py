"""Variants of a run-up scene through the noise chain, each reusing what it shares with the others.

The machinery of the run-up studies (`housingfe study`, `housingfe runup-causes`):

    session = ChainSession.from_scene("test-gearbox-runup", overrides)   # the scene, its housing model (once)
    model = session.model(session.drivetrain("B", "self_aligning", 2000.0))
    result = session.runup(model, torque=2000.0)                          # RunupResult at the scene's speeds

* the housing FE model is meshed once per session (the scene's [housing] at runup.f_max_hz);
* the coupled gearbox's modal basis and Ritz reduction are computed once per **layout** — the FE interior without
  its bearing matrices and mean mesh stiffness (shafts, gear discs, bores, bearing seats, the gear-mesh point and
  normal) — by `housingfe.runup.chain.build_gearbox_model`; another drivetrain of the same layout (gear set of the
  same geometry, bearing configuration, torque) is a Rayleigh-Ritz re-analysis on the same Ritz vectors
  (`with_drivetrain`: seconds; its Ritz space holds the static responses to unit pairs across every bearing and to
  the mesh load, docs/runup.md); with runup.bearing_speeds = "follow" the fluid films then take each run-up speed
  (`follow`, housingfe.runup.chain.follow_speeds).  `fresh_basis=True` computes a basis per variant instead (to measure what the
  reuse costs in accuracy);
* each run-up's source is the scene's, as `housingfe run` computes it (`scene_lines`: the coupled model's receptance
  at the mesh with runup.source_receptance = "coupled", the misalignment under load of runup.misalignment), so a
  variant's source sees its own bearings; `lines` gives the rigid-bore lumped source's lines instead (computed once
  per source and torque: the lumped model depends on the gear set, shafts and Appendix C's bearing diagonal, not on
  the FE bearings), which `runup-causes` uses on purpose.

`session.log` records per model whether its basis was built or re-used, and the times.
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass, field

import numpy as np

from housingfe.errors import InputError

# the speed range over which the thesis states its mean differences (Secs. 5.7-5.9)
MEAN_RANGE_RPM = (800.0, 1500.0)


@dataclass
class ModelEntry:
    """One coupled model of a session: its layout key, the drivetrain it holds, whether its basis was built here
    ("built") or re-used from the layout's first model ("re-analysed"), and the wall time (s) that took."""

    label: str
    layout: str
    how: str
    seconds: float


@dataclass
class ModelPool:
    """Housing models and coupled gearbox models shared by sessions (e.g. the same family with another engagement
    shock, or two families on one layout): keyed by what they depend on (the housing and its mesh for the highest
    line and radiators; the basis' span, damping and observed surface; the layout)."""

    housings: dict = field(default_factory=dict)
    models: dict = field(default_factory=dict)


@dataclass
class ChainSession:
    """A run-up scene (housingfe.runup.scene.RunupScene) with its housing FE model and radiators, the coupled
    models built so far per layout, the sources and their lines (see the module docstring)."""

    scene: object
    scene_path: object
    comm: object
    housing_model: object = None
    radiators: dict = field(default_factory=dict)
    fresh_basis: bool = False
    pool: ModelPool = field(default_factory=ModelPool)
    log: list = field(default_factory=list)
    timings: dict = field(default_factory=dict)
    _sources: dict = field(default_factory=dict)
    _lines: dict = field(default_factory=dict)
    _drivetrains: dict = field(default_factory=dict)
    _layouts: dict = field(default_factory=dict)
    _scene_sources: dict = field(default_factory=dict)

    @classmethod
    def from_scene(cls, name_or_path: str, overrides=(), comm=None, fresh_basis: bool = False,
                   pool: ModelPool | None = None) -> "ChainSession":
        """Read and validate a run-up scene (InputError naming the file and key); nothing is built yet.  pool: the
        housing and coupled models of other sessions, reused where they fit this scene."""
        from housingfe.runup.scene import load_runup_scene

        if comm is None:
            from mpi4py import MPI

            comm = MPI.COMM_WORLD
        scene, path = load_runup_scene(name_or_path, list(overrides))
        return cls(scene, path, comm, fresh_basis=fresh_basis, pool=pool if pool is not None else ModelPool())

    @property
    def spec(self):
        """The scene's [runup] (speeds, f_max_hz, routes, damping, engagement, ...)."""
        return self.scene.runup

    @property
    def radiation(self) -> str:
        """The radiation model the checks and studies compare (the scene's first)."""
        return self.scene.radiation.models[0]

    def drivetrain(self, gear_set: str, bearings: str, torque: float):
        """The scene's drivetrain description with another gear set / bearing configuration, at a pinion torque
        (N m), made once per session.  A bearing that cannot carry its load is an InputError naming the scene file
        (raised here, before any FE)."""
        from housingfe.runup.scene import drivetrain_of

        key = (gear_set, bearings, float(torque))
        if key not in self._drivetrains:
            spec = self.scene.drivetrain.model_copy(update={"gear_set": gear_set, "bearings": bearings})
            try:
                dt = drivetrain_of(spec, float(torque), self.scene.runup.drive_line_model)
                self._layouts[id(dt)] = layout_key(dt)      # builds the coupling spec: bearings at their loads
            except InputError as exc:
                raise InputError(f"{self.scene_path}: {exc}") from None
            self._drivetrains[key] = dt
        return self._drivetrains[key]

    def _housing_key(self) -> str:
        sc = self.scene
        return json.dumps([sc.housing.model_dump(mode="json"), sc.radiation.model_dump(mode="json"),
                           self.spec.f_max_hz], sort_keys=True)

    def housing(self):
        """The housing FE model (built on first use, or the pool's) and the radiators on it."""
        if self.housing_model is None:
            key = self._housing_key()
            if key not in self.pool.housings:
                from housingfe.runup.scene import housing_model_for, radiators_of
                from housingfe.scene import load_housing_scene

                t0 = time.perf_counter()
                hs, _ = load_housing_scene(self.scene.housing.scene, list(self.scene.housing.set))
                model = housing_model_for(hs, self.spec.f_max_hz, self.comm)
                self.pool.housings[key] = (model, radiators_of(self.scene.radiation, model))
                self.timings["mesh_s"] = time.perf_counter() - t0
            self.housing_model, self.radiators = self.pool.housings[key]
        return self.housing_model

    def model(self, drivetrain, label: str = "", follow: bool = True):
        """The coupled GearboxModel of `drivetrain`: a new basis for the first drivetrain of its layout (or for
        every drivetrain with fresh_basis), else a Rayleigh-Ritz re-analysis of that layout's model.  follow: with
        its bearings following the scene's speeds (`follow`); False for a model that is only re-analysed
        (with_drivetrain drops the speed models), not run itself."""
        from housingfe.runup.chain import build_gearbox_model, with_drivetrain

        housing = self.housing()
        spec = self.spec
        friction = spec.mesh_friction != "none"      # the friction unit loads join the reduction
        key = json.dumps([self._housing_key(), spec.basis_factor, spec.damping_ratio, spec.surface,
                          self._layouts.get(id(drivetrain)) or layout_key(drivetrain)] + (["friction"] * friction))
        t0 = time.perf_counter()
        base = None if self.fresh_basis else self.pool.models.get(key)
        if base is None:
            model = build_gearbox_model(housing, drivetrain, spec.f_max_hz, damping_ratio=spec.damping_ratio,
                                        basis_factor=spec.basis_factor, radiators=self.radiators,
                                        surface=spec.surface, friction=friction)
            self.pool.models.setdefault(key, model)
            how = "built"
        else:
            model = base if base.drivetrain is drivetrain else with_drivetrain(base, drivetrain)
            how = "re-analysed"
        if follow:
            model = self.follow(model)
        self.log.append(ModelEntry(label, key, how, time.perf_counter() - t0))
        return model

    def follow(self, model):
        """`model` with its speed-dependent bearings at each of the scene's speeds where runup.bearing_speeds is
        "follow" (housingfe.runup.chain.follow_speeds; rolling bearings: the model itself), else the model."""
        if self.spec.bearing_speeds != "follow":
            return model
        from housingfe.runup.chain import follow_speeds

        try:
            return follow_speeds(model, self.spec.speeds)
        except InputError as exc:
            raise InputError(f"{self.scene_path}: {model.drivetrain.torque:g} N m: {exc}") from None

    def source(self, drivetrain):
        """The lumped source (housingfe.source.roosmalen.operating.SourceModel) of a drivetrain with the scene's options,
        one per gear set and lumped reduction (the FE bearings play no part in it)."""
        key = source_key(drivetrain)
        if key not in self._sources:
            self._sources[key] = drivetrain.source_model(harmonics=self.spec.harmonics,
                                                         engagement=self.spec.engagement)
        return self._sources[key]

    def lines(self, drivetrain, torque: float):
        """The rigid-bore lumped source's lines (housingfe.runup.chain.Lines) at the scene's speeds and one torque
        (N m), without misalignment: the same for every FE bearing configuration (cached).  `runup` uses
        `scene_lines` instead, the source of the scene's chain."""
        from housingfe.runup.chain import source_lines

        key = (source_key(drivetrain), float(torque))
        if key not in self._lines:
            lines, seconds = source_lines(self.source(drivetrain), self.spec.speeds, [float(torque)],
                                          self.spec.f_max_hz)
            self._lines[key] = lines
            self.timings["source_s"] = self.timings.get("source_s", 0.0) + seconds
        return self._lines[key]

    def scene_lines(self, model, torque: float):
        """The source's lines of a coupled model at one torque (N m) as `housingfe run` computes them: the
        scene's source receptance (runup.source_receptance: "coupled" = this model's receptance at the mesh) and
        mesh misalignment under load (runup.misalignment).  With "rigid-bores" and no misalignment these are the
        cached lumped lines of `lines`."""
        from housingfe.runup.chain import run_source

        spec, drivetrain = self.spec, model.drivetrain
        misalignment = spec.misalignment_model
        if (spec.source_receptance == "rigid-bores" and misalignment == "none" and spec.mesh_moment_model == "none"
                and spec.mesh_friction == "none"):
            self._scene_sources[id(model)] = (model, self.source(drivetrain))
            return self.lines(drivetrain, torque)
        if misalignment == "coupled":          # the static tilt of this drivetrain on the flexible housing
            from housingfe.drivetrain.misalignment import coupled_misalignment

            gap = coupled_misalignment(self.housing(), drivetrain).lead_gap

            def misalignment(_torque: float) -> float:
                return gap
        elif misalignment == "rigid-bores":
            from housingfe.drivetrain.misalignment import lead_gap_law

            misalignment = lead_gap_law(drivetrain, "rigid-bores")
        source = drivetrain.source_model(harmonics=spec.harmonics, engagement=spec.engagement,
                                         misalignment=misalignment)
        self._scene_sources[id(model)] = (model, source)       # runup_as_made takes the same source's mesh
        lines, seconds = run_source(model, source, spec.speeds, [float(torque)], spec.f_max_hz,
                                    spec.source_receptance, spec.mesh_moment_model, spec.mesh_friction)
        self.timings["source_s"] = self.timings.get("source_s", 0.0) + seconds
        return lines

    def runup(self, model, torque: float, lines=None):
        """The run-up (RunupResult) of a coupled model at one torque (N m) over the scene's speeds and routes;
        lines: the source's (default: `scene_lines`, the source as `housingfe run` computes it)."""
        from housingfe.runup.chain import runup

        lines = self.scene_lines(model, torque) if lines is None else lines
        return runup(model, None, self.spec.speeds, [float(torque)], routes=tuple(self.spec.routes), lines=lines)

    def runup_as_made(self, model, torque: float, result):
        """The expected sidebands of gears as made (housingfe.runup.as_made.AsMadeRun) of one run-up `result` of
        `model` at a pinion torque (N m), as `housingfe run` computes them with runup.as_made = <ISO grade>: the
        source of the run-up's lines (`scene_lines`: the same mesh model, misalignment and operating point) and the
        same coupled model and routes; None when runup.as_made is "none"."""
        if self.spec.as_made == "none":
            return None
        from housingfe.runup.as_made import as_made_run

        held = self._scene_sources.get(id(model))
        if held is None or held[0] is not model:
            self.scene_lines(model, torque)            # a run-up on lines given from outside: the scene's source
            held = self._scene_sources[id(model)]
        run = as_made_run({float(torque): (model, result)}, held[1], self.spec.as_made, self.spec.f_max_hz,
                          tuple(self.spec.routes), self.spec.as_made_pitch)
        self.timings["as_made_s"] = self.timings.get("as_made_s", 0.0) + run.seconds
        return run

    @property
    def basis_builds(self) -> int:
        """How many modal bases this session computed."""
        return sum(e.how == "built" for e in self.log)


def layout_key(drivetrain) -> str:
    """What a Ritz basis is tied to: the FE interior of `drivetrain` without its bearing matrices and mean mesh
    stiffness (shafts, gear discs, bores, bearing seats and nodes, the mesh's nodes, point and normal), as text."""
    spec = drivetrain.to_coupling_spec().model_dump(mode="json")
    bearing_keys = ("name", "shaft_node", "bore", "axis")
    spec["bearings"] = [{k: b.get(k) for k in bearing_keys} for b in spec["bearings"]]
    # the drive line's springs and inertias change no DOF: a re-analysis takes other quill shafts (uncertainty)
    spec["drive_lines"] = [{k: d[k] for k in ("name", "shaft_node")} for d in spec.get("drive_lines", [])]
    for mesh in spec["gear_meshes"]:
        mesh.pop("stiffness", None)
        mesh["point"] = [round(x, 9) for x in mesh["point"]]
        mesh["direction"] = [round(x, 9) for x in mesh["direction"]]
    return json.dumps(spec, sort_keys=True)


def source_key(drivetrain) -> str:
    """What the lumped source depends on: the drivetrain without its FE bearings and torque, as text."""
    return repr((drivetrain.gears, drivetrain.shafts, drivetrain.quill_shafts, drivetrain.couplings,
                 drivetrain.loss_factor, drivetrain.lumped_bearing_stiffness, drivetrain.lumped_bearing_spans))


# ------------------------------------------------------------------------------------------------ statistics
def lwa_curve(result, route: str, radiation: str, torque: float) -> tuple[np.ndarray, np.ndarray]:
    """(speeds rev/min, L_WA dB(A)) of a run-up's total over speed."""
    return result.series(route, radiation, float(torque), "LwA_dB")


def energy_mean_db(speeds, levels_db, speed_range=MEAN_RANGE_RPM) -> float:
    """Energy (power) mean of levels (dB) over a speed range (rev/min, inclusive)."""
    s, v = np.asarray(speeds, float), np.asarray(levels_db, float)
    keep = (s >= speed_range[0]) & (s <= speed_range[1])
    return float(10.0 * np.log10(np.mean(10.0 ** (v[keep] / 10.0))))


def difference_stats(speeds, levels_db, reference_db, speed_range=MEAN_RANGE_RPM) -> tuple[float, float, int]:
    """(mean, standard deviation, count) of levels - reference (dB) at the speeds inside speed_range (rev/min,
    inclusive): the thesis' measure of a variant against its reference over 800-1500 rev/min (Secs. 5.7-5.9),
    speed by speed (population s.d.)."""
    s = np.asarray(speeds, float)
    d = np.asarray(levels_db, float) - np.asarray(reference_db, float)
    keep = (s >= speed_range[0]) & (s <= speed_range[1])
    if not keep.any():
        raise InputError(f"runup speeds: none inside {speed_range[0]:g}-{speed_range[1]:g} rev/min, where the "
                         "thesis states its mean differences")
    return float(d[keep].mean()), float(d[keep].std()), int(keep.sum())


def maximum(speeds, levels_db) -> tuple[float, float]:
    """(largest level, the speed where it is)."""
    i = int(np.argmax(levels_db))
    return float(levels_db[i]), float(np.asarray(speeds)[i])
