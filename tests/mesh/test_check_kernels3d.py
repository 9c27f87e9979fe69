"""The Numba screens of vemkit.mesh.check_kernels3d against the numpy checks of vemkit.mesh.checks3d:
a screen passes only meshes its check passes (then the check is skipped), on valid meshes and on
meshes broken in the ways each check refuses (a vertex off its face's plane, a flattened face, a
reversed or a missing face of a cell, a repeated vertex or face)."""

import numpy as np
import pytest

from vemkit.exceptions import MeshError
from vemkit.mesh import checks3d
from vemkit.mesh.check_kernels3d import cells_closed, faces_flat_and_planar, no_repeats
from vemkit.mesh.families3d.grid import hex
from vemkit.mesh.polyhedral import PolyhedralMesh


def rebuilt(mesh, **changes):
    fields = {k: getattr(mesh, k) for k in ("vertices", "face_offsets", "face_vertices", "cell_offsets", "cell_faces")}
    return PolyhedralMesh(**(fields | changes), boundary=mesh.boundary, meta=mesh.meta)


def passes(check, mesh, *args):
    try:
        check(mesh, *args)
    except MeshError:
        return False
    return True


def faces_screen(mesh, planarity=checks3d.PLANARITY_TOL):
    args = (mesh.vertices, mesh.face_offsets, mesh.face_vertices, mesh.face_vector_areas, mesh.face_centroids)
    return faces_flat_and_planar(*args, checks3d.DEGENERATE_TOL, planarity)


@pytest.mark.parametrize("seed", range(4))
def test_the_face_screen_passes_only_faces_the_check_passes(seed):
    rng = np.random.default_rng(seed)
    mesh = hex(shape=(3, 2, 2))
    outcomes = set()
    for scale in (0.0, 1e-12, 1e-9, 1e-7, 1e-3):
        moved = rebuilt(mesh, vertices=mesh.vertices + scale * rng.normal(size=mesh.vertices.shape))
        screen, check = faces_screen(moved), passes(checks3d._check_faces, moved, checks3d.PLANARITY_TOL)
        assert check or not screen
        assert screen == check or scale in (1e-9, 1e-7)  # near the tolerance the numpy check decides
        outcomes.add(check)
    assert outcomes == {True, False}
    flat = mesh.vertices.copy()
    flat[mesh.face(0)] = flat[mesh.face(0)[0]] + 1e-14 * np.arange(4)[:, None]  # a face of zero area
    assert not faces_screen(rebuilt(mesh, vertices=flat))


def test_the_closed_screen_passes_only_closed_cells():
    mesh = hex(shape=(2, 2, 1))
    assert cells_closed(mesh.cell_offsets, mesh.cell_faces, mesh.face_offsets, mesh.face_vertices)
    assert passes(checks3d._check_closed, mesh)
    flipped = mesh.cell_faces.copy()
    flipped[1] = -flipped[1] - 1  # one face of cell 0 reversed: an edge run twice the same way
    keep = np.ones(mesh.cell_faces.size, bool)
    keep[0] = False  # cell 0 without its first face: open
    for broken in (
        rebuilt(mesh, cell_faces=flipped),
        rebuilt(mesh, cell_faces=mesh.cell_faces[keep], cell_offsets=np.r_[0, mesh.cell_offsets[1:] - 1]),
    ):
        assert not cells_closed(broken.cell_offsets, broken.cell_faces, broken.face_offsets, broken.face_vertices)
        assert not passes(checks3d._check_closed, broken)


def test_the_repeat_screen_is_the_numpy_search():
    rng = np.random.default_rng(7)
    for trial in range(200):
        sizes = rng.integers(1, 8, 20)
        offsets = np.r_[0, np.cumsum(sizes)]
        values = rng.integers(0, 40 if trial % 2 else 400, offsets[-1])
        assert no_repeats(offsets, values) == (checks3d._first_repeat(offsets, values) is None)
