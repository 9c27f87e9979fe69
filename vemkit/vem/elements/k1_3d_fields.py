"""The 3D k = 1 element's loads, Dirichlet data and projected fields (Section 3.3, (3.8), docs/reference/files.md).

- Cell integrals by a signed tetrahedral fan: cell vertex mean, face vertex mean, one face edge;
  signed volumes make it exact for polynomials on any polyhedron with planar faces, non-convex
  ones included. Each tetrahedron carries a collapsed (Duffy) Gauss-Legendre product rule.
- Body force: int_K P_0 f . Pi v_h dx, P_0 f the cell average of f; exact for linear Pi v_h.
- ``projected_solution``: per cell Pi u = c + G (x - xbar), G = E + W (the kernel's coefficients).

The loops over cells and faces are the Numba kernels of ``k1_3d_fields_kernel``; the cell-by-cell
originals are their twins in ``k1_3d_fields_reference`` (pinned by tests/vem3d/test_k1_3d_fields_kernels.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vemkit.vem.elements.k1_3d_fields_kernel import (
    body_force_scatter,
    cell_moments,
    face_fan_points,
    face_trace_scatter,
    fan_quadrature,
    projected_fields,
    projection_table,
)
from vemkit.vem.projection import strain_of

QUADRATURE_CHUNK = 2**22  # points of the body force's fan rule evaluated at a time (~0.2 GiB of work arrays)
#: Gauss points per direction of the body force's rule on each fan tetrahedron: 2 (8 points, exact for
#: linear f) gives the cell means P_0 f and the centroids to O(h^2), all that (3.16)'s P_0 f needs;
#: 3 (27 points) cost 3.4 times as much (about 14 s of a 10^6-DOF hexahedral solve) for nothing
BODY_FORCE_POINTS = 2


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


def cell_quadrature(mesh, points: int = 3, cells: tuple | None = None):
    """(x (Q, 3), weight (Q,), cell (Q,)): a rule on every cell (or on cells lo <= c < hi, ``cells`` =
    (lo, hi)) by its signed tetrahedral fan (``k1_3d_fields_kernel.fan_quadrature``)."""
    ref, ref_w = tetrahedron_rule(points)
    offsets, ids = mesh.cell_vertex_lists
    lo, hi = (0, mesh.n_cells) if cells is None else cells
    return fan_quadrature(
        mesh.vertices,
        mesh.cell_offsets,
        mesh.cell_faces,
        mesh.face_offsets,
        mesh.face_vertices,
        offsets,
        ids,
        lo,
        hi,
        ref,
        ref_w,
    )


def cell_projections(mesh, geometry):
    """(xbar (M, 3), P (12, 3 sum n), volumes (M,)): the kernel's Pi coefficients of every cell, cell c's
    in the columns 3 offsets[c] ... 3 offsets[c + 1] (offsets of ``mesh.cell_vertex_lists``)."""
    vertices, cell_face_ptr, face_ptr, face_local = geometry[:4]
    offsets, ids = mesh.cell_vertex_lists
    return projection_table(vertices, offsets, ids, cell_face_ptr, face_ptr, face_local)


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
    """Pi u_h on every cell (``k1_3d_fields_kernel.projected_fields``)."""
    u = np.ascontiguousarray(np.asarray(node_values, float).reshape(-1, 3))
    vertices, cell_face_ptr, face_ptr, face_local = geometry[:4]
    offsets, ids = mesh.cell_vertex_lists
    return ProjectedSolution3D(*projected_fields(vertices, offsets, ids, cell_face_ptr, face_ptr, face_local, u))


def _cell_moments_in_chunks(mesh, field, chunk_points: int):
    """(lo, hi, |K|, P_0 f, x_K) of the cells lo <= c < hi, chunk by chunk: f evaluated on the fan rule
    of about ``chunk_points`` points at a time (whole cells), bounded memory."""
    faces = np.where(mesh.cell_faces >= 0, mesh.cell_faces, -mesh.cell_faces - 1)
    tetrahedra = int(np.diff(mesh.face_offsets)[faces].sum())  # BODY_FORCE_POINTS^3 points each
    step = max(1, int(chunk_points * mesh.n_cells // max(BODY_FORCE_POINTS**3 * tetrahedra, 1)))
    for lo in range(0, mesh.n_cells, step):
        hi = min(lo + step, mesh.n_cells)
        x, w, cells = cell_quadrature(mesh, BODY_FORCE_POINTS, (lo, hi))
        f = np.stack(np.broadcast_arrays(*field(x[:, 0], x[:, 1], x[:, 2])), axis=1).astype(float)
        yield (lo, hi, *cell_moments(cells - lo, w, x, f, hi - lo))


def body_force_load(mesh, geometry, field, chunk_points: int = QUADRATURE_CHUNK) -> np.ndarray:
    """(N, 3) int_K P_0 f . Pi phi_j dx = |K| f_K . (Pi phi_j)(x_K), x_K the centroid (Section 3.3)."""
    vertices, cell_face_ptr, face_ptr, face_local = geometry[:4]
    offsets, ids = mesh.cell_vertex_lists
    out = np.zeros((mesh.n_vertices, 3))
    for lo, _hi, volume, mean_f, centroid in _cell_moments_in_chunks(mesh, field, chunk_points):
        body_force_scatter(
            vertices, offsets, ids, cell_face_ptr, face_ptr, face_local, lo, volume, mean_f, centroid, out
        )
    return out


def body_force_averages(mesh, field, chunk_points: int = QUADRATURE_CHUNK) -> np.ndarray:
    """(M, 3) P_0 f: the cell averages of ``field`` that ``body_force_load`` scatters."""
    out = np.zeros((mesh.n_cells, 3))
    for lo, hi, _volume, mean_f, _centroid in _cell_moments_in_chunks(mesh, field, chunk_points):
        out[lo:hi] = mean_f
    return out


def dirichlet_components(mesh, dirichlet):
    """(prescribed (N, 3) bool, values (N, 3)) of side names (u = 0) or a mapping side -> (u1, u2, u3),
    each None (free), a number or a function of (x, y, z), on the vertices of the sides' faces."""
    prescribed = np.zeros((mesh.n_vertices, 3), dtype=bool)
    values = np.zeros((mesh.n_vertices, 3))
    items = dirichlet.items() if isinstance(dirichlet, dict) else ((side, (0.0, 0.0, 0.0)) for side in dirichlet)
    for side, components in items:
        vs = mesh.boundary_vertices(side)
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


