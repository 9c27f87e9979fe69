"""A one-node SLURM cluster on this Debian host, for `make cluster-test` (run as root).

Installs Debian's packages (slurm-wlm, slurmdbd, munge, mariadb-server) without letting their
maintainer scripts start services, writes /etc/slurm/slurm.conf (and slurmdbd.conf) for this host,
starts munged, mariadbd, slurmdbd, slurmctld and slurmd in the foreground as children of this process,
records each PID (and its executable) in <state>/pids/, and stops exactly those PIDs. A re-run first
stops the daemons a previous, interrupted run recorded; nothing else is ever signalled.
"""

from __future__ import annotations

import os
import secrets
import shutil
import signal
import socket
import subprocess
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
MARKER = "written by vemkit workflow/cluster (make cluster-test); safe to delete"
PACKAGES = ["slurm-wlm", "slurmdbd", "slurm-client", "munge", "mariadb-server"]
SLURM_ETC = Path("/etc/slurm")
POLICY_RC = Path("/usr/sbin/policy-rc.d")
DB_PORT = 33061
ACCOUNT = "vemkit"
WITH_ACCOUNTING = """AccountingStorageType=accounting_storage/slurmdbd
AccountingStorageHost=localhost
AccountingStorageEnforce=associations
AccountingStoreFlags=job_comment
JobAcctGatherType=jobacct_gather/linux
JobAcctGatherFrequency=5"""
WITHOUT_ACCOUNTING = """AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none"""


class ClusterError(RuntimeError):
    """The test cluster could not be set up (the message says which step and where its log is)."""


def run(argv, timeout=60, check=True, **kwargs) -> subprocess.CompletedProcess:
    """A command with a bounded wait; its output captured."""
    try:
        done = subprocess.run(argv, capture_output=True, text=True, timeout=timeout, **kwargs)
    except subprocess.TimeoutExpired as error:
        raise ClusterError(f"{' '.join(map(str, argv))}: no answer within {timeout} s") from error
    if check and done.returncode != 0:
        raise ClusterError(f"{' '.join(map(str, argv))} failed ({done.returncode}): {done.stderr.strip()}")
    return done


def wait_until(ready, what: str, timeout: float, process: subprocess.Popen | None = None, log: Path | None = None):
    """Poll ready() every 0.5 s for at most timeout seconds; fail early if the daemon died."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if ready():
            return
        if process is not None and process.poll() is not None:
            raise ClusterError(f"{what}: the daemon exited ({process.returncode}); see {log}")
        time.sleep(0.5)
    raise ClusterError(f"{what}: not ready after {timeout} s; see {log}")


# -- packages -------------------------------------------------------------------------------------
def missing_packages() -> list[str]:
    missing = []
    for package in PACKAGES:
        status = run(["dpkg-query", "-W", "-f=${Status}", package], check=False).stdout
        if "install ok installed" not in status:
            missing.append(package)
    return missing


def install_packages():
    """apt-get install what is missing; a temporary policy-rc.d keeps the packages from starting
    their services (this script starts, and stops, its own daemons)."""
    missing = missing_packages()
    if not missing:
        return []
    own_policy = not POLICY_RC.exists()
    if own_policy:
        POLICY_RC.write_text("#!/bin/sh\n# " + MARKER + "\nexit 101\n")
        POLICY_RC.chmod(0o755)
    env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
    try:
        run(["apt-get", "update", "-q"], timeout=600, env=env)
        run(["apt-get", "install", "-y", "-q", "--no-install-recommends", *missing], timeout=1800, env=env)
    finally:
        if own_policy:
            POLICY_RC.unlink()
    return missing


# -- configuration --------------------------------------------------------------------------------
def host_resources() -> dict:
    """This host's short name, CPU count and memory (MemTotal of /proc/meminfo, in MB)."""
    host = run(["hostname", "-s"]).stdout.strip()
    meminfo = dict(line.split(":", 1) for line in Path("/proc/meminfo").read_text().splitlines())
    memory_mb = int(meminfo["MemTotal"].split()[0]) // 1024
    return {"HOST": host, "CPUS": str(os.cpu_count()), "MEMORY": str(memory_mb)}


