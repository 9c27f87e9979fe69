"""Numba kernels of the clipped Voronoi family (``voronoi.py``): the cells of Shewchuk's Delaunay
triangulation and which of them the domain's boundary may cross.

- ``fans``: circumcentres of the triangles and every real point's fan of corners, grouped by
  point (twin ``fans_reference``, bit for bit);
- ``fan_cells``: each fan sorted counter-clockwise by the key point · 8 + angle, and every cell's
  area, centroid and bounding box: the order ``np.argsort`` of those keys gives (twin
  ``argsort_fans``) whenever no two keys of a point tie (then the caller asks the twin), and the
  bits of ``areas_centroids``;
- ``boxes_meet_segments``: the cells whose bounding box meets a boundary segment's (pinned by
  brute force); every other cell lies wholly on one side of the boundary;
- ``all_vertices_in``: per cell, whether all its vertices are inside.

The unit-square meshes are pinned bit for bit: every kernel keeps the bits of the numpy code it
replaced.
"""

from __future__ import annotations

import numba
import numpy as np

from vemkit.mesh.geometry import area_centroid_few, area_centroid_many, bin_boxes


@numba.njit(cache=True)
def fans(points, tris, count):
    """Circumcentres of the triangles and the fans of the first ``count`` points in CSR (offsets
    over the points; each point's corners in triangle order): for every corner its triangle and
    the vector (2, corners) from the point to the triangle's centroid. ``fans_reference`` is the
    same in numpy (bit for bit: the tests compare them)."""
    offsets = np.zeros(count + 1, np.int64)
    for t in range(tris.shape[0]):
        for k in range(3):
            if tris[t, k] < count:
                offsets[tris[t, k] + 1] += 1
    for p in range(count):
        offsets[p + 1] += offsets[p]
    fill = offsets[:-1].copy()
    centres = np.empty((tris.shape[0], 2))
    corner_tri = np.empty(offsets[count], np.int64)
    towards = np.empty((2, offsets[count]))  # x and y apart: numpy's arctan2 is faster on them
    for t in range(tris.shape[0]):
        ax, ay = points[tris[t, 0], 0], points[tris[t, 0], 1]
        bx, by = points[tris[t, 1], 0], points[tris[t, 1], 1]
        cx, cy = points[tris[t, 2], 0], points[tris[t, 2], 1]
        abx, aby, acx, acy = bx - ax, by - ay, cx - ax, cy - ay
        d = 2.0 * (abx * acy - aby * acx)
        nb = abx * abx + aby * aby
        nc = acx * acx + acy * acy
        centres[t, 0] = ax + (acy * nb - aby * nc) / d
        centres[t, 1] = ay + (abx * nc - acx * nb) / d
        gx, gy = (ax + bx + cx) / 3.0, (ay + by + cy) / 3.0
        for k in range(3):
            p = tris[t, k]
            if p < count:
                r = fill[p]
                fill[p] += 1
                corner_tri[r] = t
                towards[0, r], towards[1, r] = gx - points[p, 0], gy - points[p, 1]
    return centres, offsets, corner_tri, towards


def fans_reference(points, tris, count):
    """The numpy twin of ``fans``."""
    a, b, c = points[tris[:, 0]], points[tris[:, 1]], points[tris[:, 2]]
    ab, ac = b - a, c - a
    d = 2.0 * (ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0])
    nb, nc = (ab**2).sum(axis=1), (ac**2).sum(axis=1)
    centres = a + np.stack([ac[:, 1] * nb - ab[:, 1] * nc, ab[:, 0] * nc - ac[:, 0] * nb], axis=1) / d[:, None]
    corner_point, corner_tri = _corners(tris, count)
    by_point = np.argsort(corner_point, kind="stable")
    corner_point, corner_tri = corner_point[by_point], corner_tri[by_point]
    offsets = np.concatenate([[0], np.cumsum(np.bincount(corner_point, minlength=count))])
    return centres, offsets, corner_tri, ((a + b + c)[corner_tri] / 3.0 - points[corner_point]).T


def _corners(tris, count):
    """(point, triangle) of every corner at one of the first ``count`` points, in triangle order."""
    corner_point = tris.ravel().astype(np.int64)
    corner_tri = np.repeat(np.arange(tris.shape[0]), 3)
    real = corner_point < count
    return corner_point[real], corner_tri[real]


def argsort_fans(tris, count, angle):
    """The cells' ``refs`` as ``np.argsort(point * 8 + angle)`` over the corners in triangle
    order sorts them (``angle`` per corner in the CSR order of ``fans``): ``fan_cells``' twin, and
    the judge when two keys of a point tie (never seen: then the triangle order decides, whatever
    the numbering of the points)."""
    corner_point, corner_tri = _corners(tris, count)
    by_point = np.argsort(corner_point, kind="stable")
    angle_by_triangle = np.empty_like(angle)
    angle_by_triangle[by_point] = angle
    return corner_tri[np.argsort(corner_point * 8.0 + angle_by_triangle, kind="stable")]


