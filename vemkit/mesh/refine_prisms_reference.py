"""The cell-by-cell twins of the prisms' Numba kernels (``refine_prisms_kernels``): the plan, the
whole sides and the children of one marked prism at a time, as ``refine_prisms`` made them before its
kernels (``tests/mesh3d/test_refine_polyhedra.py`` pins the kernels to them).
"""

from __future__ import annotations

import numpy as np

from vemkit.exceptions import MeshError
from vemkit.mesh import refine_prisms
from vemkit.mesh.refine_prisms import _centroid_weights
from vemkit.mesh.refine_tetrahedra import TOL, _on_edges, plane_labels


def _newell(x, ids):
    """The normal (times twice the area) of the polygon x[ids] by Newell's formula."""
    p, q = x[ids], x[np.append(ids[1:], ids[0])]
    return np.array(
        [
            ((p[:, 1] - q[:, 1]) * (p[:, 2] + q[:, 2])).sum(),
            ((p[:, 2] - q[:, 2]) * (p[:, 0] + q[:, 0])).sum(),
            ((p[:, 0] - q[:, 0]) * (p[:, 1] + q[:, 1])).sum(),
        ]
    )


def prism_corners(mesh, c: int):
    """(bottom corners, top corners) of cell c, counter-clockwise from +z and matched, or None when
    it is not a prism along z over a convex polygon."""
    signed = mesh.cell_face_list(c)
    faces = np.where(signed >= 0, signed, -signed - 1)
    normals = mesh.face_vector_areas[faces] * np.where(signed >= 0, 1.0, -1.0)[:, None]
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    planes = plane_labels(normals)
    caps = np.abs(normals[:, 2]) > 1 - 1e-9
    if np.abs(normals[~caps, 2]).max(initial=0) > 1e-9 or np.unique(planes[caps]).size != 2:
        return None
    on = {}
    for f, plane in zip(faces, planes):
        for v in mesh.face(f).tolist():
            on.setdefault(v, set()).add(int(plane))
    corners = np.array([v for v, p in on.items() if len(p) >= 3])
    x = mesh.vertices[corners]
    low = x[:, 2] < x[:, 2].mean()
    bottom, top = corners[low], corners[~low]
    if bottom.size < 3 or bottom.size != top.size:
        return None
    centre = mesh.vertices[bottom, :2].mean(axis=0)
    bottom = bottom[np.argsort(np.arctan2(*(mesh.vertices[bottom, :2] - centre).T[::-1]))]
    match = np.linalg.norm(mesh.vertices[top, None, :2] - mesh.vertices[None, bottom, :2], axis=2).argmin(axis=0)
    top = top[match]
    p = mesh.vertices[bottom, :2]
    e, f = np.roll(p, -1, axis=0) - p, np.roll(p, -2, axis=0) - np.roll(p, -1, axis=0)
    turn = e[:, 0] * f[:, 1] - e[:, 1] * f[:, 0]
    if (turn <= 0).any() or np.unique(match).size != top.size:
        return None
    return bottom, top


def _check_lateral_faces(mesh, c: int, b, t, tol: float) -> None:
    """Every lateral face of a marked prism is a whole side or lies in one half of its depth."""
    zm = 0.5 * (mesh.vertices[b, 2].mean() + mesh.vertices[t, 2].mean())
    corners = set(b.tolist()) | set(t.tolist())
    for s in mesh.cell_face_list(c).tolist():
        face = mesh.face(s if s >= 0 else -s - 1)
        z = mesh.vertices[face, 2]
        if z.min() < zm - tol and z.max() > zm + tol and np.ptp(z) > 0 and len(corners.intersection(face.tolist())) < 4:
            raise MeshError(
                f"cell {c} has a lateral face across its mid-depth without being a whole side (the hanging "
                "vertices of an extruded mesh with hanging nodes); 3D refinement splits prisms whose lateral faces "
                "are whole sides or lie in one half of the depth"
            )


