"""The error measures of Table 1 (SPEC §5) and errors against exact solutions.

Three measures between a coarse solution u_h and the reference u_ref (the 2^-8 square mesh):

- ``projection_error``: ||Pi_1 (u_h - u_ref)||_{H1} / ||Pi_1 u_ref||_{H1} (full H1 norm, and the
  H1 seminorm), Pi_1 the elementwise projection (3.8) of each solution on its own mesh, the broken
  norm taken over the reference mesh. The integrals use a degree-2 rule on a triangulation of
  every reference cell, every quadrature point located in the coarse mesh: exact when each
  reference cell lies in one coarse cell (nested square meshes); for non-nested meshes the
  quadrature resolves the coarse cell boundaries to the reference mesh size.
- ``paper_error``, the paper's own measure (the one its Table 1 prints):
  e_h = |Pi_1^ref (I_ref u_h - u_ref)|_{H1} / |Pi_1^ref u_ref|_{H1}, I_ref u_h the interpolant of
  the coarse vertex values at the reference vertices (bilinear on square meshes, generalized
  barycentric on the other families: ``vemkit.vem.interpolation``), Pi_1^ref the projection (3.8)
  on the reference cells, the H1 seminorm broken over the reference cells (Pi_1 has a constant
  gradient per cell, so the integral is exact).
"""

from __future__ import annotations

import numba
import numpy as np

from vemkit.vem.interpolation import interpolate
from vemkit.vem.projection import ProjectedSolution, projected_solution
from vemkit.mesh.geometry import bin_boxes
from vemkit.mesh.mesh import Mesh

# degree-2 rule on triangles (barycentric coordinates, weights summing to 1)
_DEGREE2 = np.array([[2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]])
_DEGREE2_WEIGHTS = np.full(3, 1 / 3)


@numba.njit(cache=True)
def _cell_bin_boxes(vertices, offsets, cell_vertices, lo, inv, nb):
    """(M, 4) bins (i0, i1, j0, j1) covered by the bounding box of every cell."""
    n_cells = offsets.shape[0] - 1
    boxes = np.empty((n_cells, 4), dtype=np.int64)
    for c in range(n_cells):
        x0 = 1e300
        x1 = -1e300
        y0 = 1e300
        y1 = -1e300
        for p in range(offsets[c], offsets[c + 1]):
            v = cell_vertices[p]
            x0 = min(x0, vertices[v, 0])
            x1 = max(x1, vertices[v, 0])
            y0 = min(y0, vertices[v, 1])
            y1 = max(y1, vertices[v, 1])
        boxes[c, 0] = min(nb - 1, max(0, int((x0 - lo[0]) * inv[0])))
        boxes[c, 1] = min(nb - 1, max(0, int((x1 - lo[0]) * inv[0])))
        boxes[c, 2] = min(nb - 1, max(0, int((y0 - lo[1]) * inv[1])))
        boxes[c, 3] = min(nb - 1, max(0, int((y1 - lo[1]) * inv[1])))
    return boxes


@numba.njit(cache=True)
def _winding_inside(vertices, offsets, cell_vertices, c, x, y):
    """Crossing-number point-in-polygon test (points on an edge count as inside)."""
    s = offsets[c]
    n = offsets[c + 1] - s
    inside = False
    for i in range(n):
        a = cell_vertices[s + i]
        b = cell_vertices[s + (i + 1) % n]
        xa, ya = vertices[a, 0], vertices[a, 1]
        xb, yb = vertices[b, 0], vertices[b, 1]
        cross = (xb - xa) * (y - ya) - (yb - ya) * (x - xa)
        if abs(cross) <= 1e-14 * (abs(xb - xa) + abs(yb - ya)) and min(xa, xb) - 1e-14 <= x <= max(xa, xb) + 1e-14 and min(ya, yb) - 1e-14 <= y <= max(ya, yb) + 1e-14:
            return True
        if (ya > y) != (yb > y):
            xi = xa + (y - ya) * (xb - xa) / (yb - ya)
            if x < xi:
                inside = not inside
    return inside


