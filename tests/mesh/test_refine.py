"""Local refinement with hanging nodes (vemkit.mesh.refine): valid meshes, exact geometry, patch test."""

from pathlib import Path

import numpy as np
import pytest
from conftest import FAMILY_CASES, family_mesh

from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.families import build_mesh
from vemkit.mesh.mesh import from_polygons
from vemkit.mesh.refine import corner_positions, refine_cells
from vemkit.vem.elasticity import lame_parameters
from vemkit.vem.elements.k1_fields import traction_load
from vemkit.vem.space import VirtualElementSpace

LAM, MU = lame_parameters(2000.0, 0.4)
NORMALS = {"left": [-1, 0], "right": [1, 0], "bottom": [0, -1], "top": [0, 1]}


def _adapted(case: str, steps: int = 3, fraction: float = 0.3, max_hanging=None):
    mesh = family_mesh(case, 5)
    rng = np.random.default_rng(7)
    for _ in range(steps):
        mesh = refine_cells(mesh, rng.random(mesh.n_cells) < fraction, max_hanging=max_hanging).mesh
    return mesh


def _side_lengths(mesh):
    return {
        k: float(np.linalg.norm(np.diff(mesh.vertices[e], axis=1), axis=-1).sum()) for k, e in mesh.boundary.items()
    }


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
    K = VirtualElementSpace(mesh, 1).stiffness_matrix(LAM, MU, "dofi-2mu")
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
    mesh = from_polygons(
        np.r_[ring, [[0.0, 0.0]]],
        [[i, (i + 1) % m, m] for i in range(m)],
        {"rim": [[i, (i + 1) % m] for i in range(m)]},
        {"circles": {"rim": [0.0, 0.0, 1.0]}},
    )
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


def test_a_non_convex_cell_is_split_from_its_kernel_when_centroid_and_vertex_mean_lie_outside():
    # a thin L: centroid (2.87, 2.87) and vertex mean (3.67, 3.67) see neither inner edge; its kernel
    # is the unit square at the corner, whose centroid becomes the new vertex
    v = [[0, 0], [10, 0], [10, 1], [1, 1], [1, 10], [0, 10]]
    mesh = from_polygons(v, [list(range(6))], {"outer": [[i, (i + 1) % 6] for i in range(6)]})
    refined = refine_cells(mesh, [0])
    assert refined.skipped.size == 0 and refined.mesh.n_cells == 6
    validate_mesh(refined.mesh)
    assert np.allclose(refined.mesh.vertices[-1], [0.5, 0.5], atol=1e-12)
    assert np.isclose(refined.mesh.cell_areas.sum(), 19.0, rtol=1e-14)


def test_cut_cells_at_a_circular_hole_are_split_with_every_new_vertex_on_the_circle():
    """The L-bracket's bore (radius 2 at (5, 25)) on squares h = 2.5 starts as an octagon in four
    cut cells that wrap its corners; vertices moved onto the circle dent them until neither centroid
    nor vertex mean sees every edge. Every refinement splits them from a kernel point instead."""
    from vemkit.config.scene import load_scene
    from vemkit.mesh import scene_mesh
    from vemkit.studies.adaptivity import curved_sides

    scene = load_scene(
        Path(__file__).resolve().parents[2] / "config" / "scenes" / "lbracket.yaml", ["discretization.mesh.h=2.5"]
    )
    mesh, circles = scene_mesh(scene), curved_sides(scene.domain)
    area = mesh.cell_areas.sum()
    for step in range(4):
        bore = np.unique(mesh.boundary["bore"])
        at_bore = [k for k in range(mesh.n_cells) if np.isin(mesh.cell(k), bore).any()]
        refined = refine_cells(mesh, at_bore, circles=circles)
        assert refined.skipped.size == 0 and np.array_equal(refined.refined, at_bore)
        mesh = refined.mesh
        validate_mesh(mesh)
        on_bore = np.unique(mesh.boundary["bore"])
        assert on_bore.size == 2 * bore.size == 16 * 2**step
        assert np.allclose(np.linalg.norm(mesh.vertices[on_bore] - [5.0, 25.0], axis=1), 2.0, atol=1e-13)
        # the bore's polygon (16 * 2^step sides inscribed in the circle) grows towards the circle
        bore_area = 0.5 * on_bore.size * 4.0 * np.sin(2 * np.pi / on_bore.size)
        assert mesh.cell_areas.sum() < area and np.isclose(mesh.cell_areas.sum(), 700.0 - bore_area, rtol=1e-13)
        area = mesh.cell_areas.sum()


def test_a_new_vertex_the_circle_would_push_out_of_its_cell_stays_on_the_chord():
    # a thin strip x + y in [1, 1.05] whose side on the unit circle is one chord: the circle's midpoint
    # (0.707, 0.707) lies beyond the strip, so that cell keeps its new vertex at the chord's midpoint
    v = [[1, 0], [1.05, 0], [0, 1.05], [0, 1]]
    mesh = from_polygons(
        v, [[0, 1, 2, 3]], {"outer": [[0, 1], [1, 2], [2, 3]], "hole": [[3, 0]]}, {"circles": {"hole": [0.0, 0.0, 1.0]}}
    )
    refined = refine_cells(mesh, [0])
    assert refined.skipped.size == 0 and refined.mesh.n_cells == 4
    validate_mesh(refined.mesh)
    hole = np.unique(refined.mesh.boundary["hole"])
    assert hole.size == 3 and np.allclose(refined.mesh.vertices[hole[-1]], [0.5, 0.5], atol=1e-15)
