"""Generalized barycentric interpolation (Wachspress / mean value) and the paper's error measure (docs/reference/mathematics.md)."""

import numpy as np
import pytest
from conftest import FAMILY_CASES, family_mesh

from vemkit.mesh.families import build_mesh
from vemkit.mesh.locate import locate_points
from vemkit.vem.elements.k1_fields import projected_solution
from vemkit.vem.interpolation import MEAN_VALUE, WACHSPRESS, cell_kinds, coordinates, interpolate
from vemkit.vem.norms import paper_error, projection_error


def linear_field(x):
    return np.stack([0.3 + 1.7 * x[:, 0] - 0.4 * x[:, 1], -1.1 + 0.2 * x[:, 0] + 2.5 * x[:, 1]], axis=1)


def bilinear_field(x):
    return np.stack([0.5 + x[:, 0] - 2 * x[:, 1] + 3 * x[:, 0] * x[:, 1], 4 * x[:, 0] * x[:, 1] - x[:, 1]], axis=1)


def points_in_cells(mesh, rng, per_cell=3):
    """Random convex combinations of each cell's vertices (inside every star-shaped cell of the
    families), the cell centroids and the edge midpoints, with the cell of each point."""
    pts, cells = [], []
    for c in range(mesh.n_cells):
        v = mesh.vertices[mesh.cell(c)]
        w = rng.dirichlet(np.full(len(v), 0.7), size=per_cell)
        mid = 0.5 * (v + np.roll(v, -1, axis=0))
        for p in [*(w @ v), v.mean(axis=0), *mid]:
            pts.append(p)
            cells.append(c)
    return np.array(pts), np.array(cells)


@pytest.mark.parametrize("case", sorted(FAMILY_CASES))
def test_linear_fields_are_reproduced_on_every_family(case, rng):
    mesh = family_mesh(case, 6)
    values = linear_field(mesh.vertices)
    pts, cells = points_in_cells(mesh, rng)
    assert np.allclose(interpolate(mesh, values, pts, cells), linear_field(pts), atol=1e-12, rtol=0)
    ref = build_mesh("square", 32).vertices  # the located reference vertices, as the measure uses them
    assert np.allclose(interpolate(mesh, values, ref), linear_field(ref), atol=1e-12, rtol=0)


@pytest.mark.parametrize("case", sorted(FAMILY_CASES))
def test_interpolant_is_continuous_across_cells(case, rng):
    """On each shared edge (split edges with hanging nodes included) both cells give one value."""
    mesh = family_mesh(case, 5)
    values = rng.standard_normal((mesh.n_vertices, 2))
    he, cells = mesh.half_edges, mesh.half_edge_cells
    t = rng.uniform(0.1, 0.9, size=he.shape[0])[:, None]
    pts = (1 - t) * mesh.vertices[he[:, 0]] + t * mesh.vertices[he[:, 1]]
    along_edge = (1 - t) * values[he[:, 0]] + t * values[he[:, 1]]  # the trace is linear on each edge
    assert np.allclose(interpolate(mesh, values, pts, cells), along_edge, atol=1e-12, rtol=0)


def test_bilinear_fields_on_rectangles(rng):
    rect = np.array([[0.2, -0.1], [2.7, -0.1], [2.7, 0.4], [0.2, 0.4]])
    pts = np.column_stack([rng.uniform(0.2, 2.7, 50), rng.uniform(-0.1, 0.4, 50)])
    phi = coordinates(rect[:, 0], rect[:, 1], pts, WACHSPRESS)
    assert np.allclose(phi @ bilinear_field(rect), bilinear_field(pts), atol=1e-13, rtol=0)
    mesh = build_mesh("square", 4)
    ref = build_mesh("square", 16).vertices
    assert np.all(cell_kinds(mesh) == WACHSPRESS)
    assert np.allclose(interpolate(mesh, bilinear_field(mesh.vertices), ref), bilinear_field(ref), atol=1e-13, rtol=0)


def test_nested_squares_agree_with_the_tensor_bilinear_formula(rng):
    """Independent formula: u(x) = sum over the 4 corners of the grid square of (1-|dx|)(1-|dy|) u."""
    n, m = 4, 32
    coarse, fine = build_mesh("square", n), build_mesh("square", m)
    grid = rng.standard_normal((n + 1, n + 1))  # grid[i, j] at (i/n, j/n)
    ij = np.rint(coarse.vertices * n).astype(int)
    got = interpolate(coarse, grid[ij[:, 0], ij[:, 1]], fine.vertices)
    s = fine.vertices * n
    i0 = np.minimum(np.floor(s[:, 0]).astype(int), n - 1)
    j0 = np.minimum(np.floor(s[:, 1]).astype(int), n - 1)
    fx, fy = s[:, 0] - i0, s[:, 1] - j0
    expected = (
        (1 - fx) * (1 - fy) * grid[i0, j0]
        + fx * (1 - fy) * grid[i0 + 1, j0]
        + (1 - fx) * fy * grid[i0, j0 + 1]
        + fx * fy * grid[i0 + 1, j0 + 1]
    )
    assert np.allclose(got, expected, atol=1e-13, rtol=0)


