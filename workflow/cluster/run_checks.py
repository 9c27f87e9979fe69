"""The runs and checks of `make cluster-test`: a copy of the working tree per run (the checkout's own
results/ is never touched), Snakemake on SLURM and locally, the jobs' resources as SLURM recorded
them (sacct; scontrol without accounting) against the profile, and the netCDF files of both runs.
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import signal
import subprocess
import time
from collections import Counter
from pathlib import Path

import numpy as np
import xarray as xr
import yaml

ROOT = Path(__file__).resolve().parents[2]
SNAKEMAKE = ROOT / ".venv" / "bin" / "snakemake"
CONFIGFILE = "workflow/cluster/cluster-test.yaml"
#: Table 1, one sweep (2 x 2 points at n = 8, two jobs) and four cases of the robustness matrix (two jobs)
TARGETS = ["results/table1.nc", "results/sweeps/cluster-test.nc", "results/stability/stability.nc"]
#: data variables holding measured times: they differ between any two runs
TIMING = re.compile(r"(^|_)(wall|assembly|setup|total|solve|solver|elapsed)_?times?$|_seconds$")
_SKIP_DIRS = {".git", ".venv", "results", ".snakemake", "logs", "__pycache__", ".cluster-test", ".pytest_cache"}


class CheckError(AssertionError):
    """A check of the cluster test failed (the message says which and where to look)."""


def tree_files(root: Path) -> list[str]:
    """The checkout's files (tracked and untracked, not ignored; no results/), relative to root."""
    if (root / ".git").exists() and shutil.which("git"):
        listed = subprocess.run(
            ["git", "ls-files", "-co", "--exclude-standard"],
            cwd=root,
            capture_output=True,
            text=True,
            check=True,
            timeout=60,
        ).stdout.splitlines()
        return [f for f in listed if not f.startswith("results/") and (root / f).is_file()]
    files = []
    for folder, dirs, names in os.walk(root):
        dirs[:] = [d for d in dirs if d not in _SKIP_DIRS]
        files += [str((Path(folder) / n).relative_to(root)) for n in names]
    return files


def copy_tree(root: Path, dest: Path, fresh: bool) -> Path:
    """Copy the working tree's files (tree_files) to dest, modification times kept."""
    if fresh and dest.exists():
        shutil.rmtree(dest)
    for name in tree_files(root):
        target = dest / name
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(root / name, target)
    return dest


#: what the results depend on: the package, the workflow, the configuration
RESULT_SOURCES = (
    "vemkit/",
    "workflow/rules/",
    "workflow/scripts/",
    "workflow/schemas/",
    "workflow/report/",
    "config/",
    "Snakefile",
    CONFIGFILE,
)


def source_digest(tree: Path) -> str:
    """A digest of the files of a copied tree the results depend on (paths and contents)."""
    digest = hashlib.sha256()
    for name in sorted(n for n in tree_files(tree) if n.startswith(RESULT_SOURCES)):
        digest.update(name.encode() + b"\0" + (tree / name).read_bytes())
    return digest.hexdigest()


