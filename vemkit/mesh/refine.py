"""Local refinement of polygonal meshes; neighbours gain hanging nodes as plain vertices (docs/reference/files.md).

A marked cell with geometric corners c_0 … c_{m−1} (the vertices where its boundary turns; a
hanging node on a straight edge is a vertex but not a corner) is split into m polygons

    child_i = [c_i, …, s_i, z, s_{i−1}, …]        (the dots: vertices already on those edge halves)

where s_i is the midpoint of the geometric edge c_i c_{i+1} and z the centroid of the cell. A
square becomes its four quadrants (quadrisection), a triangle three quadrilaterals, a Voronoi cell
m quadrilaterals. The split needs z in the kernel of the cell (z to the left of every edge), which
holds for convex cells; for a non-convex cell the vertex mean is tried next, then the centroid of
the kernel itself (the cell's bounding box cut by the left half-plane of every edge: a cut cell at
a circular hole, dented by its new vertices on the circle, or one wrapping a corner of the hole's
polygon). A cell whose new vertices on a circle leave it no kernel gets them on its chords instead;
a cell without a kernel at all (not star-shaped) is left whole (reported in ``RefinedMesh.skipped``).

A new edge midpoint is inserted as a vertex into the one or two cells sharing that edge, so the mesh
stays vertex-conforming: the neighbour is not refined, it simply gains a vertex (docs/reference/mathematics.md).
``max_hanging = k`` also refines every cell that would otherwise carry more than k vertices inside
one of its geometric edges (repeated until none does). A new vertex of a boundary edge of a curved
piece (a circular hole or an arc: ``circles``, ``vemkit.mesh.curves``) is placed on that piece's own
circle, not on the chord, nor on another piece with the same side name (see above). Boundary
edges keep their side names. The prolongation maps vertex values of the old mesh to the new one
(linear along split edges, the vertex mean at cell centres): a warm start for the next solve.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from vemkit.exceptions import InputError
from vemkit.mesh.curves import as_pieces, on_curves
from vemkit.mesh.mesh import Mesh
from vemkit.mesh.refine_kernels import (
    augmented_rings,
    children,
    corner_flags,
    max_inner_vertices,
    midpoint_requests,
    split_centres,
)


class RefinedMesh(NamedTuple):
    mesh: Mesh
    parent: np.ndarray  # (new cells,) the old cell each new cell comes from
    prolongation: sp.csr_matrix  # (new vertices, old vertices)
    refined: np.ndarray  # old cells that were split (marked, or added by max_hanging)
    skipped: np.ndarray  # cells to split that could not be (no centre in their kernel)


def corner_positions(points: np.ndarray) -> np.ndarray:
    """Positions (in the polygon's vertex list) of the geometric corners of one polygon."""
    n = points.shape[0]
    flags = corner_flags(np.ascontiguousarray(points, dtype=float), np.array([0, n]), np.arange(n))
    return np.flatnonzero(flags)


class _Splits(NamedTuple):
    """The new edge points of one refinement pass, grouped by old edge."""

    keys: np.ndarray  # sorted min * N + max of the split old edges
    ptr: np.ndarray  # CSR over keys
    vertices: np.ndarray  # new vertex ids, per edge in the direction min -> max
    points: np.ndarray  # (new, 2) their coordinates
    ends: np.ndarray  # (new, 2) the old edge (min, max) of each new vertex
    t: np.ndarray  # (new,) the parameter along min -> max
    chords: np.ndarray  # (new, 2) the coordinates on the old edge (points: moved onto a circle)


def _plan(mesh: Mesh, cells: np.ndarray, corner: np.ndarray, circles: list) -> _Splits:
    """Midpoints of the geometric edges of ``cells``, merged per old edge (docs/reference/files.md)."""
    a, b, t = midpoint_requests(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, corner, cells)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    t = np.where(a < b, t, 1.0 - t)
    n = np.int64(mesh.n_vertices)
    rows = np.unique(np.stack([lo * n + hi, np.round(t * 1e9).astype(np.int64)], axis=1), axis=0)
    keys, ticks = rows[:, 0], rows[:, 1] / 1e9
    ends = np.stack([keys // n, keys % n], axis=1)
    chords = mesh.vertices[ends[:, 0]] + ticks[:, None] * (mesh.vertices[ends[:, 1]] - mesh.vertices[ends[:, 0]])
    points = on_curves(mesh, ends, chords, circles)
    unique_keys, first = np.unique(keys, return_index=True)
    ptr = np.r_[first, keys.size].astype(np.int64)
    return _Splits(unique_keys, ptr, n + np.arange(keys.size), points, ends, ticks, chords)


def _rings(mesh: Mesh, splits: _Splits):
    points = np.concatenate([mesh.vertices, splits.points])
    offsets, ring = augmented_rings(
        mesh.cell_offsets, mesh.cell_vertices, splits.keys, splits.ptr, splits.vertices, np.int64(mesh.n_vertices)
    )
    return points, offsets, ring


def check_refinable(mesh: Mesh, circles=None) -> None:
    """Nothing to refuse: every polygon is split or, without a kernel, left whole and reported in
    ``RefinedMesh.skipped`` (the plane counterpart of ``check_refinable3d``)."""


def refine_cells(mesh: Mesh, marked, *, max_hanging: int | None = None, circles=None) -> RefinedMesh:
    """Split the marked cells (indices or a boolean mask) as the module docstring describes."""
    marked = np.asarray(marked)
    marked = np.flatnonzero(marked) if marked.dtype == bool else np.unique(marked.astype(np.int64))
    if marked.size and (marked.min() < 0 or marked.max() >= mesh.n_cells):
        raise InputError(f"refine_cells: cell indices must lie in [0, {mesh.n_cells})", key="marked")
    if max_hanging is not None and max_hanging < 1:
        raise InputError(f"adaptivity.max_hanging = {max_hanging}: must be >= 1 (or absent)", key="max_hanging")
    circles = as_pieces(mesh.meta.get("circles") if circles is None else circles)
    corner = corner_flags(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices)
    refine = marked
    while True:
        splits = _plan(mesh, refine, corner, circles)
        points, offsets, ring = _rings(mesh, splits)
        ring_corner = np.zeros(ring.size, dtype=bool)
        ring_corner[ring < mesh.n_vertices] = corner  # old slots keep their order; new points are no corners
        if max_hanging is None:
            break
        inner = max_inner_vertices(offsets, ring, ring_corner)
        extra = np.setdiff1d(np.flatnonzero(inner > max_hanging), refine)
        if extra.size == 0:
            break
        refine = np.union1d(refine, extra)
    return _assemble(mesh, refine, splits, points, offsets, ring, ring_corner)


def _centres(mesh: Mesh, refine, splits: _Splits, points, offsets, ring):
    """(split centres, points): a cell that new vertices moved onto a circle leave without a kernel
    point gets them back on its chords (its boundary edges are its own), then it is tried again."""
    centres = split_centres(points, offsets, ring, refine)
    stuck = refine[np.isnan(centres[:, 0])]
    if stuck.size == 0:
        return centres, points
    slots = np.concatenate([ring[offsets[c] : offsets[c + 1]] for c in stuck]) - mesh.n_vertices
    new = slots[slots >= 0]
    moved = new[np.any(splits.points[new] != splits.chords[new], axis=1)]
    if moved.size == 0:
        return centres, points
    points = points.copy()
    points[mesh.n_vertices + moved] = splits.chords[moved]
    return split_centres(points, offsets, ring, refine), points


def _assemble(mesh: Mesh, refine, splits: _Splits, points, offsets, ring, ring_corner) -> RefinedMesh:
    centres, points = _centres(mesh, refine, splits, points, offsets, ring)
    ok = ~np.isnan(centres[:, 0])
    split, skipped = refine[ok], refine[~ok]
    n_new = points.shape[0]
    centre_ids = n_new + np.arange(split.size)
    child_offsets, child_ring, child_parent = children(points, offsets, ring, ring_corner, split, centre_ids)
    keep = np.setdiff1d(np.arange(mesh.n_cells), split)
    sizes = np.r_[np.diff(offsets)[keep], np.diff(child_offsets)]
    kept_ring = ring[np.concatenate([np.arange(offsets[k], offsets[k + 1]) for k in keep])] if keep.size else ring[:0]
    cell_offsets = np.r_[0, np.cumsum(sizes)].astype(np.int64)
    vertices = np.concatenate([points, centres[ok]])
    boundary = {name: _split_boundary(edges, splits, mesh.n_vertices) for name, edges in mesh.boundary.items()}
    meta = {**mesh.meta, "refinements": int(mesh.meta.get("refinements", 0)) + 1}
    new = Mesh(vertices, cell_offsets, np.concatenate([kept_ring, child_ring]), boundary, meta)
    parent = np.r_[keep, split[child_parent]].astype(np.int64)
    return RefinedMesh(new, parent, _prolongation(mesh, splits, split), split, skipped)


def _split_boundary(edges: np.ndarray, splits: _Splits, n_old: int) -> np.ndarray:
    """Boundary edges (a, b) cut at their new points, in order, with the same side.

    Each edge is read as a two-vertex polygon [a, b]: its augmented ring is a, (k new points), b,
    (the same k reversed), so the first k + 2 entries are the path from a to b.
    """
    if edges.size == 0:
        return edges.reshape(0, 2)
    offsets, ring = augmented_rings(
        np.arange(0, 2 * edges.shape[0] + 1, 2),
        edges.ravel(),
        splits.keys,
        splits.ptr,
        splits.vertices,
        np.int64(n_old),
    )
    out = []
    for start, stop in zip(offsets[:-1], offsets[1:]):
        path = ring[start : start + (stop - start) // 2 + 1]
        out.append(np.stack([path[:-1], path[1:]], axis=1))
    return np.concatenate(out).astype(np.int64)


def _prolongation(mesh: Mesh, splits: _Splits, split: np.ndarray) -> sp.csr_matrix:
    """Old vertex values to new ones: identity, linear along split edges, cell mean at centres."""
    n_old, n_edge = mesh.n_vertices, splits.t.size
    sizes = mesh.cell_sizes[split]
    rows = np.r_[
        np.arange(n_old),
        np.repeat(n_old + np.arange(n_edge), 2),
        np.repeat(n_old + n_edge + np.arange(split.size), sizes),
    ]
    cols = np.r_[
        np.arange(n_old),
        splits.ends.ravel(),
        np.concatenate([mesh.cell(k) for k in split]) if split.size else np.zeros(0, np.int64),
    ]
    vals = np.r_[np.ones(n_old), np.stack([1.0 - splits.t, splits.t], axis=1).ravel(), np.repeat(1.0 / sizes, sizes)]
    return sp.csr_matrix((vals, (rows, cols)), shape=(n_old + n_edge + split.size, n_old))
