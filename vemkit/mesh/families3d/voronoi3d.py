"""Centroidal Voronoi polyhedra of a box (docs/reference/files.md), clipped exactly by the box.

Seeds: a jittered grid of ``count`` points (about n³ per unit volume; one per lattice cell of the
box's best-fitting grid, jittered by ``jitter`` of a cell with ``numpy.random.default_rng(seed)``),
then ``lloyd_iterations`` Lloyd steps (every seed moved to its cell's centroid, by default the
centroid estimated on a regular grid of 27 sample points per cell: one diagram in all).

Clipping by mirrors: every seed within ``margin`` of a box face is mirrored across that face. For
a seed p inside the box, its mirror p' makes the face plane the bisector of p and p', and a mirror
q' is never closer than q to a point of the box, so the Voronoi cell of p among the seeds and the
mirrors is exactly its Voronoi cell among the seeds cut by the box (as long as every seed whose
cell reaches a face is mirrored: the margin starts at 1.5 cell sizes and is doubled until every cell
is bounded and inside the box). The diagram is scipy.spatial.Voronoi (Qhull), whose 3D ridges list
their vertices in order around the ridge. Ridges between two seeds are interior faces, ridges
between a seed and a mirror are boundary faces named after the mirror's face; vertices within
1e-9 cell sizes of a face are put exactly on it, and vertices closer than that to one another are
merged (Qhull may report a degenerate vertex twice).
"""

from __future__ import annotations

import itertools
from dataclasses import replace

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import Voronoi, cKDTree

from vemkit.mesh.families3d.grid import BOX_SIDES, UNIT_BOX, check_box
from vemkit.mesh.families3d.voronoi3d_kernels import nearest_seeds, owner_sums, seed_buckets
from vemkit.mesh.polyhedral import PolyhedralMesh

MERGE_TOL = 1e-9  # relative to the cell size


def seed_count(n=None, box=UNIT_BOX, cells=None) -> int:
    """Seeds for n cells per unit length (n³ per unit volume), or ``cells``."""
    lower, upper = check_box(box)
    if cells is not None:
        return max(1, int(round(float(cells))))
    if not n > 0:
        raise ValueError(f"mesh n = {n}: the number of cells per unit length must be > 0")
    return max(1, int(round(float(n) ** 3 * float(np.prod(upper - lower)))))


def jittered_seeds(count: int, lower, upper, rng, jitter: float) -> np.ndarray:
    """``count`` points: the centres of the first ``count`` cells of a grid fitted to the box (cells
    chosen at random), jittered by up to ``jitter`` of a grid cell."""
    size = upper - lower
    step = (float(np.prod(size)) / count) ** (1.0 / 3.0)
    shape = np.maximum(1, np.ceil(size / step).astype(int))
    while np.prod(shape) < count:
        shape[np.argmax(size / shape)] += 1
    pick = np.sort(rng.choice(int(np.prod(shape)), count, replace=False))
    ijk = np.stack(np.unravel_index(pick, tuple(shape)), axis=1)
    cell = size / shape
    return lower + (ijk + 0.5 + jitter * (rng.random((count, 3)) - 0.5)) * cell


def voronoi(
    n=None,
    box=UNIT_BOX,
    sides=BOX_SIDES,
    cells=None,
    seed: int = 0,
    lloyd_iterations: int = 3,
    jitter: float = 0.8,
    lloyd_samples: int = 3,
) -> PolyhedralMesh:
    """The clipped centroidal Voronoi mesh of the box (module doc). ``lloyd_samples`` = k > 0: the
    Lloyd steps take every cell's centroid as the mean of the points of a regular grid of about k³
    points per cell that are nearer to its seed than to any other (a bucket-grid search: no diagram per
    step); k = 0: the exact centroids of the clipped diagram at every step."""
    lower, upper = check_box(box)
    count = seed_count(n, box, cells)
    rng = np.random.default_rng(seed)
    points = jittered_seeds(count, lower, upper, rng, jitter)
    samples = sample_grid(count, lower, upper, int(lloyd_samples)) if lloyd_samples else None
    for _ in range(int(lloyd_iterations)):
        if samples is None:
            points = cell_centroids(clipped_voronoi(points, lower, upper, sides), points)
        else:
            points = sampled_centroids(points, samples, lower, upper)
    mesh = clipped_voronoi(points, lower, upper, sides)
    meta = {
        "family": "voronoi",
        "n": n,
        "cells": count,
        "box": np.asarray(box, float).tolist(),
        "seed": int(seed),
        "lloyd_iterations": int(lloyd_iterations),
        "jitter": float(jitter),
        "lloyd_samples": int(lloyd_samples),
    }
    return replace(mesh, meta=meta)


