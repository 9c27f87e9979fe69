"""Error measures, for every element: Table 1's (docs/reference/mathematics.md), against exact solutions (docs/reference/files.md) and on Gamma_C.

Between a coarse solution u_h and the reference u_ref (the 2^-8 square mesh):

- ``projection_error``: ||Pi (u_h - u_ref)||_{H1} / ||Pi u_ref||_{H1} (full H1 norm, and the H1
  seminorm), Pi the elementwise projection (3.8) of each solution on its own mesh (Pi_1 or Pi_2,
  any object with ``evaluate`` and ``gradient_at``), the broken norm taken over the reference mesh.
  The integrals use a rule on a triangulation of every reference cell (degree 2 by default, 5 for
  quadratic projections), every quadrature point located in the coarse mesh: exact when each
  reference cell lies in one coarse cell (nested square meshes). ``regions`` adds the share of the
  squared seminorm error inside given masks.
- ``paper_error``, the paper's own measure (the one its Table 1 prints, k = 1):
  e_h = |Pi_1^ref (I_ref u_h - u_ref)|_{H1} / |Pi_1^ref u_ref|_{H1}, I_ref u_h the interpolant of
  the coarse vertex values at the reference vertices (bilinear on square meshes, generalized
  barycentric on the other families: ``vemkit.vem.interpolation``), Pi_1^ref the projection (3.8)
  on the reference cells, the H1 seminorm broken over the reference cells.

Against an exact solution: ``exact_errors`` (absolute) and ``relative_exact_errors`` (the solution
file's ``error_l2``, ``error_h1_semi``, ``error_h1``), degree-5 rule on a cell triangulation. On
Gamma_C: ``trace_error`` (against a reference) and ``trace_errors`` (against a field, with the
interpolation error ||u - I_h u|| of the paper's estimate), through the space's trace.
"""

from __future__ import annotations

import numpy as np

from vemkit.mesh.locate import locate_points
from vemkit.mesh.mesh import Mesh
from vemkit.vem.elements.k1_fields import ProjectedSolution, projected_solution
from vemkit.vem.interpolation import interpolate
from vemkit.vem.quadrature import edge_quadrature, reference_quadrature

__all__ = [
    "difference_gradient",
    "exact_errors",
    "nesting_subdivisions",
    "paper_error",
    "projection_error",
    "error_quadrature",
    "relative_exact_errors",
    "seminorm_squared",
    "trace_error",
    "trace_errors",
]


def projection_error(coarse_mesh: Mesh, coarse, ref_mesh: Mesh, ref, quadrature=None, regions=None) -> dict:
    """Relative errors of Pi u_h against Pi u_ref over the reference mesh (docs/reference/mathematics.md).

    Returns {"h1": full H1 norm ratio, "h1_semi": seminorm ratio, "l2": L2 ratio} and, for every
    ``regions`` entry name -> mask(points) -> bool array, "share_<name>": the part of the squared
    H1-seminorm error inside it. ``quadrature`` (from ``reference_quadrature(ref_mesh, degree)``) may
    be passed to reuse it; by default its degree is that of the product of the two projections (2 for
    two k = 1 projections, 4 -> the degree-5 rule with a k = 2 one).
    """
    degree = getattr(coarse, "degree", 1) + getattr(ref, "degree", 1)
    points, weights, ref_cells = quadrature if quadrature is not None else reference_quadrature(ref_mesh, degree)
    coarse_cells = locate_points(coarse_mesh, points)
    if np.any(coarse_cells < 0):
        raise ValueError("the reference mesh is not covered by the coarse mesh (different domains?)")
    value_h, grad_h = coarse.evaluate(coarse_cells, points), coarse.gradient_at(coarse_cells, points)
    value_ref, grad_ref = ref.evaluate(ref_cells, points), ref.gradient_at(ref_cells, points)
    l2 = np.sum(weights * np.sum((value_h - value_ref) ** 2, axis=1))
    density = weights * np.sum((grad_h - grad_ref) ** 2, axis=(1, 2))
    semi = np.sum(density)
    ref_l2 = np.sum(weights * np.sum(value_ref**2, axis=1))
    ref_semi = np.sum(weights * np.sum(grad_ref**2, axis=(1, 2)))
    out = {
        "h1": float(np.sqrt((l2 + semi) / (ref_l2 + ref_semi))),
        "h1_semi": float(np.sqrt(semi / ref_semi)),
        "l2": float(np.sqrt(l2 / ref_l2)),
    }
    for name, mask in (regions or {}).items():
        out[f"share_{name}"] = float(np.sum(density[mask(points)]) / semi) if semi > 0 else 0.0
    return out