def traction_load(mesh, faces, traction, points: int = 4) -> np.ndarray:
    """(N, 3) int_F g . phi_i ds over the boundary ``faces`` (stored outward): v_h on a face taken as
    Pi^F v_h, as the face integrals of the projection (exact for v_h linear), by signed fan triangles
    from the face's vertex mean (any planar face); traction(x, y, z) -> (g1, g2, g3)."""
    ref, ref_w = triangle_rule(points)
    faces = np.ascontiguousarray(np.asarray(faces, dtype=np.int64).ravel())
    x, w = face_fan_points(mesh.vertices, mesh.face_offsets, mesh.face_vertices, faces, ref, ref_w)
    g = np.stack(np.broadcast_arrays(*traction(x[:, 0], x[:, 1], x[:, 2])), axis=1).astype(float)  # (Q, 3)
    out = np.zeros((mesh.n_vertices, 3))
    face_trace_scatter(
        mesh.vertices,
        mesh.face_offsets,
        mesh.face_vertices,
        faces,
        ref_w.size,
        x,
        np.ascontiguousarray(w[:, None] * g),
        out,
    )
    return out


def pressure_load(mesh, faces, pressure, points: int = 4) -> np.ndarray:
    """(N, 3) the load of a normal pressure p(x, y, z) (or a number) on the boundary ``faces``: the
    traction -p nu_F of each planar face F, nu_F its outward unit normal (as ``traction_load``)."""
    faces = np.ascontiguousarray(np.asarray(faces, dtype=np.int64).ravel())
    areas = mesh.face_vector_areas[faces]
    normals = areas / np.linalg.norm(areas, axis=1, keepdims=True)
    per_face = np.diff(mesh.face_offsets)[faces] * triangle_rule(points)[1].size  # fan points of each face
    normal_at = np.repeat(normals, per_face, axis=0)

    def traction(x, y, z):
        p = np.broadcast_to(pressure(x, y, z) if callable(pressure) else float(pressure), np.shape(x))
        return tuple(-p * normal_at[:, k] for k in range(3))

    return traction_load(mesh, faces, traction, points)
