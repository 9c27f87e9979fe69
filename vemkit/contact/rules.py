"""The per-facet rules of the contact boundary: where the contact points of Gamma_C are, their
nodal weights and normals, their tangent frame, and the facets of the ``gauss`` rule -- one
interface (``points``, ``tangents``, ``gauss``), one rule per kind of facet: the edges of a plane
body (``EdgeRule``), the faces of a 3D body (``FaceRule``); ``FACET_RULES`` maps the mesh's
dimension to its facets' rule.

Edges (2D). ``nodal`` quadrature (docs/reference/mathematics.md) puts the contact points at the
trace nodes with the element's nodal rule (``vemkit.contact.trace_nodes``) -- the trapezoid at the
Gamma_C vertices for k = 1 (half the length of each adjacent contact edge as weight), Simpson's rule
at the vertices and edge midpoints for k = 2 (the element's edge nodes). The outward normal of a
vertex is the length-weighted mean of the outward normals of its contact edges (exact on straight
parts), that of a midpoint its edge's normal; the tangent is tau = (-nu_2, nu_1) (on the bottom edge
nu = (0, -1), tau = (1, 0)). The ``gauss`` rule (elements with linear traces, k = 1): N =
``contact_gauss_points`` Gauss-Legendre points per edge, u_h . nu_e - g interpolated by the hat
functions of the two ends.

Faces (3D). Contact points: the vertices of the Gamma_C faces (k = 1). Weight of vertex i (the nodal
rule, docs/reference/mathematics.md, on polygonal faces):

    w_i = sum_{F in Gamma_C, i in F} int_F Pi^F phi_i ds = sum_F |F| (1/m_F + grad_i^F . (c_F - xbar_F)),

Pi^F phi_i = 1/m + grad_i . (x - xbar_F) the face projection of the vertex values
(``vemkit.vem.elements.k1_3d_fields.face_trace_weights``, linear on the planar face F with m
vertices, vertex mean xbar_F, area centroid c_F): exact for traces linear on each face, and the
weights of a face sum to |F|. On a rectangle every corner gets |F|/4, so the bottom of a prism over
a 2D mesh gives (2D trapezoid weight) x (trapezoid weight across the layer).

Normal per vertex: nu_i = the normalized sum of the vector areas |F| n_F of its Gamma_C faces
(n_F the outward unit normal; exact on plane parts, the area-weighted mean on curved ones).
Tangent basis per vertex (stored in the solution file): e = the coordinate axis least aligned with
nu (the smallest |nu_k|, the first on ties), t1 = (e x nu) / |e x nu|, t2 = nu x t1, so
(t1, t2, nu) is a right-handed orthonormal frame; on the floor z-face nu = (0, 0, -1): t1 = (0, 1, 0),
t2 = (1, 0, 0); on y = 0, nu = (0, -1, 0): t1 = (0, 0, -1), t2 = (1, 0, 0). Tangential quantities
(u_tau, lambda, sigma_tau) are their two components in (t1, t2).

The ``gauss`` rule of the normal-compliance term on faces (``contact_quadrature: gauss``, issue 21
item 1), N = ``contact_gauss_points``: on every Gamma_C face F the trace is taken as the linear
interpolant on a triangle fan, and each triangle gets a rule exact for degree 2N - 1 (the degree of
N Gauss points on an edge in 2D; ``vemkit.contact.gauss_rules.triangle_rule``: N = 3 the 7-point
degree-5 rule).

- a triangular face is its own fan: the rule integrates p_nu(t) phi_a of the P1 trace exactly for
  polynomial integrands of degree <= 2N - 1 -- on a tetrahedral mesh (where k = 1 VEM is P1) it is
  P1 FEM with that face rule (GetFEM's IM_TETRAHEDRON(5) for N = 3);
- a face with m > 3 vertices: the fan triangles T_i = (c_F, x_i, x_i+1) from its area centroid c_F,
  the trace linear on each, with the value sum_i a_i u_i at c_F, a_i = (3 w_i^F - |T_i-1| - |T_i|) / |F|
  (w_i^F the nodal weight of vertex i on F above). The k = 1 VEM trace is not a polynomial on such
  a face; this interpolant is what the rule integrates. It equals the VEM trace on the edges of F
  (linear there), has its mean (the interpolant of vertex i integrates to w_i^F = int_F Pi^F phi_i,
  which is int_F phi_i in the enhanced face space), and reproduces linear functions (sum_i a_i = 1,
  sum_i a_i x_i = c_F). So a uniform penetration gives every vertex the force of the nodal rule
  (the patch test: a box pressed uniformly stays uniform on a Voronoi mesh), a linear penetration is
  integrated exactly, and on a triangle a_i = 1/3. The apex value sum_i (w_i^F / |F|) u_i = Pi^F u (c_F)
  would reproduce linears too but fail the patch test (vertex forces off the nodal weights by
  1e-5 relative on a 3 x 3 Voronoi box). Signed fan areas: they sum to |F| on a planar face.

Dropped points, on edges and faces alike: a clamped or fully prescribed node is not a contact point
(with the gauss rule its prescribed u . n_f enters the facets around it); one with some components
prescribed stays, with those components held (``vemkit.contact.boundary``).
"""

