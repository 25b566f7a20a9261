"""The resolution report of every built-in housing scene at its own f_max, without solving: each scene's model is
built (meshing and assembly) and its housingfe.fe.resolution line printed, the measured longest cell edge being
the element size.  Run: PYTHONPATH=. OPENBLAS_NUM_THREADS=1 python benchmarks/experiments/resolution/scenes.py
"""
from __future__ import annotations

import sys

from mpi4py import MPI

from housingfe.errors import InputError
from housingfe.report import resolution_lines
from housingfe.scene import build_model_from_scene, load_housing_scene
from housingfe.scenefile import builtin_scenes, read_scene_dict


def main(names: list[str]) -> None:
    for name in names or builtin_scenes():
        data, _ = read_scene_dict(name)
        if (data.get("scene") or {}).get("kind", "housing") != "housing":
            continue
        scene, _ = load_housing_scene(name, [])
        try:
            model = build_model_from_scene(scene, MPI.COMM_WORLD)
        except InputError as exc:
            print(f"| {name} | refused: {exc} |")
            continue
        r = model.resolution.as_dict()
        w = next(w for w in r["walls"] if w["name"] == r["worst_wall"])
        bound = r["error_bound_near_f_max"]
        typical = r["estimated_error_near_f_max"]
        print(f"| {name} | {r['element_family']} | {r['f_max_hz']:g} | {w['name']} {w['thickness_m'] * 1e3:g} mm | "
              f"{r['element_size_m'] * 1e3:.1f} | {w['elements_per_wavelength']:.2f} | {w['nodes_per_wavelength']:.1f} | "
              f"{'< 1' if r['below_calibration'] else f'{typical * 100:.2g}'} | {bound * 100:.2g} | {r['status']} |",
              flush=True)
        for line in resolution_lines(r)[1:]:
            print(f"|   | {line} |")


if __name__ == "__main__":
    main(sys.argv[1:])
