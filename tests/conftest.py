import numpy as np
import pytest

from vemkit.contact.laws import ContactLaw
from vemkit.contact.problem import discrete_problem
from vemkit.mesh.families import build_mesh
from vemkit.mesh.mesh import from_polygons, tag_box_boundary

#: the settings under which uzawa and ssn must agree to 1e-10 (issue 21 item 2): tol 1e-12, direct solves,
#: uzawa stopped on both |du| and |dlambda| well below tol
AGREEMENT_SOLVERS = {
    "uzawa": {
        "method": "uzawa",
        "tol": 1e-12,
        "linear": "direct",
        "stop": "both",
        "eps_u": 1e-13,
        "eps_lambda": 1e-13,
        "max_iterations": 20000,
    },
    "ssn": {"method": "ssn", "tol": 1e-12, "linear": "direct"},
}
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


#: single cells of every kind the kernels must handle (counter-clockwise)
POLYGONS = {
    "square": [[0, 0], [1, 0], [1, 1], [0, 1]],
    "triangle": [[0, 0], [1, 0.2], [0.3, 0.9]],
    "pentagon": [[0, 0], [2, 0.1], [2.5, 1.3], [1, 2], [-0.3, 1]],
    "nonconvex-arrow": [[0, 0], [2, 0], [2, 2], [1, 0.5], [0, 2]],
    "hanging-square": [[0, 0], [0.5, 0], [1, 0], [1, 0.5], [1, 1], [0, 1]],
    "L-shape": [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]],
}


def nonconvex_mesh():
    """Unit square as two non-convex cells (a dent at (0.3, 0.55) and (0.75, 0.45)) and two triangles."""
    v = [[0, 0], [0.5, 0.3], [1, 0], [1, 0.5], [1, 1], [0.5, 0.8], [0, 1], [0, 0.5], [0.3, 0.55], [0.75, 0.45]]
    polys = [
        [0, 1, 8, 5, 6, 7],  # reflex angle at vertex 8
        [1, 9, 2, 3, 4, 5, 8],  # reflex angle at vertex 9
        [0, 2, 9, 1],  # a triangle with vertex 1 in the middle of its edge
        [5, 4, 6],
    ]
    mesh = tag_box_boundary(from_polygons(np.array(v, float), polys))
    assert np.all(mesh.cell_areas > 0) and abs(mesh.cell_areas.sum() - 1) < 1e-14
    return mesh


def assert_no_nan_stored(path) -> None:
    """Every float variable of a netCDF file holds finite numbers (undefined entries: _FillValue)."""
    import netCDF4

    with netCDF4.Dataset(path) as nc:
        nc.set_auto_mask(False)
        for name, var in nc.variables.items():
            if var.dtype is not str and var.dtype.kind == "f":
                assert np.all(np.isfinite(var[:])), name


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
