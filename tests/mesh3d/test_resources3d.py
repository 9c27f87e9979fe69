"""The 3D resource prediction against the meshes themselves."""

import pytest

from vemkit.exceptions import SceneError
from vemkit.mesh.families3d import build_mesh3d
from vemkit.mesh.families3d.resources import estimate_mesh3d

BOX = {"box": [[0, 0, 0], [2, 1, 1]]}


@pytest.mark.parametrize(
    "family, size", [("hex", {"n": 3}), ("tet", {"h": 0.5, "kind": "structured"}), ("hex", {"cells": 250})]
)
def test_grids_are_predicted_exactly(family, size):
    est = estimate_mesh3d(family, BOX, **size)
    mesh = build_mesh3d(family, BOX, **size)
    assert est.exact and (est.cells, est.vertices, est.faces) == (mesh.n_cells, mesh.n_vertices, mesh.n_faces)
    assert est.dofs == 3 * mesh.n_vertices


@pytest.mark.parametrize("options", [{}, {"contact_side": "left"}, {"rule": "random", "fraction": 0.2, "seed": 1}])
def test_octree_cells_exact_and_bounds(options):
    est = estimate_mesh3d("octree", BOX, n=3, **options)
    mesh = build_mesh3d("octree", BOX, n=3, **options)
    assert est.cells == mesh.n_cells and est.vertices >= mesh.n_vertices and est.faces >= mesh.n_faces


@pytest.mark.parametrize("size", [{"cells": 500}, {"n": 8}])
def test_voronoi_within_ten_percent(size):
    est = estimate_mesh3d("voronoi", BOX, **size)
    mesh = build_mesh3d("voronoi", BOX, **size)
    assert est.cells == mesh.n_cells
    assert mesh.n_vertices <= est.vertices <= 1.1 * mesh.n_vertices
    assert mesh.n_faces <= est.faces <= 1.1 * mesh.n_faces


def test_errors():
    with pytest.raises(SceneError, match="give a box domain"):
        estimate_mesh3d(
            "square", {"extrude": {"depth": 1}, "polygon": [[0, 0], [1, 0], [1, 1]], "sides": ["a"] * 3}, n=2
        )
    with pytest.raises(SceneError, match="unknown box family 'square'"):
        estimate_mesh3d("square", BOX, n=2)