def _fill(template: str, values: dict) -> str:
    text = (HERE / template).read_text()
    for key, value in values.items():
        text = text.replace(f"@{key}@", value)
    return text


def _write_config(path: Path, text: str, mode: int):
    if path.exists() and MARKER not in path.read_text(errors="replace"):
        raise ClusterError(
            f"{path} exists and was not written by make cluster-test: this host has its own "
            "SLURM configuration; run the test on a machine without one"
        )
    path.write_text(text)
    path.chmod(mode)


def write_configuration(state: Path, accounting: bool) -> dict:
    """slurm.conf (and slurmdbd.conf with accounting) for this host; the values used."""
    values = {
        **host_resources(),
        "STATE": str(state),
        "MARKER": MARKER,
        "DB_PORT": str(DB_PORT),
        "ACCOUNTING": WITH_ACCOUNTING if accounting else WITHOUT_ACCOUNTING,
    }
    for sub in ("slurmctld", "slurmd", "log", "pids"):
        (state / sub).mkdir(parents=True, exist_ok=True)
    SLURM_ETC.mkdir(exist_ok=True)
    _write_config(SLURM_ETC / "slurm.conf", _fill("slurm.conf.in", values), 0o644)
    if accounting:
        password = state / "db-password"
        if not password.exists():
            password.write_text(secrets.token_hex(16))
            password.chmod(0o600)
        values["DB_PASSWORD"] = password.read_text().strip()
        _write_config(SLURM_ETC / "slurmdbd.conf", _fill("slurmdbd.conf.in", values), 0o600)
    return values


def remove_configuration() -> list[str]:
    """Remove the slurm.conf and slurmdbd.conf this test wrote (the marker says so): left behind,
    every `scontrol`/`sinfo` on the host waits 9 s for a controller that is gone, and so does every
    snakemake run, which asks `scontrol show config` when SLURM is installed."""
    removed = []
    for name in ("slurm.conf", "slurmdbd.conf"):
        path = SLURM_ETC / name
        if path.exists() and MARKER in path.read_text(errors="replace"):
            path.unlink()
            removed.append(str(path))
    return removed


# -- daemons --------------------------------------------------------------------------------------
def _alive_as(pid: int, exe: str) -> bool:
    """Is pid still the process started from exe (not a later process that reuses the number)?"""
    try:
        return os.path.realpath(f"/proc/{pid}/exe") == exe and not _is_zombie(pid)
    except OSError:
        return False


def _is_zombie(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] == "Z"
    except (OSError, IndexError):
        return True


def _terminate(pid: int, exe: str, timeout: float = 30.0):
    """SIGTERM, then SIGKILL after timeout seconds, to this one PID if it still runs exe."""
    for sig in (signal.SIGTERM, signal.SIGKILL):
        if not _alive_as(pid, exe):
            return
        os.kill(pid, sig)
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline and _alive_as(pid, exe):
            time.sleep(0.2)
    if _alive_as(pid, exe):
        raise ClusterError(f"pid {pid} ({exe}) survived SIGKILL")


def stop_recorded(state: Path) -> list[str]:
    """Stop the daemons an interrupted earlier run recorded in <state>/pids (newest first)."""
    stopped = []
    for record in sorted((state / "pids").glob("*.pid"), reverse=True):
        pid, exe = record.read_text().split()[:2]
        if _alive_as(int(pid), exe):
            _terminate(int(pid), exe)
            stopped.append(f"{record.stem} (pid {pid})")
        record.unlink()
    return stopped


