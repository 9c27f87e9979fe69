"""Generalized barycentric interpolation of vertex values on polygonal meshes (docs/reference/mathematics.md).

The paper's error measure interpolates a coarse solution u_h, known at the coarse vertices, at
the vertices of the 2^-8 reference mesh: I u_h(x) = sum_i phi_i(x) u_h(v_i), x in the coarse cell
K = (v_0, ..., v_{n-1}) (counter-clockwise). On the paper's nested square meshes this is the
bilinear interpolant. To apply the same measure to every mesh family, phi_i are generalized
barycentric coordinates that are bilinear on rectangles:

- **Wachspress coordinates** on strictly convex cells (every interior angle < 180°):
  w_i(x) = C_i prod_{j != i-1, i} A_j(x), phi_i = w_i / sum_k w_k, with
  C_i = area(v_{i-1}, v_i, v_{i+1}) and A_j(x) = area(x, v_j, v_{j+1}). They are the barycentric
  coordinates on triangles, bilinear on rectangles (and parallelograms), non-negative, a partition
  of unity and reproduce linear fields. The product form (no division by A_j) stays defined on
  the cell boundary, where it reduces to linear interpolation along the edge, so the interpolant
  is continuous across cells.
- **Mean value coordinates** (Floater 2003; Hormann & Floater 2006) on every other cell: a cell
  with a hanging node (a degenerate polygon: 180° at the hanging node) or a reflex vertex.
  Wachspress is undefined there: C_h = 0 at a hanging node, so its weight vanishes identically,
  the interpolant would ignore the hanging node's value and not match the neighbouring cell along
  the split edge (and on a non-convex cell the Wachspress denominator can vanish inside).
  Mean value coordinates are defined on any simple polygon, reproduce linear fields, are
  piecewise linear along the boundary (so they match the neighbours, hanging nodes included)
  and non-negative on convex cells, degenerate ones included; on a non-convex cell they can be
  negative. They are not bilinear on rectangles, but a cell with a hanging node is not a
  4-vertex rectangle. w_i = (t_{i-1} + t_i) / r_i with r_i = |v_i - x| and
  t_i = tan(alpha_i / 2) = 2 A_i / (r_i r_{i+1} + s_i . s_{i+1}) = (r_i r_{i+1} - s_i . s_{i+1}) / (2 A_i),
  alpha_i the angle at x of (x, v_i, v_{i+1}) and s_i = v_i - x (the first form where
  s_i . s_{i+1} >= 0, the second elsewhere: no cancellation); a point within 1e-12 (relative) of
  an edge takes the linear interpolation along that edge.

The Numba kernels are pinned by the tests (linear and bilinear precision, partition of unity,
agreement with the tensor bilinear formula on square meshes).
"""

from __future__ import annotations

import numba
import numpy as np

from vemkit.mesh.geometry import turn
from vemkit.mesh.locate import locate_points
from vemkit.mesh.mesh import Mesh
from vemkit.vem.elements.k1_kernel import cell_coordinates

WACHSPRESS = 0
MEAN_VALUE = 1
CONVEX_TOLERANCE = 1e-10  # |sin| of the turning angle below which a vertex counts as straight (180°)


@numba.njit(cache=True)
def _cell_kinds(vertices, offsets, cell_vertices, tol, kinds):
    """WACHSPRESS where every vertex turns left by more than ``tol`` (|sin|), else MEAN_VALUE."""
    for c in range(offsets.shape[0] - 1):
        s = offsets[c]
        n = offsets[c + 1] - s
        kinds[c] = WACHSPRESS
        for i in range(n):
            cross, scale, _ = turn(
                vertices, cell_vertices[s + (i - 1 + n) % n], cell_vertices[s + i], cell_vertices[s + (i + 1) % n]
            )
            if cross <= tol * scale:
                kinds[c] = MEAN_VALUE
                break


def cell_kinds(mesh: Mesh) -> np.ndarray:
    """(M,) int8: WACHSPRESS (0) on strictly convex cells, MEAN_VALUE (1) on the others."""
    kinds = np.empty(mesh.n_cells, dtype=np.int8)
    _cell_kinds(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, CONVEX_TOLERANCE, kinds)
    return kinds


@numba.njit(cache=True)
def wachspress(px, py, x, y, phi):
    """Wachspress coordinates phi (n,) of (x, y) in the strictly convex polygon (px, py), CCW."""
    n = px.shape[0]
    # scale to O(1): the product of n - 2 areas neither under- nor overflows
    inv = 1.0 / max(np.max(px) - np.min(px), np.max(py) - np.min(py))
    area = np.empty(n)  # area[j] = A_j(x) of (x, v_j, v_{j+1})
    for j in range(n):
        k = (j + 1) % n
        ax, ay = (px[j] - x) * inv, (py[j] - y) * inv
        bx, by = (px[k] - x) * inv, (py[k] - y) * inv
        area[j] = 0.5 * (ax * by - ay * bx)
    total = 0.0
    for i in range(n):
        im, ip = (i - 1 + n) % n, (i + 1) % n
        ux, uy = (px[i] - px[im]) * inv, (py[i] - py[im]) * inv
        vx, vy = (px[ip] - px[i]) * inv, (py[ip] - py[i]) * inv
        w = 0.5 * (ux * vy - uy * vx)  # C_i
        for j in range(n):
            if j != im and j != i:
                w *= area[j]
        phi[i] = w
        total += w
    for i in range(n):
        phi[i] /= total


