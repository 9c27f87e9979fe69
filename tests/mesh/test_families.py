"""Mesh families: valid, deterministic, the right size, boundary parts on the four sides."""

import numpy as np
import pytest
import shapely

from vemkit.config.domain import UNIT_SQUARE_SIDES
from vemkit.mesh.checks import validate_mesh
from vemkit.mesh.families import FAMILIES, build_mesh
from vemkit.mesh.families.hanging import hanging
from vemkit.mesh.families.triangle import delaunay_triangle
from vemkit.mesh.families.voronoi import voronoi

CASES = [
    ("square", 6, {}),
    ("triangle", 6, {"kind": "structured"}),
    ("triangle", 6, {}),
    ("triangle", 9, {"seed": 5, "min_angle": 30.0}),
    ("voronoi", 6, {}),
    ("voronoi", 10, {"seed": 7, "lloyd_iterations": 0}),
    ("voronoi", 8, {"seed": 2, "anisotropy": 3.0}),
    ("hanging", 4, {"levels": 3}),
    ("hanging", 4, {"levels": 2, "contact_side": "left"}),
    ("hanging", 6, {"levels": 3, "rule": "random", "seed": 1, "fraction": 0.4}),
]
IDS = [f"{f}-{n}-{'-'.join(f'{k}={v}' for k, v in o.items())}" for f, n, o in CASES]
SIDE = {"left": (0, 0.0), "right": (0, 1.0), "bottom": (1, 0.0), "top": (1, 1.0)}


def same_mesh(a, b):
    return (
        np.array_equal(a.vertices, b.vertices)
        and np.array_equal(a.cell_offsets, b.cell_offsets)
        and np.array_equal(a.cell_vertices, b.cell_vertices)
        and a.meta == b.meta
        and all(np.array_equal(a.boundary[k], b.boundary[k]) for k in a.boundary)
    )


@pytest.mark.parametrize("family, n, options", CASES, ids=IDS)
def test_valid_unit_square_meshes(family, n, options):
    mesh = build_mesh(family, n, **dict(options))
    validate_mesh(mesh)
    assert mesh.cell_areas.sum() == pytest.approx(1.0, abs=1e-13)
    assert (mesh.cell_areas > 0).all()
    assert mesh.meta["family"] == family and mesh.meta["n"] == n
    # the four named sides partition the boundary, each covering its whole side
    assert set(mesh.boundary) == set(UNIT_SQUARE_SIDES)
    parts = np.concatenate([mesh.boundary[s] for s in UNIT_SQUARE_SIDES])
    assert sorted(map(tuple, parts)) == sorted(map(tuple, mesh.boundary_edges))
    for side, (axis, value) in SIDE.items():
        ends = mesh.vertices[mesh.boundary[side]]
        assert (ends[:, :, axis] == value).all()
        assert np.abs(ends[:, 1, 1 - axis] - ends[:, 0, 1 - axis]).sum() == pytest.approx(1.0, abs=1e-13)


@pytest.mark.parametrize("family, n, options", CASES, ids=IDS)
def test_deterministic(family, n, options):
    assert same_mesh(build_mesh(family, n, **dict(options)), build_mesh(family, n, **dict(options)))


@pytest.mark.parametrize("family", ["triangle", "voronoi"])
def test_seed_changes_the_mesh(family):
    assert not same_mesh(build_mesh(family, 8, seed=0), build_mesh(family, 8, seed=1))
    assert build_mesh(family, 8, seed=1).meta["seed"] == 1


def test_hanging_random_seed_changes_the_mesh():
    assert not same_mesh(hanging(6, 2, rule="random", seed=0), hanging(6, 2, rule="random", seed=1))


@pytest.mark.parametrize("n, seed", [(4, 0), (10, 1), (22.6, 0), (22.6, 3), (32, 2)])
def test_delaunay_count_and_quality(n, seed):
    mesh = delaunay_triangle(n, seed=seed)
    target = round(2 * n * n)
    assert abs(mesh.n_cells - target) <= 0.1 * target
    assert mesh.meta["kind"] == "delaunay" and mesh.meta["options"].startswith("pq28")
    p = mesh.vertices[mesh.cell_vertices.reshape(-1, 3)]
    angles = []
    for k in range(3):
        u, w = p[:, (k + 1) % 3] - p[:, k], p[:, (k + 2) % 3] - p[:, k]
        angles.append(np.arccos((u * w).sum(1) / np.linalg.norm(u, axis=1) / np.linalg.norm(w, axis=1)))
    assert np.degrees(np.min(angles)) >= 28.0 - 1e-9


def test_paper_figure_4_size():
    assert abs(delaunay_triangle(22.6).n_cells - 1022) <= 30


@pytest.mark.parametrize("n", [1, 3, 16])
def test_voronoi_cell_count(n):
    mesh = voronoi(n, seed=n)
    assert mesh.n_cells == n * n
    assert mesh.meta["lloyd_iterations"] == 30 and mesh.meta["seed"] == n


