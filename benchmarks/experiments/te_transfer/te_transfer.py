"""The chain per micrometre of tooth-frequency transmission error, against the measured L_omega and L_WA (issue 28).

The default run-up's te_sensitivity.csv (runup.te_sensitivity = [1, 2]: the chain driven by 1 um of TE at the tooth
frequency alone, and at its 2nd harmonic alone, on the run's own models, without mesh moment and friction), set A, ball
bearings, 2000 N m, on the fixed feet (the default) and on the frame_mount spring bed (K_v = 1e9 N/m, docs/runup.md).
Per measured speed it reads L_omega and L_WA of the driven line per um of TE, and from them:
  TE_omega = the TE the measured tooth-band L_omega needs (source side);
  TE_W     = the TE the measured L_WA needs if the tooth line made all of it (an upper bound on what the tooth line
             may need: the measured L_WA also holds the other harmonics);
  transfer deficit = 20 lg(TE_W / TE_omega) = (L_WA - L_omega)_measured - (L_WA - L_omega)_ours: how far the chain's
             sound power per unit wheel angular velocity at the tooth frequency lies under the measured ratio --
             independent of the TE.
Nothing is tuned: the TE is a unit input.  Usage (from the repository root; ~1 min):
    PYTHONPATH=. .venv/bin/python benchmarks/experiments/te_transfer/te_transfer.py [--out DIR]
"""
import argparse
import csv
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = Path(__file__).parent
MEASURED_L_OMEGA = {500.0: 109.9, 1000.0: 111.2, 1500.0: 120.8}     # Fig. 5.4, set A, 2000 N m (tooth band)
# Sec. 5.5 (Fig. 5.10): 80 dB(A) at 500 rev/min is the measured reference point; 74 / 86 / 89 at 250 / 1000 / 1500 are
# the thesis' 6 dB(A)-per-doubling overlay through it, around which the measurement scatters by 5-10 dB(A)
MEASURED_L_WA = {250.0: 74.0, 500.0: 80.0, 1000.0: 86.0, 1500.0: 89.0}
MEASURED_MAX_L_WA = 100.5


def mount(kv: float) -> list[str]:
    """The frame mount of docs/runup.md: the feet on springs of total normal stiffness kv [N/m], tangential kv / 3."""
    return [f'housing.set=["supports.0.kind=elastic","supports.0.total_normal_stiffness={kv:g}",'
            f'"supports.0.total_tangential_stiffness={kv / 3:g}"]']


# the fixed feet (the built-in scene) and three frame stiffnesses of the range docs/runup.md measured (not published)
CASES = {"fixed feet": [], "mount K_v 3e8": mount(3e8), "mount K_v 1e9": mount(1e9), "mount K_v 1e10": mount(1e10)}


def run(out: Path, extra: list[str]) -> list[dict]:
    """te_sensitivity.csv of the default run-up (1 um of TE at n = 1 and at n = 2 alone, on the run's models)."""
    cmd = [sys.executable, "-m", "housingfe", "run", "test-gearbox-runup", "--out", str(out),
           "--set", "runup.te_sensitivity=[1, 2]", "--set", 'radiation.models=["erp"]']
    for s in extra:
        cmd += ["--set", s]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    with open(out / "te_sensitivity.csv") as fh:
        return list(csv.DictReader(fh))


def main(out_dir: Path) -> None:
    out_dir.mkdir(parents=True, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory(prefix="te-transfer-") as tmp:
        all_rows, maxima = {}, []
        for case, extra in CASES.items():
            both = run(Path(tmp) / case.replace(" ", "_"), extra)
            all_rows[case] = [r for r in both if r["harmonic"] == "1"]
            second = {(r["route"], float(r["speed_rpm"])): float(r["LwA_dB"]) for r in both if r["harmonic"] == "2"}
            for r in all_rows[case]:
                speed = float(r["speed_rpm"])
                if speed not in MEASURED_L_WA:
                    continue
                route = r["route"]
                l_omega = float(r["L_omega_coupled_dB"] if route == "mesh_force" else r["L_omega_dB"])
                l_wa = float(r["LwA_dB"])
                row = {"case": case, "route": route, "speed_rpm": speed,
                       "L_omega_per_um_dB": round(l_omega, 2), "LwA_per_um_dBA": round(l_wa, 2),
                       "TE_W_um": round(10 ** ((MEASURED_L_WA[speed] - l_wa) / 20), 3),
                       "LwA_per_um_n2_dBA": round(second[route, speed], 2),
                       "TE_W_n2_um": round(10 ** ((MEASURED_L_WA[speed] - second[route, speed]) / 20), 3)}
                if speed in MEASURED_L_OMEGA:
                    row["TE_omega_um"] = round(10 ** ((MEASURED_L_OMEGA[speed] - l_omega) / 20), 3)
                    row["transfer_deficit_dB"] = round(20 * math.log10(row["TE_W_um"] / row["TE_omega_um"]), 1)
                rows.append(row)
            for route in ("tf_omega", "mesh_force"):
                best = max((float(r["LwA_dB"]), float(r["speed_rpm"])) for r in all_rows[case] if r["route"] == route)
                maxima.append({"case": case, "route": route, "max_LwA_per_um_dBA": round(best[0], 2),
                               "at_rpm": best[1],
                               "TE_for_measured_max_um": round(10 ** ((MEASURED_MAX_L_WA - best[0]) / 20), 2)})
    keys = ["case", "route", "speed_rpm", "L_omega_per_um_dB", "LwA_per_um_dBA", "TE_omega_um", "TE_W_um",
            "transfer_deficit_dB", "LwA_per_um_n2_dBA", "TE_W_n2_um"]
    with open(out_dir / "te_transfer.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, keys)
        w.writeheader()
        w.writerows(rows)
    print("| case | route | rpm | L_omega per um, dB | L_WA per um, dB(A) | TE for measured L_omega, um | "
          "TE for measured L_WA, um | transfer deficit, dB | L_WA per um at n = 2, dB(A) | TE at n = 2 alone for "
          "measured L_WA, um |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print("| " + " | ".join(str(r.get(k, "")) for k in keys) + " |")
    print("\n| case | route | max L_WA per um, dB(A) | at rpm | TE for the measured 100.5 dB(A), um |")
    print("|---|---|---|---|---|")
    for m in maxima:
        print(f"| {m['case']} | {m['route']} | {m['max_LwA_per_um_dBA']} | {m['at_rpm']:g} | "
              f"{m['TE_for_measured_max_um']} |")
    with open(out_dir / "te_transfer_maxima.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, list(maxima[0]))
        w.writeheader()
        w.writerows(maxima)
    fig, ax = plt.subplots(figsize=(7, 4))
    for case in CASES:
        for route, marker in (("tf_omega", "o"), ("mesh_force", "s")):
            pts = [(r["speed_rpm"], r["transfer_deficit_dB"]) for r in rows
                   if r["case"] == case and r["route"] == route and "transfer_deficit_dB" in r]
            ax.plot(*zip(*pts), marker=marker, label=f"{case}, {route}")
    ax.axhline(0, color="k", lw=0.8)
    ax.set_xlabel("pinion speed [rev/min] (tooth frequency = 0.4 x rpm Hz)")
    ax.set_ylabel("(L_WA - L_omega) measured - ours [dB]")
    ax.set_title("set A, 2000 N m: the chain's sound power per wheel angular velocity, tooth line", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out_dir / "te_transfer.png", dpi=120)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=HERE)
    main(parser.parse_args().out)
