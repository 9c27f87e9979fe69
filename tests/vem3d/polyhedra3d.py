"""Small polyhedral meshes for the 3D element's tests, built by hand with ``from_polyhedra``: box
grids (a hanging-node configuration among them), cubes split into tetrahedra, an L-shaped prism
(non-convex), convex hulls of random points; and random affine maps of them."""

from __future__ import annotations

import itertools

import numpy as np
from scipy.spatial import ConvexHull

from vemkit.mesh.polyhedral import from_polyhedra

SIDES = ("left", "right", "front", "back", "bottom", "top")  # xmin, xmax, ymin, ymax, zmin, zmax


def _rectangle_face(points, lo, hi, axis, outward):
    """The vertices (indices into points) on the boundary of the axis-aligned rectangle [lo, hi]
    (lo[axis] == hi[axis]), ordered counter-clockwise about the outward normal sign * e_axis."""
    u, v = (axis + 1) % 3, (axis + 2) % 3  # e_u x e_v = e_axis
    if outward < 0:
        u, v = v, u
    tol = 1e-9
    inside = np.all((points >= lo - tol) & (points <= hi + tol), axis=1)
    on_edge = inside & (
        (np.abs(points[:, u] - lo[u]) < tol)
        | (np.abs(points[:, u] - hi[u]) < tol)
        | (np.abs(points[:, v] - lo[v]) < tol)
        | (np.abs(points[:, v] - hi[v]) < tol)
    )
    ids = np.flatnonzero(on_edge)
    centre = 0.5 * (lo + hi)
    angle = np.arctan2(points[ids, v] - centre[v], points[ids, u] - centre[u])
    return [int(i) for i in ids[np.argsort(angle)]]


def box_cell(points, lo, hi, split=()):
    """The outward faces of the box [lo, hi]: every mesh vertex on a face's boundary is a vertex of
    it (hanging nodes); the faces named in ``split`` ((axis, side) pairs) are four faces each."""
    faces = []
    for axis, side in itertools.product(range(3), (0, 1)):
        a, b = lo.copy(), hi.copy()
        if side == 0:
            b[axis] = lo[axis]
        else:
            a[axis] = hi[axis]
        pieces = [(a, b)]
        if (axis, side) in split:
            mid = 0.5 * (a + b)
            u, v = [k for k in range(3) if k != axis]
            pieces = []
            for cu, cv in itertools.product((0, 1), (0, 1)):
                pa, pb = a.copy(), b.copy()
                pa[u], pb[u] = (a[u], mid[u]) if cu == 0 else (mid[u], b[u])
                pa[v], pb[v] = (a[v], mid[v]) if cv == 0 else (mid[v], b[v])
                pieces.append((pa, pb))
        for pa, pb in pieces:
            faces.append(_rectangle_face(points, pa, pb, axis, 1 if side else -1))
    return faces


def _unique_points(boxes):
    corners = np.array(
        [
            [(b[0] if s == 0 else b[1])[k] for k, s in enumerate(bits)]
            for b in boxes
            for bits in itertools.product((0, 1), repeat=3)
        ]
    )
    return np.unique(np.round(corners, 12), axis=0)


def _boundary(points, cells, box):
    """Boundary faces by side: faces with all vertices on a face of the bounding box."""
    lo, hi = np.asarray(box[0], float), np.asarray(box[1], float)
    parts = {s: [] for s in SIDES}
    for faces in cells:
        for face in faces:
            p = points[face]
            for k, (axis, val) in enumerate([(a, (lo, hi)[s][a]) for a in range(3) for s in (0, 1)]):
                if np.all(np.abs(p[:, axis] - val) < 1e-9):
                    parts[SIDES[k]].append(face)
    return parts


def boxes_mesh(boxes, splits=None):
    points = _unique_points(boxes)
    splits = splits or {}
    cells = [
        box_cell(points, np.asarray(b[0], float), np.asarray(b[1], float), splits.get(i, ()))
        for i, b in enumerate(boxes)
    ]
    lo, hi = np.min([b[0] for b in boxes], axis=0), np.max([b[1] for b in boxes], axis=0)
    return from_polyhedra(points, cells, _boundary(points, cells, (lo, hi)))


def hex_grid(n, size=(1.0, 1.0, 1.0)):
    """n^3 boxes on [0, size] (``box_cell``'s faces, their vertices found among the box's corners)."""
    h = np.asarray(size, float) / n
    grid = np.array(list(itertools.product(range(n + 1), repeat=3)))
    points = grid * h
    number = lambda ijk: (ijk[0] * (n + 1) + ijk[1]) * (n + 1) + ijk[2]  # noqa: E731
    cells = []
    for ijk in itertools.product(range(n), repeat=3):
        corner_ids = [number(np.array(ijk) + bits) for bits in itertools.product((0, 1), repeat=3)]
        local = box_cell(points[corner_ids], np.array(ijk) * h, (np.array(ijk) + 1) * h)
        cells.append([[corner_ids[v] for v in face] for face in local])
    return from_polyhedra(points, cells, _boundary(points, cells, (np.zeros(3), np.asarray(size, float))))


