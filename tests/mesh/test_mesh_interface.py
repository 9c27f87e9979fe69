"""One mesh interface for d = 2, 3 (issue 34 item 1): the polygonal and the polyhedral mesh offer
the members of vemkit.mesh.interface.MeshInterface under the same names, with the same meaning.

Every body here is the unit square or a box (or a prism over the unit square), so that the outward
normal, the volume and the centroid of the body are known."""

import numpy as np
import pytest
from test_domains import BRACKET  # a re-entrant corner, a circular hole and a triangular one

from vemkit.exceptions import MeshError
from vemkit.mesh.families import build_mesh
from vemkit.mesh.families3d import extrude, hex, octree, tet, voronoi
from vemkit.mesh.files import read_mesh
from vemkit.mesh.files3d import read_mesh3d
from vemkit.mesh.interface import INTERFACE_MEMBERS, MeshInterface
from vemkit.mesh.locate import locate_points
from vemkit.mesh.refine import refine_cells
from vemkit.mesh.ugrid import write_ugrid

MESHES = {
    "square": lambda: build_mesh("square", 3),
    "triangle": lambda: build_mesh("triangle", 4, seed=1),
    "voronoi": lambda: build_mesh("voronoi", 5, seed=2),
    "hanging": lambda: build_mesh("hanging", 2, levels=2),
    "refined": lambda: refine_cells(build_mesh("square", 3), [0, 4]).mesh,
    "hex": lambda: hex(2),
    "tet": lambda: tet(2),
    "octree": lambda: octree(2),
    "voronoi3d": lambda: voronoi(2, seed=1),
    "prisms": lambda: extrude(build_mesh("voronoi", 3, seed=1), 2, 1.0),
}


@pytest.fixture(scope="module", params=sorted(MESHES))
def mesh(request):
    return MESHES[request.param]()


def _signed_facets(mesh):
    """(cell of every entry, facet, +1 / -1) of ``cell_facet_lists``."""
    offsets, signed = mesh.cell_facet_lists
    cells = np.repeat(np.arange(mesh.n_cells), np.diff(offsets))
    return cells, np.where(signed >= 0, signed, -signed - 1), np.where(signed >= 0, 1.0, -1.0)


def test_every_member_is_there_with_its_shape(mesh):
    d, n, m, f = mesh.dimension, mesh.n_vertices, mesh.n_cells, mesh.n_facets
    assert isinstance(mesh, MeshInterface)
    assert all(hasattr(mesh, name) for name in INTERFACE_MEMBERS)
    assert d in (2, 3) and mesh.vertices.shape == (n, d)
    for offsets, ids, count in (mesh.cell_vertex_lists + (m,), mesh.cell_facet_lists + (m,), mesh.facets + (f,)):
        assert offsets.shape == (count + 1,) and offsets[0] == 0 and offsets[-1] == ids.size
        assert (np.diff(offsets) > 0).all() and ids.dtype == np.int64
    assert mesh.facet_cells.shape == (f, 2)
    for name in ("facet_vector_areas", "facet_normals", "facet_centroids"):
        assert getattr(mesh, name).shape == (f, d), name
    assert mesh.facet_areas.shape == (f,) and (mesh.facet_areas > 0).all()
    assert np.allclose(np.linalg.norm(mesh.facet_normals, axis=1), 1.0)
    assert mesh.cell_volumes.shape == (m,) and (mesh.cell_volumes > 0).all()
    assert mesh.cell_centroids.shape == (m, d) and mesh.cell_diameters.shape == (m,)
    assert mesh.edges.shape[1] == 2 and mesh.h == mesh.cell_diameters.max()
    assert isinstance(mesh.meta, dict)


def test_the_facets_of_every_cell_close_it(mesh):
    """Σ over a cell's facets, with their signs, of |F| n_F = 0; and each facet lies in the cells
    ``facet_cells`` names, pointing out of column 0 and into column 1."""
    cells, facets, sign = _signed_facets(mesh)
    closure = np.zeros((mesh.n_cells, mesh.dimension))
    np.add.at(closure, cells, sign[:, None] * mesh.facet_vector_areas[facets])
    assert np.abs(closure).max() <= 1e-12 * mesh.facet_areas.max()
    column = np.where(sign > 0, 0, 1)
    assert (mesh.facet_cells[facets, column] == cells).all()


def test_the_volumes_and_centroids_add_up_to_the_body(mesh):
    lower, upper = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    volume = float(np.prod(upper - lower))
    assert mesh.cell_volumes.sum() == pytest.approx(volume, rel=1e-12)
    moment = (mesh.cell_volumes[:, None] * mesh.cell_centroids).sum(axis=0)
    assert moment / volume == pytest.approx(0.5 * (lower + upper), rel=1e-12)
    offsets, ids = mesh.cell_vertex_lists
    for c in range(mesh.n_cells):  # a centroid lies in the box around its cell's vertices
        corners = mesh.vertices[ids[offsets[c] : offsets[c + 1]]]
        assert (corners.min(axis=0) - 1e-12 <= mesh.cell_centroids[c]).all()
        assert (mesh.cell_centroids[c] <= corners.max(axis=0) + 1e-12).all()


def test_the_boundary_facets_point_out_of_the_body(mesh):
    exterior = mesh.exterior_facets
    assert (mesh.facet_cells[exterior, 0] >= 0).all() and (mesh.facet_cells[exterior, 1] == -1).all()
    lower, upper = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    normal, centroid = mesh.facet_normals[exterior], mesh.facet_centroids[exterior]
    assert np.allclose(np.abs(normal).max(axis=1), 1.0)  # a box: every boundary normal is an axis
    assert ((centroid - 0.5 * (lower + upper)) * normal).sum(axis=1).min() > 0
    total = (mesh.facet_vector_areas[exterior]).sum(axis=0)
    assert np.abs(total).max() <= 1e-12 * mesh.facet_areas.sum()


