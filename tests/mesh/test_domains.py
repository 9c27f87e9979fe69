"""Domains (docs/reference/files.md): validation of the domain mapping, every family on a body with holes (valid,
sides named, area kept, VEM patch test), mesh size by n, h or cells."""

import re

import numpy as np
import pytest
import shapely

from vemkit.config.domain import UNIT_SQUARE, UNIT_SQUARE_SIDES, CircleHole, domain_from_spec
from vemkit.exceptions import InputError
from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.families import build_mesh
from vemkit.vem.elasticity import lame_parameters
from vemkit.vem.space import VirtualElementSpace

# a bracket: non-convex outer boundary (a re-entrant corner), a circle, a triangle given clockwise
BRACKET = {
    "polygon": [[0, 0], [3, 0], [3, 1], [1.2, 1], [1.2, 2], [0, 2]],
    "sides": ["bottom", "right", "shelf", "step", "top", "left"],
    "holes": [
        {"circle": [0.6, 0.6, 0.25], "side": "bore"},
        {"polygon": [[2.0, 0.3], [2.2, 0.7], [2.5, 0.3]], "sides": ["slot_a", "slot_b", "slot_c"]},
    ],
}
FAMILY_CASES = [
    ("square", {}),
    ("triangle", {"seed": 3}),
    ("voronoi", {"seed": 2}),
    ("hanging", {"levels": 2, "contact_side": "bore"}),
    ("hanging", {"levels": 2, "rule": "random", "seed": 4, "fraction": 0.4}),
]
IDS = [f"{f}-{'-'.join(f'{k}={v}' for k, v in o.items())}" for f, o in FAMILY_CASES]
N = 6


def bracket_segments(h):
    polygonal = domain_from_spec(BRACKET).discretize(h)
    return polygonal, polygonal.points[polygonal.segments]


def chord_size(mesh) -> float:
    """The size of the chords standing for the circle: 1/N, for hanging that of its finest squares."""
    return 1.0 / N / (2 ** mesh.meta["levels"] if mesh.meta["family"] == "hanging" else 1)


@pytest.fixture(scope="module", params=FAMILY_CASES, ids=IDS)
def bracket_mesh(request):
    family, options = request.param
    return build_mesh(family, N, domain=BRACKET, **options)


def test_bracket_meshes_are_valid_and_keep_the_area(bracket_mesh):
    validate_mesh(bracket_mesh)
    polygonal, _ = bracket_segments(chord_size(bracket_mesh))
    assert (bracket_mesh.cell_areas > 0).all()
    assert bracket_mesh.cell_areas.sum() == pytest.approx(polygonal.shape.area, rel=1e-13)
    # the area of the polygonal domain: exact minus the circle's segments (inscribed polygon)
    circle = domain_from_spec(BRACKET).holes[0]
    m = circle.polygon(chord_size(bracket_mesh)).shape[0]
    exact_polygon_area = 0.5 * m * circle.r**2 * np.sin(2 * np.pi / m)
    assert polygonal.shape.area == pytest.approx(3.0 + 1.2 - exact_polygon_area - 0.5 * 0.5 * 0.4, rel=1e-13)


def test_every_boundary_edge_is_named_after_the_side_it_lies_on(bracket_mesh):
    mesh = bracket_mesh
    polygonal, segments = bracket_segments(chord_size(mesh))
    assert set(mesh.boundary) == set(domain_from_spec(BRACKET).side_names)
    parts = np.concatenate(list(mesh.boundary.values()))
    assert sorted(map(tuple, parts)) == sorted(map(tuple, mesh.boundary_edges))  # a partition
    for name, edges in mesh.boundary.items():
        lines = shapely.multilinestrings(segments[polygonal.segment_sides == name])
        ends = shapely.points(mesh.vertices[edges.ravel()])
        assert shapely.distance(lines, ends).max() < 1e-12, name
        # and the named side is covered: the mesh edges add up to the side's length
        length = np.linalg.norm(np.diff(mesh.vertices[edges], axis=1)[:, 0], axis=1).sum()
        assert length == pytest.approx(lines.length, rel=1e-12), name


def test_linear_displacements_are_in_the_kernel_of_interior_rows(bracket_mesh):
    """VEM patch test: K u_I has zero rows at every interior vertex for every linear u."""
    mesh = bracket_mesh
    lam, mu = lame_parameters(1.0, 0.3)
    K = VirtualElementSpace(mesh, 1).stiffness_matrix(lam, mu, "dofi-2mu")
    interior = np.setdiff1d(np.arange(mesh.n_vertices), mesh.boundary_edges.ravel())
    assert interior.size > 10
    rows = np.stack([2 * interior, 2 * interior + 1], axis=1).ravel()
    for G, b in [(np.array([[0.3, -1.2], [0.7, 0.25]]), np.array([0.4, -0.9])), (np.eye(2), np.zeros(2))]:
        u = (mesh.vertices @ G.T + b).ravel()
        residual = (K @ u)[rows]
        assert np.abs(residual).max() <= 1e-10 * abs(K).max() * np.abs(u).max()


