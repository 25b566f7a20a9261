"""`housingfe bench radiation`: numerical radiation efficiency, time per frequency against error.

Cases with analytic references (ka = 0.1 ... 5, radius a = 0.1 m):
- pulsating sphere, sigma = (ka)^2 / (1 + (ka)^2)   - exterior Helmholtz FE (BGT2 on r = 1.5 a)
- oscillating sphere (v_n = cos theta, sampled), sigma = (ka)^4 / (4 + (ka)^4) - FE
- baffled piston, sigma = 1 - J1(2ka)/(ka)          - FE (BGT2 or PML) and the Rayleigh integral
- 60-degree cap vibrating on a rigid sphere (one 'plate' of a closed body), spherical-harmonic series - FE
Writes radiation_bench.csv (one row per case/setting/ka), radiation_bench_summary.csv, radiation_bench.png,
and (full run) radiation_box_comparison.csv: a box with its faces in their (1,1) mode, closed-body FE
next to baffled plates and Föller's estimate - an illustration of the later housing check, not a verification.

The comparison of Föller's box estimate with the numerical sigma of the real housing needs the housing's
forced response: `compare_box_estimate_with_numerical` takes its surface data when it exists.
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from housingfe.outputs import atomic_output_dir, format_table, write_csv
from housingfe.radiation import analytic, fem, foller, numerical

A = 0.1  # m
KA = np.array([0.1, 0.2, 0.5, 1.0, 2.0, 3.0, 4.0, 5.0])


def _fibonacci_sphere(n: int, radius: float) -> np.ndarray:
    i = np.arange(n) + 0.5
    z = 1 - 2 * i / n
    phi = np.pi * (1 + 5**0.5) * i
    r = np.sqrt(1 - z**2)
    return radius * np.column_stack([r * np.cos(phi), r * np.sin(phi), z])


def _fem_cases(quick: bool):
    """(case, method, setting label, geometry, velocity, truncation, reference sigma(ka))."""
    sphere_h = [(0.4, 0.25)] if quick else [(0.4, 0.25), (0.25, 0.15), (0.15, 0.1)]
    piston_h = [(0.35, 0.15)] if quick else [(0.35, 0.15), (0.25, 0.1), (0.15, 0.06)]
    pts = _fibonacci_sphere(6000, A)
    dipole = (pts, (1.0 + 0j) * pts[:, 2] / A)
    cases = []
    for h, hs in sphere_h:
        cases.append(("pulsating sphere", "FE bgt2 R=1.5a", f"h={h}a hs={hs}a",
                      fem.sphere_geometry(A, h * A, h_surface_m=hs * A), 1.0, "bgt2", analytic.sphere_sigma))
        cases.append(("oscillating sphere", "FE bgt2 R=1.5a", f"h={h}a hs={hs}a",
                      fem.sphere_geometry(A, h * A, h_surface_m=hs * A), dipole, "bgt2",
                      lambda ka: ka**4 / (4 + ka**4)))
    cap_pts = _fibonacci_sphere(20000, A)
    cap = (cap_pts, (cap_pts[:, 2] / A > np.cos(np.pi / 3)).astype(complex))
    for h, hs in sphere_h[:1] if quick else sphere_h[:2]:
        cases.append(("cap on sphere", "FE bgt2 R=1.5a", f"h={h}a hs={hs}a",
                      fem.sphere_geometry(A, h * A, h_surface_m=hs * A), cap, "bgt2",
                      lambda ka: analytic.sphere_cap_sigma(ka, np.pi / 3)))
    for h, hs in piston_h:
        cases.append(("baffled piston", "FE bgt2 R=2a", f"h={h}a hs={hs}a",
                      fem.baffled_piston_geometry(A, h * A, h_surface_m=hs * A), 1.0, "bgt2", analytic.piston_sigma))
    h, hs = piston_h[0]
    for R in ([] if quick else [1.5, 3.0]):
        cases.append(("baffled piston", f"FE bgt2 R={R}a", f"h={h}a hs={hs}a",
                      fem.baffled_piston_geometry(A, h * A, outer_radius_m=R * A, h_surface_m=hs * A), 1.0,
                      "bgt2", analytic.piston_sigma))
    if not quick:
        cases.append(("baffled piston", "FE pml R=2a d=a", f"h={h}a hs={hs}a",
                      fem.baffled_piston_geometry(A, h * A, h_surface_m=hs * A, pml_thickness_m=A), 1.0,
                      "pml", analytic.piston_sigma))
        cases.append(("pulsating sphere", "FE bgt1 R=1.5a", f"h={sphere_h[0][0]}a hs={sphere_h[0][1]}a",
                      fem.sphere_geometry(A, sphere_h[0][0] * A, h_surface_m=sphere_h[0][1] * A), 1.0,
                      "bgt1", analytic.sphere_sigma))
    return cases


def _run_fem(quick: bool):
    rows, summary = [], []
    f = KA * analytic.SPEED_OF_SOUND / (2 * np.pi * A)
    for case, method, setting, geometry, velocity, truncation, reference in _fem_cases(quick):
        sweep = fem.helmholtz_fem_radiation(geometry, f, velocity=velocity, truncation=truncation)
        err = [10 * np.log10(r.sigma / reference(ka)) if r.sigma > 0 else np.nan
               for r, ka in zip(sweep.results, KA)]
        for r, ka, e in zip(sweep.results, KA, err):
            rows.append((case, method, setting, sweep.ndofs, ka, r.sigma, float(reference(ka)), e, r.seconds))
        per_f = float(np.mean([r.seconds for r in sweep.results]))
        summary.append((case, method, setting, sweep.ndofs, float(np.nanmax(np.abs(err))), per_f,
                        sweep.mesh_seconds + sweep.setup_seconds))
    return rows, summary


def _run_rayleigh(quick: bool):
    rows, summary = [], []
    settings = [(4, 12), (8, 24)] if quick else [(4, 12), (8, 24), (16, 48)]
    for n_r, n_t in settings:
        pts, nrm, w = numerical.disc_quadrature(A, n_r, n_t)
        errs, times = [], []
        for ka in KA:
            f = ka * analytic.SPEED_OF_SOUND / (2 * np.pi * A)
            t0 = time.perf_counter()
            r = numerical.rayleigh_radiated_power(pts, nrm, w, np.ones(len(w)), f)
            dt = time.perf_counter() - t0
            e = 10 * np.log10(r.sigma / analytic.piston_sigma(ka))
            errs.append(e)
            times.append(dt)
            rows.append(("baffled piston", "Rayleigh", f"{n_r}x{n_t} points", len(w), ka, r.sigma,
                         float(analytic.piston_sigma(ka)), e, dt))
        summary.append(("baffled piston", "Rayleigh", f"{n_r}x{n_t} points", len(w),
                        float(np.max(np.abs(errs))), float(np.mean(times)), 0.0))
    return rows, summary


def _plot(path: Path, rows, summary) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.5))
    for case, method, setting, n, err, per_f, _ in summary:
        ax1.loglog(per_f, max(err, 1e-5), "o" if method.startswith("FE") else "s")
        ax1.annotate(f"{case.split()[0][:5]} {method} {setting}", (per_f, max(err, 1e-5)), fontsize=5)
    ax1.axhline(0.5, color="r", lw=0.8, ls="--", label="0.5 dB acceptance")
    ax1.set_xlabel("time per frequency [s]")
    ax1.set_ylabel("max |error| over ka = 0.1 ... 5 [dB] (shown >= 1e-5)")
    ax1.grid(True, which="both", alpha=0.3)
    ax1.legend(fontsize=8)
    ka = np.geomspace(0.05, 10, 200)
    ax2.semilogx(ka, 10 * np.log10(analytic.sphere_sigma(ka)), "k-", label="pulsating sphere (4.9)")
    ax2.semilogx(ka, 10 * np.log10(analytic.piston_sigma(ka)), "k--", label="baffled piston")
    ax2.semilogx(ka, 10 * np.log10(ka**4 / (4 + ka**4)), "k:", label="oscillating sphere")
    ax2.semilogx(ka, 10 * np.log10(analytic.sphere_cap_sigma(ka, np.pi / 3)), "k-.", lw=0.8,
                 label="60 deg cap on sphere")
    first_setting = {}
    markers = {"FE bgt2": "o", "FE bgt1": "^", "FE pml ": "v", "Rayleig": "x"}
    colors = {"pulsating sphere": "C0", "baffled piston": "C1", "oscillating sphere": "C2", "cap on sphere": "C3"}
    labelled = set()
    for case, method, setting, n, k, sigma, ref, e, dt in rows:
        if first_setting.setdefault((case, method), setting) != setting:
            continue  # the coarsest setting of each method is enough to see the curves
        label = f"{case}, {method}" if (case, method) not in labelled else None
        labelled.add((case, method))
        ax2.semilogx(k, 10 * np.log10(sigma), markers.get(method[:7], "o"), ms=4, color=colors[case],
                     mfc="none", label=label)
    ax2.set_ylim(-45, 3)
    ax2.set_xlabel("ka")
    ax2.set_ylabel("radiation index [dB]")
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(fontsize=6, ncol=2, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def compare_box_estimate_with_numerical(plates, points, normals, weights, velocity, plate_ids, frequency_hz,
                                        c: float = analytic.SPEED_OF_SOUND):
    """For the housing (later, with the lead's forced response): Föller's estimate (dB) next to the
    plate-by-plate Rayleigh estimate (dB) at one frequency (Hz), from surface quadrature data
    (points (n,3) m, unit normals (n,3), weights (n,) m^2, complex peak normal velocity (n,) m/s,
    plate ids (n,)).  Returns (L_sigma_foller_db, L_sigma_rayleigh_db)."""
    box = foller.foller_radiation_index(plates, [frequency_hz], c=c)
    ray = numerical.baffled_plates_radiated_power(points, normals, weights, velocity, plate_ids, frequency_hz,
                                                  c=c)
    return float(box.L_sigma_db[0]), ray.radiation_index_db


BOX = (0.325, 0.225, 0.125)  # m, the free box of Sec. 4.2 (reconstructed dimensions, STACK-NOTES)


def box_surface_samples(edges=BOX, n: int = 24):
    """Midpoint-rule samples of the six faces of a box centred at the origin: points (m), outward
    normals, weights (m^2), face ids, and the (1,1) plate-mode shape of each face (max 1)."""
    pts, nrm, wts, ids, shape = [], [], [], [], []
    for axis in range(3):
        u_ax, v_ax = [a for a in range(3) if a != axis]
        lu, lv = edges[u_ax], edges[v_ax]
        u = (np.arange(n) + 0.5) / n
        U, V = np.meshgrid(u, u, indexing="ij")
        for side in (-1.0, 1.0):
            p = np.zeros((n * n, 3))
            p[:, u_ax] = (U.ravel() - 0.5) * lu
            p[:, v_ax] = (V.ravel() - 0.5) * lv
            p[:, axis] = side * edges[axis] / 2
            normal = np.zeros(3)
            normal[axis] = side
            pts.append(p)
            nrm.append(np.tile(normal, (n * n, 1)))
            wts.append(np.full(n * n, lu * lv / n**2))
            ids.append(np.full(n * n, 2 * axis + (side > 0)))
            shape.append(np.sin(np.pi * U.ravel()) * np.sin(np.pi * V.ravel()))
    return (np.vstack(pts), np.vstack(nrm), np.concatenate(wts), np.concatenate(ids), np.concatenate(shape))


def _box_plates(edges=BOX, thickness: float = 0.008):
    """The six faces as Föller plates (steel, f_c from the material)."""
    plates = []
    for axis, name in enumerate(("x", "y", "z")):
        lu, lv = [edges[a] for a in range(3) if a != axis]
        plates.append(foller.Plate.from_material(f"face {name}", 2, lu * lv, 2 * (lu + lv), thickness,
                                                 210e9, 7850.0, 0.3))
    return plates


def _run_box_comparison():
    """Illustration (no reference solution): a closed box whose faces all vibrate in phase in their (1,1)
    plate mode, radiation index from the closed-body FE, from baffled plates (Rayleigh) and Föller."""
    f = np.array([100.0, 200.0, 400.0, 800.0, 1600.0])
    pts, nrm, w, ids, shape = box_surface_samples()
    v = shape.astype(complex)
    sweep = fem.helmholtz_fem_radiation(fem.box_geometry(BOX, h_m=0.03, h_surface_m=0.02), f, velocity=(pts, v))
    rows = []
    for r in sweep.results:
        L_box, L_ray = compare_box_estimate_with_numerical(_box_plates(), pts, nrm, w, v, ids, r.frequency_hz)
        rows.append((r.frequency_hz, r.radiation_index_db, L_ray, L_box, r.seconds))
    return rows, sweep.ndofs


def main(out_dir: Path, quick: bool = False) -> None:
    """Run the radiation benchmark; print the tables and write CSV + PNG into out_dir (atomically)."""
    rows_r, summary_r = _run_rayleigh(quick)
    rows_f, summary_f = _run_fem(quick)
    rows, summary = rows_f + rows_r, summary_f + summary_r
    header = ["case", "method", "setting", "dofs/points", "max |err| dB", "s per frequency", "mesh+setup s"]
    print(format_table(header, summary, floatfmt="{:.3g}"))
    box_header = ["f [Hz]", "L_sigma FE closed box [dB]", "L_sigma baffled plates [dB]",
                  "L_sigma Föller [dB]", "FE s per frequency"]
    box_rows = None
    if not quick:
        box_rows, ndofs = _run_box_comparison()
        print(f"\nbox {BOX} m, faces in phase in their (1,1) mode (illustration, no reference; FE {ndofs} DOFs)")
        print(format_table(box_header, box_rows, floatfmt="{:.2f}"))
    with atomic_output_dir(out_dir) as tmp:
        write_csv(tmp / "radiation_bench_summary.csv", header, summary)
        write_csv(tmp / "radiation_bench.csv",
                  ["case", "method", "setting", "dofs_or_points", "ka", "sigma", "sigma_analytic", "error_db",
                   "seconds"], rows)
        _plot(tmp / "radiation_bench.png", rows, summary)
        if box_rows is not None:
            write_csv(tmp / "radiation_box_comparison.csv", box_header, box_rows)
    print(f"wrote {out_dir}/radiation_bench.csv, radiation_bench_summary.csv, radiation_bench.png"
          + ("" if quick else ", radiation_box_comparison.csv"))
