"""Contact on any side of any body (docs/reference/files.md): a slanted side gets its own normal and tangent."""

from pathlib import Path

import numpy as np
import yaml

import vemkit
from vemkit.config.scene import scene_from_dict
from vemkit.solvers.verification import verify_solution

PAPER = Path(__file__).resolve().parents[2] / "config" / "scenes" / "paper.yaml"


def test_a_slanted_contact_side_has_its_own_normal_and_the_solution_passes_the_check():
    data = yaml.safe_load(PAPER.read_text())
    data["domain"] = {"polygon": [[0, 0], [2, 0], [3, 1], [0, 1]], "sides": ["base", "slope", "top", "left"]}
    data["boundary"] = {
        "dirichlet": ["left"],
        "neumann": {"top": {"traction": [0.0, -200.0]}},
        "contact": ["base", "slope"],
    }
    data["discretization"]["mesh"] = {"family": "voronoi", "n": 6}
    scene = scene_from_dict(data)
    problem = vemkit.scene_problem(scene)
    solution = vemkit.solve(problem, scene.solver_options)
    assert verify_solution(problem, solution.u, solution.multiplier)["worst"] < 1e-9
    cb = problem.contact
    x, y = cb.coords[:, 0], cb.coords[:, 1]
    on_slope = np.isclose(y, x - 2.0) & (y > 1e-9)
    on_base = np.isclose(y, 0.0) & (x < 2.0 - 1e-9)
    assert on_slope.sum() >= 3 and on_base.sum() >= 3
    assert np.allclose(cb.normal[on_slope], [2**-0.5, -(2**-0.5)])
    assert np.allclose(cb.normal[on_base], [0.0, -1.0])
    assert np.allclose(np.sum(cb.normal * cb.tangent, axis=1), 0.0)
