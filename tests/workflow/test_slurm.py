"""The SLURM profile on a real cluster: a mesh and one solve (results/solutions/square/dofi-2mu/n2.nc)
submitted through `snakemake --profile workflow/profiles/slurm`, then the same run locally.

- both jobs go through sbatch (the executor reports their SLURM job ids) and SLURM reports them
  COMPLETED with the profile's memory, wall time and CPUs (sacct; scontrol on a cluster without accounting);
- the solution file equals the local run's (data variables; times aside).

Needs `sbatch`, `sacct` and a cluster that answers `sinfo`; skipped (with the reason) otherwise: this
test never starts SLURM daemons (`make cluster-test` does, and runs this test against its cluster; any
other run skips that temporary cluster, whose daemons stop when the cluster test ends).
The run directory is under the checkout (.cluster-test/, which ignores itself): the compute nodes must
see it, as they must see the checkout.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import uuid
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "workflow" / "cluster"))
import local_cluster  # noqa: E402  (workflow/cluster/local_cluster.py: the marker of its slurm.conf)
import run_checks  # noqa: E402  (workflow/cluster/run_checks.py: tree copy, job records, netCDF comparison)

PROFILE = ROOT / "workflow" / "profiles" / "slurm" / "config.yaml"
TARGET = "results/solutions/square/dofi-2mu/n2.nc"  # n = 2 is no convergence level: rules mesh + solve


def _answers(argv) -> bool:
    try:
        return subprocess.run(argv, capture_output=True, timeout=20).returncode == 0
    except (OSError, subprocess.TimeoutExpired):
        return False


def _cluster_or_skip() -> bool:
    """Skip unless sbatch/sacct exist and a cluster answers; True if job accounting answers."""
    missing = [tool for tool in ("sbatch", "sacct", "sinfo") if shutil.which(tool) is None]
    if missing:
        pytest.skip(f"no SLURM here: {', '.join(missing)} not found (make cluster-test sets up a test cluster)")
    if not _answers(["sinfo", "-h"]):
        pytest.skip("SLURM is installed but no cluster answers `sinfo` (slurmctld not running?)")
    conf = Path(os.environ.get("SLURM_CONF", "/etc/slurm/slurm.conf"))
    temporary = conf.exists() and local_cluster.MARKER in conf.read_text(errors="replace")
    if temporary and os.environ.get("VEMKIT_CLUSTER_TEST") != "1":
        pytest.skip(
            "the cluster answering is the temporary one of a running `make cluster-test` (it runs this "
            "test itself, then stops its daemons)"
        )
    if not run_checks.SNAKEMAKE.exists():
        pytest.skip(f"{run_checks.SNAKEMAKE} not found: run make install")
    return _answers(["sacct", "-n", "-X", "--starttime=now"])


def test_mesh_and_solve_through_slurm_match_a_local_run():
    accounting = _cluster_or_skip()
    base = ROOT / ".cluster-test"
    base.mkdir(exist_ok=True)
    (base / ".gitignore").write_text("*\n")
    work = base / f"pytest-{uuid.uuid4().hex[:8]}"
    try:
        slurm_dir = run_checks.copy_tree(ROOT, work / "slurm", fresh=True)
        local_dir = run_checks.copy_tree(slurm_dir, work / "local", fresh=True)  # the same code
        since = subprocess.run(["date", "+%Y-%m-%dT%H:%M:%S"], capture_output=True, text=True).stdout.strip()
        status = [] if accounting else ["--slurm-status-command", "squeue"]  # README: clusters without accounting
        log, cache = work / "slurm.log", base / "numba-cache"
        profile = slurm_dir / PROFILE.relative_to(ROOT)  # the copy's: the checkout may change meanwhile
        args = ["--profile", str(profile.parent), TARGET, *status, "--slurm-init-seconds-before-status-checks", "5"]
        code, _ = run_checks.snakemake(slurm_dir, args, log, 600, numba_cache=cache)
        assert code == 0, f"the SLURM run failed or hung ({code}):\n{log.read_text()[-3000:]}"
        submitted, local_rules = run_checks.run_rules(log)
        assert submitted == {"mesh": 1, "solve": 1} and not local_rules
        assert len(re.findall(r"submitted with SLURM jobid", log.read_text())) == 2  # both through sbatch

        jobs = run_checks.sacct_jobs(slurm_dir, since) if accounting else run_checks.scontrol_jobs(slurm_dir)
        run_checks.check_jobs(jobs, submitted, local_rules, profile, account=None)

        code, _ = run_checks.snakemake(local_dir, ["-j1", TARGET], work / "local.log", 600, numba_cache=cache)
        assert code == 0, (work / "local.log").read_text()[-3000:]
        assert run_checks.compare_netcdf(slurm_dir / TARGET, local_dir / TARGET) == []
    finally:
        shutil.rmtree(work, ignore_errors=True)