def snakemake(
    workdir: Path, args: list[str], log: Path, timeout: float, numba_cache: Path | None = None
) -> tuple[int | None, float]:
    """Run snakemake in workdir, output to log; (exit code or None on timeout, seconds). The run, and its
    SLURM jobs (sbatch --export=ALL), import vemkit from workdir's copy (PYTHONPATH), so a run is not
    changed by edits of the checkout while it runs; numba's cache can be kept in numba_cache."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(workdir), os.environ.get("PYTHONPATH")]))}
    if numba_cache is not None:
        env["NUMBA_CACHE_DIR"] = str(numba_cache)
    start = time.monotonic()
    with open(log, "w") as out:
        process = subprocess.Popen(
            [str(SNAKEMAKE), *args],
            cwd=workdir,
            stdout=out,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            start_new_session=True,
            env=env,
        )
        try:
            code = process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            code = None
            for sig in (signal.SIGINT, signal.SIGKILL):  # SIGINT: snakemake cancels its SLURM jobs
                if process.poll() is None:
                    os.killpg(process.pid, sig)
                    try:
                        process.wait(timeout=60)
                    except subprocess.TimeoutExpired:
                        pass
    return code, time.monotonic() - start


def run_rules(log: Path) -> tuple[Counter, Counter]:
    """(jobs submitted per rule, jobs run locally per rule) from a snakemake log."""
    text = log.read_text()
    return (Counter(re.findall(r"^rule (\w+):$", text, re.M)), Counter(re.findall(r"^localrule (\w+):$", text, re.M)))


# -- what SLURM recorded ---------------------------------------------------------------------------
def expected_resources(profile: Path, rule: str, threads: int = 1) -> dict:
    """mem_mb, runtime (minutes) and cpus_per_task the profile asks for a rule."""
    settings = yaml.safe_load(profile.read_text())
    wanted = {**settings.get("default-resources", {}), **settings.get("set-resources", {}).get(rule, {})}
    return {
        "mem_mb": int(wanted["mem_mb"]),
        "runtime": int(wanted["runtime"]),
        "cpus_per_task": int(wanted.get("cpus_per_task", threads)),
    }


def _minutes(limit: str) -> int:
    """SLURM's [D-]HH:MM:SS as minutes."""
    days, _, clock = limit.rpartition("-")
    h, m, s = (int(x) for x in clock.split(":"))
    return (int(days or 0) * 24 + h) * 60 + m + (s > 0)


def _megabytes(mem: str) -> int:
    number, unit = re.fullmatch(r"([\d.]+)([KMGT]?)n?", mem).groups()
    return round(float(number) * {"K": 1 / 1024, "M": 1, "G": 1024, "T": 1024**2, "": 1}[unit])


def _rule_of(comment: str) -> str:
    """The rule of a job from the executor's --comment 'rule_<name>[_wildcards_<...>]'."""
    return comment[len("rule_") :].split("_wildcards_")[0] if comment.startswith("rule_") else ""


SACCT_FIELDS = [
    "JobIDRaw",
    "JobID",
    "Comment",
    "State",
    "ReqMem",
    "Timelimit",
    "ReqCPUS",
    "Account",
    "Elapsed",
    "TotalCPU",
    "MaxRSS",
    "WorkDir",
]


def sacct_jobs(workdir: Path, since: str) -> list[dict]:
    """The jobs of workdir since `since`, from sacct (job accounting): one dict per job."""
    out = subprocess.run(
        ["sacct", "-a", "-P", "-n", f"--starttime={since}", "--format=" + ",".join(f"{f}%400" for f in SACCT_FIELDS)],
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    ).stdout
    jobs, max_rss = {}, Counter()
    for line in out.splitlines():
        row = dict(zip(SACCT_FIELDS, line.split("|")))
        if "." in row["JobID"]:  # a step: its peak memory
            rss = row["MaxRSS"] or "0K"
            max_rss[row["JobIDRaw"].split(".")[0]] = max(max_rss[row["JobIDRaw"].split(".")[0]], _megabytes(rss))
        elif Path(row["WorkDir"]) == workdir:
            jobs[row["JobIDRaw"]] = row
    return [
        {
            "id": i,
            "rule": _rule_of(r["Comment"]),
            "state": r["State"],
            "mem_mb": _megabytes(r["ReqMem"]),
            "runtime": _minutes(r["Timelimit"]),
            "cpus_per_task": int(r["ReqCPUS"]),
            "account": r["Account"],
            "elapsed": r["Elapsed"],
            "cpu_used": r["TotalCPU"],
            "max_rss_mb": max_rss[i],
        }
        for i, r in jobs.items()
    ]


