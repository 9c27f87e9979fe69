"""Pi_2 u_h of a k = 2 solution (3.8) and its errors against an exact solution.

``projected_solution_k2(mesh, u_nodes, lam, mu)`` gives, per cell, the coefficients of Pi_2 u_h in
the element kernel's basis (rigid motions about the centroid x_K and nine non-rigid fields in
(xi, eta) = (x - x_K) / h_K; see ``vemkit.vem.element_k2``). Pi_2 depends on the material: it is
the energy projection of a_K. ``exact_errors_k2`` integrates |u - Pi_2 u_h|^2 and
|grad(u - Pi_2 u_h)|^2 with the degree-5 rule on a triangulation of every cell
(``vemkit.vem.norms.reference_quadrature``): exact for the polynomial part, O(h^6) for the rest.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from vemkit.mesh.mesh import Mesh
from vemkit.vem.assembly_k2 import cell_nodes
from vemkit.vem.element_k2 import N_BASIS, cell_projection, largest_cell, projection_workspace


@numba.njit(cache=True)
def _cell_projections(vertices, offsets, nodes, u, lam, mu, coef, frame):
    Pi, rhs, G, sig = projection_workspace(largest_cell(offsets))
    for c in range(offsets.shape[0] - 1):
        start = offsets[c]
        size, area, xc, yc, h, m20, m11, m02 = cell_projection(vertices, offsets, nodes, c, lam, mu, Pi, rhs, G, sig)
        frame[c, 0] = xc
        frame[c, 1] = yc
        frame[c, 2] = h
        for b in range(N_BASIS):
            acc = 0.0
            for i in range(size):
                acc += Pi[b, 2 * i] * u[nodes[start + i], 0] + Pi[b, 2 * i + 1] * u[nodes[start + i], 1]
            coef[c, b] = acc


@dataclass(frozen=True)
class ProjectedSolutionK2:
    """Pi_2 u on every cell: coefficients (M, 12) in the kernel's basis; frame (M, 3) = (x_K, y_K, h_K)."""

    coef: np.ndarray
    frame: np.ndarray

    def _scaled(self, cells, points):
        f = self.frame[cells]
        return (points[:, 0] - f[:, 0]) / f[:, 2], (points[:, 1] - f[:, 1]) / f[:, 2], f[:, 2]

    def evaluate(self, cells: np.ndarray, points: np.ndarray) -> np.ndarray:
        """(P, 2) values of Pi_2 u at points, each in the given cell."""
        xi, eta, _ = self._scaled(cells, points)
        c = self.coef[cells].T
        u1 = c[0] - c[2] * eta + c[3] * xi + c[5] * eta + c[6] * xi**2 + c[7] * xi * eta + c[8] * eta**2
        u2 = c[1] + c[2] * xi + c[4] * eta + c[5] * xi + c[9] * xi**2 + c[10] * xi * eta + c[11] * eta**2
        return np.stack([u1, u2], axis=1)

    def gradient(self, cells: np.ndarray, points: np.ndarray) -> np.ndarray:
        """(P, 2, 2) gradient of Pi_2 u at points: [i, j] = d u_i / d x_j."""
        xi, eta, h = self._scaled(cells, points)
        c = self.coef[cells].T
        g = np.empty((points.shape[0], 2, 2))
        g[:, 0, 0] = c[3] + 2 * c[6] * xi + c[7] * eta
        g[:, 0, 1] = -c[2] + c[5] + c[7] * xi + 2 * c[8] * eta
        g[:, 1, 0] = c[2] + c[5] + 2 * c[9] * xi + c[10] * eta
        g[:, 1, 1] = c[4] + c[10] * xi + 2 * c[11] * eta
        return g / h[:, None, None]


