"""`housingfe.benchmarks.bearings` quick run: files written, analytic K agrees with central differences."""
import csv

from housingfe.benchmarks import bearings as bench


def test_quick_benchmark_writes_tables_and_agrees(tmp_path):
    out = tmp_path / "bench"
    bench.main(out, quick=True)
    assert (out / "bearings.png").stat().st_size > 10000
    with open(out / "bearings.csv") as fh:
        rows = list(csv.DictReader(fh))
    best = [float(r["fd_rel_error"]) for r in rows if float(r["fd_rel_step"]) == 1e-6]
    assert len(best) == 3 and max(best) < 1e-8
    with open(out / "fluid_film.csv") as fh:
        fluid = list(csv.DictReader(fh))
    assert abs(float(fluid[-1]["eccentricity"]) - 0.888) < 0.002