def seminorm_squared(areas: np.ndarray, gradient: np.ndarray) -> float:
    """|v|_{H1}^2 = sum_K |K| |grad v|_K|^2 of a field with a constant gradient (M, 2, 2) per cell."""
    return float(np.sum(areas * np.sum(gradient**2, axis=(1, 2))))


def paper_error(
    coarse_mesh: Mesh,
    u_coarse: np.ndarray,
    ref_mesh: Mesh,
    u_ref: np.ndarray,
    ref_projected: ProjectedSolution | None = None,
    ref_areas: np.ndarray | None = None,
) -> float:
    """The paper's measure |Pi_1^ref (I_ref u_h - u_ref)|_{H1} / |Pi_1^ref u_ref|_{H1} (docs/reference/mathematics.md).

    ``u_coarse`` (N_h, 2) and ``u_ref`` (N_ref, 2) are vertex values. ``ref_projected``
    (Pi_1^ref u_ref) and ``ref_areas`` (``ref_mesh.cell_areas``) may be passed to reuse them.
    """
    u_ref = np.asarray(u_ref, dtype=float).reshape(ref_mesh.n_vertices, 2)
    u_interpolated = interpolate(coarse_mesh, np.asarray(u_coarse, dtype=float).reshape(-1, 2), ref_mesh.vertices)
    areas = ref_mesh.cell_areas if ref_areas is None else ref_areas
    ref_projected = projected_solution(ref_mesh, u_ref) if ref_projected is None else ref_projected
    difference = projected_solution(ref_mesh, u_interpolated - u_ref).gradient
    return float(np.sqrt(seminorm_squared(areas, difference) / seminorm_squared(areas, ref_projected.gradient)))


#: points per direction of the collapsed Gauss rule on every tetrahedron of a 3D cell's fan
#: (``k1_3d_fields.tetrahedron_rule``: exact for degree 2 points - 3; 4 -> degree 5, as the 2D rule)
QUADRATURE_POINTS_3D = 4
#: on a 3D mesh the exact field is evaluated on at most this many quadrature points at once (bounded
#: memory); 2D sums in one piece, as before
CHUNK_POINTS_3D = 200_000


def _plane_rule(mesh, degree: int):
    return reference_quadrature(mesh, degree=degree)


def _polyhedral_rule(mesh, degree: int):
    from vemkit.vem.elements.k1_3d_fields import cell_quadrature  # the 3D element's own rule

    return cell_quadrature(mesh, QUADRATURE_POINTS_3D)


#: dimension -> (the rule of the exact errors on a mesh, at most how many points are evaluated at once)
ERROR_RULES = {2: (_plane_rule, None), 3: (_polyhedral_rule, CHUNK_POINTS_3D)}


def error_quadrature(mesh, degree: int = 5):
    """(points (Q, d), weights (Q,), cells (Q,)) for the exact errors (``ERROR_RULES``): in 2D the
    degree-``degree`` rule on a triangulation of every cell; on a 3D mesh the signed tetrahedral fan
    of ``k1_3d_fields.cell_quadrature`` with QUADRATURE_POINTS_3D points per direction."""
    rule, _chunk = ERROR_RULES[mesh.dimension]
    return rule(mesh, degree)


def exact_errors(mesh: Mesh, proj, u_exact, grad_exact, quadrature=None) -> dict:
    """Absolute L2 and H1-seminorm errors of Pi u_h (any projection) against an exact solution.

    u_exact(x, y) -> (u1, u2); grad_exact(x, y) -> ((du1/dx, du1/dy), (du2/dx, du2/dy)); on a 3D
    mesh u_exact(x, y, z) -> (u1, u2, u3) and grad_exact(x, y, z) -> (3, 3, ...).
    The rule of :func:`error_quadrature` is used unless ``quadrature`` is given.
    """
    points, weights, cells = quadrature if quadrature is not None else error_quadrature(mesh)
    l2 = semi = l2_exact = semi_exact = 0.0
    chunk = ERROR_RULES[points.shape[1]][1] or max(points.shape[0], 1)
    for start in range(0, points.shape[0], chunk):
        part = slice(start, start + chunk)
        x, w, c = points[part], weights[part], cells[part]
        ue = np.stack(np.broadcast_arrays(*u_exact(*x.T)), axis=1).astype(float)
        ge = np.moveaxis(np.asarray(grad_exact(*x.T), dtype=float), -1, 0)
        diff = proj.evaluate(c, x) - ue
        grad = proj.gradient_at(c, x) - ge
        l2 += float(np.sum(w * np.sum(diff**2, axis=1)))
        semi += float(np.sum(w * np.sum(grad**2, axis=(1, 2))))
        l2_exact += float(np.sum(w * np.sum(ue**2, axis=1)))
        semi_exact += float(np.sum(w * np.sum(ge**2, axis=(1, 2))))
    return {
        "l2": float(np.sqrt(l2)),
        "h1_semi": float(np.sqrt(semi)),
        "l2_exact": float(np.sqrt(l2_exact)),  # the norms of u itself, from the same evaluations
        "h1_semi_exact": float(np.sqrt(semi_exact)),
    }


