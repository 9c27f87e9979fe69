"""Provenance every result file records: package versions and the git commit of the checkout."""

from __future__ import annotations

import subprocess
from importlib import metadata

VERSIONED_PACKAGES = ("numpy", "scipy", "numba", "pyamg", "xarray", "netCDF4", "vemkit")


def package_versions(names=VERSIONED_PACKAGES) -> dict:
    """Installed versions of the packages behind a result ("not installed" where absent)."""
    out = {}
    for name in names:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "not installed"
    if "vemkit" in out:
        import vemkit

        out["vemkit"] = vemkit.__version__
    return out


def git_commit(path=".") -> str:
    """``git rev-parse HEAD`` of the repository holding ``path`` (with ``-dirty`` if the tracked
    files are modified), or ``"unknown"`` outside a git checkout or without git."""

    def git(*args):
        return subprocess.run(
            ["git", *args], cwd=path, capture_output=True, text=True, timeout=10, check=True
        ).stdout.strip()

    try:
        commit = git("rev-parse", "HEAD")
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    try:
        dirty = bool(git("status", "--porcelain", "--untracked-files=no"))
    except (OSError, subprocess.SubprocessError):
        dirty = False
    return commit + ("-dirty" if dirty else "")
