"""The loaded contact edge of a tip relief (MeshModel.edge_refinement): the mesh stiffness with the default points
per contact line against a continuum reference computed here, and the refined points still standing for their
segments."""
from dataclasses import replace

import numpy as np
import pytest
from scipy.optimize import brentq

from housingfe.source.gears import GearPair
from housingfe.source.stiffness import Corrections, MeshModel, normal_force_from_torque
from tests.source.thesis_gears import REF

# a linear tip relief on both gears, deep enough that independent slices lose contact inside the path at 2000 N m
RELIEF = Corrections(tip_relief=(60e-6, 40e-6), tip_relief_length=(6e-3, 4e-3))


def independent_slices(**kw) -> MeshModel:
    """Rigid bodies, no plate coupling: every slice of a contact line carries q = its own (approach - gap) through
    its tooth compliance and Weber's Hertzian approach, so the continuum needs no matrix."""
    return MeshModel(GearPair.from_table(REF["single_helical"]), corrections=RELIEF, include_plate_coupling=False,
                     include_body_torsion=False, **kw)


def continuum_stiffness(model: MeshModel, u: float, force: float, per_line: int = 1500, rel: float = 1e-3) -> float:
    """dF / d(delta) [N/m] of the independent-slice model with `per_line` slices per contact line, as
    `MeshModel.stiffness_at` takes it (secant over a force step `rel`): each slice's load solves
    c q + delta_Hertz(q) = delta - e by bisection, delta the approach at which the loads sum to the force."""
    fine = replace(model, n_slices=per_line, edge_refinement=1)
    pts = fine.contact_points(u)
    n = pts["s"].size
    c = np.concatenate([np.diag(fine.compliance({k: v[i:i + 500] for k, v in pts.items()})) for i in range(0, n, 500)])
    e = fine.gaps(pts)

    def total(delta):
        room = delta - e
        lo, hi = np.zeros(n), np.maximum(room, 0.0) / c
        for _ in range(40):
            q = 0.5 * (lo + hi)
            over = c * q + fine.hertz(pts, q) > room
            hi, lo = np.where(over, q, hi), np.where(over, lo, q)
        return np.where(room > 0, 0.5 * (lo + hi), 0.0).sum()

    d0 = brentq(lambda d: total(d) - force, e.min(), e.min() + 1e-3, xtol=1e-18, rtol=1e-14)
    d1 = brentq(lambda d: total(d) - force * (1 + rel), d0, d0 + 1e-4, xtol=1e-18, rtol=1e-14)
    return force * rel / (d1 - d0)


def test_stiffness_at_the_default_points_matches_the_continuum_where_the_relief_edge_lies_inside_the_path():
    """With one point per uniform segment the loaded edge jumps a whole segment (1/24 of the line) when it crosses a
    point: at these six positions the stiffness was off by 0.02 - 0.95 % (edge_refinement = 1, the code before).
    With the segments around the edge cut into 8, 0.01 - 0.10 %; required: within 0.2 % at every position.  The
    edge really lies inside the path at all six (checked)."""
    model = independent_slices()
    pair = model.pair
    force = normal_force_from_torque(pair, 2000.0)
    errors = []
    for x in (0.113, 0.413, 0.513, 0.613, 0.713, 0.913):
        u = x * pair.transverse_base_pitch
        pts, F, _ = model.load_distribution(u, force)
        assert np.any(F == 0) and np.any(F > 0)              # an edge inside the path of contact
        k_ref = continuum_stiffness(model, u, force)
        errors.append(model.stiffness_at(u, force)["stiffness"] / k_ref - 1)
    assert np.max(np.abs(errors)) < 2e-3, np.round(np.array(errors) * 100, 3)


def test_refined_points_stand_for_their_segments_and_keep_equal_approach():
    """The refined points of set-A-like relieved flanks (plate coupling, bodies): the widths of each contact line
    still add up to its length inside the path, the forces to the total, the loaded points share one approach and
    the released ones keep their gap open; the segments around each edge are cut into edge_refinement parts."""
    model = replace(independent_slices(), include_plate_coupling=True, include_body_torsion=True)
    coarse = replace(model, edge_refinement=1)
    pair = model.pair
    force = normal_force_from_torque(pair, 2000.0)
    u = 0.613 * pair.transverse_base_pitch
    pts, F, delta = model.load_distribution(u, force)
    ref_pts = coarse.contact_points(u)
    assert pts["s"].size > ref_pts["s"].size
    for key in set(zip(ref_pts["pair"].tolist(), ref_pts["helix"].tolist())):
        mine = (pts["pair"] == key[0]) & (pts["helix"] == key[1])
        theirs = (ref_pts["pair"] == key[0]) & (ref_pts["helix"] == key[1])
        assert pts["width"][mine].sum() == pytest.approx(ref_pts["width"][theirs].sum(), rel=1e-12)
        assert np.all(np.diff(pts["w_local"][mine]) * (1 if key[1] == 0 else -1) > 0)     # still in order
        assert set(np.round(ref_pts["width"][theirs][0] / pts["width"][mine], 9)) <= {1.0, 8.0}
    assert F.sum() == pytest.approx(force, rel=1e-12)
    loaded = F > 0
    approach = model.compliance(pts) @ F + model.gaps(pts)
    assert np.allclose(approach[loaded] + model.hertz(pts, F)[loaded], delta, rtol=1e-6)
    assert np.all(approach[~loaded] >= delta - 1e-12)
    # every change between loaded and released along a line lies between two cut segments
    coarse_width = {(k, h): w for k, h, w in zip(ref_pts["pair"], ref_pts["helix"], ref_pts["width"])}
    narrow = pts["width"] < 0.5 * np.array([coarse_width[k, h] for k, h in zip(pts["pair"], pts["helix"])])
    same_line = (pts["pair"][1:] == pts["pair"][:-1]) & (pts["helix"][1:] == pts["helix"][:-1])
    change = np.flatnonzero(same_line & (loaded[1:] != loaded[:-1]))
    assert change.size >= 1
    assert np.all(narrow[change]) and np.all(narrow[change + 1])