def difference_gradient(field, step: float):
    """grad_exact for :func:`exact_errors` from field(x, y) -> (u1, u2) alone (or, in 3D,
    field(x, y, z) -> (u1, u2, u3)), by fourth-order central differences of width ``step``
    (truncation O(step^4), rounding O(eps / step))."""

    def grad(*x):
        d = len(x)
        out = None
        for axis in range(d):

            def at(s, axis=axis):
                return field(*(xi + s * step if i == axis else xi for i, xi in enumerate(x)))

            shifted = [at(s) for s in (-2, -1, 1, 2)]
            if out is None:
                out = np.empty((len(shifted[0]), d) + np.shape(x[0]))
            for c in range(out.shape[0]):
                out[c, axis] = (shifted[0][c] - 8.0 * shifted[1][c] + 8.0 * shifted[2][c] - shifted[3][c]) / (
                    12.0 * step
                )
        return out

    return grad


def relative_exact_errors(mesh: Mesh, proj, u_exact) -> dict:
    """docs/reference/files.md: relative errors of Pi u_h (``proj``, any element's projection) against
    u_exact(x, y) -> (u1, u2): ``error_l2`` = ||Pi u_h - u|| / ||u||, ``error_h1_semi`` = |.|_1 / |u|_1,
    ``error_h1`` with the full H1 norm; a degree-5 rule on a triangulation of every cell, the
    gradient of u exact (``u_exact.gradient``, e.g. of ``vemkit.config.expressions.vector_field``) or,
    for a plain callable, by :func:`difference_gradient` with a step of 1e-3 times the body's size.
    On a 3D mesh (docs/reference/files.md) the same with u_exact(x, y, z) -> (u1, u2, u3) and the tetrahedral-fan
    rule of :func:`error_quadrature`."""
    quadrature = error_quadrature(mesh)
    step = 1e-3 * float(np.ptp(mesh.vertices, axis=0).max())
    grad = getattr(u_exact, "gradient", None) or difference_gradient(u_exact, step)  # exact if the field has it
    found = exact_errors(mesh, proj, u_exact, grad, quadrature)  # u and its gradient evaluated once
    tiny = np.finfo(float).tiny
    return {
        "error_l2": found["l2"] / max(found["l2_exact"], tiny),
        "error_h1_semi": found["h1_semi"] / max(found["h1_semi_exact"], tiny),
        "error_h1": float(
            np.hypot(found["l2"], found["h1_semi"]) / max(np.hypot(found["l2_exact"], found["h1_semi_exact"]), tiny)
        ),
    }


# --------------------------------------------------------------------------------------------
# on boundary sides (Gamma_C): the trace of the space
# --------------------------------------------------------------------------------------------
def _part_edges(mesh: Mesh, parts) -> np.ndarray:
    parts = [parts] if isinstance(parts, str) else list(parts)
    return np.concatenate([np.asarray(mesh.boundary[p], dtype=np.int64).reshape(-1, 2) for p in parts])