def test_meshing_is_deterministic_and_records_the_domain():
    a = build_mesh("voronoi", 5, domain=BRACKET, seed=1)
    b = build_mesh("voronoi", 5, domain=BRACKET, seed=1)
    assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.cell_vertices, b.cell_vertices)
    assert a.meta["domain"] == domain_from_spec(BRACKET).to_spec()
    assert domain_from_spec(a.meta["domain"]) == domain_from_spec(BRACKET)


def test_cut_cells_have_no_sliver():
    """Merging rule: no cell below half its square; measured worst ratio to the largest neighbour."""
    for n in (5, 7.3, 12):
        mesh = build_mesh("square", n, domain=BRACKET)
        validate_mesh(mesh)
        area = mesh.cell_areas
        assert area.min() >= 0.5 / n**2 * (1 - 1e-12)
        pairs = mesh.edge_cells[mesh.edge_cells[:, 1] >= 0]
        largest = np.zeros(mesh.n_cells)
        np.maximum.at(largest, pairs[:, 0], area[pairs[:, 1]])
        np.maximum.at(largest, pairs[:, 1], area[pairs[:, 0]])
        assert (area / largest).min() > 0.2


def test_a_circle_becomes_a_polygon_on_the_circle():
    circle = CircleHole(1.0, 2.0, 0.5, "bore")
    for h, m in [(1.0, 8), (0.1, 32), (0.01, 315)]:
        p = circle.polygon(h)
        assert p.shape == (m, 2)
        np.testing.assert_allclose(np.hypot(p[:, 0] - 1.0, p[:, 1] - 2.0), 0.5, rtol=1e-15)
        assert shapely.LinearRing(p).is_ccw


@pytest.mark.parametrize("family", ["square", "triangle", "voronoi", "hanging"])
def test_mesh_size_by_n_h_or_cells(family):
    area = domain_from_spec(BRACKET).exact_area
    per_square = 2 if family == "triangle" else 1
    by_cells = build_mesh(family, cells=400, domain=BRACKET)
    by_h = build_mesh(family, h=0.1, domain=BRACKET)
    by_n = build_mesh(family, 10, domain=BRACKET)
    assert np.array_equal(by_h.vertices, by_n.vertices)
    if family != "hanging":  # hanging refines on top of the squares
        assert abs(by_cells.n_cells - 400) <= 0.15 * 400
        assert abs(by_n.n_cells - per_square * 100 * area) <= 0.15 * per_square * 100 * area
    with pytest.raises(InputError, match="give exactly one of n, h and cells"):
        build_mesh(family, 10, h=0.1, domain=BRACKET)
    with pytest.raises(InputError, match="mesh size h = -1"):
        build_mesh(family, h=-1, domain=BRACKET)


def test_unit_square_spec_is_the_old_mesh():
    for family, options in [("square", {}), ("voronoi", {"seed": 1}), ("triangle", {}), ("hanging", {"levels": 2})]:
        old = build_mesh(family, 8, **options)
        new = build_mesh(family, 8, domain="unit_square", **options)
        same = build_mesh(
            family,
            h=0.125,
            domain={"polygon": [[0, 0], [1, 0], [1, 1], [0, 1]], "sides": ["bottom", "right", "top", "left"]},
            **options,
        )
        for m in (new, same):
            assert np.array_equal(m.vertices, old.vertices) and np.array_equal(m.cell_vertices, old.cell_vertices)
            assert m.meta == old.meta and list(m.boundary) == list(old.boundary)


def test_structured_triangles_stay_on_the_unit_square():
    with pytest.raises(InputError, match="structured is a unit-square family"):
        build_mesh("triangle", 4, domain=BRACKET, kind="structured")


def test_unit_square_sides():
    assert UNIT_SQUARE.sides == ("bottom", "right", "top", "left")
    assert set(UNIT_SQUARE.side_names) == set(UNIT_SQUARE_SIDES)
    assert domain_from_spec("unit_square") is UNIT_SQUARE and domain_from_spec(None) is UNIT_SQUARE


SQUARE = [[0, 0], [2, 0], [2, 2], [0, 2]]
SIDES4 = ["a", "b", "c", "d"]
BAD_DOMAINS = [
    ({"polygon": [[0, 0], [2, 0], [0, 2], [2, 2]], "sides": SIDES4}, "domain.polygon", "crosses itself"),
    ({"polygon": SQUARE[::-1], "sides": SIDES4}, "domain.polygon", "is clockwise; list its corners counter-clockwise"),
    ({"polygon": SQUARE, "sides": ["a", "b", "c"]}, "domain.sides", "has 3 names but the polygon has 4 edges"),
    (
        {"polygon": [[0, 0], [2, 0], [2, 0], [2, 2], [0, 2]], "sides": SIDES4 + ["e"]},
        "domain.polygon",
        "edge 1 from (2, 0) to (2, 0) has zero length",
    ),
    ({"polygon": SQUARE + [[0, 0]], "sides": SIDES4 + ["e"]}, "domain.polygon", "do not repeat the first corner"),
    ({"polygon": SQUARE, "sides": ["a", "b c", "c", "d"]}, "domain.sides", "side name 'b c' is not an identifier"),
    (
        {"polygon": SQUARE, "sides": SIDES4, "holes": [{"circle": [1, 1, 0], "side": "h"}]},
        "domain.holes[0].circle",
        "radius 0 must be a positive",
    ),
    (
        {"polygon": SQUARE, "sides": SIDES4, "holes": [{"circle": [1, 1, -0.5], "side": "h"}]},
        "domain.holes[0].circle",
        "radius -0.5 must be a positive",
    ),
    (
        {"polygon": SQUARE, "sides": SIDES4, "holes": [{"circle": [5, 5, 0.5], "side": "h"}]},
        "domain.holes[0]",
        "lies outside the body",
    ),
    (
        {"polygon": SQUARE, "sides": SIDES4, "holes": [{"polygon": [[3, 3], [4, 3], [4, 4]], "sides": ["h"] * 3}]},
        "domain.holes[0]",
        "lies outside the body",
    ),
    (
        {"polygon": SQUARE, "sides": SIDES4, "holes": [{"circle": [1.8, 1, 0.5], "side": "h"}]},
        "domain.holes[0]",
        "overlaps the outer boundary",
    ),
    (
        {"polygon": SQUARE, "sides": SIDES4, "holes": [{"polygon": [[1, 1], [2.5, 1], [1, 1.5]], "sides": ["h"] * 3}]},
        "domain.holes[0]",
        "overlaps the outer boundary",
    ),
    (
        {
            "polygon": SQUARE,
            "sides": SIDES4,
            "holes": [{"circle": [0.7, 1, 0.3], "side": "h"}, {"circle": [1.2, 1, 0.3], "side": "k"}],
        },
        "domain.holes[1]",
        "overlaps domain.holes[0]",
    ),
    (
        {
            "polygon": SQUARE,
            "sides": SIDES4,
            "holes": [
                {"polygon": [[0.5, 0.5], [1.5, 0.5], [1, 1.5]], "sides": ["h"] * 3},
                {"circle": [1, 0.8, 0.1], "side": "k"},
            ],
        },
        "domain.holes[1]",
        "overlaps domain.holes[0]",
    ),
    (
        {
            "polygon": SQUARE,
            "sides": SIDES4,
            "holes": [{"polygon": [[0.5, 0.5], [1.5, 1.5], [1.5, 0.5], [0.5, 1.5]], "sides": ["h"] * 4}],
        },
        "domain.holes[0].polygon",
        "crosses itself",
    ),
    (
        {"polygon": SQUARE, "sides": SIDES4, "holes": [{"circle": [1, 1, 0.2], "side": "h?"}]},
        "domain.holes[0].side",
        "is not an identifier",
    ),
    (
        {
            "polygon": SQUARE,
            "sides": SIDES4,
            "holes": [{"polygon": [[0.5, 0.5], [1.5, 0.5], [1, 1.5]], "sides": ["h"]}],
        },
        "domain.holes[0].sides",
        "has 1 names but the polygon has 3 edges",
    ),
    ({"polygon": SQUARE}, "domain.sides", "domain.sides is missing"),
    ({"polygon": SQUARE, "sides": SIDES4, "hole": []}, "domain.hole", "unknown key"),
    ("unit_circle", "domain", "the only named domain is unit_square"),
]


@pytest.mark.parametrize("spec, key, message", BAD_DOMAINS, ids=[m for _, _, m in BAD_DOMAINS])
def test_broken_domains_are_refused_with_one_line(spec, key, message):
    with pytest.raises(InputError, match=re.escape(message)) as error:
        domain_from_spec(spec)
    assert error.value.key == key
    assert "\n" not in str(error.value)


def test_holes_may_be_given_either_way_round():
    hole = [[0.5, 0.5], [1.5, 0.5], [1, 1.5]]
    ccw = domain_from_spec({"polygon": SQUARE, "sides": SIDES4, "holes": [{"polygon": hole, "sides": ["p", "q", "r"]}]})
    cw = domain_from_spec(
        {"polygon": SQUARE, "sides": SIDES4, "holes": [{"polygon": hole[::-1], "sides": ["q", "p", "r"]}]}
    )
    assert ccw == cw  # the same edges carry the same names
    mesh = build_mesh("triangle", 8, domain=cw)
    validate_mesh(mesh)
    q = mesh.vertices[mesh.boundary["q"]]  # the edge (1.5, 0.5) -> (1, 1.5): on x + y/2 = 1.75
    np.testing.assert_allclose(q[:, :, 0] + 0.5 * q[:, :, 1], 1.75, atol=1e-12)
