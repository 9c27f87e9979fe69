"""Point location in a polygonal mesh: the cell that contains each point (binned bounding boxes,
then a crossing-number test; points on an edge count as inside), and the nearest cell of points
outside every cell (slivers between two discretizations of a curved side)."""

from __future__ import annotations

import numba
import numpy as np

from vemkit.mesh.geometry import bin_boxes
from vemkit.mesh.mesh import Mesh


@numba.njit(cache=True)
def _cell_bin_boxes(vertices, offsets, cell_vertices, lo, inv, nb):
    """(M, 4) bins (i0, i1, j0, j1) covered by the bounding box of every cell."""
    n_cells = offsets.shape[0] - 1
    boxes = np.empty((n_cells, 4), dtype=np.int64)
    for c in range(n_cells):
        x0 = 1e300
        x1 = -1e300
        y0 = 1e300
        y1 = -1e300
        for p in range(offsets[c], offsets[c + 1]):
            v = cell_vertices[p]
            x0 = min(x0, vertices[v, 0])
            x1 = max(x1, vertices[v, 0])
            y0 = min(y0, vertices[v, 1])
            y1 = max(y1, vertices[v, 1])
        boxes[c, 0] = min(nb - 1, max(0, int((x0 - lo[0]) * inv[0])))
        boxes[c, 1] = min(nb - 1, max(0, int((x1 - lo[0]) * inv[0])))
        boxes[c, 2] = min(nb - 1, max(0, int((y0 - lo[1]) * inv[1])))
        boxes[c, 3] = min(nb - 1, max(0, int((y1 - lo[1]) * inv[1])))
    return boxes


@numba.njit(cache=True)
def _winding_inside(vertices, offsets, cell_vertices, c, x, y):
    """Crossing-number point-in-polygon test (points on an edge count as inside)."""
    s = offsets[c]
    n = offsets[c + 1] - s
    inside = False
    for i in range(n):
        a = cell_vertices[s + i]
        b = cell_vertices[s + (i + 1) % n]
        xa, ya = vertices[a, 0], vertices[a, 1]
        xb, yb = vertices[b, 0], vertices[b, 1]
        cross = (xb - xa) * (y - ya) - (yb - ya) * (x - xa)
        if (
            abs(cross) <= 1e-14 * (abs(xb - xa) + abs(yb - ya))
            and min(xa, xb) - 1e-14 <= x <= max(xa, xb) + 1e-14
            and min(ya, yb) - 1e-14 <= y <= max(ya, yb) + 1e-14
        ):
            return True
        if (ya > y) != (yb > y):
            xi = xa + (y - ya) * (xb - xa) / (yb - ya)
            if x < xi:
                inside = not inside
    return inside


@numba.njit(cache=True)
def _locate(vertices, offsets, cell_vertices, lo, inv, nb, count, members, points, out):
    for p in range(points.shape[0]):
        x, y = points[p, 0], points[p, 1]
        i = min(nb - 1, max(0, int((x - lo[0]) * inv[0])))
        j = min(nb - 1, max(0, int((y - lo[1]) * inv[1])))
        b = j * nb + i
        out[p] = -1
        for t in range(count[b], count[b + 1]):
            c = members[t]
            if _winding_inside(vertices, offsets, cell_vertices, c, x, y):
                out[p] = c
                break


def locate_points(mesh: Mesh, points: np.ndarray) -> np.ndarray:
    """Index of a cell containing each point (-1 outside the mesh)."""
    points = np.ascontiguousarray(points, dtype=float)
    lo = mesh.vertices.min(axis=0)
    hi = mesh.vertices.max(axis=0)
    nb = max(1, int(np.sqrt(mesh.n_cells)))
    inv = nb / np.maximum(hi - lo, 1e-300) * (1 - 1e-12)
    count, members = bin_boxes(_cell_bin_boxes(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, lo, inv, nb), nb)
    out = np.empty(points.shape[0], dtype=np.int64)
    _locate(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, lo, inv, nb, count, members, points, out)
    return out


def nearest_cells(mesh: Mesh, points: np.ndarray, within_diameter: bool = True) -> np.ndarray:
    """The cell whose vertex mean is nearest each point; with ``within_diameter``, -1 where that is
    farther than the cell's diameter."""
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    if points.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    means = np.add.reduceat(mesh.vertices[mesh.cell_vertices], mesh.cell_offsets[:-1]) / mesh.cell_sizes[:, None]
    from scipy.spatial import cKDTree  # lazily: scipy.spatial is 0.1-0.3 s of a start-up

    distance, nearest = cKDTree(means).query(points)
    return np.where(distance <= mesh.cell_diameters[nearest], nearest, -1) if within_diameter else nearest