@numba.njit(cache=True)
def fan_cells(vertices, offsets, corner_tri, angle):
    """The Voronoi cells from the fans (CSR, see ``fans``): ``refs`` (each fan sorted by the key
    point · 8 + angle, angle in [0, 2π] < 8: counter-clockwise), ``tied`` (two keys of a point are
    equal: then ``argsort_fans`` must order, and nothing else is computed), and per cell the signed
    area and centroid of ``vertices[refs]`` (bits of ``areas_centroids``) and the bounding box."""
    count = offsets.shape[0] - 1
    refs, key = np.empty_like(corner_tri), np.empty(129)
    area, centroid = np.empty(count), np.empty((count, 2))
    lo, hi = np.empty((count, 2)), np.empty((count, 2))
    for p in range(count):
        s, n = offsets[p], offsets[p + 1] - offsets[p]
        if n > 129:  # (never in a Voronoi diagram) numpy sums a long polygon by halves
            return refs, True, area, centroid, lo, hi
        for i in range(n):
            key[i] = p * 8.0 + angle[s + i]
        for i in range(n):  # a corner's place in its fan: the number of smaller keys (no branches)
            smaller = equal = 0
            for j in range(n):
                smaller += key[j] < key[i]
                equal += key[j] == key[i]
            if equal > 1:
                return refs, True, area, centroid, lo, hi
            refs[s + smaller] = corner_tri[s + i]
    work = np.empty((3, 129))
    for p in range(count):  # a second pass: no branch mispredicted between the vertex loads
        s, e = offsets[p], offsets[p + 1]
        if e - s <= 8:
            area[p], centroid[p, 0], centroid[p, 1] = area_centroid_few(vertices, refs, s, e)
        else:
            area[p], centroid[p, 0], centroid[p, 1] = area_centroid_many(vertices, refs, s, e, work)
        lx = hx = vertices[refs[s], 0]
        ly = hy = vertices[refs[s], 1]
        for i in range(s + 1, e):
            x, y = vertices[refs[i], 0], vertices[refs[i], 1]
            lx, hx, ly, hy = min(lx, x), max(hx, x), min(ly, y), max(hy, y)
        lo[p, 0], lo[p, 1], hi[p, 0], hi[p, 1] = lx, ly, hx, hy
    return refs, False, area, centroid, lo, hi


@numba.njit(cache=True)
def boxes_meet_segments(lo, hi, seg_lo, seg_hi, origin, inv, g):
    """Which boxes [lo, hi] overlap the bounding box of some segment (grid bins of 1/inv)."""
    boxes = segment_bins(seg_lo, seg_hi, origin, inv, g)
    ptr, items = bin_boxes(boxes, g)
    out = np.zeros(lo.shape[0], dtype=np.bool_)
    for c in range(lo.shape[0]):
        i0, i1 = grid_index(lo[c, 0], origin[0], inv, g), grid_index(hi[c, 0], origin[0], inv, g)
        j0, j1 = grid_index(lo[c, 1], origin[1], inv, g), grid_index(hi[c, 1], origin[1], inv, g)
        for j in range(j0, j1 + 1):
            for i in range(i0, i1 + 1):
                for t in range(ptr[j * g + i], ptr[j * g + i + 1]):
                    s = items[t]
                    if (
                        seg_lo[s, 0] <= hi[c, 0]
                        and lo[c, 0] <= seg_hi[s, 0]
                        and seg_lo[s, 1] <= hi[c, 1]
                        and lo[c, 1] <= seg_hi[s, 1]
                    ):
                        out[c] = True
    return out


@numba.njit(cache=True)
def grid_index(x, origin, inv, g):
    """The bin (0..g-1, clamped) of coordinate x; monotone in x."""
    return min(max(int((x - origin) * inv), 0), g - 1)


@numba.njit(cache=True)
def segment_bins(seg_lo, seg_hi, origin, inv, g):
    """The bin boxes (i0, i1, j0, j1) of the segments' bounding boxes (for ``bin_boxes``)."""
    boxes = np.empty((seg_lo.shape[0], 4), dtype=np.int64)
    for s in range(seg_lo.shape[0]):
        for d in range(2):
            boxes[s, 2 * d] = grid_index(seg_lo[s, d], origin[d], inv, g)
            boxes[s, 2 * d + 1] = grid_index(seg_hi[s, d], origin[d], inv, g)
    return boxes


@numba.njit(cache=True)
def all_vertices_in(offsets, refs, cells, vertex_in):
    """For each of ``cells``: are all its vertices ``vertex_in``?"""
    out = np.ones(cells.shape[0], dtype=np.bool_)
    for c in range(cells.shape[0]):
        for i in range(offsets[cells[c]], offsets[cells[c] + 1]):
            if not vertex_in[refs[i]]:
                out[c] = False
                break
    return out
