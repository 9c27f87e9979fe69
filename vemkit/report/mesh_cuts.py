"""What a figure draws of a mesh's cells: the polygons of a plane mesh, or a plane cut through a polyhedral one.

:data:`CELL_POLYGONS` is keyed by the mesh's dimension; each entry returns ``(polygons, cells)``: the
2D polygons to draw (a list of (m, 2) arrays) and the cell of each, so that per-cell values (the
indicator η_K, the diameter h_K) colour them.

The cut of a polyhedral mesh by the plane x_a = c (``axis`` a, ``at`` c): every cell with vertices on
both sides is cut, its section the polygon of the points where its faces' edges cross the plane
(sorted by angle about their mean: exact for convex cells, the boxes, tetrahedra and convex prisms
that refinement makes). Drawn in the other two coordinates, in their order (y, z for a cut at x).
A plane through vertices of the mesh (the middle of a regular grid) is moved by 10⁻⁷ of the body's
size, so that the drawn cells are those just above it instead of none.

Imports from vemkit: nothing (a mesh of either dimension through its interface).
"""

from __future__ import annotations

import numpy as np

AXES = "xyz"
NUDGE = 1e-7  # relative to the body's size: off a plane of vertices


def plane_polygons(mesh, cut=None):
    """(polygons, cells) of a plane mesh: every cell's polygon (``cut`` is not used)."""
    offsets, ids = mesh.cell_vertex_lists
    return [mesh.vertices[ids[offsets[k] : offsets[k + 1]]] for k in range(mesh.n_cells)], np.arange(mesh.n_cells)


def _edge_rows(mesh):
    """(cell, a, b) of every edge of every cell, once (a < b)."""
    cell_offsets, cell_facets = mesh.cell_facet_lists
    facet_offsets, facet_vertices = mesh.facets
    facets = np.where(cell_facets >= 0, cell_facets, -cell_facets - 1)
    cells = np.repeat(np.arange(mesh.n_cells), np.diff(cell_offsets))
    sizes = np.diff(facet_offsets)[facets]
    start = np.repeat(facet_offsets[facets], sizes)
    k = np.arange(sizes.sum()) - np.repeat(np.cumsum(sizes) - sizes, sizes)
    a = facet_vertices[start + k]
    b = facet_vertices[start + (k + 1) % np.repeat(sizes, sizes)]
    rows = np.unique(np.stack([np.repeat(cells, sizes), np.minimum(a, b), np.maximum(a, b)], axis=1), axis=0)
    return rows[:, 0], rows[:, 1], rows[:, 2]


def section_polygons(mesh, cut):
    """(polygons, cells) of the cut {axis, at} through a polyhedral mesh (module docstring)."""
    axis = AXES.index(cut["axis"])
    height = mesh.vertices[:, axis]
    level = float(cut["at"])
    size = float(np.ptp(mesh.vertices, axis=0).max())
    if np.any(np.abs(height - level) <= NUDGE * size):
        level += NUDGE * size
    cell, a, b = _edge_rows(mesh)
    ha, hb = height[a] - level, height[b] - level
    crossing = ha * hb < 0
    cell, a, b, ha, hb = cell[crossing], a[crossing], b[crossing], ha[crossing], hb[crossing]
    t = ha / (ha - hb)
    points = mesh.vertices[a] + t[:, None] * (mesh.vertices[b] - mesh.vertices[a])
    plane = [i for i in range(3) if i != axis]
    points = points[:, plane]
    if cell.size == 0:
        return [], np.zeros(0, dtype=np.int64)
    cells, first, counts = np.unique(cell, return_index=True, return_counts=True)
    order = np.argsort(cell, kind="stable")
    centre = np.add.reduceat(points[order], first, axis=0) / counts[:, None]
    angle = np.arctan2(*(points[order] - np.repeat(centre, counts, axis=0)).T[::-1])
    within = np.lexsort((angle, np.repeat(np.arange(cells.size), counts)))
    ordered = points[order][within]
    polygons = np.split(ordered, np.cumsum(counts)[:-1])
    return polygons, cells


#: dimension of the mesh -> (mesh, cut) -> (polygons, cells)
CELL_POLYGONS = {2: plane_polygons, 3: section_polygons}


def drawn_cells(mesh, cut=None):
    """(polygons, cells) a figure draws of ``mesh`` (:data:`CELL_POLYGONS`; ``cut`` for a 3D mesh,
    default the plane z through the middle of the body)."""
    if cut is None:
        middle = 0.5 * (mesh.vertices[:, -1].min() + mesh.vertices[:, -1].max())
        cut = {"axis": AXES[mesh.vertices.shape[1] - 1], "at": middle}
    return CELL_POLYGONS[mesh.dimension](mesh, cut)
