"""The cells of a polyhedral mesh cover its body once: no two cells overlap (issue 33).

Why not compare volumes. Once every cell is closed and outward and every interior face is shared
by two cells in opposite orientations (``vemkit.mesh.checks3d``), the divergence theorem makes the
cells' volumes add up to exactly the volume their boundary surface encloses, counted with its
winding number: interior faces cancel, the identity holds whatever the cells do, and an overlap
(two cubes shifted by 0.3: cells 2.0, body 1.657) passes it. What the overlap changes is the winding
number: the number of cells covering a point equals the boundary surface's winding number there,
2 inside both cubes. So, as in 2D (``vemkit.mesh.checks``), the winding number is checked where it
must be 0: just outside the boundary, at points ``OUTSIDE_OFFSET`` x the face's diameter off each
boundary face (its centroid, and a point near each vertex, a tenth of the way to the centroid).
Any such point inside a cell is an overlap (or a cell poking out through the boundary).

The winding number of a point is counted along a ray in one fixed direction, generic so that it
meets no edge of a grid-aligned mesh: the boundary faces, cut into fans of triangles, are binned
by their shadows in the plane normal to the ray, and each ray meets only the triangles of its bin
(about linear work: 0.1 s for 10^5 boundary faces). An edge the ray meets exactly is counted once
(a half-open rule on the shadow's edges).

What is not seen: an overlap that reaches none of the sample points (a sliver thinner than the
offset, or an overlap between a face's samples that no sample of any face enters).
"""

from __future__ import annotations

import numba
import numpy as np

from vemkit.exceptions import MeshError
from vemkit.mesh.geometry import bin_boxes

#: the sample points lie this fraction of the face's diameter outside the boundary face
OUTSIDE_OFFSET = 1e-6
#: the ray's direction: generic (no grid line, no diagonal of a structured mesh)
RAY = np.array([1.0, 0.3455751918948773, 0.3533766376383])


