"""Square meshes with hanging nodes: an n x n grid, some squares cut into four, repeatedly.

Each of ``levels`` rounds splits (quadrisection) a set of the current squares:

- ``rule="contact"``: the squares touching the contact side (``contact_side``, default the bottom
  y = 0). After k rounds the squares along that side have size h / 2^k, those behind them
  h / 2^(k-1), ...: a graded layer, 2:1 across every level change.
- ``rule="random"``: ``round(fraction · count)`` of the current squares, chosen with
  ``numpy.random.default_rng(seed)``. Nothing balances the tree, so a square can border squares
  4, 8, ... times smaller (more than one hanging node per side); that is intended, for testing.

Every square lists, counter-clockwise from its lower-left corner, all the vertices lying on its
boundary: the corners of its smaller neighbours are hanging nodes, so a coarse square becomes a
5-, 6-, ... vertex polygon with collinear vertices (SPEC §3). Coordinates are computed on the
integer grid of the finest possible level and divided once, so shared vertices coincide exactly.
"""

from __future__ import annotations

import numpy as np

from vemkit.mesh.mesh import Mesh, tag_box_boundary

RULES = ("contact", "random")
SIDES = ("left", "right", "bottom", "top")


def hanging(n: int, levels: int = 1, rule: str = "contact", seed: int = 0, fraction: float = 0.3,
            contact_side: str = "bottom") -> Mesh:
    """n x n squares refined ``levels`` times by ``rule`` ("contact" or "random")."""
    n, levels = int(n), int(levels)
    if n < 1:
        raise ValueError(f"mesh n = {n}: the number of cells per side must be >= 1")
    if levels < 0:
        raise ValueError(f"levels = {levels}: give a number of refinement rounds >= 0")
    if rule not in RULES:
        raise ValueError(f"rule = {rule!r}: valid rules are {', '.join(RULES)}")
    if contact_side not in SIDES:
        raise ValueError(f"contact_side = {contact_side!r}: valid sides are {', '.join(SIDES)}")
    if rule == "random" and not 0.0 <= fraction <= 1.0:
        raise ValueError(f"fraction = {fraction}: give a fraction of cells between 0 and 1")
    fine = n << levels  # grid points per side at the finest level
    unit = 1 << levels
    j, i = np.divmod(np.arange(n * n, dtype=np.int64), n)
    squares = np.stack([i * unit, j * unit, np.full(n * n, unit)], axis=1)  # (x0, y0, size) on the fine grid
    rng = np.random.default_rng(seed)
    for _ in range(levels):
        if rule == "contact":
            chosen = _touching(squares, contact_side, fine)
        else:
            chosen = np.zeros(squares.shape[0], dtype=bool)
            chosen[rng.choice(squares.shape[0], int(round(fraction * squares.shape[0])), replace=False)] = True
        squares = _quadrisect(squares, chosen)
    vertices, offsets, cell_vertices = _polygons(squares, fine)
    meta = {"family": "hanging", "n": n, "levels": levels, "rule": rule, "seed": int(seed)}
    if rule == "random":
        meta["fraction"] = float(fraction)
    else:
        meta["contact_side"] = contact_side
    return tag_box_boundary(Mesh(vertices, offsets, cell_vertices, {}, meta))


def _touching(squares: np.ndarray, side: str, fine: int) -> np.ndarray:
    x0, y0, s = squares.T
    return {"left": x0 == 0, "bottom": y0 == 0, "right": x0 + s == fine, "top": y0 + s == fine}[side]


def _quadrisect(squares: np.ndarray, chosen: np.ndarray) -> np.ndarray:
    """Replace every chosen square, in place, by its four children (lower-left, lower-right, upper-right, upper-left)."""
    copies = np.where(chosen, 4, 1)
    out = np.repeat(squares, copies, axis=0)
    child = np.arange(out.shape[0]) - np.repeat(np.cumsum(copies) - copies, copies)
    split = np.repeat(chosen, copies)
    half = out[:, 2] // 2
    dx = np.array([0, 1, 1, 0])[child % 4]
    dy = np.array([0, 0, 1, 1])[child % 4]
    out[split, 0] += (dx * half)[split]
    out[split, 1] += (dy * half)[split]
    out[split, 2] = half[split]
    return out


def _polygons(squares: np.ndarray, fine: int):
    """Vertices and CSR polygons: each square with every square corner lying on its boundary."""
    x0, y0, s = squares.T
    corners = np.concatenate([
        np.stack([x0, y0], 1), np.stack([x0 + s, y0], 1), np.stack([x0 + s, y0 + s], 1), np.stack([x0, y0 + s], 1)
    ])
    keys = np.unique(corners[:, 1] * (fine + 1) + corners[:, 0])
    offsets = np.zeros(squares.shape[0] + 1, dtype=np.int64)
    pieces, owners = [], []
    for size in np.unique(s):
        cells = np.flatnonzero(s == size)
        t = np.arange(size)
        # walk the boundary one fine step at a time: bottom, right, top, left (counter-clockwise)
        px = np.concatenate([t, np.full(size, size), size - t, np.zeros(size, np.int64)])
        py = np.concatenate([np.zeros(size, np.int64), t, np.full(size, size), size - t])
        walk = (y0[cells, None] + py) * (fine + 1) + (x0[cells, None] + px)
        pos = np.minimum(np.searchsorted(keys, walk), keys.size - 1)
        present = keys[pos] == walk
        pieces.append(pos[present])
        owners.append(np.repeat(cells, present.sum(axis=1)))
        offsets[cells + 1] = present.sum(axis=1)
    order = np.argsort(np.concatenate(owners), kind="stable")
    cell_vertices = np.concatenate(pieces)[order]
    offsets = np.cumsum(offsets)
    y, x = np.divmod(keys, fine + 1)
    vertices = np.stack([x, y], axis=1) / fine
    return vertices, offsets, cell_vertices
