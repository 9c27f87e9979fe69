"""Structured meshes of the unit square: n x n squares, and the same grid split into triangles."""

from __future__ import annotations

import numpy as np

from vemkit.mesh.mesh import Mesh


def _grid_vertices(n: int) -> np.ndarray:
    t = np.linspace(0.0, 1.0, n + 1)
    x, y = np.meshgrid(t, t, indexing="xy")
    return np.stack([x.ravel(), y.ravel()], axis=1)


def _box_sides(n: int) -> dict:
    """Boundary parts of the (n+1) x (n+1) vertex grid, edges oriented counter-clockwise."""
    i = np.arange(n, dtype=np.int64)
    row = n + 1
    bottom = np.stack([i, i + 1], axis=1)
    right = np.stack([i * row + n, (i + 1) * row + n], axis=1)
    top = np.stack([n * row + i + 1, n * row + i], axis=1)
    left = np.stack([(i + 1) * row, i * row], axis=1)
    return {"left": left, "right": right, "bottom": bottom, "top": top}


def square(n: int) -> Mesh:
    """n x n axis-aligned squares of side h = 1/n."""
    n = int(n)
    if n < 1:
        raise ValueError(f"mesh n = {n}: the number of cells per side must be >= 1")
    row = n + 1
    i, j = np.meshgrid(np.arange(n, dtype=np.int64), np.arange(n, dtype=np.int64), indexing="xy")
    v0 = (j * row + i).ravel()
    cells = np.stack([v0, v0 + 1, v0 + 1 + row, v0 + row], axis=1)
    offsets = np.arange(0, 4 * n * n + 1, 4, dtype=np.int64)
    return Mesh(_grid_vertices(n), offsets, cells.ravel(), _box_sides(n), {"family": "square", "n": n})


def structured_triangle(n: int) -> Mesh:
    """The n x n grid with every square cut along its diagonal into two triangles."""
    n = int(n)
    if n < 1:
        raise ValueError(f"mesh n = {n}: the number of cells per side must be >= 1")
    row = n + 1
    i, j = np.meshgrid(np.arange(n, dtype=np.int64), np.arange(n, dtype=np.int64), indexing="xy")
    v0 = (j * row + i).ravel()
    lower = np.stack([v0, v0 + 1, v0 + 1 + row], axis=1)
    upper = np.stack([v0, v0 + 1 + row, v0 + row], axis=1)
    cells = np.stack([lower, upper], axis=1).reshape(-1, 3)
    offsets = np.arange(0, 3 * cells.shape[0] + 1, 3, dtype=np.int64)
    meta = {"family": "triangle", "kind": "structured", "n": n}
    return Mesh(_grid_vertices(n), offsets, cells.ravel(), _box_sides(n), meta)
