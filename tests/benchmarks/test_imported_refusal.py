"""`housingfe bench imported` whose case is refused (bad input, here the memory guard at a 1 mm element size):
one line, exit 2, and nothing left that looks like a result -- no result folder, no <out>.partial, no
<out>.inputs (it is kept only once the checkpoint holds the C3D10 deck a --resume re-uses; docs/imported-bench.md)."""
import os
import subprocess
import sys


def test_refused_case_leaves_no_folders(tmp_path):
    env = {**os.environ, "HOUSINGFE_PROGRESS_SECONDS": "0", "OPENBLAS_NUM_THREADS": "1"}
    run = subprocess.run([sys.executable, "-m", "housingfe", "bench", "imported", "--size", "1", "--cases",
                          "housingfe1", "--rounds", "1", "--out", str(tmp_path / "bench")],
                         capture_output=True, text=True, env=env, timeout=300)
    assert run.returncode == 2, run.stderr
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("housingfe: error: bench imported: case housingfe: mesh: model "
                                                   "too large"), run.stderr
    assert "mesh.allow_large" in lines[0] and "Traceback" not in run.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == []
