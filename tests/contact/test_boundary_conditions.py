"""docs/reference/files.md boundary conditions pinned by exact solutions: rollers, prescribed displacements,
normal pressure, the exact-error attributes, the foundation line, rigid motions refused."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from manufactured import elasticity_solution

from vemkit.config.scene import load_scene, scene_from_dict
from vemkit.exceptions import SceneError
from vemkit.studies.scene_solve import solve_scene

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "config" / "scenes" / "paper.yaml"
FAMILIES = ["square", "triangle", "voronoi", "hanging"]
E, NU, P = 100.0, 0.25, 3.0
SHRINK = P * (1 - NU) / E  # plane stress, sigma = -p I: eps = -p (1 - nu) / E in every direction
PLATE = {
    "polygon": [[0, 0], [2, 0], [2, 1], [0, 1]],
    "sides": ["bottom", "right", "top", "left"],
    "holes": [{"circle": [1.2, 0.5, 0.2], "side": "hole"}],
}


def _scene(boundary, domain=PLATE, family="voronoi", size=("h", 0.2), **extra):
    data = {
        "name": "bc",
        "domain": domain,
        "material": {"E": E, "nu": NU},
        "boundary": boundary,
        "discretization": {"mesh": {"family": family, size[0]: size[1]}},
        **extra,
    }
    return scene_from_dict(data)


@pytest.mark.parametrize("family", FAMILIES)
def test_pressure_on_every_free_side_and_the_hole_with_rollers_is_uniform_compression(family):
    """Patch test with a hole: pressure p on right, top and the hole, rollers on left and bottom
    give sigma = -p I exactly, u = -p (1 - nu) / E (x, y); the exact-error attributes are ~0."""
    scene = _scene(
        {
            "dirichlet": {"left": [0.0, None], "bottom": [None, 0.0]},
            "neumann": {side: {"pressure": P} for side in ("right", "top", "hole")},
        },
        family=family,
        exact={"displacement": [f"-{SHRINK}*x", f"-{SHRINK}*y"]},
    )
    problem, solution, ds = solve_scene(scene)
    u = problem.dofs.expand(solution.u)
    np.testing.assert_allclose(u, -SHRINK * problem.mesh.vertices, atol=1e-12)
    for name in ("error_h1", "error_h1_semi", "error_l2"):
        assert ds.attrs[name] < 1e-9
    np.testing.assert_allclose(ds["stress_11"].values, -P, atol=1e-9)


@pytest.mark.parametrize("family", FAMILIES)
def test_prescribed_linear_displacement_on_the_boundary_is_reproduced_inside(family):
    """Nonzero Dirichlet expressions on every side (a kept vertex per dof, held by identity rows):
    the linear field is the exact solution, reproduced at every vertex."""
    field = ("0.01*x + 0.02*y", "-0.005*x + 0.03*y")
    scene = _scene(
        {"dirichlet": {side: list(field) for side in ("bottom", "right", "top", "left")}},
        domain="unit_square",
        family=family,
        size=("n", 6),
        exact={"displacement": list(field)},
    )
    problem, solution, ds = solve_scene(scene)
    x, y = problem.mesh.vertices.T
    np.testing.assert_allclose(
        problem.dofs.expand(solution.u), np.stack([0.01 * x + 0.02 * y, -0.005 * x + 0.03 * y], axis=1), atol=1e-12
    )
    assert ds.attrs["error_h1"] < 1e-9


def test_exact_errors_of_a_nonpolynomial_field_fall_at_the_expected_rates():
    """u = (sin x sin y, x y^2 / 4) imposed on the whole boundary with its body force: relative
    H1 error O(h), L2 O(h^2) (Pi_1 of u_h, docs/reference/files.md)."""
    field = ["sin(x)*sin(y)", "x*y**2/4"]
    force = elasticity_solution(*field, E, NU)["body_force"]
    sides = ("bottom", "right", "top", "left")
    errors = []
    for n in (8, 16):
        scene = _scene(
            {"dirichlet": {side: field for side in sides}},
            domain="unit_square",
            family="square",
            size=("n", n),
            exact={"displacement": field},
            body_force=force,
        )
        errors.append(solve_scene(scene)[2].attrs)
    h1 = np.log2(errors[0]["error_h1"] / errors[1]["error_h1"])
    l2 = np.log2(errors[0]["error_l2"] / errors[1]["error_l2"])
    assert 0.9 < h1 < 1.2 and 1.8 < l2 < 2.3, (h1, l2)


@pytest.mark.parametrize(
    "dirichlet, motion",
    [
        ({"bottom": [None, 0.0]}, "a translation in x"),
        ({"left": [0.0, None]}, "a translation in y"),
        ({"left": [0.0, None], "right": [0.0, None]}, "a translation in y"),
    ],
)
def test_a_free_rigid_motion_is_refused_naming_it(dirichlet, motion):
    """Refused when the scene is read (on the domain's sides), before any mesh exists."""
    with pytest.raises(SceneError, match=motion) as caught:
        _scene({"dirichlet": dirichlet}, domain="unit_square", size=("n", 4))
    assert caught.value.key == "boundary.dirichlet"


def test_a_rotation_left_free_is_named_with_its_centre():
    """Horizontal rollers along one vertical line hold x; a vertical roller at one point of it
    would not stop a rotation about that point: a single corner vertex shared by two sides."""
    domain = {"polygon": [[0, 0], [1, 0], [1, 1], [0, 1]], "sides": ["s", "s", "t", "u"]}
    with pytest.raises(SceneError, match="translation in y"):
        _scene({"dirichlet": {"u": [0.0, None]}}, domain=domain, size=("n", 2))
    from vemkit.config.boundary_conditions import free_rigid_motion

    one_point = free_rigid_motion(np.array([[2.0, 3.0]]), np.array([[True, True]]))
    assert one_point == "a rotation about (2, 3)"


def test_the_rigid_motion_error_is_one_line_through_the_cli(tmp_path):
    scene = tmp_path / "free.yaml"
    scene.write_text(PAPER.read_text().replace("dirichlet: [right]", "dirichlet: {right: [null, 0.0]}"))
    run = subprocess.run(
        [sys.executable, "-m", "vemkit.cli", "solve", scene, "-o", tmp_path / "out.nc"], capture_output=True, text=True
    )
    assert run.returncode == 2 and len(run.stderr.splitlines()) == 1, run.stderr
    assert "translation in x" in run.stderr and not (tmp_path / "out.nc").exists()


def test_the_mapping_form_of_a_clamp_is_the_list_form():
    listed = load_scene(PAPER, ["discretization.mesh.n=8"])
    data = listed.data
    data["boundary"]["dirichlet"] = {"right": [0, 0]}
    mapped = scene_from_dict(data)
    a, b = solve_scene(listed)[1], solve_scene(mapped)[1]
    assert np.array_equal(a.u, b.u)


def test_a_foundation_line_gives_the_gap_it_stands_for():
    """A floor 0.002 below the paper's bottom side is the constant gap 0.002 (nu = (0, -1))."""
    gap = load_scene(PAPER, ["discretization.mesh.n=8", "contact.gap=0.002"])
    data = load_scene(PAPER, ["discretization.mesh.n=8"]).data
    del data["contact"]["gap"]
    data["contact"]["foundation"] = {"point": [0.0, -0.002], "normal": [0.0, 2.0]}
    floor = scene_from_dict(data)
    a, b = solve_scene(gap)[1], solve_scene(floor)[1]
    np.testing.assert_allclose(a.u, b.u, rtol=0, atol=1e-12)


def test_a_foundation_along_a_slanted_normal_divides_by_the_cosine():
    from vemkit.contact.boundary import FoundationLine

    line = FoundationLine((0.0, 0.0), (0.0, 1.0))
    tilted = np.array([[np.sin(0.3), -np.cos(0.3)]])
    assert line.along(np.array([[5.0, 0.5]]), tilted)[0] == pytest.approx(0.5 / np.cos(0.3))


@pytest.mark.parametrize(
    "change, named",
    [
        ({"gap": 0.0}, "either gap or foundation"),
        ({"foundation": {"point": [0, 0.5], "normal": [0, 1]}}, "beyond the foundation line"),
        ({"foundation": {"point": [0, 0], "normal": [0, 0]}}, "contact.foundation.normal"),
    ],
)
def test_bad_foundations_are_refused(change, named):
    data = load_scene(PAPER).data
    del data["contact"]["gap"]
    data["contact"].update(change)
    if "gap" in change:
        data["contact"]["foundation"] = {"point": [0, -1], "normal": [0, 1]}
    with pytest.raises(SceneError, match=named):
        scene_from_dict(data)


@pytest.mark.parametrize(
    "boundary, named",
    [
        ({"dirichlet": {"left": [None, None]}}, "prescribes nothing"),
        ({"dirichlet": ["left"], "neumann": {"right": {"traction": [0, 1], "pressure": 1}}}, "exactly one of"),
        ({"dirichlet": ["left"], "neumann": {"right": {}}}, "exactly one of"),
        ({"dirichlet": {"nowhere": [0, 0]}}, "unknown boundary name"),
        ({"dirichlet": {"left": ["sqrt(x-1)", 0]}}, "boundary.dirichlet.left"),
    ],
)
def test_bad_boundary_conditions_are_one_line_errors(boundary, named):
    with pytest.raises(SceneError, match=named) as caught:
        _scene(boundary, domain="unit_square", size=("n", 2))
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize(
    "mesh, named",
    [
        ({"family": "square"}, "exactly one of n, h and cells"),
        ({"family": "square", "n": 4, "h": 0.25}, "exactly one of n, h and cells"),
        ({"n": 4}, "family is missing"),
        ({"file": "m.msh", "family": "square"}, "drop family"),
    ],
)
def test_the_mesh_size_is_exactly_one_of_n_h_cells_or_a_file(mesh, named):
    data = load_scene(PAPER).data
    data["discretization"]["mesh"] = mesh
    with pytest.raises(SceneError, match=named):
        scene_from_dict(data)


def test_h_and_cells_size_the_mesh():
    h = solve_scene(_scene({"dirichlet": ["left"]}, domain="unit_square", family="square", size=("h", 0.125)))[0]
    cells = solve_scene(_scene({"dirichlet": ["left"]}, domain="unit_square", family="square", size=("cells", 64)))[0]
    assert h.mesh.n_cells == cells.mesh.n_cells == 64


def test_gauss_contact_keeps_the_prescribed_displacement_of_a_dropped_end():
    """The corner (0, 0) of a side moved down by d is left out of Gamma_C, but the Gauss rule sees
    its displacement: with u = 0 elsewhere, the penetration falls linearly from d to 0 along the
    first bottom edge, so its free end feels k d |e| / 6 (m = 1)."""
    from vemkit.contact.boundary import contact_boundary
    from vemkit.contact.laws import ContactLaw
    from vemkit.mesh.families import build_mesh
    from vemkit.vem.space import VirtualElementSpace

    d, k = 0.01, 50.0
    mesh = build_mesh("square", 4)
    space = VirtualElementSpace(mesh, 1)
    dofs = space.constrain(*space.dirichlet_components({"left": [0.0, -d]}))
    cb = contact_boundary(space, ["bottom"], dofs, lambda x, y: np.zeros_like(x), "gauss", 3)
    assert not np.any(np.all(cb.coords == 0.0, axis=1))  # the corner is not a contact vertex
    u = np.zeros(dofs.n_free)
    u[dofs.fixed_dofs] = dofs.fixed_values
    force = cb.normal_force(u, ContactLaw(k, 1.0, 0.0, 0.0))
    neighbour = int(np.flatnonzero(np.all(np.isclose(cb.coords, [0.25, 0.0]), axis=1))[0])
    assert force[cb.dofs[neighbour, 1]] == pytest.approx(-k * d * 0.25 / 6, rel=1e-12)
    assert np.count_nonzero(force) == 1


def test_an_override_of_the_mesh_size_replaces_the_scenes_own():
    scene = load_scene(PAPER, ["discretization.mesh.h=0.125"])
    assert "n" not in scene.mesh_options and scene.mesh_options["h"] == 0.125
    scene = scene.with_overrides(["discretization.mesh.cells=100"])
    assert set(scene.mesh_options) & {"n", "h", "cells"} == {"cells"}
    assert scene.with_overrides(["discretization.mesh.file=m.msh"]).mesh_options == {"file": "m.msh"}