def hanging_mesh():
    """A unit cube next to eight cubes of size 1/2 on [1, 2] x [0, 1]^2: its face x = 1 is four
    faces, its four faces around it are pentagons (a hanging node on an edge), and the centre of
    the face x = 1 is a hanging node too."""
    boxes = [(np.zeros(3), np.ones(3))]
    for ijk in itertools.product((0, 1), repeat=3):
        lo = np.array([1.0, 0.0, 0.0]) + 0.5 * np.array(ijk)
        boxes.append((lo, lo + 0.5))
    return boxes_mesh(boxes, {0: ((0, 1),)})


def _oriented(points, faces, inside):
    """The triangles/polygons ``faces`` turned to point away from the point ``inside``."""
    out = []
    for f in faces:
        p = points[list(f)]
        normal = np.cross(p[1] - p[0], p[2] - p[0])
        out.append(list(f) if normal @ (p[0] - inside) > 0 else list(f)[::-1])
    return out


def tet_grid(n):
    """n^3 cubes on the unit cube, each split into six tetrahedra (Kuhn: one per permutation of
    the axes, conforming across the cubes)."""
    grid = np.array(list(itertools.product(range(n + 1), repeat=3)), float) / n
    index = {tuple(np.round(p * n).astype(int)): i for i, p in enumerate(grid)}
    cells, tets = [], []
    for ijk in itertools.product(range(n), repeat=3):
        for perm in itertools.permutations(range(3)):
            corner = np.array(ijk)
            ids = [index[tuple(corner)]]
            for axis in perm:
                corner = corner.copy()
                corner[axis] += 1
                ids.append(index[tuple(corner)])
            tets.append(ids)
            faces = [[ids[a] for a in range(4) if a != skip] for skip in range(4)]
            cells.append(_oriented(grid, faces, grid[ids].mean(axis=0)))
    return from_polyhedra(grid, cells, _boundary(grid, cells, (np.zeros(3), np.ones(3)))), np.array(tets)


def prism_faces(m, bottom_ids, top_ids):
    """The outward faces of a prism over a counter-clockwise polygon (its m bottom and top vertices)."""
    faces = [list(bottom_ids[::-1]), list(top_ids)]
    for i in range(m):
        j = (i + 1) % m
        faces.append([bottom_ids[i], bottom_ids[j], top_ids[j], top_ids[i]])
    return faces


def l_prism(height=1.0):
    """One non-convex cell: the prism over the L-shaped hexagon [0,2]^2 minus [1,2]^2."""
    base = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], float)
    return star_prism(base, height)


def star_prism(base, height=1.0):
    m = base.shape[0]
    points = np.vstack([np.c_[base, np.zeros(m)], np.c_[base, np.full(m, height)]])
    return from_polyhedra(points, [prism_faces(m, list(range(m)), list(range(m, 2 * m)))])


def random_hull(rng, n=12):
    """The convex hull of n random points: one cell with triangular faces."""
    points = rng.standard_normal((n, 3))
    hull = ConvexHull(points)
    used = np.unique(hull.simplices)
    renumber = {int(v): k for k, v in enumerate(used)}
    pts = points[used]
    faces = [[renumber[int(v)] for v in s] for s in hull.simplices]
    return from_polyhedra(pts, [_oriented(pts, faces, pts.mean(axis=0))])


def random_star_prism(rng, m=7):
    """A prism over a random star-shaped (often non-convex) polygon."""
    angle = np.sort(rng.uniform(0, 2 * np.pi, m))
    radius = rng.uniform(0.3, 1.0, m)
    return star_prism(np.c_[radius * np.cos(angle), radius * np.sin(angle)], rng.uniform(0.3, 1.5))


def mapped(mesh, A, b):
    """The image of a mesh under x -> A x + b (det A > 0): planar faces stay planar."""
    from vemkit.mesh.polyhedral import PolyhedralMesh

    return PolyhedralMesh(
        mesh.vertices @ np.asarray(A).T + b,
        mesh.face_offsets,
        mesh.face_vertices,
        mesh.cell_offsets,
        mesh.cell_faces,
        mesh.boundary,
        mesh.meta,
    )


def random_affine(rng):
    A = np.eye(3) + 0.4 * rng.standard_normal((3, 3))
    if np.linalg.det(A) < 0:
        A[:, 0] *= -1
    return A, rng.standard_normal(3)


def l_stack(layers=3):
    """The box [0, 2]^2 x [0, layers], each layer a non-convex L-shaped prism and the cube that
    fills its notch; the vertices (1, 1, z) between the layers are interior."""
    base = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2], [2, 2]], float)
    points = np.vstack([np.c_[base, np.full(7, z)] for z in range(layers + 1)])
    cells = []
    for k in range(layers):
        lo, hi = 7 * k, 7 * (k + 1)
        ell = [0, 1, 2, 3, 4, 5]
        cube = [3, 2, 6, 4]
        cells.append(prism_faces(6, [lo + i for i in ell], [hi + i for i in ell]))
        cells.append(prism_faces(4, [lo + i for i in cube], [hi + i for i in cube]))
    return from_polyhedra(points, cells, _boundary(points, cells, ((0, 0, 0), (2, 2, layers))))


def boundary_vertices(mesh):
    """The vertices of the boundary faces."""
    return np.unique(np.concatenate([mesh.face(f) for f in mesh.boundary_faces]))
