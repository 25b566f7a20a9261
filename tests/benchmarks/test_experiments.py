"""The experiment scripts under benchmarks/experiments keep working against the package's API (they live outside
it, so nothing else would notice a changed signature)."""
import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_layers_experiment_gives_the_layer_size_mesh():
    """2 layers through the walls and 4 through the flange by hand are mesh.layer_size = 4 mm's mesh: the same
    31 926 DOFs and, like tests/fe/test_element_families.py, below 1 % on the free box."""
    script = ROOT / "benchmarks" / "experiments" / "same_mesh" / "layers.py"
    proc = subprocess.run([sys.executable, str(script), "0.030:2:4:0.5"], cwd=ROOT, capture_output=True, text=True,
                          env=dict(os.environ, OPENBLAS_NUM_THREADS="1"), timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    found = re.search(r"DOFs\s+(\d+)\s+[\d.]+ s\s+max ([\d.]+) %", proc.stdout)
    assert found, proc.stdout
    assert int(found.group(1)) == 31926
    assert float(found.group(2)) < 1.0


def test_lomega_budget_first_order_is_the_full_balance():
    """The L_omega budget (benchmarks/experiments/lomega_budget) splits the tooth line into TE x receptance on the
    mean-stiffness system; that split holds only while the parametric feedback is small: the first-order tooth-band
    L_omega must agree with the full harmonic balance within the stiffness ripple's effect (1.8 % = 0.16 dB) for both
    engagement models at 500 / 1000 / 1500 rpm."""
    script = ROOT / "benchmarks" / "experiments" / "lomega_budget" / "lomega_budget.py"
    proc = subprocess.run([sys.executable, str(script), "--lumped-only"], cwd=ROOT, capture_output=True, text=True,
                          env=dict(os.environ, OPENBLAS_NUM_THREADS="1"), timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    rows = re.findall(r"\|\s*([\d.]+) / ([\d.]+) \| ([\d.]+) / ([\d.]+) \|\s*$", proc.stdout, re.M)
    assert len(rows) == 3, proc.stdout
    for fo_fw, fo_2d, full_fw, full_2d in rows:
        assert abs(float(fo_fw) - float(full_fw)) <= 0.16
        assert abs(float(fo_2d) - float(full_2d)) <= 0.16


def test_as_made_experiment_keeps_the_aligned_model_and_its_stiffness(tmp_path):
    """benchmarks/experiments/as_made: the aligned pair's tooth line is the default's quasi-static TE (0.56 um,
    docs/source.md), the point stiffnesses sum to the mesh stiffness k_m, and grade-5 deviations raise the tooth band
    above the aligned model's 0.56 um but keep it under 5 um (docs/source.md, 'Gears as made': 1.0-1.8 um)."""
    script = ROOT / "benchmarks" / "experiments" / "as_made" / "as_made.py"
    proc = subprocess.run([sys.executable, str(script), "--draws", "8", "--no-exact", "--rigid-only", "--out",
                           str(tmp_path)],
                          cwd=ROOT, capture_output=True, text=True, env=dict(os.environ, OPENBLAS_NUM_THREADS="1"),
                          timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    line = re.search(r"aligned pair alone .*tooth line ([\d.]+) um", proc.stdout)
    assert line and abs(float(line.group(1)) - 0.56) < 0.01, proc.stdout
    k = re.search(r"sum k_i = ([\d.e+]+) N/m .*k_m = ([\d.e+]+) N/m", proc.stdout)
    assert abs(float(k.group(1)) / float(k.group(2)) - 1) < 1e-3
    band = re.search(r"^\| all \| [^|]+\| ([\d.]+) / ([\d.]+) / ([\d.]+) \[", proc.stdout, re.M)
    assert band, proc.stdout
    assert all(0.6 < float(x) < 5.0 for x in band.groups())
    assert (tmp_path / "as_made.csv").is_file() and (tmp_path / "as_made.png").is_file()


def test_reindex_experiment_moves_only_the_shared_orders(tmp_path):
    """benchmarks/experiments/reindex (the pinion turned by 8 and 16 teeth, thesis Sec. 5.6): the aligned tooth line is
    the default's 0.56 um (docs/source.md); with "runout" pitch the pinion's pitch lines (72 n +- 3) share no order with
    the wheel's (72 n +- 1), so only the flanks' cross terms move the level and the per-draw s.d. of the tooth band's
    L(turned) - L(0) stays below the "independent" model's, whose pinion and wheel pitch spectra share every 3rd
    order (50 draws: medians 0.15 and 0.65 dB); and "none" (no pitch deviation) puts almost none of the change at
    72 n +- 3 and +- 6, where the independent model's low pitch orders put most of it."""
    script = ROOT / "benchmarks" / "experiments" / "reindex" / "reindex.py"
    proc = subprocess.run([sys.executable, str(script), "--draws", "6", "--rigid-only", "--out", str(tmp_path)],
                          cwd=ROOT, capture_output=True, text=True, env=dict(os.environ, OPENBLAS_NUM_THREADS="1"),
                          timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    line = re.search(r"aligned tooth line ([\d.]+) um", proc.stdout)
    assert line and abs(float(line.group(1)) - 0.56) < 0.01, proc.stdout
    sd = {m: float(re.search(rf"^\| {m} \| rigid: tooth \| 50-1500 \| [^|]+\| ([\d.]+) \[", proc.stdout, re.M).group(1))
          for m in ("independent", "runout")}
    assert sd["runout"] < sd["independent"], proc.stdout
    share = {m: float(re.search(rf"^{m}: share .* median (\d+) %", proc.stdout, re.M).group(1))
             for m in ("independent", "none")}
    assert share["independent"] > 50 and share["none"] < 20, proc.stdout
    assert all((tmp_path / f).is_file() for f in ("reindex.csv", "reindex_summary.csv", "reindex.png"))


def test_frame_mount_modes_approach_the_rigid_gearbox_on_soft_springs():
    """benchmarks/experiments/frame_mount: the run-up's coupled gearbox (housing, shafts, gears, bearings, drive line)
    with its feet on a soft frame (K_v = 1e7 N/m, coarse mesh, built as `housingfe run test-gearbox-runup` builds it)
    has no zero mode, and its six lowest mount modes (most strain energy in the springs) are the six-DOF rigid
    gearbox on the spring bed within 1 % (measured 0-0.7 %: 15.4-47.9 Hz): the interior's flexibility (its modes from
    77 Hz) barely lowers them.
    A mount the coupled model dropped would leave zero modes or none "on the mount"."""
    import importlib.util

    import numpy as np

    path = ROOT / "benchmarks" / "experiments" / "frame_mount" / "frame_mount.py"
    spec = importlib.util.spec_from_file_location("frame_mount", path)
    frame_mount = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(frame_mount)
    rows = frame_mount.mode_rows("1e7", "coarse")
    mount = [r for r in rows if r["kind"] == "coupled_mode" and r["type"] == "on the mount"]
    estimate = sorted(r["frequency_hz"] for r in rows if r["kind"] == "rigid_estimate")
    assert len(mount) == 6, rows
    fe = np.array(sorted(r["frequency_hz"] for r in mount))
    assert fe[0] > 5.0
    assert np.allclose(fe, estimate, rtol=0.01), (fe, estimate)
    assert np.all(fe <= np.array(estimate) * (1 + 1e-3))     # Rayleigh-Ritz: the estimate bounds from above
    mass = next(r for r in rows if r["kind"] == "mass")["rigid_motion"]
    assert 160.0 < float(mass.split()[1]) < 180.0, mass       # housing 110.6 kg + interior


def test_sa_housing_experiment_keeps_its_two_load_paths(tmp_path):
    """benchmarks/experiments/sa_housing (why self-aligning bearings' T_housing has opposite signs on the two routes)
    rests on: the wheel torque of route tf_omega loads the bores as the mesh force pair does (tooth-line T_housing
    equal within 0.1 dB, ball and self-aligning), the shuttling moment makes mesh_force's bore forces (> 10 dB above
    the pair's), the self-aligning bearings put no moment on the bores (zero moment rows, shaft node at the bore
    master: below -200 dB re 1 N m), and self-aligning bearings raise the pair's axial share of the bore force and
    lower the shuttling moment's.  On the coarse gearbox (60 mm mesh, lines to 1.5 kHz; ~20 s)."""
    import csv

    script = ROOT / "benchmarks" / "experiments" / "sa_housing" / "sa_housing.py"
    proc = subprocess.run([sys.executable, str(script), "--coarse", "--no-variants", "--out", str(tmp_path)],
                          cwd=ROOT, capture_output=True, text=True,
                          env=dict(os.environ, OPENBLAS_NUM_THREADS="1", PYTHONPATH=str(ROOT)), timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    rows = {(r["config"], r["part"]): {k: float(v) for k, v in r.items() if k.endswith("_dB")}
            for r in csv.DictReader(open(tmp_path / "load_parts.csv")) if r["harmonic"] == "1"}
    for cfg in ("ball", "self_aligning"):
        assert abs(rows[cfg, "tf_omega"]["T_housing_dB"] - rows[cfg, "mesh pair only"]["T_housing_dB"]) < 0.1
        assert rows[cfg, "shuttling moment only"]["L_bore_dB"] > rows[cfg, "mesh pair only"]["L_bore_dB"] + 10
    for part in ("tf_omega", "mesh_force"):
        assert rows["self_aligning", part]["L_bore_moment_dB"] < -200
    share = {k: v["axial_minus_radial_dB"] for k, v in rows.items()}
    assert share["self_aligning", "mesh pair only"] > share["ball", "mesh pair only"] + 3
    assert share["self_aligning", "shuttling moment only"] < share["ball", "shuttling moment only"] - 10


def _experiment(name):
    """The script benchmarks/experiments/<name>/<name>.py as a module."""
    import importlib.util

    path = ROOT / "benchmarks" / "experiments" / name / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _floating_axial():
    return _experiment("floating_axial")


def test_floating_axial_stick_criterion_by_hand():
    """benchmarks/experiments/floating_axial: a speed with two harmonic lines of rms axial force 3+4j N and 1j N has
    a time peak of at most sqrt(2) (5 + 1) = 8.485 N and an rms of sqrt(26) N; a rotating radial line (1, 1j, 0) N rms
    peaks at sqrt(2) sqrt(2) = 2 N.  With F_r = 1000 N, a dynamic radial peak of 200 N and mu = 0.1 the fit holds
    0.1 (1000 - 200) = 80 N: margin 80 / 8.485 = 9.43; a radial load the vibration lifts off holds nothing."""
    import numpy as np

    fa = _floating_axial()
    keys, peak, rms = fa.peak_and_rms(np.array([3 + 4j, 1j, 7.0]), np.array([100.0, 100.0, 200.0]))
    assert list(keys) == [100.0, 200.0]
    assert np.allclose(peak, [6 * np.sqrt(2), 7 * np.sqrt(2)])
    assert np.allclose(rms, [np.sqrt(26), 7.0])
    _, rpeak, _ = fa.peak_and_rms(np.array([[1.0, 1j, 0.0]]), np.array([1.0]))
    assert np.isclose(rpeak[0], 2.0)
    assert np.isclose(fa.stick_margin(6 * np.sqrt(2), 1000.0, 200.0, 0.1), 80 / (6 * np.sqrt(2)))
    assert fa.stick_margin(1.0, 1000.0, 1200.0, 0.2) == 0.0
    # coherent lines: f = sqrt(2) (cos t - cos 3t) = 4 sqrt(2) c (1 - c^2), c = cos t, peaks at c = 1/sqrt(3):
    # 8 sqrt(2) / (3 sqrt(3)) = 2.177 N, below the bound 2 sqrt(2)
    assert np.isclose(fa.synthesised_peak(np.array([1.0, -1.0]), np.array([1, 3]), np.array([5.0, 5.0]))[0],
                      8 * np.sqrt(2) / (3 * np.sqrt(3)), rtol=1e-3)


def test_floating_axial_experiment_runs_coarse(tmp_path):
    """benchmarks/experiments/floating_axial on the coarse default run-up (60 mm mesh, lines to 1.5 kHz; ~15 s): the
    floating bearings get no axial force in the statics, the linear interior on rigid bores shares each shaft's
    axial mesh force between its two bearings (their sum = the locating bearing's statics force, equilibrium), and the
    margins of margins.csv are the smallest over the speeds of mu (F_r - F_r_dyn) / F_a_dyn recomputed from the
    per-speed rows."""
    import csv

    import numpy as np

    script = ROOT / "benchmarks" / "experiments" / "floating_axial" / "floating_axial.py"
    proc = subprocess.run([sys.executable, str(script), "--coarse", "--only-default", "--out", str(tmp_path)],
                          cwd=ROOT, capture_output=True, text=True,
                          env=dict(os.environ, OPENBLAS_NUM_THREADS="1", PYTHONPATH=str(ROOT)), timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    static = {r["bearing"]: r for r in csv.DictReader(open(tmp_path / "static.csv"))}
    for shaft in ("pinion", "wheel"):
        front, back = static[f"{shaft}_front"], static[f"{shaft}_back"]
        assert front["role"] == "locating" and back["role"] == "floating"
        assert float(back["F_a_statics_N"]) == 0.0
        assert abs(float(front["F_a_statics_N"])) > 5000.0          # the helical mesh's axial force
        total = float(front["F_a_linear_rigid_bores_N"]) + float(back["F_a_linear_rigid_bores_N"])
        assert np.isclose(total, float(front["F_a_statics_N"]), rtol=1e-4)
    rows = list(csv.DictReader(open(tmp_path / "floating_axial.csv")))
    margins = list(csv.DictReader(open(tmp_path / "margins.csv")))
    assert {(m["route"], m["bearing"]) for m in margins} == {(r, b) for r in ("tf_omega", "mesh_force")
                                                              for b in ("pinion_back", "wheel_back")}
    for m in margins:
        sel = [r for r in rows if r["route"] == m["route"] and r["bearing"] == m["bearing"]]
        for mu in (0.1, 0.2):
            by_hand = min(mu * (float(r["F_r_static_N"]) - float(r["F_r_dyn_peak_N"])) / float(r["F_a_dyn_peak_N"])
                          for r in sel)
            assert np.isclose(float(m[f"min_margin_mu{mu:g}_dB"]), 20 * np.log10(by_hand), atol=0.01)


def test_first_mode_rayleigh_sensitivity_two_springs():
    """benchmarks/experiments/first_mode: masses m1 = 2, m2 = 1 kg, k1 (ground-m1) = 3e6, k2 (m1-m2) = 1e6 N/m.  The
    closed-form eigenfrequencies of the 2x2 problem, differentiated numerically in ln k1 (step 1e-6), give
    d f / d ln k1 for both modes; the experiment's Rayleigh sensitivity f/2 x (k1's strain energy share) must match to
    1e-6, and a single spring-mass (k1 alone, m1) gives exactly f/2."""
    from types import SimpleNamespace

    import numpy as np
    import scipy.linalg

    fm = _experiment("first_mode")
    M = np.diag([2.0, 1.0])

    def K_parts(k1, k2):
        return np.array([[k1, 0.0], [0.0, 0.0]]), np.array([[k2, -k2], [-k2, k2]])

    def system(k1, k2):
        K = sum(K_parts(k1, k2))
        lam, Y = scipy.linalg.eigh(K, M)
        return SimpleNamespace(Kr=K, Mr=M, Y=Y, frequencies_hz=np.sqrt(lam) / (2 * np.pi))

    def closed_form(k1, k2):            # det(K - w^2 M) = 0: 2 w^4 - (k1 + 3 k2) w^2 + k1 k2 = 0
        b, c = k1 + 3 * k2, k1 * k2
        w2 = np.array([(b - np.sqrt(b * b - 8 * c)) / 4, (b + np.sqrt(b * b - 8 * c)) / 4])
        return np.sqrt(w2) / (2 * np.pi)

    k1, k2, h = 3e6, 1e6, 1e-6
    s = system(k1, k2)
    assert np.allclose(s.frequencies_hz, closed_form(k1, k2), rtol=1e-12)
    dfd = (closed_form(k1 * np.exp(h), k2) - closed_form(k1 * np.exp(-h), k2)) / (2 * h)
    for j in range(2):
        got = fm.rayleigh_sensitivity(s, K_parts(k1, k2)[0], j)
        assert abs(got / dfd[j] - 1) < 1e-6, (j, got, dfd[j])
        # both parts' shares make the whole: scaling every stiffness by x scales f by sqrt(x)
        both = got + fm.rayleigh_sensitivity(s, K_parts(k1, k2)[1], j)
        assert abs(both - s.frequencies_hz[j] / 2) < 1e-9 * s.frequencies_hz[j]
    one = SimpleNamespace(Kr=np.array([[k1]]), Mr=np.array([[2.0]]), Y=np.array([[1 / np.sqrt(2.0)]]),
                          frequencies_hz=np.array([np.sqrt(k1 / 2.0) / (2 * np.pi)]))
    assert np.isclose(fm.rayleigh_sensitivity(one, np.array([[k1]]), 0), one.frequencies_hz[0] / 2, rtol=1e-14)


def test_first_mode_experiment_runs_coarse(tmp_path):
    """benchmarks/experiments/first_mode on the coarse default gearbox (60 mm mesh, lines to 1.5 kHz; ~30 s, no
    sweep): every mode's kinetic and strain energy shares of the parts (housing from its FE matrices, the interior's
    elements projected on their nodes' rows: independent of the coupled K, M) add to 1 within 1e-6; each part's
    Rayleigh sensitivity equals the finite difference of the re-analysed system (with_change) within 1 %; the
    re-analysis of the drivetrain with all four bearings' K x (1 +/- 2 %) (with_drivetrain: the coupled matrices
    re-projected) gives the sum of the four bearings' Rayleigh sensitivities within 2 %; the first mode is the wheel's
    (its wheel_front bearing holds the largest strain energy share)."""
    import csv

    import numpy as np

    script = ROOT / "benchmarks" / "experiments" / "first_mode" / "first_mode.py"
    proc = subprocess.run([sys.executable, str(script), "--coarse", "--no-sweep", "--out", str(tmp_path)],
                          cwd=ROOT, capture_output=True, text=True,
                          env=dict(os.environ, OPENBLAS_NUM_THREADS="1", PYTHONPATH=str(ROOT)), timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    energies = list(csv.DictReader(open(tmp_path / "energies.csv")))
    modes = sorted({float(r["frequency_Hz"]) for r in energies})
    assert 150 < modes[0] < 300, modes
    for f in modes:
        rows = [r for r in energies if float(r["frequency_Hz"]) == f]
        assert abs(sum(float(r["kinetic_share"]) for r in rows) - 1) < 1e-6
        assert abs(sum(float(r["strain_share"]) for r in rows) - 1) < 1e-6
    first = [r for r in energies if float(r["frequency_Hz"]) == modes[0]]
    assert max(first, key=lambda r: float(r["strain_share"]))["part"] == "bearing wheel_front"
    sens = list(csv.DictReader(open(tmp_path / "sensitivities.csv")))
    for r in sens:
        if r["kind"] == "part stiffness" and abs(float(r["df_dlnp_Hz"])) > 0.1:
            assert np.isclose(float(r["df_dlnp_Hz"]), float(r["df_dlnp_fd_Hz"]), rtol=0.01), r
    f1 = min(float(r["mode_Hz"]) for r in sens)
    bearings = sum(float(r["df_dlnp_Hz"]) for r in sens if float(r["mode_Hz"]) == f1
                   and r["kind"] == "part stiffness" and r["input"].startswith("bearing "))
    whole = next(float(r["df_dlnp_Hz"]) for r in sens if float(r["mode_Hz"]) == f1
                 and r["input"] == "bearing stiffness (all four)")
    assert bearings > 10 and np.isclose(whole, bearings, rtol=0.02), (whole, bearings)


def test_housing_reconstruction_experiment_runs_coarse(tmp_path):
    """benchmarks/experiments/housing_reconstruction on the coarse gearbox (60 mm mesh, lines to 1.5 kHz; the default
    and the 11.5 mm wall, ~25 s, and `housingfe run` of the same coarse scene, ~12 s):

    * the default variant is the scene's own run: its mesh_force slope terms and max L_WA are those of
      `housingfe run`'s slope_terms.csv and checks.csv;
    * the rows add up: excitation + transfer + L_sigma + A = L_WA, T_path + T_housing = transfer, and the
      speed-law check's fit equals the decomposition's L_WA slope;
    * the wall thickening is what it says: walls grow inward (outer size kept), so by hand the housing gains
      rho [(L W H - (L - 2t)(W - 2t)(H - t)) change - 2 x 0.438 x 0.242 dt (the bearing plates' proud part, 65 mm
      in all, loses dt) - 2 L x 31.25 mm dt (the feet's outside part)] = 3.259 kg for t = 10 -> 11.5 mm;
    * a thicker wall raises the first housing mode (interior share < 0.5) but by less than sqrt(1.15^3) = 1.233
      (Rayleigh: the walls' bending stiffness grows at most as t^3, their mass as t, the other parts unchanged)."""
    import csv

    script = ROOT / "benchmarks" / "experiments" / "housing_reconstruction" / "housing_reconstruction.py"
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", PYTHONPATH=str(ROOT))
    proc = subprocess.run([sys.executable, str(script), "--coarse", "--only", "default", "wall 11.5 mm", "--out",
                           str(tmp_path)], cwd=ROOT, capture_output=True, text=True, env=env, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    cli = tmp_path / "cli"
    proc = subprocess.run([sys.executable, "-m", "housingfe", "run", "test-gearbox-runup", "--set",
                           'housing.set=["mesh.size=0.06"]', "--set", "runup.f_max_hz=1500.0", "--out", str(cli)],
                          cwd=ROOT, capture_output=True, text=True, env=env, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    slopes = {(r["variant"], r["route"]): {k: (float(v) if k not in ("variant", "route", "speed_law_passes") else v)
                                           for k, v in r.items()}
              for r in csv.DictReader(open(tmp_path / "slopes.csv"))}
    assert set(slopes) == {(v, r) for v in ("default", "wall 11.5 mm") for r in ("mesh_force", "tf_omega")}
    terms = {r["term"]: float(r["slope_dB_per_doubling"]) for r in csv.DictReader(open(cli / "slope_terms.csv"))
             if (r["route"], r["radiation"], r["basis"]) == ("mesh_force", "erp", "total")}
    ours = slopes["default", "mesh_force"]
    for mine, theirs in (("speed_law", "L_WA"), ("excitation", "excitation"), ("T_path", "transfer_path"),
                         ("T_housing", "transfer_housing"), ("A_weighting", "A_weighting")):
        assert abs(ours[mine] - terms[theirs]) < 1e-4, (mine, ours[mine], terms[theirs])
    lwa_max = next(float(r["ours"]) for r in csv.DictReader(open(cli / "checks.csv"))
                   if r["check"] == "LwA_max" and r["quantity"].startswith("mesh_force"))
    assert abs(ours["max_LWA_dBA"] - lwa_max) <= 0.05 + 1e-9
    for row in slopes.values():
        assert abs(row["excitation"] + row["transfer"] + row["L_sigma"] + row["A_weighting"] - row["L_WA"]) < 1e-4
        assert abs(row["T_path"] + row["T_housing"] - row["transfer"]) < 1e-4
        assert abs(row["speed_law"] - row["L_WA"]) < 1e-4
    var = {r["variant"]: r for r in csv.DictReader(open(tmp_path / "variants.csv"))}
    L, W, H, t0, t1 = 0.49, 0.17, 0.3753, 0.010, 0.0115

    def shell(t):
        return L * W * H - (L - 2 * t) * (W - 2 * t) * (H - t)
    gain = 7850.0 * (shell(t1) - shell(t0) - 2 * 0.438 * 0.242 * (t1 - t0) - 2 * L * 0.03125 * (t1 - t0))
    assert abs(gain - 3.2595) < 1e-3
    got = float(var["wall 11.5 mm"]["housing_mass_kg"]) - float(var["default"]["housing_mass_kg"])
    assert abs(got - gain) < 0.01, (got, gain)
    ratio = float(var["wall 11.5 mm"]["first_housing_mode_Hz"]) / float(var["default"]["first_housing_mode_Hz"])
    assert 1.0 < ratio < 1.15 ** 1.5, ratio


def test_relief_tolerance_grid_by_hand_and_coupled_stiffness_follows():
    """benchmarks/experiments/relief_tolerance: ISO 1328-1:1995 grade 5 f_Halpha = 2 sqrt(m) + 0.14 sqrt(d) + 0.5 um
    with the geometric means of the ranges m 2-3.5 mm (sqrt 7) and d 50-125 / 280-560 mm: 4.998 -> 5.0 um (pinion),
    6.539 -> 6.5 um (wheel), so the corner p+w- is (25, 35.5) um.  The amounts are patched where the gear set is
    built: the coupled model's mean mesh stiffness at 1000 N m drops with more relief (less flank in contact) and the
    lengths stay Appendix F's 2.2 / 3.3 mm (~3 s)."""
    import math

    rt = _experiment("relief_tolerance")
    m, d1, d2 = math.sqrt(2 * 3.5), math.sqrt(50 * 125), math.sqrt(280 * 560)
    assert abs(2 * math.sqrt(m) + 0.14 * math.sqrt(d1) + 0.5 - 4.998) < 1e-3
    assert abs(2 * math.sqrt(m) + 0.14 * math.sqrt(d2) + 0.5 - 6.539) < 1e-3
    assert rt.profile_slope_tolerances() == (5.0, 6.5)
    assert rt.amounts("p+w-") == (25.0, 35.5) and rt.amounts("p0w0") == (20.0, 42.0)
    from housingfe.drivetrain.description import test_gearbox

    nominal = test_gearbox("double_helical", "cylindrical_roller", 1000.0)
    rt.patch_amounts(25.0, 48.5)
    try:
        more = test_gearbox("double_helical", "cylindrical_roller", 1000.0)
    finally:
        from housingfe.source.roosmalen import run as roosmalen
        roosmalen.build = roosmalen.build.__wrapped__
    assert math.isclose(nominal.gears.corrections.tip_relief[0], 20e-6)
    assert math.isclose(nominal.gears.corrections.tip_relief[1], 42e-6)
    assert math.isclose(more.gears.corrections.tip_relief[0], 25e-6)
    assert math.isclose(more.gears.corrections.tip_relief[1], 48.5e-6)
    assert more.gears.corrections.tip_relief_length == nominal.gears.corrections.tip_relief_length
    assert more.gear_forces().stiffness < 0.995 * nominal.gear_forces().stiffness
