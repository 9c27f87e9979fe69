"""The 3D k = 1 element's loads, Dirichlet data and projected fields (Section 3.3, (3.8), SPEC §10).

- Cell integrals by a signed tetrahedral fan: cell vertex mean, face vertex mean, one face edge;
  signed volumes make it exact for polynomials on any polyhedron with planar faces, non-convex
  ones included. Each tetrahedron carries a collapsed (Duffy) Gauss-Legendre product rule.
- Body force: int_K P_0 f . Pi v_h dx, P_0 f the cell average of f; exact for linear Pi v_h.
- ``projected_solution``: per cell Pi u = c + G (x - xbar), G = E + W (the kernel's coefficients).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vemkit.vem.elements.k1_3d_kernel import boundary_vectors, projection_coefficients, strain_operator
from vemkit.vem.projection import strain_of


def tetrahedron_rule(points: int = 3):
    """(barycentric-free) reference rule on the unit tetrahedron: (Q, 3) points, (Q,) weights, by the
    collapsed product of Gauss-Legendre rules (exact for degree 2 points - 3 and more)."""
    g, w = np.polynomial.legendre.leggauss(points)
    g, w = (g + 1) / 2, w / 2
    a, b, c = np.meshgrid(g, g, g, indexing="ij")
    wa, wb, wc = np.meshgrid(w, w, w, indexing="ij")
    x = a * (1 - b) * (1 - c)
    y = b * (1 - c)
    z = c
    weight = wa * wb * wc * (1 - b) * (1 - c) ** 2
    return np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1), weight.ravel()


def cell_quadrature(mesh, points: int = 3):
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


def cell_projections(mesh, geometry):
    """(xbar (M, 3), P list of (12, 3n), volumes (M,)): the kernel's Pi coefficients per cell."""
    vertices, cell_face_ptr, face_ptr, face_local = geometry
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


def _gradients(P):
    """(3n, 3, 3) G = E + W of Pi phi_j for every dof j (rows of P: c, omega, E11 E22 E33 E12 E13 E23)."""
    G = np.zeros((P.shape[1], 3, 3))
    G[:, 0, 0], G[:, 1, 1], G[:, 2, 2] = P[6], P[7], P[8]
    G[:, 0, 1] = G[:, 1, 0] = P[9]
    G[:, 0, 2] = G[:, 2, 0] = P[10]
    G[:, 1, 2] = G[:, 2, 1] = P[11]
    om = P[3:6]
    G[:, 0, 1] -= om[2]
    G[:, 1, 0] += om[2]
    G[:, 0, 2] += om[1]
    G[:, 2, 0] -= om[1]
    G[:, 1, 2] -= om[0]
    G[:, 2, 1] += om[0]
    return G


@dataclass
class ProjectedSolution3D:
    """Pi u_h on every cell: u(x) = c_K + G_K (x - xbar_K)."""

    xbar: np.ndarray  # (M, 3)
    c: np.ndarray  # (M, 3)
    G: np.ndarray  # (M, 3, 3)

    def evaluate(self, cells, points):
        cells = np.asarray(cells)
        return self.c[cells] + np.einsum("qij,qj->qi", self.G[cells], np.asarray(points) - self.xbar[cells])

    def gradient_at(self, cells, points=None):
        return self.G[np.asarray(cells)]

    def cell_mean_strain(self):
        """(M, 6) eps11, eps22, eps33, eps12, eps13, eps23 of Pi u on every cell (constant there)."""
        return strain_of(self.G)


def projected_solution(mesh, geometry, node_values) -> ProjectedSolution3D:
    u = np.asarray(node_values, float).reshape(-1, 3)
    offsets, ids = mesh.cell_vertex_lists
    xbar, Ps, _ = cell_projections(mesh, geometry)
    c, G = np.zeros((mesh.n_cells, 3)), np.zeros((mesh.n_cells, 3, 3))
    for k, P in enumerate(Ps):
        v = u[ids[offsets[k] : offsets[k + 1]]].ravel()
        c[k] = P[:3] @ v
        G[k] = np.einsum("j,jab->ab", v, _gradients(P))
    return ProjectedSolution3D(xbar, c, G)


def body_force_load(mesh, geometry, field) -> np.ndarray:
    """(N, 3) int_K P_0 f . Pi phi_j dx = |K| f_K . (Pi phi_j)(x_K), x_K the centroid."""
    x, w, cells = cell_quadrature(mesh, 3)
    f = np.stack(np.broadcast_arrays(*field(x[:, 0], x[:, 1], x[:, 2])), axis=1) * w[:, None]
    volume = np.bincount(cells, w, mesh.n_cells)
    mean_f = np.stack([np.bincount(cells, f[:, k], mesh.n_cells) for k in range(3)], axis=1) / volume[:, None]
    centroid = np.stack([np.bincount(cells, w * x[:, k], mesh.n_cells) for k in range(3)], axis=1) / volume[:, None]
    offsets, ids = mesh.cell_vertex_lists
    xbar, Ps, _ = cell_projections(mesh, geometry)
    out = np.zeros((mesh.n_vertices, 3))
    for k, P in enumerate(Ps):
        value = P[:3].T + _gradients(P) @ (centroid[k] - xbar[k])  # (3n, 3) Pi phi_j (x_K)
        load = volume[k] * value @ mean_f[k]
        np.add.at(out, ids[offsets[k] : offsets[k + 1]], load.reshape(-1, 3))
    return out


