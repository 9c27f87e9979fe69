"""One solve across MPI ranks through the real command (issue 37, items 2 and 3):
``mpiexec -n 2 vemkit solve SCENE -o OUT.nc --set solver.linear=petsc``.

- The file of two ranks is the serial solve's (the same variables and attributes; displacement and
  friction multiplier to 1e-8) on the paper scene and on 3D friction (the sheared box, hex and
  Voronoi cells), with ssn and with uzawa; the summary line is printed once.
- A bad input under MPI is one line, printed once; every rank exits 2, nothing hangs, no file.
- A rank that dies ends the job: mpiexec returns, the other rank is gone, no file is written.
"""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

TESTS = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(TESTS), str(TESTS / "solvers")]
from mpi_jobs import require_mpi, vemkit_job  # noqa: E402
from test_petsc_backend import BOX, CASES, PAPER, SETTINGS  # noqa: E402  (the one-process PETSc cases)

from vemkit.cli import main  # noqa: E402

#: the one-process PETSc backend's cases and tight settings (two ways of solving meet far below 1e-8)
CASES = dict(zip(["paper", "box-hex", "box-voronoi"], CASES))


def _sets(values):
    return [a for value in values for a in ("--set", value)]


def _relative(a, b) -> float:
    return float(np.linalg.norm(a - b) / max(np.linalg.norm(b), 1e-300))


@pytest.mark.parametrize("method", ["ssn", "uzawa"])
@pytest.mark.parametrize("case", CASES)
def test_two_ranks_write_the_serial_solution(tmp_path, case, method):
    path, mesh = CASES[case]
    values = mesh + SETTINGS[method] + ["solver.linear=petsc"]  # the same backend: the same file variables
    assert main(["solve", str(path), "-o", str(tmp_path / "serial.nc"), "-q", *_sets(values)]) == 0
    run = vemkit_job(2, "solve", path, "-o", tmp_path / "ranks.nc", *_sets(values))
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.count("ranks.nc:") == 1 and "converged" in run.stdout  # the summary, once
    assert run.stderr.count("exited 0") == 2
    with xr.open_dataset(tmp_path / "serial.nc") as serial, xr.open_dataset(tmp_path / "ranks.nc") as ranks:
        assert set(ranks.variables) == set(serial.variables) and set(ranks.attrs) == set(serial.attrs)
        components = [name for name in ("u1", "u2", "u3") if name in serial]
        assert _relative(*(np.stack([ds[c].values for c in components]) for ds in (ranks, serial))) <= 1e-8
        lam, lam_serial = ranks["friction_multiplier"].values, serial["friction_multiplier"].values
        assert np.linalg.norm(lam - lam_serial) <= 1e-8 * max(np.linalg.norm(lam_serial), 1.0)


BAD_INPUTS = {
    "a bad value": (BOX, ["material.E=-1"], "material.E"),
    "a one-process backend": (BOX, ["solver.linear=amg"], "solver.linear"),
    "k = 2 with contact": (PAPER, ["discretization.order=2"], "discretization.order"),
    "the nodal average": (
        BOX,
        ["solver.linear=petsc", "discretization.volumetric_strain=nodal_average"],
        "volumetric_strain",
    ),
    "a bad PETSc option": (BOX, ["solver.linear=petsc", "solver.petsc_options.pc_type=nonsense"], "petsc_options"),
}


@pytest.mark.parametrize("bad", BAD_INPUTS)
def test_bad_input_is_one_line_once_and_every_rank_exits_2(tmp_path, bad):
    path, values, named = BAD_INPUTS[bad]
    values = values + ["discretization.mesh.n=3"]
    run = vemkit_job(2, "solve", path, "-o", tmp_path / "out.nc", *_sets(values), timeout=120)
    errors = [line for line in run.stderr.splitlines() if line.startswith("vemkit: error:")]
    assert len(errors) == 1 and named in errors[0], run.stderr
    assert "Traceback" not in run.stderr and run.stdout == ""
    assert run.stderr.count("exited 2") == 2 and run.returncode == 2
    assert list(tmp_path.iterdir()) == []


def test_only_solve_runs_across_ranks(tmp_path):
    run = vemkit_job(2, "adapt", BOX, "-o", tmp_path / "out.nc", timeout=120)
    assert run.stderr.count("vemkit: error: vemkit adapt runs in one process") == 1
    assert run.stderr.count("exited 2") == 2 and list(tmp_path.iterdir()) == []


def _rank_processes(output: Path) -> list[int]:
    """The pids of the vemkit processes writing ``output`` (the ranks, not mpiexec)."""
    found = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            command = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
        except OSError:
            continue
        if str(output).encode() in command and any(part.endswith(b"python") or b"python3" in part for part in command):
            found.append(int(pid))
    return sorted(found)


def test_a_rank_that_dies_ends_the_job(tmp_path):
    mpiexec = require_mpi()
    output = tmp_path / "out.nc"
    bin_dir = os.path.dirname(sys.executable)
    command = [mpiexec, "-n", "2", f"{bin_dir}/vemkit", "solve", str(BOX), "-o", str(output), "-q"]
    command += _sets(["solver.linear=petsc", "discretization.mesh.n=40"])  # ~ 200 000 unknowns: long enough
    job = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while len(ranks := _rank_processes(output)) < 2 and time.monotonic() < deadline and job.poll() is None:
            time.sleep(0.2)
        assert len(ranks) == 2, "the two ranks did not start"
        time.sleep(3.0)  # inside the solve
        os.kill(ranks[-1], signal.SIGKILL)
        job.wait(timeout=60)
    except subprocess.TimeoutExpired:
        job.kill()
        pytest.fail("the job went on after one of its ranks died")
    finally:
        if job.poll() is None:
            job.kill()
        job.communicate()
    assert job.returncode != 0
    assert _rank_processes(output) == [] and not output.exists()
