"""Largest numeric difference per CSV file between two result folders: python csv_diff.py OLD_DIR NEW_DIR."""
import csv
import glob
import math
import os
import sys


def main(old: str, new: str) -> None:
    for fa in sorted(glob.glob(os.path.join(old, "*.csv"))):
        ra = list(csv.reader(open(fa)))
        rb = list(csv.reader(open(os.path.join(new, os.path.basename(fa)))))
        worst, count, same_text = 0.0, 0, len(ra) == len(rb)
        for x, y in zip(ra, rb):
            for u, v in zip(x, y):
                try:
                    fu, fv = float(u), float(v)
                except ValueError:
                    same_text &= u == v
                    continue
                if not (math.isnan(fu) and math.isnan(fv)):
                    count += 1
                    worst = max(worst, abs(fu - fv))
        print(f"{os.path.basename(fa):36s} numbers={count:6d} max|diff|={worst:.3g} text-equal={same_text}")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