def dirichlet_components(mesh, dirichlet):
    """(prescribed (N, 3) bool, values (N, 3)) of side names (u = 0) or a mapping side -> (u1, u2, u3),
    each None (free), a number or a function of (x, y, z), on the vertices of the sides' faces."""
    prescribed = np.zeros((mesh.n_vertices, 3), dtype=bool)
    values = np.zeros((mesh.n_vertices, 3))
    items = dirichlet.items() if isinstance(dirichlet, dict) else ((side, (0.0, 0.0, 0.0)) for side in dirichlet)
    for side, components in items:
        faces = mesh.boundary[side]
        vs = np.unique(np.concatenate([mesh.face(f) for f in faces])) if faces.size else np.zeros(0, np.int64)
        x, y, z = mesh.vertices[vs].T
        for k, g in enumerate(components):
            if g is None:
                continue
            prescribed[vs, k] = True
            values[vs, k] = g(x, y, z) if callable(g) else float(g)
    return prescribed, values


def triangle_rule(points: int = 3):
    """(Q, 2) points (barycentric s, t of the second and third corner) and weights on the unit
    triangle (area 1/2), a collapsed Gauss-Legendre product (exact for degree 2 points - 2)."""
    g, w = np.polynomial.legendre.leggauss(points)
    g, w = (g + 1) / 2, w / 2
    a, b = np.meshgrid(g, g, indexing="ij")
    wa, wb = np.meshgrid(w, w, indexing="ij")
    return np.stack([(a * (1 - b)).ravel(), b.ravel()], axis=1), (wa * wb * (1 - b)).ravel()


def face_trace_weights(p, points):
    """(Q, m) the values of Pi^F phi_i (the face's k = 1 projection, ``k1_3d_kernel``) at ``points``
    (Q, 3) of the planar face with vertices p (m, 3): 1/m + grad_i . (x - xbar_F)."""
    m = p.shape[0]
    xb = p.mean(axis=0)
    a = 0.5 * np.cross(p - xb, np.roll(p, -1, axis=0) - xb).sum(axis=0)
    area = np.linalg.norm(a)
    grad = np.cross(np.roll(p, -1, axis=0) - np.roll(p, 1, axis=0), a / area) / (2 * area)  # (m, 3)
    return 1.0 / m + (points - xb) @ grad.T


def face_rule(mesh, f: int, ref, ref_w):
    """(vertex ids, vertices p (m, 3), points x (Q, 3), weights w (Q,)): the rule of signed fan
    triangles from the vertex mean of the planar face f (stored orientation), ``ref`` a triangle rule."""
    ids = mesh.face(f)
    p = mesh.vertices[ids]
    xb = p.mean(axis=0)
    q = np.roll(p, -1, axis=0)
    x = xb + ref[None, :, :1] * (p - xb)[:, None] + ref[None, :, 1:] * (q - xb)[:, None]  # (m, Q, 3)
    c = np.cross(p - xb, q - xb)
    w = (c @ (c.sum(axis=0) / np.linalg.norm(c.sum(axis=0))))[:, None] * ref_w[None]  # 2 |T| (signed) x weights
    return ids, p, x.reshape(-1, 3), w.ravel()


def traction_load(mesh, faces, traction, points: int = 4) -> np.ndarray:
    """(N, 3) int_F g . phi_i ds over the boundary ``faces`` (stored outward): v_h on a face taken as
    Pi^F v_h, as the face integrals of the projection (exact for v_h linear), by signed fan triangles
    from the face's vertex mean (any planar face); traction(x, y, z) -> (g1, g2, g3)."""
    ref, ref_w = triangle_rule(points)
    out = np.zeros((mesh.n_vertices, 3))
    for f in np.asarray(faces, dtype=np.int64).ravel():
        ids, p, x, w = face_rule(mesh, f, ref, ref_w)
        g = np.stack(np.broadcast_arrays(*traction(x[:, 0], x[:, 1], x[:, 2])), axis=1)  # (Q, 3)
        np.add.at(out, ids, face_trace_weights(p, x).T @ (w[:, None] * g))
    return out


def pressure_load(mesh, faces, pressure, points: int = 4) -> np.ndarray:
    """(N, 3) the load of a normal pressure p(x, y, z) (or a number) on the boundary ``faces``: the
    traction -p nu_F of each planar face F, nu_F its outward unit normal (as ``traction_load``)."""
    ref, ref_w = triangle_rule(points)
    out = np.zeros((mesh.n_vertices, 3))
    faces = np.asarray(faces, dtype=np.int64).ravel()
    areas = mesh.face_vector_areas[faces]
    for f, nu in zip(faces, areas / np.linalg.norm(areas, axis=1, keepdims=True)):
        ids, p, x, w = face_rule(mesh, f, ref, ref_w)
        value = pressure(x[:, 0], x[:, 1], x[:, 2]) if callable(pressure) else float(pressure)
        np.add.at(out, ids, np.outer(face_trace_weights(p, x).T @ (w * value), -nu))
    return out
