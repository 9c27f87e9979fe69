"""The lowest-order element in three dimensions (k = 1, Section 3 for d = 3): the displacement at
the vertices of polyhedra (docs/reference/files.md).

Its kernel is ``k1_3d_kernel`` (the projection (3.8) from face integrals of the vertex values and
the stiffness (3.9)), its loads and projected fields ``k1_3d_fields``, its numpy twin
``k1_3d_reference``. The kernel needs the cells' faces, not only their vertices: ``geometry(mesh)``
is what the assembly hands it in place of the vertex coordinates (the 2D elements hand the
coordinates themselves).
"""

from __future__ import annotations

import weakref

import numba
import numpy as np

from vemkit.vem.elements import k1_3d_fields, k1_3d_kernel
from vemkit.vem.elements.base import Element

_FACES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # mesh -> local_faces(mesh)


def local_faces(mesh):
    """(cell_face_ptr, face_ptr, face_local): every cell's faces, outward, as lists of local vertex
    numbers (positions in the cell's list of ``mesh.cell_vertex_lists``)."""
    offsets, ids = mesh.cell_vertex_lists
    signed = mesh.cell_faces
    faces = np.where(signed >= 0, signed, -signed - 1)
    face_ptr = np.concatenate([[0], np.cumsum(np.diff(mesh.face_offsets)[faces])]).astype(np.int64)
    face_local = _local_faces(
        mesh.cell_offsets, signed, mesh.face_offsets, mesh.face_vertices, offsets, ids, face_ptr, mesh.n_vertices
    )
    return mesh.cell_offsets.copy(), face_ptr, face_local


@numba.njit(cache=True)
def _local_faces(cell_offsets, cell_faces, face_offsets, face_vertices, offsets, ids, face_ptr, n_vertices):
    """face_local of ``local_faces``: each face's vertices (reversed where the cell lists it reversed)
    renumbered by their positions in the cell's vertex list."""
    local = np.full(n_vertices, -1, dtype=np.int64)
    out = np.empty(face_ptr[-1], dtype=np.int64)
    for c in range(cell_offsets.shape[0] - 1):
        for k in range(offsets[c], offsets[c + 1]):
            local[ids[k]] = k - offsets[c]
        for t in range(cell_offsets[c], cell_offsets[c + 1]):
            s = cell_faces[t]
            f = s if s >= 0 else -s - 1
            lo, m = face_offsets[f], face_offsets[f + 1] - face_offsets[f]
            for i in range(m):
                out[face_ptr[t] + i] = local[face_vertices[lo + (i if s >= 0 else m - 1 - i)]]
    return out


#: a face is horizontal (vertical) when its unit normal's z component is within this of +-1 (of 0)
PRISM_TOLERANCE = 1e-10


def stabilization_lengths(mesh) -> np.ndarray:
    """(M,) the length h_K of the 3D dofi-dofi scaling alpha_K = 2 mu h_K (``k1_3d_kernel``): the
    cell's diameter, except for a right prism along z (exactly two horizontal faces, the others
    vertical: the cells of an extruded mesh and of the hex grid), where it is half the prism's height
    t. There a field independent of z with u3 = 0 has the stabilization 2 (mu t) sum_i e_i^2 over the
    two copies of each base vertex: t times the 2D dofi-2mu term, as its consistency term is t times
    the 2D one (plane strain), so that an extruded body with u3 = 0 on its end faces solves to the
    2D plane-strain solution (docs/reference/files.md). t / 2 scales like h_K on shape-regular prisms."""
    areas = mesh.face_vector_areas
    nz = areas[:, 2] / np.linalg.norm(areas, axis=1)
    signed = mesh.cell_faces
    faces = np.where(signed >= 0, signed, -signed - 1)
    cell = np.repeat(np.arange(mesh.n_cells), np.diff(mesh.cell_offsets))
    horizontal = np.abs(np.abs(nz[faces]) - 1.0) < PRISM_TOLERANCE
    vertical = np.abs(nz[faces]) < PRISM_TOLERANCE
    prism = (np.bincount(cell, horizontal, mesh.n_cells) == 2) & (
        np.bincount(cell, horizontal | vertical, mesh.n_cells) == np.diff(mesh.cell_offsets)
    )
    offsets, ids = mesh.cell_vertex_lists
    z = mesh.vertices[ids, 2]
    height = np.maximum.reduceat(z, offsets[:-1]) - np.minimum.reduceat(z, offsets[:-1])
    return np.where(prism, 0.5 * height, mesh.cell_diameters)


class FirstOrder3D(Element):
    name = "k1_3d"
    order = 1
    dimension = 3
    layout = {"vertex": 1}
    condensed_nodes = 0
    numbering = "mesh"
    stress_degree = 0
    polynomial_on_triangles = True  # on tetrahedra V_h is P1: the stiffness of P1 finite elements
    projection_uses_material = False
    contact_rule = ()  # contact in 3D is not part of this element yet
    workspace = staticmethod(k1_3d_kernel.workspace)
    cell_matrix = staticmethod(k1_3d_kernel.cell_matrix)

    def cell_nodes(self, mesh):
        return mesh.cell_vertex_lists

    def geometry(self, mesh):
        """(vertices, cell_face_ptr, face_ptr, face_local, stabilization lengths): what ``cell_matrix``
        reads (``local_faces``, ``stabilization_lengths``)."""
        if mesh not in _FACES:
            _FACES[mesh] = local_faces(mesh) + (stabilization_lengths(mesh),)
        return (mesh.vertices,) + _FACES[mesh]

    def node_coordinates(self, mesh) -> np.ndarray:
        return mesh.vertices

    def boundary_nodes(self, mesh, sides) -> np.ndarray:
        """The vertices of boundary faces ``sides`` (face numbers)."""
        return mesh.face_vertex_ids(sides)

    def interpolate(self, mesh, field) -> np.ndarray:
        x, y, z = mesh.vertices.T
        return np.stack(np.broadcast_arrays(*field(x, y, z)), axis=1).astype(float)

    def body_force_load(self, mesh, field, lam, mu, projection="p0") -> np.ndarray:
        """int_K P_0 f . Pi v_h dx (Section 3.3), P_0 f the cell average of f."""
        return k1_3d_fields.body_force_load(mesh, self.geometry(mesh), field)

    def body_force_averages(self, mesh, field) -> np.ndarray:
        """(M, 3) P_0 f on every cell of a field f(x, y, z) -> (f1, f2, f3) (the fan rule of the load)."""
        return k1_3d_fields.body_force_averages(mesh, field)

    def traction_load(self, mesh, faces, traction) -> np.ndarray:
        """int_F g . v_h ds over boundary ``faces`` (face numbers), v_h as Pi^F v_h on each face."""
        return k1_3d_fields.traction_load(mesh, faces, traction)

    def pressure_load(self, mesh, faces, pressure) -> np.ndarray:
        """The traction load of -p nu_F on every boundary face F (nu_F its outward unit normal)."""
        return k1_3d_fields.pressure_load(mesh, faces, pressure)

    def project(self, mesh, node_values, lam=None, mu=None):
        return k1_3d_fields.projected_solution(mesh, self.geometry(mesh), node_values)

    def divergence_table(self, mesh):
        from vemkit.vem.elements.k1_divergence import divergence_3d

        return divergence_3d(mesh, self.geometry(mesh))

    def dirichlet_components(self, mesh, dirichlet):
        return k1_3d_fields.dirichlet_components(mesh, dirichlet)


ELEMENT = FirstOrder3D()