def sample_grid(count: int, lower, upper, k: int) -> np.ndarray:
    """The centres of a regular grid of about k³ x count cells of the box."""
    size = upper - lower
    step = (float(np.prod(size)) / (count * k**3)) ** (1.0 / 3.0)
    shape = np.maximum(1, np.round(size / step).astype(int))
    axes = [lower[a] + (np.arange(shape[a]) + 0.5) * size[a] / shape[a] for a in range(3)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


def sampled_centroids(points: np.ndarray, samples: np.ndarray, lower=None, upper=None) -> np.ndarray:
    """Every seed moved to the mean of the samples nearest to it (kept where it has none); the nearest
    seeds by a bucket grid over the box [lower, upper] (default: the samples' bounding box), the Numba
    kernels of ``voronoi3d_kernels`` (the cKDTree query is their twin in the tests)."""
    lower = samples.min(axis=0) if lower is None else np.asarray(lower, float)
    upper = samples.max(axis=0) if upper is None else np.asarray(upper, float)
    shape, h, ptr, seeds = seed_buckets(points, lower, upper)
    owner = nearest_seeds(points, samples, lower, shape, h, ptr, seeds)
    sums, count = owner_sums(owner, samples, points.shape[0])
    out = points.copy()
    has = count > 0
    out[has] = sums[has] / count[has, None]
    return out


def cell_centroids(mesh: PolyhedralMesh, inside: np.ndarray) -> np.ndarray:
    """Volume centroids: the pyramids from a point ``inside`` every cell to its faces (a pyramid's
    centroid lies 3/4 of the way from its apex to its base's centroid)."""
    faces = np.where(mesh.cell_faces >= 0, mesh.cell_faces, -mesh.cell_faces - 1)
    sign = np.where(mesh.cell_faces >= 0, 1.0, -1.0)
    cells = np.repeat(np.arange(mesh.n_cells), np.diff(mesh.cell_offsets))
    x = mesh.face_centroids[faces] - inside[cells]
    vol = sign * np.einsum("ij,ij->i", x, mesh.face_vector_areas[faces]) / 3.0
    total = np.bincount(cells, weights=vol, minlength=mesh.n_cells)
    moment = np.stack([np.bincount(cells, weights=vol * 0.75 * x[:, a], minlength=mesh.n_cells) for a in range(3)], 1)
    return inside + moment / total[:, None]


def _mirrored(points, lower, upper, margin):
    """Seeds and their mirrors across the faces they are within ``margin`` of; (all, plane of each mirror)."""
    out, plane = [points], [np.full(points.shape[0], -1)]
    for k in range(6):
        axis, value = k // 2, (lower, upper)[k % 2][k // 2]
        near = np.flatnonzero(np.abs(points[:, axis] - value) <= margin)
        q = points[near].copy()
        q[:, axis] = 2.0 * value - q[:, axis]
        out.append(q)
        plane.append(np.full(near.size, k))
    return np.concatenate(out), np.concatenate(plane)


def _diagram(points, lower, upper):
    """(vertices, ridge_points, ridge sizes, flat ridge vertices, plane of every point, merge tolerance,
    seeds and mirrors) with every
    original cell bounded and inside the box (the margin grows until it is so)."""
    count = points.shape[0]
    size = float(np.max(upper - lower))
    step = (float(np.prod(upper - lower)) / count) ** (1.0 / 3.0)
    margin = min(1.5 * step, size)
    while True:
        allpoints, plane = _mirrored(points, lower, upper, margin)
        vor = Voronoi(allpoints)
        pairs = vor.ridge_points
        keep = np.flatnonzero(pairs.min(axis=1) < count)
        ridges = [vor.ridge_vertices[r] for r in keep]
        sizes = np.fromiter(map(len, ridges), dtype=np.int64, count=len(ridges))
        flat = np.fromiter(itertools.chain.from_iterable(ridges), dtype=np.int64, count=int(sizes.sum()))
        tol = MERGE_TOL * step
        ok = flat.size and flat.min() >= 0
        if ok:
            v = vor.vertices[flat]
            ok = bool(((v >= lower - 1e-6 * step) & (v <= upper + 1e-6 * step)).all())
        if ok or margin >= size:
            if not ok:
                raise RuntimeError("the clipped Voronoi diagram has a cell outside the box; give another seed")
            return vor.vertices.copy(), pairs[keep], sizes, flat, plane, tol, allpoints
        margin = min(2.0 * margin, size)


def _merge_vertices(vertices, sizes, flat, tol):
    """Merge vertices closer than tol; drop repeated (cyclically consecutive) vertices in each ridge."""
    referenced = np.zeros(vertices.shape[0], dtype=bool)
    referenced[flat] = True
    used = np.flatnonzero(referenced)  # np.unique(flat), without the sort
    pairs = cKDTree(vertices[used]).query_pairs(tol, output_type="ndarray")
    if pairs.size:
        graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(used.size, used.size))
        _, label = connected_components(graph, directed=False)
    else:
        label = np.arange(used.size)
    new = label[(np.cumsum(referenced) - 1)[flat]]
    owner = np.repeat(np.arange(sizes.size), sizes)
    start = np.repeat(np.cumsum(sizes) - sizes, sizes)
    nxt = np.where(np.arange(flat.size) + 1 - start == np.repeat(sizes, sizes), start, np.arange(flat.size) + 1)
    keep = new != new[nxt]
    first = np.zeros(label.max() + 1, dtype=np.int64)
    first[label] = np.arange(used.size)  # one representative vertex per group
    points = vertices[used[first]]
    return points, np.bincount(owner[keep], minlength=sizes.size), new[keep]