class Daemons:
    """The daemons this run started, in order; each recorded as <state>/pids/NN-name.pid (PID, exe)."""

    def __init__(self, state: Path):
        self.state = state
        self.started: list[tuple[str, subprocess.Popen, str, Path]] = []
        (state / "pids").mkdir(parents=True, exist_ok=True)
        (state / "log").mkdir(parents=True, exist_ok=True)

    def start(self, name: str, argv: list[str], ready, timeout: float = 60.0, user: str | None = None):
        # started by its PATH name (Debian's slurmctld-wlm, the alternative behind slurmctld, crashes when
        # called by that name); the resolved executable is recorded, to recognise the PID later
        exe = os.path.realpath(shutil.which(argv[0]) or argv[0])
        log = self.state / "log" / f"{name}.out"
        with open(log, "ab") as out:
            process = subprocess.Popen(
                argv,
                stdout=out,
                stderr=subprocess.STDOUT,
                cwd=self.state / "log",
                stdin=subprocess.DEVNULL,
                start_new_session=True,
                user=user,
            )
        record = self.state / "pids" / f"{len(self.started) + 1:02d}-{name}.pid"
        record.write_text(f"{process.pid}\n{exe}\n")
        self.started.append((name, process, exe, record))
        wait_until(ready, name, timeout, process, log)
        return process.pid

    def stop_all(self) -> list[str]:
        """Stop every daemon started here (last started first), by PID; return 'name pid' each."""
        stopped = []
        while self.started:
            name, process, exe, record = self.started.pop()
            if process.poll() is None:
                _terminate(process.pid, exe)
            process.wait(timeout=10)
            record.unlink(missing_ok=True)
            stopped.append(f"{name} {process.pid}")
        return stopped


def _answers(argv, expect: str = "") -> bool:
    try:
        done = subprocess.run(argv, capture_output=True, text=True, timeout=15)
    except subprocess.TimeoutExpired:
        return False
    return done.returncode == 0 and expect in done.stdout


def _munge_answers() -> bool:
    try:
        cred = subprocess.run(["munge", "-n"], capture_output=True, timeout=10)
        return (
            cred.returncode == 0
            and subprocess.run(["unmunge"], input=cred.stdout, capture_output=True, timeout=10).returncode == 0
        )
    except subprocess.TimeoutExpired:
        return False


def start_munge(daemons: Daemons) -> str:
    """Our munged, unless one already answers here (then it is used and left alone)."""
    if _munge_answers():
        return "munged: already running here, used and left running (not started by this test)"
    run_dir = Path("/run/munge")
    run_dir.mkdir(mode=0o755, exist_ok=True)
    shutil.chown(run_dir, "munge", "munge")
    if not Path("/etc/munge/munge.key").exists():
        run(["mungekey", "--create"], user="munge")
    pid = daemons.start("munged", ["munged", "--foreground"], _munge_answers, user="munge")
    return f"munged: started, pid {pid}"


def start_mariadb(daemons: Daemons, state: Path, password: str) -> str:
    """A private mariadbd (datadir <state>/mysql, 127.0.0.1:DB_PORT) with the slurm database user."""
    datadir, sock = state / "mysql", state / "mysql" / "mysqld.sock"
    if not (datadir / "mysql").is_dir():
        datadir.mkdir(parents=True, exist_ok=True)
        shutil.chown(datadir, "mysql", "mysql")
        run(
            [
                "mariadb-install-db",
                "--no-defaults",
                f"--datadir={datadir}",
                "--user=mysql",
                "--skip-test-db",
                "--auth-root-authentication-method=socket",
            ],
            timeout=300,
        )
    argv = [
        "mariadbd",
        "--no-defaults",
        f"--datadir={datadir}",
        f"--socket={sock}",
        f"--port={DB_PORT}",
        "--bind-address=127.0.0.1",
        "--skip-name-resolve",
        "--user=mysql",
        f"--pid-file={datadir / 'mariadbd.pid'}",
        f"--log-error={state / 'log' / 'mariadbd.log'}",
    ]
    ping = ["mariadb-admin", "--no-defaults", f"--socket={sock}", "-u", "root", "ping"]
    pid = daemons.start("mariadbd", argv, lambda: _answers(ping), timeout=120)
    sql = (
        f"CREATE USER IF NOT EXISTS 'slurm'@'127.0.0.1' IDENTIFIED BY '{password}'; "
        f"ALTER USER 'slurm'@'127.0.0.1' IDENTIFIED BY '{password}'; "
        "GRANT ALL PRIVILEGES ON slurm_acct_db.* TO 'slurm'@'127.0.0.1'; FLUSH PRIVILEGES;"
    )
    run(["mariadb", "--no-defaults", f"--socket={sock}", "-u", "root", "-e", sql])
    return f"mariadbd: started, pid {pid}"


