"""The Numba passes of vemkit.mesh.check_kernels against the numpy formulas they replace, on random
polygon soups (cells of 3 to 40 vertices, repeats and clockwise cells included) and on meshes."""

import numpy as np
import pytest

from vemkit.exceptions import MeshError
from vemkit.mesh.check_kernels import (
    cell_perimeters,
    corner_angle_sums,
    first_repeated_vertex,
    worst_coordinate_over_edge,
)
from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.families.square import square
from vemkit.mesh.mesh import Mesh, edge_table, edge_table_numpy, from_polygons


def random_soup(seed, n_vertices=60, n_cells=200, repeats=True):
    """Random cells (3 to 40 vertex indices, a few with a vertex twice) over random vertices."""
    rng = np.random.default_rng(seed)
    sizes = rng.integers(3, 41, n_cells)
    sizes[: n_cells // 2] = rng.integers(3, 9, n_cells // 2)  # mostly small cells, as in meshes
    cells = [rng.choice(n_vertices, size, replace=repeats and rng.random() < 0.1) for size in sizes]
    vertices = rng.normal(size=(n_vertices, 2)) * 10.0 ** rng.integers(-3, 4)
    return from_polygons(vertices, cells)


def numpy_first_repeat(mesh):
    n = mesh.n_vertices
    key = np.sort(mesh.half_edge_cells * np.int64(n) + mesh.cell_vertices)
    rep = np.flatnonzero(key[1:] == key[:-1])
    return divmod(int(key[rep[0]]), n) if rep.size else (-1, -1)


def numpy_corner_sums(mesh):
    v, he = mesh.vertices, mesh.half_edges
    prev = np.empty(he.shape[0], dtype=np.int64)
    prev[1:] = he[:-1, 0]
    prev[mesh.cell_offsets[:-1]] = he[mesh.cell_offsets[1:] - 1, 0]
    a, b = v[he[:, 1]] - v[he[:, 0]], v[prev] - v[he[:, 0]]
    angle = np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], (a * b).sum(axis=1))
    angle = np.where(angle < 0, angle + 2 * np.pi, angle)
    return np.bincount(he[:, 0], weights=angle, minlength=mesh.n_vertices)


@pytest.mark.parametrize("seed", range(8))
def test_kernels_compute_the_numpy_formulas(seed):
    mesh = random_soup(seed)
    args = (mesh.cell_offsets, mesh.cell_vertices)
    assert first_repeated_vertex(*args) == numpy_first_repeat(mesh)
    v, he = mesh.vertices, mesh.half_edges
    perimeter = np.add.reduceat(np.linalg.norm(v[he[:, 1]] - v[he[:, 0]], axis=1), mesh.cell_offsets[:-1])
    np.testing.assert_allclose(cell_perimeters(v, *args), perimeter, rtol=1e-14)
    # the angle sums of cells without repeats (the checks reject the others first: a zero vector's
    # angle depends on the sign of its zeros)
    distinct = random_soup(seed, repeats=False)
    sums = corner_angle_sums(distinct.vertices, distinct.cell_offsets, distinct.cell_vertices)
    np.testing.assert_allclose(sums, numpy_corner_sums(distinct), rtol=1e-13, atol=1e-13)
    length = np.hypot(*(v[he[:, 1]] - v[he[:, 0]]).T)
    reach = np.abs(v[he[:, 0]]).max(axis=1)
    ratio = np.divide(reach, length, out=np.zeros_like(reach), where=length > 0)
    worst = int(np.argmax(ratio))
    assert worst_coordinate_over_edge(v, *args) == (worst, ratio[worst], length[worst], reach[worst])


def test_repeat_search_names_the_first_cell_and_its_smallest_repeat():
    # cell 1 repeats 7 and 3 (20 vertices: the sorted search), cell 2 repeats 0 (the pairwise search)
    cells = [[0, 1, 2], list(range(8, 26)) + [7, 3, 7, 3], [4, 0, 5, 0]]
    assert first_repeated_vertex(*_csr(cells)) == (1, 3)
    assert first_repeated_vertex(*_csr([cells[0], cells[2], cells[1]])) == (1, 0)
    assert first_repeated_vertex(*_csr([cells[0]])) == (-1, -1)


def test_angle_sums_of_a_mesh_are_two_pi_inside():
    mesh = square(6)
    total = corner_angle_sums(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices)
    inside = np.all((mesh.vertices > 0) & (mesh.vertices < 1), axis=1)
    np.testing.assert_allclose(total[inside], 2 * np.pi, rtol=1e-14)
    corners = np.all(np.isin(mesh.vertices, [0.0, 1.0]), axis=1)
    np.testing.assert_allclose(total[corners], np.pi / 2, rtol=1e-14)


def test_same_direction_edge_named_by_its_smallest_vertex_pair():
    # cells 1 and 3 both run (0, 1), cells 0 and 2 both run (2, 3): (0, 1) is named, as a sort names it
    v = [[0, 0], [1, 0], [0.5, 1], [0.5, 3], [0.3, 2], [0.4, 4]]
    cells = [[2, 3, 4], [0, 1, 2], [2, 3, 5], [0, 1, 4]]
    with pytest.raises(MeshError, match=r"edge \(0, 1\) is traversed in the same direction by cells 1 and 3"):
        validate_mesh(from_polygons(v, cells))


