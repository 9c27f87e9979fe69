"""The fast paths of the clipped Voronoi family against the code they replaced: the Numba kernels
keep numpy's bits (areas and centroids, fan order), the Lloyd steps in spatial order give the same
points, the grid's inside/outside calls equal the exact vertex test, and the Green's-theorem
centroids of clipped cells equal shapely's up to round-off."""

import sys

import numpy as np
import pytest
import shapely
import triangle as shewchuk

from vemkit.config.domain import domain_from_spec
from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.families import build_mesh, voronoi_clip, voronoi_kernels
from vemkit.mesh.geometry import areas_centroids, areas_centroids_numpy, indexed_polygon_areas

voronoi_module = sys.modules["vemkit.mesh.families.voronoi"]  # the package exports the function

PLATE = {
    "polygon": [[0, 0], [2, 0], [2, 1], [0, 1]],
    "sides": ["bottom", "right", "top", "left"],
    "holes": [{"circle": [0.5, 0.5, 0.25], "side": "a"}, {"circle": [1.4, 0.45, 0.3], "side": "b"}],
}
L_SHAPE = shapely.Polygon([(0, 0), (1, 0), (1, 0.5), (0.5, 0.5), (0.5, 1), (0, 1)])


def plate(n):
    """The plate as the Voronoi family sees it: shapely shape (holes as polygons), index, cell count."""
    shape, _ = voronoi_module._domain_shape(domain_from_spec(PLATE), n)
    shapely.prepare(shape)
    count = int(round(n * n * shape.area))
    return shape, voronoi_clip.domain_index(shape, count), count


def diagram(points, anisotropy=1.0):
    """The Voronoi cells of points in a domain of size about 1, with the four far points."""
    far = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=float) * 30.0
    return voronoi_module._voronoi_cells(np.vstack([points * [anisotropy, 1.0], far]), len(points), anisotropy)


def test_areas_centroids_kernel_keeps_numpys_bits():
    rng = np.random.default_rng(4)
    sizes = np.concatenate([rng.integers(1, 10, 3000), np.arange(1, 140)])  # up to 129 points, then numpy
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    coords = rng.normal(size=(offsets[-1], 2)) * 10.0 ** rng.integers(-6, 4, (offsets[-1], 1)) + [250.0, -3.0]
    for got, want in zip(areas_centroids(coords, offsets), areas_centroids_numpy(coords, offsets)):
        np.testing.assert_array_equal(got, want)
    uneven = np.array([0, 3, 3, 7])  # an empty polygon: numpy's reduceat semantics, from the twin
    for got, want in zip(areas_centroids(coords[:7], uneven), areas_centroids_numpy(coords[:7], uneven)):
        np.testing.assert_array_equal(got, want)


def test_indexed_areas_keep_the_bits_of_the_gathered_areas():
    rng = np.random.default_rng(5)
    sizes = np.concatenate([rng.integers(3, 10, 3000), np.arange(3, 140)])  # up to 129 points, then numpy
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    points = rng.normal(size=(500, 2)) * 10.0 ** rng.integers(-6, 4, (500, 1)) + [250.0, -3.0]
    refs = rng.integers(0, 500, offsets[-1])
    np.testing.assert_array_equal(
        indexed_polygon_areas(points, offsets, refs), areas_centroids_numpy(points[refs], offsets)[0]
    )


def test_fan_cells_keep_the_argsort_order_and_the_bits_of_areas():
    points = np.random.default_rng(1).random((3000, 2))
    scaled = np.vstack([points * [2.0, 1.0], [[-60, -30], [60, -30], [60, 30], [-60, 30]]])
    tris = shewchuk.delaunay(scaled)
    centres, offsets, corner_tri, towards = voronoi_kernels.fans(scaled, tris, 3000)
    angle = np.arctan2(towards[1], towards[0]) + np.pi
    vertices = centres / [2.0, 1.0]
    refs, tied, area, centroid, lo, hi = voronoi_kernels.fan_cells(vertices, offsets, corner_tri, angle)
    want = voronoi_kernels.argsort_fans(tris, 3000, angle)
    assert not tied
    np.testing.assert_array_equal(refs, want)
    for got, expected in zip((area, centroid), areas_centroids_numpy(vertices[want], offsets)):
        np.testing.assert_array_equal(got, expected)
    np.testing.assert_array_equal(lo, np.minimum.reduceat(vertices[want], offsets[:-1]))
    np.testing.assert_array_equal(hi, np.maximum.reduceat(vertices[want], offsets[:-1]))
    angle[offsets[7] + 1] = angle[offsets[7]]  # two equal keys in one fan: argsort must decide
    assert voronoi_kernels.fan_cells(vertices, offsets, corner_tri, angle)[1]


def test_triangle_does_not_depend_on_the_order_of_its_points():
    """What the Lloyd steps in spatial order rely on: the same triangles, corners and order."""
    rng = np.random.default_rng(7)
    points = rng.random((5000, 2))
    tris = shewchuk.delaunay(points)
    for _ in range(3):
        order = rng.permutation(5000)
        np.testing.assert_array_equal(order[shewchuk.delaunay(points[order])], tris)


