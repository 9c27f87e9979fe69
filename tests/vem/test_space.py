"""The one space over every element: what ``VirtualElementSpace`` promises, the same way for k = 1 and k = 2.

Each test pins mathematics that holds for any element of order k: polynomials of degree k are in the
space and reproduced by Pi, rigid motions are the kernel of the stiffness matrix, the trace of the
interpolant of a degree-k field is the field on every edge, and the numbering is a bijection of the
free nodes."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import family_mesh

from vemkit.contact.problem import discrete_problem
from vemkit.vem.elasticity import lame_parameters
from vemkit.vem.elements import ORDERS, element_for
from vemkit.vem.space import VirtualElementSpace

LAM, MU = lame_parameters(2000.0, 0.4)
CASES = ["square", "voronoi", "hanging-random", "triangle-delaunay"]


def polynomial(order: int):
    """A vector field of degree ``order`` (every monomial present)."""

    def field(x, y):
        u1 = 0.1 + 0.2 * x - 0.3 * y + (order >= 2) * (0.05 * x * x - 0.07 * x * y + 0.02 * y * y)
        u2 = -0.2 + 0.1 * x + 0.4 * y + (order >= 2) * (0.03 * x * x + 0.06 * x * y - 0.04 * y * y)
        return u1, u2

    return field


@pytest.mark.parametrize("order", ORDERS)
@pytest.mark.parametrize("case", CASES)
def test_pi_reproduces_polynomials_of_the_elements_degree(order, case):
    space = VirtualElementSpace(family_mesh(case, 6), order)
    field = polynomial(order)
    projection = space.project(space.interpolate(field), LAM, MU)
    rng = np.random.default_rng(0)
    cells = rng.integers(0, space.mesh.n_cells, 200)
    offsets = space.mesh.cell_offsets
    corner = space.mesh.vertices[space.mesh.cell_vertices[offsets[cells]]]
    centre = (
        np.add.reduceat(space.mesh.vertices[space.mesh.cell_vertices], offsets[:-1])[cells]
        / space.mesh.cell_sizes[cells, None]
    )
    points = centre + rng.uniform(0, 0.5, (200, 1)) * (corner - centre)  # inside a star-shaped cell
    exact = np.stack(field(points[:, 0], points[:, 1]), axis=1)
    assert np.max(np.abs(projection.evaluate(cells, points) - exact)) < 1e-11


@pytest.mark.parametrize("order", ORDERS)
def test_the_stiffness_kernel_is_the_rigid_motions(order):
    space = VirtualElementSpace(family_mesh("voronoi", 5), order)
    dofs = space.numbering(natural=True)
    K = space.stiffness_matrix(LAM, MU, "dofi-2mu", dofs)
    for motion in (lambda x, y: (np.ones_like(x), 0 * x), lambda x, y: (0 * x, np.ones_like(x)), lambda x, y: (-y, x)):
        u = dofs.restrict(space.interpolate(motion))
        assert np.max(np.abs(K @ u)) < 1e-9 * abs(K).max()
    eigenvalues = np.linalg.eigvalsh(K.toarray())
    assert np.sum(eigenvalues < 1e-10 * eigenvalues[-1]) == 3


@pytest.mark.parametrize("order", ORDERS)
def test_the_trace_of_the_interpolant_is_the_field_on_every_edge(order):
    space = VirtualElementSpace(family_mesh("square", 4), order)
    field = polynomial(order)
    edges = space.mesh.boundary["bottom"]
    s = np.linspace(0, 1, edges.shape[0])
    points = (1 - s)[:, None] * space.mesh.vertices[edges[:, 0]] + s[:, None] * space.mesh.vertices[edges[:, 1]]
    trace = space.boundary_trace(edges, space.interpolate(field), s)
    assert np.max(np.abs(trace - np.stack(field(points[:, 0], points[:, 1]), axis=1))) < 1e-13


@pytest.mark.parametrize("order", ORDERS)
def test_the_numbering_numbers_every_free_node_once(order):
    space = VirtualElementSpace(family_mesh("hanging-random", 4), order)
    clamped = space.clamped_on(space.mesh.boundary["right"])
    for condensed in (False, True):
        dofs = space.numbering(clamped, condensed=condensed)
        free = ~clamped
        if condensed:
            free[space.node_range("cell")] = False
        assert np.array_equal(np.sort(dofs.free_nodes), np.flatnonzero(free))
        assert np.array_equal(dofs.free_index[dofs.free_nodes], np.arange(dofs.free_nodes.size))
        assert dofs.n_free == 2 * int(free.sum()) and dofs.condensed == (condensed and order > 1)
    assert space.n_dofs == element_for(order).count_dofs(
        space.mesh.n_vertices, space.mesh.edges.shape[0], space.mesh.n_cells
    )


def test_the_unknowns_invert_the_change_of_variables_of_the_contact_midpoints():
    problem = discrete_problem(
        family_mesh("square", 4),
        2000.0,
        0.4,
        order=2,
        contact=["bottom"],
        neumann={"left": lambda x, y: (np.ones_like(x), 0 * x)},
    )
    assert problem.dofs.change is not None
    rng = np.random.default_rng(1)
    values = problem.dofs.node_values(rng.standard_normal(problem.n_dofs))
    u = problem.dofs.unknowns(values)
    assert np.allclose(problem.dofs.node_values(u), values, rtol=0, atol=1e-14)
