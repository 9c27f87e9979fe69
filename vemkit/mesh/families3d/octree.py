"""Hexahedra with hanging nodes (docs/reference/files.md): the box grid with some cells cut into 8 (one level).

Refined are (``rule``) the cells touching ``contact_side`` (default ``bottom``, z = z0), or
``round(fraction x count)`` cells chosen with ``numpy.random.default_rng(seed)`` (``rule="random"``).
A refined cell becomes 8 hexahedra of half its size. A coarse cell keeps its 8 corners and gains
as vertices the hanging nodes of its refined neighbours: a face shared with a refined cell is
split into its 4 quarter faces (the face centre and the 4 edge midpoints become vertices of the
coarse cell), and an edge shared with a refined cell (across a face or only across the edge)
carries its midpoint, so a coarse face may be a pentagon ... octagon with collinear vertices. The
coarse cell is a polyhedron of 6 to 24 faces.

Every vertex sits on the lattice of half cells, numbered (k (2ny+1) + j)(2nx+1) + i before the
unused ones are dropped, so shared vertices are exactly shared. Cells: the coarse ones first
(grid order), then the 8 children of every refined cell (grid order of the parents).
"""

from __future__ import annotations

import numpy as np

from vemkit.mesh.families3d.grid import BOX_SIDES, CORNERS, HEX_FACES, UNIT_BOX, check_box, grid_shape
from vemkit.mesh.polyhedral import PolyhedralMesh
from vemkit.mesh.polyhedral_build import from_face_soup, tag_box_faces

RULES = ("contact", "random")


def _chosen(shape, rule, contact_side, sides, fraction, seed) -> np.ndarray:
    nx, ny, nz = shape
    k, j, i = (t.ravel() for t in np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij"))
    if rule == "random":
        out = np.zeros(i.size, dtype=bool)
        out[np.random.default_rng(seed).choice(i.size, int(round(fraction * i.size)), replace=False)] = True
        return out
    axis, high = divmod(list(sides).index(contact_side), 2)
    index, count = (i, j, k)[axis], shape[axis]
    return index == (count - 1 if high else 0)


def octree(
    n=None,
    box=UNIT_BOX,
    sides=BOX_SIDES,
    shape=None,
    rule: str = "contact",
    contact_side: str = "bottom",
    fraction: float = 0.3,
    seed: int = 0,
    levels: int = 1,
) -> PolyhedralMesh:
    """The grid of the box with one level of refinement by ``rule`` (module doc)."""
    if int(levels) != 1:
        raise ValueError(f"levels = {levels}: the octree family refines one level (levels = 1)")
    if rule not in RULES:
        raise ValueError(f"rule = {rule!r}: valid rules are {', '.join(RULES)}")
    if rule == "contact" and contact_side not in sides:
        raise ValueError(f"contact_side = {contact_side!r}: valid sides are {', '.join(sides)}")
    if rule == "random" and not 0.0 <= fraction <= 1.0:
        raise ValueError(f"fraction = {fraction}: give a fraction of cells between 0 and 1")
    shape = grid_shape(n, box, shape)
    lower, upper = check_box(box)
    refined = _chosen(shape, rule, contact_side, sides, fraction, seed)
    nx, ny, nz = shape
    dims = np.array([2 * nx + 1, 2 * ny + 1, 2 * nz + 1])
    k, j, i = (t.ravel() for t in np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij"))
    origin = 2 * np.stack([i, j, k], axis=1)  # lattice corner of every grid cell

    def vid(p):
        return (p[..., 2] * dims[1] + p[..., 1]) * dims[0] + p[..., 0]

    active = np.zeros(int(np.prod(dims)), dtype=bool)
    active[vid(origin[:, None, :] + 2 * CORNERS)] = True
    three = np.stack(np.meshgrid(*[np.arange(3)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    active[vid(origin[refined][:, None, :] + three)] = True
    coarse_rows, coarse_counts = _coarse_faces(origin[~refined], vid, active)
    child = (origin[refined][:, None, :] + CORNERS[None]).reshape(-1, 3)  # children's lowest corners
    child_rows = vid(child[:, None, None, :] + CORNERS[HEX_FACES][None]).reshape(-1, 4)
    rows = np.concatenate([coarse_rows, np.pad(child_rows, ((0, 0), (0, 4)), constant_values=-1)])
    counts = np.concatenate([coarse_counts, np.full(child.shape[0], 6)])
    valid = rows >= 0
    used = np.unique(rows[valid])
    renumber = np.full(active.size, -1, dtype=np.int64)
    renumber[used] = np.arange(used.size)
    kk, rest = np.divmod(used, dims[0] * dims[1])
    jj, ii = np.divmod(rest, dims[0])
    vertices = lower + np.stack([ii, jj, kk], axis=1) / (dims - 1) * (upper - lower)
    meta = {
        "family": "octree",
        "n": n,
        "shape": list(shape),
        "box": np.asarray(box, float).tolist(),
        "rule": rule,
        "levels": 1,
        "refined": int(refined.sum()),
    }
    meta.update(
        {"fraction": float(fraction), "seed": int(seed)} if rule == "random" else {"contact_side": contact_side}
    )
    mesh = from_face_soup(vertices, counts, valid.sum(axis=1), renumber[rows[valid]], None, (), meta)
    return tag_box_faces(mesh, lower, upper, sides)


def _coarse_faces(origin: np.ndarray, vid, active: np.ndarray):
    """Rows (padded to 8) of the outward faces of the coarse cells, and each cell's number of faces."""
    corners = origin[:, None, None, :] + 2 * CORNERS[HEX_FACES][None]  # (C, 6, 4, 3)
    mids = (corners + np.roll(corners, -1, axis=2)) // 2  # mid of corner q -> q + 1
    centre = corners.sum(axis=2) // 4  # (C, 6, 3)
    ring = np.stack([corners, mids], axis=3).reshape(origin.shape[0], 6, 8, 3)
    ring_ids = vid(ring)
    keep = active[ring_ids]
    split = active[vid(centre)]  # the neighbour across is refined
    c = vid(centre)[..., None]
    r = ring_ids
    quarters = np.stack(
        [
            np.concatenate([r[..., [0, 1]], c, r[..., [7]]], axis=-1),
            np.concatenate([r[..., [1, 2, 3]], c], axis=-1),
            np.concatenate([c, r[..., [3, 4, 5]]], axis=-1),
            np.concatenate([r[..., [7]], c, r[..., [5, 6]]], axis=-1),
        ],
        axis=2,
    )  # (C, 6, 4, 4)
    whole = np.where(keep, ring_ids, -1)
    # compact every whole face to the left (keep its cyclic order)
    order = np.argsort(~keep, axis=-1, kind="stable")
    whole = np.take_along_axis(whole, order, axis=-1)
    cells = np.repeat(np.arange(origin.shape[0]), 6).reshape(-1, 6)
    face = np.tile(np.arange(6), (origin.shape[0], 1))
    one_rows = whole[~split]
    one_key = np.stack([cells[~split], face[~split], np.zeros(one_rows.shape[0], int)], axis=1)
    four_rows = np.pad(quarters[split].reshape(-1, 4), ((0, 0), (0, 4)), constant_values=-1)
    four_key = np.stack(
        [np.repeat(cells[split], 4), np.repeat(face[split], 4), np.tile(np.arange(4), int(split.sum()))], axis=1
    )
    rows = np.concatenate([one_rows, four_rows])
    key = np.concatenate([one_key, four_key])
    order = np.lexsort((key[:, 2], key[:, 1], key[:, 0]))
    counts = 6 + 3 * split.sum(axis=1)
    return rows[order], counts
