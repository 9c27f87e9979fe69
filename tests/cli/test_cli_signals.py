"""SIGINT/SIGTERM end a run within a second, even inside a long Numba kernel (issue 18, item 8), through
the real command (``python -m vemkit.cli`` and the console entry point: the work runs in a forked
worker, the parent handles the signal, vemkit.io.supervisor): exit 130/143, no ``.part`` left, the
earlier output untouched. Before, the handler waited until the running kernel returned."""

import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import xarray as xr

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "config" / "scenes" / "paper.yaml"
EARLIER = b"an earlier result"
LIMIT = 1.0  # seconds from the signal to the exit (README, "Signals")

# the real command line path (main() with no argv), with a marker file written when a phase starts
HARNESS = """
import sys
import vemkit.cli as cli
MARK, OUT = sys.argv.pop(1), sys.argv[-1]
{patch}
sys.exit(cli.main())
"""
IN_A_KERNEL = """
def long_kernel(argv):
    from pathlib import Path
    import numba
    from vemkit.io import output_files

    @numba.njit(cache=False)
    def spin(n):
        total = 0.0
        for i in range(n):
            total += (i % 7) * 1e-9
        return total

    spin(10)  # compiled before the marker: the signal lands inside the compiled loop
    output_files._temporary_next_to(Path(OUT).resolve())  # a .part the parent must remove
    open(MARK, "w").close()
    return 0 if spin(40_000_000_000) > 0 else 1  # tens of seconds in one kernel call
cli._run = long_kernel
"""
IN_ASSEMBLY = """
original_run = cli._run
def marked_run(argv):
    import vemkit.vem.assembly as assembly
    assemble = assembly.stiffness_matrix
    def marked(*args, **kwargs):
        open(MARK, "w").close()
        return assemble(*args, **kwargs)
    assembly.stiffness_matrix = marked
    return original_run(argv)
cli._run = marked_run
"""


def _parts(folder: Path) -> list:
    return sorted(p.name for p in folder.iterdir() if p.name.endswith(".part"))


def _signalled(tmp_path, patch, args, signame, wait_for_mark=True, delay=0.0):
    """Start the command, signal it once the marker exists (or after ``delay``); returns
    (process, stderr, seconds from the signal to the exit)."""
    mark, out = tmp_path / "mark", tmp_path / "out.nc"
    mark.unlink(missing_ok=True)
    out.write_bytes(EARLIER)
    process = subprocess.Popen(
        [sys.executable, "-c", HARNESS.format(patch=patch), mark, *args, "-o", out],
        stderr=subprocess.PIPE,
        text=True,
        cwd=tmp_path,
    )
    deadline = time.monotonic() + 120
    while wait_for_mark and not mark.exists() and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    time.sleep(delay)
    start = time.monotonic()
    process.send_signal(getattr(signal, signame))
    try:
        _, stderr = process.communicate(timeout=60)
    finally:
        process.kill()
    return process, stderr, time.monotonic() - start


@pytest.mark.parametrize("signame, status", [("SIGINT", 130), ("SIGTERM", 143)])
def test_a_signal_inside_a_long_numba_kernel_ends_the_run_within_a_second(tmp_path, signame, status):
    process, stderr, latency = _signalled(tmp_path, IN_A_KERNEL, ["solve", PAPER], signame)
    assert latency < LIMIT, f"{signame}: {latency:.2f} s inside the kernel"
    assert process.returncode == status, stderr
    assert stderr.strip() == f"vemkit: interrupted by {signame}; no output written"
    assert not _parts(tmp_path) and (tmp_path / "out.nc").read_bytes() == EARLIER


@pytest.mark.slow
@pytest.mark.parametrize("signame, status", [("SIGINT", 130), ("SIGTERM", 143)])
def test_a_large_k2_solve_signalled_during_assembly_and_later_ends_within_a_second(tmp_path, signame, status):
    """k = 2 on 512^2 squares (about 8 s): signalled as the assembly starts, and 1, 2.5 s after it
    (the solve); a run that finished first leaves a complete result."""
    args = ["solve", PAPER, "-q", "--set", "discretization.order=2", "--set", "discretization.mesh.n=512"]
    for delay in (0.0, 0.3, 1.0, 2.5):
        process, stderr, latency = _signalled(tmp_path, IN_ASSEMBLY, args, signame, delay=delay)
        assert latency < LIMIT, f"{signame} {delay} s after the assembly started: {latency:.2f} s"
        assert not _parts(tmp_path), (delay, _parts(tmp_path))
        assert "Traceback" not in stderr, stderr
        if process.returncode == 0:  # it had finished: a complete result
            with xr.open_dataset(tmp_path / "out.nc") as ds:
                assert ds.attrs["order"] == 2
        else:
            assert process.returncode == status, (delay, process.returncode, stderr)
            assert (tmp_path / "out.nc").read_bytes() == EARLIER, delay


