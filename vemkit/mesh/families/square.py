"""Structured meshes of the unit square: n x n squares, and the same grid split into triangles;
``square`` on any other domain: cut cells (``cut.py``)."""

from __future__ import annotations

import numpy as np

from vemkit.config.domain import UNIT_SQUARE, UNIT_SQUARE_SIDE_LINES
from vemkit.mesh.families.cut import cut_squares
from vemkit.mesh.mesh import Mesh


def _grid_vertices(n: int) -> np.ndarray:
    t = np.linspace(0.0, 1.0, n + 1)
    x, y = np.meshgrid(t, t, indexing="xy")
    return np.stack([x.ravel(), y.ravel()], axis=1)


def _box_sides(n: int) -> dict:
    """Boundary parts of the (n+1) x (n+1) vertex grid, edges oriented counter-clockwise."""
    t = np.arange(n, dtype=np.int64)
    row = n + 1
    parts = {}
    for name, (axis, fraction) in UNIT_SQUARE_SIDE_LINES.items():
        fixed = int(fraction) * n
        ends = np.stack([t, t + 1], axis=1)
        index = fixed * row + ends if axis == 1 else ends * row + fixed
        forward = (axis == 1) == (fraction == 0)  # bottom and right run forward, top and left back
        parts[name] = index if forward else index[:, ::-1]
    return parts


def square(n: int, domain=None) -> Mesh:
    """n x n axis-aligned squares of side h = 1/n.

    On a :class:`~vemkit.config.domain.Domain` other than the unit square (or with n not an
    integer): the grid of squares of side 1/n clipped to the domain (cut cells, ``cut.cut_squares``).
    """
    if (domain is not None and not domain.is_unit_square) or not float(n).is_integer():
        if not n > 0:
            raise ValueError(f"mesh n = {n}: the number of cells per unit length must be > 0")
        return cut_squares(domain or UNIT_SQUARE, n)
    n, v0, row = _lower_left_corners(n)
    cells = np.stack([v0, v0 + 1, v0 + 1 + row, v0 + row], axis=1)
    offsets = np.arange(0, 4 * n * n + 1, 4, dtype=np.int64)
    return Mesh(_grid_vertices(n), offsets, cells.ravel(), _box_sides(n), {"family": "square", "n": n})


def _lower_left_corners(n):
    """(n, the lower-left vertex of every grid square row by row, vertices per row) of the n x n grid."""
    n = int(n)
    if n < 1:
        raise ValueError(f"mesh n = {n}: the number of cells per side must be >= 1")
    row = n + 1
    i, j = np.meshgrid(np.arange(n, dtype=np.int64), np.arange(n, dtype=np.int64), indexing="xy")
    return n, (j * row + i).ravel(), row


def structured_triangle(n: int) -> Mesh:
    """The n x n grid with every square cut along its diagonal into two triangles."""
    n, v0, row = _lower_left_corners(n)
    lower = np.stack([v0, v0 + 1, v0 + 1 + row], axis=1)
    upper = np.stack([v0, v0 + 1 + row, v0 + row], axis=1)
    cells = np.stack([lower, upper], axis=1).reshape(-1, 3)
    offsets = np.arange(0, 3 * cells.shape[0] + 1, 3, dtype=np.int64)
    meta = {"family": "triangle", "kind": "structured", "n": n}
    return Mesh(_grid_vertices(n), offsets, cells.ravel(), _box_sides(n), meta)
