"""The initial gap g_a of the contact points (2.11): a foundation line (2D) or plane (3D), or an
expression of the coordinates, evaluated at the contact points and checked >= 0."""

from __future__ import annotations

import numpy as np

from vemkit.exceptions import SceneError


class FoundationLine:
    """The foundation as a line (docs/reference/files.md ``contact.foundation``), or a plane in 3D (docs/reference/files.md, a point and
    a normal of three components): the gap of a boundary point x with
    outward normal nu is the distance from x along nu to the line, d / cos with d = (x - point) . n
    (n the unit normal of the line towards the body) and cos = -nu . n; a surface turned away from
    the line (cos below MIN_FACING) gets d / MIN_FACING, far enough never to touch."""

    MIN_FACING = 1e-2

    def __init__(self, point, normal):
        self.point = np.asarray(point, dtype=float)
        normal = np.asarray(normal, dtype=float)
        self.normal = normal / (np.hypot(*normal) if normal.size == 2 else np.linalg.norm(normal))

    def along(self, coords: np.ndarray, normals: np.ndarray) -> np.ndarray:
        distance = (coords - self.point) @ self.normal
        facing = np.maximum(-(normals @ self.normal), self.MIN_FACING)
        return distance / facing


def _gap_values(gap, coords, normals, check=True):
    if isinstance(gap, FoundationLine):
        g = gap.along(coords, normals)
    else:
        g = np.broadcast_to(np.asarray(gap(*coords.T), dtype=float), (coords.shape[0],)).copy()
    if not np.all(np.isfinite(g)) or (check and np.any(g < 0)):
        bad = int(np.flatnonzero(~np.isfinite(g) | (g < 0))[0])
        where = f"{g[bad]:.6g} at " + ", ".join(f"{a}={c:.6g}" for a, c in zip("xyz", coords[bad]))
        if isinstance(gap, FoundationLine):
            what = "line" if gap.normal.size == 2 else "plane"
            raise SceneError(
                f"contact.foundation: the contact side is beyond the foundation {what} (gap {where}: the "
                "body starts out penetrating it); move contact.foundation.point or flip its normal",
                key="contact.foundation",
            )
        raise SceneError(
            f"contact.gap must be finite and >= 0 at every contact vertex (2.11): it is {where}", key="contact.gap"
        )
    return g


def _facet_gaps(gap, facet_coords, facet_vertex, vertex_gap, facet_normal):
    """(n_f, m) gap at the vertices of the Gamma_C facets (edges, faces): the contact points' gaps,
    evaluated anew only at dropped vertices (with the facet's normal)."""
    ends = np.zeros(facet_vertex.shape)
    free = facet_vertex >= 0
    ends[free] = vertex_gap[facet_vertex[free]]
    if np.any(~free):
        normals = np.broadcast_to(facet_normal[:, None, :], facet_coords.shape)
        ends[~free] = _gap_values(gap, facet_coords[~free], normals[~free], check=False)
    return ends
