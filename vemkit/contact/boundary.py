"""The discrete contact boundary: Gamma_C vertices with their quadrature weights, normals and gaps.

``nodal`` quadrature (SPEC §3): each Gamma_C vertex gets half the length of each adjacent contact
edge as weight; the outward normal of a vertex is the length-weighted mean of the outward
normals of its contact edges (exact on straight parts), the tangent is tau = (-nu_2, nu_1)
(on the bottom edge nu = (0, -1), tau = (1, 0)). Clamped vertices are dropped: their
displacement is zero and they carry no unknown.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vemkit.vem.assembly import DofMap
from vemkit.mesh.mesh import Mesh


@dataclass(frozen=True)
class ContactBoundary:
    vertices: np.ndarray  # (n_c,) mesh vertex indices
    dofs: np.ndarray  # (n_c, 2) free-dof indices of (u1, u2)
    weight: np.ndarray  # (n_c,) quadrature weights
    normal: np.ndarray  # (n_c, 2) unit outward normals nu
    tangent: np.ndarray  # (n_c, 2) unit tangents tau
    gap: np.ndarray  # (n_c,) initial gap g_a >= 0
    coords: np.ndarray  # (n_c, 2) vertex coordinates

    @property
    def size(self) -> int:
        return self.vertices.size

    def normal_displacement(self, u):
        """u_nu at the contact vertices from the free-dof vector u."""
        return u[self.dofs[:, 0]] * self.normal[:, 0] + u[self.dofs[:, 1]] * self.normal[:, 1]

    def tangential_displacement(self, u):
        """u_tau (a scalar in 2D) at the contact vertices."""
        return u[self.dofs[:, 0]] * self.tangent[:, 0] + u[self.dofs[:, 1]] * self.tangent[:, 1]

    def scatter(self, normal_part, tangential_part, n_dofs):
        """Free-dof vector of sum_c (normal_part_c nu_c + tangential_part_c tau_c)."""
        out = np.zeros(n_dofs)
        np.add.at(out, self.dofs[:, 0], normal_part * self.normal[:, 0] + tangential_part * self.tangent[:, 0])
        np.add.at(out, self.dofs[:, 1], normal_part * self.normal[:, 1] + tangential_part * self.tangent[:, 1])
        return out


def contact_boundary(mesh: Mesh, parts, dofs: DofMap, gap) -> ContactBoundary:
    """Collect the contact vertices of the named boundary ``parts``; gap(x, y) -> array."""
    edges = np.concatenate([mesh.boundary[name] for name in parts]) if parts else np.zeros((0, 2), np.int64)
    nv = mesh.n_vertices
    t = mesh.vertices[edges[:, 1]] - mesh.vertices[edges[:, 0]]
    length = np.linalg.norm(t, axis=1)
    weighted_normal = np.stack([t[:, 1], -t[:, 0]], axis=1)  # |e| * outward normal (CCW boundary)
    weight = np.zeros(nv)
    nsum = np.zeros((nv, 2))
    for end in (0, 1):
        np.add.at(weight, edges[:, end], 0.5 * length)
        np.add.at(nsum, edges[:, end], weighted_normal)
    verts = np.unique(edges)
    verts = verts[dofs.free_index[verts] >= 0]
    normal = nsum[verts] / np.linalg.norm(nsum[verts], axis=1, keepdims=True)
    tangent = np.stack([-normal[:, 1], normal[:, 0]], axis=1)
    free = dofs.free_index[verts]
    coords = mesh.vertices[verts]
    g = np.broadcast_to(np.asarray(gap(coords[:, 0], coords[:, 1]), dtype=float), (verts.size,)).copy()
    if np.any(g < 0) or not np.all(np.isfinite(g)):
        raise ValueError("contact.gap must be finite and >= 0 at every contact vertex (2.11)")
    return ContactBoundary(verts, np.stack([2 * free, 2 * free + 1], axis=1), weight[verts], normal, tangent, g, coords)
