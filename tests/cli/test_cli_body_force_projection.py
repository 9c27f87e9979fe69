"""k = 2 delivers its order by default when there is a body force (issue 18, item 9), through the real
command: ``discretization.body_force_projection`` is p1 at order 2 unless the scene names p0 (the
paper's P_0 f1, which caps the L2 order at 2); at order 1 it is irrelevant (p1 refused)."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

ROOT = Path(__file__).resolve().parents[2]
SLIDING = ROOT / "config" / "order2" / "sliding.yaml"


def _solve(tmp_path, name, *sets):
    out = tmp_path / f"{name}.nc"
    args = [a for s in sets for a in ("--set", s)]
    run = subprocess.run(
        [sys.executable, "-m", "vemkit.cli", "solve", SLIDING, "-o", out, "-q", *args],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, run.stderr
    with xr.open_dataset(out) as ds:
        scene = yaml.safe_load(ds.attrs["scene"])
        x, y = ds["mesh2d_node_x"].values, ds["mesh2d_node_y"].values
        u = np.stack([ds["u1"].values, ds["u2"].values])
        return dict(ds.attrs), scene["discretization"], u, (x, y)


def _vertex_error(u, xy):
    from vemkit.config.expressions import vector_field
    from vemkit.config.scene import load_scene

    exact = np.stack(vector_field(load_scene(SLIDING).exact_displacement)(*xy))
    return np.linalg.norm(u - exact) / np.linalg.norm(exact)


@pytest.mark.slow
def test_order_2_loads_p1_by_default_and_reaches_l2_order_3(tmp_path):
    found = {n: _solve(tmp_path, f"k2-{n}", "discretization.order=2", f"discretization.mesh.n={n}") for n in (8, 16)}
    attrs, discretization, u, xy = found[16]
    assert discretization["body_force_projection"] == "p1"  # recorded in the solution file's scene
    assert np.log2(found[8][0]["error_l2"] / attrs["error_l2"]) >= 2.8
    p0, p0_discretization, p0_u, _ = _solve(
        tmp_path, "p0", "discretization.order=2", "discretization.mesh.n=16", "discretization.body_force_projection=p0"
    )
    assert p0_discretization["body_force_projection"] == "p0"
    assert p0["error_l2"] > 10 * attrs["error_l2"] and p0["error_h1"] > 1.8 * attrs["error_h1"]
    k1, k1_discretization, k1_u, k1_xy = _solve(tmp_path, "k1", "discretization.mesh.n=16")
    assert "body_force_projection" not in k1_discretization  # irrelevant at order 1
    # vertex values: k = 2 with p1 is 51x closer to u than k = 1 here, with p0 only 1.2x
    assert _vertex_error(k1_u, k1_xy) > 20 * _vertex_error(u, xy)
    assert _vertex_error(k1_u, k1_xy) < 2 * _vertex_error(p0_u, xy)