from __future__ import annotations

import numpy as np

from vemkit.contact.gauss_rules import gauss_rule, triangle_rule
from vemkit.contact.trace_nodes import contact_edges, midpoint_edges, rule_weights
from vemkit.mesh.mesh import Mesh, edge_indices


def contact_nodes(dofs, nodes) -> np.ndarray:
    """The ``nodes`` that are contact points: they carry unknowns and at least one component without
    Dirichlet data -- a roller meeting Gamma_C stays, its free components in the law (issue 21)."""
    d = dofs.dimension
    count = np.bincount(dofs.free_nodes[dofs.fixed_dofs // d], minlength=dofs.n_nodes)
    return nodes[(dofs.free_index[nodes] >= 0) & (count[nodes] < d)]


# -- edges: the Gamma_C facets of a plane body ---------------------------------------------------------
def edge_ends(mesh: Mesh, edges: np.ndarray, end_weight: float):
    """(|e|, |e| nu_e, vertex weights, vertex normal sums) of the contact ``edges`` (a, b), nu_e the
    outward normal (CCW boundary): each end of an edge gets ``end_weight`` |e| (trapezoid 1/2,
    Simpson 1/6) and |e| nu_e (normalised later: the vertex normal)."""
    t = mesh.vertices[edges[:, 1]] - mesh.vertices[edges[:, 0]]
    length = np.linalg.norm(t, axis=1)
    weighted_normal = np.stack([t[:, 1], -t[:, 0]], axis=1)
    weight = np.zeros(mesh.n_vertices)
    nsum = np.zeros((mesh.n_vertices, 2))
    for end in (0, 1):
        np.add.at(weight, edges[:, end], end_weight * length)
        np.add.at(nsum, edges[:, end], weighted_normal)
    return length, weighted_normal, weight, nsum


def _midpoints(space, parts, edges, dofs, length, weighted_normal, mid_weight):
    """(nodes, weights, normals, coordinates) of the Gamma_C edge midpoints that are contact points."""
    mids = midpoint_edges(space, parts, dofs)
    on_edge = {int(e): k for k, e in enumerate(edge_indices(space.mesh, edges))} if mids.size else {}
    k_mid = np.array([on_edge[int(e)] for e in mids], dtype=np.int64)
    normal = weighted_normal[k_mid] / length[k_mid, None]
    coords = 0.5 * (space.mesh.vertices[edges[k_mid, 0]] + space.mesh.vertices[edges[k_mid, 1]])
    return space.node_range("edge").start + mids, mid_weight * length[k_mid], normal, coords


class EdgeRule:
    """The Gamma_C edges of a plane body (module docstring)."""

    @staticmethod
    def points(space, parts, dofs):
        """(nodes, nodal weights, unit normals, coordinates) of the contact points: the Gamma_C
        vertices, then the element's edge nodes (the k = 2 midpoints) when it has them."""
        mesh = space.mesh
        edges = contact_edges(mesh, parts)
        w_end, w_mid = rule_weights(space.element)
        length, weighted_normal, weight, nsum = edge_ends(mesh, edges, w_end)
        nodes = contact_nodes(dofs, np.unique(edges))
        normal = nsum[nodes] / np.linalg.norm(nsum[nodes], axis=1, keepdims=True)
        weight, coords = weight[nodes], mesh.vertices[nodes]
        mids = [] if w_mid is None else [_midpoints(space, parts, edges, dofs, length, weighted_normal, w_mid)]
        for mid, mid_w, mid_normal, mid_coords in mids:
            nodes, weight = np.concatenate([nodes, mid]), np.concatenate([weight, mid_w])
            normal = np.concatenate([normal, mid_normal]).reshape(-1, 2)
            coords = np.concatenate([coords, mid_coords]).reshape(-1, 2)
        return nodes, weight, normal, coords

    @staticmethod
    def tangents(normal) -> list:
        """[tau], tau = (-nu_2, nu_1)."""
        return [np.stack([-normal[:, 1], normal[:, 0]], axis=1)]

    @staticmethod
    def gauss(space, parts, gauss_points):
        """(facet nodes (n_e, 2), unit normals, |e| w_q (n_e, n_q), hat functions at the Gauss points
        (n_e, n_q, 2)) of the gauss rule on the Gamma_C edges."""
        edges = contact_edges(space.mesh, parts)
        length, weighted_normal, _, _ = edge_ends(space.mesh, edges, 0.5)
        s, w = gauss_rule(gauss_points)
        shape = np.broadcast_to(np.stack([1.0 - s, s], axis=1), (edges.shape[0], s.size, 2))
        return edges, weighted_normal / length[:, None], length[:, None] * w, shape


# -- faces: the Gamma_C facets of a 3D body ------------------------------------------------------------
def contact_faces(mesh, parts) -> np.ndarray:
    """The boundary faces of the named parts (each once)."""
    faces = [np.asarray(mesh.boundary[name], dtype=np.int64).ravel() for name in parts]
    return np.unique(np.concatenate(faces)) if faces else np.zeros(0, np.int64)


def face_vertex_weights(mesh, faces):
    """(ids, weights, vector areas) of every (face, vertex) pair of ``faces``: int_F Pi^F phi_i ds and
    |F| n_F repeated per vertex (module docstring)."""
    sizes = np.diff(mesh.face_offsets)[faces]
    starts = mesh.face_offsets[faces]
    owner = np.repeat(np.arange(faces.size), sizes)
    local = np.arange(sizes.sum()) - np.repeat(np.cumsum(sizes) - sizes, sizes)
    ids = mesh.face_vertices[starts[owner] + local]
    nxt = mesh.face_vertices[starts[owner] + (local + 1) % sizes[owner]]
    prv = mesh.face_vertices[starts[owner] + (local - 1) % sizes[owner]]
    va = mesh.face_vector_areas[faces]  # (k, 3) |F| n_F
    area = np.linalg.norm(va, axis=1)
    xbar = np.stack([np.bincount(owner, mesh.vertices[ids, c], faces.size) for c in range(3)], axis=1) / sizes[:, None]
    centroid = mesh.face_centroids[faces]
    unit = va / area[:, None]
    grad = np.cross(mesh.vertices[nxt] - mesh.vertices[prv], unit[owner]) / (2.0 * area[owner, None])
    weight = area[owner] * (1.0 / sizes[owner] + np.sum(grad * (centroid - xbar)[owner], axis=1))
    return ids, weight, va[owner]


def tangent_basis(normal: np.ndarray):
    """(t1, t2) of the module docstring, per row of ``normal`` (unit vectors)."""
    axis = np.argmin(np.abs(normal), axis=1)
    e = np.zeros_like(normal)
    e[np.arange(normal.shape[0]), axis] = 1.0
    t1 = np.cross(e, normal)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    return t1, np.cross(normal, t1)


class FaceRule:
    """The Gamma_C faces of a 3D body (module docstring)."""

    @staticmethod
    def points(space, parts, dofs):
        """(nodes, nodal weights, unit normals, coordinates) of the contact points: the Gamma_C vertices."""
        mesh = space.mesh
        ids, face_weight, va = face_vertex_weights(mesh, contact_faces(mesh, parts))
        weight = np.bincount(ids, face_weight, mesh.n_vertices)
        nsum = np.stack([np.bincount(ids, va[:, c], mesh.n_vertices) for c in range(3)], axis=1)
        nodes = contact_nodes(dofs, np.unique(ids))
        normal = nsum[nodes] / np.linalg.norm(nsum[nodes], axis=1, keepdims=True)
        return nodes, weight[nodes], normal, mesh.vertices[nodes]

    @staticmethod
    def tangents(normal) -> list:
        """[t1, t2] (``tangent_basis``)."""
        return list(tangent_basis(normal))

    @staticmethod
    def gauss(space, parts, gauss_points):
        """(facet nodes (n_f, m), unit normals, |T| w_q (n_f, n_q), interpolants (n_f, n_q, m)) of
        the gauss rule on the Gamma_C faces (``face_fans``)."""
        faces = contact_faces(space.mesh, parts)
        _, face_weight, _ = face_vertex_weights(space.mesh, faces)
        return face_fans(space.mesh, faces, face_weight, triangle_rule(gauss_points))


FACET_RULES = {2: EdgeRule, 3: FaceRule}  # the mesh's dimension -> the rule of its Gamma_C facets


def face_fans(mesh, faces, face_weight, rule):
    """(nodes (n_f, m), unit normals, |T| w_q (n_f, n_q), interpolants (n_f, n_q, m)) of the gauss
    rule on the Gamma_C faces (module docstring): the triangle rule on a triangular face, on every fan
    triangle (c_F, x_i, x_i+1) of a larger one. ``face_weight``: the nodal weights w_i^F of
    ``face_vertex_weights``, in its order (they fix the apex values)."""
    points, weights = rule
    q, sizes = weights.size, np.diff(mesh.face_offsets)[faces]
    m = int(sizes.max(initial=3))
    corner = np.arange(m)[None, :]
    nodes = mesh.face_vertices[mesh.face_offsets[faces][:, None] + np.where(corner < sizes[:, None], corner, 0)]
    va = mesh.face_vector_areas[faces]
    area = np.linalg.norm(va, axis=1)
    unit = va / area[:, None]
    shape = np.zeros((faces.size, q * (m if m > 3 else 1), m))  # a fan: q points per triangle
    gauss_weight = np.zeros(shape.shape[:2])
    tri = sizes == 3
    shape[tri, :q, :3] = points
    gauss_weight[tri, :q] = area[tri, None] * weights
    fan, nxt = np.flatnonzero(~tri), (corner + 1) % sizes[:, None]
    if fan.size == 0:
        return nodes, unit, gauss_weight, shape
    fan_area = _fan_areas(mesh, faces[fan], nodes[fan], nxt[fan], unit[fan], sizes[fan])  # (n_fan, m)
    nodal = np.zeros((faces.size, m))  # w_i^F per corner
    owner = np.repeat(np.arange(faces.size), sizes)
    nodal[owner, np.arange(sizes.sum()) - np.repeat(np.cumsum(sizes) - sizes, sizes)] = face_weight
    previous = np.take_along_axis(fan_area, (corner - 1) % sizes[fan, None], axis=1)
    apex = np.where(corner < sizes[fan, None], 3.0 * nodal[fan] - previous - fan_area, 0.0) / area[fan, None]
    for i in range(m):
        rows = np.flatnonzero(i < sizes[fan])
        cells, block, after = fan[rows][:, None], np.arange(i * q, (i + 1) * q)[None, :], nxt[fan[rows], i][:, None]
        shape[cells, block, :] = points[None, :, 0, None] * apex[rows, None, :]
        shape[cells, block, i] += points[None, :, 1]
        shape[cells, block, after] += points[None, :, 2]
        gauss_weight[cells, block] = fan_area[rows, i, None] * weights[None, :]
    return nodes, unit, gauss_weight, shape


def _fan_areas(mesh, faces, nodes, nxt, unit, sizes):
    """(n, m) signed areas of the fan triangles (c_F, x_i, x_i+1) (0 past a face's size): they sum to
    |F| on a planar face."""
    centroid = mesh.face_centroids[faces][:, None, :]
    a = mesh.vertices[nodes] - centroid
    b = mesh.vertices[np.take_along_axis(nodes, nxt, axis=1)] - centroid
    areas = 0.5 * np.sum(np.cross(a, b) * unit[:, None, :], axis=2)
    return np.where(np.arange(nodes.shape[1])[None, :] < sizes[:, None], areas, 0.0)
