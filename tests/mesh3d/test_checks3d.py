"""validate_mesh3d: valid meshes pass, and every kind of broken mesh is refused with one line naming it."""

import numpy as np
import pytest

from vemkit.exceptions import MeshError
from vemkit.mesh.checks3d import unnamed_boundary_faces, validate_mesh3d
from vemkit.mesh.families3d.grid import hex
from vemkit.mesh.polyhedral import PolyhedralMesh, from_polyhedra

CUBE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
CUBE_FACES = [[0, 4, 7, 3], [1, 2, 6, 5], [0, 1, 5, 4], [3, 7, 6, 2], [0, 3, 2, 1], [4, 5, 6, 7]]


def cube(vertices=CUBE, faces=CUBE_FACES, name=True):
    return from_polyhedra(vertices, [faces], {"all": faces} if name else None)


def rebuilt(mesh, **changes):
    fields = dict(
        vertices=mesh.vertices,
        face_offsets=mesh.face_offsets,
        face_vertices=mesh.face_vertices,
        cell_offsets=mesh.cell_offsets,
        cell_faces=mesh.cell_faces,
        boundary=mesh.boundary,
        meta=mesh.meta,
    )
    fields.update(changes)
    return PolyhedralMesh(**fields)


def refused(mesh, *words, **kwargs):
    with pytest.raises(MeshError) as info:
        validate_mesh3d(mesh, **kwargs)
    message = str(info.value)
    assert "\n" not in message
    for word in words:
        assert word in message, message
    return message


def test_valid_meshes_pass():
    validate_mesh3d(cube())
    validate_mesh3d(hex(shape=(3, 2, 2)))


def test_a_face_used_the_same_way_by_both_cells():
    mesh = hex(shape=(2, 1, 1))
    shared = int(np.flatnonzero((mesh.face_cells >= 0).all(axis=1))[0])
    faces = mesh.cell_faces.copy()
    faces[faces == -(shared + 1)] = shared
    refused(rebuilt(mesh, cell_faces=faces), f"face {shared}", "both its cells", "inside out")


def test_a_missing_face_leaves_the_cell_open():
    mesh = hex(shape=(2, 1, 1))
    keep = np.ones(mesh.cell_faces.size, bool)
    keep[0] = False  # cell 0 loses its first (boundary) face: the face is unused
    offsets = mesh.cell_offsets - np.r_[0, np.ones(mesh.n_cells, int)]
    refused(rebuilt(mesh, cell_faces=mesh.cell_faces[keep], cell_offsets=offsets), "belongs to no cell")
    # the same cell with a face listed twice instead
    faces = mesh.cell_faces.copy()
    faces[0] = faces[1]
    refused(rebuilt(mesh, cell_faces=faces), "cell 0 lists face", "more than once")


def test_an_open_cell():
    faces = CUBE_FACES[:5] + [[4, 5, 6]]  # the top has lost its triangle (4, 6, 7)
    refused(from_polyhedra(CUBE, [faces], {"a": faces}), "cell 0 is not closed", "belongs to 1 of its faces")


def test_a_face_listed_the_wrong_way_round():
    mesh = cube()
    fv = mesh.face_vertices.copy()
    fv[0:4] = fv[0:4][::-1]
    refused(rebuilt(mesh, face_vertices=fv), "cell 0 is not consistently oriented", "reverse one")


def test_an_inside_out_cell():
    mesh = cube()
    refused(rebuilt(mesh, cell_faces=-mesh.cell_faces - 1), "cell 0 is inside out", "outward")


def test_a_bent_face():
    v = CUBE.copy()
    v[6, 2] = 1.001
    refused(cube(v), "not planar", "tolerance 1e-08")
    v[6, 2] = 1.0 + 1e-12  # within the stated tolerance
    validate_mesh3d(cube(v))


def test_degenerate_faces_and_cells():
    flat = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], float)  # a "tetrahedron" of coplanar points
    faces = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]]
    refused(from_polyhedra(flat, [faces], {"s": faces}), "zero volume")
    line = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 0, 1]], float)
    refused(from_polyhedra(line, [faces], {"s": faces}), "zero area")


def test_array_defects():
    mesh = cube()
    refused(rebuilt(mesh, vertices=mesh.vertices[:, :2]), "(N, 3)")
    v = mesh.vertices.copy()
    v[3, 1] = np.nan
    refused(rebuilt(mesh, vertices=v), "vertex 3", "non-finite")
    fv = mesh.face_vertices.copy()
    fv[5] = 99
    refused(rebuilt(mesh, face_vertices=fv), "face 1 refers to vertex 99")
    fv = mesh.face_vertices.copy()
    fv[1] = fv[0]
    refused(rebuilt(mesh, face_vertices=fv), "face 0 lists vertex", "more than once")
    refused(rebuilt(mesh, cell_offsets=np.array([0, 3, 6]), cell_faces=mesh.cell_faces), "cell 0 has 3 faces")
    refused(rebuilt(mesh, cell_faces=np.array([0, 1, 2, 3, 4, -9])), "cell 0 refers to face -9")


def test_a_face_of_three_cells():
    mesh = hex(shape=(2, 1, 1))
    shared = int(np.flatnonzero((mesh.face_cells >= 0).all(axis=1))[0])
    third = from_polyhedra(CUBE + 5, [CUBE_FACES])
    v = np.concatenate([mesh.vertices, third.vertices])
    fo = np.concatenate([mesh.face_offsets, mesh.face_offsets[-1] + third.face_offsets[1:]])
    fv = np.concatenate([mesh.face_vertices, third.face_vertices + mesh.n_vertices])
    cf = np.concatenate([mesh.cell_faces, third.cell_faces[:-1] + mesh.n_faces, [shared]])
    co = np.concatenate([mesh.cell_offsets, mesh.cell_offsets[-1] + third.cell_offsets[1:]])
    refused(
        rebuilt(mesh, vertices=v, face_offsets=fo, face_vertices=fv, cell_faces=cf, cell_offsets=co),
        f"face {shared} belongs to 3 cells",
    )


def test_vertex_defects():
    v = np.concatenate([CUBE, [[5.0, 5.0, 5.0]]])
    refused(cube(v), "vertex 8 belongs to no face")
    v = CUBE.copy()
    v = np.concatenate([v, v[[6]]])
    faces = [f[:] for f in CUBE_FACES]
    faces[5] = [4, 5, 8, 7]
    refused(from_polyhedra(v, [faces], {"a": faces}), "not closed")


def test_boundary_names():
    mesh = hex(shape=(2, 2, 2))
    parts = dict(mesh.boundary)
    del parts["top"]
    message = refused(rebuilt(mesh, boundary=parts), "4 boundary faces carry no side name")
    assert "centroid" in message
    assert unnamed_boundary_faces(rebuilt(mesh, boundary=parts)).tolist() == sorted(mesh.boundary["top"].tolist())
    validate_mesh3d(rebuilt(mesh, boundary=parts), require_named=False)
    parts = dict(mesh.boundary, extra=mesh.boundary["top"][:1])
    refused(rebuilt(mesh, boundary=parts), "in both parts 'top' and 'extra'")
    inner = int(np.flatnonzero((mesh.face_cells >= 0).all(axis=1))[0])
    refused(
        rebuilt(mesh, boundary=dict(mesh.boundary, top=np.r_[mesh.boundary["top"], inner])),
        f"face {inner} is not a boundary face",
    )
    refused(rebuilt(mesh, boundary=dict(mesh.boundary, top=[10**6])), "refers to face 1000000")
    refused(rebuilt(mesh, boundary={"top side": mesh.boundary_faces}), "not an identifier")
