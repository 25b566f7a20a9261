"""Midsurface Reissner-Mindlin shell model of the free welded box vs the 3D-solid reference.

usage: /usr/bin/python3 box_shell.py [--h 0.01] [--degree 2] [--variant strip|nostrip] [--drill 1.0]
                                      [--shear-qdeg N] [--factor cholesky|lu] [--json out.json]

Geometry (SI, origin at the centre of the flange underside, z up):
  L, W, H = 0.325, 0.225, 0.125; t = 0.008; tf = 0.015; b = 0.073
  walls at x = +-(L/2 - t/2), y = +-(W/2 - t/2), z in [tf/2, H - t/2]   (thickness t)
  top   at z = H - t/2, |x| <= L/2 - t/2, |y| <= W/2 - t/2             (thickness t)
  flange at z = tf/2, |x| <= L/2 + b, |y| <= W/2 + b minus the opening  (thickness tf)
     variant 'strip'  : opening |x| < L/2 - t, |y| < W/2 - t  (keeps the t/2 inward strip, as the solid)
     variant 'nostrip': opening |x| < L/2 - t/2, |y| < W/2 - t/2 (flange ends at the wall midline)
Conforming structured quad grid: shared breakpoints, each interval divided in ceil(len/h) equal parts.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

E, NU, RHO = 210e9, 0.3, 7850.0
L, W, H, T, TF, B = 0.325, 0.225, 0.125, 0.008, 0.015, 0.073
REF = os.path.join(os.path.dirname(os.path.abspath(__file__)), *[".."] * 3, "housingfe", "data", "benchmarks",
                   "box_free_modes_reference.json")


def subdivide(breaks, h):
    breaks = sorted(set(np.round(breaks, 12)))
    out = [breaks[0]]
    for a, b in zip(breaks[:-1], breaks[1:]):
        n = max(1, int(np.ceil((b - a) / h - 1e-9)))
        out.extend(list(np.linspace(a, b, n + 1)[1:]))
    return np.array(out)


def box_grid(h, variant="strip"):
    a, c = L / 2 - T / 2, W / 2 - T / 2          # wall midlines
    xo, yo = (L / 2 - T, W / 2 - T) if variant == "strip" else (a, c)   # opening edge
    xf, yf = L / 2 + B, W / 2 + B                 # flange outer edge
    z0, z1 = TF / 2, H - T / 2                    # flange and top midsurfaces
    X = subdivide([-xf, -a, -xo, xo, a, xf], h)
    Y = subdivide([-yf, -c, -yo, yo, c, yf], h)
    Z = subdivide([z0, z1], h)
    ia = [int(np.argmin(abs(X - s))) for s in (-a, a)]
    jc = [int(np.argmin(abs(Y - s))) for s in (-c, c)]
    assert np.allclose(X[ia], [-a, a]) and np.allclose(Y[jc], [-c, c])
    nodes: dict = {}
    pts = []

    def nid(i, j, k):
        key = (i, j, k)
        if key not in nodes:
            nodes[key] = len(pts)
            pts.append((X[i], Y[j], Z[k]))
        return nodes[key]

    quads, thick = [], []
    kt = len(Z) - 1
    eps = 1e-12
    # flange (k = 0) and top (k = kt)
    for i in range(len(X) - 1):
        for j in range(len(Y) - 1):
            xm, ym = (X[i] + X[i + 1]) / 2, (Y[j] + Y[j + 1]) / 2
            if not (abs(xm) < xo - eps and abs(ym) < yo - eps):
                quads.append([nid(i, j, 0), nid(i + 1, j, 0), nid(i, j + 1, 0), nid(i + 1, j + 1, 0)])
                thick.append(TF)
            if abs(xm) < a and abs(ym) < c:
                quads.append([nid(i, j, kt), nid(i + 1, j, kt), nid(i, j + 1, kt), nid(i + 1, j + 1, kt)])
                thick.append(T)
    # walls x = +-a (grid in y, z) and y = +-c (grid in x, z)
    for k in range(kt):
        for i in ia:
            for j in range(jc[0], jc[1]):
                quads.append([nid(i, j, k), nid(i, j + 1, k), nid(i, j, k + 1), nid(i, j + 1, k + 1)])
                thick.append(T)
        for j in jc:
            for i in range(ia[0], ia[1]):
                quads.append([nid(i, j, k), nid(i + 1, j, k), nid(i, j, k + 1), nid(i + 1, j, k + 1)])
                thick.append(T)
    return np.array(pts), np.array(quads, dtype=np.int64), np.array(thick)


def shell_mass(pts, quads, thick):
    p = pts[quads]
    area = np.linalg.norm(p[:, 1] - p[:, 0], axis=1) * np.linalg.norm(p[:, 2] - p[:, 0], axis=1)
    return RHO * float(np.sum(area * thick))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--h", type=float, default=0.01)
    ap.add_argument("--degree", type=int, default=2)
    ap.add_argument("--variant", default="strip", choices=["strip", "nostrip"])
    ap.add_argument("--drill", type=float, default=1.0)
    ap.add_argument("--shear-qdeg", type=int, default=None)
    ap.add_argument("--factor", default="cholesky", choices=["cholesky", "lu"])
    ap.add_argument("--nev", type=int, default=42)
    ap.add_argument("--json", default=None)
    args = ap.parse_args()

    t0 = time.perf_counter()
    from shell import assemble, cell_data, eigensolve, make_quad_mesh, shell_forms  # imports dolfinx
    t_import = time.perf_counter() - t0

    t0 = time.perf_counter()
    pts, quads, thick = box_grid(args.h, args.variant)
    msh = make_quad_mesh(pts, quads)
    z_flange = TF / 2
    e, th = cell_data(msh, lambda cen, n: TF if (abs(cen[2] - z_flange) < 1e-9 and abs(n[2]) > 0.99) else T)
    t_mesh = time.perf_counter() - t0

    t0 = time.perf_counter()
    V, a, m = shell_forms(msh, e, th, E, NU, RHO, degree=args.degree, drill_factor=args.drill,
                          shear_qdeg=args.shear_qdeg)
    K, M = assemble(V, a, m)
    t_asm = time.perf_counter() - t0
    ndof = V.dofmap.index_map.size_global * V.dofmap.index_map_bs

    t0 = time.perf_counter()
    f, eps = eigensolve(K, M, nev=args.nev, factor=args.factor)
    t_eig = time.perf_counter() - t0

    # post-processing (not timed): share of kinetic energy (x^T M x) in the flange cells, per mode
    import ufl
    from dolfinx import fem
    from shell import assemble as _asm
    chi = fem.Function(th.function_space)
    chi.x.array[:] = (th.x.array > (T + TF) / 2).astype(float)
    wt, wv = ufl.TrialFunction(V), ufl.TestFunction(V)
    ut, uv = ufl.as_vector([wt[0], wt[1], wt[2]]), ufl.as_vector([wv[0], wv[1], wv[2]])
    mflange = chi * RHO * th * ufl.dot(ut, uv) * ufl.dx
    Mf = _asm(V, mflange, mflange)[0]   # translational kinetic energy of the flange cells
    pairs = []
    xr = K.createVecRight()
    for i in range(eps.getConverged()):
        lam = eps.getEigenpair(i, xr).real
        y1, y2 = M.createVecLeft(), Mf.createVecLeft()
        M.mult(xr, y1)
        Mf.mult(xr, y2)
        pairs.append((lam, xr.dot(y2) / xr.dot(y1)))
    pairs.sort()
    flange_share = [p[1] for p in pairs]

    ref = np.array(json.load(open(REF))["frequencies_hz"])
    ref_sorted = np.sort(ref)
    n_rigid = int(np.sum(np.abs(f) < 5.0))
    elastic = f[np.abs(f) >= 5.0]
    fshare = np.array(flange_share)[np.abs(f) >= 5.0]
    res = dict(h=args.h, degree=args.degree, variant=args.variant, drill=args.drill, shear_qdeg=args.shear_qdeg,
               factor=args.factor, ncells=int(len(quads)), ndof=int(ndof), mass_kg=shell_mass(pts, quads, thick),
               nconv=int(len(f)), n_rigid=n_rigid, rigid_hz=[float(x) for x in f[np.abs(f) < 5.0]],
               t_import=t_import, t_mesh=t_mesh, t_assembly=t_asm, t_eigensolve=t_eig,
               f_elastic=[float(x) for x in elastic], flange_mass_share=[float(x) for x in fshare])
    n = min(36, len(elastic))
    err = np.abs(elastic[:n] / ref_sorted[:n] - 1)
    res.update(max_err=float(err.max()), mean_err=float(err.mean()), n_compared=n,
               n_below_4k=int(np.sum(elastic < 4000.0)))
    worst = np.argsort(-err)[:5]
    res["worst5"] = [(int(i + 1), float(ref_sorted[i]), float(elastic[i]), float(err[i]), float(fshare[i]))
                     for i in worst]
    print(f"h={args.h*1000:.1f} mm Q{args.degree} {args.variant} drill={args.drill} sq={args.shear_qdeg} "
          f"{args.factor}: cells={len(quads)} dofs={ndof} mass={res['mass_kg']:.3f} kg")
    print(f"  rigid modes (|f|<5 Hz): {n_rigid}  {np.round(res['rigid_hz'], 4)}; converged {len(f)}; "
          f"elastic < 4 kHz: {res['n_below_4k']}")
    print(f"  time: mesh {t_mesh:.2f} s, assembly {t_asm:.2f} s, eigensolve {t_eig:.2f} s "
          f"(total {t_mesh + t_asm + t_eig:.2f} s; import {t_import:.2f} s)")
    print(f"  max err {100*res['max_err']:.3f} %  mean err {100*res['mean_err']:.3f} %  over {n} modes")
    print("  worst5: " + "; ".join(f"#{i} ref {r:.1f} shell {s:.1f} ({100*e_:.2f} %, flange KE {fs:.2f})"
                                for i, r, s, e_, fs in res["worst5"]))
    print("  err % / flange KE share per mode: " + " ".join(f"{100*x:.1f}/{y:.2f}" for x, y in zip(err, fshare)))
    print("  f_elastic: " + " ".join(f"{x:.1f}" for x in elastic[:38]))
    if args.json:
        json.dump(res, open(args.json, "w"), indent=1)


if __name__ == "__main__":
    main()
