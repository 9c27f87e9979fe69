"""A posteriori error indicators η_K of the k = 1 VEM solution of the contact problem (SPEC §9).

Computable from u_h and the data only. With σ_K = C ε(Π u_h) on cell K (constant for k = 1, so
div σ_K = 0), f_K the cell average of the body force, and n_e the outward unit normal of edge e:

    η_K² = (1 / 2μ) [ h_K² |f_K|² |K|                                   volume residual
                    + ½ Σ_{e ⊂ ∂K interior} |e| ‖[σ n_e]‖²_e           jumps of the projected traction
                    + Σ_{e ⊂ ∂K ∩ Γ_F} |e| ‖f2 − σ_K n_e‖²_e           mismatch on Neumann sides
                    + Σ_{e ⊂ ∂K ∩ Γ_C} |e| ‖t_C − σ_K n_e‖²_e ]        mismatch with the contact traction
           + α_K S_K((I − Π) u_h, (I − Π) u_h)                            the VEM stabilization term (3.9)

where [σ n_e] = (σ_K − σ_K') n_e is constant on an interior edge, and t_C = −p_ν(u_ν − g) ν + σ_τ τ
is the contact traction of (2.6)–(2.9) at the Γ_C vertices, interpolated linearly along the edge
(σ_τ = −p_τ λ with the friction multiplier λ); the edge integrals use 3-point Gauss rules. The
residual terms are those of the residual estimator for the VEM of Beirão da Veiga & Manzini
(IMA J. Numer. Anal. 35, 2015) and Cangiani, Georgoulis, Pryer & Sutton (Numer. Math. 137, 2017),
with the boundary residual of the contact problem taking the contact traction as its Neumann datum
(as for normal compliance in finite elements, e.g. Wohlmuth, Acta Numerica 2011, §6). The factor
1/(2μ) turns the residuals (stress² × length²) into energy, the units of the stabilization term,
so that η² estimates the energy norm a(u − u_h, u − u_h) of the error. The relative estimate is

    η = (Σ_K η_K²)^½ / a_h(u_h, u_h)^½.

Imports from vemkit: ``mesh`` and this layer; the caller (``vemkit.studies.adaptivity``) turns the
scene's data and the contact solution into the plain arrays and callables taken here.
"""

from __future__ import annotations

import numba
import numpy as np

from vemkit.mesh.mesh import Mesh
from vemkit.vem.element import cell_coordinates, element_stiffness, stabilization_code
from vemkit.vem.projection import projected_solution, stress

GAUSS3 = (np.array([0.5 - np.sqrt(0.15), 0.5, 0.5 + np.sqrt(0.15)]), np.array([5.0, 8.0, 5.0]) / 18.0)


@numba.njit(cache=True)
def local_energies(vertices, offsets, cell_vertices, u, lam, mu, stab):
    """Per cell: a_h^K(u, u) (3.9) and its consistency part a_K(Π u, Π u); the difference is the
    stabilization energy α_K S_K((I − Π)u, (I − Π)u)."""
    n_cells = offsets.shape[0] - 1
    total = np.zeros(n_cells)
    consistency = np.zeros(n_cells)
    for c in range(n_cells):
        s = offsets[c]
        n = offsets[c + 1] - s
        m = 2 * n
        px, py = cell_coordinates(vertices, offsets, cell_vertices, c)
        K = np.empty((m, m))
        B = np.empty((3, m))
        P = np.empty((6, m))
        R = np.empty((m, m))
        area = element_stiffness(px, py, lam, mu, stab, K, B, P, R)
        ue = np.empty(m)
        for i in range(n):
            ue[2 * i] = u[cell_vertices[s + i], 0]
            ue[2 * i + 1] = u[cell_vertices[s + i], 1]
        energy = 0.0
        for i in range(m):
            for j in range(m):
                energy += ue[i] * K[i, j] * ue[j]
        e0 = 0.0
        e1 = 0.0
        e2 = 0.0
        for j in range(m):
            e0 += B[0, j] * ue[j]
            e1 += B[1, j] * ue[j]
            e2 += B[2, j] * ue[j]  # 2 eps12
        total[c] = energy
        consistency[c] = area * ((lam + 2 * mu) * (e0 * e0 + e1 * e1) + 2 * lam * e0 * e1 + mu * e2 * e2)
    return total, consistency


def _edge_normals(points_a, points_b):
    """Outward unit normals (for a counter-clockwise cell) and lengths of the edges a -> b."""
    d = points_b - points_a
    length = np.linalg.norm(d, axis=1)
    return np.stack([d[:, 1], -d[:, 0]], axis=1) / length[:, None], length


