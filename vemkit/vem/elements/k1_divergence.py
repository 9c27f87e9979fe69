"""The divergence of the k = 1 projection, div_K(Pi v) = tr eps_K(Pi v), as a linear form of the
vertex values of every cell: what the nodal averaging of the volumetric strain
(``vemkit.vem.volumetric``) needs from the element, and nothing else.

For k = 1 the strain of Pi v is the cell average of eps(v) (3.8), so its trace is the cell average
of div v, a boundary integral: div_K(Pi v) = (1 / |K|) int_dK v . n ds = sum_i q_i . v_i. The
weights are read off the element's own strain operator (rows eps11 + eps22 (+ eps33) of B), so
they are the element's projection, not a second formula: in 2D ``k1_kernel.strain_operator``, in
3D the packed projection table of ``k1_3d_fields_kernel.projection_table`` (rows E11 + E22 + E33).

Both return (weights, measures): ``weights`` (d * sum n_K,) the coefficient of the dof d i + a of
every cell's local vertex i (in the element's ``cell_nodes`` order, cell after cell), ``measures``
(M,) the cells' areas (volumes) as the kernels compute them.
"""

from __future__ import annotations

import numba
import numpy as np

from vemkit.mesh.geometry import polygon_area
from vemkit.vem.elements.k1_3d_fields_kernel import projection_table
from vemkit.vem.elements.k1_kernel import cell_coordinates, strain_operator


@numba.njit(cache=True)
def divergence_table_2d(vertices, offsets, cell_vertices):
    """(weights (2 sum n,), areas (M,)): the rows eps11 + eps22 of every polygon's strain operator."""
    cells = offsets.shape[0] - 1
    weights = np.empty(2 * offsets[-1])
    areas = np.empty(cells)
    for c in range(cells):
        px, py = cell_coordinates(vertices, offsets, cell_vertices, c)
        n = px.shape[0]
        B = np.empty((3, 2 * n))
        areas[c] = polygon_area(px, py)
        strain_operator(px, py, areas[c], B)
        for j in range(2 * n):
            weights[2 * offsets[c] + j] = B[0, j] + B[1, j]
    return weights, areas


def divergence_2d(mesh):
    """The divergence weights and areas of every polygon of a 2D mesh (module docstring)."""
    return divergence_table_2d(mesh.vertices, mesh.cell_offsets, mesh.cell_vertices)


def divergence_3d(mesh, geometry):
    """The divergence weights and volumes of every polyhedron (module docstring); ``geometry`` the
    element's (``FirstOrder3D.geometry``)."""
    vertices, cell_face_ptr, face_ptr, face_local = geometry[:4]
    offsets, ids = mesh.cell_vertex_lists
    _, table, volumes = projection_table(vertices, offsets, ids, cell_face_ptr, face_ptr, face_local)
    return table[6] + table[7] + table[8], volumes
