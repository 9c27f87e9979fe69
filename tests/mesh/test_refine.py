"""Local refinement with hanging nodes (vemkit.mesh.refine): valid meshes, exact geometry, patch test."""

import numpy as np
import pytest

from conftest import FAMILY_CASES, family_mesh
from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.families import build_mesh
from vemkit.mesh.mesh import from_polygons
from vemkit.mesh.refine import corner_positions, refine_cells
from vemkit.vem.assembly import stiffness_matrix
from vemkit.vem.elasticity import lame_parameters
from vemkit.vem.load import traction_load

LAM, MU = lame_parameters(2000.0, 0.4)
NORMALS = {"left": [-1, 0], "right": [1, 0], "bottom": [0, -1], "top": [0, 1]}


def _adapted(case: str, steps: int = 3, fraction: float = 0.3, max_hanging=None):
    mesh = family_mesh(case, 5)
    rng = np.random.default_rng(7)
    for _ in range(steps):
        mesh = refine_cells(mesh, rng.random(mesh.n_cells) < fraction, max_hanging=max_hanging).mesh
    return mesh


def _side_lengths(mesh):
    return {k: float(np.linalg.norm(np.diff(mesh.vertices[e], axis=1), axis=-1).sum()) for k, e in mesh.boundary.items()}


def test_a_square_is_quadrisected_and_its_neighbours_gain_hanging_nodes():
    mesh = build_mesh("square", 2)
    refined = refine_cells(mesh, [0])
    new = refined.mesh
    assert new.n_cells == 7 and new.n_vertices == 9 + 5
    children = new.cell_areas[refined.parent == 0]
    assert np.allclose(children, 0.0625)
    # the two neighbours of cell 0 are now pentagons: one hanging node each, no new corner
    neighbours = [k for k in range(new.n_cells) if refined.parent[k] != 0 and new.cell_sizes[k] == 5]
    assert len(neighbours) == 2
    for k in neighbours:
        assert corner_positions(new.vertices[new.cell(k)]).size == 4


@pytest.mark.parametrize("case", list(FAMILY_CASES))
def test_adaptively_refined_meshes_are_valid_and_keep_area_and_sides(case):
    coarse = family_mesh(case, 5)
    mesh = _adapted(case)
    validate_mesh(mesh)
    assert mesh.n_cells > coarse.n_cells
    assert np.isclose(mesh.cell_areas.sum(), coarse.cell_areas.sum(), rtol=1e-13)
    before, after = _side_lengths(coarse), _side_lengths(mesh)
    assert before.keys() == after.keys() and all(np.isclose(before[k], after[k], rtol=1e-13) for k in before)


@pytest.mark.parametrize("case", list(FAMILY_CASES))
def test_patch_test_on_adaptively_refined_meshes(case):
    """K u_I equals the boundary traction load for every linear u on the refined mesh."""
    mesh = _adapted(case)
    G = np.array([[0.3, -1.2], [0.7, 0.25]])
    u = (mesh.vertices @ G.T + np.array([0.4, -0.9])).ravel()
    eps = 0.5 * (G + G.T)
    sig = LAM * np.trace(eps) * np.eye(2) + 2 * MU * eps
    f = np.zeros((mesh.n_vertices, 2))
    for side, normal in NORMALS.items():
        t = sig @ np.array(normal, float)
        f += traction_load(mesh, mesh.boundary[side], lambda x, y, t=t: (t[0] + 0 * x, t[1] + 0 * x))
    K = stiffness_matrix(mesh, LAM, MU, "dofi-2mu")
    assert np.abs(K @ u - f.ravel()).max() < 1e-10 * np.abs(f).max()


@pytest.mark.parametrize("limit", [1, 2])
def test_max_hanging_bounds_the_vertices_inside_every_geometric_edge(limit):
    mesh = build_mesh("square", 4)
    for _ in range(4):  # refine the corner cell at the origin again and again
        corner = np.argmin(np.linalg.norm(mesh.vertices[mesh.cell_vertices].reshape(-1, 2), axis=1))
        cell = np.searchsorted(mesh.cell_offsets, corner, side="right") - 1
        mesh = refine_cells(mesh, [cell], max_hanging=limit).mesh
    validate_mesh(mesh)
    for k in range(mesh.n_cells):
        corners = corner_positions(mesh.vertices[mesh.cell(k)])
        gaps = np.diff(np.r_[corners, corners[0] + mesh.cell_sizes[k]]) - 1
        assert gaps.max() <= limit


def test_prolongation_reproduces_linear_fields_and_maps_old_vertices_to_themselves():
    mesh = family_mesh("voronoi", 6)
    refined = refine_cells(mesh, np.arange(0, mesh.n_cells, 3))
    u_old = mesh.vertices @ np.array([[1.5, -0.2], [0.3, 2.0]]) + 0.7
    u_new = refined.prolongation @ u_old
    exact = refined.mesh.vertices @ np.array([[1.5, -0.2], [0.3, 2.0]]) + 0.7
    on_edges = np.r_[np.arange(mesh.n_vertices), np.flatnonzero(np.diff(refined.prolongation.indptr) == 2)]
    assert np.allclose(u_new[on_edges], exact[on_edges], atol=1e-13)
    assert np.allclose(u_new[: mesh.n_vertices], u_old)


def test_new_vertices_on_a_circular_side_lie_on_the_circle():
    m = 16
    t = 2 * np.pi * np.arange(m) / m
    ring = np.stack([np.cos(t), np.sin(t)], axis=1)
    mesh = from_polygons(np.r_[ring, [[0.0, 0.0]]], [[i, (i + 1) % m, m] for i in range(m)],
                         {"rim": [[i, (i + 1) % m] for i in range(m)]}, {"circles": {"rim": [0.0, 0.0, 1.0]}})
    refined = refine_cells(mesh, np.arange(m)).mesh
    validate_mesh(refined)
    rim = np.unique(refined.boundary["rim"])
    assert rim.size == 2 * m
    assert np.allclose(np.linalg.norm(refined.vertices[rim], axis=1), 1.0, atol=1e-14)


def test_a_non_convex_cell_without_a_kernel_point_is_reported_not_broken():
    # a thin "C": neither the centroid nor the vertex mean sees every edge
    v = [[0, 0], [3, 0], [3, 1], [1, 1], [1, 2], [3, 2], [3, 3], [0, 3]]
    mesh = from_polygons(v, [list(range(8))], {"outer": [[i, (i + 1) % 8] for i in range(8)]})
    refined = refine_cells(mesh, [0])
    assert refined.skipped.tolist() == [0] and refined.mesh.n_cells == 1
    validate_mesh(refined.mesh)


def test_bad_cell_indices_are_refused():
    from vemkit.exceptions import InputError

    with pytest.raises(InputError, match="cell indices"):
        refine_cells(build_mesh("square", 2), [4])
