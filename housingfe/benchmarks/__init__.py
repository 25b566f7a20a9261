"""Benchmarks (`housingfe bench <name>`): speed next to error, printed as a table, written as CSV + PNG.

Each module `housingfe.benchmarks.<name>` defines `main(out_dir: pathlib.Path, quick: bool) -> None`.
"""
