"""Unstructured quality Delaunay triangulations of any domain (Shewchuk's Triangle).

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

On any other domain (:class:`~vemkit.config.domain.Domain`) the input is every side of the outer
polygon and of the holes as segments (circles as polygons with edges of about h = 1/n), a point
inside every hole, and about ``n √area`` seeded points on a coarse jittered grid kept at least
1/n inside the domain; the target is ``round(2 n² · area)`` triangles. Triangle may split a
segment (quality), never leaves it: every boundary edge lies on one side, whose name it takes.
"""

from __future__ import annotations

import numpy as np
import shapely
import triangle as shewchuk

from vemkit.config.domain import UNIT_SQUARE_CORNERS
from vemkit.mesh.families.polygons import tag_sides
from vemkit.mesh.mesh import Mesh, tag_box_boundary

_SQUARE = np.array(UNIT_SQUARE_CORNERS)
_SIDES = np.array([[0, 1], [1, 2], [2, 3], [3, 0]], dtype=np.int64)
_MAX_AREA_ROUNDS = 12


def delaunay_triangle(n: float, seed: int = 0, min_angle: float = 28.0, domain=None) -> Mesh:
    """About ``round(2 n² · area)`` quality Delaunay triangles (no angle below ``min_angle`` degrees)
    of ``domain`` (a :class:`~vemkit.config.domain.Domain`; default the unit square)."""
    if not 0.0 < min_angle <= 33.0:
        raise ValueError(f"min_angle = {min_angle}: Triangle guarantees quality only for 0 < min_angle <= 33 degrees")
    if domain is None or domain.is_unit_square:
        if not n >= 1:
            raise ValueError(f"mesh n = {n}: the number of cells per side must be >= 1")
        target = int(round(2 * n * n))
        pslg = {"vertices": np.vstack([_SQUARE, _seed_points(n, seed)]), "segments": _SIDES}
        mesh, meta = _quality_triangles(pslg, target, min_angle)
        meta = _delaunay_meta(n, seed, min_angle, meta)
        return tag_box_boundary(Mesh(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, {}, meta))
    if not n > 0:
        raise ValueError(f"mesh n = {n}: the number of cells per unit length must be > 0")
    polygonal = domain.discretize(1.0 / n)
    target = max(1, int(round(2 * n * n * polygonal.shape.area)))
    pslg = {
        "vertices": np.vstack([polygonal.points, _domain_seed_points(polygonal.shape, n, seed)]),
        "segments": polygonal.segments,
    }
    if polygonal.hole_points.size:
        pslg["holes"] = polygonal.hole_points
    mesh, meta = _quality_triangles(pslg, target, min_angle, polygonal.shape.area)
    meta = _delaunay_meta(n, seed, min_angle, meta, domain=domain.to_spec())
    mesh = _drop_unused_vertices(mesh)
    return tag_sides(Mesh(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, {}, meta), polygonal)


def _delaunay_meta(n, seed, min_angle, triangle_meta: dict, **domain) -> dict:
    """The mesh's ``meta``: the family's parameters, then Triangle's (``_quality_triangles``), then the
    domain's spec where it is not the unit square."""
    return {
        "family": "triangle",
        "kind": "delaunay",
        "n": n,
        "seed": int(seed),
        "min_angle": float(min_angle),
        **triangle_meta,
        **domain,
    }


def _quality_triangles(pslg: dict, target: int, min_angle: float, area: float = 1.0):
    """Triangle's quality mesh of the PSLG (of the given area) with a maximum triangle area adjusted
    until the number of triangles is within 2 % of target (at most 12 tries; the closest is kept)."""
    max_area = 1.5 * area / target
    best = None
    for _ in range(_MAX_AREA_ROUNDS):
        options = f"pq{min_angle:g}a{np.format_float_positional(max_area, trim='-')}Q"
        out = shewchuk.triangulate(pslg, options)
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
    return Mesh(vertices, offsets, cells.ravel(), {}, {}), {"options": options, "target_cells": target}


def _domain_seed_points(shape, n: float, seed: int) -> np.ndarray:
    """About n √area jittered points on a coarse grid over the domain, at least 1/n inside it."""
    rng = np.random.default_rng(seed)
    x0, y0, x1, y1 = shape.bounds
    g = max(1, int(np.sqrt(n * np.sqrt(shape.area))))
    step = max(x1 - x0, y1 - y0) / g
    i, j = np.meshgrid(np.arange(int(np.ceil((x1 - x0) / step))), np.arange(int(np.ceil((y1 - y0) / step))))
    centres = np.stack([i.ravel(), j.ravel()], axis=1) + 0.5
    points = (centres + 0.5 * (rng.random(centres.shape) - 0.5)) * step + [x0, y0]
    inner = shape.buffer(-1.0 / n)
    return points[shapely.contains_xy(inner, points[:, 0], points[:, 1])] if not inner.is_empty else points[:0]


def _drop_unused_vertices(mesh: Mesh) -> Mesh:
    used = np.zeros(mesh.n_vertices, dtype=bool)
    used[mesh.cell_vertices] = True
    renumber = np.cumsum(used) - 1
    return Mesh(mesh.vertices[used], mesh.cell_offsets, renumber[mesh.cell_vertices], {}, {})


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