def projected_solution_k2(mesh: Mesh, u_nodes: np.ndarray, lam: float, mu: float) -> ProjectedSolutionK2:
    """Pi_2 of the k = 2 node values ``u_nodes`` (n_nodes, 2) on every cell."""
    offsets, nodes = cell_nodes(mesh)
    u = np.ascontiguousarray(u_nodes, dtype=float).reshape(-1, 2)
    coef = np.empty((mesh.n_cells, N_BASIS))
    frame = np.empty((mesh.n_cells, 3))
    _cell_projections(mesh.vertices, offsets, nodes, u, float(lam), float(mu), coef, frame)
    return ProjectedSolutionK2(coef, frame)


def exact_errors_k2(mesh: Mesh, proj: ProjectedSolutionK2, u_exact, grad_exact, quadrature=None) -> dict:
    """Absolute L2 and H1-seminorm errors of Pi_2 u_h against an exact solution.

    u_exact(x, y) -> (u1, u2); grad_exact(x, y) -> ((du1/dx, du1/dy), (du2/dx, du2/dy)).
    """
    from vemkit.vem.norms import reference_quadrature

    points, weights, cells = quadrature if quadrature is not None else reference_quadrature(mesh, degree=5)
    ue = np.stack(np.broadcast_arrays(*u_exact(points[:, 0], points[:, 1])), axis=1)
    ge = np.moveaxis(np.asarray(grad_exact(points[:, 0], points[:, 1]), dtype=float), -1, 0)
    diff = proj.evaluate(cells, points) - ue
    grad = proj.gradient(cells, points) - ge
    return {
        "l2": float(np.sqrt(np.sum(weights * np.sum(diff**2, axis=1)))),
        "h1_semi": float(np.sqrt(np.sum(weights * np.sum(grad**2, axis=(1, 2))))),
    }


def relative_exact_errors_k2(mesh: Mesh, proj: ProjectedSolutionK2, u_exact) -> dict:
    """SPEC §7 for k = 2: ``error_l2``, ``error_h1_semi``, ``error_h1`` of Pi_2 u_h against u_exact(x, y)
    -> (u1, u2), relative to the norms of u_exact (as ``vemkit.vem.norms.relative_exact_errors``)."""
    from vemkit.vem.norms import difference_gradient, reference_quadrature

    quadrature = reference_quadrature(mesh, degree=5)
    grad = getattr(u_exact, "gradient", None) or difference_gradient(  # exact if the field has it
        u_exact, 1e-3 * float(np.ptp(mesh.vertices, axis=0).max()))
    absolute = exact_errors_k2(mesh, proj, u_exact, grad, quadrature)
    zero = exact_errors_k2(mesh, ProjectedSolutionK2(np.zeros_like(proj.coef), proj.frame), u_exact, grad, quadrature)
    tiny = np.finfo(float).tiny
    return {"error_l2": absolute["l2"] / max(zero["l2"], tiny),
            "error_h1_semi": absolute["h1_semi"] / max(zero["h1_semi"], tiny),
            "error_h1": float(np.hypot(absolute["l2"], absolute["h1_semi"]) / max(np.hypot(zero["l2"], zero["h1_semi"]), tiny))}


def _values_and_gradients(proj, cells, points):
    """(values (P, 2), gradients (P, 2, 2)) of a k = 1 ``ProjectedSolution`` or a ``ProjectedSolutionK2``."""
    if isinstance(proj, ProjectedSolutionK2):
        return proj.evaluate(cells, points), proj.gradient(cells, points)
    return proj.evaluate(cells, points), proj.gradient[cells]