def _csr(cells):
    mesh = Mesh(np.zeros((30, 2)), np.cumsum([0] + [len(c) for c in cells]), np.concatenate(cells), {}, {})
    return mesh.cell_offsets, mesh.cell_vertices


@pytest.mark.parametrize("seed", range(4))
def test_edge_table_is_the_stable_sort_of_the_vertex_pairs(seed):
    mesh = random_soup(seed, n_vertices=40, n_cells=300)  # vertices of degree over INSERTION_SORT_MAX
    for got, want in zip(edge_table(mesh.half_edges, mesh.n_vertices), edge_table_numpy(mesh.half_edges, 40)):
        assert np.array_equal(got, want)
    fine = square(9)
    for got, want in zip(fine._edge_table, edge_table_numpy(fine.half_edges, fine.n_vertices)):
        assert np.array_equal(got, want)


def brute_force_t_junction(v, seg, tol):
    """The smallest (vertex, segment) of all pairs with the vertex within tol of the segment's interior."""
    a, c = v[seg[:, 0]], v[seg[:, 1]]
    d = c - a
    length = np.hypot(d[:, 0], d[:, 1])
    rel = v[:, None, :] - a[None, :, :]  # (vertex, segment, 2)
    along = (rel[..., 0] * d[:, 0] + rel[..., 1] * d[:, 1]) / length
    across = np.abs(rel[..., 0] * d[:, 1] - rel[..., 1] * d[:, 0]) / length
    end = (seg[None, :, 0] == np.arange(len(v))[:, None]) | (seg[None, :, 1] == np.arange(len(v))[:, None])
    hit = ~end & (across <= tol) & (tol < along) & (along < length - tol)
    found = np.argwhere(hit)
    return tuple(int(x) for x in found[0]) if found.size else (-1, -1)


@pytest.mark.parametrize("seed", range(6))
def test_t_junctions_found_by_binned_points_are_the_smallest_of_all_pairs(seed):
    from vemkit.mesh.checks import _first_t_junction, _grid_for

    rng = np.random.default_rng(seed)
    v = np.round(rng.random((80, 2)), 1) + rng.random((80, 2)) * 1e-3 * (seed % 2)
    seg = rng.choice(80, size=(120, 2), replace=True)
    seg = seg[seg[:, 0] != seg[:, 1]]
    seg = seg[np.hypot(*(v[seg[:, 1]] - v[seg[:, 0]]).T) > 0]
    on = rng.choice(seg.shape[0], 5)  # vertices put on segments: T-junctions
    v = np.vstack([v, 0.5 * (v[seg[on, 0]] + v[seg[on, 1]])])
    tol = 1e-9
    expected = brute_force_t_junction(v, seg, tol)
    assert expected != (-1, -1)
    assert _first_t_junction(v, seg, *_grid_for(v, seg.shape[0]), tol) == expected
    clean = v[:80]
    assert _first_t_junction(clean, seg, *_grid_for(clean, seg.shape[0]), tol) == brute_force_t_junction(
        clean, seg, tol
    )


@pytest.mark.parametrize("seed", range(8))
def test_the_edge_screen_passes_exactly_the_meshes_the_edge_checks_pass(seed):
    from vemkit.mesh.check_kernels import edges_shared_properly
    from vemkit.mesh.checks import _name_edge_defect

    outcomes = set()
    for mesh in (random_soup(seed, n_vertices=400, n_cells=8), random_soup(seed), square(3 + seed)):
        try:
            _name_edge_defect(mesh)
            passed = True
        except MeshError:
            passed = False
        assert edges_shared_properly(mesh.half_edges, mesh.half_edge_edge, mesh.edge_first_half_edges) == passed
        outcomes.add(passed)
    assert outcomes == {True, False}


@pytest.mark.parametrize("seed", range(4))
def test_topology_kernels_are_the_numpy_forms(seed):
    from vemkit.mesh.mesh import cells_of_edges, half_edge_pairs

    for mesh in (random_soup(seed), square(3 + seed)):
        nxt = np.arange(1, mesh.cell_vertices.size + 1)
        nxt[mesh.cell_offsets[1:] - 1] = mesh.cell_offsets[:-1]
        np.testing.assert_array_equal(
            half_edge_pairs(mesh.cell_offsets, mesh.cell_vertices),
            np.stack([mesh.cell_vertices, mesh.cell_vertices[nxt]], 1),
        )
        first = mesh.edge_first_half_edges
        want = np.full((first.size, 2), -1)
        want[:, 0] = mesh.half_edge_cells[first]
        other = np.ones(mesh.half_edges.shape[0], bool)
        other[first] = False
        want[mesh.half_edge_edge[other], 1] = mesh.half_edge_cells[other]  # crowded edges: the last
        np.testing.assert_array_equal(cells_of_edges(mesh.cell_offsets, mesh.half_edge_edge, first), want)
