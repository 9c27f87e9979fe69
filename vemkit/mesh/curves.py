"""The pieces of a body's boundary, and new boundary points moved onto their own piece (docs/reference/files.md).

A piece is one curved or straight part of the boundary: a circular hole (the whole circle), an arc of
the outer boundary (``domain.arcs``), a straight outer edge or an edge of a polygonal hole. Refinement
(``vemkit.mesh.refine``) puts the new vertex of a boundary edge on the curve of the piece THAT EDGE
lies on: of the pieces carrying the edge's side name, the one nearest the edge's midpoint (a chord of
a circle is within its sagitta r (1 − cos(θ/2)) of its arc; a straight piece of the same name would
have to come closer than that). Only when that piece is curved is the point moved, radially onto its
circle. A side name alone decides nothing: two circular holes, an arc and a polygonal hole, or arcs of
different circles may share one name, and every edge still follows its own piece.

Pieces are mappings: ``{"side": name, "circle": [cx, cy, r], "sweep": [t0, dt] | None}`` (None: the
whole circle; t0 the start angle, dt the signed sweep of an arc) or ``{"side": name, "segment":
[[x0, y0], [x1, y1]]}``. The older form ``{side: [cx, cy, r]}`` (one circle per side name, no
straight pieces) is read as circles without a sweep.
"""

from __future__ import annotations

import math

import numpy as np
import shapely

from vemkit.config.domain import CircleHole, arc_angles, domain_from_spec

__all__ = ["as_pieces", "domain_curves", "on_curves"]


def domain_curves(domain_spec) -> list:
    """Every piece of a domain's boundary (module docstring): circular holes, outer arcs and edges,
    polygonal holes' edges."""
    domain = domain_from_spec(domain_spec)
    pieces, k = [], len(domain.polygon)
    for i in range(k):
        a, b = domain.polygon[i], domain.polygon[(i + 1) % k]
        centre = domain.arcs[i] if domain.arcs else None
        if centre is None:
            pieces.append({"side": domain.sides[i], "segment": [list(a), list(b)]})
        else:
            r, t0, dt = arc_angles(a, b, centre)
            pieces.append(
                {"side": domain.sides[i], "circle": [float(centre[0]), float(centre[1]), r], "sweep": [t0, dt]}
            )
    for hole in domain.holes:
        if isinstance(hole, CircleHole):
            pieces.append({"side": hole.side, "circle": [hole.cx, hole.cy, hole.r], "sweep": None})
            continue
        m = len(hole.polygon)
        pieces += [
            {"side": hole.sides[j], "segment": [list(hole.polygon[j]), list(hole.polygon[(j + 1) % m])]}
            for j in range(m)
        ]
    return pieces


def as_pieces(curves) -> list:
    """Pieces from either form (module docstring); None or empty: no piece."""
    if not curves:
        return []
    if isinstance(curves, dict):
        return [{"side": side, "circle": list(circle), "sweep": None} for side, circle in curves.items()]
    return list(curves)


def _arc_distance(points: np.ndarray, piece: dict) -> np.ndarray:
    """Distance of each point to a circle piece: to the circle within the sweep, else to the nearer end."""
    cx, cy, r = (float(v) for v in piece["circle"])
    radial = np.abs(np.hypot(points[:, 0] - cx, points[:, 1] - cy) - r)
    if piece.get("sweep") is None:
        return radial
    t0, dt = piece["sweep"]
    angle = np.arctan2(points[:, 1] - cy, points[:, 0] - cx)
    s = np.remainder((angle - t0) * math.copysign(1.0, dt), 2.0 * math.pi) / abs(dt)
    ends = np.array(
        [[cx + r * math.cos(t0), cy + r * math.sin(t0)], [cx + r * math.cos(t0 + dt), cy + r * math.sin(t0 + dt)]]
    )
    to_ends = np.min(np.hypot(points[:, None, 0] - ends[None, :, 0], points[:, None, 1] - ends[None, :, 1]), axis=1)
    return np.where(s <= 1.0, radial, to_ends)


def _segment_distance(points: np.ndarray, segments: list) -> np.ndarray:
    """Distance of each point to the nearest straight piece (a shapely STRtree: no points x pieces table)."""
    if not segments:
        return np.full(points.shape[0], np.inf)
    tree = shapely.STRtree(shapely.linestrings(np.asarray(segments, dtype=float)))
    (index, nearest), distance = tree.query_nearest(shapely.points(points), return_distance=True, all_matches=False)
    out = np.full(points.shape[0], np.inf)
    out[index] = distance
    return out


def _side_edges(mesh, side: str, keys: np.ndarray) -> np.ndarray:
    """Which of the old edges ``keys`` (min * N + max) are boundary edges of ``side``."""
    edges = mesh.boundary.get(side)
    if edges is None or edges.size == 0:
        return np.zeros(keys.size, dtype=bool)
    n = np.int64(mesh.n_vertices)
    side_keys = np.unique(np.minimum(edges[:, 0], edges[:, 1]) * n + np.maximum(edges[:, 0], edges[:, 1]))
    return side_keys[np.minimum(np.searchsorted(side_keys, keys), side_keys.size - 1)] == keys


def on_curves(mesh, ends: np.ndarray, points: np.ndarray, curves) -> np.ndarray:
    """``points`` (new points on the old edges ``ends``, (k, 2) vertex pairs) with every point of a
    boundary edge whose own piece is curved moved radially onto that piece's circle (module docstring).
    Linear in the points, the boundary edges and the pieces (times log for the straight ones)."""
    points = points.copy()
    pieces = as_pieces(curves)
    n = np.int64(mesh.n_vertices)
    keys = np.minimum(ends[:, 0], ends[:, 1]) * n + np.maximum(ends[:, 0], ends[:, 1])
    for side in dict.fromkeys(p["side"] for p in pieces if "circle" in p):
        rows = np.flatnonzero(_side_edges(mesh, side, keys))
        if rows.size == 0:
            continue
        mine = [p for p in pieces if p["side"] == side]
        circles = [p for p in mine if "circle" in p]
        nearest, best = np.full(rows.size, np.inf), np.full(rows.size, -1)
        for c, piece in enumerate(circles):  # a running minimum: memory linear in the points
            distance = _arc_distance(points[rows], piece)
            closer = distance < nearest
            nearest[closer], best[closer] = distance[closer], c
        best[nearest >= _segment_distance(points[rows], [p["segment"] for p in mine if "segment" in p])] = -1
        for c, piece in enumerate(circles):
            hit = rows[best == c]
            cx, cy, r = (float(v) for v in piece["circle"])
            d = points[hit] - (cx, cy)
            points[hit] = np.array([cx, cy]) + r * d / np.linalg.norm(d, axis=1)[:, None]
    return points