def check_cover3d(mesh) -> None:
    """MeshError naming a boundary face whose outside lies in a cell (module doc)."""
    faces, signs, triangles = _boundary_triangles(mesh)
    if faces.size == 0:
        return
    d = RAY / np.linalg.norm(RAY)
    e1 = np.cross(d, [0.0, 0.0, 1.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(d, e1)  # (d, e1, e2) right-handed: a triangle's shadow turns as its normal . d
    frame = np.stack([d, e1, e2])
    points, owner = _samples(mesh, faces, signs)
    u, q = _turned(mesh.vertices, frame), _turned(points, frame)
    shadow = np.ascontiguousarray(u[:, 1:])
    lo = shadow.min(axis=0)
    span = float(max((shadow.max(axis=0) - lo).max(), np.finfo(float).tiny))
    g = int(min(max(1, np.sqrt(triangles.shape[0])), 2048))
    inv = g / span * (1.0 - 1e-12)
    corners = shadow[triangles]  # (T, 3, 2)
    boxes = np.clip(
        np.concatenate(
            [
                np.floor((corners.min(axis=1) - lo) * inv).astype(np.int64),
                np.floor((corners.max(axis=1) - lo) * inv).astype(np.int64),
            ],
            axis=1,
        )[:, [0, 2, 1, 3]],
        0,
        g - 1,
    )
    ptr, items = bin_boxes(np.ascontiguousarray(boxes), g)
    bad = _first_wound(u, triangles, ptr, items, q, lo, inv, g)
    if bad >= 0:
        f = int(faces[owner[bad]])
        cell = int(mesh.face_cells[f].max())
        where = tuple(float(x) for x in np.round(points[bad], 6))
        raise MeshError(
            f"cells overlap: the point {where} just outside boundary face {f} (of cell {cell}) lies inside "
            "another cell (the boundary's winding number there is not 0); remove or fix the overlapping "
            "cells so that every point of the body is in one cell"
        )


def _turned(points, frame):
    """``points @ frame.T`` without BLAS (whose threads cost 0.1 s on a busy machine for 10^5 points)."""
    return np.ascontiguousarray(sum(points[:, k, None] * frame[:, k] for k in range(3)))


def _boundary_triangles(mesh):
    """(boundary faces, their outward signs (+1 stored outward), fan triangles (T, 3) turned outward)."""
    faces = np.asarray(mesh.boundary_faces, dtype=np.int64)
    cf = mesh.cell_faces
    index = np.where(cf >= 0, cf, -cf - 1)
    signs = np.ones(mesh.n_faces, dtype=np.int64)
    signs[index[cf < 0]] = -1
    signs = signs[faces]
    sizes = np.diff(mesh.face_offsets)[faces]
    starts = mesh.face_offsets[faces]
    face_of = np.repeat(np.arange(faces.size), sizes - 2)
    k = np.arange(face_of.size) - np.repeat(np.cumsum(sizes - 2) - (sizes - 2), sizes - 2) + 1
    first = mesh.face_vertices[starts[face_of]]
    a = mesh.face_vertices[starts[face_of] + k]
    b = mesh.face_vertices[starts[face_of] + k + 1]
    flip = signs[face_of] < 0
    a, b = np.where(flip, b, a), np.where(flip, a, b)
    return faces, signs, np.ascontiguousarray(np.stack([first, a, b], axis=1))


def _samples(mesh, faces, signs):
    """Points just outside each boundary face: its centroid and one near each vertex; their faces."""
    sizes = np.diff(mesh.face_offsets)[faces]
    va = mesh.face_vector_areas[faces] * signs[:, None]
    normal = va / np.linalg.norm(va, axis=1)[:, None]
    centre = mesh.face_centroids[faces]
    face_of = np.repeat(np.arange(faces.size), sizes)
    local = np.arange(face_of.size) - np.repeat(np.cumsum(sizes) - sizes, sizes)
    ids = mesh.face_vertices[mesh.face_offsets[faces][face_of] + local]
    corner = mesh.vertices[ids]
    reach = np.zeros(faces.size)
    np.maximum.at(reach, face_of, np.linalg.norm(corner - centre[face_of], axis=1))
    near = corner + 0.1 * (centre[face_of] - corner)
    points = np.concatenate([centre, near])
    owner = np.concatenate([np.arange(faces.size), face_of])
    return points + (OUTSIDE_OFFSET * 2.0 * reach[owner])[:, None] * normal[owner], owner


@numba.njit(cache=True)
def _counts(px, py, qx, qy, rx, ry):
    """Whether the shadow point (px, py) is on the left of the edge q -> r, the edge itself counted
    for a half-open rule (a point on an edge shared by two triangles belongs to one)."""
    o = (rx - qx) * (py - qy) - (ry - qy) * (px - qx)
    if o != 0.0:
        return o > 0.0
    return ry > qy or (ry == qy and rx > qx)


@numba.njit(cache=True)
def _first_wound(u, triangles, ptr, items, q, lo, inv, g):
    """First sample point whose winding number (signed crossings of the ray in +u[:, 0] with the
    triangles binned at its shadow) is not 0, or -1."""
    for s in range(q.shape[0]):
        i = min(max(int(np.floor((q[s, 1] - lo[0]) * inv)), 0), g - 1)
        j = min(max(int(np.floor((q[s, 2] - lo[1]) * inv)), 0), g - 1)
        b = j * g + i
        wind = 0
        for t in range(ptr[b], ptr[b + 1]):
            tri = triangles[items[t]]
            a0, a1, a2 = tri[0], tri[1], tri[2]
            area = (u[a1, 1] - u[a0, 1]) * (u[a2, 2] - u[a0, 2]) - (u[a2, 1] - u[a0, 1]) * (u[a1, 2] - u[a0, 2])
            if area == 0.0:
                continue  # a triangle seen edge-on: the ray runs along it
            sign = 1
            if area < 0.0:  # normalized counter-clockwise, the crossing's sign kept
                a1, a2, sign = a2, a1, -1
            px, py = q[s, 1], q[s, 2]
            if not (
                _counts(px, py, u[a0, 1], u[a0, 2], u[a1, 1], u[a1, 2])
                and _counts(px, py, u[a1, 1], u[a1, 2], u[a2, 1], u[a2, 2])
                and _counts(px, py, u[a2, 1], u[a2, 2], u[a0, 1], u[a0, 2])
            ):
                continue
            w0 = (u[a2, 1] - u[a1, 1]) * (py - u[a1, 2]) - (u[a2, 2] - u[a1, 2]) * (px - u[a1, 1])
            w1 = (u[a0, 1] - u[a2, 1]) * (py - u[a2, 2]) - (u[a0, 2] - u[a2, 2]) * (px - u[a2, 1])
            w2 = (u[a1, 1] - u[a0, 1]) * (py - u[a0, 2]) - (u[a1, 2] - u[a0, 2]) * (px - u[a0, 1])
            total = w0 + w1 + w2
            hit = (w0 * u[a0, 0] + w1 * u[a1, 0] + w2 * u[a2, 0]) / total
            if hit > q[s, 0]:
                wind += sign
        if wind != 0:
            return s
    return -1
