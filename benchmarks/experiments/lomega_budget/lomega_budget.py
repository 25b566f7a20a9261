"""Where the tooth-band L_omega deficit of gear set A sits (issue 28): a budget, nothing tuned, no model change.

For gear set A at 2000 N m (the drivetrain of `test-gearbox-runup`, ball bearings) this prints

1. the receptance from a unit transmission error (TE) at the tooth frequency to the wheel's angular velocity,
   R_TE(f) = |Omega_wheel| / |e| [(rad/s)/m], of the rigid-bore lumped source (14 DOFs, holding the mean mesh
   stiffness k_m, loaded by k_m e along the mesh normal: the first-order, mean-stiffness solve) and, unless
   --lumped-only, of the coupled gearbox (housing, bearings, shafts, gear bodies; its Ritz reduction, loaded by
   k_ref e at the gear mesh);
2. the TE amplitude at n = 1 that the measured tooth-band L_omega (Fig. 5.4) would need at 500/1000/1500 rpm, beside
   the model's quasi-static TE d_qs = (F - F_e)/S for the face-width shock (default), the stiffness variation alone
   (F_e = 0) and the thesis' 2-D shock (Eq. 2.62);
3. the lumped model's modes between 150 and 900 Hz with the share of each in the wheel's angular velocity;
4. the tooth-band L_omega over speed (rigid bores, full harmonic balance, 10 rpm steps to 1800 rpm): the speed and
   height of its maximum, and what the maximum's height would be with that resonance moved to 600 Hz (1500 rpm).

    PYTHONPATH=. OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/experiments/lomega_budget/lomega_budget.py
"""
import argparse
import math
import time

import numpy as np
import scipy.linalg as sla

from housingfe import levels
from housingfe.source.roosmalen import dynamics as dyn

MEASURED = {500: 109.9, 1000: 111.2, 1500: 120.8}     # Fig. 5.4, tooth 1/3-octave band, set A, 2000 N m [dB re 5e-8]
TORQUE = 2000.0
R_ACC = 0.136         # radius of the two circumferential accelerometers on the wheel (Sec. 5.3)
W = dyn.WHEEL_THETA_Z


def amplitude_for_level(level_db: float) -> float:
    """One-sided amplitude [rad/s] of a single line whose level is level_db (mean square a^2/2 re OMEGA0^2)."""
    return math.sqrt(2.0) * levels.OMEGA0 * 10 ** (level_db / 20)


def level_of_amplitude(a: float) -> float:
    return 20 * math.log10(a / (math.sqrt(2.0) * levels.OMEGA0))


def print_extrema(fgrid, R, label: str) -> None:
    """Print the local maxima and minima of a receptance R [rad/s per m of TE] over fgrid [Hz] as L_omega per um."""
    inner = range(1, len(fgrid) - 1)
    peaks = [i for i in inner if R[i] > R[i - 1] and R[i] >= R[i + 1]]
    dips = [i for i in inner if R[i] < R[i - 1] and R[i] <= R[i + 1]]
    print(f"R_TE peaks ({label}): " + ", ".join(
        f"{fgrid[i]:.0f} Hz: L_omega {level_of_amplitude(R[i] * 1e-6):.1f} dB per um" for i in peaks))
    print(f"R_TE minima ({label}): " + ", ".join(
        f"{fgrid[i]:.0f} Hz: {level_of_amplitude(R[i] * 1e-6):.1f} dB per um" for i in dips))


def lumped_te_receptance(mats, f_hz):
    """|Omega_wheel / e| [(rad/s)/m] of the rigid-bore model holding k_m, loaded by k_m e along h."""
    km, h = mats.mean_mesh_stiffness, mats.h
    K = mats.K0 + km * np.outer(h, h)
    out = []
    for f in np.atleast_1d(f_hz):
        w = 2 * math.pi * f
        q = np.linalg.solve(K - w**2 * mats.M + 1j * w * mats.D, h)
        out.append(w * km * q[W])
    return np.abs(np.array(out))


def first_harmonic(x):
    return 2 * abs(np.fft.rfft(x)[1]) / len(x)


def lumped_modes(mats):
    """Mass-normalised modes of the mean system: f [Hz], phi (14, 14)."""
    km, h = mats.mean_mesh_stiffness, mats.h
    w2, phi = sla.eigh(mats.K0 + km * np.outer(h, h), mats.M)
    return np.sqrt(w2) / (2 * math.pi), phi


