"""The pipeline's dry run, as the workflow tests call it: ``snakemake --dry-run --forceall`` from the
repository's root (skipped where snakemake is not installed)."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def dry_run(*args, cores: int = 1) -> subprocess.CompletedProcess:
    exe = Path(sys.executable).with_name("snakemake")
    exe = str(exe) if exe.exists() else shutil.which("snakemake")
    if exe is None:
        pytest.skip("snakemake is not installed")
    return subprocess.run(
        [exe, "--dry-run", "--forceall", "--nolock", "--cores", str(cores), *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
