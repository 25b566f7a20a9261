"""The coarse coupled test gearbox run-up shared by the run-up tests (built once per session)."""
import pytest

F_LINES = 1500.0
SPEEDS = [500.0, 1000.0, 1100.0]


@pytest.fixture(scope="session")
def coarse(comm):
    """(GearboxModel, source, lines, RunupResult): test gearbox on a 60 mm mesh, set A, 2000 N m, lines to 1.5 kHz,
    the source's stiffness at 32 positions per base pitch."""
    from housingfe.drivetrain.description import test_gearbox
    from housingfe.radiation.radiators import RADIATORS
    from housingfe.runup.chain import build_gearbox_model, runup, source_lines
    from housingfe.runup.scene import housing_model_for
    from housingfe.scene import load_housing_scene

    hs, _ = load_housing_scene("test-gearbox", ["mesh.size=0.06"])
    hm = housing_model_for(hs, F_LINES, comm)
    dt = test_gearbox("A")
    gm = build_gearbox_model(hm, dt, F_LINES, radiators={"erp": RADIATORS["erp"]()})
    src = dt.source_model(stiffness_positions=32)     # coarse too (the run-up's default is 128): test speed
    lines, _ = source_lines(src, SPEEDS, [2000.0], F_LINES)
    return gm, src, lines, runup(gm, None, SPEEDS, [2000.0], lines=lines)


@pytest.fixture(scope="session")
def scene_run(tmp_path_factory):
    """run(scene, settings) -> the output folder of `run_scene(scene, <folder>, settings)`, each distinct (scene,
    settings) run once per session: test_as_made, test_as_made_totals and test_imported_runup assert different
    things about the same coarse run-ups (the default one, and with runup.as_made = 5), which are deterministic, so
    one run serves all of them.  The folders are read, never written, by the tests."""
    from housingfe.runup.scene import run_scene

    done = {}

    def run(scene: str, settings: list[str]):
        key = (scene, tuple(settings))
        if key not in done:
            done[key] = run_scene(scene, str(tmp_path_factory.mktemp("scene_run") / "out"), list(settings))
        return done[key]

    return run
