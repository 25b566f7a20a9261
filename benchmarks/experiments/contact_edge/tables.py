"""Tables of the contact_edge README from contact_edge_before.csv / contact_edge_after.csv: per set and points per
line, the largest |S_n| - |S_n,ref| over n = 1..30 in 1e-4 k_m (and where), against the reference REF (label,
n_slices) of each set, and the time per position.

    /work/main/.venv/bin/python benchmarks/experiments/contact_edge/tables.py [DIR] [--ref after:192]
"""
import argparse
import csv
from collections import defaultdict
from pathlib import Path

HERE = Path(__file__).parent


def read(folder: Path):
    data = defaultdict(dict)           # (label, set, n_slices) -> {n: amp}
    ms = {}
    for label in ("before", "after"):
        path = folder / f"contact_edge_{label}.csv"
        if not path.exists():
            continue
        with path.open() as fh:
            for row in csv.DictReader(fh):
                key = (row["label"], row["set"], int(row["n_slices"]))
                data[key][int(row["n"])] = float(row["amp_rel"])
                ms[key] = float(row["ms_per_position"])
    return data, ms


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("folder", nargs="?", default=str(HERE))
    ap.add_argument("--ref", default="after:192", help="label:n_slices of the reference (falls back to the finest)")
    ap.add_argument("--nmax", type=int, default=30)
    args = ap.parse_args()
    data, ms = read(Path(args.folder))
    ref_label, ref_n = args.ref.split(":")
    sets = sorted({k[1] for k in data}, key=lambda s: "ABCDu".index(s[0]))
    print(f"max_n<={args.nmax} | |S_n| - |S_n,ref| | [1e-4 k_m] (at n); reference {args.ref} (else the finest)")
    print("| set | code | " + " | ".join(str(n) for n in (24, 48, 96, 192, 384)) + " |")
    for s in sets:
        ref_key = (ref_label, s, int(ref_n))
        if ref_key not in data:
            ref_key = max((k for k in data if k[1] == s), key=lambda k: (k[0] == "after", k[2]))
        ref = data[ref_key]
        for label in ("before", "after"):
            cells = []
            for n_sl in (24, 48, 96, 192, 384):
                key = (label, s, n_sl)
                if key not in data or key == ref_key:
                    cells.append("ref" if key == ref_key else "—")
                    continue
                err = {n: abs(data[key][n] - ref[n]) for n in range(1, args.nmax + 1)}
                worst = max(err, key=err.get)
                cells.append(f"{err[worst] * 1e4:.2f} (n={worst})")
            print(f"| {s} | {label} | " + " | ".join(cells) + " |")
    print("\nms per position (this machine, shared):")
    for s in sets:
        print(s, {f"{k[0]}:{k[2]}": round(v, 1) for k, v in sorted(ms.items()) if k[1] == s})


if __name__ == "__main__":
    main()
