"""`make cluster-test MODE=mpi`: workflow/cluster/solve_mpi.sbatch run on the one-node test cluster.

In a copy of the working tree (its .venv: the Python running this test), one scene is solved twice:
serially (`vemkit solve ... --set solver.linear=petsc`, the reference) and by the shipped job script,
submitted with `sbatch --wait` on one node and two tasks (the options a one-node cluster needs are given
on the sbatch command line; the script keeps its multi-node #SBATCH lines). The job must complete, its
log hold exactly one summary line (rank 0 speaks), and its file equal the serial one to 1e-8 (u1, u2, u3
and slip relative to each field's largest magnitude; friction_multiplier to 1e-8 where it is not the direction of
a slip, and within the bound that a slip's difference puts on its direction where it is).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import run_checks as checks
import xarray as xr

SCRIPT = "workflow/cluster/solve_mpi.sbatch"
SCENE = "config/scenes/3d/sheared_box.yaml"
SETTINGS = ["--set", "discretization.mesh.n=8"]
#: what a one-node cluster of two cores needs, given on the command line (the script asks for 2 x 16 ranks)
ONE_NODE = ["--nodes=1", "--ntasks-per-node=2", "--mem-per-cpu=1G"]
FIELDS = ("u1", "u2", "u3", "slip")  # and friction_multiplier (compare)
TOLERANCE = 1e-8
#: vemkit solve's summary line: "box.nc: ssn converged in 5 iterations, 2187 dofs, 1.23 s (check 1.0e-12)"
SUMMARY = re.compile(r"^\S+\.nc: .*, \d+ dofs, [\d.]+ s \(check \S+\)$")


def prepare(state: Path) -> tuple[Path, dict]:
    """A fresh copy of the tree with .venv pointing at this Python's environment; the environment of
    its runs (vemkit imported from the copy, Numba's cache kept in the state folder)."""
    run = checks.copy_tree(checks.ROOT, state / "runs" / "mpi", fresh=True)
    (run / ".venv").symlink_to(Path(sys.prefix), target_is_directory=True)
    env = {**os.environ, "PYTHONPATH": str(run), "NUMBA_CACHE_DIR": str(state / "numba-cache")}
    return run, env


def serial_solve(run: Path, env: dict, output: Path, timeout: float) -> tuple[float, str]:
    """The reference: one process, solver.linear=petsc; (seconds, its summary line)."""
    argv = [".venv/bin/vemkit", "solve", SCENE, "-o", str(output), "--set", "solver.linear=petsc", *SETTINGS]
    start = time.monotonic()
    done = subprocess.run(argv, cwd=run, env=env, capture_output=True, text=True, timeout=timeout)
    if done.returncode != 0:
        raise checks.CheckError(f"serial solve failed ({done.returncode}): {done.stderr.strip()[-2000:]}")
    return time.monotonic() - start, done.stdout.strip()


def submit(run: Path, env: dict, output: Path, timeout: float) -> tuple[str, int, float, str]:
    """sbatch --wait of the shipped script; (job id, sbatch's exit code, seconds, sbatch's stderr)."""
    argv = ["sbatch", "--wait", "--parsable", *ONE_NODE, SCRIPT, SCENE, str(output), *SETTINGS]
    start = time.monotonic()
    process = subprocess.Popen(argv, cwd=run, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        out, err = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        subprocess.run(["scancel", "--user=root"], capture_output=True, timeout=30)
        process.kill()
        out, err = process.communicate()
        raise checks.CheckError(f"the MPI job did not finish within {timeout:.0f} s (cancelled): {out} {err}") from None
    job = out.strip().split(";")[0]
    if not job.isdigit():
        raise checks.CheckError(f"sbatch did not submit ({process.returncode}): {err.strip()}")
    return job, process.returncode, time.monotonic() - start, err.strip()


def job_record(job: str) -> dict:
    """The finished job as slurmctld keeps it (MinJobAge: an hour, no accounting needed)."""
    out = subprocess.run(["scontrol", "-o", "show", "job", job], capture_output=True, text=True, timeout=60).stdout
    return dict(re.findall(r"(\S+?)=(\S*)", out))


def _field(a: xr.Dataset, b: xr.Dataset, name: str) -> tuple[np.ndarray, np.ndarray]:
    x, y = np.asarray(a[name].values, float), np.asarray(b[name].values, float)
    if x.shape != y.shape:
        raise checks.CheckError(f"{name}: shape {x.shape} in the MPI file, {y.shape} in the serial one")
    return x, y


def _direction_allowance(a: xr.Dataset, b: xr.Dataset) -> np.ndarray:
    """Per contact vertex, what the friction multiplier may differ by: TOLERANCE, and at a slip vertex,
    where lambda is the unit direction of the slip s, also 2 |s_MPI - s_serial| / |s_serial| (the bound
    of |a/|a| - b/|b||): a short slip turns a 1e-13 difference of u into a larger one of its direction."""
    x, y = _field(a, b, "slip")
    moved = np.linalg.norm((x - y).reshape(len(y), -1), axis=1)
    length = np.linalg.norm(y.reshape(len(y), -1), axis=1)
    slipping = (np.asarray(b["contact_state"].values) == 2) & (length > 0)
    return TOLERANCE + np.where(slipping, 2 * moved / np.where(slipping, length, 1.0), 0.0)


def compare(parallel: Path, serial: Path) -> tuple[list[str], list[str]]:
    """(one line per field: its largest difference, problems) of the MPI file against the serial one:
    u1, u2, u3 and slip to TOLERANCE x their largest magnitude, friction_multiplier (in the unit disk)
    to _direction_allowance."""
    lines, problems = [], []
    with xr.open_dataset(parallel) as a, xr.open_dataset(serial) as b:
        for name in FIELDS:
            x, y = _field(a, b, name)
            scale, diff = float(np.max(np.abs(y), initial=0.0)), float(np.max(np.abs(x - y), initial=0.0))
            lines.append(f"{name}: max |MPI - serial| = {diff:.2e} (largest |serial| {scale:.2e})")
            if not diff <= TOLERANCE * scale:
                problems.append(f"{name}: differs by {diff:.2e} > {TOLERANCE:g} x {scale:.2e}")
        x, y = _field(a, b, "friction_multiplier")
        diff = np.linalg.norm((x - y).reshape(len(y), -1), axis=1)
        allowed = _direction_allowance(a, b)
        worst = int(np.argmax(diff / allowed))
        lines.append(
            f"friction_multiplier: max |MPI - serial| = {diff.max():.2e}; worst against its allowance: vertex "
            f"{worst}, {diff[worst]:.2e} <= {allowed[worst]:.2e} (TOLERANCE + 2 |d slip| / |slip|)"
        )
        if not np.all(diff <= allowed):
            problems.append(f"friction_multiplier: vertex {worst} differs by {diff[worst]:.2e} > {allowed[worst]:.2e}")
    return lines, problems


def exercise(state: Path, timeout: float, say):
    """The serial reference, the job, and its checks; CheckError on the first failed check."""
    listed = subprocess.run(["srun", "--mpi=list"], capture_output=True, text=True, timeout=60)
    say(f"srun --mpi=list: {' '.join((listed.stdout + listed.stderr).split())}")
    run, env = prepare(state)
    folder = state / "mpi"
    folder.mkdir(parents=True, exist_ok=True)
    serial, parallel = folder / "serial.nc", folder / "box.nc"
    parallel.unlink(missing_ok=True)
    seconds, line = serial_solve(run, env, serial, timeout)
    say(f"serial reference (vemkit solve, solver.linear=petsc): {seconds:.0f} s: {line}")
    launcher = [ln.strip() for ln in (run / SCRIPT).read_text().splitlines() if ln.strip().startswith(("srun", "mpi"))]
    say(f"job script's launcher line: {launcher}")
    say(f"sbatch --wait {' '.join(ONE_NODE)} {SCRIPT} {SCENE} {parallel} {' '.join(SETTINGS)}")
    job, code, seconds, err = submit(run, env, parallel, timeout)
    record = job_record(job)
    log = run / f"vemkit-mpi-{job}.log"
    text = log.read_text() if log.exists() else f"(no log {log})"
    say(
        f"job {job}: {record.get('JobState')} exit {record.get('ExitCode')}, NumTasks={record.get('NumTasks')}, "
        f"RunTime={record.get('RunTime')}; sbatch --wait returned {code} after {seconds:.0f} s"
    )
    say(f"sbatch stderr: {err or '(empty)'}\njob log {log}:\n```\n{text.rstrip()}\n```")
    if code != 0 or record.get("JobState") != "COMPLETED" or record.get("ExitCode") != "0:0":
        raise checks.CheckError(f"the MPI job {job} did not complete (sbatch {code}); see {log}")
    summaries = [ln for ln in text.splitlines() if SUMMARY.match(ln.strip())]
    if len(summaries) != 1:
        raise checks.CheckError(f"the job log has {len(summaries)} summary lines, not one; see {log}")
    if not parallel.exists():
        raise checks.CheckError(f"the MPI job wrote no {parallel}")
    lines, problems = compare(parallel, serial)
    say("MPI file against the serial one:\n" + "\n".join(f"- {ln}" for ln in lines))
    if problems:
        raise checks.CheckError("the MPI solve differs from the serial one: " + "; ".join(problems))
    say(f"MPI job: completed, one summary line, its file equal to the serial solve's ({TOLERANCE:g}; see above)")
