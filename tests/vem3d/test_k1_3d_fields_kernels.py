"""The Numba kernels of the 3D loads and projected fields (``k1_3d_fields``) against their numpy twins,
the cell-by-cell originals (``k1_3d_fields_reference``): the same numbers to round-off, on hexahedra,
tetrahedra, non-convex prisms, hanging nodes and random convex hulls under random affine maps."""

import numpy as np
import pytest
from polyhedra3d import hanging_mesh, hex_grid, l_stack, mapped, random_affine, random_hull, tet_grid

from vemkit.vem.elements import element_for
from vemkit.vem.elements import k1_3d_fields as fields
from vemkit.vem.elements import k1_3d_fields_reference as reference

ELEMENT = element_for(1, 3)


def meshes():
    rng = np.random.default_rng(11)
    for base in (hex_grid(3), tet_grid(2)[0], hanging_mesh(), l_stack(2), random_hull(rng, 16)):
        yield mapped(base, *random_affine(rng))


def close(a, b, rtol=1e-12):
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and np.abs(a - b).max(initial=0.0) <= rtol * max(np.abs(b).max(initial=0.0), 1e-300)


FIELD = staticmethod(lambda x, y, z: (np.sin(x) * y + 1.0, z * z - x, np.exp(0.3 * y) + 0 * x))


@pytest.mark.parametrize("index", range(5))
def test_quadrature_projections_loads_and_fields_equal_the_reference(index):
    mesh = list(meshes())[index]
    geometry = ELEMENT.geometry(mesh)
    f = FIELD.__func__
    for new, old in zip(fields.cell_quadrature(mesh, 3), reference.cell_quadrature_reference(mesh, 3)):
        assert close(new, old)
    xbar, table, volumes = fields.cell_projections(mesh, geometry)
    xbar_ref, Ps, volumes_ref = reference.cell_projections_reference(mesh, geometry)
    assert close(xbar, xbar_ref) and close(volumes, volumes_ref) and close(table, np.concatenate(Ps, axis=1))
    assert close(fields.body_force_load(mesh, geometry, f), reference.body_force_load_reference(mesh, geometry, f))
    chunked = fields.body_force_load(mesh, geometry, f, chunk_points=1)  # one cell at a time
    assert close(chunked, reference.body_force_load_reference(mesh, geometry, f))
    u = np.random.default_rng(index).standard_normal((mesh.n_vertices, 3))
    new, old = fields.projected_solution(mesh, geometry, u), reference.projected_solution_reference(mesh, geometry, u)
    assert close(new.xbar, old.xbar) and close(new.c, old.c) and close(new.G, old.G)
    faces = mesh.boundary_faces
    assert close(fields.traction_load(mesh, faces, f), reference.traction_load_reference(mesh, faces, f))