def test_lloyd_relaxation_evens_out_cells():
    raw, relaxed = voronoi(16, seed=3, lloyd_iterations=0), voronoi(16, seed=3)
    assert np.std(relaxed.cell_areas) < 0.3 * np.std(raw.cell_areas)

    def shortest_edge(mesh):
        return np.linalg.norm(np.diff(mesh.vertices[mesh.edges], axis=1)[:, 0], axis=1).min()

    assert shortest_edge(raw) < shortest_edge(relaxed)


def test_voronoi_anisotropy_stretches_cells():
    mesh = voronoi(10, seed=1, anisotropy=3.0)
    interior = np.setdiff1d(np.arange(mesh.n_cells), mesh.edge_cells[mesh.edge_cells[:, 1] < 0, 0])
    spans = np.array([np.ptp(mesh.vertices[mesh.cell(k)], axis=0) for k in interior])
    assert np.median(spans[:, 1] / spans[:, 0]) > 2.0


def test_voronoi_on_l_shaped_domain():
    domain = shapely.Polygon([(0, 0), (1, 0), (1, 0.5), (0.5, 0.5), (0.5, 1), (0, 1)])
    for seed in range(3):
        mesh = voronoi(12, seed=seed, domain=domain)
        validate_mesh(mesh)
        assert mesh.cell_areas.sum() == pytest.approx(0.75, abs=1e-13)
        assert abs(mesh.n_cells - 108) <= 3
        assert sorted(map(tuple, mesh.boundary["boundary"])) == sorted(map(tuple, mesh.boundary_edges))
        # the re-entrant corner is a vertex, and the cell holding it is non-convex there
        corner = np.flatnonzero((mesh.vertices == [0.5, 0.5]).all(axis=1))
        assert corner.size == 1
        owners = np.unique(mesh.half_edge_cells[mesh.cell_vertices == corner[0]])
        assert owners.size == 1
        cell = mesh.cell(owners[0])
        i = int(np.flatnonzero(cell == corner[0])[0])
        a, b, c = mesh.vertices[cell[i - 1]], mesh.vertices[cell[i]], mesh.vertices[cell[(i + 1) % cell.size]]
        assert (b - a)[0] * (c - b)[1] - (b - a)[1] * (c - b)[0] < 0  # a reflex corner


def test_hanging_contact_layer():
    n, levels = 4, 3
    mesh = hanging(n, levels)
    assert mesh.n_cells == n * n + 3 * n * (2**levels - 1)
    assert mesh.meta == {
        "family": "hanging",
        "n": n,
        "levels": levels,
        "rule": "contact",
        "seed": 0,
        "contact_side": "bottom",
    }
    bottom = mesh.vertices[mesh.boundary["bottom"]]
    np.testing.assert_allclose(np.abs(bottom[:, 1, 0] - bottom[:, 0, 0]), 1 / (n * 2**levels))
    top = mesh.vertices[mesh.boundary["top"]]
    np.testing.assert_allclose(np.abs(top[:, 1, 0] - top[:, 0, 0]), 1 / n)


@pytest.mark.parametrize("options", [{"levels": 1}, {"levels": 3, "rule": "random", "seed": 4}])
def test_hanging_nodes_are_vertices_of_both_cells(options):
    mesh = hanging(4, **options)
    assert (mesh.cell_sizes > 4).any()
    validate_mesh(mesh)  # includes the T-junction check
    for k in np.flatnonzero(mesh.cell_sizes > 4):
        cell = mesh.cell(k)
        p = mesh.vertices[cell]
        u, w = np.roll(p, -1, axis=0) - p, p - np.roll(p, 1, axis=0)
        turn = u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]
        hanging_nodes = cell[turn == 0]
        assert hanging_nodes.size == cell.size - 4
        for v in hanging_nodes:  # every hanging node belongs to the smaller neighbours too
            owners = np.unique(mesh.half_edge_cells[mesh.cell_vertices == v])
            assert owners.size >= 3 or np.isin(v, mesh.boundary_edges)
            assert k in owners


def test_hanging_random_allows_more_than_two_to_one():
    mesh = hanging(4, levels=4, rule="random", fraction=0.5, seed=3)
    assert mesh.cell_sizes.max() > 8  # some side carries more than one hanging node
    validate_mesh(mesh)


def test_build_mesh_dispatch_and_errors():
    assert FAMILIES == ("square", "triangle", "voronoi", "hanging")
    assert build_mesh("triangle", 4).meta["kind"] == "delaunay"
    assert build_mesh("triangle", 4, kind="structured").n_cells == 32
    with pytest.raises(ValueError, match="mesh family 'hexagon' is unknown; valid families: square, triangle"):
        build_mesh("hexagon", 4)
    with pytest.raises(ValueError, match="mesh option 'seed' is not valid for family square; valid options: none"):
        build_mesh("square", 4, seed=1)
    with pytest.raises(ValueError, match="'levls' is not valid for family hanging; valid options: levels, rule"):
        build_mesh("hanging", 4, levls=2)
    with pytest.raises(ValueError, match="triangle mesh kind 'quad' is unknown; valid kinds: delaunay, structured"):
        build_mesh("triangle", 4, kind="quad")
    with pytest.raises(ValueError, match="rule = 'everywhere'"):
        build_mesh("hanging", 4, rule="everywhere")
