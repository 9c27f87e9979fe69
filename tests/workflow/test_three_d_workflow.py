"""`snakemake three_d` (dry runs: nothing is solved): one job per manufactured case of
config/three_d.yaml, one per study, a figure per case, not in the default target; bad settings are
refused naming the key."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest
import yaml
from snakemake_runs import dry_run as run_dry

ROOT = Path(__file__).resolve().parents[2]
CONFIG = yaml.safe_load((ROOT / "config" / "three_d.yaml").read_text())
THREE_D = CONFIG["three_d"]


def dry_run(*args) -> subprocess.CompletedProcess:
    return run_dry(*args, cores=2)


def planned(*args) -> dict:
    run = dry_run(*args)
    assert run.returncode == 0, run.stdout + run.stderr
    stats = run.stdout[run.stdout.index("Job stats:") :]
    stats = stats[: stats.index("total")]
    return {m.group(1): int(m.group(2)) for m in re.finditer(r"^(\w+)\s+(\d+)\s*$", stats, re.M)}


def test_three_d_plans_every_case_and_study_and_is_not_in_the_default_target():
    jobs = planned("three_d")
    cases = len(THREE_D["manufactured"])
    assert cases >= 5
    assert jobs == {
        "three_d": 1,
        "three_d_manufactured": cases,
        "three_d_convergence": 1,
        "three_d_lame": 1,
        "three_d_plane_strain": 1,
        "three_d_plane_stress": 1,
        "three_d_figure": cases + 1,
        "three_d_hertz": 1,
        "three_d_mindlin": 1,
    }
    assert not any(rule.startswith("three_d") for rule in planned())
    for case in THREE_D["manufactured"].values():
        assert (ROOT / case["scene"]).is_file()
    for study in ("hertz", "mindlin"):
        assert (ROOT / CONFIG[study]["scene"]).is_file()


def test_a_bad_setting_is_refused_naming_the_key(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump({"three_d": {**THREE_D, "lame": {**THREE_D["lame"], "families": ["hex"]}}}))
    run = dry_run("three_d", "--configfile", str(path))
    assert run.returncode != 0
    assert "three_d.lame.families[0]" in run.stdout + run.stderr


@pytest.mark.parametrize(
    ("study", "bad", "key"),
    [
        ("mindlin", {"shift": [0.001]}, "mindlin.shift: unknown key (did you mean 'shifts'?)"),
        ("hertz", {"nu": 0.5}, "hertz.nu"),
        ("mindlin", {"solver": {"linear": "auto"}}, "mindlin.solver.linear"),
    ],
)
def test_a_bad_contact_setting_is_refused_naming_the_key(tmp_path, study, bad, key):
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump({**CONFIG, study: {**CONFIG[study], **bad}}))
    run = dry_run("three_d", "--configfile", str(path))
    assert run.returncode != 0
    assert key in run.stdout + run.stderr
