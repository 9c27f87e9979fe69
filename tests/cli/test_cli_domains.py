"""Any body through the real CLI (SPEC §7): the shipped Cook's membrane scene against its reference."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

ROOT = Path(__file__).resolve().parents[2]
COOK = ROOT / "config" / "scenes" / "cook.yaml"
REFERENCE = 23.96  # vertical displacement at the middle of the loaded edge (config/scenes/cook.yaml)


@pytest.mark.parametrize("family", ["square", "triangle", "voronoi"])
def test_cooks_membrane_meets_the_published_displacement(tmp_path, family):
    out = tmp_path / "cook.nc"
    run = subprocess.run([sys.executable, "-m", "vemkit.cli", "solve", str(COOK), "-o", str(out), "-q",
                          "--set", f"discretization.mesh.family={family}", "--set", "discretization.mesh.n=1"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    with xr.open_dataset(out) as ds:
        x, y, v = ds["mesh2d_node_x"].values, ds["mesh2d_node_y"].values, ds["u2"].values
    on_edge = np.isclose(x, 48.0)
    mid = np.argmin(np.where(on_edge, np.abs(y - 52.0), np.inf))
    assert abs(y[mid] - 52.0) < 0.5
    assert abs(v[mid] - REFERENCE) < 0.02 * REFERENCE
