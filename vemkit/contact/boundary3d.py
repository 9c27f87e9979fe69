"""The contact boundary of a 3D body (SPEC §10): Gamma_C any set of boundary faces, the nodal rule.

Contact points: the vertices of the Gamma_C faces (k = 1). Weight of vertex i (the nodal rule,
SPEC §3, on polygonal faces):

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

Dirichlet data as in 2D (``vemkit.contact.boundary``): a clamped or fully prescribed vertex is
dropped, one with some components prescribed stays with those components held.
Gap: a callable g(x, y, z) >= 0 or a ``FoundationLine`` built from a 3D point and normal (a plane;
gap along nu as in 2D).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from vemkit.contact.boundary import ContactBoundary, contact_nodes, fixed_components
from vemkit.contact.gaps import _gap_values
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


def contact_boundary_3d(space, parts, dofs, gap, quadrature: str = "nodal") -> ContactBoundary:
    """The contact points of the named boundary face sets ``parts`` (module docstring)."""
    if quadrature != "nodal":
        raise SceneError(
            f"discretization.contact_quadrature = {quadrature!r} is not available on 3D bodies yet "
            "(the nodal rule at the Gamma_C vertices is); set contact_quadrature: nodal",
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
    return ContactBoundary(
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