def plan_prisms_reference(mesh, cells: np.ndarray, refinable: str, curves=None):
    """``refine_prisms.plan_prisms``, cell by cell (its twin)."""
    n, vertices = mesh.n_vertices, mesh.vertices
    offsets, ids = mesh.cell_vertex_lists
    new_of, points, sources, lattices, extra, inner = {}, [], [], [], {}, 0
    for c in cells.tolist():
        found = prism_corners(mesh, c)
        if found is None:
            raise MeshError(
                f"cell {c} of the {mesh.meta.get('family', 'given')} mesh is not an axis-aligned box, a tetrahedron "
                f"or a prism along z over a convex polygon; 3D refinement splits the cells of the families {refinable}"
            )
        b, t = found
        m = b.size
        own = ids[offsets[c] : offsets[c + 1]]
        size = np.ptp(vertices[own], axis=0).max()
        _check_lateral_faces(mesh, c, b, t, TOL * size)
        nb, nt = np.roll(b, -1), np.roll(t, -1)
        groups = [[b[i], t[i]] for i in range(m)] + [[b[i], nb[i]] for i in range(m)]
        groups += [[t[i], nt[i]] for i in range(m)] + [[b[i], nb[i], t[i], nt[i]] for i in range(m)]
        groups += [list(b), list(t), list(b) + list(t) + [-1 - c]]
        row = list(b) + list(t)
        for k, group in enumerate(groups):
            real = [g for g in group if g >= 0]
            weights = np.full(len(real), 1.0 / len(real))
            if k >= 4 * m:  # a centroid: of a cap, or between the caps
                w = _centroid_weights(vertices[real[:m], :2])
                weights = w if len(real) == m else np.concatenate([w, w]) / 2
            point = weights @ vertices[real]
            near = own[np.linalg.norm(vertices[own] - point, axis=1) < TOL * size]
            key = tuple(sorted(group))
            if near.size:
                row.append(int(near[0]))
                continue
            if key not in new_of:
                new_of[key] = n + len(points)
                points.append(point)
                sources.append((np.array([new_of[key]]), np.array([real]), weights[None, :]))
            row.append(new_of[key])
        lattices.append(np.array(row, dtype=np.int64))
        inner += 3 * m
        for key, pieces in ((tuple(sorted([b[i], nb[i], t[i], nt[i]])), 4) for i in range(m)):
            extra[key] = pieces - 1
        extra[tuple(sorted(b))] = extra[tuple(sorted(t))] = m - 1
    edges = np.array([k for k in new_of if len(k) == 2], dtype=np.int64).reshape(-1, 2)
    mids = np.array([new_of[tuple(k)] for k in edges.tolist()], dtype=np.int64)
    keys = edges[:, 0] * np.int64(n) + edges[:, 1]
    order = np.argsort(keys)
    added = sum(v for k, v in extra.items() if tuple(k) in new_of)  # a whole side has a new centre
    points = refine_prisms._onto_curves(mesh, cells, lattices, np.array(points).reshape(-1, 3), curves)
    return lattices, points, sources, (keys[order], mids[order]), added, inner


def _ring(m: int, level: int, i: int) -> list:
    """Lattice positions of Q_i (c_i, s_i, z, s_{i-1}) at level 0 (bottom), 1 (mid-depth) or 2 (top)."""
    corner, mid, centre = [(0, 3 * m, 6 * m), (2 * m, 5 * m, 6 * m + 2), (m, 4 * m, 6 * m + 1)][level]
    return [corner + i, mid + i, centre, mid + (i - 1) % m]


def _oriented(x, ids, direction):
    return ids if _newell(x, ids) @ direction > 0 else ids[::-1]


def split_prism_sides(mesh, lattice, cell: int, face_offsets, face_vertices, x):
    """(face, pieces as stored) of the sides of a marked prism that are one face."""
    m = (lattice.size - 3) // 6
    signed = mesh.cell_face_list(cell)
    faces = np.where(signed >= 0, signed, -signed - 1)
    cycles = [face_vertices[face_offsets[f] : face_offsets[f + 1]] for f in faces]
    pool = np.union1d(np.concatenate(cycles), lattice)
    for f, cycle in zip(faces.tolist(), cycles):
        if np.isin(lattice[:m], cycle).all():
            pieces = [_ring(m, 0, i) for i in range(m)]
        elif np.isin(lattice[m : 2 * m], cycle).all():
            pieces = [_ring(m, 2, i) for i in range(m)]
        else:
            i = next(
                (i for i in range(m) if np.isin(lattice[[i, (i + 1) % m, m + i, m + (i + 1) % m]], cycle).all()), None
            )
            if i is None:
                continue
            j = (i + 1) % m
            B, T, V, SB, ST, SM = (k * m for k in range(6))
            pieces = [[B + i, SB + i, SM + i, V + i], [SB + i, B + j, V + j, SM + i]]
            pieces += [[SM + i, V + j, T + j, ST + i], [V + i, SM + i, ST + i, T + i]]
        direction = mesh.face_vector_areas[f]
        yield f, [_on_edges(_oriented(x, lattice[p], direction), pool, x) for p in pieces]


def prism_children(mesh, lattice, cycles: list, labels, x):
    """The outward faces and labels of the 2m children of a marked prism; ``cycles``: its (face,
    outward cycle) with its whole sides already split."""
    m = (lattice.size - 3) // 6
    pool = np.union1d(np.concatenate([cycle for _, cycle in cycles]), lattice)
    centres = np.array([x[cycle].mean(axis=0) for _, cycle in cycles])
    size = np.ptp(x[lattice], axis=0).max()
    upper = centres[:, 2] > x[lattice[6 * m + 2], 2]
    out = []
    for layer in (0, 1):
        for i in range(m):
            low, high = _ring(m, layer, i), _ring(m, layer + 1, i)
            q = x[lattice[_ring(m, 0, i)], :2]
            d, r = np.roll(q, -1, axis=0) - q, centres[:, None, :2] - q[None]
            cross = d[None, :, 0] * r[:, :, 1] - d[None, :, 1] * r[:, :, 0]
            mine = np.flatnonzero((cross > -TOL * size * size).all(axis=1) & (upper == bool(layer)))
            faces = [cycles[k][1] for k in mine]
            face_labels = [labels[cycles[k][0]] for k in mine]
            child_centre = x[lattice[low + high]].mean(axis=0)
            polygons = [] if layer == 0 else [low]
            polygons += [] if layer == 1 else [high]
            polygons += [[low[k], low[k + 1], high[k + 1], high[k]] for k in (1, 2)]
            for polygon in polygons:
                ids = lattice[polygon]
                faces.append(_on_edges(_oriented(x, ids, x[ids].mean(axis=0) - child_centre), pool, x))
                face_labels.append(-1)
            out.append((faces, face_labels))
    return out