@numba.njit(cache=True)
def _locate(vertices, offsets, cell_vertices, lo, inv, nb, count, members, points, out):
    for p in range(points.shape[0]):
        x, y = points[p, 0], points[p, 1]
        i = min(nb - 1, max(0, int((x - lo[0]) * inv[0])))
        j = min(nb - 1, max(0, int((y - lo[1]) * inv[1])))
        b = j * nb + i
        out[p] = -1
        for t in range(count[b], count[b + 1]):
            c = members[t]
            if _winding_inside(vertices, offsets, cell_vertices, c, x, y):
                out[p] = c
                break


def locate_points(mesh: Mesh, points: np.ndarray) -> np.ndarray:
    """Index of a cell containing each point (-1 outside the mesh)."""
    points = np.ascontiguousarray(points, dtype=float)
    lo = mesh.vertices.min(axis=0)
    hi = mesh.vertices.max(axis=0)
    nb = max(1, int(np.sqrt(mesh.n_cells)))
    inv = nb / np.maximum(hi - lo, 1e-300) * (1 - 1e-12)
    count, members = bin_boxes(_cell_bin_boxes(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, lo, inv, nb), nb)
    out = np.empty(points.shape[0], dtype=np.int64)
    _locate(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, lo, inv, nb, count, members, points, out)
    return out


def reference_quadrature(mesh: Mesh, degree: int = 2):
    """Quadrature (degree 2 or 5) on a triangulation of the cells: points (P, 2), weights (P,), cell (P,)."""
    from vemkit.vem.load import TRIANGLE_RULE
    from vemkit.mesh.triangulate import triangulate_cells

    bary, w = (_DEGREE2, _DEGREE2_WEIGHTS) if degree <= 2 else (TRIANGLE_RULE[:, :3], TRIANGLE_RULE[:, 3])
    tri, parent = triangulate_cells(mesh)
    p = mesh.vertices[tri]
    area = 0.5 * np.abs((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))
    points = np.einsum("qk,tkc->tqc", bary, p).reshape(-1, 2)
    weights = (area[:, None] * w[None, :]).ravel()
    cells = np.repeat(parent, bary.shape[0])
    return points, weights, cells


def projection_error(coarse_mesh: Mesh, coarse: ProjectedSolution, ref_mesh: Mesh, ref: ProjectedSolution, quadrature=None):
    """Relative errors of Pi_1 u_h against Pi_1 u_ref over the reference mesh (SPEC §5).

    Returns {"h1": full H1 norm ratio, "h1_semi": seminorm ratio, "l2": L2 ratio}.
    ``quadrature`` (from ``reference_quadrature(ref_mesh)``) may be passed to reuse it.
    """
    points, weights, ref_cells = quadrature if quadrature is not None else reference_quadrature(ref_mesh)
    coarse_cells = locate_points(coarse_mesh, points)
    if np.any(coarse_cells < 0):
        raise ValueError("the reference mesh is not covered by the coarse mesh (different domains?)")
    diff = coarse.evaluate(coarse_cells, points) - ref.evaluate(ref_cells, points)
    grad = coarse.gradient[coarse_cells] - ref.gradient[ref_cells]
    l2 = np.sum(weights * np.sum(diff**2, axis=1))
    semi = np.sum(weights * np.sum(grad**2, axis=(1, 2)))
    ref_l2 = np.sum(weights * np.sum(ref.evaluate(ref_cells, points) ** 2, axis=1))
    ref_semi = np.sum(weights * np.sum(ref.gradient[ref_cells] ** 2, axis=(1, 2)))
    return {
        "h1": float(np.sqrt((l2 + semi) / (ref_l2 + ref_semi))),
        "h1_semi": float(np.sqrt(semi / ref_semi)),
        "l2": float(np.sqrt(l2 / ref_l2)),
    }


def seminorm_squared(areas: np.ndarray, gradient: np.ndarray) -> float:
    """|v|_{H1}^2 = sum_K |K| |grad v|_K|^2 of a field with a constant gradient (M, 2, 2) per cell."""
    return float(np.sum(areas * np.sum(gradient**2, axis=(1, 2))))