def projection_error_k2(coarse_mesh: Mesh, coarse, ref_mesh: Mesh, ref, quadrature=None, regions=None) -> dict:
    """SPEC §5's first measure for either order: ||Pi u_h - Pi u_ref|| / ||Pi u_ref|| broken over the
    reference cells, Pi = Pi_1 or Pi_2 of each solution on its own mesh (``coarse`` and ``ref`` are
    k = 1 ``ProjectedSolution`` or ``ProjectedSolutionK2``). A degree-5 rule on a triangulation of
    every reference cell: exact for two quadratic projections when each reference cell lies in one
    coarse cell (nested meshes). Returns {"h1", "h1_semi", "l2"} (full H1 norm, seminorm, L2) and,
    for every ``regions`` entry name -> mask(points) -> bool array, "share_<name>": the part of the
    squared H1-seminorm error inside it (where the error sits)."""
    from vemkit.vem.norms import locate_points, reference_quadrature

    points, weights, ref_cells = quadrature if quadrature is not None else reference_quadrature(ref_mesh, degree=5)
    coarse_cells = locate_points(coarse_mesh, points)
    if np.any(coarse_cells < 0):
        raise ValueError("the reference mesh is not covered by the coarse mesh (different domains?)")
    value_h, grad_h = _values_and_gradients(coarse, coarse_cells, points)
    value_ref, grad_ref = _values_and_gradients(ref, ref_cells, points)
    l2 = np.sum(weights * np.sum((value_h - value_ref) ** 2, axis=1))
    density = weights * np.sum((grad_h - grad_ref) ** 2, axis=(1, 2))
    semi = np.sum(density)
    ref_l2 = np.sum(weights * np.sum(value_ref**2, axis=1))
    ref_semi = np.sum(weights * np.sum(grad_ref**2, axis=(1, 2)))
    out = {"h1": float(np.sqrt((l2 + semi) / (ref_l2 + ref_semi))), "h1_semi": float(np.sqrt(semi / ref_semi)),
           "l2": float(np.sqrt(l2 / ref_l2))}
    for name, mask in (regions or {}).items():
        out[f"share_{name}"] = float(np.sum(density[mask(points)]) / semi) if semi > 0 else 0.0
    return out


def _part_edges(mesh: Mesh, parts) -> np.ndarray:
    parts = [parts] if isinstance(parts, str) else list(parts)
    return np.concatenate([np.asarray(mesh.boundary[p], dtype=np.int64).reshape(-1, 2) for p in parts])


