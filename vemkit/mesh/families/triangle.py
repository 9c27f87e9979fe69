"""Unstructured quality Delaunay triangulations of the unit square (Shewchuk's Triangle).

``delaunay_triangle(n)`` has about ``2 n²`` triangles, as many as the structured n x n triangle
mesh (the paper's Fig. 4 uses 1024 triangles: n ≈ 22.6). Triangle is run on the square's four
sides as segments (so each side is exactly a union of mesh edges) plus a few seeded points, with
the quality switch ``q<min_angle>`` and a maximum-area switch ``a`` that is adjusted until the
number of triangles is within 2 % of ``round(2 n²)`` (the closest count found is kept).

The seed: ``numpy.random.default_rng(seed)`` places about ``n`` extra input points, one in each
cell of a ``⌊√n⌋ x ⌊√n⌋`` grid, jittered within the middle half of the grid cell. They are far
apart compared with the mesh size, so they change the mesh without spoiling its grading; the
same (n, seed, min_angle) always gives the same mesh. Below n = 4 there is no room for them and
the seed has no effect.
"""

from __future__ import annotations

import numpy as np
import triangle as shewchuk

from vemkit.mesh.mesh import Mesh, tag_box_boundary

_SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
_SIDES = np.array([[0, 1], [1, 2], [2, 3], [3, 0]], dtype=np.int64)
_MAX_AREA_ROUNDS = 12


def delaunay_triangle(n: float, seed: int = 0, min_angle: float = 28.0) -> Mesh:
    """About ``round(2 n²)`` quality Delaunay triangles (no angle below ``min_angle`` degrees)."""
    if not n >= 1:
        raise ValueError(f"mesh n = {n}: the number of cells per side must be >= 1")
    if not 0.0 < min_angle <= 33.0:
        raise ValueError(f"min_angle = {min_angle}: Triangle guarantees quality only for 0 < min_angle <= 33 degrees")
    target = int(round(2 * n * n))
    points = np.vstack([_SQUARE, _seed_points(n, seed)])
    max_area = 1.5 / target
    best = None
    for _ in range(_MAX_AREA_ROUNDS):
        options = f"pq{min_angle:g}a{np.format_float_positional(max_area, trim='-')}Q"
        out = shewchuk.triangulate({"vertices": points, "segments": _SIDES}, options)
        count = out["triangles"].shape[0]
        if best is None or abs(count - target) < abs(best[1] - target):
            best = (out, count, options)
        if abs(count - target) <= 0.02 * target:
            break
        max_area *= count / target
    out, count, options = best
    vertices = np.asarray(out["vertices"], dtype=np.float64)
    cells = _counter_clockwise(vertices, np.asarray(out["triangles"], dtype=np.int64))
    offsets = np.arange(0, 3 * count + 1, 3, dtype=np.int64)
    meta = {"family": "triangle", "kind": "delaunay", "n": n, "seed": int(seed), "min_angle": float(min_angle),
            "options": options, "target_cells": target}
    return tag_box_boundary(Mesh(vertices, offsets, cells.ravel(), {}, meta))


def _seed_points(n: float, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    g = int(np.sqrt(n)) if n >= 4 else 0
    i, j = np.meshgrid(np.arange(g), np.arange(g), indexing="xy")
    centres = np.stack([i.ravel(), j.ravel()], axis=1) + 0.5
    return (centres + 0.5 * (rng.random((g * g, 2)) - 0.5)) / g


def _counter_clockwise(vertices: np.ndarray, tris: np.ndarray) -> np.ndarray:
    a, b, c = vertices[tris[:, 0]], vertices[tris[:, 1]], vertices[tris[:, 2]]
    signed = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    tris = tris.copy()
    flip = signed < 0
    tris[flip] = tris[flip][:, ::-1]
    return tris