def main(lumped_only: bool):
    from housingfe.studies.chain_session import ChainSession

    t0 = time.perf_counter()
    session = ChainSession.from_scene("test-gearbox-runup")
    dspec = session.scene.drivetrain
    dt = session.drivetrain(dspec.gear_set, dspec.bearings, TORQUE)
    ops = {}
    for eng in ("face-width", "thesis-2d"):
        ops[eng] = dt.source_model(harmonics=session.spec.harmonics, engagement=eng)._point(TORQUE)
    op = ops["face-width"]
    mats, S = op.mats, op.S
    km = mats.mean_mesh_stiffness
    F = op.normal_force
    te = {"face-width": first_harmonic((F - ops["face-width"].shock) / S),
          "stiffness only": first_harmonic(F / S),
          "thesis-2d": first_harmonic((F - ops["thesis-2d"].shock) / S)}
    src = dt.source_model(harmonics=session.spec.harmonics)
    ftooth = {rpm: src.pair.tooth_frequency(rpm) for rpm in MEASURED}
    print(f"set A, {TORQUE:.0f} N m: mean mesh stiffness k_m = {km:.3e} N/m, normal force F = {F:.0f} N, "
          f"ripple 2|S_1|/S_0 = {first_harmonic(S) / S.mean():.4f}")
    print("quasi-static TE at n = 1 (2|d_qs,1|): " + ", ".join(f"{k} {v * 1e6:.3f} um" for k, v in te.items()))

    # ---- 1. receptance and the TE the measurement needs (rigid bores)
    R = {rpm: lumped_te_receptance(mats, ftooth[rpm])[0] for rpm in MEASURED}
    print("\n## Rigid-bore lumped source: TE -> wheel angular velocity at the tooth frequency")
    print("| rpm | f_tooth, Hz | R_TE, (rad/s)/um | L_omega per 1 um TE, dB | measured L_omega, dB | TE needed, um | "
          "needed / face-width, dB | needed / stiffness only, dB | needed / thesis-2d, dB | "
          "first-order L_omega face-width / thesis-2d, dB | full HB face-width / thesis-2d, dB |")
    print("|" + "---|" * 11)
    for rpm in MEASURED:
        a_meas = amplitude_for_level(MEASURED[rpm])
        need = a_meas / R[rpm]
        full = [dyn.tooth_band_level(ops[e].steady_state(src.pair, rpm, src.harmonics)) for e in ops]
        fo = [level_of_amplitude(R[rpm] * te[e]) for e in ("face-width", "thesis-2d")]
        print(f"| {rpm} | {ftooth[rpm]:.0f} | {R[rpm] * 1e-6:.4f} | {level_of_amplitude(R[rpm] * 1e-6):.1f} | "
              f"{MEASURED[rpm]} | {need * 1e6:.2f} | {20 * math.log10(need / te['face-width']):+.1f} | "
              f"{20 * math.log10(need / te['stiffness only']):+.1f} | {20 * math.log10(need / te['thesis-2d']):+.1f} | "
              f"{fo[0]:.1f} / {fo[1]:.1f} | {full[0]:.1f} / {full[1]:.1f} |")

    # ---- what else the two rim accelerometers could see (Sec. 5.3: r = 136 mm, circumferential, summed / 2)
    print("\n## Rigid bores, per unit TE at the tooth frequency: wheel motions at the accelerometer radius r = "
          f"{R_ACC} m")
    print(f"wheel base radius r_b2 = {mats.h[W] / math.cos(src.pair.base_helix_angle):.4f} m; "
          "share of the TE the wheel takes = h_w |theta_w| / |e| (h_w = r_b2 cos beta_b)")
    print("| rpm | r |Omega_z|, m/s per um | in-plane translation |v_xy|, m/s per um | rim axial from tilt r |Omega_xy|, "
          "m/s per um | translation / rotation, dB | tilt / rotation, dB | wheel's share of the TE |")
    print("|---|---|---|---|---|---|---|")
    for rpm in MEASURED:
        w = 2 * math.pi * ftooth[rpm]
        q = np.linalg.solve(mats.K0 + km * np.outer(mats.h, mats.h) - w**2 * mats.M + 1j * w * mats.D,
                            mats.h) * km * 1e-6 * w
        rot, trans, tilt = R_ACC * abs(q[W]), np.linalg.norm(q[6:8]), R_ACC * np.linalg.norm(q[9:11])
        print(f"| {rpm} | {rot:.3e} | {trans:.3e} | {tilt:.3e} | {20 * math.log10(trans / rot):+.1f} | "
              f"{20 * math.log10(tilt / rot):+.1f} | {mats.h[W] * abs(q[W]) / w / 1e-6:.2f} |")

    print("measured wheel angle at the tooth frequency as a displacement along the line of action, h_w |theta_w| "
          "(model-free: what the wheel would take if it took the whole TE): " + ", ".join(
              f"{rpm} rpm {mats.h[W] * amplitude_for_level(MEASURED[rpm]) / (2 * math.pi * ftooth[rpm]) * 1e6:.2f} um"
              for rpm in MEASURED))

    # ---- 3. modes and their share in the wheel's angular velocity
    fr, phi = lumped_modes(mats)
    zeta = src.interior.loss_factor / 2
    print("\n## Lumped modes (mean system), share in the wheel's angular velocity under a mesh load")
    print("| mode f, Hz | wheel theta_z kinetic-energy share | mesh strain-energy share | modal constant "
          "phi_w (h.phi), rad/(N s^2) | share of Omega_wheel at 200 / 400 / 600 Hz / at its own f | kinetic energy "
          "by part: largest three |")
    print("|---|---|---|---|---|---|")
    parts = {"pinion x,y": [0, 1], "pinion z": [2], "pinion tilt": [3, 4], "pinion theta_z": [5],
             "wheel x,y": [6, 7], "wheel z": [8], "wheel tilt": [9, 10], "wheel theta_z": [11],
             "pinion-side coupling": [12], "wheel-side coupling": [13]}
    J_w = mats.M[W, W]
    for r in range(len(fr)):
        if not 150 <= fr[r] <= 900:
            continue
        A = phi[W, :] * (mats.h @ phi)                 # modal constants of theta_w per unit mesh force
        shares = []
        for f in (200.0, 400.0, 600.0, fr[r]):
            w = 2 * math.pi * f
            contrib = A / ((2 * math.pi * fr) ** 2 - w**2 + 2j * zeta * (2 * math.pi * fr) * w)
            shares.append(abs(contrib[r]) / abs(contrib.sum()))
        ke = J_w * phi[W, r] ** 2                      # phi^T M phi = 1
        se = km * (mats.h @ phi[:, r]) ** 2 / (2 * math.pi * fr[r]) ** 2
        kin = {k: float(sum(mats.M[j, j] * phi[j, r] ** 2 for j in v)) for k, v in parts.items()}
        top = sorted(kin.items(), key=lambda kv: -kv[1])[:3]
        print(f"| {fr[r]:.0f} | {ke:.3f} | {se:.3f} | {A[r]:+.3e} | " + " / ".join(f"{s:.2f}" for s in shares)
              + " | " + ", ".join(f"{k} {v:.2f}" for k, v in top) + " |")

    # receptance over frequency: its peaks in 100-900 Hz
    fgrid = np.arange(50.0, 1200.0, 1.0)
    Rg = lumped_te_receptance(mats, fgrid)
    print()
    print_extrema(fgrid, Rg, "rigid bores")

    # ---- 4. L_omega over speed: resonance placement
    print("\n## Tooth-band L_omega over speed, rigid bores, full harmonic balance (10 rpm steps)")
    speeds = np.arange(100.0, 1810.0, 10.0)
    print("| engagement | max L_omega, dB | at rpm (f_tooth, Hz) | L_omega at 500/1000/1500 rpm, dB | "
          "max moved to 600 Hz, dB (-20 lg(600/f_peak)) | measured 1500 rpm |")
    print("|---|---|---|---|---|---|")
    for eng, o in ops.items():
        L = np.array([dyn.tooth_band_level(o.steady_state(src.pair, v, src.harmonics)) for v in speeds])
        i = int(np.argmax(L))
        fpk = src.pair.tooth_frequency(speeds[i])
        at = [L[np.argmin(abs(speeds - v))] for v in MEASURED]
        moved = L[i] - 20 * math.log10(ftooth[1500] / fpk)
        print(f"| {eng} | {L[i]:.1f} | {speeds[i]:.0f} ({fpk:.0f}) | " + " / ".join(f"{x:.1f}" for x in at)
              + f" | {moved:.1f} | {MEASURED[1500]} |")
    band = (fgrid >= 150) & (fgrid <= 650)
    i = int(np.flatnonzero(band)[np.argmax(Rg[band])])
    print(f"rigid-bore R_TE maximum in 150-650 Hz: {fgrid[i]:.0f} Hz, {level_of_amplitude(Rg[i] * 1e-6):.1f} dB per um; "
          "TE the measured level would need if each speed sat on this peak (peak x f_peak / f): " + ", ".join(
              f"{rpm} rpm {amplitude_for_level(MEASURED[rpm]) / (Rg[i] * fgrid[i] / ftooth[rpm]) * 1e6:.2f} um"
              for rpm in MEASURED))
    print(f"\nlumped part: {time.perf_counter() - t0:.1f} s")
    if lumped_only:
        return

    # ---- coupled gearbox: the same receptance on the flexible housing
    from housingfe.response.observers import node_key

    t1 = time.perf_counter()
    model = session.model(dt)
    red = model.reduction
    k_ref = float(model.structure.spec.gear_meshes[0].stiffness)
    node = red.reduced.points[node_key(model.wheel_node)]
    axis = model.wheel_axis / np.linalg.norm(model.wheel_axis)

    def coupled_R(f):
        f = np.atleast_1d(np.asarray(f, float))
        c = red.coefficients(f, {"mesh": np.full(len(f), k_ref, complex)})   # unit TE: k_ref e, e = 1 m
        return np.abs(2 * math.pi * f * (axis @ (node[3:6] @ c)))

    print(f"\n## Coupled gearbox (k_ref = {k_ref:.3e} N/m; model built in {time.perf_counter() - t1:.1f} s)")
    print("| rpm | R_TE coupled, (rad/s)/um | coupled - rigid, dB | TE needed on the coupled model, um | "
          "needed / face-width, dB | needed / stiffness only, dB | needed / thesis-2d, dB |")
    print("|---|---|---|---|---|---|---|")
    for rpm in MEASURED:
        rc = coupled_R(ftooth[rpm])[0]
        need = amplitude_for_level(MEASURED[rpm]) / rc
        print(f"| {rpm} | {rc * 1e-6:.4f} | {20 * math.log10(rc / R[rpm]):+.1f} | {need * 1e6:.2f} | "
              f"{20 * math.log10(need / te['face-width']):+.1f} | {20 * math.log10(need / te['stiffness only']):+.1f} | "
              f"{20 * math.log10(need / te['thesis-2d']):+.1f} |")
    print("| rpm | r |Omega_axis|, m/s per um | |v| of the wheel node, m/s per um | r |Omega_tilt|, m/s per um | "
          "translation / rotation, dB | tilt / rotation, dB |")
    print("|---|---|---|---|---|---|")
    for rpm in MEASURED:
        f = np.array([ftooth[rpm]])
        c = red.coefficients(f, {"mesh": np.full(1, k_ref * 1e-6, complex)})
        u = 2 * math.pi * f[0] * (node[0:3] @ c)[:, 0]
        th = 2 * math.pi * f[0] * (node[3:6] @ c)[:, 0]
        rot = R_ACC * abs(axis @ th)
        tilt = R_ACC * np.linalg.norm(th - axis * (axis @ th))
        print(f"| {rpm} | {rot:.3e} | {np.linalg.norm(u):.3e} | {tilt:.3e} | "
              f"{20 * math.log10(np.linalg.norm(u) / rot):+.1f} | {20 * math.log10(tilt / rot):+.1f} |")
    Rc = coupled_R(fgrid)
    print_extrema(fgrid, Rc, "coupled")
    band = (fgrid >= 150) & (fgrid <= 650)
    i = int(np.flatnonzero(band)[np.argmax(Rc[band])])
    print(f"coupled R_TE maximum in 150-650 Hz: {fgrid[i]:.0f} Hz ({fgrid[i] / src.pair.tooth_frequency(1.0):.0f} rpm), "
          f"{level_of_amplitude(Rc[i] * 1e-6):.1f} dB per um; face-width TE would give "
          f"{level_of_amplitude(Rc[i] * te['face-width']):.1f} dB there")
    print("TE the measured level would need if each speed sat on the coupled 150-650 Hz peak (peak x f_peak / f): "
          + ", ".join(f"{rpm} rpm {amplitude_for_level(MEASURED[rpm]) / (Rc[i] * fgrid[i] / ftooth[rpm]) * 1e6:.2f} um"
                      for rpm in MEASURED))
    print(f"total {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lumped-only", action="store_true", help="skip the coupled gearbox (about 30-60 s)")
    main(ap.parse_args().lumped_only)
