"""The workflow's configuration is checked when the Snakefile loads it, before any job (issue 33 item 4).

Every broken value below used to pass ``snakemake -n`` and fail inside a job (a traceback in its log),
or run to the end with a wrong result; now the dry run stops before planning any job, with exit 1 and
one line: the file that set the key, the config key (not the scene key it is forwarded to), the
problem and the fix. Dry runs only: nothing is built.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml
from snakemake_runs import dry_run

from vemkit.exceptions import WorkflowConfigError
from vemkit.studies.workflow_config import config_source

ROOT = Path(__file__).resolve().parents[2]
#: Snakemake's own notice for every --configfile; not an error line
NOTICE = re.compile(r"^Config file \S+ is extended by additional config specified via the command line\.$")
TINY_SWEEP = {"overrides": ["discretization.mesh.n=2"], "grid": {"contact.normal.k": [1.0]}}


def error_lines(run) -> list[str]:
    return [line for line in (run.stdout + run.stderr).splitlines() if line.strip() and not NOTICE.match(line)]


def assert_refused(run, source, key, *words):
    """Exit 1 before any job is planned, one line: ``{source}: {key}: ...`` with ``words``."""
    lines = error_lines(run)
    assert run.returncode == 1, run.stdout + run.stderr
    assert len(lines) == 1, lines
    assert lines[0].startswith(f"{source}: {key}: "), lines[0]
    for word in words:
        assert word in lines[0], lines[0]
    assert "Job stats" not in run.stdout and "Traceback" not in run.stderr


BROKEN = {
    # the seven of the issue: a traceback inside a job, or a wrong result with exit 0
    "figure-level": (
        {"three_d": {"figure_level": 10}},
        "three_d",
        "three_d.figure_level",
        ["10 is not an index of the 4 levels", "use 0..3"],
    ),
    "voronoi-seed": (
        {"meshes": {"voronoi": {"family": "voronoi", "options": {"seed": -1}}}},
        "results/table1.nc",
        "meshes.voronoi.options.seed",
        ["must be >= 0"],
    ),
    "paper-solver-tol": (
        {"solver": {"tol": 10}},
        "results/table1.nc",
        "solver.tol",
        ["config/scenes/paper.yaml", "must be <= 0.01"],
    ),
    "sweep-grid-value": (
        {"sweeps": {"tiny": {**TINY_SWEEP, "grid": {"contact.normal.k": [1.0, -1.0]}}}},
        "results/sweeps/tiny.nc",
        "sweeps.tiny.grid.contact.normal.k[1]",
        ["must be >= 0"],
    ),
    "three-d-solver-tol": ({"three_d": {"solver": {"tol": 10}}}, "three_d", "three_d.solver.tol", ["must be <= 0.01"]),
    "stability-solver-tol": (
        {"stability": {"solvers": {"ssn": {"tol": 10}}}},
        "extras",
        "stability.solvers.ssn.tol",
        ["must be <= 0.01"],
    ),
    "adaptivity-override": (
        {
            "adaptivity_study": {
                "scenes": {"tiny": {"scene": "config/scenes/kirsch.yaml", "overrides": ["material.nu=0.7"]}}
            }
        },
        "adaptivity",
        "adaptivity_study.scenes.tiny.overrides[0]",
        ["material.nu", "< 0.5"],
    ),
    # the other keys forwarded into a scene or a mesh family
    "studies-override": ({"studies_overrides": ["material.E=-1"]}, "extras", "studies_overrides[0]", ["material.E"]),
    "sweep-defaults-tol": ({"sweep_defaults": {"solver": {"tol": 0.5}}}, "extras", "sweep_defaults.solver.tol", []),
    "sweep-override": (
        {"sweeps": {"tiny": {**TINY_SWEEP, "overrides": ["discretization.mesh.n=0"]}}},
        "results/sweeps/tiny.nc",
        "sweeps.tiny.overrides[0]",
        ["discretization.mesh.n"],
    ),
    "sweep-grid-key": (
        {"sweeps": {"tiny": {**TINY_SWEEP, "grid": {"contact.normal.kk": [1.0]}}}},
        "results/sweeps/tiny.nc",
        "sweeps.tiny.grid.contact.normal.kk[0]",
        ["unknown key"],
    ),
    "paper-override": ({"overrides": ["solver.tl=1e-8"]}, "results/table1.nc", "overrides[0]", ["did you mean 'tol'"]),
    "tradeoff-tolerance": ({"tradeoff": {"tolerances": [1e-6, 0.5]}}, "extras", "tradeoff.tolerances[1]", []),
    "tradeoff-options": (
        {"tradeoff": {"families": {"sq": {"family": "square", "options": {"bogus": 1}}}}},
        "extras",
        "tradeoff.families.sq.options.bogus",
        ["unknown key"],
    ),
    "manufactured-options": (
        {
            "three_d": {
                "manufactured": {
                    "hex": {
                        "scene": "config/scenes/3d/box_manufactured.yaml",
                        "family": "voronoi",
                        "levels": [4, 6],
                        "options": {"seed": -2},
                    }
                }
            }
        },
        "three_d",
        "three_d.manufactured.hex.options.seed",
        ["must be >= 0"],
    ),
    "hertz-solver-tol": ({"hertz": {"solver": {"tol": 0.5}}}, "three_d", "hertz.solver.tol", []),
    "lame-scene": (
        {"three_d": {"lame": {"scene": "config/scenes/3d/no-such.yaml"}}},
        "three_d",
        "three_d.lame.scene",
        ["no-such.yaml"],
    ),
    # cross-field constraints
    "stability-case": (
        {"stability": {"cases": ["paper", "no-such-case"]}},
        "extras",
        "stability.cases[1]",
        ["robustness"],
    ),
    "stability-scene": (
        {"stability": {"scenes": {"box3d": "config/scenes/3d/no-such.yaml"}}},
        "extras",
        "stability.scenes.box3d",
        ["no-such.yaml"],
    ),
    "sweep-figure-select": (
        {"sweeps": {"exponent-gap": {"figures": {"map": {"select": {"k_nu": 11.0}}}}}},
        "extras",
        "sweeps.exponent-gap.figures.map.select.k_nu",
        ["not a value of the grid's k_nu"],
    ),
    "sweep-figure-select-held": (
        {
            "sweeps": {
                "tiny": {
                    **TINY_SWEEP,
                    "grid": {"contact.normal.k": [1.0, 10.0], "contact.friction.k": [0.0, 450.0]},
                    "figures": {"lines": {"x": "k_nu", "quantities": ["normal_force"], "select": {"k_tau": 5.0}}},
                }
            }
        },
        "results/sweeps/tiny/lines.png",
        "sweeps.tiny.figures.lines.select.k_tau",
        ["5.0 is not a value of the grid's k_tau (0.0, 450.0)"],
    ),
    "sweep-figure-axis": (
        {"sweeps": {"exponent-gap": {"figures": {"lines": {"hue": "contact_normal_m"}}}}},
        "extras",
        "sweeps.exponent-gap.figures.lines.hue",
        ["m_nu"],
    ),
    "mindlin-shifts": ({"mindlin": {"shifts": [0.002, 0.001]}}, "three_d", "mindlin.shifts[1]", ["increasing"]),
    "unknown-key": ({"three_d": {"figure_levle": 1}}, "three_d", "three_d.figure_levle", ["figure_level"]),
}


@pytest.mark.parametrize("name", list(BROKEN))
def test_a_broken_value_is_refused_before_any_job_naming_the_file_and_the_config_key(tmp_path, name):
    config, target, key, words = BROKEN[name]
    path = tmp_path / "broken.yaml"
    path.write_text(yaml.safe_dump(config))
    assert_refused(dry_run(target, "--configfile", str(path)), str(path), key, *words)


def test_the_file_named_is_the_last_one_that_set_the_key(tmp_path):
    first, second = tmp_path / "first.yaml", tmp_path / "second.yaml"
    first.write_text(yaml.safe_dump({"three_d": {"figure_level": 10}}))
    second.write_text(yaml.safe_dump({"three_d": {"figure_level": -9}}))
    run = dry_run("three_d", "--configfile", str(first), str(second))
    assert_refused(run, str(second), "three_d.figure_level", "-9 is not an index")


def test_a_value_of_the_command_line_is_named_as_config():
    assert_refused(dry_run("--config", "batch_levels=3"), "--config", "batch_levels", "boolean")


@pytest.mark.parametrize("configfile", ["config/sweeps3d.yaml", "workflow/cluster/cluster-test.yaml"])
def test_the_shipped_alternative_configfiles_pass(configfile):
    run = dry_run("extras", "--configfile", configfile)
    assert run.returncode == 0, run.stdout + run.stderr


def test_config_source_and_the_typed_error():
    layers = [
        ("config/three_d.yaml", {"three_d": {"figure_level": -1, "solver": {}}}),
        ("mine.yaml", {"three_d": {"solver": {"tol": 1}}}),
        ("--config", {}),
    ]
    assert config_source(("three_d", "solver", "tol"), layers) == "mine.yaml"
    assert config_source(("three_d", "figure_level"), layers) == "config/three_d.yaml"
    error = WorkflowConfigError("too big", path=("sweeps", "a", "grid", "contact.normal.k", 0))
    assert error.key == "sweeps.a.grid.contact.normal.k[0]" and error.path[-1] == 0
