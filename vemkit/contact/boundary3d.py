"""The contact boundary of a 3D body (docs/reference/files.md): Gamma_C any set of boundary faces, the nodal or the gauss rule.

Contact points: the vertices of the Gamma_C faces (k = 1). Weight of vertex i (the nodal rule,
docs/reference/mathematics.md, on polygonal faces):

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

The ``gauss`` rule of the normal-compliance term (``contact_quadrature: gauss``, issue 21 item 1),
N = ``contact_gauss_points``: on every Gamma_C face F the trace is taken as the linear interpolant on
a triangle fan, and each triangle gets a rule exact for degree 2N - 1 (the degree of N Gauss points
on an edge in 2D; ``vemkit.contact.gauss_rules.triangle_rule``: N = 3 the 7-point degree-5 rule).

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

The penetration t = u . n_F - g is interpolated from the face's vertices (n_F the unit face normal,
g the vertex gaps), as t along an edge in 2D; the friction term stays at the vertices with the nodal
weights (``vemkit.contact.boundary``).

Dirichlet data as in 2D (``vemkit.contact.boundary``): a clamped or fully prescribed vertex is
dropped (with the gauss rule its prescribed u . n_F enters the faces around it), one with some
components prescribed stays with those components held.
Gap: a callable g(x, y, z) >= 0 or a ``FoundationLine`` built from a 3D point and normal (a plane;
gap along nu as in 2D).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from vemkit.contact.boundary import QUADRATURES, ContactBoundary, contact_nodes, fixed_components, with_facets
from vemkit.contact.gaps import _gap_values
from vemkit.contact.gauss_rules import triangle_rule
from vemkit.exceptions import SceneError


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


def contact_boundary_3d(space, parts, dofs, gap, quadrature: str = "nodal", gauss_points: int = 3) -> ContactBoundary:
    """The contact points of the named boundary face sets ``parts`` (module docstring)."""
    if quadrature not in QUADRATURES:
        raise SceneError(
            f"discretization.contact_quadrature = {quadrature!r}: use nodal or gauss",
            key="discretization.contact_quadrature",
        )
    mesh = space.mesh
    faces = contact_faces(mesh, parts)
    ids, face_weight, va = face_vertex_weights(mesh, faces)
    weight = np.bincount(ids, face_weight, mesh.n_vertices)
    nsum = np.stack([np.bincount(ids, va[:, c], mesh.n_vertices) for c in range(3)], axis=1)
    verts = contact_nodes(dofs, np.unique(ids))
    normal = nsum[verts] / np.linalg.norm(nsum[verts], axis=1, keepdims=True)
    t1, t2 = tangent_basis(normal)
    coords = mesh.vertices[verts]
    free = dofs.free_index[verts]
    point_dofs = np.stack([3 * free, 3 * free + 1, 3 * free + 2], axis=1).reshape(-1, 3)
    cb = ContactBoundary(
        verts,
        point_dofs,
        weight[verts],
        normal,
        t1,
        _gap_values(gap, coords, normal),
        coords,
        quadrature,
        tangent2=t2,
        fixed=fixed_components(dofs, point_dofs),
    )
    if quadrature == "nodal":
        return cb
    nodes, face_normal, gauss_weight, gauss_shape = face_fans(mesh, faces, face_weight, triangle_rule(gauss_points))
    return with_facets(cb, mesh, nodes, face_normal, dofs, gap, gauss_weight, gauss_shape)


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


def normals_in_roller_planes(cb: ContactBoundary, gap) -> ContactBoundary:
    """``cb`` with the normal of every vertex that has prescribed components (a symmetry roller, e.g.
    u1 = 0 on the plane x = 0) put into the roller's plane: those components of nu set to zero,
    renormalized, the tangent basis and the gap (``gap``: a callable or FoundationLine) rebuilt.

    The area-weighted normal of a vertex on x = 0 sees the Gamma_C faces on one side only and tilts
    out of the plane, while the whole symmetric body's normal lies in it; with the roller a stick
    vertex is then pinned and a sliding one cannot follow its slip direction (the held component's
    friction force is the constraint's), so ssn's slip-direction test stalls (measured: 4e-4 on the
    Hertz half sphere). Only for rollers on symmetry planes: a vertex held for another reason keeps
    the normal of its faces when this is not called."""
    if cb.fixed is None or not np.any(cb.fixed):
        return cb
    normal = np.where(cb.fixed, 0.0, cb.normal)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    t1, t2 = tangent_basis(normal)
    return replace(cb, normal=normal, tangent=t1, tangent2=t2).with_gap(gap)
