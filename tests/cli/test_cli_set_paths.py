"""``--set`` key paths and long expressions (issue 18, item 5), through the real command: list entries
are indexed as a user writes them (``boundary.dirichlet[0]=top``), bounds and types are checked in one
true line, an empty key component is refused, and a long flat sum is not called "nested"."""

import subprocess
import sys
from pathlib import Path

import pytest
import xarray as xr
import yaml

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "config" / "scenes" / "paper.yaml"


def solve(tmp_path, *sets):
    args = [a for s in (*sets, "discretization.mesh.n=4") for a in ("--set", s)]
    return subprocess.run(
        [sys.executable, "-m", "vemkit.cli", "solve", PAPER, "-o", tmp_path / "out.nc", "-q", *args],
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_a_list_entry_is_set_by_its_index(tmp_path):
    """The paper scene clamps [right]; clamp the top instead (its traction dropped first)."""
    run = solve(tmp_path, "boundary.neumann={left: {traction: ['200*(5-y)', -200]}}", "boundary.dirichlet[0]=top")
    assert run.returncode == 0 and not run.stderr, run.stderr
    with xr.open_dataset(tmp_path / "out.nc") as ds:
        assert yaml.safe_load(ds.attrs["scene"])["boundary"]["dirichlet"] == ["top"]


SUM = "+".join(["x"] * 300)  # a flat chain: 299 BinOps deep, nesting 1
GROUPED = "+".join(["(" + "+".join(["x"] * 30) + ")"] * 10)


@pytest.mark.parametrize(
    "override, says",
    [
        (
            "boundary.dirichlet[1]=left",
            'boundary.dirichlet = ["right"] has 1 entry: give the index 0, or set the '
            "whole list, e.g. --set 'boundary.dirichlet=[...]'",
        ),
        ("body_force[2]=1", "body_force = [0.0, 0.0] has 2 entries: give an index 0 ... 1"),
        ("boundary.dirichlet[0]=3", "boundary.dirichlet[0] = 3: must be a string"),
        ("boundary.dirichlet[0][1]=x", "boundary.dirichlet[0] = 'right' is not a list; drop [1]"),
        ("material[0]=1", 'material = {"E": 2000.0, "nu": 0.4} is not a list; drop [0]'),
        ("boundary.dirichlet.left=[0,0]", 'boundary.dirichlet = ["right"] is a list: index it (boundary.dirichlet[0])'),
        ("boundary.dirichlet[-1]=left", "a list index is a whole number from 0 in brackets"),
        ("material..E=3", "a key component is empty"),
        ("material.E.=3", "a key component is empty"),
        (".material.E=3", "a key component is empty"),
        (
            f"body_force[0]={SUM}",
            "more than 100 operations in one chain (a sum or product of that many terms); "
            "group the terms in parentheses",
        ),
    ],
)
def test_bad_key_paths_and_long_sums_are_one_true_line(tmp_path, override, says):
    run = solve(tmp_path, override)
    assert run.returncode == 2 and run.stderr.count("\n") == 1, run.stderr
    assert says in run.stderr and "nested" not in run.stderr, run.stderr
    assert not (tmp_path / "out.nc").exists()


def test_a_long_sum_grouped_in_parentheses_solves(tmp_path):
    run = solve(tmp_path, f"body_force[0]={GROUPED}")
    assert run.returncode == 0, run.stderr
