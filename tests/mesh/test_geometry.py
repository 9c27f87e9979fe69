"""The one shoelace formula (Numba kernel and vectorized twin) and the polygon helpers of the
cut-cell and clipped families, pinned by exact values and brute force."""

import numpy as np
import pytest
import shapely

from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.families.polygons import insert_edge_vertices, merge_small_cells
from vemkit.mesh.geometry import areas_centroids, counter_clockwise, polygon_area, polygon_area_centroid
from vemkit.mesh.mesh import from_polygons


def star_polygons(rng, count):
    sizes = rng.integers(4, 12, count)
    polygons = []
    for m in sizes:  # angle gaps below π: star-shaped about the origin, counter-clockwise
        t = 2 * np.pi * (np.arange(m) + rng.uniform(0.25, 0.75, m)) / m
        r = rng.uniform(0.3, 1.0, m)
        polygons.append(np.stack([r * np.cos(t), r * np.sin(t)], axis=1) + rng.normal(size=2))
    return polygons


def test_kernel_and_vectorized_shoelace_agree_with_shapely():
    polygons = star_polygons(np.random.default_rng(3), 50)
    offsets = np.concatenate([[0], np.cumsum([len(p) for p in polygons])])
    area, centroid = areas_centroids(np.concatenate(polygons), offsets)
    for k, p in enumerate(polygons):
        a, cx, cy = polygon_area_centroid(p[:, 0].copy(), p[:, 1].copy())
        shape = shapely.Polygon(p)
        assert a == pytest.approx(shape.area, rel=1e-13) and area[k] == pytest.approx(a, rel=1e-13)
        np.testing.assert_allclose([cx, cy], [shape.centroid.x, shape.centroid.y], rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(centroid[k], [cx, cy], rtol=1e-12, atol=1e-12)
        assert polygon_area(p[::-1, 0].copy(), p[::-1, 1].copy()) == pytest.approx(-a, rel=1e-13)  # clockwise: < 0


def test_shoelace_exact_values():
    a, cx, cy = polygon_area_centroid(np.array([0.0, 2.0, 2.0, 0.0]), np.array([0.0, 0.0, 1.0, 1.0]))
    assert (a, cx, cy) == (2.0, 1.0, 0.5)
    a, cx, cy = polygon_area_centroid(np.array([0.0, 3.0, 0.0]), np.array([0.0, 0.0, 3.0]))
    assert (a, cx, cy) == (4.5, 1.0, 1.0)


def test_counter_clockwise_reverses_only_clockwise_cells():
    pool = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    refs = counter_clockwise(pool, np.array([0, 3, 6]), np.array([0, 1, 2, 0, 2, 3])[[0, 1, 2, 5, 4, 3]])
    assert refs.tolist() == [0, 1, 2, 0, 2, 3]


def test_hanging_nodes_are_inserted_into_the_larger_cell():
    # one 2 x 2 square beside two 1 x 1 squares: vertex (2, 1) lies inside the big square's right edge
    v = np.array([[0, 0], [2, 0], [2, 2], [0, 2], [3, 0], [3, 1], [2, 1], [3, 2]], dtype=float)
    cells = [[0, 1, 2, 3], [1, 4, 5, 6], [6, 5, 7, 2]]
    mesh = from_polygons(v, cells)
    offsets, refs = insert_edge_vertices(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, 1e-12)
    fixed = from_polygons(v, [refs[offsets[k] : offsets[k + 1]] for k in range(3)])
    assert fixed.cell(0).tolist() == [0, 1, 6, 2, 3]
    assert fixed.cell(1).tolist() == [1, 4, 5, 6] and fixed.cell(2).tolist() == [6, 5, 7, 2]
    validate_mesh(fixed)


def test_a_sliver_joins_the_neighbour_it_shares_most_with():
    # a unit square split at x = 0.95 (a sliver on the right) and a square above it
    v = np.array([[0, 0], [0.95, 0], [1, 0], [1, 1], [0.95, 1], [0, 1], [0, 2], [1, 2]], dtype=float)
    mesh = from_polygons(v, [[0, 1, 4, 5], [1, 2, 3, 4], [5, 4, 3, 7, 6]])
    merged = merge_small_cells(mesh, np.full(3, 0.5))
    validate_mesh(merged)
    assert merged.n_cells == 2
    assert sorted(merged.cell_areas.tolist()) == pytest.approx([1.0, 1.0])
    # the sliver (area 0.05) shares 1.0 with the left part and only 0.05 with the top: joined to the
    # left; the bottom corner (0.95, 0) stays a (collinear) vertex, (0.95, 1) is shared with the top cell
    bottom = int(np.argmin([mesh.vertices[merged.cell(k)][:, 1].mean() for k in range(2)]))
    assert sorted(map(tuple, mesh.vertices[merged.cell(bottom)])) == sorted(map(tuple, v[:6]))


def test_boxes_meet_segments_matches_brute_force():
    from vemkit.mesh.families import voronoi_kernels

    rng = np.random.default_rng(5)
    lo = rng.uniform(0, 10, (400, 2))
    hi = lo + rng.uniform(0, 0.5, (400, 2))
    a, b = rng.uniform(0, 10, (60, 2)), rng.uniform(-1, 1, (60, 2))
    seg_lo, seg_hi = np.minimum(a, a + b), np.maximum(a, a + b)
    got = voronoi_kernels.boxes_meet_segments(lo, hi, seg_lo, seg_hi, np.zeros(2), 2.0, 20)
    want = ((seg_lo[None, :, :] <= hi[:, None, :]) & (lo[:, None, :] <= seg_hi[None, :, :])).all(axis=2).any(axis=1)
    np.testing.assert_array_equal(got, want)
    assert 0 < want.sum() < 400


def test_voronoi_fan_kernel_equals_its_numpy_twin_bit_for_bit():
    import triangle as shewchuk

    from vemkit.mesh.families import voronoi_kernels

    points = np.random.default_rng(2).random((500, 2))
    tris = shewchuk.delaunay(points).astype(np.int64)
    for got, want in zip(voronoi_kernels.fans(points, tris, 480), voronoi_kernels.fans_reference(points, tris, 480)):
        np.testing.assert_array_equal(got, want)
