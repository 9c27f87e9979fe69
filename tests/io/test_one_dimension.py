"""One set of file writers and result figures for 2D and 3D (issue 34, item 3): no 3D twin modules in
``vemkit/io`` or ``vemkit/report``, no import cycle through them or the mesh file writers (every import
counted, function-level ones too), modules that fit in about 400 lines; and the one description of a
mesh's topology and the one VTU writer serve both dimensions."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

from vemkit.mesh.families import build_mesh
from vemkit.mesh.families3d import hex
from vemkit.mesh.ugrid import mesh_topology, topology_file
from vemkit.mesh.vtu import write_vtu

PACKAGE = Path(__file__).resolve().parents[2] / "vemkit"
ONE_DIMENSION = ("vemkit.io", "vemkit.report", "vemkit.mesh.ugrid", "vemkit.mesh.vtu", "vemkit.mesh.files")
MAX_LINES = 400


def modules() -> dict[str, Path]:
    out = {}
    for path in PACKAGE.rglob("*.py"):
        name = ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        out[name.removesuffix(".__init__")] = path
    return out


def imports(path: Path, known: dict) -> set[str]:
    """The vemkit modules ``path`` imports anywhere in it (function-level imports included)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found |= {
                f"{node.module}.{a.name}" if f"{node.module}.{a.name}" in known else node.module for a in node.names
            }
        elif isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
    return {name for name in found if name in known and name != "vemkit"}


def reaches(graph: dict, start: str) -> set[str]:
    seen, todo = set(), list(graph[start])
    while todo:
        name = todo.pop()
        if name not in seen:
            seen.add(name)
            todo.extend(graph[name])
    return seen


def test_no_3d_twin_modules_in_io_and_report():
    twins = [p.name for folder in ("io", "report") for p in (PACKAGE / folder).glob("*.py") if "3d" in p.name]
    assert twins == []


def test_no_import_cycle_through_the_file_writers_and_figures():
    known = modules()
    graph = {name: imports(path, known) - {name} for name, path in known.items()}
    cyclic = [name for name in known if name.startswith(ONE_DIMENSION) and name in reaches(graph, name)]
    assert cyclic == []


@pytest.mark.parametrize("folder", ["io", "report"])
def test_modules_fit_in_about_400_lines(folder):
    long = {p.name: n for p in (PACKAGE / folder).glob("*.py") if (n := len(p.read_text().splitlines())) > MAX_LINES}
    assert long == {}


@pytest.mark.parametrize("mesh", [build_mesh("voronoi", 3, seed=1), hex(shape=(2, 1, 1))], ids=["2d", "3d"])
def test_one_topology_description_serves_both_dimensions(mesh):
    topology = mesh_topology(mesh)
    assert topology.name == f"mesh{mesh.dimension}d" and topology.dimension == mesh.dimension
    file = topology_file(topology)
    assert file[topology.name].attrs["topology_dimension"] == mesh.dimension
    assert [file[v.name].dims for v in topology.node_coordinates] == [(topology.node_dimension,)] * mesh.dimension
    cells = {2: "mesh2d_nFaces", 3: "mesh3d_nVolumes"}[mesh.dimension]
    assert topology.cell_dimension == cells and any(cells in file[v.name].dims for v in topology.connectivity)


@pytest.mark.parametrize("mesh", [build_mesh("voronoi", 3, seed=1), hex(shape=(2, 1, 1))], ids=["2d", "3d"])
def test_one_vtu_writer_serves_both_dimensions(mesh, tmp_path):
    import meshio

    values = np.arange(mesh.n_cells, dtype=float)
    write_vtu(mesh, tmp_path / "m.vtu", point_data={"u": mesh.vertices}, cell_data={"c": values})
    back = meshio.read(tmp_path / "m.vtu")
    index = np.concatenate(back.cell_data["cell_index"])
    assert np.array_equal(np.sort(index), np.arange(mesh.n_cells))
    assert np.array_equal(np.concatenate(back.cell_data["c"]), values[index])
    assert np.array_equal(back.points[:, : mesh.dimension], mesh.vertices)
    assert back.point_data["u"].shape == (mesh.n_vertices, 3)
    assert all(b.type.startswith("polygon" if mesh.dimension == 2 else "polyhedron") for b in back.cells)
