"""``discretization.volumetric_strain`` through the real ``vemkit solve``: a bad value, and
``nodal_average`` at order 2 (which does not lock), are refused in one line naming the key, exit 2."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "config" / "scenes" / "paper.yaml"


@pytest.mark.parametrize(
    "sets, fix",
    [
        (["discretization.volumetric_strain=bogus"], "must be one of auto, cell, nodal_average"),
        (
            ["discretization.volumetric_strain=nodal_average", "discretization.order=2"],
            "needs discretization.order = 1 (k = 2 does not lock); drop it or set discretization.volumetric_strain=cell",
        ),
    ],
)
def test_bad_values_are_refused_in_one_line(tmp_path, sets, fix):
    args = [a for s in sets for a in ("--set", s)]
    run = subprocess.run(
        [sys.executable, "-m", "vemkit.cli", "solve", PAPER, "-o", tmp_path / "out.nc", "-q", *args],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 2
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and "discretization.volumetric_strain" in lines[0] and fix in lines[0], run.stderr
    assert not (tmp_path / "out.nc").exists()
