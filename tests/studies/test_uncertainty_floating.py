"""`housingfe uncertainty` with a floating_axial_ratio: each sample's result says, per configuration it ran, what each
shaft's floating bearing held and whether its ring slid; the summary counts in how many samples each one's rings slid.

The bearings family (gear set B) at a pinned ratio of -0.15: a directional locating bearing (angular contact, tapered
roller) is relieved until it would lift off, so there the floating ring slides and holds less than ratio |F_r|; the
ball and self-aligning locating bearings take either direction and hold the request (docs/bearings.md).  Where the
tapered roller lifts off depends on its estimated calculation factor e (tapered_e_scale, a sampled internal, range
0.85-1.15): at 1.0 its wheel ring slides, at 1.15 both -- so each sample's statics carry its own internals (and the
slide cache keeps them apart in one process).  Statics only: the run-ups are flat synthetic curves (the floating cells do not depend on them),
every number is checked against Drivetrain.floating_axial_held computed here.  A ratio of 0 (pinned, or not drawn)
adds no column and no line."""
import csv
from types import SimpleNamespace

import numpy as np
import pytest

from housingfe.studies import uncertainty as unc

SPEEDS = np.array([800.0, 1150.0, 1500.0])
RATIO = -0.15


class _FlatRunup:
    def __init__(self, level: float):
        self.level = level

    def series(self, route, radiation, torque, what):
        return SPEEDS, np.full(len(SPEEDS), self.level)


@pytest.fixture()
def sample(monkeypatch):
    """evaluate_sample of the bearings family on the scene's drivetrains without the FE: a base with the scene (no
    bores renamed), flat run-ups (one level per bearing configuration), no check rows."""
    from housingfe.runup.scene import load_runup_scene

    scene, _ = load_runup_scene("test-gearbox-runup")
    spec = SimpleNamespace(torques_nm=scene.runup.torques_nm, routes=tuple(scene.runup.routes))
    base = SimpleNamespace(session=SimpleNamespace(scene=scene, spec=spec), surfaces={})
    levels = {b: 80.0 + i for i, b in enumerate(unc.BEARING_FAMILY)}
    monkeypatch.setattr(unc, "_sample_base", lambda *a: (base, 0.0, 0.0))
    monkeypatch.setattr(unc, "_runs", lambda base, values, gear_set, bearings, torque=None, engagements=(None,): (
        None, {e: _FlatRunup(levels[bearings]) for e in engagements}))
    monkeypatch.setattr(unc, "default_chain_checks", lambda *a: {})
    monkeypatch.setattr(unc, "_family_checks", lambda *a, **k: {})
    values = {**{k: v[0] for k, v in unc.nominal_ranges(scene).items()}, unc.MOUNT: None}
    values.update({k: None for k in unc.SIDES})          # the scene's wheel side, as the fresh drivetrains below

    def run(samples: list[dict], folder):
        samples = [{**values, **s} for s in samples]
        metrics = [unc.evaluate_sample("test-gearbox-runup", (), s, ("bearings",)) for s in samples]
        result = unc.UncertaintyResult("test-gearbox-runup", 1, samples, metrics, spec.routes, SPEEDS,
                                       ("bearings",), {}, "serial", 1,
                                       {"wall_s": 1.0, "per_sample_s": 1.0, "per_sample_cpu_s": 1.0,
                                        "basis_per_process_s": 0.0, "processes": 1})
        unc.write(folder, result)
        with open(folder / "samples.csv") as fh:
            return result, list(csv.DictReader(fh))
    return run


def _held(bearings: str, e_scale: float) -> dict:
    """A fresh Drivetrain.floating_axial_held of gear set B with `bearings` at the scene's top torque, ratio -0.15."""
    from housingfe.bearings.catalogue import estimated_internals
    from housingfe.studies.chain_session import ChainSession

    session = ChainSession.from_scene("test-gearbox-runup", [f"drivetrain.floating_axial_ratio={RATIO}"])
    with estimated_internals(tapered_e_scale=e_scale):
        return session.drivetrain("B", bearings, max(session.spec.torques_nm)).floating_axial_held()


def test_each_sample_says_which_configurations_floating_rings_slid(sample, tmp_path):
    result, rows = sample([{unc.FLOATING_AXIAL: RATIO, "tapered_e_scale": 1.0},
                           {unc.FLOATING_AXIAL: RATIO, "tapered_e_scale": 1.15}], tmp_path)
    want_slid = ({"ball": [], "angular_contact": ["pinion", "wheel"], "self_aligning": [], "tapered_roller": ["wheel"]},
                 {"ball": [], "angular_contact": ["pinion", "wheel"], "self_aligning": [], "tapered_roller": ["pinion", "wheel"]})
    for row, e_scale, want in zip(rows, (1.0, 1.15), want_slid):
        assert float(row[unc.FLOATING_AXIAL]) == RATIO
        assert row["A_ball_floating_rings_slid"] == "none"          # set A, ball: the default chain's configuration
        for bearings in unc.BEARING_FAMILY:
            label = f"B_{bearings}"
            slid = []
            for shaft, (requested, held) in _held(bearings, e_scale).items():
                assert float(row[f"{label}_{shaft}_floating_requested_N"]) == pytest.approx(requested, abs=0.05)
                assert float(row[f"{label}_{shaft}_floating_held_N"]) == pytest.approx(held, abs=0.05)
                assert requested == pytest.approx(RATIO * 2e4, rel=0.5)   # -0.15 |F_r| of some 20 kN: kN
                if abs(held) < abs(requested) - 1.0:                    # slid: well below the request (> 1 N)
                    assert np.sign(held) == np.sign(requested)
                    slid.append(shaft)
                else:
                    assert held == requested
            assert slid == want[bearings], (label, e_scale)
            assert row[f"{label}_floating_rings_slid"] == (" ".join(slid) or "none")
    line = ("floating rings slid (drivetrain.floating_axial_ratio != 0; held loads per sample in samples.csv "
            "*_floating_*): A_ball 0/2, B_ball 0/2, B_angular_contact 2/2 (pinion 2, wheel 2), B_self_aligning 0/2, "
            "B_tapered_roller 2/2 (pinion 1, wheel 2)")
    assert line in unc.summary_text(result).splitlines()
    assert line in (tmp_path / "summary.txt").read_text().splitlines()


def test_a_ratio_of_zero_adds_no_column_and_no_line(sample, tmp_path):
    result, rows = sample([{unc.FLOATING_AXIAL: 0.0}, {unc.FLOATING_AXIAL: None}], tmp_path)
    assert not [c for c in rows[0] if "floating" in c and c != unc.FLOATING_AXIAL]
    assert [r[unc.FLOATING_AXIAL] for r in rows] == ["0.0", ""]
    assert "floating" not in unc.summary_text(result)