def clipped_voronoi(points, lower, upper, sides=BOX_SIDES) -> PolyhedralMesh:
    """The Voronoi cells of ``points`` (inside the box) cut by the box (module doc); cell i is seed i."""
    count = points.shape[0]
    vertices, pairs, sizes, flat, plane, tol, allpoints = _diagram(points, lower, upper)
    for k in range(6):  # put the vertices on the box faces exactly
        axis, value = k // 2, (lower, upper)[k % 2][k // 2]
        vertices[np.abs(vertices[:, axis] - value) <= tol, axis] = value
    vertices, sizes, flat = _merge_vertices(vertices, sizes, flat, tol)
    good = sizes >= 3
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    flat = flat[np.repeat(good, sizes)]
    pairs, sizes = pairs[good], sizes[good]
    a = np.where(pairs[:, 0] < count, pairs[:, 0], pairs[:, 1])
    b = np.where(pairs[:, 0] < count, pairs[:, 1], pairs[:, 0])
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    mesh = PolyhedralMesh(vertices, offsets, flat, np.zeros(1, np.int64), np.zeros(0, np.int64))
    direction = allpoints[b] - allpoints[a]
    flip = np.einsum("ij,ij->i", mesh.face_vector_areas, direction) < 0
    flat = _reverse_faces(offsets, flat, flip)
    faces = np.arange(sizes.size)
    inner = b < count
    owner = np.concatenate([a, b[inner]])
    signed = np.concatenate([faces, -faces[inner] - 1])
    order = np.argsort(owner, kind="stable")
    cell_offsets = np.concatenate([[0], np.cumsum(np.bincount(owner, minlength=count))])
    boundary = {}
    for k, name in enumerate(sides):
        part = faces[~inner][plane[b[~inner]] == k]
        boundary[name] = np.concatenate([boundary.get(name, np.zeros(0, np.int64)), part])
    return PolyhedralMesh(vertices, offsets, flat, cell_offsets, signed[order], boundary, {})


def _reverse_faces(offsets, flat, flip):
    sizes = np.diff(offsets)
    start = np.repeat(offsets[:-1], sizes)
    local = np.arange(flat.size) - start
    rev = start + np.repeat(sizes, sizes) - 1 - local
    return np.where(np.repeat(flip, sizes), flat[rev], flat)
