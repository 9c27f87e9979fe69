import numpy as np
import pytest

from vemkit.contact.laws import ContactLaw
from vemkit.mesh.families import build_mesh
from vemkit.contact.problem import discrete_problem

PAPER = dict(E=2000.0, nu=0.4, gap=0.1, law=ContactLaw(10.0, 1.0, 450.0, 0.0))

# one mesh of every family and kind, small enough for quick tests
FAMILY_CASES = {
    "square": dict(family="square"),
    "triangle-structured": dict(family="triangle", kind="structured"),
    "triangle-delaunay": dict(family="triangle", kind="delaunay", seed=1),
    "voronoi": dict(family="voronoi", seed=2),
    "hanging-contact": dict(family="hanging", levels=2, rule="contact"),
    "hanging-random": dict(family="hanging", levels=2, rule="random", seed=3),
}


def family_mesh(case: str, n: int):
    opts = dict(FAMILY_CASES[case])
    return build_mesh(opts.pop("family"), n, **opts)


def paper_problem(mesh, stabilization="dofi-2mu", law=None, gap=None, E=None, nu=None):
    g = PAPER["gap"] if gap is None else gap
    return discrete_problem(
        mesh,
        PAPER["E"] if E is None else E,
        PAPER["nu"] if nu is None else nu,
        dirichlet=("right",),
        neumann={"left": lambda x, y: (200 * (5 - y), -200 + 0 * y), "top": lambda x, y: (0 * x, 0 * x)},
        contact=("bottom",),
        gap=lambda x, y: g + 0 * x,
        law=PAPER["law"] if law is None else law,
        stabilization=stabilization,
    )


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
