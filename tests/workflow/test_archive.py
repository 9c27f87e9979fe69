"""The archived Table 1 (results/archive/table1.nc) against a fresh computation of its coarse rows.

For every archived stabilization: solve the 2^-8 square reference and the h = 2^-2, 2^-3 square
meshes from the archived scene, measure the errors as the workflow does (SPEC §5) and compare
them with the archive. The archive is refreshed on purpose with ``snakemake -j2 archive``.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from vemkit.studies.convergence import ReferenceSolution, read_convergence, run_record, study_scene

ROOT = Path(__file__).resolve().parents[2]
ARCHIVE = ROOT / "results" / "archive"
COARSE = (4, 8)  # h = 2^-2, 2^-3
RTOL = 1e-6

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def archive():
    path = ARCHIVE / "table1.nc"
    if not path.exists():
        pytest.skip(f"{path} is missing: run `snakemake -j2 archive`")
    return read_convergence(path)


def _solve(scene_file, parameters, family, n, stab):
    from vemkit.mesh.families import build_mesh
    from vemkit.studies.scene_solve import solve_scene

    overrides = parameters["overrides"] + [f"solver.{k}={v}" for k, v in parameters["solver"].items()]
    spec = parameters["meshes"][family]
    scene = study_scene(scene_file, overrides, spec["family"], spec.get("options") or {}, n, stab)
    problem, _, ds = solve_scene(scene, mesh=build_mesh(spec["family"], n, **(spec.get("options") or {})))
    return problem.mesh, ds


def test_archive_is_complete(archive):
    assert archive.attrs["scene"].startswith("name: paper")
    assert json.loads(archive.attrs["package_versions"])["vemkit"]
    assert archive.attrs["git_commit"]
    assert int(archive["defined"].sum()) == archive["defined"].size
    for name in ("error_h1", "error_h1_semi", "order", "n_dofs", "iterations", "wall_time"):
        assert name in archive


def test_coarse_rows_of_table1_recomputed(archive, tmp_path):
    parameters = json.loads(archive.attrs["parameters"])
    scene_file = tmp_path / "scene.yaml"
    scene_file.write_text(archive.attrs["scene"])  # the archived scene, as solved
    family = str(archive["family"].values[0])
    ref = parameters["reference"]
    quadrature = None  # the same reference mesh for every stabilization: one quadrature
    for stab in [str(s) for s in archive["stabilization"].values]:
        solution = _solve(scene_file, parameters, ref["mesh"], ref["n"], stab)
        reference = ReferenceSolution("<memory>", quadrature=quadrature, solution=solution)
        quadrature = reference.quadrature
        for n in COARSE:
            mesh, ds = _solve(scene_file, parameters, family, n, stab)
            record = run_record(family, stab, n, mesh, ds, reference)
            row = archive.sel(family=family, stabilization=stab, h=1.0 / n)
            for key in ("error_h1", "error_h1_semi"):
                assert np.isclose(record[key], float(row[key]), rtol=RTOL, atol=0), \
                    f"{stab} n={n} {key}: fresh {record[key]!r}, archived {float(row[key])!r}"
            assert record["n_dofs"] == int(row["n_dofs"])
