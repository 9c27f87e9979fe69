"""The plane cut a 3D mesh figure draws (``vemkit.report.mesh_cuts``): the sections of convex cells
tile the body's cross-section exactly, each section lies in its own cell, and a plane through a layer
of vertices still draws the cells just above it."""

import numpy as np
import pytest

from vemkit.mesh.families3d.build import build_mesh3d
from vemkit.report.mesh_cuts import drawn_cells, section_polygons

BOX = {"box": [[0, 0, 0], [1, 2, 0.5]]}


def _area(polygon) -> float:
    x, y = polygon.T
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _inside(mesh, cell, point) -> bool:
    """``point`` on the inner side of every face of the convex ``cell``."""
    offsets, facets = mesh.cell_facet_lists
    signed = facets[offsets[cell] : offsets[cell + 1]]
    faces = np.where(signed >= 0, signed, -signed - 1)
    outward = np.where(mesh.facet_cells[faces, 0] == cell, 1.0, -1.0)[:, None] * mesh.facet_normals[faces]
    return bool(np.all(np.einsum("fi,fi->f", point - mesh.facet_centroids[faces], outward) < 1e-12))


@pytest.mark.parametrize("family", ["hex", "tet", "voronoi", "octree"])
@pytest.mark.parametrize("axis, at, area", [("z", 0.2, 2.0), ("x", 0.37, 1.0), ("y", 1.5, 0.5)])
def test_the_sections_tile_the_cross_section(family, axis, at, area):
    mesh = build_mesh3d(family, BOX, n=3)
    polygons, cells = section_polygons(mesh, {"axis": axis, "at": at})
    assert len(polygons) == cells.size and np.unique(cells).size == cells.size
    assert sum(_area(p) for p in polygons) == pytest.approx(area, rel=1e-12)
    # the mean of each section lies in its cell (the convex cells of these families)
    k = "xyz".index(axis)
    means = np.array([p.mean(axis=0) for p in polygons])
    points = np.insert(means, k, at, axis=1)
    assert all(_inside(mesh, c, p) for c, p in zip(cells, points, strict=True))


def test_a_plane_through_vertices_draws_the_cells_just_above_it():
    mesh = build_mesh3d("hex", BOX, n=4)  # vertices at z = 0.25
    polygons, cells = drawn_cells(mesh, {"axis": "z", "at": 0.25})
    assert sum(_area(p) for p in polygons) == pytest.approx(2.0, rel=1e-9)
    assert np.all(mesh.cell_centroids[cells, 2] > 0.25)
