"""Validation of a polyhedral mesh (docs/reference/files.md): every way it can be broken, with a one-line message.

``validate_mesh3d(mesh)`` returns ``None`` for a valid mesh and raises ``MeshError`` naming the
offending cell, face or vertex and the defect, for the first problem found. In order:

1. arrays: shapes, finite coordinates, CSR offsets, indices in range, at least 3 vertices per face
   and 4 faces per cell, no vertex twice in a face, no face twice in a cell;
2. faces: every face used by one or two cells, and by two cells in opposite orientations (stored
   for one, reversed for the other); none unused;
3. faces are planar: every vertex within ``PLANARITY_TOL`` x the face's diameter of the plane
   through its centroid normal to its vector area; no face of zero area (|F| <= ``DEGENERATE_TOL``
   x diameter²);
4. cells are closed: every edge of a cell's signed faces is used by exactly two of its faces, in
   opposite directions (then the surface is closed and consistently oriented);
5. cells point outward: the divergence-theorem volume is positive, and not degenerate (> ``DEGENERATE_TOL``
   x diameter³); a negative volume means the faces point in;
6. vertices: none unused, no two at the same place (within ``tol`` x the mesh extent);
7. no two cells overlap: the boundary's winding number is 0 just outside every boundary face
   (``vemkit.mesh.cover3d``: the volume identity of the divergence theorem cannot see an overlap);
8. boundary parts: names are identifiers, faces exist and are boundary faces, no face in two parts,
   and (``require_named``) every boundary face in one part (``unnamed_boundary_faces`` lists them).

Everything is vectorized (numpy), so a mesh of 10^6 cells is checked in seconds; Numba screens
(``vemkit.mesh.check_kernels3d``) pass a valid mesh's repeats, faces and closed cells in one pass
each, the numpy checks deciding whenever a screen does not pass.
"""

from __future__ import annotations

import numpy as np

from vemkit.exceptions import MeshError
from vemkit.mesh.check_kernels3d import cells_closed, faces_flat_and_planar, no_repeats
from vemkit.mesh.close_points import close_pairs, has_close_pair
from vemkit.mesh.cover3d import check_cover3d
from vemkit.mesh.geometry import extents
from vemkit.mesh.polyhedral import PolyhedralMesh

#: largest distance of a face vertex from the face's plane, relative to the face's diameter
PLANARITY_TOL = 1e-8
#: a face of area <= this x diameter², a cell of volume <= this x diameter³ is degenerate
DEGENERATE_TOL = 1e-12


def validate_mesh3d(
    mesh: PolyhedralMesh, tol: float = 1e-12, planarity: float = PLANARITY_TOL, require_named: bool = True
) -> None:
    """Raise ``MeshError`` for the first defect found (module doc); ``tol`` is relative to the mesh extent."""
    _check_arrays(mesh)
    _check_face_use(mesh)
    _check_faces(mesh, planarity)
    _check_closed(mesh)
    _check_volumes(mesh)
    _check_vertices(mesh, tol)
    check_cover3d(mesh)
    _check_boundary(mesh, require_named)


def unnamed_boundary_faces(mesh: PolyhedralMesh) -> np.ndarray:
    """Boundary faces in no named part."""
    named = np.concatenate([np.zeros(0, np.int64)] + [np.asarray(p, np.int64) for p in mesh.boundary.values()])
    return np.setdiff1d(mesh.boundary_faces, named)


def _csr(offsets, values, what, item, count, least):
    if offsets.ndim != 1 or offsets.size < 1 or offsets[0] != 0:
        raise MeshError(f"{what}_offsets must be a 1-D array starting at 0 (CSR offsets, one more than {item}s)")
    if values.ndim != 1 or offsets[-1] != values.size:
        raise MeshError(f"{what}_offsets end at {offsets[-1]} but there are {values.size} entries; make them agree")
    sizes = np.diff(offsets)
    small = np.flatnonzero(sizes < least)
    if small.size:
        k = int(small[0])
        raise MeshError(
            f"{item} {k} has {sizes[k]} {'vertices' if item == 'face' else 'faces'}; a "
            f"{'polygon' if item == 'face' else 'polyhedron'} needs at least {least}"
        )
    out = np.flatnonzero((values < -count if item == "cell" else values < 0) | (values >= count))
    if out.size:
        k = int(np.searchsorted(offsets, out[0], side="right") - 1)
        raise MeshError(
            f"{item} {k} refers to {'face' if item == 'cell' else 'vertex'} {values[out[0]]} but there are "
            f"{count}; fix its list"
        )


def _first_repeat(offsets, values):
    """(segment, value) of the first value listed twice within one CSR segment, or None."""
    owner = np.repeat(np.arange(offsets.size - 1, dtype=np.int64), np.diff(offsets))
    key = np.sort(owner * np.int64(max(int(values.max(initial=0)) + 1, 1)) + values)
    rep = np.flatnonzero(key[1:] == key[:-1])
    if not rep.size:
        return None
    return divmod(int(key[rep[0]]), max(int(values.max(initial=0)) + 1, 1))