def test_the_named_sides_cover_the_boundary_exactly_once(mesh):
    named = np.concatenate([mesh.boundary_facets(side) for side in mesh.boundaries])
    assert np.array_equal(np.sort(named), mesh.exterior_facets)
    assert np.array_equal(mesh.boundary_facets(), mesh.exterior_facets)
    lower, upper = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    for side, facets in mesh.boundaries.items():  # each side is one plane of the box
        offsets, ids = mesh.facets
        points = mesh.vertices[np.concatenate([ids[offsets[f] : offsets[f + 1]] for f in facets])]
        on_plane = [np.ptp(points[:, a]) == 0 and points[0, a] in (lower[a], upper[a]) for a in range(mesh.dimension)]
        assert sum(on_plane) == 1, side


def test_a_sides_vertices_and_edges_are_those_of_its_facets(mesh):
    offsets, ids = mesh.facets
    known = {tuple(pair) for pair in np.sort(mesh.edges, axis=1).tolist()}
    for side, facets in mesh.boundaries.items():
        vertices = np.concatenate([ids[offsets[f] : offsets[f + 1]] for f in facets])
        assert np.array_equal(mesh.boundary_vertices(side), np.unique(vertices)), side
        pairs = mesh.side_edges(side)
        assert pairs.shape[1] == 2 and {tuple(pair) for pair in np.sort(pairs, axis=1).tolist()} <= known, side
        assert np.array_equal(np.unique(pairs), np.unique(vertices)), side


def test_the_cells_facets_and_edges_make_a_ball():
    """V - E + F - C = 1 (3D) and V - E + C = 1 (2D): the Euler characteristic of a ball, a check
    that ``edges`` lists every side of every face once."""
    for name, make in MESHES.items():
        mesh = make()
        euler = mesh.n_vertices - mesh.edges.shape[0] + mesh.n_cells * (-1) ** mesh.dimension
        assert euler + (mesh.n_facets if mesh.dimension == 3 else 0) == 1, name


def test_the_2d_sides_as_edge_ids_are_the_vertex_pairs():
    mesh = build_mesh("hanging", 2, levels=2)
    for side, pairs in mesh.boundary.items():
        edges = mesh.edges[mesh.boundary_facets(side)]
        assert np.array_equal(np.sort(edges, axis=1), np.sort(pairs, axis=1)), side
    assert mesh.facets[1].reshape(-1, 2).tolist() == mesh.edges.tolist()


def test_meshes_read_from_files_have_the_interface(tmp_path):
    for mesh, reader in ((build_mesh("voronoi", 4, seed=3), read_mesh), (octree(2), read_mesh3d)):
        write_ugrid(mesh, tmp_path / f"mesh{mesh.dimension}.nc")
        read = reader(tmp_path / f"mesh{mesh.dimension}.nc")
        assert isinstance(read, MeshInterface) and read.dimension == mesh.dimension
        assert read.cell_volumes.sum() == pytest.approx(mesh.cell_volumes.sum(), rel=1e-12)
        assert {k: v.size for k, v in read.boundaries.items()} == {k: v.size for k, v in mesh.boundaries.items()}


def _boundary_volume(mesh) -> float:
    """The body's volume from its boundary alone: (1/d) Σ over the exterior facets of x_F . |F| n_F."""
    exterior = mesh.exterior_facets
    return float((mesh.facet_centroids[exterior] * mesh.facet_vector_areas[exterior]).sum()) / mesh.dimension


@pytest.mark.parametrize("family, options", [("triangle", {"seed": 3}), ("voronoi", {"seed": 2}), ("square", {})])
def test_on_a_body_with_holes_the_boundary_normals_point_out_of_it(family, options):
    plane = build_mesh(family, 6, domain=BRACKET, **options)
    exterior = plane.exterior_facets
    step = 1e-6 * plane.facet_areas[exterior, None] * plane.facet_normals[exterior]
    outside = locate_points(plane, plane.facet_centroids[exterior] + step)
    inside = locate_points(plane, plane.facet_centroids[exterior] - step)
    assert (outside == -1).all() and (inside == plane.facet_cells[exterior, 0]).all()
    assert _boundary_volume(plane) == pytest.approx(plane.cell_volumes.sum(), rel=1e-12)
    named = np.concatenate(list(plane.boundaries.values()))
    assert np.array_equal(np.sort(named), exterior)
    assert set(plane.boundaries) == {
        "bottom",
        "right",
        "shelf",
        "step",
        "top",
        "left",
        "bore",
        "slot_a",
        "slot_b",
        "slot_c",
    }


def test_on_prisms_over_a_body_with_holes_the_boundary_normals_point_out_of_it():
    prisms = extrude(build_mesh("triangle", 6, domain=BRACKET, seed=3), 2, 0.5)  # convex cells
    exterior = prisms.exterior_facets
    away = prisms.facet_centroids[exterior] - prisms.cell_centroids[prisms.facet_cells[exterior, 0]]
    assert ((away * prisms.facet_normals[exterior]).sum(axis=1) > 0).all()
    assert _boundary_volume(prisms) == pytest.approx(prisms.cell_volumes.sum(), rel=1e-12)
    assert np.array_equal(np.sort(np.concatenate(list(prisms.boundaries.values()))), exterior)


def test_a_2d_side_that_is_no_edge_is_a_mesh_error_naming_it():
    mesh = build_mesh("square", 2)
    broken = mesh.with_boundary(rim=np.array([[0, 4]]))  # a diagonal of the first square
    with pytest.raises(MeshError, match="boundary part 'rim': \\(0, 4\\) is not an edge"):
        broken.boundaries  # noqa: B018
