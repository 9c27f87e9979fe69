"""Output paths of every kind a user may give (issue 18, item 4), through the real command: names
that are not UTF-8, folders where a file can be made but not renamed or removed, paths so long that
they would crowd the reason out of the one-line error."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "config" / "scenes" / "paper.yaml"
SMALL = ("--set", "discretization.mesh.n=4")


def vemkit(*args, cwd):
    """The real command; arguments may be bytes (file names that are not UTF-8)."""
    return subprocess.run(
        [
            os.fsencode(sys.executable),
            b"-m",
            b"vemkit.cli",
            *(os.fsencode(a if isinstance(a, bytes) else str(a)) for a in args),
        ],
        cwd=cwd,
        capture_output=True,
        timeout=300,
    )


def _parts(folder: Path) -> list:
    return [p for p in os.listdir(os.fsencode(folder)) if p.endswith(b".part")]


def test_output_names_that_are_not_utf8_are_written_and_shown_escaped(tmp_path):
    """b'out\\xff.nc' is a valid Linux name: solve writes it (and a VTU, and into a folder whose
    name is not UTF-8), and the summary shows the byte as \\xff."""
    folder = os.fsencode(tmp_path) + b"/d\xfe"
    os.mkdir(folder)
    run = vemkit("solve", PAPER, "-o", b"out\xff.nc", "--vtu", folder + b"/v\xff.vtu", *SMALL, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert run.stdout.decode().startswith("out\\xff.nc: ssn converged")
    assert os.path.getsize(os.fsencode(tmp_path) + b"/out\xff.nc") > 1000
    assert open(folder + b"/v\xff.vtu", "rb").read(5) == b"<?xml"
    run = vemkit("mesh", "square", 2, "-o", folder + b"/m\xff.nc", "-q", cwd=tmp_path)
    assert run.returncode == 0 and not run.stderr, run.stderr
    assert not _parts(tmp_path) and not _parts(Path(os.fsdecode(folder)))


def _append_only(folder: Path) -> bool:
    if shutil.which("chattr") is None:
        return False
    return subprocess.run(["chattr", "+a", str(folder)], capture_output=True).returncode == 0


def test_an_append_only_folder_is_refused_before_any_work(tmp_path):
    """chattr +a: a file can be made there but never renamed over the target nor removed; the run
    is refused before it solves anything, and the folder is left empty."""
    folder = tmp_path / "logs"
    folder.mkdir()
    if not _append_only(folder):
        pytest.skip("chattr +a needs root and a file system with inode flags")
    try:
        run = vemkit("solve", PAPER, "-o", folder / "out.nc", *SMALL, cwd=tmp_path)
        message = run.stderr.decode()
        assert run.returncode == 2 and message.count("\n") == 1, message
        assert "append-only (chattr +a)" in message and "chattr -a" in message
        assert os.listdir(folder) == []
    finally:
        subprocess.run(["chattr", "-a", str(folder)], check=True)


LEFT_BEHIND = """
import errno, os, sys
from vemkit.cli import main
def refuse(*args, **kwargs):
    raise PermissionError(errno.EPERM, "Operation not permitted", str(args[0]))
os.replace = os.unlink = refuse
sys.exit(main(sys.argv[1:]))
"""


def test_a_temporary_file_that_cannot_be_removed_is_named_in_a_true_message(tmp_path):
    """Where the folder refuses renames and removals after the check (attributes changed during
    the run, a file system that hides them): the message says that nothing was written *and* which
    temporary file is left, never only 'nothing was written'."""
    out = tmp_path / "out.nc"
    out.write_bytes(b"earlier")
    run = subprocess.run(
        [sys.executable, "-c", LEFT_BEHIND, "solve", PAPER, "-o", out, *SMALL],
        capture_output=True,
        text=True,
        timeout=300,
    )
    (left,) = _parts(tmp_path)
    assert run.returncode == 2 and run.stderr.count("\n") == 1, run.stderr
    assert "nothing was written" in run.stderr and os.fsdecode(left) in run.stderr
    assert "could not be removed (Operation not permitted); remove it by hand" in run.stderr
    assert out.read_bytes() == b"earlier"


@pytest.mark.parametrize("where", ["missing-folder", "long-name"])
def test_a_very_long_path_is_shortened_in_the_message_and_the_reason_stays_whole(tmp_path, where):
    deep = tmp_path.joinpath(*["d" * 200] * 20) / "out.nc" if where == "missing-folder" else tmp_path / ("n" * 400)
    run = vemkit("solve", PAPER, "-o", deep, *SMALL, cwd=tmp_path)
    message = run.stderr.decode()
    assert run.returncode == 2 and message.count("\n") == 1 and len(message) < 400, message
    fix = "does not exist; create it first" if where == "missing-folder" else "choose a shorter one"
    assert message.rstrip().endswith(fix) and "..." in message


def test_an_append_only_target_is_refused_before_any_work(tmp_path):
    """chattr +a on the file itself: it cannot be renamed over; refused, the file and the folder untouched."""
    out = tmp_path / "out.nc"
    out.write_bytes(b"earlier")
    if not _append_only(out):
        pytest.skip("chattr +a needs root and a file system with inode flags")
    try:
        run = vemkit("solve", PAPER, "-o", out, *SMALL, cwd=tmp_path)
        message = run.stderr.decode()
        assert run.returncode == 2 and message.count("\n") == 1, message
        assert "the file is append-only or immutable (chattr); it cannot be replaced" in message
        assert sorted(os.listdir(tmp_path)) == ["out.nc"] and out.read_bytes() == b"earlier"
    finally:
        subprocess.run(["chattr", "-a", str(out)], check=True)


def test_names_up_to_255_bytes_are_written(tmp_path):
    """Any name Linux takes is an output name (issue 33, item 5: names of 232-255 bytes were refused,
    the room kept for the temporary file's name): 255 bytes (ASCII, and 2-byte UTF-8 characters) for
    -o and --vtu, written, no .part left; 256 bytes refused in one line."""
    out = "o" * 252 + ".nc"
    vtu = ("\u00e9" * 125 + ".vtu").encode()  # 250 + 4 bytes: the temporary name is made ASCII
    vtu = vtu[:-4] + b"x.vtu"  # 255 bytes
    assert len(out.encode()) == 255 and len(vtu) == 255
    run = vemkit("solve", PAPER, "-o", out, "--vtu", vtu, "-q", *SMALL, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert (tmp_path / out).stat().st_size > 1000
    assert open(os.fsencode(tmp_path) + b"/" + vtu, "rb").read(5) == b"<?xml"
    assert not _parts(tmp_path)
    run = vemkit("solve", PAPER, "-o", "o" + out, *SMALL, cwd=tmp_path)
    message = run.stderr.decode()
    assert run.returncode == 2 and message.count("\n") == 1 and "a name at most 255 bytes" in message, message