def _check_arrays(mesh: PolyhedralMesh) -> None:
    v = mesh.vertices
    if v.ndim != 2 or v.shape[1] != 3:
        raise MeshError(f"vertices have shape {v.shape}; give an (N, 3) array of x, y, z coordinates")
    bad = np.zeros(0, dtype=np.int64) if np.isfinite(v).all() else np.flatnonzero(~np.isfinite(v).all(axis=1))
    if bad.size:
        raise MeshError(f"vertex {bad[0]} has non-finite coordinates {tuple(v[bad[0]].tolist())}; fix its coordinates")
    if mesh.n_cells < 1:
        raise MeshError("the mesh has no cells; give at least one polyhedron")
    _csr(mesh.face_offsets, mesh.face_vertices, "face", "face", mesh.n_vertices, 3)
    _csr(mesh.cell_offsets, mesh.cell_faces, "cell", "cell", mesh.n_faces, 4)
    rep = (
        None
        if no_repeats(mesh.face_offsets, mesh.face_vertices)
        else _first_repeat(mesh.face_offsets, mesh.face_vertices)
    )
    if rep:
        raise MeshError(f"face {rep[0]} lists vertex {rep[1]} more than once; list every vertex of a face once")
    faces = np.where(mesh.cell_faces >= 0, mesh.cell_faces, -mesh.cell_faces - 1)
    rep = None if no_repeats(mesh.cell_offsets, faces) else _first_repeat(mesh.cell_offsets, faces)
    if rep:
        raise MeshError(f"cell {rep[0]} lists face {rep[1]} more than once; list every face of a cell once")


def _check_face_use(mesh: PolyhedralMesh) -> None:
    faces = np.where(mesh.cell_faces >= 0, mesh.cell_faces, -mesh.cell_faces - 1)
    cells = np.repeat(np.arange(mesh.n_cells, dtype=np.int64), np.diff(mesh.cell_offsets))
    uses = np.bincount(faces, minlength=mesh.n_faces)
    crowded = np.flatnonzero(uses > 2)
    if crowded.size:
        f = int(crowded[0])
        raise MeshError(
            f"face {f} belongs to {uses[f]} cells {cells[faces == f].tolist()}; a face is shared by at most 2 cells"
        )
    unused = np.flatnonzero(uses == 0)
    if unused.size:
        raise MeshError(f"face {unused[0]} belongs to no cell; remove it (and renumber)")
    forward = np.bincount(faces[mesh.cell_faces >= 0], minlength=mesh.n_faces)
    same = np.flatnonzero((uses == 2) & (forward != 1))
    if same.size:
        f = int(same[0])
        owners = cells[faces == f].tolist()
        way = "as stored" if forward[f] == 2 else "reversed"
        raise MeshError(
            f"face {f} is used {way} by both its cells {owners}; a shared face points out of one cell and "
            "into the other (one of the cells is inside out)"
        )


def _check_faces(mesh: PolyhedralMesh, planarity: float) -> None:
    args = (mesh.vertices, mesh.face_offsets, mesh.face_vertices, mesh.face_vector_areas, mesh.face_centroids)
    if faces_flat_and_planar(*args, DEGENERATE_TOL, float(planarity)):
        return
    sizes = np.diff(mesh.face_offsets)
    owner = np.repeat(np.arange(mesh.n_faces, dtype=np.int64), sizes)
    p = mesh.vertices[mesh.face_vertices]
    centre = mesh.face_centroids
    reach = np.zeros(mesh.n_faces)
    np.maximum.at(reach, owner, np.linalg.norm(p - centre[owner], axis=1))
    diameter = 2.0 * reach
    va = mesh.face_vector_areas
    area = np.linalg.norm(va, axis=1)
    flat = np.flatnonzero(area <= DEGENERATE_TOL * diameter**2)
    if flat.size:
        f = int(flat[0])
        raise MeshError(
            f"face {f} has zero area (its vertices are collinear or coincide); remove it or fix its vertices"
        )
    unit = va / area[:, None]
    off = np.abs(np.einsum("ij,ij->i", p - centre[owner], unit[owner]))
    worst = np.zeros(mesh.n_faces)
    np.maximum.at(worst, owner, off)
    bent = np.flatnonzero(worst > planarity * diameter)
    if bent.size:
        f = int(bent[0])
        raise MeshError(
            f"face {f} is not planar: a vertex lies {worst[f] / diameter[f]:.2e} x its diameter off its "
            f"plane (tolerance {planarity:.0e}); split it into planar faces"
        )