def boundary_trace(mesh: Mesh, parts, node_values: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(P, 2) the trace of a discrete displacement on the boundary ``parts`` (a name or names) at
    ``points`` (P, 2) lying on them: linear between the vertex values (k = 1, ``node_values``
    (n_vertices, 2)) or the quadratic of Section 3.1 from the vertex values and the edge mean (k = 2,
    (n_nodes, 2)). Each point is placed on the nearest edge (O(points x edges) work)."""
    from vemkit.vem.assembly_k2 import edge_indices
    from vemkit.vem.load_k2 import trace_weights

    edges = _part_edges(mesh, parts)
    a, b = mesh.vertices[edges[:, 0]], mesh.vertices[edges[:, 1]]
    d = b - a
    t = np.einsum("pek,ek->pe", points[:, None, :] - a[None], d) / np.sum(d * d, axis=1)[None]
    t = np.clip(t, 0.0, 1.0)
    gap = np.linalg.norm(a[None] + t[..., None] * d[None] - points[:, None, :], axis=2)
    e = np.argmin(gap, axis=1)
    s = t[np.arange(points.shape[0]), e]
    values = np.asarray(node_values, dtype=float).reshape(-1, 2)
    ua, ub = values[edges[e, 0]], values[edges[e, 1]]
    if values.shape[0] == mesh.n_vertices:  # k = 1: linear trace
        return (1 - s)[:, None] * ua + s[:, None] * ub
    mean = values[mesh.n_vertices + edge_indices(mesh, edges[e])]
    w = trace_weights(s)
    return w[:, 0:1] * ua + w[:, 1:2] * ub + w[:, 2:3] * mean


def trace_error(coarse_mesh: Mesh, coarse_values, ref_mesh: Mesh, ref_values, parts, points: int = 5) -> float:
    """||u_h - u_ref||_{L2(parts)} / ||u_ref||_{L2(parts)}: the traces (``boundary_trace``) compared at
    ``points`` Gauss points on every edge of the reference mesh's ``parts`` (exact for nested meshes)."""
    from vemkit.vem.load import edge_quadrature

    edges = _part_edges(ref_mesh, parts)
    s, w = edge_quadrature(points)
    a, b = ref_mesh.vertices[edges[:, 0]], ref_mesh.vertices[edges[:, 1]]
    x = (a[:, None, :] * (1 - s)[None, :, None] + b[:, None, :] * s[None, :, None]).reshape(-1, 2)
    weights = (np.linalg.norm(b - a, axis=1)[:, None] * w[None, :]).ravel()
    ref = boundary_trace(ref_mesh, parts, ref_values, x)
    diff = boundary_trace(coarse_mesh, parts, coarse_values, x) - ref
    return float(np.sqrt(np.sum(weights * np.sum(diff**2, axis=1)) / np.sum(weights * np.sum(ref**2, axis=1))))


def trace_errors(mesh: Mesh, parts, node_values, field, subdivisions: int = 4, points: int = 5) -> dict:
    """The errors on the boundary ``parts`` against a field known everywhere on them, relative to
    ||u||_{L2(parts)}: ``contact_l2`` = ||u - u_h|| (the discrete trace, ``boundary_trace``) and
    ``interpolation_contact_l2`` = ||u - I_h u||, I_h u the trace of the interpolant of the same order
    as ``node_values`` (k = 1: linear between the vertex values; k = 2: the quadratic with the vertex
    values and the edge mean, Section 3.1) -- the term ||u - u_I||_{L2(Gamma_C)} of the paper's a
    priori estimate, whose square root gives its O(h^{k/2 + 1/2}) = O(h^{3/2}) claim for k = 2.

    ``field(points (P, 2)) -> (P, 2)``. Every edge is cut into ``subdivisions`` equal pieces with a
    ``points``-point Gauss rule each (exact for a piecewise quadratic field whose pieces nest)."""
    from vemkit.vem.load import edge_quadrature
    from vemkit.vem.load_k2 import trace_weights

    edges = _part_edges(mesh, parts)
    s, w = edge_quadrature(points)
    t = ((np.arange(subdivisions)[:, None] + s[None, :]) / subdivisions).ravel()
    weights = np.tile(w, subdivisions) / subdivisions
    a, b = mesh.vertices[edges[:, 0]], mesh.vertices[edges[:, 1]]
    x = a[:, None, :] + t[None, :, None] * (b - a)[:, None, :]  # (E, Q, 2)
    lengths = np.linalg.norm(b - a, axis=1)
    exact = np.asarray(field(x.reshape(-1, 2)), dtype=float).reshape(x.shape)
    discrete = boundary_trace(mesh, parts, node_values, x.reshape(-1, 2)).reshape(x.shape)
    ua, ub = np.asarray(field(a), dtype=float), np.asarray(field(b), dtype=float)
    if np.asarray(node_values).reshape(-1, 2).shape[0] == mesh.n_vertices:  # k = 1
        interpolant = (1 - t)[None, :, None] * ua[:, None] + t[None, :, None] * ub[:, None]
    else:
        mean = np.einsum("q,eqk->ek", weights, exact)
        tw = trace_weights(t)
        interpolant = (tw[None, :, 0:1] * ua[:, None] + tw[None, :, 1:2] * ub[:, None]
                       + tw[None, :, 2:3] * mean[:, None])
    dx = lengths[:, None] * weights[None, :]
    norm = np.sqrt(np.sum(dx * np.sum(exact**2, axis=2)))
    return {"contact_l2": float(np.sqrt(np.sum(dx * np.sum((discrete - exact) ** 2, axis=2))) / norm),
            "interpolation_contact_l2": float(np.sqrt(np.sum(dx * np.sum((interpolant - exact) ** 2, axis=2))) / norm)}


def nesting_subdivisions(mesh: Mesh, ref_mesh: Mesh, parts) -> int:
    """The power of two m such that 1/m of the longest edge of ``mesh`` on ``parts`` is at most the
    shortest reference edge there: with nested dyadic meshes, each piece then lies in one reference edge."""
    def lengths(m):
        edges = _part_edges(m, parts)
        return np.linalg.norm(m.vertices[edges[:, 1]] - m.vertices[edges[:, 0]], axis=1)

    ratio = lengths(mesh).max() / lengths(ref_mesh).min()
    return int(2 ** max(0, int(np.ceil(np.log2(ratio) - 1e-9))))
