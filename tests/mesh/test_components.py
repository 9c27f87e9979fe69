"""The pieces of a mesh: cells joined through shared vertices, numbered by their first cell."""

import numpy as np

from vemkit.mesh.components import mesh_pieces
from vemkit.mesh.families import build_mesh
from vemkit.mesh.mesh import from_polygons


def test_two_pieces_and_an_unused_vertex():
    vertices = np.array([[3, 0], [4, 0], [4, 1], [3, 1], [0, 0], [1, 0], [1, 1], [0, 1], [2, 0], [9, 9], [2, 1]], float)
    cells = [[0, 1, 2, 3], [4, 5, 6, 7], [5, 8, 10, 6]]  # piece 0: cell 0; piece 1: cells 1, 2 (shared edge)
    pieces = mesh_pieces(from_polygons(vertices, cells))
    assert pieces.count == 2
    assert pieces.cell_piece.tolist() == [0, 1, 1]
    assert pieces.vertex_piece.tolist() == [0, 0, 0, 0, 1, 1, 1, 1, 1, -1, 1]
    assert np.allclose(pieces.point_in(from_polygons(vertices, cells), 0), [3.5, 0.5])


def test_cells_meeting_at_one_vertex_are_one_piece():
    vertices = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [2, 1], [2, 2], [1, 2]], float)
    pieces = mesh_pieces(from_polygons(vertices, [[0, 1, 2, 3], [2, 4, 5, 6]]))
    assert pieces.count == 1 and (pieces.cell_piece == 0).all()


def test_a_family_mesh_is_one_piece():
    pieces = mesh_pieces(build_mesh("voronoi", 8, seed=1))
    assert pieces.count == 1 and (pieces.vertex_piece == 0).all()
