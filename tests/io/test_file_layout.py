"""The files' layout, pinned (docs/reference/files.md): what `vemkit solve`, `vemkit adapt` and `vemkit mesh`
write, 2D and 3D, has the recorded dimensions (in order, with their sizes), variables (in order, with
their types, dimensions and every attribute) and global attributes (in order, with their types).

``file_layout.json`` was recorded by the code before the 2D and 3D writers became one (issue 34,
item 3: ``io/solution_file3d``, ``mesh/files3d``'s writers), so that reshaping left every name and
attribute as it was; the values themselves are pinned by ``tests/golden``. Record it again, only for a
deliberate change of the file contract, with ``python tests/io/test_file_layout.py``.
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import netCDF4
import numpy as np
import pytest

from vemkit.cli import main

ROOT = Path(__file__).resolve().parents[2]
RECORD = Path(__file__).with_name("file_layout.json")
PAPER = str(ROOT / "config" / "scenes" / "paper.yaml")
SLIDING = str(ROOT / "config" / "scenes" / "3d" / "contact_sliding.yaml")
SHEARED = str(ROOT / "config" / "scenes" / "3d" / "sheared_box.yaml")
N2 = ("--set", "discretization.mesh.n=2")

#: the command of each file (its output -o FILE.nc added)
COMMANDS = {
    "solve_2d_k1": ("solve", PAPER, *N2),
    "solve_2d_k2": ("solve", PAPER, *N2, "--set", "discretization.order=2"),
    "solve_3d_contact": ("solve", SLIDING, *N2),
    "adapt_2d": ("adapt", PAPER, *N2, "--set", "adaptivity.max_steps=2"),
    "mesh_2d": ("mesh", "voronoi", "3"),
    "mesh_3d": ("mesh", "--scene", SHEARED, *N2),
}
#: global attributes whose values are results or the run's own (timings, checks, the scene text)
ATTRIBUTE_NAMES_ONLY = (
    "scene",
    "vemkit_version",
    "solver",
    "iterations",
    "linear_iterations",
    "solver_globalization",
    "n_dofs",
)
RESULT_PREFIXES = ("check_", "error_", "adapt_estimate")
SIZES_OF_RESULTS = ("iteration", "step")  # solver iterations, adaptive steps


def _value(value):
    """An attribute value as JSON: its type and value."""
    if isinstance(value, np.ndarray):
        return [str(value.dtype), value.tolist()]
    if isinstance(value, np.generic):
        return [str(value.dtype), value.item()]
    return [type(value).__name__, value]


def file_layout(path: Path) -> dict:
    """Dimensions, variables with their attributes, and global attributes of a netCDF file, in file order."""
    with netCDF4.Dataset(path) as nc:
        dims = [[d.name, None if d.name in SIZES_OF_RESULTS else d.size] for d in nc.dimensions.values()]
        variables = [
            [v.name, str(v.dtype), list(v.dimensions), [[k, _value(v.getncattr(k))] for k in v.ncattrs()]]
            for v in nc.variables.values()
        ]
        globals_ = []
        for key in nc.ncattrs():
            value = _value(nc.getncattr(key))
            names_only = key in ATTRIBUTE_NAMES_ONLY or "time" in key or key.startswith(RESULT_PREFIXES)
            globals_.append([key, value[0] if names_only else value])
    return {"dimensions": dims, "variables": variables, "attributes": globals_}


def written(name: str, directory: Path) -> Path:
    path = directory / f"{name}.nc"
    assert main([*COMMANDS[name], "-o", str(path), "-q"]) == 0
    return path


@pytest.mark.parametrize("name", list(COMMANDS))
def test_the_file_has_the_recorded_layout(name, tmp_path):
    recorded = json.loads(RECORD.read_text())[name]
    now = json.loads(json.dumps(file_layout(written(name, tmp_path))))  # tuples as lists, like the record
    for part in ("dimensions", "variables", "attributes"):
        assert [row[0] for row in now[part]] == [row[0] for row in recorded[part]], f"{name}: {part} (names, order)"
        for row, then in zip(now[part], recorded[part], strict=True):
            assert row == then, f"{name}: {part} {row[0]}"


if __name__ == "__main__":  # record the layouts with the vemkit on the path
    with tempfile.TemporaryDirectory() as directory:
        layouts = {name: file_layout(written(name, Path(directory))) for name in COMMANDS}
    RECORD.write_text(json.dumps(layouts, indent=1) + "\n")
    print(f"{RECORD}: {len(layouts)} files", file=sys.stderr)
