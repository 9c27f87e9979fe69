"""triangulate_cells: equal to its plain-Python twin, exact areas, proper triangles."""

import numpy as np
import pytest

from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.families import build_mesh
from vemkit.mesh.mesh import from_polygons
from vemkit.mesh.triangulate import ear_clip_reference, triangulate_cells

L_SHAPE = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
ARROW = [(0, 0), (3, 1), (0, 2), (1, 1)]
COMB = [(0, 0), (5, 0), (5, 3), (4, 3), (4, 1), (3, 1), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3)]
# a square with hanging nodes on every side, two on the bottom
HANGING_SQUARE = [(0, 0), (0.25, 0), (0.5, 0), (1, 0), (1, 0.5), (1, 1), (0.5, 1), (0, 1), (0, 0.5)]
# an L whose re-entrant corner has collinear neighbours, and collinear runs on the long sides
COLLINEAR_L = [(0, 0), (1, 0), (2, 0), (2, 0.5), (2, 1), (1.5, 1), (1, 1), (1, 1.5), (1, 2), (0.5, 2), (0, 2), (0, 1)]
POLYGONS = {"L": L_SHAPE, "arrow": ARROW, "comb": COMB, "hanging": HANGING_SQUARE, "collinear L": COLLINEAR_L}


def signed_areas(xy, tris):
    a, b, c = xy[tris[:, 0]], xy[tris[:, 1]], xy[tris[:, 2]]
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))


def shoelace(xy):
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)


def cross(u, v):
    return u[0] * v[1] - u[1] * v[0]


def assert_proper(xy, tris):
    """Positive triangles, no polygon vertex inside a triangle or on one of its sides."""
    assert (signed_areas(xy, tris) > 0).all()
    for t in tris:
        a, b, c = xy[t]
        for r in np.delete(np.arange(len(xy)), t):
            p = xy[r]
            d = [cross(b - a, p - a), cross(c - b, p - b), cross(a - c, p - c)]
            assert min(d) < 0, f"vertex {r} lies in triangle {t}"


def star_polygon(seed, m=11):
    rng = np.random.default_rng(seed)
    angles = np.sort(rng.uniform(0, 2 * np.pi, m))
    radii = rng.uniform(0.3, 1.0, m)
    return np.stack([radii * np.cos(angles), radii * np.sin(angles)], axis=1)


@pytest.mark.parametrize("name", POLYGONS)
def test_single_polygon_matches_reference_and_area(name):
    xy = np.array(POLYGONS[name], float)
    mesh = from_polygons(xy, [np.arange(len(xy))])
    validate_mesh(mesh)
    tris, parent = triangulate_cells(mesh)
    assert tris.shape == (len(xy) - 2, 3)
    assert (parent == 0).all()
    np.testing.assert_array_equal(tris, ear_clip_reference(xy))
    assert abs(signed_areas(xy, tris).sum() - shoelace(xy)) <= 1e-14 * abs(shoelace(xy))
    assert_proper(xy, tris)


@pytest.mark.parametrize("seed", range(20))
def test_random_star_polygons(seed):
    xy = star_polygon(seed)
    mesh = from_polygons(xy, [np.arange(len(xy))])
    tris, _ = triangulate_cells(mesh)
    np.testing.assert_array_equal(tris, ear_clip_reference(xy))
    np.testing.assert_allclose(signed_areas(xy, tris).sum(), shoelace(xy), rtol=1e-13)
    assert_proper(xy, tris)


@pytest.mark.parametrize(
    "family, options",
    [
        ("square", {}),
        ("triangle", {"seed": 1}),
        ("voronoi", {"seed": 3}),
        ("voronoi", {"seed": 4, "lloyd_iterations": 0}),
        ("hanging", {"levels": 3, "rule": "random", "fraction": 0.4, "seed": 2}),
    ],
)
def test_family_meshes(family, options):
    mesh = build_mesh(family, 8, **options)
    tris, parent = triangulate_cells(mesh)
    assert tris.shape[0] == mesh.cell_sizes.sum() - 2 * mesh.n_cells
    np.testing.assert_array_equal(parent, np.repeat(np.arange(mesh.n_cells), mesh.cell_sizes - 2))
    for k in range(mesh.n_cells):
        cell = mesh.cell(k)
        np.testing.assert_array_equal(tris[parent == k], cell[ear_clip_reference(mesh.vertices[cell])])
    areas = np.bincount(parent, weights=signed_areas(mesh.vertices, tris), minlength=mesh.n_cells)
    np.testing.assert_allclose(areas, mesh.cell_areas, rtol=1e-13, atol=1e-16)
    assert (signed_areas(mesh.vertices, tris) > 0).all()


def test_clockwise_polygon_is_refused():
    xy = np.array(L_SHAPE[::-1], float)
    mesh = from_polygons(xy, [np.arange(len(xy))])
    with pytest.raises(ValueError, match="cell 0 could not be triangulated"):
        triangulate_cells(mesh)
    with pytest.raises(ValueError, match="could not be triangulated"):
        ear_clip_reference(xy)
