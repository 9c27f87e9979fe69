"""The tabulated normal compliance (contact.normal: {law: table, penetration, pressure}) behind the law interface.

A table sampling a linear p_nu (m = 1: [0, 1] -> [0, k]) is the power law to the last bit, as a law and
through both solvers in 2D and 3D; ssn converges fast on a nonlinear table; a bad table is refused with
one line naming the key.
"""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import vemkit
from vemkit.contact.laws import ContactLaw, TabulatedContactLaw
from vemkit.exceptions import SceneError
from vemkit.solvers.verification import verify_solution

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "config" / "scenes" / "paper.yaml"
SHEARED = ROOT / "config" / "scenes" / "3d" / "sheared_box.yaml"


def _table_of_linear(k: float) -> str:
    return "contact.normal=" + json.dumps({"law": "table", "penetration": [0.0, 1.0], "pressure": [0.0, k]})


def test_a_linear_table_is_the_power_law_to_the_last_bit():
    power = ContactLaw(10.0, 1.0, 450.0, 0.0)
    table = TabulatedContactLaw((0.0, 1.0), (0.0, 10.0), 450.0, 0.0)
    t = np.concatenate([np.linspace(-0.3, 2.5, 1001), [0.0, 1.0, 1e-300, 1e6]])
    for name in ("normal_pressure", "normal_stiffness", "normal_energy", "friction_bound", "friction_bound_derivative"):
        np.testing.assert_array_equal(getattr(table, name)(t), getattr(power, name)(t), err_msg=name)
    assert table.friction_coefficient == power.friction_coefficient and table.reduced and not table.frictionless
    assert table.lagged_stiffness(t) == power.lagged_stiffness(t) == 10.0


def test_the_table_is_piecewise_linear_and_goes_on_with_its_last_slope():
    law = TabulatedContactLaw((0.0, 0.01, 0.05), (0.0, 5.0, 40.0), 0.0, 0.0)
    t = np.array([-1.0, 0.0, 0.005, 0.01, 0.03, 0.05, 0.15])
    np.testing.assert_allclose(law.normal_pressure(t), [0.0, 0.0, 2.5, 5.0, 22.5, 40.0, 127.5], rtol=1e-14)
    # p_nu' piecewise constant: the right slope at a point of the table, 0 at and below 0
    np.testing.assert_allclose(law.normal_stiffness(t), [0.0, 0.0, 500.0, 875.0, 875.0, 875.0, 875.0], rtol=1e-14)
    # P_nu' = p_nu: the energy against a fine trapezoid integral of the pressure
    s = np.linspace(0.0, 0.15, 300001)
    p = law.normal_pressure(s)
    integral = np.concatenate([[0.0], np.cumsum(np.diff(s) * (p[:-1] + p[1:]) / 2.0)])
    np.testing.assert_allclose(law.normal_energy(s[::1000]), integral[::1000], rtol=1e-8, atol=1e-14)
    assert law.lagged_stiffness(t) == pytest.approx(875.0) and law.frictionless


def _solve(path, settings):
    scene = vemkit.load_scene(path, settings)
    problem = vemkit.scene_problem(scene)
    return problem, vemkit.solve(problem, scene.solver_options)


CASES = {
    "2d-ssn": (PAPER, ["discretization.mesh.n=8"], 10.0),
    "2d-uzawa": (PAPER, ["discretization.mesh.n=8", "solver.method=uzawa"], 10.0),
    "3d-ssn-amg": (SHEARED, ["discretization.mesh.n=3"], 200.0),
    "3d-uzawa": (SHEARED, ["discretization.mesh.n=3", "solver.method=uzawa"], 200.0),
}


@pytest.mark.parametrize("case", CASES)
def test_a_linear_table_solves_as_the_power_law(case):
    path, settings, k = CASES[case]
    _, power = _solve(path, settings)
    problem, table = _solve(path, [*settings, _table_of_linear(k)])
    assert isinstance(problem.law, TabulatedContactLaw)
    np.testing.assert_array_equal(table.u, power.u)  # the same numbers in the same order: bit for bit
    np.testing.assert_array_equal(table.multiplier, power.multiplier)
    assert table.iterations == power.iterations and table.linear_iterations == power.linear_iterations


