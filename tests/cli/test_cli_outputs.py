"""Outputs never destroy what the user had; signals end a run cleanly (issue 9), through the real CLI."""

import os
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


def command(*args):
    return [sys.executable, "-m", "vemkit.cli", *map(str, args)]


def _leftovers(path: Path) -> list:
    return sorted(p.name for p in path.iterdir() if p.name.endswith(".part"))


def test_success_replaces_the_file_a_link_points_to(tmp_path):
    real = tmp_path / "real.nc"
    real.write_bytes(EARLIER)
    os.symlink(real, tmp_path / "link.nc")
    run = subprocess.run(
        command("mesh", "square", 3, "-o", "link.nc", "--vtu", "m.vtu", "-q"),
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0 and not run.stderr, run.stderr
    assert (tmp_path / "link.nc").is_symlink()
    with xr.open_dataset(real) as ds:
        assert ds.sizes["mesh2d_nFaces"] == 9
    assert (real.stat().st_mode & 0o777) == 0o666 & ~_umask()
    assert (tmp_path / "m.vtu").read_bytes().startswith(b"<?xml") and not _leftovers(tmp_path)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _assert_earlier_or_complete(out: Path, nodes: int, earlier: bool = True) -> None:
    if earlier and out.read_bytes() == EARLIER:
        return
    with xr.open_dataset(out) as ds:
        assert ds.sizes["mesh2d_nNodes"] == nodes and ds.attrs["iterations"] >= 1


@pytest.mark.slow
@pytest.mark.parametrize("signame, status", [("SIGINT", 130), ("SIGTERM", 143)])
def test_a_signal_at_any_moment_leaves_the_earlier_file_and_no_temporary(tmp_path, signame, status):
    """Signals sent while Python starts, while the scene is read, during the solve and around the
    write: the run ends promptly with 128 + signal (or by the default action while Python starts
    or shuts down); out.nc is the earlier file or a complete new result, never a part."""
    out = tmp_path / "out.nc"
    for delay in (0.3, 1.5, 3.0, 5.0):
        out.write_bytes(EARLIER)
        process = subprocess.Popen(
            command("solve", PAPER, "-o", out, "-q", "--set", "discretization.mesh.n=96"),
            stderr=subprocess.PIPE,
            text=True,
        )
        time.sleep(delay)
        process.send_signal(getattr(signal, signame))
        start = time.perf_counter()
        _, stderr = process.communicate(timeout=60)
        assert time.perf_counter() - start < 10, f"{signame} after {delay} s: not prompt"
        assert "Traceback" not in stderr, stderr
        assert not _leftovers(tmp_path), (delay, _leftovers(tmp_path))
        if delay < 1.0:  # Python is still starting: nothing of the earlier file may change
            assert out.read_bytes() == EARLIER
        elif process.returncode == -getattr(signal, signame):
            # the default action ended the process: either Python was still starting (under load
            # this can take seconds) or it was already shutting down after the write (the
            # interpreter restores the default handlers then): the earlier file or a whole result
            _assert_earlier_or_complete(out, 97**2)
        elif process.returncode == 0 or "wrote" in stderr:  # it had finished: a complete result
            assert process.returncode in (0, status), (delay, process.returncode, stderr)
            _assert_earlier_or_complete(out, 97**2, earlier=False)
        else:
            assert process.returncode == status, (delay, process.returncode, stderr)
            assert (
                out.read_bytes() == EARLIER and stderr.strip() == f"vemkit: interrupted by {signame}; no output written"
            )


WRITE_INTERRUPTED = """
import os, signal, sys, time
from vemkit.cli import main
from vemkit.mesh.file_description import FileDescription  # the command's netCDF writer
original = FileDescription.write_netcdf4
def slow_write(self, path, *args, **kwargs):
    original(self, path, *args, **kwargs)
    os.kill(os.getpid(), signal.{signame})
    time.sleep(0.2)
    open(sys.argv[-1], "w").write("written, then signalled")
FileDescription.write_netcdf4 = slow_write
sys.exit(main(sys.argv[1:-1]))
"""


@pytest.mark.parametrize("signame, status", [("SIGINT", 130), ("SIGTERM", 143)])
def test_a_signal_inside_the_netcdf_write_is_delivered_after_it(tmp_path, signame, status):
    """The write cannot hang on a lock (the signal waits until the writer returned) and the
    half-made result is discarded."""
    out, marker = tmp_path / "out.nc", tmp_path / "marker"
    out.write_bytes(EARLIER)
    run = subprocess.run(
        [
            sys.executable,
            "-c",
            WRITE_INTERRUPTED.format(signame=signame),
            "solve",
            PAPER,
            "-o",
            out,
            "-q",
            "--set",
            "discretization.mesh.n=4",
            marker,
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert marker.read_text() == "written, then signalled"
    assert run.returncode == status, run.stderr
    assert out.read_bytes() == EARLIER and not _leftovers(tmp_path)
    assert run.stderr.strip() == f"vemkit: interrupted by {signame}; no output written"


def test_two_runs_writing_one_file_leave_one_complete_file(tmp_path):
    out = tmp_path / "out.nc"
    out.write_bytes(EARLIER)
    runs = [
        subprocess.Popen(
            command("solve", PAPER, "-o", out, "-q", "--set", f"discretization.mesh.n={n}"),
            stderr=subprocess.PIPE,
            text=True,
        )
        for n in (8, 9)
    ]
    for process in runs:
        assert process.wait(timeout=240) == 0, process.stderr.read()
    with xr.open_dataset(out) as ds:
        assert ds.sizes["mesh2d_nNodes"] in (9**2, 10**2) and ds.attrs["iterations"] >= 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.nc"]
