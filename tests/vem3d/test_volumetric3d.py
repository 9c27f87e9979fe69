"""The averaged nodal volumetric strain on polyhedra (``vemkit.vem.volumetric``): the element's
divergence, the patch test, no spurious modes on tetrahedra, and the extruded Cook membrane on gmsh
tetrahedra at nu = 0.4999."""

from __future__ import annotations

import numpy as np
import pytest
from volumetric_checks import LAM, MU, kernel_size, patch_test

from vemkit.config.scene import scene_from_dict
from vemkit.contact.problem import scene_problem
from vemkit.mesh.families3d import build_mesh3d
from vemkit.solvers.dispatch import solve
from vemkit.vem.space import VirtualElementSpace
from vemkit.vem.volumetric import NodalAverage, stiffness_matrix

CUBE = {"box": [[0, 0, 0], [1, 1, 1]]}
MESHES = {
    "tet": lambda: build_mesh3d("tet", CUBE, n=2),
    "hex": lambda: build_mesh3d("hex", CUBE, n=3),
    "voronoi": lambda: build_mesh3d("voronoi", CUBE, n=3, seed=2),
}


@pytest.fixture(scope="module", params=list(MESHES))
def space(request):
    return VirtualElementSpace(MESHES[request.param](), 1)


def test_the_divergence_rows_are_the_trace_of_the_elements_projected_strain(space):
    u = np.random.default_rng(1).normal(size=(space.n_nodes, 3))
    strain = space.project(u, LAM, MU).cell_mean_strain()
    found = NodalAverage.of(space).cell_divergence(u)
    assert np.allclose(found, strain[:, :3].sum(axis=1), rtol=0, atol=1e-11)


def test_a_linear_displacement_is_reproduced_exactly(space):
    assert patch_test(space) < 1e-10


def test_no_spurious_modes_on_tetrahedra_the_kernel_is_the_rigid_motions():
    space = VirtualElementSpace(MESHES["tet"](), 1)
    K = stiffness_matrix(space, LAM, MU, "dofi-2mu", space.numbering(natural=True), "nodal_average")
    assert kernel_size(K) == 6


COOK_REFERENCE = 7.7695


def cook_tip_3d(h: float, volumetric: str, depth: float = 1.0) -> float:
    """u2 at the edge x = 48, y = 60 (mean over its vertices) / the plane-strain reference, on gmsh's
    tetrahedra of the membrane extruded to ``depth`` with u3 = 0 on both end faces."""
    scene = scene_from_dict(
        {
            "name": "cook_extruded",
            "model": "3d",
            "domain": {
                "polygon": [[0, 0], [48, 44], [48, 60], [0, 44]],
                "sides": ["bottom", "load", "top", "clamped"],
                "extrude": {"depth": depth, "ends": ["front", "back"]},
            },
            "material": {"E": 250.0, "nu": 0.4999},
            "boundary": {
                "dirichlet": {"clamped": [0.0, 0.0, 0.0], "front": [None, None, 0.0], "back": [None, None, 0.0]},
                "neumann": {"load": {"traction": [0.0, 6.25, 0.0]}},
            },
            "discretization": {"mesh": {"family": "tet", "h": h}, "volumetric_strain": volumetric},
        }
    )
    problem = scene_problem(scene)
    u = problem.dofs.expand(solve(problem, {**scene.solver_options, "linear": "direct"}).u)
    edge = np.all(np.isclose(problem.mesh.vertices[:, :2], [48.0, 60.0]), axis=1)
    return float(u[edge, 1].mean()) / COOK_REFERENCE


def test_cook_tetrahedra_lock_with_the_cell_form_and_not_with_nodal_averaging():
    """Measured (depth 1, the issue's numbers for cell): cell 0.669 (h = 4), 0.689 (h = 2);
    nodal_average 0.947 and 0.9715 (the issue's target: within 3 % at h = 2)."""
    assert cook_tip_3d(4.0, "cell") < 0.68
    assert cook_tip_3d(4.0, "nodal_average") > 0.94
    assert abs(cook_tip_3d(2.0, "nodal_average") - 1.0) < 0.03