def scontrol_jobs(workdir: Path) -> list[dict]:
    """The same from slurmctld's memory (no accounting; MinJobAge keeps finished jobs an hour)."""
    out = subprocess.run(["scontrol", "-o", "show", "job"], capture_output=True, text=True, timeout=60).stdout
    jobs = []
    for line in out.splitlines():
        row = dict(re.findall(r"(\S+?)=(\S*)", line))
        if Path(row.get("WorkDir", "")) != workdir:
            continue
        comment = re.search(r"Comment=(\S+)", line)
        jobs.append(
            {
                "id": row["JobId"],
                "rule": _rule_of(comment.group(1) if comment else ""),
                "state": row["JobState"],
                "mem_mb": _megabytes(row["MinMemoryNode"]),
                "runtime": _minutes(row["TimeLimit"]),
                "cpus_per_task": int(row.get("CPUs/Task", 1)),
                "account": row.get("Account", ""),
                "elapsed": row["RunTime"],
                "cpu_used": None,
                "max_rss_mb": None,
            }
        )
    return jobs


def check_jobs(jobs: list[dict], submitted: Counter, local: Counter, profile: Path, account: str | None):
    """Every submitted job ran under SLURM, completed, with the profile's resources; no local rule did."""
    problems = []
    ran = Counter(job["rule"] for job in jobs)
    if ran != submitted:
        problems.append(f"jobs per rule: SLURM ran {dict(ran)}, snakemake submitted {dict(submitted)}")
    for rule in set(ran) & set(local):
        problems.append(f"rule {rule} is a localrule but ran as a SLURM job")
    for job in jobs:
        want = expected_resources(profile, job["rule"])
        got = {key: job[key] for key in want}
        if job["state"] != "COMPLETED":
            problems.append(f"job {job['id']} ({job['rule']}): state {job['state']}")
        if got != want:
            problems.append(f"job {job['id']} ({job['rule']}): SLURM allocated {got}, the profile asks {want}")
        if account and job["account"] != account:
            problems.append(f"job {job['id']} ({job['rule']}): account {job['account']!r}, expected {account!r}")
    if problems:
        raise CheckError("; ".join(problems))


def jobs_table(jobs: list[dict]) -> str:
    """The per-job summary as a Markdown table."""
    lines = [
        "| job | rule | state | mem_mb | runtime (min) | cpus | account | elapsed | CPU used | MaxRSS (MB) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for j in sorted(jobs, key=lambda j: int(j["id"])):
        lines.append(
            f"| {j['id']} | {j['rule']} | {j['state']} | {j['mem_mb']} | {j['runtime']} | "
            f"{j['cpus_per_task']} | {j['account']} | {j['elapsed']} | {j['cpu_used']} | {j['max_rss_mb']} |"
        )
    return "\n".join(lines)


# -- results --------------------------------------------------------------------------------------
def _same(a: xr.DataArray, b: xr.DataArray) -> bool:
    if a.dims != b.dims or a.shape != b.shape:
        return False
    x, y = np.asarray(a.values), np.asarray(b.values)
    if x.dtype.kind in "fc":
        return bool(np.array_equal(x, y, equal_nan=True))
    return bool(np.array_equal(x, y))


def compare_netcdf(first: Path, second: Path) -> list[str]:
    """Differences between two netCDF files: variables (data and coordinates) by name and value,
    measured times and all attributes aside."""
    with xr.open_dataset(first, decode_times=False) as a, xr.open_dataset(second, decode_times=False) as b:
        names_a = {str(n) for n in a.variables if not TIMING.search(str(n))}
        names_b = {str(n) for n in b.variables if not TIMING.search(str(n))}
        diffs = [f"variables only in one file: {sorted(names_a ^ names_b)}"] if names_a != names_b else []
        diffs += [f"{name} differs" for name in sorted(names_a & names_b) if not _same(a[name], b[name])]
    return diffs


def compare_results(run: Path, reference: Path) -> tuple[int, list[str]]:
    """Every netCDF file of run/results against the same file of reference/results."""
    files = sorted((run / "results").rglob("*.nc"))
    problems = []
    for path in files:
        name = path.relative_to(run)
        other = reference / name
        if not other.exists():
            problems.append(f"{name}: not made by the local run")
            continue
        problems += [f"{name}: {d}" for d in compare_netcdf(path, other)]
    return len(files), problems
