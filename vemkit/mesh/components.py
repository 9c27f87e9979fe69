"""The separate pieces of a mesh: cells joined through shared vertices (2D and 3D, one function).

A mesh file may hold a body in two pieces (a part drawn beside the body, a cell left over). Each
piece has its own rigid motions: the stiffness matrix is block diagonal over the pieces, so a piece
that its own Dirichlet data does not hold makes it singular whatever holds the others. The pieces are
the connected components of the bipartite graph cells -- vertices (a cell is joined to each of its
vertices), found by :func:`scipy.sparse.csgraph.connected_components` in linear time.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

__all__ = ["MeshPieces", "mesh_pieces"]


class MeshPieces:
    """``count`` pieces; ``cell_piece`` (M,) and ``vertex_piece`` (N,) their numbers (-1: a vertex
    no cell uses), numbered in the order of their first cell."""

    def __init__(self, count: int, cell_piece: np.ndarray, vertex_piece: np.ndarray):
        self.count = int(count)
        self.cell_piece = cell_piece
        self.vertex_piece = vertex_piece

    def cells(self, piece: int) -> np.ndarray:
        return np.flatnonzero(self.cell_piece == piece)

    def vertices(self, piece: int) -> np.ndarray:
        return np.flatnonzero(self.vertex_piece == piece)

    def point_in(self, mesh, piece: int) -> np.ndarray:
        """A point of the piece to name it by: the vertex mean of its cell nearest to the vertex mean
        of the whole piece (that mean itself may lie outside a piece that is not convex)."""
        offsets, ids = mesh.cell_vertex_lists
        cells = self.cells(piece)
        sizes = offsets[cells + 1] - offsets[cells]
        take = np.repeat(offsets[cells] - np.cumsum(sizes) + sizes, sizes) + np.arange(int(sizes.sum()))
        centres = np.add.reduceat(mesh.vertices[ids[take]], np.cumsum(sizes) - sizes, axis=0) / sizes[:, None]
        middle = mesh.vertices[self.vertices(piece)].mean(axis=0)
        return centres[np.argmin(((centres - middle) ** 2).sum(axis=1))]


def mesh_pieces(mesh) -> MeshPieces:
    """The pieces of ``mesh`` (any :class:`~vemkit.mesh.interface.MeshInterface`: its
    ``cell_vertex_lists``): cells that share a vertex are in one piece."""
    offsets, ids = mesh.cell_vertex_lists
    m, n = mesh.n_cells, mesh.n_vertices
    # the incidence matrix as CSR straight from the cell lists (cell c's row holds m + its vertices; the
    # vertices' rows are empty, the graph is taken undirected): no COO sort (0.35 s at 1e6 cells)
    index = np.int32 if m + n + ids.shape[0] < 2**31 else np.int64  # csgraph's own index type: no copies
    row_starts = np.concatenate([offsets, np.full(n, offsets[-1], dtype=offsets.dtype)]).astype(index)
    columns = (ids + m).astype(index)
    incidence = sp.csr_matrix((np.ones(ids.shape[0], dtype=np.int8), columns, row_starts), shape=(m + n, m + n))
    _, labels = connected_components(incidence, directed=False)
    cell_labels = labels[:m]
    # number the pieces in the order of their first cell
    first = np.unique(cell_labels, return_index=True)[1] if m else np.zeros(0, dtype=np.int64)
    order = np.argsort(first, kind="stable")
    renumber = np.full(m + n, -1, dtype=np.int64)
    renumber[np.unique(cell_labels)[order]] = np.arange(order.shape[0], dtype=np.int64)
    used = np.zeros(n, dtype=bool)
    used[ids] = True
    vertex_piece = np.where(used, renumber[labels[m:]], -1)
    return MeshPieces(order.shape[0], renumber[cell_labels], vertex_piece)
