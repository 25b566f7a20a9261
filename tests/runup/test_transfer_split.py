"""The transfer split into path and housing (housingfe.runup.slopes, the bore loads of housingfe.runup.chain
.route_bore_loads) on the coarse coupled test gearbox (set A, 2000 N m, no drive line, fixed feet):

* T_path + T_housing = T per operating point and in slope, to round-off, on both bases and routes; L_bore of the
  mesh_force route is 10 lg sum |F|^2 of the bearings' bore loads.
* Statics: far below the first coupled mode (212 Hz) the shafts and gears are in equilibrium, so the loads the
  bearings put on the bores add up to what is applied to the interior (the bearings are its only tie to the
  housing; no drive line here): a unit force on the wheel or the pinion gives sum F_bore = that force, and the
  bores' moments about the origin (moment at each master + r_bore x F) add up to the applied moment.  What is
  left is the interior's inertia and modal damping, bounded by (f/f_1)^2 + 2 xi f/f_1.  A wrong sign or the shaft
  node's rows instead of the bore's give -F (an error of 2), rows mixed up the wrong components.
* The static mesh pair: the gears turn freely apart from the mesh (no drive line), so the mesh spring takes a
  static mesh pair whole (g(0) = 1/k_ref, chain.static_mesh_receptance) and the bearings carry only the
  inertia share, bounded likewise.
"""
import numpy as np
import pytest

from housingfe.drivetrain.bore_loads import force_level_db
from housingfe.runup.slopes import SPLIT, decompose_all

F_LOW = 1.0         # Hz, far below the first coupled mode of the coarse gearbox (212 Hz)
XI = 0.04           # the run-up's modal damping ratio


@pytest.mark.slow
def test_path_plus_housing_is_the_transfer(coarse):
    gm, src, lines, res = coarse
    ds = decompose_all(res)
    assert {d.route for d in ds} == {"tf_omega", "mesh_force"}
    for d in ds:
        assert d.has_split, d.sentence()
        np.testing.assert_allclose(d.levels["transfer_path"] + d.levels["transfer_housing"], d.levels["transfer"],
                                   atol=1e-9)
        assert abs(d.split_residual_db) < 1e-9
        assert d.term_sum == pytest.approx(d.slopes["L_WA"], abs=1e-9)     # the five terms untouched
    mf = res.routes["mesh_force"]
    np.testing.assert_allclose(mf.bore_force_db, force_level_db(mf.bore_loads), atol=1e-12)
    assert mf.bore_loads.shape == (len(lines.frequency), 4, 6)
    tooth = np.flatnonzero(lines.harmonic == 1)
    d = next(d for d in ds if d.route == "mesh_force" and d.basis == "tooth_band")
    np.testing.assert_allclose(d.levels["L_bore"], mf.bore_force_db[tooth], atol=1e-9)
    np.testing.assert_allclose(d.levels["transfer_housing"], mf.L_v[tooth] - mf.bore_force_db[tooth], atol=1e-9)
    # tf_omega's coefficients are under 1 N m of wheel torque: its L_bore is scaled as its L_v is
    tf = res.routes["tf_omega"]
    shift = tf.L_v - tf.response.velocity_level_db
    np.testing.assert_allclose(tf.bore_force_db, force_level_db(tf.bore_loads) + shift, atol=1e-9)
    assert set(SPLIT) <= set(d.slopes)


@pytest.mark.slow
def test_bore_loads_balance_the_applied_load_at_low_frequency(coarse):
    from housingfe.response.reduced import RitzReduction
    from housingfe.runup.chain import bearing_pairs, route_bore_loads, with_reduction
    from housingfe.solvers import harmonic

    gm, _, _, _ = coarse
    st = gm.structure
    assert not st.spec.drive_lines
    f1 = gm.basis.frequencies_hz[gm.basis.rigid_count]
    assert f1 > 150.0
    bound = (F_LOW / f1) ** 2 + 2 * XI * F_LOW / f1        # ~4e-4: the interior's inertia and modal damping
    pinion = f"pinion:{gm.drivetrain.shaft_nodes('pinion')[1]['gear']}"
    d = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    loads = {"force_wheel": st.node_load(gm.wheel_node, "force", d, "test"),
             "force_pinion": st.node_load(pinion, "force", d, "test"),
             "moment_wheel": st.node_load(gm.wheel_node, "moment", [1.0, 0.0, 0.0], "test")}
    damping = harmonic.Damping(lambda f: np.zeros(np.shape(f)), modal_ratio=XI)
    red = RitzReduction(gm.basis, loads, damping, nodes=(gm.wheel_node,), static_vectors=bearing_pairs(st))
    model = with_reduction(gm, red)
    pos = st.parts.positions
    bores = [b.bore for b in st.spec.bearings]
    applied = {"force_wheel": (gm.wheel_node, d, np.zeros(3)), "force_pinion": (pinion, d, np.zeros(3)),
               "moment_wheel": (gm.wheel_node, np.zeros(3), np.array([1.0, 0.0, 0.0]))}
    for name, (node, F, M) in applied.items():
        c = red.coefficients([F_LOW], {name: 1.0})
        L = route_bore_loads(model, [F_LOW], [1000.0], c)[0]        # (bearings, 6), complex per unit load
        assert L.shape == (4, 6)
        assert np.max(np.abs(L[:, :3].sum(axis=0) - F)) < bound, (name, L[:, :3].sum(axis=0))
        moment = sum(L[i, 3:] + np.cross(pos[b], L[i, :3]) for i, b in enumerate(bores))
        # moments (N m per N or per N m) about the origin: lever arms ~0.2 m
        assert np.max(np.abs(moment - (M + np.cross(pos[node], F)))) < bound, (name, moment)
    # the pinion's force goes into the pinion's bores (the wheel's carry the part the mesh passes on)
    c = red.coefficients([F_LOW], {"force_pinion": 1.0})
    L = route_bore_loads(model, [F_LOW], [1000.0], c)[0]
    assert np.linalg.norm(L[:2, :3].sum(axis=0)) > 0.5
    # the static mesh pair is the mesh spring's: the bearings carry the inertia share only
    c = gm.reduction.coefficients([F_LOW], {"mesh": 1.0})
    L = route_bore_loads(gm, [F_LOW], [1000.0], c)[0]
    assert np.max(np.abs(L[:, :3])) < bound
