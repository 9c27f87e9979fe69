"""Numba kernels of the refinement of prisms (``refine_prisms``), one loop over the marked prisms each.

``prisms_plan`` finds every marked prism's corners and the vertices its lattice points name (the
vertex there already, or the group of corners naming a new one), ``prisms_sides`` splits the whole
sides (a cap into the m quadrilaterals Q_i, a lateral side into 4 quarters) and ``prisms_children``
makes the faces of the 2m children. Their twins are the cell-by-cell functions of
``refine_prisms_reference`` (``tests/mesh3d/test_refine_polyhedra.py`` pins the kernels to them).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from vemkit.mesh.refine_polyhedra_kernels import grown, insert_on_edges


@numba.njit(cache=True)
def _turned(ids, direction, x):
    """The polygon ``ids``, reversed when its normal (Newell's) points against ``direction``."""
    n = ids.shape[0]
    normal = np.zeros(3)
    for k in range(n):
        p, q = x[ids[k]], x[ids[(k + 1) % n]]
        normal[0] += (p[1] - q[1]) * (p[2] + q[2])
        normal[1] += (p[2] - q[2]) * (p[0] + q[0])
        normal[2] += (p[0] - q[0]) * (p[1] + q[1])
    return ids if normal @ direction > 0 else ids[::-1].copy()


@numba.njit(cache=True)
def _ring(m, level, i):
    """Lattice positions of Q_i (c_i, s_i, z, s_{i-1}) of a prism at level 0 (bottom), 1 (mid-depth), 2 (top)."""
    corner, mid, centre = (
        (0, 3 * m, 6 * m) if level == 0 else ((2 * m, 5 * m, 6 * m + 2) if level == 1 else (m, 4 * m, 6 * m + 1))
    )
    return np.array([corner + i, mid + i, centre, mid + (i - 1 + m) % m])


@numba.njit(cache=True)
def _pool(parts_offsets, parts, first, last, lattice):
    """The sorted distinct vertices of the cycles first ... last - 1 and of ``lattice``."""
    n = parts_offsets[last] - parts_offsets[first]
    gathered = np.empty(n + lattice.shape[0], np.int64)
    gathered[:n] = parts[parts_offsets[first] : parts_offsets[last]]
    gathered[n:] = lattice
    return np.unique(gathered)


@numba.njit(cache=True)
def prisms_children(lattice_offsets, lattices, row_start, cycle_offsets, cycle_vertices, x, tol):
    """The children of the marked prisms (``refine_prisms``): per face of a child, child by child (Q_i
    below mid-depth, then above), (row, child, the parent's cycle it is, or -1 for a new face), and the
    new faces' (sizes, flat vertices). Per row r: its lattice (``lattice_offsets``, ``lattices``:
    6 m + 3 points) and its outward cycles row_start[r] ... (whole sides split)."""
    rows, kids, sources = np.empty(0, np.int64), np.empty(0, np.int64), np.empty(0, np.int64)
    sizes, flat = np.empty(0, np.int64), np.empty(0, np.int64)
    n_app, n_new, n_flat = 0, 0, 0
    for r in range(row_start.shape[0] - 1):
        lattice = lattices[lattice_offsets[r] : lattice_offsets[r + 1]]
        m = (lattice.shape[0] - 3) // 6
        c0, c1 = row_start[r], row_start[r + 1]
        pool = _pool(cycle_offsets, cycle_vertices, c0, c1, lattice)
        centres = np.zeros((c1 - c0, 3))
        for c in range(c0, c1):
            for i in range(cycle_offsets[c], cycle_offsets[c + 1]):
                centres[c - c0] += x[cycle_vertices[i]]
            centres[c - c0] /= cycle_offsets[c + 1] - cycle_offsets[c]
        size = 0.0
        for axis in range(3):
            size = max(size, x[lattice, axis].max() - x[lattice, axis].min())
        middle = x[lattice[6 * m + 2], 2]
        need = n_app + 2 * m * (c1 - c0 + 3)
        rows, kids, sources = grown(rows, need), grown(kids, need), grown(sources, need)
        sizes = grown(sizes, n_new + 6 * m)
        flat = grown(flat, n_flat + 6 * m * (4 + pool.shape[0]))
        for layer in range(2):
            for i in range(m):
                child = layer * m + i
                low, high = _ring(m, layer, i), _ring(m, layer + 1, i)
                q = x[lattice[_ring(m, 0, i)], :2]
                for c in range(c1 - c0):
                    if (centres[c, 2] > middle) != (layer == 1):
                        continue
                    inside = True
                    for k in range(4):
                        d = q[(k + 1) % 4] - q[k]
                        if not d[0] * (centres[c, 1] - q[k, 1]) - d[1] * (centres[c, 0] - q[k, 0]) > -tol * size * size:
                            inside = False
                    if inside:
                        rows[n_app], kids[n_app], sources[n_app] = r, child, c0 + c
                        n_app += 1
                centre = np.zeros(3)
                for k in range(4):
                    centre += x[lattice[low[k]]] + x[lattice[high[k]]]
                centre /= 8.0
                polygons = np.empty((3, 4), np.int64)
                polygons[0] = low if layer == 1 else high
                for k in (1, 2):
                    polygons[k] = np.array([low[k], low[k + 1], high[k + 1], high[k]])
                for p in range(3):
                    ids = lattice[polygons[p]]
                    away = (x[ids[0]] + x[ids[1]] + x[ids[2]] + x[ids[3]]) / 4.0 - centre
                    end = insert_on_edges(_turned(ids, away, x), pool, x, tol, flat, n_flat)
                    sizes[n_new] = end - n_flat
                    n_flat, n_new = end, n_new + 1
                    rows[n_app], kids[n_app], sources[n_app] = r, child, -1
                    n_app += 1
    return rows[:n_app], kids[:n_app], sources[:n_app], sizes[:n_new], flat[:n_flat]


@numba.njit(cache=True)
def _all_in(wanted, cycle):
    for v in wanted:
        found = False
        for w in cycle:
            if w == v:
                found = True
                break
        if not found:
            return False
    return True


@numba.njit(cache=True)
def _side_pieces(lattice, m, cycle):
    """The pieces (lattice positions, 4 per row) of the whole side ``cycle`` of a prism: the m Q_i of
    a cap, or the 4 quarters of a lateral side; no rows when it is not a whole side."""
    if _all_in(lattice[:m], cycle) or _all_in(lattice[m : 2 * m], cycle):
        level = 0 if _all_in(lattice[:m], cycle) else 2
        out = np.empty((m, 4), np.int64)
        for i in range(m):
            out[i] = _ring(m, level, i)
        return out
    for i in range(m):
        j = (i + 1) % m
        if _all_in(np.array([lattice[i], lattice[j], lattice[m + i], lattice[m + j]]), cycle):
            B, T, V, SB, ST, SM = 0, m, 2 * m, 3 * m, 4 * m, 5 * m
            return np.array(
                [
                    [B + i, SB + i, SM + i, V + i],
                    [SB + i, B + j, V + j, SM + i],
                    [SM + i, V + j, T + j, ST + i],
                    [V + i, SM + i, ST + i, T + i],
                ]
            )
    return np.empty((0, 4), np.int64)


@numba.njit(cache=True)
def prisms_sides(lattice_offsets, lattices, cell_start, faces, face_offsets, face_vertices, face_normals, x, tol):
    """The whole sides of the marked prisms (``refine_prisms_reference.split_prism_sides``): per side (row,
    face, number of pieces), row after row, and the pieces' (sizes, flat vertices), as stored (turned
    along ``face_normals``) with the vertices of the cell inside their edges."""
    rows, found, counts = np.empty(0, np.int64), np.empty(0, np.int64), np.empty(0, np.int64)
    sizes, flat = np.empty(0, np.int64), np.empty(0, np.int64)
    n_side, n_piece, n_flat = 0, 0, 0
    for r in range(cell_start.shape[0] - 1):
        lattice = lattices[lattice_offsets[r] : lattice_offsets[r + 1]]
        m = (lattice.shape[0] - 3) // 6
        f0, f1 = cell_start[r], cell_start[r + 1]
        total = lattice.shape[0]
        for f in faces[f0:f1]:
            total += face_offsets[f + 1] - face_offsets[f]
        gathered = np.empty(total, np.int64)
        gathered[: lattice.shape[0]] = lattice
        k = lattice.shape[0]
        for f in faces[f0:f1]:
            n = face_offsets[f + 1] - face_offsets[f]
            gathered[k : k + n] = face_vertices[face_offsets[f] : face_offsets[f + 1]]
            k += n
        pool = np.unique(gathered)
        need = n_side + f1 - f0
        rows, found, counts = grown(rows, need), grown(found, need), grown(counts, need)
        sizes = grown(sizes, n_piece + (f1 - f0) * max(m, 4))
        flat = grown(flat, n_flat + (f1 - f0) * max(m, 4) * (4 + pool.shape[0]))
        for f in faces[f0:f1]:
            pieces = _side_pieces(lattice, m, face_vertices[face_offsets[f] : face_offsets[f + 1]])
            if pieces.shape[0] == 0:
                continue
            for p in range(pieces.shape[0]):
                end = insert_on_edges(_turned(lattice[pieces[p]], face_normals[f], x), pool, x, tol, flat, n_flat)
                sizes[n_piece] = end - n_flat
                n_flat, n_piece = end, n_piece + 1
            rows[n_side], found[n_side], counts[n_side] = r, f, pieces.shape[0]
            n_side += 1
    return rows[:n_side], found[:n_side], counts[:n_side], sizes[:n_piece], flat[:n_flat]


@numba.njit(cache=True)
def _plane_labels(normals):
    """``refine_tetrahedra.plane_labels``: the first face without a plane starts the next one."""
    labels = np.full(normals.shape[0], -1, np.int64)
    count = 0
    for k in range(normals.shape[0]):
        if labels[k] < 0:
            for j in range(normals.shape[0]):
                if labels[j] < 0 and normals[j] @ normals[k] > 1 - 1e-9:
                    labels[j] = count
            count += 1
    return labels, count


@numba.njit(cache=True)
def _prism_corners(faces, normals, face_offsets, face_vertices, x):
    """(bottom, top) corners of a cell (``refine_prisms_reference.prism_corners``), or empty arrays."""
    none = np.empty(0, np.int64)
    labels, count = _plane_labels(normals)
    cap_planes = np.zeros(count, np.bool_)
    for k in range(faces.shape[0]):
        if abs(normals[k, 2]) > 1 - 1e-9:
            cap_planes[labels[k]] = True
        elif abs(normals[k, 2]) > 1e-9:
            return none, none
    if cap_planes.sum() != 2:
        return none, none
    total = 0
    for f in faces:
        total += face_offsets[f + 1] - face_offsets[f]
    seen = np.empty(total, np.int64)
    on = np.zeros((total, count), np.bool_)
    n_seen = 0
    for k in range(faces.shape[0]):
        for v in face_vertices[face_offsets[faces[k]] : face_offsets[faces[k] + 1]]:
            at = 0
            while at < n_seen and seen[at] != v:
                at += 1
            if at == n_seen:
                seen[at] = v
                n_seen += 1
            on[at, labels[k]] = True
    corners = seen[:n_seen][on[:n_seen].sum(axis=1) >= 3]
    z = x[corners, 2]
    low = z < z.mean()
    bottom, top = corners[low], corners[~low]
    if bottom.shape[0] < 3 or bottom.shape[0] != top.shape[0]:
        return none, none
    centre = np.zeros(2)
    for v in bottom:
        centre += x[v, :2]
    centre /= bottom.shape[0]
    angle = np.array([math.atan2(x[v, 1] - centre[1], x[v, 0] - centre[0]) for v in bottom])
    bottom = bottom[np.argsort(angle)]
    match = np.empty(bottom.shape[0], np.int64)
    for j in range(bottom.shape[0]):
        d = (x[top, 0] - x[bottom[j], 0]) ** 2 + (x[top, 1] - x[bottom[j], 1]) ** 2
        match[j] = np.argmin(d)
    if np.unique(match).shape[0] != top.shape[0]:
        return none, none
    m = bottom.shape[0]
    for i in range(m):
        p, q, r = x[bottom[i], :2], x[bottom[(i + 1) % m], :2], x[bottom[(i + 2) % m], :2]
        if (q[0] - p[0]) * (r[1] - q[1]) - (q[1] - p[1]) * (r[0] - q[0]) <= 0:
            return none, none
    return bottom, top[match]


@numba.njit(cache=True)
def _cap_centroid(ids, x):
    """The area centroid (xy) of the convex polygon x[ids] by the fan from its first corner."""
    area, cx, cy = 0.0, 0.0, 0.0
    for i in range(1, ids.shape[0] - 1):
        a, b, c = x[ids[0]], x[ids[i]], x[ids[i + 1]]
        w = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
        area += w
        cx += w * (a[0] + b[0] + c[0]) / 3.0
        cy += w * (a[1] + b[1] + c[1]) / 3.0
    return cx / area, cy / area


@numba.njit(cache=True)
def prisms_plan(cells, cell_start, faces, normals, face_offsets, face_vertices, own_start, own, x, width, tol):
    """The lattices of the marked prisms (``refine_prisms.plan_prisms``), before new points are named:
    per row its status (0, 1 not a prism over a convex polygon, 2 a lateral face across its mid-depth)
    and corners (bottom then top, m each: ``corner_start``), and per lattice point after the corners,
    row by row (V, SB, ST, SM, ZB, ZT, ZM), the vertex of the cell there already or -1, its group's
    vertices sorted (padded with -1 at the end to ``width``; the prism's centroid also names its cell
    as -1 - c) and its kind (0 a pair's midpoint, 1 a lateral side's centre, 2 a cap's, 3 the body's)."""
    m_rows = cells.shape[0]
    status = np.zeros(m_rows, np.int64)
    corner_start = np.zeros(m_rows + 1, np.int64)
    corners = np.empty(0, np.int64)
    near, kind = np.empty(0, np.int64), np.empty(0, np.int64)
    keys = np.empty((0, width), np.int64)
    n_req = 0
    for r in range(m_rows):
        f0, f1 = cell_start[r], cell_start[r + 1]
        b, t = _prism_corners(faces[f0:f1], normals[f0:f1], face_offsets, face_vertices, x)
        mine = own[own_start[r] : own_start[r + 1]]
        m = b.shape[0]
        corner_start[r + 1] = corner_start[r] + 2 * m
        if m == 0:
            status[r] = 1
            continue
        corners = grown(corners, corner_start[r + 1])
        corners[corner_start[r] : corner_start[r] + m] = b
        corners[corner_start[r] + m : corner_start[r + 1]] = t
        size = 0.0
        for axis in range(3):
            size = max(size, x[mine, axis].max() - x[mine, axis].min())
        zm = 0.5 * (x[b, 2].mean() + x[t, 2].mean())
        for f in faces[f0:f1]:
            z = x[face_vertices[face_offsets[f] : face_offsets[f + 1]], 2]
            hits = 0
            for v in face_vertices[face_offsets[f] : face_offsets[f + 1]]:
                hits += (b == v).sum() + (t == v).sum()
            if z.min() < zm - tol * size and z.max() > zm + tol * size and z.max() > z.min() and hits < 4:
                status[r] = 2
        if status[r]:
            continue
        n_new = 4 * m + 3
        near, kind = grown(near, n_req + n_new), grown(kind, n_req + n_new)
        if keys.shape[0] < n_req + n_new:
            bigger = np.empty((max(n_req + n_new, 2 * keys.shape[0]), width), np.int64)
            bigger[: keys.shape[0]] = keys
            keys = bigger
        for k in range(n_new):
            i, j = k % m, (k % m + 1) % m
            group = np.empty(0, np.int64)
            point = np.zeros(3)
            if k < 3 * m:
                group = (
                    np.array([b[i], t[i]])
                    if k < m
                    else (np.array([b[i], b[j]]) if k < 2 * m else np.array([t[i], t[j]]))
                )
                point = 0.5 * (x[group[0]] + x[group[1]])
                kind[n_req] = 0
            elif k < 4 * m:
                group = np.array([b[i], b[j], t[i], t[j]])
                point = 0.25 * (x[b[i]] + x[b[j]] + x[t[i]] + x[t[j]])
                kind[n_req] = 1
            else:
                cap = b if k == 4 * m else t
                cx, cy = _cap_centroid(cap, x)
                point[0], point[1] = cx, cy
                if k < 4 * m + 2:
                    group = cap.copy()
                    point[2] = x[cap, 2].mean()
                    kind[n_req] = 2
                else:
                    group = np.concatenate((np.array([-1 - cells[r]]), b, t))
                    point[2] = zm
                    kind[n_req] = 3
            near[n_req] = -1
            for v in mine:
                d = x[v] - point
                if math.sqrt(d @ d) < tol * size:
                    near[n_req] = v
                    break
            keys[n_req] = -1
            keys[n_req, : group.shape[0]] = np.sort(group)
            n_req += 1
    return status, corner_start, corners[: corner_start[m_rows]], near[:n_req], keys[:n_req], kind[:n_req]