@numba.njit(cache=True)
def mean_value(px, py, x, y, phi):
    """Mean value coordinates phi (n,) of (x, y) in the simple polygon (px, py), CCW."""
    n = px.shape[0]
    inv = 1.0 / max(np.max(px) - np.min(px), np.max(py) - np.min(py))
    sx = np.empty(n)
    sy = np.empty(n)
    r = np.empty(n)
    for i in range(n):
        sx[i] = (px[i] - x) * inv
        sy[i] = (py[i] - y) * inv
        r[i] = np.sqrt(sx[i] * sx[i] + sy[i] * sy[i])
        phi[i] = 0.0
    for i in range(n):  # x at a vertex
        if r[i] <= 1e-14:
            phi[i] = 1.0
            return
    t = np.empty(n)
    for i in range(n):
        k = (i + 1) % n
        cross = sx[i] * sy[k] - sy[i] * sx[k]  # 2 A_i
        dot = sx[i] * sx[k] + sy[i] * sy[k]
        if abs(cross) <= 1e-12 * r[i] * r[k] and dot < 0.0:  # x on the edge (v_i, v_{i+1})
            phi[i] = r[k] / (r[i] + r[k])
            phi[k] = r[i] / (r[i] + r[k])
            return
        # tan(alpha/2) = 2A / (r r' + s.s') = (r r' - s.s') / 2A: the form without cancellation
        t[i] = cross / (r[i] * r[k] + dot) if dot >= 0.0 else (r[i] * r[k] - dot) / cross
    total = 0.0
    for i in range(n):
        w = (t[(i - 1 + n) % n] + t[i]) / r[i]
        phi[i] = w
        total += w
    for i in range(n):
        phi[i] /= total


@numba.njit(cache=True)
def _interpolate(vertices, offsets, cell_vertices, kinds, cells, points, values, out):
    """out[p] = sum_i phi_i(points[p]) values[v_i] over the vertices v_i of cells[p]."""
    for p in range(points.shape[0]):
        c = cells[p]
        s = offsets[c]
        n = offsets[c + 1] - s
        px, py = cell_coordinates(vertices, offsets, cell_vertices, c)
        phi = np.empty(n)
        if kinds[c] == WACHSPRESS:
            wachspress(px, py, points[p, 0], points[p, 1], phi)
        else:
            mean_value(px, py, points[p, 0], points[p, 1], phi)
        for k in range(values.shape[1]):
            acc = 0.0
            for i in range(n):
                acc += phi[i] * values[cell_vertices[s + i], k]
            out[p, k] = acc


def coordinates(px, py, points, kind: int = WACHSPRESS) -> np.ndarray:
    """(P, n) generalized barycentric coordinates of ``points`` in one polygon (px, py)."""
    px, py = np.ascontiguousarray(px, dtype=float), np.ascontiguousarray(py, dtype=float)
    points = np.ascontiguousarray(points, dtype=float).reshape(-1, 2)
    out = np.empty((points.shape[0], px.shape[0]))
    kernel = wachspress if kind == WACHSPRESS else mean_value
    for p in range(points.shape[0]):
        kernel(px, py, points[p, 0], points[p, 1], out[p])
    return out


def interpolate(
    mesh: Mesh, values: np.ndarray, points: np.ndarray, cells: np.ndarray | None = None, kinds: np.ndarray | None = None
) -> np.ndarray:
    """Values (P, k) at ``points`` of the generalized barycentric interpolant of the vertex
    ``values`` (N, k) or (N,) on ``mesh``. ``cells``: a cell containing each point (default:
    located with ``vemkit.mesh.locate.locate_points``); ``kinds``: from :func:`cell_kinds`."""
    points = np.ascontiguousarray(points, dtype=float).reshape(-1, 2)
    vals = np.asarray(values, dtype=float)
    flat = vals.ndim == 1
    vals = np.ascontiguousarray(vals.reshape(mesh.n_vertices, -1))
    if cells is None:
        cells = locate_points(mesh, points)
    cells = np.ascontiguousarray(cells, dtype=np.int64)
    if np.any(cells < 0):
        raise ValueError(f"{int(np.sum(cells < 0))} interpolation points lie outside the mesh")
    kinds = cell_kinds(mesh) if kinds is None else np.ascontiguousarray(kinds, dtype=np.int8)
    out = np.empty((points.shape[0], vals.shape[1]))
    _interpolate(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, kinds, cells, points, vals, out)
    return out[:, 0] if flat else out
