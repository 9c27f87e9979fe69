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
5-, 6-, ... vertex polygon with collinear vertices (docs/reference/mathematics.md). Coordinates are computed on the
integer grid of the finest possible level and divided once, so shared vertices coincide exactly.

On any other domain (``domain=``, a :class:`~vemkit.config.domain.Domain`) the same refinement runs on
the squares of side 1/n that meet the domain (``contact_side``: any side name of the domain), and
the refined squares are then cut to the domain (``cut.cut_hanging``), whose circles and arcs are
chords of the finest squares (h / 2^levels): curved sides follow the refinement.
"""

from __future__ import annotations

import numpy as np

from vemkit.config.domain import UNIT_SQUARE, UNIT_SQUARE_SIDE_LINES, UNIT_SQUARE_SIDES
from vemkit.mesh.families.cut import cut_hanging, quadrisect
from vemkit.mesh.mesh import Mesh, tag_box_boundary

RULES = ("contact", "random")


def hanging(
    n: int,
    levels: int = 1,
    rule: str = "contact",
    seed: int = 0,
    fraction: float = 0.3,
    contact_side: str = "bottom",
    domain=None,
) -> Mesh:
    """n x n squares refined ``levels`` times by ``rule`` ("contact" or "random").

    On a :class:`~vemkit.config.domain.Domain` other than the unit square (or with n not an
    integer): squares of side 1/n over the domain, refined, then cut (``cut.cut_hanging``).
    """
    levels = int(levels)
    sides = UNIT_SQUARE_SIDES if domain is None else domain.side_names
    if levels < 0:
        raise ValueError(f"levels = {levels}: give a number of refinement rounds >= 0")
    if rule not in RULES:
        raise ValueError(f"rule = {rule!r}: valid rules are {', '.join(RULES)}")
    if contact_side not in sides and (rule == "contact" or domain is None):
        raise ValueError(f"contact_side = {contact_side!r}: valid sides are {', '.join(sides)}")
    if rule == "random" and not 0.0 <= fraction <= 1.0:
        raise ValueError(f"fraction = {fraction}: give a fraction of cells between 0 and 1")
    if (domain is not None and not domain.is_unit_square) or not float(n).is_integer():
        if not n > 0:
            raise ValueError(f"mesh n = {n}: the number of cells per unit length must be > 0")
        return cut_hanging(domain or UNIT_SQUARE, n, levels, rule, seed, fraction, contact_side)
    n = int(n)
    if n < 1:
        raise ValueError(f"mesh n = {n}: the number of cells per side must be >= 1")
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
        squares = quadrisect(squares, chosen)
    vertices, offsets, cell_vertices = _polygons(squares, fine)
    meta = {"family": "hanging", "n": n, "levels": levels, "rule": rule, "seed": int(seed)}
    if rule == "random":
        meta["fraction"] = float(fraction)
    else:
        meta["contact_side"] = contact_side
    return tag_box_boundary(Mesh(vertices, offsets, cell_vertices, {}, meta))


def _touching(squares: np.ndarray, side: str, fine: int) -> np.ndarray:
    axis, fraction = UNIT_SQUARE_SIDE_LINES[side]
    start, size = squares[:, axis], squares[:, 2]
    return start == 0 if fraction == 0 else start + size == fine


def _polygons(squares: np.ndarray, fine: int):
    """Vertices and CSR polygons: each square with every square corner lying on its boundary."""
    x0, y0, s = squares.T
    corners = np.concatenate(
        [np.stack([x0, y0], 1), np.stack([x0 + s, y0], 1), np.stack([x0 + s, y0 + s], 1), np.stack([x0, y0 + s], 1)]
    )
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
