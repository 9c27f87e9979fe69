"""The Section 4 study's error measures (vemkit.vem.norms) on fields with known errors:
projections of either order against a k = 2 reference on a nested finer mesh, and traces on Gamma_C."""

import numpy as np
import pytest

from vemkit.mesh.families import build_mesh
from vemkit.vem.elasticity import lame_parameters
from vemkit.vem.elements.k1_fields import projected_solution
from vemkit.vem.elements.k2_fields import projected_solution_k2
from vemkit.vem.norms import projection_error, trace_error
from vemkit.vem.quadrature import reference_quadrature
from vemkit.vem.space import VirtualElementSpace

LAM, MU = lame_parameters(2000.0, 0.4)


def _quadratic(x, y):
    return 0.3 * x * x - 0.2 * x * y + 0.1, 0.5 * y * y + 0.4 * x


def _k2(mesh, field):
    values = VirtualElementSpace(mesh, 2).interpolate(field)
    return values, projected_solution_k2(mesh, values, LAM, MU)


def projection_error_degree5(coarse_mesh, coarse, ref_mesh, ref, regions=None):
    """``projection_error`` with the degree-5 rule on the reference cells (quadratic projections)."""
    return projection_error(coarse_mesh, coarse, ref_mesh, ref, reference_quadrature(ref_mesh, degree=5), regions)


def test_a_quadratic_has_no_error_at_k2_and_a_linear_field_none_at_k1():
    fine = build_mesh("square", 16)
    coarse = build_mesh("hanging", 4, levels=1, rule="contact")
    ref_values, ref = _k2(fine, _quadratic)
    coarse_values, coarse_proj = _k2(coarse, _quadratic)
    err = projection_error_degree5(
        coarse, coarse_proj, fine, ref, regions={"everywhere": lambda p: np.ones(len(p), bool)}
    )
    assert max(err["h1"], err["h1_semi"], err["l2"]) < 1e-12
    assert (
        trace_error(VirtualElementSpace(coarse, 2), coarse_values, VirtualElementSpace(fine, 2), ref_values, "bottom")
        < 1e-12
    )

    def linear(x, y):
        return 0.3 * x - 0.2 * y + 0.1, 0.5 * y + 0.4 * x

    _, ref_linear = _k2(fine, linear)
    k1 = projected_solution(coarse, np.stack(linear(*coarse.vertices.T), axis=1))
    assert projection_error_degree5(coarse, k1, fine, ref_linear)["h1"] < 1e-12


@pytest.mark.parametrize("n", [4, 8])
def test_known_errors_of_the_k1_interpolant_of_x_squared(n):
    """u = (x^2, 0) on n x n squares: the k = 1 projection of the vertex interpolant has the gradient
    2 x_mid per cell, so |Pi_1 u_I - u|_1 / |u|_1 = h / 2; on the bottom side the linear interpolant
    misses by (x - a)(b - x), so ||u_I - u||_L2 / ||u||_L2 = h^2 / sqrt(6)."""
    h = 1.0 / n

    def field(x, y):
        return x * x, 0 * x

    fine = build_mesh("square", 4 * n)
    ref_values, ref = _k2(fine, field)
    coarse = build_mesh("square", n)
    vertex_values = np.stack(field(*coarse.vertices.T), axis=1)
    err = projection_error_degree5(
        coarse, projected_solution(coarse, vertex_values), fine, ref, regions={"left half": lambda p: p[:, 0] < 0.5}
    )
    assert err["h1_semi"] == pytest.approx(h / 2, rel=1e-12)
    assert err["share_left half"] == pytest.approx(0.5, rel=1e-12)  # the error density is uniform
    assert trace_error(
        VirtualElementSpace(coarse, 1), vertex_values, VirtualElementSpace(fine, 2), ref_values, ["bottom"]
    ) == pytest.approx(h * h / np.sqrt(6), rel=1e-12)


@pytest.mark.parametrize("order", [1, 2])
def test_trace_errors_of_the_interpolants_of_a_cubic(order):
    """u = (x^3, 0) on the bottom of 4 x 4 squares, an edge x = c + eta m, m in [-1, 1]: the linear
    interpolant misses by eta^2 (1 - m^2)(3c + eta m) (the cubic's secant), the quadratic one with the
    vertex values and the edge mean by eta^3 (m^3 - m) (zero at both ends, zero mean). Given the
    interpolant as u_h, both errors of ``trace_errors`` are that number."""
    from vemkit.vem.norms import trace_errors

    mesh = build_mesh("square", 4)
    space = VirtualElementSpace(mesh, order)
    values = (
        np.stack([mesh.vertices[:, 0] ** 3, 0 * mesh.vertices[:, 0]], axis=1)
        if order == 1
        else space.interpolate(lambda x, y: (x**3, 0 * x))
    )
    err = trace_errors(space, "bottom", values, lambda p: np.stack([p[:, 0] ** 3, 0 * p[:, 0]], axis=1))
    m, w = np.polynomial.legendre.leggauss(10)
    eta, squared = 0.125, 0.0
    for c in (np.arange(4) + 0.5) / 4:
        miss = eta**2 * (1 - m**2) * (3 * c + eta * m) if order == 1 else eta**3 * (m**3 - m)
        squared += eta * np.sum(w * miss**2)
    expected = np.sqrt(squared / (1 / 7))  # ||x^3||^2 on [0, 1] = 1/7
    assert err["interpolation_contact_l2"] == pytest.approx(expected, rel=1e-12)
    assert err["contact_l2"] == pytest.approx(expected, rel=1e-12)


def test_trace_errors_against_a_nested_reference_trace_is_trace_error():
    """With the reference's trace as the field and pieces nested in its edges, ``trace_errors`` gives
    ``trace_error``'s number (the same integral over other pieces)."""
    from vemkit.vem.norms import boundary_trace, nesting_subdivisions, trace_errors

    def field(x, y):
        return np.sin(3 * x) * np.exp(y), np.cos(2 * x + y)

    fine, coarse = build_mesh("square", 32), build_mesh("hanging", 4, levels=1, rule="contact")
    fine_space, coarse_space = VirtualElementSpace(fine, 2), VirtualElementSpace(coarse, 2)
    ref_values, coarse_values = fine_space.interpolate(field), coarse_space.interpolate(field)
    m = nesting_subdivisions(coarse, fine, "bottom")
    assert m == 4  # coarse bottom edges 1/8, reference edges 1/32
    err = trace_errors(
        coarse_space, "bottom", coarse_values, lambda p: boundary_trace(fine_space, "bottom", ref_values, p), m
    )
    assert err["contact_l2"] == pytest.approx(
        trace_error(coarse_space, coarse_values, fine_space, ref_values, "bottom"), rel=1e-10
    )
    # the coarse values are the interpolant of the field, the reference a 4x finer one: I_h u_ref is
    # I_h u up to the reference's own O(h^3 / 64) trace error
    assert err["interpolation_contact_l2"] == pytest.approx(err["contact_l2"], rel=0.05)
