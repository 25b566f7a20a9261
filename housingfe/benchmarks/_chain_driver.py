"""One fresh-process run of `housingfe bench chain_speed` (run as a script with PYTHONPATH on the tree under test,
so that the same driver times the code before and after a change).

    python _chain_driver.py OUT_DIR RESULT_JSON [override ...]

1. the chain of `make demo` (`housingfe run test-gearbox-runup`, housingfe.runup.scene.run_scene) with the
   overrides, its stages as run_scene times them, and the wall clock when it has finished (time.time(): the
   parent knows when it started the process);
2. re-analyses on the chain's coupled model (housingfe.runup.chain.with_drivetrain) for another torque
   (1000 N m), gear set (B) and bearing configuration (self-aligning), each followed by its source and run-up:
   time of the re-analysis alone and of the whole re-run;
3. the numbers to compare versions with: L_WA over speed (every route and radiator, full precision), the modal
   basis' and the Ritz reduction's frequencies, and the re-analysed models' Ritz frequencies and L_WA.

Only API present in both versions is used (run_scene, with_drivetrain, run_source, runup, matched_drivetrains).
"""
from __future__ import annotations

import json
import resource
import sys
import time

SCENE = "test-gearbox-runup"
VARIANTS = (("torque 1000 N m", {"torque": 1000.0}), ("gear set B", {"gear_set": "B"}),
            ("self-aligning bearings", {"bearings": "self_aligning"}))


def _cpu_s() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def _lwa(result) -> dict:
    """{"route/radiation/torque": [L_WA per speed]} of a RunupResult, full precision."""
    out = {}
    for t in result.totals:
        out.setdefault(f"{t['route']}/{t['radiation']}/{t['torque_nm']:g}", []).append(float(t["LwA_dB"]))
    return out


def main(out_dir: str, result_json: str, overrides: list[str]) -> None:
    from housingfe.runup import chain
    from housingfe.runup import scene as rs

    captured = {"results": []}
    build, run_source, runup = chain.build_gearbox_model, chain.run_source, chain.runup

    def capture_build(*args, **kwargs):
        captured["model"] = build(*args, **kwargs)
        return captured["model"]

    def capture_source(model, source, *args, **kwargs):
        captured["source"] = source
        return run_source(model, source, *args, **kwargs)

    def capture_runup(*args, **kwargs):
        res = runup(*args, **kwargs)
        captured["results"].append(res)
        return res

    chain.build_gearbox_model, chain.run_source, chain.runup = capture_build, capture_source, capture_runup
    rs.run_scene(SCENE, out_dir, list(overrides))
    chain_end = time.time()
    chain_cpu = _cpu_s()
    chain.build_gearbox_model, chain.run_source, chain.runup = build, run_source, runup
    gm = captured["model"]
    out = {"chain_end_epoch": chain_end, "chain_cpu_s": chain_cpu,
           "timings": json.load(open(f"{out_dir}/runup.json"))["timings_s"],
           "lwa": _lwa(captured["results"][0]),
           "basis_hz": [float(x) for x in gm.basis.frequencies_hz],
           "ritz_hz": [float(x) for x in gm.reduction.frequencies_hz], "variants": {}}

    scene, path = rs.load_runup_scene(SCENE, list(overrides))
    spec = scene.runup
    base_torque = max(spec.torques_nm)
    for label, change in VARIANTS:
        torque = float(change.get("torque", base_torque))
        dspec = scene.drivetrain.model_copy(update={k: v for k, v in change.items() if k != "torque"})
        t0, c0 = time.perf_counter(), _cpu_s()
        dt = rs.drivetrain_of(dspec, torque, spec.drive_line_model)
        dt = rs.matched_drivetrains(scene.housing, gm.housing_model, {torque: dt}, path)[0][torque]
        model = chain.with_drivetrain(gm, dt)
        reanalysis_s = time.perf_counter() - t0
        if "torque" in change:
            source = captured["source"]             # the same gear set: its source at another torque
        else:
            misalignment = spec.misalignment_model
            if misalignment == "rigid-bores":
                from housingfe.drivetrain.misalignment import lead_gap_law

                misalignment = lead_gap_law(dt, "rigid-bores")
            source = dt.source_model(harmonics=spec.harmonics, engagement=spec.engagement,
                                     misalignment=misalignment)
        lines, _ = chain.run_source(model, source, spec.speeds, [torque], spec.f_max_hz, spec.source_receptance)
        res = chain.runup(model, None, spec.speeds, [torque], routes=tuple(spec.routes), lines=lines)
        out["variants"][label] = {"reanalysis_s": reanalysis_s, "rerun_s": time.perf_counter() - t0,
                                  "rerun_cpu_s": _cpu_s() - c0, "lwa": _lwa(res),
                                  "ritz_hz": [float(x) for x in model.reduction.frequencies_hz]}
    with open(result_json, "w") as fh:
        json.dump(out, fh)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3:])
