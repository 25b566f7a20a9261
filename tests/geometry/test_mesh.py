"""Reproducible meshes (issue 12 item 9): the same scene gives the same mesh and the same numbers, in one
process, in another process and on 1 or 2 MPI ranks."""
import hashlib
import json
import shutil
import sys

import numpy as np
import pytest

from tests.two_ranks import module_result

# round bores, thin walls and the sliver refinement: the tet path that HXT made irreproducible
SCENE = ("test-gearbox-interior",)
# a small tet model for the frequencies
FREQ_SCENE = (*SCENE, "analysis.modal.f_max=1500.0")


def fingerprint(scene_args, comm) -> dict:
    """Global node and cell counts and a hash of the sorted node coordinates (gathered from all ranks)."""
    from housingfe.fe.model import element_size
    from housingfe.geometry import build_mesh
    from tests.conftest import load_scene

    scene = load_scene(*scene_args)
    size = element_size(scene.mesh, scene.geometry, scene.analysis.f_max, scene.material.resolve())
    housing = build_mesh(scene.geometry, scene.mesh.element, size, scene.mesh.layers, comm)
    mesh = housing.mesh
    owned = mesh.geometry.x[:mesh.geometry.index_map().size_local]
    x = np.concatenate(comm.allgather(owned))
    x = x[np.lexsort(x.T[::-1])]
    return {"nodes": mesh.geometry.index_map().size_global, "cells": mesh.topology.index_map(3).size_global,
            "hash": hashlib.sha1(np.round(x, 12).tobytes()).hexdigest(), "mesher": housing.quality["mesher"],
            "quality": housing.quality["min"]}


def frequencies(comm) -> dict:
    from housingfe.scene import build_model_from_scene
    from housingfe.solvers import modal
    from tests.conftest import load_scene

    scene = load_scene(*FREQ_SCENE)
    model = build_model_from_scene(scene, comm)
    result = modal.solve_modes(model.K, model.M, scene.analysis.modal.f_max)
    return {"dofs": model.dofs, "frequencies_hz": result.frequencies_hz[result.rigid_count:].tolist()}


def _run(ranks: int, what: str) -> dict:
    return module_result("tests.geometry.test_mesh", what, ranks=ranks, timeout=600)


def test_same_scene_same_tet_mesh_in_one_and_in_two_processes(comm):
    first = fingerprint(SCENE, comm)
    assert first["mesher"].startswith("gmsh Delaunay") and first["quality"] > 0.08
    assert fingerprint(SCENE, comm) == first                  # again in this process (gmsh state reused)
    assert _run(1, "mesh") == first                           # a fresh process (new heap, new addresses)


@pytest.mark.mpi
def test_one_and_two_ranks_give_the_same_mesh_and_frequencies(comm):
    if not shutil.which("mpirun"):
        pytest.skip("mpirun not installed")
    assert _run(2, "mesh") == fingerprint(SCENE, comm)
    one, two = frequencies(comm), _run(2, "frequencies")
    assert two["dofs"] == one["dofs"] and len(two["frequencies_hz"]) == len(one["frequencies_hz"]) > 2
    assert np.max(np.abs(np.divide(two["frequencies_hz"], one["frequencies_hz"]) - 1)) < 1e-9


if __name__ == "__main__":     # python -m tests.geometry.test_mesh mesh|frequencies [under mpirun -n 2]
    from mpi4py import MPI

    out = fingerprint(SCENE, MPI.COMM_WORLD) if sys.argv[1] == "mesh" else frequencies(MPI.COMM_WORLD)
    if MPI.COMM_WORLD.rank == 0:
        print(json.dumps(out))
