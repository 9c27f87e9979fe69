"""validate_mesh: valid meshes pass, every kind of broken mesh is named precisely."""

import time

import numpy as np
import pytest

from vemkit.exceptions import MeshError
from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.families.square import square, structured_triangle
from vemkit.mesh.mesh import Mesh, from_polygons

# two unit squares side by side: vertices 0..5
#   3---4---5
#   | 0 | 1 |
#   0---1---2
TWO = np.array([[0, 0], [1, 0], [2, 0], [0, 1], [1, 1], [2, 1]], float)
TWO_CELLS = [[0, 1, 4, 3], [1, 2, 5, 4]]


def raw(vertices, offsets, cell_vertices, boundary=None):
    return Mesh(np.asarray(vertices, float), offsets, cell_vertices, boundary or {}, {})


def rejects(mesh, *fragments):
    with pytest.raises(MeshError) as info:
        validate_mesh(mesh)
    message = str(info.value)
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, message
    return message


def test_valid_meshes_pass():
    validate_mesh(from_polygons(TWO, TWO_CELLS))
    validate_mesh(square(5))
    validate_mesh(structured_triangle(5))


def test_hanging_node_listed_in_both_cells_passes():
    v = [[0, 0], [2, 0], [2, 2], [0, 2], [3, 0], [3, 1], [3, 2], [2, 1]]
    validate_mesh(from_polygons(v, [[0, 1, 7, 2, 3], [1, 4, 5, 7], [7, 5, 6, 2]]))


def test_vertex_array_shape_and_finite():
    rejects(raw(np.zeros((4, 3)), [0, 3], [0, 1, 2]), "(4, 3)", "(N, 2)")
    v = TWO.copy()
    v[2, 1] = np.nan
    rejects(from_polygons(v, TWO_CELLS), "vertex 2", "non-finite")


def test_bad_offsets():
    rejects(raw(TWO, [1, 4, 8], np.array(TWO_CELLS).ravel()), "starting at 0")
    rejects(raw(TWO, [0, 4, 7], np.array(TWO_CELLS).ravel()), "end at 7", "8 cell_vertices")
    rejects(raw(TWO, [0, 5, 4, 8], np.array(TWO_CELLS).ravel()), "decrease at cell 1")


def test_cell_with_too_few_vertices():
    rejects(raw(TWO, [0, 4, 6, 8], [0, 1, 4, 3, 1, 2, 5, 4]), "cell 1 has 2 vertices")


def test_vertex_index_out_of_range():
    rejects(from_polygons(TWO, [[0, 1, 4, 3], [1, 2, 99, 4]]), "cell 1", "vertex 99")


def test_repeated_vertex_in_cell():
    rejects(from_polygons(TWO, [[0, 1, 4, 3], [1, 2, 5, 1, 4]]), "cell 1", "vertex 1 more than once")


def test_clockwise_cell():
    rejects(from_polygons(TWO, [[0, 1, 4, 3], [4, 5, 2, 1]]), "cell 1 is clockwise", "counter-clockwise")


def test_zero_area_cell():
    v = [[0, 0], [1, 0], [2, 0]]
    rejects(from_polygons(v, [[0, 1, 2]]), "cell 0 has zero area")


def test_self_intersecting_cell():
    v = np.array([[0, 0], [4, 0], [4, 3], [2, -1], [0, 3]], float)
    mesh = from_polygons(v, [[0, 1, 2, 3, 4]])
    assert mesh.cell_areas[0] > 0  # positive area: only the crossing is wrong
    rejects(mesh, "cell 0 is self-intersecting", "(0, 1)", "(2, 3)")


def test_duplicated_vertices():
    v = np.vstack([TWO, [[1, 0], [1, 1]]])  # 6 and 7 copy 1 and 4
    rejects(from_polygons(v, [[0, 1, 4, 3], [6, 2, 5, 7]]), "vertices 1 and 6", "merge")


def test_unused_vertex():
    v = np.vstack([TWO, [[5, 5]]])
    rejects(from_polygons(v, TWO_CELLS), "vertex 6 belongs to no cell")


def test_edge_in_three_cells():
    v = [[0, 0], [1, 0], [0.5, 1], [0.5, -1], [0.3, 2]]
    rejects(from_polygons(v, [[0, 1, 2], [1, 0, 3], [0, 1, 4]]), "edge (0, 1) belongs to 3 cells", "[0, 1, 2]")


def test_edge_traversed_twice_in_same_direction():
    v = [[0, 0], [1, 0], [0.5, 1], [0.3, 2]]
    rejects(from_polygons(v, [[0, 1, 2], [0, 1, 3]]), "edge (0, 1)", "same direction by cells 0 and 1")


def test_t_junction_is_named():
    # the big square does not list vertex 7, the corner of its two small neighbours
    v = [[0, 0], [2, 0], [2, 2], [0, 2], [3, 0], [3, 1], [3, 2], [2, 1]]
    rejects(
        from_polygons(v, [[0, 1, 2, 3], [1, 4, 5, 7], [7, 5, 6, 2]]),
        "vertex 7 lies inside edge (1, 2) of cell 0",
        "T-junction",
        "insert vertex 7 into cell 0",
    )


def test_double_cover_around_a_vertex():
    # a fan of 8 triangles winding twice around vertex 0 (inner and outer sheet)
    k = 4
    angle = [2 * np.pi * i / k for i in range(k)] + [2 * np.pi * (i + 0.5) / k for i in range(k)]
    ring = [[r * np.cos(a), r * np.sin(a)] for r, a in zip([1] * k + [2] * k, angle)]
    v = [[0.0, 0.0]] + ring
    cells = [[0, 1 + i, 1 + (i + 1) % (2 * k)] for i in range(2 * k)]
    rejects(from_polygons(v, cells), "cells around vertex 0 cover an angle of 12.56", "instead of 6.28")


def test_overlapping_cells_with_crossing_boundaries():
    v = [[0, 0], [2, 0], [2, 2], [0, 2], [1, 1], [3, 1], [3, 3], [1, 3]]
    rejects(from_polygons(v, [[0, 1, 2, 3], [4, 5, 6, 7]]), "boundary edges", "cross")


def test_cell_lying_inside_another():
    v = [[0, 0], [3, 0], [3, 3], [0, 3], [1, 1], [2, 1], [2, 2], [1, 2]]
    rejects(from_polygons(v, [[0, 1, 2, 3], [4, 5, 6, 7]]), "just outside boundary edge", "on top of others")


def test_boundary_part_without_edges():
    rejects(square(2).with_boundary(top=np.zeros((0, 2))), "boundary part 'top' has no edge")


def test_boundary_part_edge_not_on_boundary():
    mesh = square(2)  # vertices 0..8 on a 3 x 3 grid; (1, 4) is interior
    rejects(mesh.with_boundary(top=[[1, 4]]), "boundary part 'top' edge (1, 4) is not a boundary edge")
    rejects(mesh.with_boundary(bottom=[[1, 0]]), "boundary part 'bottom' edge (1, 0) runs clockwise", "(0, 1)")
    rejects(mesh.with_boundary(bottom=[[0, 42]]), "boundary part 'bottom' edge (0, 42)", "does not exist")


def test_large_square_mesh_is_fast():
    validate_mesh(square(4))  # compile
    mesh = square(256)
    start = time.perf_counter()
    validate_mesh(mesh)
    assert time.perf_counter() - start < 5.0
