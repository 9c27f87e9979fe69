"""Inputs whose cost scales (issue 18, item 2), through the real command: what grows with the input
is linear in it or predicted and refused before it is spent.

- the rigid-motion test of the Dirichlet set: a polygon of 3 000 corners, all on its clamped side
  (it took 2.2 GiB, quadratic in the corners: a dense SVD of the 6 000 x 3 constraints);
- ``vemkit adapt`` checks every refined mesh against the memory the machine has before solving it.
"""

import json
import sys
from pathlib import Path

import numpy as np
import xarray as xr

from vemkit.cli import main

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from measured_process import run_vemkit  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "config" / "scenes" / "paper.yaml"


def run_measured(args, cwd: Path, timeout: float = 300.0):
    """(exit status, stderr, seconds, peak resident bytes) of one vemkit process (tests/measured_process.py)."""
    status, _, stderr, seconds, peak = run_vemkit(args, cwd, timeout=timeout)
    return status, stderr, seconds, peak


def test_a_polygon_of_3000_clamped_corners_is_solved_in_linear_memory(tmp_path):
    t = 2.0 * np.pi * np.arange(3000) / 3000
    corners = [[round(float(np.cos(a)), 6), round(float(np.sin(a)), 6)] for a in t]
    scene = {
        "name": "many-corners",
        "domain": {"polygon": corners, "sides": ["rim"] * len(corners)},
        "material": {"E": 1.0, "nu": 0.3},
        "body_force": [0.0, -1.0],
        "boundary": {"dirichlet": ["rim"], "neumann": {}, "contact": []},
        "discretization": {"mesh": {"family": "square", "h": 0.1}},
        "solver": {"method": "ssn"},
    }
    (tmp_path / "many.yaml").write_text(json.dumps(scene))
    # the first process may compile numba kernels (their LLVM memory is not the solve's): measure the second
    run_measured(["solve", "many.yaml", "-o", "warm.nc", "-q"], tmp_path)
    status, stderr, seconds, peak = run_measured(["solve", "many.yaml", "-o", "out.nc", "-q"], tmp_path)
    assert status == 0, stderr
    assert peak < 700 * 2**20, f"peak {peak / 2**20:.0f} MiB"
    with xr.open_dataset(tmp_path / "out.nc") as ds:
        assert ds.sizes["mesh2d_nFaces"] > 250 and ds.attrs["check_worst"] < 1e-6


def test_adapt_stops_before_a_refined_mesh_the_machine_cannot_hold(tmp_path, monkeypatch, capsys):
    """The first mesh fits (its prediction is checked when the scene is read); a refined mesh whose
    predicted memory is beyond the machine is not solved: the loop stops there with a note, exit 0,
    and the file holds the last mesh that was solved."""
    import vemkit.config.limits as limits

    # the machine has room for 400 MiB + 2 500 bytes per DOF of about 700 DOFs: n = 4 (50 DOFs) fits,
    # so do its first refinements; the loop must stop before a mesh of more than about 700 DOFs
    room = limits.BASE_BYTES + limits.BYTES_PER_DOF * 700
    monkeypatch.setattr(limits, "available_memory", lambda: int(room / limits.MEMORY_FRACTION))
    out = tmp_path / "a.nc"
    code = main(
        [
            "adapt",
            str(PAPER),
            "-o",
            str(out),
            "--set",
            "discretization.mesh.n=4",
            "--set",
            "adaptivity.max_steps=30",
            "--set",
            "adaptivity.target=1e-6",
            "-q",
        ]
    )
    err = capsys.readouterr().err
    assert code == 0, err
    assert "not reached" in err and "memory" in err and len(err.splitlines()) == 1, err
    with xr.open_dataset(out) as ds:
        assert ds.attrs["adapt_stop_reason"] == "memory"
        assert 1 < ds.sizes["adapt_step"] < 30 and ds["adapt_n_dofs"].values.max() <= 700
