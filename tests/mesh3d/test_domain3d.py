"""3D domain specs (docs/reference/files.md): parsed, refused with one-line SceneErrors naming the key, and meshed."""

import numpy as np
import pytest

from vemkit.config.domain3d import Box, Extruded, cells_per_length3d, domain3d_from_spec, is_3d_domain
from vemkit.exceptions import SceneError
from vemkit.mesh.checks3d import validate_mesh3d
from vemkit.mesh.families import build_mesh
from vemkit.mesh.families3d import build_mesh3d

BOX = {"box": [[0, 0, 0], [1, 1, 0.5]]}
EXTRUDE = {
    "extrude": {"depth": 0.25},
    "polygon": [[0, 0], [1, 0], [1, 1], [0, 1]],
    "sides": ["bottom", "right", "top", "left"],
    "holes": [{"circle": [0.5, 0.5, 0.2], "side": "bore"}],
}


def test_box_and_extrude_specs():
    box = domain3d_from_spec(BOX)
    assert box == Box((0.0, 0.0, 0.0), (1.0, 1.0, 0.5)) and box.volume == 0.5
    assert box.sides == ("left", "right", "front", "back", "bottom", "top")
    named = domain3d_from_spec({"box": [[0, 0, 0], [1, 1, 1]], "sides": ["a", "a", "b", "b", "c", "d"]})
    assert named.side_names == ("a", "b", "c", "d")
    ext = domain3d_from_spec(EXTRUDE)
    assert isinstance(ext, Extruded) and ext.ends == ("front", "back") and ext.depth == 0.25
    assert ext.side_names == ("bottom", "right", "top", "left", "bore", "front", "back")
    assert is_3d_domain(BOX) and is_3d_domain(EXTRUDE) and not is_3d_domain({"polygon": []})
    assert not is_3d_domain("unit_square")


@pytest.mark.parametrize(
    "spec, key, words",
    [
        ({"box": [[0, 0], [1, 1]]}, "domain.box", "two corners"),
        ({"box": [[0, 0, 1], [1, 1, 1]]}, "domain.box", "z1 = 1 is not above z0 = 1"),
        ({"box": [[0, 0, 0], [1, 1, "x"]]}, "domain.box", "finite numbers"),
        ({"box": [[0, 0, 0], [1, 1, 1]], "sides": ["a"] * 5}, "domain.sides", "has 5 names; give 6"),
        ({"box": [[0, 0, 0], [1, 1, 1]], "sides": ["a b"] * 6}, "domain.sides", "not an identifier"),
        ({"box": [[0, 0, 0], [1, 1, 1]], "holes": []}, "domain.holes", "unknown key"),
        ({"box": [[0, 0, 0], [1, 1, 1]], "extrude": {"depth": 1}}, "domain", "not both"),
        (dict(EXTRUDE, extrude={"depth": -1}), "domain.extrude.depth", "positive number"),
        (dict(EXTRUDE, extrude={}), "domain.extrude.depth", "missing"),
        (dict(EXTRUDE, extrude={"depth": 1, "layers": 3}), "domain.extrude.layers", "valid keys: depth, ends"),
        (dict(EXTRUDE, extrude={"depth": 1, "ends": ["front"]}), "domain.extrude.ends", "give 2"),
        (dict(EXTRUDE, extrude=3), "domain.extrude", "depth: D"),
        (dict(EXTRUDE, sides=["a", "b"]), "domain.sides", "one name per edge"),
        (dict(EXTRUDE, holes=[{"circle": [5, 5, 0.1], "side": "h"}]), "domain.holes[0]", "outside the body"),
    ],
)
def test_broken_specs_are_refused(spec, key, words):
    with pytest.raises(SceneError) as info:
        domain3d_from_spec(spec)
    assert info.value.key == key and words in str(info.value) and "\n" not in str(info.value)


def test_sizes():
    box = domain3d_from_spec(BOX)
    assert cells_per_length3d(box, n=4) == 4 and cells_per_length3d(box, h=0.25) == 4
    assert cells_per_length3d(box, cells=32) == 4 and cells_per_length3d(box, cells=192, cells_per_cube=6.0) == 4
    with pytest.raises(SceneError, match="exactly one of n, h and cells"):
        cells_per_length3d(box, n=4, h=0.25)
    with pytest.raises(SceneError, match="positive number"):
        cells_per_length3d(box, h=0)


@pytest.mark.parametrize(
    "family, size, cells",
    [
        ("hex", {"n": 4}, 32),
        ("tet", {"h": 0.5, "kind": "structured"}, 24),
        ("octree", {"n": 2}, 4 + 7 * 4),
        ("voronoi", {"cells": 40}, 40),
    ],
)
def test_box_meshes(family, size, cells):
    mesh = build_mesh3d(family, BOX, **size)
    validate_mesh3d(mesh)
    assert mesh.n_cells == cells
    assert abs(mesh.cell_volumes.sum() - 0.5) <= 1e-12
    assert set(mesh.boundary) == {"left", "right", "front", "back", "bottom", "top"}


@pytest.mark.parametrize("family", ["square", "triangle", "voronoi", "hanging"])
def test_extruded_meshes_are_prisms_over_the_2d_mesh(family):
    mesh = build_mesh3d(family, EXTRUDE, n=8)
    base = build_mesh(family, 8, domain={k: v for k, v in EXTRUDE.items() if k != "extrude"})
    validate_mesh3d(mesh)
    assert mesh.meta["layers"] == 2 and mesh.n_cells == 2 * base.n_cells  # layers = round(depth n)
    assert np.array_equal(mesh.vertices[: base.n_vertices, :2], base.vertices)
    assert abs(mesh.cell_volumes.sum() - 0.25 * base.cell_areas.sum()) <= 1e-12
    assert set(mesh.boundary) == {"bottom", "right", "top", "left", "bore", "front", "back"}
    assert build_mesh3d(family, EXTRUDE, n=8, layers=3).n_cells == 3 * base.n_cells


@pytest.mark.parametrize("options", [{}, {"rule": "random", "fraction": 0.5, "seed": 2}, {"contact_side": "left"}])
def test_octree_cells_count_the_refined_mesh(options):
    mesh = build_mesh3d("octree", BOX, cells=3000, **options)
    assert 0.6 * 3000 <= mesh.n_cells <= 1.5 * 3000


def test_family_errors():
    with pytest.raises(SceneError, match="mesh option 'levels2' is not valid for family octree; valid options: rule"):
        build_mesh3d("octree", BOX, n=2, levels2=3)
    with pytest.raises(SceneError, match="does not mesh a box; valid families: hex, tet, octree, voronoi"):
        build_mesh3d("square", BOX, n=2)
    with pytest.raises(SceneError, match="does not mesh an extrude domain"):
        build_mesh3d("hex", EXTRUDE, n=2)
    with pytest.raises(SceneError, match="layers applies to an extrude domain only"):
        build_mesh3d("hex", BOX, n=2, layers=2)
    with pytest.raises(SceneError, match="layers = 0"):
        build_mesh3d("square", EXTRUDE, n=2, layers=0)