def _check_closed(mesh: PolyhedralMesh) -> None:
    if cells_closed(mesh.cell_offsets, mesh.cell_faces, mesh.face_offsets, mesh.face_vertices):
        return
    faces = np.where(mesh.cell_faces >= 0, mesh.cell_faces, -mesh.cell_faces - 1)
    sizes = np.diff(mesh.face_offsets)[faces]
    entry = np.repeat(np.arange(faces.size, dtype=np.int64), sizes)
    local = np.arange(entry.size, dtype=np.int64) - np.repeat(np.cumsum(sizes) - sizes, sizes)
    start = mesh.face_offsets[faces][entry]
    a = mesh.face_vertices[start + local]
    b = mesh.face_vertices[start + (local + 1) % sizes[entry]]
    reverse = mesh.cell_faces[entry] < 0
    a, b = np.where(reverse, b, a), np.where(reverse, a, b)
    cells = np.repeat(np.arange(mesh.n_cells, dtype=np.int64), np.diff(mesh.cell_offsets))[entry]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    n = np.int64(max(mesh.n_vertices, 1))
    if float(mesh.n_cells) * float(n) * float(n) * 2.0 < 2.0**62:  # one int64 key: a sort, not a lexsort
        order = np.argsort(((cells * n + lo) * n + hi) * 2 + (a > b), kind="stable")
    else:
        order = np.lexsort((a > b, hi, lo, cells))
    key = np.stack([cells[order], lo[order], hi[order]], axis=1)
    new = np.ones(order.size, dtype=bool)
    new[1:] = (key[1:] != key[:-1]).any(axis=1)
    starts = np.flatnonzero(new)
    count = np.diff(np.append(starts, order.size))
    up = np.add.reduceat((a > b)[order].astype(np.int64), starts)
    bad = np.flatnonzero((count != 2) | (up != 1))
    if bad.size:
        i = starts[bad[0]]
        c, x, y = (int(t) for t in key[i])
        if count[bad[0]] != 2:
            raise MeshError(
                f"cell {c} is not closed: its edge ({x}, {y}) belongs to {count[bad[0]]} of its faces "
                "instead of 2 (a missing face, or a neighbour's hanging node missing from this cell's "
                "faces)"
            )
        raise MeshError(
            f"cell {c} is not consistently oriented: its two faces at edge ({x}, {y}) run along it in the "
            "same direction; reverse one of them (cells list their faces outward)"
        )


def _check_volumes(mesh: PolyhedralMesh) -> None:
    vol = mesh.cell_volumes
    diam = mesh.cell_diameters
    flat = np.flatnonzero(np.abs(vol) <= DEGENERATE_TOL * diam**3)
    if flat.size:
        raise MeshError(f"cell {flat[0]} has zero volume (a flat polyhedron); remove it or fix its vertices")
    inward = np.flatnonzero(vol < 0)
    if inward.size:
        c = int(inward[0])
        raise MeshError(
            f"cell {c} is inside out (volume {vol[c]:.3g} < 0 by the divergence theorem); list its faces "
            "outward (flip every sign in its face list)"
        )


def _check_vertices(mesh: PolyhedralMesh, tol: float) -> None:
    used = np.bincount(mesh.face_vertices, minlength=mesh.n_vertices)
    unused = np.flatnonzero(used == 0)
    if unused.size:
        raise MeshError(f"vertex {unused[0]} belongs to no face; remove it (and renumber)")
    extent = float(np.max(extents(mesh.vertices)))
    radius = tol * max(extent, np.finfo(float).tiny)
    pairs = close_pairs(mesh.vertices, radius) if has_close_pair(mesh.vertices, radius) else np.zeros((0, 2))
    if pairs.size:
        a, b = sorted(int(x) for x in pairs[np.argmin(pairs.min(axis=1))])
        where = tuple(mesh.vertices[a].tolist())
        raise MeshError(f"vertices {a} and {b} have the same coordinates {where}; merge them into one vertex")


def _check_boundary(mesh: PolyhedralMesh, require_named: bool) -> None:
    from vemkit.config.domain import SIDE_NAME

    is_boundary = np.zeros(mesh.n_faces, dtype=bool)
    is_boundary[mesh.boundary_faces] = True
    owner = np.full(mesh.n_faces, -1, dtype=np.int64)
    names = list(mesh.boundary)
    for k, (name, part) in enumerate(mesh.boundary.items()):
        if not SIDE_NAME.fullmatch(name):
            raise MeshError(f"boundary part {name!r} is not an identifier; use letters, digits, _ and - only")
        out = part[(part < 0) | (part >= mesh.n_faces)]
        if out.size:
            raise MeshError(f"boundary part '{name}' refers to face {out[0]} but there are {mesh.n_faces} faces")
        inner = part[~is_boundary[part]]
        if inner.size:
            raise MeshError(
                f"boundary part '{name}' face {inner[0]} is not a boundary face (two cells share it); "
                "remove it from the part"
            )
        twice = part[owner[part] >= 0]
        if twice.size or np.unique(part).size != part.size:
            f = int(twice[0]) if twice.size else int(part[np.flatnonzero(np.diff(np.sort(part)) == 0)[0]])
            other = names[owner[f]] if owner[f] >= 0 else name
            raise MeshError(f"boundary face {f} is in both parts '{other}' and '{name}'; a face has one side name")
        owner[part] = k
    if require_named:
        rest = unnamed_boundary_faces(mesh)
        if rest.size:
            where = tuple(np.round(mesh.face_centroids[rest[0]], 12).tolist())
            raise MeshError(
                f"{rest.size} boundary faces carry no side name (first: face {rest[0]}, centroid {where}); "
                "name them in a boundary part"
            )
