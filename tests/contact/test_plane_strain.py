"""The scene's model (docs/reference/files.md): plane strain beside the paper's plane stress, checked against closed forms
nobody here wrote.

Lamé's thick-walled cylinder (a quarter annulus a < r < b with rollers on its straight sides and an
internal pressure p) has the radial displacement

    plane strain:  u_r = (1 + nu) p a^2 / (E (b^2 - a^2)) ((1 - 2 nu) r + b^2 / r)
    plane stress:  u_r = p a^2 / (E (b^2 - a^2)) ((1 - nu) r + (1 + nu) b^2 / r)

Each model must converge to its own formula (H1 order ~1 for k = 1, ~2 for k = 2 on the curved
body) and not to the other's; a uniform pressure on a square gives u = -p (1 + nu)(1 - 2 nu)/E x in
plane strain and -p (1 - nu)/E x in plane stress, exact on every family."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import FAMILY_CASES  # noqa: F401  (the families' options)

from vemkit.config.scene import scene_from_dict
from vemkit.studies.scene_solve import solve_scene

A, B, P, E, NU = 1.0, 2.0, 1.0, 100.0, 0.3


def radial(model: str) -> str:
    """u_r(r) / r as an expression (u = u_r x / r)."""
    c = P * A * A / (E * (B * B - A * A))
    if model == "plane_strain":
        return f"{(1 + NU) * c}*({1 - 2 * NU} + {B * B}/(x**2 + y**2))"
    return f"{c}*({1 - NU} + {(1 + NU) * B * B}/(x**2 + y**2))"


def cylinder(model: str, exact_model: str, h: float, order: int = 1) -> dict:
    g = radial(exact_model)
    return {
        "name": "lame",
        "model": model,
        "domain": {
            "polygon": [[A, 0], [B, 0], [0, B], [0, A]],
            "sides": ["bottom", "outer", "left", "bore"],
            "arcs": [None, [0, 0], None, [0, 0]],
        },
        "material": {"E": E, "nu": NU},
        "boundary": {"dirichlet": {"bottom": [None, 0.0], "left": [0.0, None]}, "neumann": {"bore": {"pressure": P}}},
        "discretization": {"mesh": {"family": "triangle", "h": h}, "order": order},
        "exact": {"displacement": [f"x*{g}", f"y*{g}"]},
        "solver": {"method": "ssn", "tol": 1e-12},
    }


@pytest.mark.parametrize("model", ["plane_stress", "plane_strain"])
def test_the_thick_cylinder_converges_to_lames_closed_form_of_its_model(model):
    errors = [solve_scene(scene_from_dict(cylinder(model, model, h)))[2].attrs["error_h1_semi"] for h in (0.2, 0.1)]
    assert errors[1] < 0.1 and np.log2(errors[0] / errors[1]) > 0.9, errors
    other = "plane_stress" if model == "plane_strain" else "plane_strain"
    wrong = solve_scene(scene_from_dict(cylinder(model, other, 0.1)))[2].attrs["error_l2"]
    assert wrong > 10 * solve_scene(scene_from_dict(cylinder(model, model, 0.1)))[2].attrs["error_l2"]


def test_plane_strain_with_k2_converges_at_order_two():
    errors = [
        solve_scene(scene_from_dict(cylinder("plane_strain", "plane_strain", h, 2)))[2].attrs["error_h1_semi"]
        for h in (0.4, 0.2)
    ]
    assert np.log2(errors[0] / errors[1]) > 1.7, errors


@pytest.mark.parametrize("family", ["square", "triangle", "voronoi", "hanging"])
@pytest.mark.parametrize("model, factor", [("plane_stress", (1 - NU)), ("plane_strain", (1 + NU) * (1 - 2 * NU))])
def test_uniform_pressure_gives_the_models_exact_strain_on_every_family(family, model, factor):
    scene = {
        "name": "compression",
        "model": model,
        "material": {"E": E, "nu": NU},
        "boundary": {
            "dirichlet": {"left": [0.0, None], "bottom": [None, 0.0]},
            "neumann": {"right": {"pressure": P}, "top": {"pressure": P}},
        },
        "discretization": {"mesh": {"family": family, "n": 4}},
        "solver": {"method": "ssn", "tol": 1e-12},
    }
    _, _, ds = solve_scene(scene_from_dict(scene))
    x, y = ds["mesh2d_node_x"].values, ds["mesh2d_node_y"].values
    assert np.max(np.abs(ds["u1"].values + P * factor / E * x)) < 1e-12
    assert np.max(np.abs(ds["u2"].values + P * factor / E * y)) < 1e-12
    assert ds.attrs["model"] == model
