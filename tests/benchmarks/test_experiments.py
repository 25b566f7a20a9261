"""The experiment scripts under benchmarks/experiments keep working against the package's API (they live outside
it, so nothing else would notice a changed signature)."""
import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_layers_experiment_gives_the_layer_size_mesh():
    """2 layers through the walls and 4 through the flange by hand are mesh.layer_size = 4 mm's mesh: the same
    31 926 DOFs and, like tests/fe/test_element_families.py, below 1 % on the free box."""
    script = ROOT / "benchmarks" / "experiments" / "same_mesh" / "layers.py"
    proc = subprocess.run([sys.executable, str(script), "0.030:2:4:0.5"], cwd=ROOT, capture_output=True, text=True,
                          env=dict(os.environ, OPENBLAS_NUM_THREADS="1"), timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    found = re.search(r"DOFs\s+(\d+)\s+[\d.]+ s\s+max ([\d.]+) %", proc.stdout)
    assert found, proc.stdout
    assert int(found.group(1)) == 31926
    assert float(found.group(2)) < 1.0
