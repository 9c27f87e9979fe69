"""`make cluster-test`: the SLURM profile proven on a real one-node SLURM cluster on this host.

Run as root on Debian (it installs packages and starts daemons):
    .venv/bin/python workflow/cluster/cluster_test.py                       with job accounting (slurmdbd)
    .venv/bin/python workflow/cluster/cluster_test.py --mode no-accounting  without (status through squeue)
    .venv/bin/python workflow/cluster/cluster_test.py --mode mpi            solve_mpi.sbatch (mpi_check.py)

Steps: install slurm-wlm, slurmdbd, munge, mariadb-server (local_cluster.py); write /etc/slurm/slurm.conf
(+ slurmdbd.conf) for this host; start munged, mariadbd, slurmdbd, slurmctld, slurmd, each PID recorded in
<state>/pids; run `snakemake --profile workflow/profiles/slurm` on Table 1, one sweep and the robustness
matrix (workflow/cluster/cluster-test.yaml) in a copy of the working tree, and `snakemake -j2` on the same
in another copy; check the jobs' resources as SLURM recorded them against the profile and every netCDF
file against the local run (run_checks.py); run tests/workflow/test_slurm.py against the cluster; stop
exactly the daemons started. Mode mpi starts the cluster without accounting and runs only the MPI job
script against a serial solve (mpi_check.py). Every wait is bounded. Re-running is safe: it first stops what an
interrupted run left (by recorded PID), reuses the database, and replaces the SLURM run's copy.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import time
from datetime import datetime
from pathlib import Path

import local_cluster as cluster
import mpi_check
import run_checks as checks
import yaml

PROFILE = checks.ROOT / "workflow" / "profiles" / "slurm" / "config.yaml"
#: the first status check this many seconds after a submission (the plugin's default, 40 s, only slows a test)
FIRST_STATUS_CHECK = "10"
#: how long the no-accounting mode lets the default (sacct) status command wait for a finished job
HANG_DEMO_SECONDS = 150


def profile_for_test(state: Path, run: Path, accounting: bool) -> tuple[Path, list[str]]:
    """The profile and extra arguments of the SLURM run: the shipped profile (of the copy `run`) plus what
    the README tells a user to set: slurm_account (skips the executor's broken account guess), or without
    accounting `--slurm-status-command squeue`."""
    extra = ["--slurm-init-seconds-before-status-checks", FIRST_STATUS_CHECK]
    shipped = run / PROFILE.relative_to(checks.ROOT)
    if not accounting:
        return shipped, extra + ["--slurm-status-command", "squeue"]
    settings = yaml.safe_load(shipped.read_text())
    settings.setdefault("default-resources", {})["slurm_account"] = cluster.ACCOUNT
    profile = state / "profiles" / "slurm-with-account" / "config.yaml"
    profile.parent.mkdir(parents=True, exist_ok=True)
    profile.write_text(f"# {shipped} with slurm_account set (make cluster-test)\n" + yaml.safe_dump(settings))
    return profile, extra


def slurm_run(state: Path, run: Path, accounting: bool, timeout: float, say):
    """The targets through the SLURM profile in the copy `run`; check the jobs SLURM ran."""
    mode = "accounting" if accounting else "no-accounting"
    profile, extra = profile_for_test(state, run, accounting)
    log = state / "log" / f"snakemake-slurm-{mode}.log"
    since = datetime.now().strftime("%Y-%m-%dT%H:%M:%S")
    args = ["--profile", str(profile.parent), *checks.TARGETS, "--configfile", checks.CONFIGFILE, *extra]
    code, seconds = checks.snakemake(run, args, log, timeout, numba_cache=state / "numba-cache")
    if code is None:
        raise checks.CheckError(f"the SLURM run did not finish within {timeout:.0f} s (stopped); see {log}")
    if code != 0:
        raise checks.CheckError(f"the SLURM run failed ({code}); see {log}")
    say(f"snakemake --profile ({mode}): {seconds:.0f} s, log {log}")
    if accounting and "invalid option" in log.read_text():
        raise checks.CheckError(
            f"the executor's account guess ran (sacct: invalid option) although slurm_account is set; see {log}"
        )
    submitted, local = checks.run_rules(log)
    jobs = checks.sacct_jobs(run, since) if accounting else checks.scontrol_jobs(run)
    checks.check_jobs(jobs, submitted, local, profile, cluster.ACCOUNT if accounting else None)
    source = "sacct" if accounting else "scontrol (no accounting)"
    say(
        f"{len(jobs)} SLURM jobs, all COMPLETED with the profile's mem_mb/runtime/cpus_per_task ({source}); "
        f"local rules (not submitted): {dict(local)}\n\n{checks.jobs_table(jobs)}\n"
    )


def hang_without_squeue(state: Path, seconds: float, say):
    """Without accounting, the executor's default status command (sacct) never learns that a job ended:
    one mesh job, the shipped profile as it is, stopped after `seconds`. Reported, not failed, either way."""
    run = checks.copy_tree(checks.ROOT, state / "runs" / "slurm-default-status", fresh=True)
    log = state / "log" / "snakemake-slurm-default-status.log"
    target = "results/meshes/square/n2.nc"
    profile = run / PROFILE.parent.relative_to(checks.ROOT)
    args = ["--profile", str(profile), target, "--slurm-init-seconds-before-status-checks", FIRST_STATUS_CHECK]
    code, seconds_run = checks.snakemake(run, args, log, seconds, numba_cache=state / "numba-cache")
    made = (run / target).exists()
    if code is None:
        say(
            f"default status command (sacct) without accounting: still waiting after {seconds_run:.0f} s although "
            f"the job {'completed (its output exists)' if made else 'ran'}; stopped (the hang the README warns of)"
        )
    else:
        say(
            f"default status command (sacct) without accounting: exited {code} after {seconds_run:.0f} s "
            f"(no hang: the executor has changed; see {log})"
        )


def local_run(state: Path, snapshot: Path, timeout: float, say) -> Path:
    """The same targets with `snakemake -j2` on the same code as the SLURM run (kept between test runs
    while the code and configuration are unchanged, then snakemake has nothing to do)."""
    run, digest = state / "runs" / "local", checks.source_digest(snapshot)
    stamp = run / ".source-digest"
    if not stamp.exists() or stamp.read_text() != digest:
        checks.copy_tree(snapshot, run, fresh=True)
    log = state / "log" / "snakemake-local.log"
    code, seconds = checks.snakemake(
        run,
        ["-j2", *checks.TARGETS, "--configfile", checks.CONFIGFILE],
        log,
        timeout,
        numba_cache=state / "numba-cache",
    )
    if code != 0:
        raise checks.CheckError(f"the local run failed or timed out ({code}); see {log}")
    stamp.write_text(digest)
    say(f"snakemake -j2 (local reference): {seconds:.0f} s, log {log}")
    return run


def pytest_against_cluster(timeout: float, say):
    """tests/workflow/test_slurm.py must run (not skip) while the cluster answers."""
    argv = [sys.executable, "-m", "pytest", "-q", "-rs", "-p", "no:cacheprovider", "tests/workflow/test_slurm.py"]
    env = {**os.environ, "VEMKIT_CLUSTER_TEST": "1"}  # elsewhere the test skips this temporary cluster
    done = subprocess.run(argv, cwd=checks.ROOT, capture_output=True, text=True, timeout=timeout, env=env)
    summary = done.stdout.strip().splitlines()[-1] if done.stdout.strip() else done.stderr.strip()
    if done.returncode != 0 or "skipped" in summary or "passed" not in summary:
        raise checks.CheckError(f"tests/workflow/test_slurm.py against the cluster: {summary}\n{done.stdout}")
    say(f"tests/workflow/test_slurm.py: {summary}")


def exercise(state: Path, accounting: bool, timeout: float, say):
    mode = "accounting" if accounting else "no-accounting"
    run = checks.copy_tree(checks.ROOT, state / "runs" / f"slurm-{mode}", fresh=True)  # the code under test
    reference = local_run(state, run, timeout, say)
    slurm_run(state, run, accounting, timeout, say)
    count, problems = checks.compare_results(run, reference)
    if problems:
        raise checks.CheckError("results differ from the local run: " + "; ".join(problems))
    say(f"{count} netCDF files identical to the local run's (data variables; times and attributes aside)")
    pytest_against_cluster(timeout, say)
    if not accounting:
        hang_without_squeue(state, HANG_DEMO_SECONDS, say)


def _leftovers(stopped: list[str]) -> list[str]:
    """Processes of the test cluster still running (must be none): the daemons stopped, anything in
    their sessions (slurmscriptd, ...) and any slurmstepd (only this test's slurmd runs here)."""
    pids = {int(entry.split()[-1]) for entry in stopped}
    left = []
    for proc in Path("/proc").iterdir():
        if not proc.name.isdigit() or cluster._is_zombie(int(proc.name)):
            continue
        try:
            sid = int((proc / "stat").read_text().rsplit(")", 1)[1].split()[3])
            name = (proc / "comm").read_text().strip()
        except (OSError, IndexError, ValueError):
            continue
        if int(proc.name) in pids or sid in pids or name.startswith("slurmstepd"):
            left.append(f"{name} {proc.name}")
    return left


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mode", choices=["accounting", "no-accounting", "mpi"], default="accounting")
    parser.add_argument(
        "--state", type=Path, default=Path(os.environ.get("VEMKIT_CLUSTER_STATE", "/tmp/vemkit-cluster-test"))
    )
    parser.add_argument("--timeout", type=float, default=3600, help="seconds per snakemake run (default 3600)")
    args = parser.parse_args(argv)
    if os.geteuid() != 0:
        print("cluster-test: run as root: it installs Debian packages and starts the SLURM daemons")
        return 2
    accounting, state, start = args.mode == "accounting", args.state.resolve(), time.monotonic()
    state.mkdir(parents=True, exist_ok=True)
    report = state / f"report-{args.mode}.md"
    report.write_text(f"# make cluster-test, mode {args.mode}, {datetime.now():%Y-%m-%d %H:%M}\n\n")

    def say(line):
        print(line, flush=True)
        with open(report, "a") as out:
            out.write(line + "\n")

    signal.signal(signal.SIGTERM, signal.default_int_handler)  # SIGTERM stops the daemons like Ctrl-C
    for entry in cluster.stop_recorded(state):
        say(f"stopped a daemon an earlier run left: {entry}")
    daemons, status = cluster.Daemons(state), 1
    try:
        say(f"packages installed: {cluster.install_packages() or 'none (all present)'}")
        cluster.host_is_free()
        values = cluster.write_configuration(state, accounting)
        say(f"/etc/slurm/slurm.conf: node {values['HOST']}, CPUs={values['CPUS']}, RealMemory={values['MEMORY']} MB")
        for line in cluster.start_cluster(daemons, state, accounting, values):
            say(line)
        say(f"cluster up after {time.monotonic() - start:.0f} s")
        if args.mode == "mpi":
            mpi_check.exercise(state, args.timeout, say)
        else:
            exercise(state, accounting, args.timeout, say)
        status = 0
    except (cluster.ClusterError, checks.CheckError, subprocess.TimeoutExpired) as error:
        say(f"FAILED: {error}")
    finally:
        if daemons.started:  # jobs of an interrupted run: cancelled before their slurmd stops
            subprocess.run(["scancel", "--user=root"], capture_output=True, timeout=30)
        stopped = daemons.stop_all()
        left = _leftovers(stopped)
        say(f"stopped (by PID): {', '.join(stopped) or 'nothing'}; still running: {left or 'none'}")
        say(f"configuration removed: {', '.join(cluster.remove_configuration()) or 'none'}")
        status = status or bool(left)
    say(
        f"cluster-test ({args.mode}): {'PASSED' if status == 0 else 'FAILED'} in {time.monotonic() - start:.0f} s;"
        f" report {report}"
    )
    return status


if __name__ == "__main__":
    sys.exit(main())
