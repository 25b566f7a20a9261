"""Scene runner and benchmark rows for the Trueman drive (filled in below)."""
from __future__ import annotations


def run_scene(scene: dict, scene_path: str, out_dir) -> None:  # pragma: no cover - placeholder
    raise NotImplementedError


def bench_rows(quick: bool) -> list[dict]:  # pragma: no cover - placeholder
    raise NotImplementedError
