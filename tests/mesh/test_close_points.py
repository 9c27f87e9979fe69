"""close_pairs (vemkit.mesh.close_points, numpy bins) finds exactly the pairs that scipy's k-d tree
finds, in 2D and 3D, with exact duplicates, rounded (gridded) coordinates and radii from 0 to a
fifth of the extent; and a duplicated vertex is still refused by the 2D and the 3D checks."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from vemkit.exceptions import MeshError
from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.close_points import close_pairs, has_close_pair
from vemkit.mesh.families import build_mesh
from vemkit.mesh.mesh import Mesh


def as_set(pairs):
    return {tuple(p) for p in np.asarray(pairs).tolist()}


@pytest.mark.parametrize("dimension", [2, 3])
def test_the_pairs_are_the_k_d_tree_pairs(dimension):
    rng = np.random.default_rng(dimension)
    for trial in range(40):
        n = int(rng.integers(2, 300))
        points = rng.random((n, dimension)) * float(rng.choice([1e-3, 1.0, 1e6]))
        if trial % 3 == 0:  # on a grid: many ties in each coordinate
            points = np.round(points, int(rng.integers(1, 3)))
        points = np.vstack([points, points[rng.integers(0, n, size=int(rng.integers(0, 5)))]])
        radius = float(rng.choice([0.0, 1e-12, 0.01, 0.2])) * float(np.ptp(points, axis=0).max())
        found = close_pairs(points, radius)
        assert (found[:, 0] < found[:, 1]).all()
        assert as_set(found) == as_set(cKDTree(points).query_pairs(radius, output_type="ndarray"))


def test_fewer_than_two_points_have_no_pairs():
    assert close_pairs(np.zeros((1, 2)), 1.0).shape == (0, 2)
    assert close_pairs(np.zeros((0, 3)), 1.0).shape == (0, 2)


def test_a_duplicated_vertex_is_still_refused():
    mesh = build_mesh("square", 2)
    vertices = np.vstack([mesh.vertices, mesh.vertices[4]])  # a copy of the centre ...
    cells = mesh.cell_vertices.copy()
    cells[np.flatnonzero(cells == 4)[0]] = len(vertices) - 1  # ... used by the first cell
    broken = Mesh(vertices, mesh.cell_offsets, cells, mesh.boundary, mesh.meta)
    with pytest.raises(MeshError, match=f"vertices 4 and {len(vertices) - 1} have the same coordinates"):
        validate_mesh(broken)


@pytest.mark.parametrize("dimension", [2, 3])
def test_the_screen_says_true_exactly_when_there_are_pairs(dimension):
    rng = np.random.default_rng(10 + dimension)
    seen = set()
    for trial in range(60):
        n = int(rng.integers(2, 300))
        points = rng.random((n, dimension)) * float(rng.choice([1e-3, 1.0, 1e6]))
        if trial % 3 == 0:
            points = np.round(points, int(rng.integers(1, 3)))
        points = np.vstack([points, points[rng.integers(0, n, size=int(rng.integers(0, 3)))]])
        radius = float(rng.choice([0.0, 1e-12, 0.01, 0.2])) * float(np.ptp(points, axis=0).max())
        expected = close_pairs(points, radius).size > 0
        assert has_close_pair(points, radius) == expected
        seen.add(expected)
    assert seen == {True, False}