def paper_error(coarse_mesh: Mesh, u_coarse: np.ndarray, ref_mesh: Mesh, u_ref: np.ndarray,
                ref_projected: ProjectedSolution | None = None, ref_areas: np.ndarray | None = None) -> float:
    """The paper's measure |Pi_1^ref (I_ref u_h - u_ref)|_{H1} / |Pi_1^ref u_ref|_{H1} (SPEC §5).

    ``u_coarse`` (N_h, 2) and ``u_ref`` (N_ref, 2) are vertex values. ``ref_projected``
    (Pi_1^ref u_ref) and ``ref_areas`` (``ref_mesh.cell_areas``) may be passed to reuse them.
    """
    u_ref = np.asarray(u_ref, dtype=float).reshape(ref_mesh.n_vertices, 2)
    u_interpolated = interpolate(coarse_mesh, np.asarray(u_coarse, dtype=float).reshape(-1, 2), ref_mesh.vertices)
    areas = ref_mesh.cell_areas if ref_areas is None else ref_areas
    ref_projected = projected_solution(ref_mesh, u_ref) if ref_projected is None else ref_projected
    difference = projected_solution(ref_mesh, u_interpolated - u_ref).gradient
    return float(np.sqrt(seminorm_squared(areas, difference) / seminorm_squared(areas, ref_projected.gradient)))


def exact_errors(mesh: Mesh, proj: ProjectedSolution, u_exact, grad_exact, quadrature=None):
    """Absolute L2 and H1-seminorm errors of Pi_1 u_h against an exact solution.

    u_exact(x, y) -> (u1, u2); grad_exact(x, y) -> ((du1/dx, du1/dy), (du2/dx, du2/dy)).
    A degree-5 rule on a triangulation of each cell is used unless ``quadrature`` is given.
    """
    points, weights, cells = quadrature if quadrature is not None else reference_quadrature(mesh, degree=5)
    ue = np.stack(u_exact(points[:, 0], points[:, 1]), axis=1)
    ge = np.asarray(grad_exact(points[:, 0], points[:, 1]), dtype=float)  # (2, 2, P)
    ge = np.moveaxis(ge, -1, 0)
    diff = proj.evaluate(cells, points) - ue
    grad = proj.gradient[cells] - ge
    return {
        "l2": float(np.sqrt(np.sum(weights * np.sum(diff**2, axis=1)))),
        "h1_semi": float(np.sqrt(np.sum(weights * np.sum(grad**2, axis=(1, 2))))),
    }


def difference_gradient(field, step: float):
    """grad_exact for :func:`exact_errors` from field(x, y) -> (u1, u2) alone, by fourth-order
    central differences of width ``step`` (truncation O(step^4), rounding O(eps / step))."""
    def grad(x, y):
        out = np.empty((2, 2) + np.shape(x))
        for axis in (0, 1):
            shifted = [field(x + s * step, y) if axis == 0 else field(x, y + s * step) for s in (-2, -1, 1, 2)]
            for c in (0, 1):
                out[c, axis] = (shifted[0][c] - 8.0 * shifted[1][c] + 8.0 * shifted[2][c] - shifted[3][c]) / (12.0 * step)
        return out
    return grad


def relative_exact_errors(mesh: Mesh, u_vertices: np.ndarray, u_exact) -> dict:
    """SPEC §7: relative errors of Pi_1 u_h against u_exact(x, y) -> (u1, u2): ``error_l2`` =
    ||Pi u_h - u|| / ||u||, ``error_h1_semi`` = |.|_1 / |u|_1, ``error_h1`` with the full H1 norm;
    a degree-5 rule on a triangulation of every cell, the gradient of u exact (``u_exact.gradient``) or,
    for a plain callable, by :func:`difference_gradient` with a step of 1e-3 times the body's size."""
    quadrature = reference_quadrature(mesh, degree=5)
    step = 1e-3 * float(np.ptp(mesh.vertices, axis=0).max())
    grad = getattr(u_exact, "gradient", None) or difference_gradient(u_exact, step)  # exact if the field has it
    absolute = exact_errors(mesh, projected_solution(mesh, u_vertices), u_exact, grad, quadrature)
    zero = exact_errors(mesh, projected_solution(mesh, np.zeros_like(u_vertices)), u_exact, grad, quadrature)
    tiny = np.finfo(float).tiny
    return {"error_l2": absolute["l2"] / max(zero["l2"], tiny),
            "error_h1_semi": absolute["h1_semi"] / max(zero["h1_semi"], tiny),
            "error_h1": float(np.hypot(absolute["l2"], absolute["h1_semi"]) / max(np.hypot(zero["l2"], zero["h1_semi"]), tiny))}
