"""The solve's errors against ``exact:`` (docs/reference/files.md) are the exact integrals (issue 18, item 6).

For a field that varies on the scale of a finite-difference step (waves of length 0.1 to 0.16)
``error_h1_semi``, ``error_h1`` and ``error_l2`` must equal ||Π u_h − u|| / ||u|| computed with the
field's gradient written out by hand, to rounding, for k = 1 and k = 2 alike. (A fourth-order
difference of step 1e-3 is off by about 1e-6 relative here.)
"""

from pathlib import Path

import numpy as np
import pytest

from vemkit.config.scene import load_scene
from vemkit.studies.scene_solve import solve_scene
from vemkit.vem.norms import exact_errors
from vemkit.vem.quadrature import reference_quadrature

ROOT = Path(__file__).resolve().parents[2]

TEXT = ["0.01*sin(40*x)*cos(30*y)", "0.01*exp(x*y)*sin(50*y)"]


def field(x, y):
    return 0.01 * np.sin(40 * x) * np.cos(30 * y), 0.01 * np.exp(x * y) * np.sin(50 * y)


def field_gradient(x, y):
    """[component, derivative] of ``field``, differentiated by hand."""
    return np.array(
        [
            [0.4 * np.cos(40 * x) * np.cos(30 * y), -0.3 * np.sin(40 * x) * np.sin(30 * y)],
            [
                0.01 * y * np.exp(x * y) * np.sin(50 * y),
                0.01 * np.exp(x * y) * (x * np.sin(50 * y) + 50 * np.cos(50 * y)),
            ],
        ]
    )


@pytest.mark.parametrize("order", [1, 2])
def test_the_exact_error_attributes_are_the_exact_integrals(order):
    scene = load_scene(ROOT / "config" / "scenes" / "paper.yaml").with_overrides(
        ["discretization.mesh.n=8", f"discretization.order={order}", f"exact.displacement={TEXT}"]
    )
    problem, solution, ds = solve_scene(scene)
    quadrature = points, weights, _ = reference_quadrature(problem.mesh, degree=5)
    absolute = exact_errors(problem.mesh, problem.projected(solution.u), field, field_gradient, quadrature)
    l2 = np.sqrt(np.sum(weights * np.sum(np.square(field(*points.T)), axis=0)))
    semi = np.sqrt(np.sum(weights * np.sum(np.square(field_gradient(*points.T)), axis=(0, 1))))
    assert ds.attrs["error_l2"] == pytest.approx(absolute["l2"] / l2, rel=1e-12)
    assert ds.attrs["error_h1_semi"] == pytest.approx(absolute["h1_semi"] / semi, rel=1e-12)
    assert ds.attrs["error_h1"] == pytest.approx(
        np.hypot(absolute["l2"], absolute["h1_semi"]) / np.hypot(l2, semi), rel=1e-12
    )