def start_slurmdbd(daemons: Daemons, cluster: str) -> str:
    """slurmdbd, then the cluster, the account ACCOUNT and root's association with it."""
    pid = daemons.start(
        "slurmdbd", ["slurmdbd", "-D"], lambda: _answers(["sacctmgr", "-n", "list", "cluster"]), timeout=120
    )
    run(["sacctmgr", "-i", "add", "cluster", cluster], check=False)
    run(
        [
            "sacctmgr",
            "-i",
            "add",
            "account",
            ACCOUNT,
            f"Cluster={cluster}",
            "Description=vemkit cluster test",
            "Organization=vemkit",
        ],
        check=False,
    )
    run(
        [
            "sacctmgr",
            "-i",
            "add",
            "user",
            "root",
            f"Account={ACCOUNT}",
            f"DefaultAccount={ACCOUNT}",
            f"Cluster={cluster}",
        ],
        check=False,
    )
    assocs = run(["sacctmgr", "-n", "-P", "show", "assoc", "user=root", "format=account"]).stdout.split()
    if ACCOUNT not in assocs:
        raise ClusterError(f"sacctmgr: root has no association with account {ACCOUNT} (has {assocs})")
    return f"slurmdbd: started, pid {pid}"


def start_slurm(daemons: Daemons, host: str) -> list[str]:
    """slurmctld (fresh: its saved state removed; `slurmctld -c` crashes with slurmdbd in 22.05.8) and
    slurmd; wait until the node is idle."""
    saved = daemons.state / "slurmctld"
    shutil.rmtree(saved, ignore_errors=True)
    saved.mkdir()
    ctld = daemons.start("slurmctld", ["slurmctld", "-D"], lambda: _answers(["scontrol", "ping"], "UP"))
    slurmd = daemons.start("slurmd", ["slurmd", "-D"], lambda: _answers(["sinfo", "-h", "-N", "-o", "%T"], ""))

    def idle() -> bool:
        state = run(["sinfo", "-h", "-N", "-n", host, "-o", "%T"], check=False).stdout.strip()
        if state.startswith(("drain", "down")):
            run(["scontrol", "update", f"nodename={host}", "state=resume"], check=False)
        return state.startswith("idle")

    wait_until(idle, f"node {host} idle", 90, log=daemons.state / "log" / "slurmd.log")
    return [f"slurmctld: started, pid {ctld}", f"slurmd: started, pid {slurmd}"]


def start_cluster(daemons: Daemons, state: Path, accounting: bool, values: dict) -> list[str]:
    """Every daemon of the mode, in dependency order; one line per daemon."""
    lines = [start_munge(daemons)]
    if accounting:
        lines.append(start_mariadb(daemons, state, values["DB_PASSWORD"]))
        lines.append(start_slurmdbd(daemons, "vemkit-test"))
    lines += start_slurm(daemons, values["HOST"])
    return lines


def host_is_free() -> None:
    """Refuse to start when slurmctld/slurmd/slurmdbd already listen here (someone else's cluster)."""
    for port, name in ((6817, "slurmctld"), (6818, "slurmd"), (6819, "slurmdbd"), (DB_PORT, "mariadbd")):
        with socket.socket() as probe:
            probe.settimeout(1)
            if probe.connect_ex(("127.0.0.1", port)) == 0:
                raise ClusterError(
                    f"port {port} ({name}) is in use: a daemon not started by this test runs "
                    "here; stop it (or run the test on another machine)"
                )