def test_the_worker_dies_with_its_parent(tmp_path):
    """A parent killed outright (SIGKILL: no handler) takes its worker with it (PR_SET_PDEATHSIG)."""
    process, stderr, _ = _signalled(tmp_path, IN_A_KERNEL, ["solve", PAPER], "SIGKILL")
    assert process.returncode == -signal.SIGKILL
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline:
        found = subprocess.run(["pgrep", "-f", str(tmp_path / "mark")], capture_output=True, text=True).stdout
        if not found.strip():
            break
        time.sleep(0.1)
    assert not found.strip(), f"worker left running: {found}"


IN_THE_WRITE = """
original_run = cli._run
def marked_run(argv):
    import time
    from vemkit.mesh.file_description import FileDescription  # the command's netCDF writer
    write = FileDescription.write_netcdf4
    def slow_write(self, path, *args, **kwargs):
        write(self, path, *args, **kwargs)
        open(MARK, "w").close()
        time.sleep(0.5)
        open(MARK + ".written", "w").close()
    FileDescription.write_netcdf4 = slow_write
    return original_run(argv)
cli._run = marked_run
"""


@pytest.mark.parametrize("signame, status", [("SIGINT", 130), ("SIGTERM", 143)])
def test_a_signal_during_the_final_write_waits_for_the_writer_then_discards_it(tmp_path, signame, status):
    """The parent forwards a signal that comes while the worker writes: the writer finishes (never
    interrupted inside a lock), then the run ends with 128 + signal and the earlier file."""
    args = ["solve", PAPER, "-q", "--set", "discretization.mesh.n=4"]
    process, stderr, latency = _signalled(tmp_path, IN_THE_WRITE, args, signame)
    assert (tmp_path / "mark.written").exists() and latency < LIMIT + 0.5
    assert process.returncode == status, stderr
    assert stderr.strip() == f"vemkit: interrupted by {signame}; no output written"
    assert not _parts(tmp_path) and (tmp_path / "out.nc").read_bytes() == EARLIER


def test_the_supervised_command_keeps_every_exit_status_and_stream(tmp_path):
    """The parent exits with the worker's status: --version / --help (argparse's own exits) 0, a
    usage error 2 in one line, a solve 0 with its summary on stdout."""

    def run(*args):
        return subprocess.run(
            [sys.executable, "-m", "vemkit.cli", *map(str, args)],
            capture_output=True,
            text=True,
            timeout=300,
            cwd=tmp_path,
        )

    version = run("--version")
    assert version.returncode == 0 and version.stdout.startswith("vemkit ") and not version.stderr
    assert run("--help").returncode == 0
    usage = run("solve")
    assert usage.returncode == 2 and usage.stderr.count("\n") == 1 and "required" in usage.stderr
    solved = run("solve", PAPER, "-o", "o.nc", "--set", "discretization.mesh.n=4")
    assert solved.returncode == 0 and solved.stdout.startswith("o.nc: ssn converged") and not solved.stderr


def test_sigint_as_the_part_file_appears_never_leaves_it(tmp_path):
    """SIGINT sent the moment ``.out.nc.XXXX.part`` appears, plus a random 0-3 ms, 24 times: never a
    ``.part`` left (issue 33: once 1 in 24, a signal landing while the parent was reading the
    worker's records ``hold`` / ``part NAME`` made it lose them), the earlier file or a complete one."""
    rng = random.Random(33)
    args = [
        sys.executable,
        "-m",
        "vemkit.cli",
        "solve",
        PAPER,
        "-o",
        "out.nc",
        "-q",
        *("--set", "discretization.mesh.n=2"),
    ]
    for attempt in range(24):
        (tmp_path / "out.nc").write_bytes(EARLIER)
        process = subprocess.Popen(args, cwd=tmp_path, stderr=subprocess.PIPE, text=True)
        deadline = time.monotonic() + 120
        while process.poll() is None and not _parts(tmp_path) and time.monotonic() < deadline:
            time.sleep(0.0005)
        time.sleep(rng.uniform(0.0, 0.003))
        process.send_signal(signal.SIGINT)
        try:
            _, stderr = process.communicate(timeout=60)
        finally:
            process.kill()
        assert not _parts(tmp_path), (attempt, _parts(tmp_path), stderr)
        assert process.returncode in (0, 130) and "Traceback" not in stderr, (attempt, stderr)
        if (tmp_path / "out.nc").read_bytes() != EARLIER:  # it had replaced the file: a complete result
            with xr.open_dataset(tmp_path / "out.nc") as ds:
                assert ds.attrs["solver"] == "ssn", attempt