def boundary_trace(space, parts, node_values: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(P, 2) the trace of a discrete displacement (``node_values`` (n_nodes, 2) of ``space``) on the
    boundary ``parts`` (a name or names) at ``points`` (P, 2) lying on them (linear between the
    vertex values for k = 1; the quadratic of Section 3.1 for k = 2). Each point is placed on the
    nearest edge (O(points x edges) work)."""
    edges = _part_edges(space.mesh, parts)
    a, b = space.mesh.vertices[edges[:, 0]], space.mesh.vertices[edges[:, 1]]
    d = b - a
    t = np.einsum("pek,ek->pe", points[:, None, :] - a[None], d) / np.sum(d * d, axis=1)[None]
    t = np.clip(t, 0.0, 1.0)
    gap = np.linalg.norm(a[None] + t[..., None] * d[None] - points[:, None, :], axis=2)
    e = np.argmin(gap, axis=1)
    return space.boundary_trace(edges[e], node_values, t[np.arange(points.shape[0]), e])


def trace_error(coarse_space, coarse_values, ref_space, ref_values, parts, points: int = 5) -> float:
    """||u_h - u_ref||_{L2(parts)} / ||u_ref||_{L2(parts)}: the traces (``boundary_trace``) compared at
    ``points`` Gauss points on every edge of the reference mesh's ``parts`` (exact for nested meshes)."""
    edges = _part_edges(ref_space.mesh, parts)
    s, w = edge_quadrature(points)
    a, b = ref_space.mesh.vertices[edges[:, 0]], ref_space.mesh.vertices[edges[:, 1]]
    x = (a[:, None, :] * (1 - s)[None, :, None] + b[:, None, :] * s[None, :, None]).reshape(-1, 2)
    weights = (np.linalg.norm(b - a, axis=1)[:, None] * w[None, :]).ravel()
    ref = boundary_trace(ref_space, parts, ref_values, x)
    diff = boundary_trace(coarse_space, parts, coarse_values, x) - ref
    return float(np.sqrt(np.sum(weights * np.sum(diff**2, axis=1)) / np.sum(weights * np.sum(ref**2, axis=1))))


def trace_errors(space, parts, node_values, field, subdivisions: int = 4, points: int = 5) -> dict:
    """The errors on the boundary ``parts`` against a field known everywhere on them, relative to
    ||u||_{L2(parts)}: ``contact_l2`` = ||u - u_h|| (the discrete trace, ``boundary_trace``) and
    ``interpolation_contact_l2`` = ||u - I_h u||, I_h u the trace of the interpolant of the space
    (k = 1: linear between the vertex values; k = 2: the quadratic with the vertex values and the
    edge mean, Section 3.1) -- the term ||u - u_I||_{L2(Gamma_C)} of the paper's a priori estimate,
    whose square root gives its O(h^{k/2 + 1/2}) = O(h^{3/2}) claim for k = 2.

    ``field(points (P, 2)) -> (P, 2)``. Every edge is cut into ``subdivisions`` equal pieces with a
    ``points``-point Gauss rule each (exact for a piecewise quadratic field whose pieces nest)."""
    edges = _part_edges(space.mesh, parts)
    s, w = edge_quadrature(points)
    t = ((np.arange(subdivisions)[:, None] + s[None, :]) / subdivisions).ravel()
    weights = np.tile(w, subdivisions) / subdivisions
    a, b = space.mesh.vertices[edges[:, 0]], space.mesh.vertices[edges[:, 1]]
    x = a[:, None, :] + t[None, :, None] * (b - a)[:, None, :]  # (E, Q, 2)
    lengths = np.linalg.norm(b - a, axis=1)
    exact = np.asarray(field(x.reshape(-1, 2)), dtype=float).reshape(x.shape)
    discrete = boundary_trace(space, parts, node_values, x.reshape(-1, 2)).reshape(x.shape)
    ends = [np.asarray(field(a), dtype=float), np.asarray(field(b), dtype=float)]
    means = [np.einsum("q,eqk->ek", weights, exact)] * (space.edge_nodes(edges[:1]).shape[1] - 2)
    trace_weights = space.element.edge_trace(t)  # (Q, k + 1): the interpolant's dofs are end values and means
    interpolant = sum(trace_weights[None, :, k, None] * dof[:, None] for k, dof in enumerate(ends + means))
    dx = lengths[:, None] * weights[None, :]
    norm = np.sqrt(np.sum(dx * np.sum(exact**2, axis=2)))
    return {
        "contact_l2": float(np.sqrt(np.sum(dx * np.sum((discrete - exact) ** 2, axis=2))) / norm),
        "interpolation_contact_l2": float(np.sqrt(np.sum(dx * np.sum((interpolant - exact) ** 2, axis=2))) / norm),
    }


def nesting_subdivisions(mesh: Mesh, ref_mesh: Mesh, parts) -> int:
    """The power of two m such that 1/m of the longest edge of ``mesh`` on ``parts`` is at most the
    shortest reference edge there: with nested dyadic meshes, each piece then lies in one reference edge."""

    def lengths(m):
        edges = _part_edges(m, parts)
        return np.linalg.norm(m.vertices[edges[:, 1]] - m.vertices[edges[:, 0]], axis=1)

    ratio = lengths(mesh).max() / lengths(ref_mesh).min()
    return int(2 ** max(0, int(np.ceil(np.log2(ratio) - 1e-9))))
