"""The Python API's Dataset is the file `vemkit solve` writes: the same variables, the same global
attributes (the scene as YAML, mesh family, the independent check, ...), and the summary line says
what the solver did (issue 33)."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import xarray as xr

import vemkit
from vemkit.cli import solved_how

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "config" / "scenes"
#: attributes that measure the run, not what it computed
TIMINGS = {"wall_time", "assembly_time"}


def vemkit_cli(*args):
    return subprocess.run([sys.executable, "-m", "vemkit.cli", *map(str, args)], capture_output=True, text=True)


def test_solution_dataset_carries_what_the_cli_file_carries(tmp_path):
    out = tmp_path / "paper.nc"
    run = vemkit_cli("solve", SCENES / "paper.yaml", "-o", out, "--set", "discretization.mesh.n=8")
    assert run.returncode == 0, run.stderr
    scene = vemkit.load_scene(SCENES / "paper.yaml", ["discretization.mesh.n=8"])
    problem = vemkit.scene_problem(scene)
    ds = vemkit.solution_dataset(problem, vemkit.solve(problem, scene.solver_options))
    with xr.open_dataset(out) as written:
        assert set(ds.variables) == set(written.variables)
        assert set(ds.attrs) == set(written.attrs)
        for key in set(ds.attrs) - TIMINGS - {"check_worst"}:
            assert ds.attrs[key] == written.attrs[key], key
        assert ds.attrs["scene"] and ds.attrs["mesh_family"] == "square"
        assert ds.attrs["check_worst"] <= ds.attrs["check_tolerance"]
        np.testing.assert_allclose(ds["u2"].values, written["u2"].values, rtol=0, atol=1e-12)


def test_the_summary_line_of_a_solve_without_contact(tmp_path):
    """kirsch.yaml has no contact side: one linear solve, not "converged in 0 iterations"."""
    out = tmp_path / "kirsch.nc"
    run = vemkit_cli("solve", SCENES / "kirsch.yaml", "-o", out, "--set", "discretization.mesh.h=2")
    assert run.returncode == 0, run.stderr
    assert "no contact side, one linear solve" in run.stdout and "0 iterations" not in run.stdout


def test_solved_how_names_iterations_only_when_there_were_some():
    class Contact:
        def __init__(self, size):
            self.size = size

    class Problem:
        def __init__(self, size):
            self.contact = Contact(size)

    class Solution:
        def __init__(self, iterations):
            self.method, self.iterations = "ssn", iterations

    assert solved_how(Problem(0), Solution(0)) == "ssn: no contact side, one linear solve"
    assert solved_how(Problem(5), Solution(0)) == "ssn: no contact force at the linear solution, one linear solve"
    assert solved_how(Problem(5), Solution(1)) == "ssn converged in 1 iteration"
    assert solved_how(Problem(5), Solution(7)) == "ssn converged in 7 iterations"