@pytest.mark.parametrize("domain", [None, L_SHAPE, "plate"])
def test_lloyd_steps_in_spatial_order_give_the_same_points(domain):
    if domain == "plate":
        shape, index, count = plate(20)
    else:
        shape = voronoi_module.UNIT_SQUARE if domain is None else domain
        shapely.prepare(shape)
        count = 300
        index = voronoi_clip.domain_index(shape, count)
    points = voronoi_module._random_points(shape, count, np.random.default_rng(3))
    want = points
    for _ in range(4):
        want = voronoi_module._clipped_cells(want, index, 1.5, centroids_only=True).centroids
    got = voronoi_module._lloyd(points, index, 1.5, 4, float(np.sqrt(shape.area / count)))
    np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("domain", [L_SHAPE, "plate"])
def test_inside_cells_are_those_whose_vertices_are_and_no_boundary_crosses(domain):
    shape, index, count = plate(25) if domain == "plate" else (domain, voronoi_clip.domain_index(domain, 800), 800)
    points = voronoi_module._random_points(shape, count, np.random.default_rng(5))
    vertices, offsets, refs, _, _, lo, hi = diagram(points)
    inside, _ = voronoi_module._inside(index, vertices, offsets, refs, lo, hi)
    every = shapely.contains_xy(shape, vertices[:, 0], vertices[:, 1])
    want = np.logical_and.reduceat(every[refs], offsets[:-1])
    cells = voronoi_module._polygons(vertices, offsets, refs, np.arange(count))
    want &= ~shapely.intersects(cells, shape.boundary)
    np.testing.assert_array_equal(inside, want)
    assert 0 < (~want).sum() < count // 2


def test_green_centroids_of_clipped_cells_equal_shapelys():
    shape, index, count = plate(40)
    h = np.sqrt(shape.area / count)
    points = voronoi_module._random_points(shape, count, np.random.default_rng(2))
    for anisotropy in (1.0, 0.4):
        vertices, offsets, refs, area, _, lo, hi = diagram(points, anisotropy)
        inside, vertex_in = voronoi_module._inside(index, vertices, offsets, refs, lo, hi)
        cut = np.flatnonzero(~inside)
        got, ok = voronoi_clip.clipped_centroids(
            vertices,
            offsets,
            refs,
            cut,
            points[cut],
            vertex_in,
            index.ends,
            index.ptr,
            index.items,
            index.origin,
            index.inv,
            index.g,
            area[cut],
        )
        pieces = shapely.intersection(voronoi_module._polygons(vertices, offsets, refs, cut), shape)
        assert ok.all() and cut.size > 100
        np.testing.assert_allclose(got, shapely.get_coordinates(shapely.centroid(pieces)), rtol=0, atol=1e-11 * h)


def test_green_centroid_with_a_vertex_on_the_boundary():
    """A cell touching the boundary at a vertex (contains_xy: outside) is found whole."""
    square = shapely.box(0, 0, 1, 1)
    index = voronoi_clip.domain_index(square, 16)
    vertices = np.array([[0.5, 0.0], [0.8, 0.3], [0.2, 0.3], [0.3, -0.2], [1.3, 0.5], [0.4, 0.6]])
    offsets, refs = np.array([0, 3, 6]), np.arange(6)
    vertex_in = shapely.contains_xy(square, vertices[:, 0], vertices[:, 1])
    area = areas_centroids(vertices, offsets)[0]
    got, ok = voronoi_clip.clipped_centroids(
        vertices,
        offsets,
        refs,
        np.arange(2),
        np.array([[0.5, 0.2], [0.7, 0.3]]),
        vertex_in,
        index.ends,
        index.ptr,
        index.items,
        index.origin,
        index.inv,
        index.g,
        area,
    )
    want = shapely.get_coordinates(
        shapely.centroid(shapely.intersection([shapely.Polygon(vertices[:3]), shapely.Polygon(vertices[3:])], square))
    )
    assert ok.all()
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-14)


def test_voronoi_on_a_plate_with_holes_is_valid_and_shapelys_up_to_round_off(monkeypatch):
    mesh = build_mesh("voronoi", 40, domain=PLATE, seed=1, lloyd_iterations=10)
    validate_mesh(mesh)
    assert mesh.cell_areas.sum() == pytest.approx(2.0 - np.pi * (0.25**2 + 0.3**2), rel=2e-3)  # circles as polygons
    monkeypatch.setattr(
        voronoi_module,
        "clipped_centroids",
        lambda *args: (np.zeros((len(args[3]), 2)), np.zeros(len(args[3]), dtype=bool)),
    )
    by_shapely = build_mesh("voronoi", 40, domain=PLATE, seed=1, lloyd_iterations=10)
    np.testing.assert_array_equal(mesh.cell_vertices, by_shapely.cell_vertices)
    np.testing.assert_allclose(mesh.vertices, by_shapely.vertices, rtol=0, atol=1e-10)  # h = 0.025
