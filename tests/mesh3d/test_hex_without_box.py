"""Fichera's corner (issue 36, item 4): ``hex_without_box`` meshes the cube (-1, 1)^3 without the
octant [0, 1]^3 by boxes; config/scenes/3d/fichera_mesh.nc is that mesh, read back as written, its
cells split into 8 by ``refine_cells``, and config/scenes/3d/fichera.yaml solves on it."""

from pathlib import Path

import numpy as np
import pytest

from vemkit.config.scene import load_scene
from vemkit.mesh.checks3d import validate_mesh3d
from vemkit.mesh.families3d.grid import hex_without_box
from vemkit.mesh.files3d import read_mesh3d
from vemkit.mesh.refine_polyhedra import refine_cells
from vemkit.studies.scene_solve import solve_scene

SCENES = Path(__file__).parents[2] / "config" / "scenes" / "3d"
CUBE = ((-1, -1, -1), (1, 1, 1))
OCTANT = ((0, 0, 0), (1, 1, 1))
#: the area of every side: the faces x = -1, y = -1, z = -1 whole, x = 1, y = 1, z = 1 three quarters,
#: the three faces the octant's removal opens one square each
AREAS = {"left": 4, "right": 3, "front": 4, "back": 3, "bottom": 4, "top": 3, "notch": 3}


def side_areas(mesh):
    return {
        name: float(np.linalg.norm(mesh.face_vector_areas[faces], axis=1).sum())
        for name, faces in mesh.boundary.items()
    }


@pytest.mark.parametrize("cells_per_edge", [2, 4, 6])
def test_the_cube_without_its_octant_has_seven_eighths_of_its_volume_and_named_sides(cells_per_edge):
    mesh = hex_without_box(shape=(cells_per_edge,) * 3, box=CUBE, removed=OCTANT)
    validate_mesh3d(mesh)
    assert mesh.n_cells == 7 * cells_per_edge**3 // 8
    assert mesh.cell_volumes.sum() == pytest.approx(7.0, rel=1e-14)
    assert side_areas(mesh) == pytest.approx(AREAS, rel=1e-14)


def test_the_scene_mesh_file_is_that_mesh_and_its_boxes_split_into_eight():
    mesh = read_mesh3d(SCENES / "fichera_mesh.nc")
    made = hex_without_box(shape=(4, 4, 4), box=CUBE, removed=OCTANT)
    np.testing.assert_array_equal(mesh.vertices, made.vertices)
    np.testing.assert_array_equal(mesh.cell_faces, made.cell_faces)
    np.testing.assert_array_equal(mesh.face_vertices, made.face_vertices)
    finer = refine_cells(mesh, np.arange(mesh.n_cells)).mesh
    validate_mesh3d(finer)
    assert finer.n_cells == 8 * mesh.n_cells
    assert side_areas(finer) == pytest.approx(AREAS, rel=1e-14)
    near_corner = np.flatnonzero(np.linalg.norm(mesh.cell_centroids, axis=1) < 0.5)
    local = refine_cells(mesh, near_corner).mesh
    validate_mesh3d(local)
    assert local.n_cells == mesh.n_cells + 7 * near_corner.size


def test_the_fichera_scene_solves_on_its_mesh_file():
    problem, _, ds = solve_scene(load_scene(SCENES / "fichera.yaml"))
    assert problem.mesh.n_cells == 56 and ds.attrs["model"] == "3d"
    u3 = ds["u3"].values
    assert np.isfinite(u3).all() and u3.min() < 0  # the traction pushes the top down
