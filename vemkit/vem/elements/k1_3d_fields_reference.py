"""The plain numpy/Python twins of the 3D k = 1 loads and projected fields (``k1_3d_fields``): the
original cell-by-cell and face-by-face implementations, kept as the references the tests pin the
Numba kernels of ``k1_3d_fields_kernel`` to (same formulas; the results agree to round-off)."""

from __future__ import annotations

import numpy as np

from vemkit.vem.elements.k1_3d_fields import (
    ProjectedSolution3D,
    _gradients,
    face_trace_weights,
    tetrahedron_rule,
    triangle_rule,
)
from vemkit.vem.elements.k1_3d_kernel import boundary_vectors, projection_coefficients, strain_operator


def cell_quadrature_reference(mesh, points: int = 3):
    """(x (Q, 3), weight (Q,), cell (Q,)): a rule on every cell by its signed tetrahedral fan."""
    ref, ref_w = tetrahedron_rule(points)
    offsets, ids = mesh.cell_vertex_lists
    corners, cells = [], []
    for c in range(mesh.n_cells):
        centre = mesh.vertices[ids[offsets[c] : offsets[c + 1]]].mean(axis=0)
        for s in mesh.cell_face_list(c):
            face = mesh.face(s) if s >= 0 else mesh.face(-s - 1)[::-1]
            p = mesh.vertices[face]
            m = np.broadcast_to(p.mean(axis=0), p.shape)
            corners.append(np.stack([np.broadcast_to(centre, p.shape), m, p, np.roll(p, -1, axis=0)], axis=1))
            cells.append(np.full(p.shape[0], c))
    tets = np.concatenate(corners)  # (T, 4, 3): cell mean, face mean, one edge of the face
    J = np.transpose(tets[:, 1:] - tets[:, :1], (0, 2, 1))  # columns: the three edges from the cell mean
    x = tets[:, None, 0] + np.einsum("tij,qj->tqi", J, ref)
    w = np.linalg.det(J)[:, None] * ref_w[None]
    cell = np.repeat(np.concatenate(cells), ref_w.size)
    return x.reshape(-1, 3), w.ravel(), cell


def cell_projections_reference(mesh, geometry):
    """(xbar (M, 3), P list of (12, 3n), volumes (M,)): the kernel's Pi coefficients per cell."""
    vertices, cell_face_ptr, face_ptr, face_local = geometry[:4]
    offsets, ids = mesh.cell_vertex_lists
    xbars, Ps, vols = np.zeros((mesh.n_cells, 3)), [], np.zeros(mesh.n_cells)
    for c in range(mesh.n_cells):
        p = np.ascontiguousarray(vertices[ids[offsets[c] : offsets[c + 1]]])
        n = p.shape[0]
        q, w, B, P = np.empty((n, 3)), np.empty(n), np.empty((6, 3 * n)), np.empty((12, 3 * n))
        vols[c] = boundary_vectors(p, face_ptr, face_local, cell_face_ptr[c], cell_face_ptr[c + 1], q, w)
        strain_operator(q, vols[c], B)
        xbars[c] = projection_coefficients(p, B, P)
        Ps.append(P)
    return xbars, Ps, vols


def projected_solution_reference(mesh, geometry, node_values) -> ProjectedSolution3D:
    u = np.asarray(node_values, float).reshape(-1, 3)
    offsets, ids = mesh.cell_vertex_lists
    xbar, Ps, _ = cell_projections_reference(mesh, geometry)
    c, G = np.zeros((mesh.n_cells, 3)), np.zeros((mesh.n_cells, 3, 3))
    for k, P in enumerate(Ps):
        v = u[ids[offsets[k] : offsets[k + 1]]].ravel()
        c[k] = P[:3] @ v
        G[k] = np.einsum("j,jab->ab", v, _gradients(P))
    return ProjectedSolution3D(xbar, c, G)


def body_force_load_reference(mesh, geometry, field) -> np.ndarray:
    """(N, 3) int_K P_0 f . Pi phi_j dx = |K| f_K . (Pi phi_j)(x_K), x_K the centroid."""
    x, w, cells = cell_quadrature_reference(mesh, 2)  # k1_3d_fields.BODY_FORCE_POINTS
    f = np.stack(np.broadcast_arrays(*field(x[:, 0], x[:, 1], x[:, 2])), axis=1) * w[:, None]
    volume = np.bincount(cells, w, mesh.n_cells)
    mean_f = np.stack([np.bincount(cells, f[:, k], mesh.n_cells) for k in range(3)], axis=1) / volume[:, None]
    centroid = np.stack([np.bincount(cells, w * x[:, k], mesh.n_cells) for k in range(3)], axis=1) / volume[:, None]
    offsets, ids = mesh.cell_vertex_lists
    xbar, Ps, _ = cell_projections_reference(mesh, geometry)
    out = np.zeros((mesh.n_vertices, 3))
    for k, P in enumerate(Ps):
        value = P[:3].T + _gradients(P) @ (centroid[k] - xbar[k])  # (3n, 3) Pi phi_j (x_K)
        load = volume[k] * value @ mean_f[k]
        np.add.at(out, ids[offsets[k] : offsets[k + 1]], load.reshape(-1, 3))
    return out


def traction_load_reference(mesh, faces, traction, points: int = 4) -> np.ndarray:
    """(N, 3) int_F g . phi_i ds over the boundary ``faces`` (stored outward): v_h on a face taken as
    Pi^F v_h, as the face integrals of the projection (exact for v_h linear), by signed fan triangles
    from the face's vertex mean (any planar face); traction(x, y, z) -> (g1, g2, g3)."""
    ref, ref_w = triangle_rule(points)
    out = np.zeros((mesh.n_vertices, 3))
    for f in np.asarray(faces, dtype=np.int64).ravel():
        ids = mesh.face(f)
        p = mesh.vertices[ids]
        xb = p.mean(axis=0)
        q = np.roll(p, -1, axis=0)
        x = xb + ref[None, :, :1] * (p - xb)[:, None] + ref[None, :, 1:] * (q - xb)[:, None]  # (m, Q, 3)
        c = np.cross(p - xb, q - xb)
        w = (c @ (c.sum(axis=0) / np.linalg.norm(c.sum(axis=0))))[:, None] * ref_w[None]  # 2 |T| (signed) x weights
        x, w = x.reshape(-1, 3), w.ravel()
        g = np.stack(np.broadcast_arrays(*traction(x[:, 0], x[:, 1], x[:, 2])), axis=1)  # (Q, 3)
        np.add.at(out, ids, face_trace_weights(p, x).T @ (w[:, None] * g))
    return out