@pytest.mark.parametrize("case", ["voronoi", "triangle-delaunay", "hanging-contact", "hanging-random"])
def test_partition_of_unity_and_non_negativity_on_convex_cells(case, rng):
    mesh = family_mesh(case, 6)
    kinds = cell_kinds(mesh)
    pts, cells = points_in_cells(mesh, rng)
    for c in range(mesh.n_cells):  # every cell of these families is convex (hanging: degenerate)
        v = mesh.vertices[mesh.cell(c)]
        phi = coordinates(v[:, 0], v[:, 1], pts[cells == c], kinds[c])
        assert np.allclose(phi.sum(axis=1), 1.0, atol=1e-13)
        assert phi.min() >= -1e-14
        assert np.allclose(phi @ v, pts[cells == c], atol=1e-13)  # linear precision: x = sum phi_i v_i


def test_cell_kinds_and_the_coordinates_at_hanging_nodes():
    hanging = np.array([[0, 0], [0.5, 0], [1, 0], [1, 1], [0, 1]], float)  # 180° at (0.5, 0)
    l_shape = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], float)
    mesh = build_mesh("hanging", 2, levels=1, rule="contact")
    kinds = cell_kinds(mesh)
    assert np.all(kinds[mesh.cell_sizes > 4] == MEAN_VALUE) and np.all(kinds[mesh.cell_sizes == 4] == WACHSPRESS)
    # mean value coordinates interpolate the hanging node's value along the split edge
    phi = coordinates(hanging[:, 0], hanging[:, 1], [[0.25, 0.0], [0.5, 0.0], [0.5, 0.5]], MEAN_VALUE)
    assert np.allclose(phi[0], [0.5, 0.5, 0, 0, 0]) and np.allclose(phi[1], [0, 1, 0, 0, 0])
    assert phi[2, 1] > 0 and np.isclose(phi[2].sum(), 1.0)
    # a non-convex cell: still a partition of unity with linear precision
    pts = np.array([[0.5, 0.5], [1.5, 0.5], [0.5, 1.5], [0.9, 0.9], [1.2, 0.2]])
    phi = coordinates(l_shape[:, 0], l_shape[:, 1], pts, MEAN_VALUE)
    assert np.allclose(phi.sum(axis=1), 1.0) and np.allclose(phi @ l_shape, pts, atol=1e-13)


@pytest.mark.parametrize("case", sorted(FAMILY_CASES))
def test_paper_measure_of_a_linear_field_and_of_the_reference_itself_is_zero(case, rng):
    ref = build_mesh("square", 16)
    u_ref = rng.standard_normal((ref.n_vertices, 2))
    assert paper_error(ref, u_ref, ref, u_ref) == 0.0
    mesh = family_mesh(case, 4)
    assert paper_error(mesh, linear_field(mesh.vertices), ref, linear_field(ref.vertices)) < 1e-12


def test_paper_measure_on_nested_squares_converges_at_order_one():
    """Nodal interpolants of a smooth field: e_h = O(h), and on one mesh the paper's measure and
    the seminorm of Pi_1 on each mesh coincide up to the interpolation inside the coarse cells."""

    def smooth(x):
        return np.stack([np.sin(2 * x[:, 0]) * np.cos(x[:, 1]), np.exp(x[:, 0] * x[:, 1])], axis=1)

    ref = build_mesh("square", 64)
    errors = []
    for n in (4, 8, 16):
        mesh = build_mesh("square", n)
        errors.append(paper_error(mesh, smooth(mesh.vertices), ref, smooth(ref.vertices)))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - 1.0) < 0.1), orders
    mesh = build_mesh("square", 16)
    semi = projection_error(
        mesh, projected_solution(mesh, smooth(mesh.vertices)), ref, projected_solution(ref, smooth(ref.vertices))
    )["h1_semi"]
    assert 0.5 < errors[-1] / semi < 2.0


def test_cell_areas_and_point_location_cover_the_domain():
    for case in FAMILY_CASES:
        mesh = family_mesh(case, 5)
        assert np.isclose(mesh.cell_areas.sum(), 1.0) and np.all(mesh.cell_areas > 0)
        assert np.all(locate_points(mesh, build_mesh("square", 20).vertices) >= 0)
