"""The a posteriori indicators (vemkit.vem.estimator): exact where they must be, and Dörfler marking."""

import numpy as np
import pytest
from conftest import FAMILY_CASES, family_mesh

from vemkit.contact.problem import discrete_problem
from vemkit.solvers.linear import linear_solver
from vemkit.vem.elasticity import lame_parameters
from vemkit.vem.elements import stabilization_code
from vemkit.vem.estimator import dorfler_marking, error_indicators, local_energies
from vemkit.vem.space import VirtualElementSpace

LAM, MU = lame_parameters(2000.0, 0.4)


@pytest.mark.parametrize("case", list(FAMILY_CASES))
@pytest.mark.parametrize("stab", ["dofi", "dofi-2mu", "trace"])
def test_local_energies_add_up_to_the_assembled_energy(case, stab):
    mesh = family_mesh(case, 5)
    u = np.random.default_rng(3).normal(size=(mesh.n_vertices, 2))
    total, consistency = local_energies(
        mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, u, LAM, MU, stabilization_code(stab)
    )
    K = VirtualElementSpace(mesh, 1).stiffness_matrix(LAM, MU, stab)
    assert np.isclose(total.sum(), u.ravel() @ (K @ u.ravel()), rtol=1e-12)
    assert np.all(consistency <= total * (1 + 1e-12))


@pytest.mark.parametrize("case", list(FAMILY_CASES))
def test_the_estimate_vanishes_for_the_exact_solution_of_the_patch_test(case):
    """A linear displacement is the discrete solution: no jump, no traction misfit, no stabilization."""
    mesh = family_mesh(case, 6)
    c = np.array([0.02, -0.013])
    grad = np.outer(c, [1.0, 0.0])
    eps = 0.5 * (grad + grad.T)
    sig = LAM * np.trace(eps) * np.eye(2) + 2 * MU * eps
    tractions = {
        side: (lambda x, y, t=sig @ np.array(n, float): (t[0] + 0 * x, t[1] + 0 * x))
        for side, n in {"left": [-1, 0], "top": [0, 1], "bottom": [0, -1]}.items()
    }
    pb = discrete_problem(mesh, 2000.0, 0.4, dirichlet=("right",), neumann=tractions)
    u = pb.dofs.expand(linear_solver(pb.stiffness, "direct").solve(pb.load))
    found = error_indicators(mesh, u, pb.lam, pb.mu, pb.stabilization, neumann=tractions)
    assert found["estimate"] < 1e-6  # round-off: the terms are squares, η their root (a wrong datum: 1e-1)
    # a wrong traction datum on one side is seen there, and only in the cells touching that side
    wrong = dict(tractions, top=lambda x, y: (0 * x + sig[0, 1] + 1.0, 0 * x + sig[1, 1]))
    seen = error_indicators(mesh, u, pb.lam, pb.mu, pb.stabilization, neumann=wrong)
    flagged = np.flatnonzero(seen["neumann"] > 1e-12)
    top = np.unique(
        np.searchsorted(
            mesh.cell_offsets, np.flatnonzero(np.isin(mesh.cell_vertices, mesh.boundary["top"])), side="right"
        )
        - 1
    )
    touching = [k for k in top if np.isin(mesh.boundary["top"], mesh.cell(k)).all(axis=1).any()]
    assert flagged.tolist() == sorted(touching)
    # |e| ∫_e |Δt|² summed over the top side = Σ |e|² with Δt = (1, 0): the side length squared / m
    lengths = np.linalg.norm(np.diff(mesh.vertices[mesh.boundary["top"]], axis=1), axis=-1).ravel()
    assert np.isclose(seen["neumann"].sum(), np.sum(lengths**2), rtol=1e-10)


def test_the_contact_traction_is_the_datum_on_the_contact_side():
    """σ n = t_C makes the contact term vanish; any other t_C is measured as |e| ∫ |t_C − σ n|²."""
    mesh = family_mesh("square", 4)
    u = np.zeros((mesh.n_vertices, 2))
    t_c = np.zeros((mesh.n_vertices, 2))
    assert error_indicators(mesh, u, LAM, MU, "dofi-2mu", contact={"bottom": t_c})["estimate"] == 0.0
    t_c[:, 1] = 3.0
    found = error_indicators(mesh, u + np.array([0.0, 1e-3]), LAM, MU, "dofi-2mu", contact={"bottom": t_c})
    edge = 0.25
    assert np.isclose(found["contact"].sum(), 4 * edge**2 * 9.0)


def test_dorfler_marks_the_fewest_cells_holding_theta_of_the_estimate():
    eta = np.array([0.1, 3.0, 0.5, 2.0, 0.2])
    marked = dorfler_marking(eta, 0.5)
    assert marked.tolist() == [1]  # 9 of 13.3
    marked = dorfler_marking(eta, 0.8)
    assert marked.tolist() == [1, 3]  # 13 of 13.3
    assert dorfler_marking(eta, 1.0).tolist() == [0, 1, 2, 3, 4]
