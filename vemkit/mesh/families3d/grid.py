"""Box meshes on a Cartesian grid (docs/reference/files.md): ``hex`` (n x m x l hexahedra) and ``tet`` (each hexahedron
cut into the 6 Kuhn tetrahedra around its diagonal from the lowest to the highest corner: the same
cut in every box, so neighbouring boxes agree on their shared faces' diagonals; the family ``tet``
with ``kind: structured``, while its default kind, delaunay, is gmsh's: ``gmsh_tet``).

The box is ``[lower, upper]``; its faces x = x0, x = x1, y = y0, y = y1, z = z0, z = z1 are named by
``sides`` (default ``left, right, front, back, bottom, top``). The grid has ``max(1, round(n L))``
cells along an edge of length L (``n`` cells per unit length), or exactly ``shape`` = (nx, ny, nz).

``hex_without_box`` is the hex grid with the cells whose centres lie in a second box ``removed``
left out: with ``removed`` on grid lines, the body box minus that box. ``(-1, 1)^3`` minus
``[0, 1]^3`` is Fichera's corner (three re-entrant edges meeting at a re-entrant vertex); no scene
key makes it, a mesh file does (``vemkit.mesh.ugrid.write_ugrid``, ``config/scenes/3d/fichera.yaml``).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from vemkit.mesh.polyhedral import PolyhedralMesh
from vemkit.mesh.polyhedral_build import from_face_soup, tag_box_faces

UNIT_BOX = ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0))
BOX_SIDES = ("left", "right", "front", "back", "bottom", "top")

#: the cube's corners (bit 0: x, bit 1: y, bit 2: z, in the order 0 1 3 2 4 5 7 6 of the bits) ...
CORNERS = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]])
#: ... and its faces, outward, in the order xmin, xmax, ymin, ymax, zmin, zmax
HEX_FACES = np.array([[0, 4, 7, 3], [1, 2, 6, 5], [0, 1, 5, 4], [3, 7, 6, 2], [0, 3, 2, 1], [4, 5, 6, 7]])
#: the 6 Kuhn tetrahedra: paths 0 -> 6 along the axes in every order
KUHN = np.array([[0, 1, 2, 6], [0, 3, 2, 6], [0, 3, 7, 6], [0, 4, 7, 6], [0, 4, 5, 6], [0, 1, 5, 6]])
#: the faces of a positively oriented tetrahedron (a, b, c, d), outward
TET_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])


def grid_shape(n, box, shape=None) -> tuple:
    """(nx, ny, nz): ``shape`` if given, else max(1, round(n L)) along each edge."""
    if shape is not None:
        shape = tuple(int(s) for s in shape)
        if len(shape) != 3 or min(shape) < 1:
            raise ValueError(f"shape = {shape}: give three cell counts >= 1")
        return shape
    if not n > 0:
        raise ValueError(f"mesh n = {n}: the number of cells per unit length must be > 0")
    lengths = np.subtract(box[1], box[0])
    return tuple(max(1, int(round(float(n) * L))) for L in lengths)


def check_box(box) -> tuple:
    lower, upper = (np.asarray(b, dtype=float) for b in box)
    if lower.shape != (3,) or upper.shape != (3,) or not (upper > lower).all():
        raise ValueError(f"box = {box}: give [[x0, y0, z0], [x1, y1, z1]] with x1 > x0, y1 > y0, z1 > z0")
    return lower, upper


def lattice(shape, box):
    """Vertex coordinates of the (nx+1)(ny+1)(nz+1) grid (x fastest) and the corner ids of every cell."""
    lower, upper = check_box(box)
    nx, ny, nz = shape
    axes = [lower[a] + (upper[a] - lower[a]) * np.arange(s + 1) / s for a, s in enumerate(shape)]
    z, y, x = np.meshgrid(axes[2], axes[1], axes[0], indexing="ij")
    vertices = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    k, j, i = (t.ravel() for t in np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij"))
    c = CORNERS
    ids = ((k[:, None] + c[:, 2]) * (ny + 1) + j[:, None] + c[:, 1]) * (nx + 1) + i[:, None] + c[:, 0]
    return vertices, ids


def hex(n=None, box=UNIT_BOX, sides=BOX_SIDES, shape=None) -> PolyhedralMesh:
    """The grid of hexahedra of the box (module doc)."""
    shape = grid_shape(n, box, shape)
    vertices, ids = lattice(shape, box)
    labels = np.tile(np.arange(6), ids.shape[0])
    mesh = _cells_mesh(vertices, ids, HEX_FACES, labels, tuple(sides), _grid_meta(n, shape, box, family="hex"))
    return _merge_repeated_names(mesh, sides)


def hex_without_box(
    n=None, box=UNIT_BOX, removed=None, sides=BOX_SIDES, removed_side="notch", shape=None
) -> PolyhedralMesh:
    """The hex grid of ``box`` without the cells whose centres lie inside the box ``removed`` (module
    doc); the faces on the planes of ``box`` named by ``sides``, the faces the removal opens by
    ``removed_side``."""
    shape = grid_shape(n, box, shape)
    vertices, ids = lattice(shape, box)
    lower, upper = check_box(removed)
    centres = vertices[ids].mean(axis=1)
    kept = ids[~((centres > lower) & (centres < upper)).all(axis=1)]
    used, corners = np.unique(kept, return_inverse=True)
    meta = _grid_meta(n, shape, box, family="hex", removed=np.asarray(removed, float).tolist())
    mesh = _cells_mesh(vertices[used], corners.reshape(kept.shape), HEX_FACES, None, (), meta)
    mesh = tag_box_faces(mesh, *check_box(box), tuple(sides))
    named = np.concatenate([np.zeros(0, np.int64), *mesh.boundary.values()])
    opened = np.setdiff1d(mesh.boundary_faces, named)
    return replace(mesh, boundary={**mesh.boundary, removed_side: opened})


def tet(n=None, box=UNIT_BOX, sides=BOX_SIDES, shape=None) -> PolyhedralMesh:
    """The Kuhn tetrahedra of the grid of the box: 6 per hexahedron (module doc)."""
    shape = grid_shape(n, box, shape)
    vertices, ids = lattice(shape, box)
    tets = ids[:, KUHN].reshape(-1, 4)
    p = vertices[tets]
    det = np.einsum("ij,ij->i", p[:, 1] - p[:, 0], np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]))
    tets[det < 0] = tets[det < 0][:, [0, 2, 1, 3]]
    meta = _grid_meta(n, shape, box, family="tet", kind="structured")
    return tag_box_faces(_cells_mesh(vertices, tets, TET_FACES, None, (), meta), *check_box(box), sides)


def _cells_mesh(vertices, cells, cell_faces, labels, sides, meta) -> PolyhedralMesh:
    """``from_face_soup`` of cells given by their corners ``cells`` (m, c), each with the faces
    ``cell_faces`` (f, k) (local corner numbers, outward); ``labels``, ``sides`` its boundary names."""
    m = cells.shape[0]
    n_faces, face_size = cell_faces.shape
    faces = cells[:, cell_faces].reshape(-1, face_size)
    return from_face_soup(
        vertices, np.full(m, n_faces), np.full(n_faces * m, face_size), faces.ravel(), labels, sides, meta
    )


def _grid_meta(n, shape, box, **family) -> dict:
    """The ``meta`` of a grid mesh: the family (and kind), ``n``, the cell counts and the box."""
    return {**family, "n": n, "shape": list(shape), "box": np.asarray(box, float).tolist()}


def _merge_repeated_names(mesh: PolyhedralMesh, sides) -> PolyhedralMesh:
    """from_face_soup with a name given twice already joins the parts; keep the sides' order."""
    parts = {name: mesh.boundary.get(name, np.zeros(0, np.int64)) for name in dict.fromkeys(sides)}
    return replace(mesh, boundary=parts)