def test_ssn_converges_fast_on_a_nonlinear_table():
    points = [0.0, 0.02, 0.05, 0.1, 0.2]
    table = {"law": "table", "penetration": points, "pressure": [0.0, 0.5, 5.0, 40.0, 200.0]}
    problem, solution = _solve(PAPER, ["discretization.mesh.n=16", "contact.normal=" + json.dumps(table)])
    t = problem.contact.normal_displacement(solution.u) - problem.contact.gap
    segments = set(np.searchsorted(points, t[t > 0.0], side="right"))
    assert len(segments) >= 3 and np.max(t) > 0.1  # the solution crosses the kinks of the table
    residual = np.asarray(solution.history["residual"])
    assert solution.iterations <= 8 and residual[-1] <= 1e-10
    # a generalized Newton method on a piecewise linear law: once the pieces are found, the next step
    # is exact (the last step drops the residual to rounding), before that each step gains an order
    assert residual[-1] <= 1e-8 * residual[-2]
    assert all(later <= 0.1 * earlier for earlier, later in zip(residual[:-1], residual[1:]))
    checks = verify_solution(problem, solution.u, solution.multiplier, 1e-8)
    assert checks["passed"]


@pytest.mark.parametrize(
    "table, key",
    [
        ({"law": "table", "penetration": [0, 0.02, 0.01], "pressure": [0, 1, 2]}, "contact.normal.penetration"),
        ({"law": "table", "penetration": [0.01, 0.02], "pressure": [0, 1]}, "contact.normal.penetration"),
        ({"law": "table", "penetration": [0, 0.01, 0.02], "pressure": [0, 5, 4]}, "contact.normal.pressure"),
        ({"law": "table", "penetration": [0, 0.01], "pressure": [1, 5]}, "contact.normal.pressure"),
        ({"law": "table", "penetration": [0, 0.01, 0.02], "pressure": [0, 5]}, "contact.normal.pressure"),
        ({"law": "table", "penetration": [0, 0.01]}, "contact.normal.pressure"),
        ({"law": "table", "penetration": [0, 0.01], "pressure": [0, 5], "k": 10}, "contact.normal.k"),
        ({"m": 1.0}, "contact.normal.k"),
    ],
)
def test_a_bad_table_is_refused_naming_the_key(table, key):
    with pytest.raises(SceneError) as error:
        vemkit.load_scene(PAPER, ["contact.normal=" + json.dumps(table)])
    assert error.value.key == key and "\n" not in str(error.value) and key in str(error.value)


def test_the_command_refuses_a_bad_table_with_one_line(tmp_path):
    out = tmp_path / "out.nc"
    table = {"law": "table", "penetration": [0, 0.02, 0.01], "pressure": [0, 1, 2]}
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "vemkit.cli",
            "solve",
            str(PAPER),
            "-o",
            str(out),
            "--set",
            f"contact.normal={json.dumps(table)}",
        ],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 2
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and "contact.normal.penetration" in lines[0] and "increase" in lines[0]
    assert not out.exists()


def test_uzawa_on_a_stiff_table_names_the_table_and_its_slope():
    """Uzawa's contraction estimate asks the law (its largest slope), not a k it does not have."""
    from dataclasses import replace

    from vemkit.exceptions import ConvergenceError
    from vemkit.solvers.uzawa import solve_uzawa

    scene = vemkit.load_scene(PAPER, ["discretization.mesh.n=16"])
    problem = vemkit.scene_problem(scene)
    stiff = replace(problem, law=TabulatedContactLaw((0.0, 0.01, 1.0), (0.0, 10.0, 1e6), 450.0, 0.0))
    with pytest.raises(ConvergenceError) as failure:
        solve_uzawa(stiff, linear="direct")
    message = str(failure.value)
    assert "\n" not in message and "unstable for the table contact.normal (largest slope 1.01009e+06)" in message