def _traction(sig: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """σ n for Voigt rows (σ11, σ22, σ12) and unit normals, both (E, ...)."""
    return np.stack([sig[:, 0] * normal[:, 0] + sig[:, 2] * normal[:, 1],
                     sig[:, 2] * normal[:, 0] + sig[:, 1] * normal[:, 1]], axis=1)


def _jump_terms(mesh: Mesh, sig: np.ndarray) -> np.ndarray:
    """½ |e|² |[σ n]|² added to each of the two cells of every interior edge."""
    edges, cells = mesh.edges, mesh.edge_cells
    inner = cells[:, 1] >= 0
    e, c = edges[inner], cells[inner]
    normal, length = _edge_normals(mesh.vertices[e[:, 0]], mesh.vertices[e[:, 1]])
    jump = _traction(sig[c[:, 0]] - sig[c[:, 1]], normal)
    term = 0.5 * length**2 * np.sum(jump**2, axis=1)
    out = np.zeros(mesh.n_cells)
    np.add.at(out, c[:, 0], term)
    np.add.at(out, c[:, 1], term)
    return out


def _boundary_cells(mesh: Mesh, edges: np.ndarray) -> np.ndarray:
    """The cell of every boundary edge (a, b) (as stored in ``mesh.boundary``)."""
    key = np.minimum(mesh.edges[:, 0], mesh.edges[:, 1]) * mesh.n_vertices + np.maximum(mesh.edges[:, 0], mesh.edges[:, 1])
    order = np.argsort(key)
    wanted = np.minimum(edges[:, 0], edges[:, 1]) * mesh.n_vertices + np.maximum(edges[:, 0], edges[:, 1])
    return mesh.edge_cells[order[np.searchsorted(key[order], wanted)], 0]


def _boundary_terms(mesh: Mesh, sig: np.ndarray, edges: np.ndarray, datum) -> np.ndarray:
    """|e| ∫_e |datum − σ_K n|² per cell, ``datum(points (Q, E, 2), t (Q,)) -> (Q, E, 2)``."""
    out = np.zeros(mesh.n_cells)
    if edges.size == 0:
        return out
    cells = _boundary_cells(mesh, edges)
    a, b = mesh.vertices[edges[:, 0]], mesh.vertices[edges[:, 1]]
    normal, length = _edge_normals(a, b)
    own = _traction(sig[cells], normal)
    t, w = GAUSS3
    points = a[None] + t[:, None, None] * (b - a)[None]
    misfit = datum(points, t) - own[None]
    np.add.at(out, cells, length**2 * np.einsum("q,qe->e", w, np.sum(misfit**2, axis=2)))
    return out


def error_indicators(mesh: Mesh, u_vertices, lam: float, mu: float, stabilization: str, *,
                     body_force=None, neumann=None, contact=None) -> dict:
    """η_K² by term and in total, and the relative estimate η (module docstring).

    body_force: (M, 2) cell averages f_K or None; neumann: {side: traction(x, y) -> (t1, t2)};
    contact: {side: (N, 2) contact traction t_C at every vertex (only Γ_C vertices are read)}.
    Returns {"indicator" (M,) η_K, "volume", "jump", "neumann", "contact", "stabilization" (M,) the
    squared terms, "estimate" η, "energy" a_h(u_h, u_h)}.
    """
    u = np.ascontiguousarray(u_vertices, dtype=float).reshape(mesh.n_vertices, 2)
    sig = stress(projected_solution(mesh, u).strain, lam, mu)
    total, consistency = local_energies(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, u, lam, mu,
                                        stabilization_code(stabilization))
    terms = {"volume": np.zeros(mesh.n_cells), "jump": _jump_terms(mesh, sig),
             "neumann": np.zeros(mesh.n_cells), "contact": np.zeros(mesh.n_cells)}
    if body_force is not None:
        terms["volume"] = mesh.cell_diameters**2 * np.sum(np.asarray(body_force) ** 2, axis=1) * mesh.cell_areas
    for side, traction in (neumann or {}).items():
        terms["neumann"] += _boundary_terms(mesh, sig, mesh.boundary[side], _sampled(traction))
    for side, at_vertices in (contact or {}).items():
        edges = mesh.boundary[side]
        terms["contact"] += _boundary_terms(mesh, sig, edges, _linear_along(np.asarray(at_vertices), edges))
    residual = sum(terms.values()) / (2.0 * mu)
    terms["stabilization"] = np.maximum(total - consistency, 0.0)
    squared = residual + terms["stabilization"]
    energy = float(total.sum())
    return {"indicator": np.sqrt(squared), **terms, "estimate": float(np.sqrt(squared.sum() / energy)) if energy > 0
            else 0.0, "energy": energy}


def _sampled(traction):
    def datum(points, _t):
        t1, t2 = traction(points[..., 0], points[..., 1])
        return np.stack(np.broadcast_arrays(t1, t2), axis=-1)
    return datum


def _linear_along(at_vertices: np.ndarray, edges: np.ndarray):
    ta, tb = at_vertices[edges[:, 0]], at_vertices[edges[:, 1]]

    def datum(_points, t):
        return ta[None] + t[:, None, None] * (tb - ta)[None]
    return datum


def dorfler_marking(indicator: np.ndarray, theta: float) -> np.ndarray:
    """The fewest cells (largest η_K first) with Σ_marked η_K² ≥ θ Σ η_K² (Dörfler 1996)."""
    squared = np.asarray(indicator, float) ** 2
    order = np.argsort(-squared, kind="stable")
    cumulative = np.cumsum(squared[order])
    count = int(np.searchsorted(cumulative, theta * cumulative[-1] * (1 - 1e-12))) + 1 if cumulative.size else 0
    return np.sort(order[:count])
