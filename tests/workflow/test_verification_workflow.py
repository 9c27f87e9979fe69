"""The `verification` target (dry run: nothing is solved): one job per shipped scene and family,
one gather, one report. (That none of it is in the default target: test_workflow.py, which pins
the default target's rules.)"""

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from vemkit.studies.verification import CASES, FAMILY_OPTIONS

ROOT = Path(__file__).resolve().parents[2]


def _jobs(*targets) -> dict:
    exe = Path(sys.executable).with_name("snakemake")
    exe = str(exe) if exe.exists() else shutil.which("snakemake")
    if exe is None:
        pytest.skip("snakemake is not installed")
    run = subprocess.run(
        [exe, "--dry-run", "--forceall", "--nolock", "--cores", "2", *targets],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    stats = run.stdout[run.stdout.index("Job stats:") :]
    return {
        m.group(1): int(m.group(2)) for m in re.finditer(r"^(\w+)\s+(\d+)\s*$", stats[: stats.index("total")], re.M)
    }


def test_verification_target_runs_every_scene_on_every_family():
    jobs = _jobs("verification")
    assert jobs == {
        "verification_run": len(CASES) * len(FAMILY_OPTIONS),
        "verification_gather": 1,
        "verification_report": 1,
        "verification": 1,
    }
    assert set(CASES) == {"cook", "kirsch", "hertz", "lbracket"}
    assert all(len(case.sizes) >= 3 and list(case.sizes) == sorted(case.sizes, reverse=True) for case in CASES.values())
    for name in CASES:
        assert (ROOT / "config" / "scenes" / f"{name}.yaml").is_file()
