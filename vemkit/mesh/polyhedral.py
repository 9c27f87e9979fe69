"""The polyhedral mesh (docs/reference/files.md): plain arrays, as the polygonal :class:`~vemkit.mesh.mesh.Mesh`.

A 3D mesh is
- ``vertices``: ``(N, 3)`` float64 coordinates;
- ``face_offsets`` ``(F + 1,)`` and ``face_vertices``: the polygonal faces (CSR), each listed once;
  its vertex order gives its normal by the right-hand rule;
- ``cell_offsets`` ``(M + 1,)`` and ``cell_faces``: the faces of every cell (CSR), signed: ``f >= 0``
  is face f as stored, ``-(f + 1)`` face f reversed; taken with their signs the faces of a cell
  point OUT of it (the solution file's ``mesh3d_volume_faces`` convention). A hanging node is a
  vertex of the faces around it; a refined neighbour's face is several faces of the coarse cell;
- ``boundary``: named boundary parts, each a ``(k,)`` int64 array of boundary faces (stored
  outward);
- ``meta``: how the mesh was made.

Derived topology and geometry are computed on demand and cached. The members of
:class:`~vemkit.mesh.interface.MeshInterface` (the facets are the faces) are among them, as in 2D.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numba
import numpy as np

from vemkit.mesh import polyhedral_kernels
from vemkit.mesh.interface import SharedMeshMembers


@dataclass(frozen=True, eq=False)
class PolyhedralMesh(SharedMeshMembers):
    vertices: np.ndarray
    face_offsets: np.ndarray
    face_vertices: np.ndarray
    cell_offsets: np.ndarray
    cell_faces: np.ndarray
    boundary: dict = field(default_factory=dict)
    meta: dict = field(default_factory=dict)

    dimension = 3
    array_fields = (
        ("vertices", np.float64),
        ("face_offsets", np.int64),
        ("face_vertices", np.int64),
        ("cell_offsets", np.int64),
        ("cell_faces", np.int64),
    )
    boundary_part_shape = (-1,)  # face ids

    # -- sizes -----------------------------------------------------------------------------
    n_vertices = property(lambda self: self.vertices.shape[0], doc="number of vertices")
    n_faces = property(lambda self: self.face_offsets.shape[0] - 1, doc="number of faces (each stored once)")
    n_cells = property(lambda self: self.cell_offsets.shape[0] - 1, doc="number of cells")

    def face(self, f: int) -> np.ndarray:
        return self.face_vertices[self.face_offsets[f] : self.face_offsets[f + 1]]

    def face_vertex_ids(self, faces) -> np.ndarray:
        """The vertices of ``faces`` (face numbers), face after face (with repeats)."""
        faces = np.asarray(faces, dtype=np.int64).ravel()
        sizes = self.face_offsets[faces + 1] - self.face_offsets[faces]
        start = np.repeat(self.face_offsets[faces] - np.cumsum(sizes) + sizes, sizes)
        return self.face_vertices[start + np.arange(int(sizes.sum()), dtype=np.int64)]

    def boundary_vertices(self, name: str) -> np.ndarray:
        """Sorted unique vertices of the faces of a named side."""
        return np.unique(self.face_vertex_ids(self.boundary[name]))

    def side_edges(self, name: str) -> np.ndarray:
        """``(k, 2)`` the sides of a named side's faces as vertex pairs, face after face (an edge shared
        by two of its faces appears twice)."""
        faces = self.boundary[name]
        sizes = self.face_offsets[faces + 1] - self.face_offsets[faces]
        ids = self.face_vertex_ids(faces)
        start = np.repeat(np.cumsum(sizes) - sizes, sizes)
        following = np.arange(ids.shape[0]) + 1
        following[np.cumsum(sizes) - 1] = start[np.cumsum(sizes) - 1]  # the last vertex closes the face
        return np.stack([ids, ids[following]], axis=1)

    def cell_face_list(self, c: int) -> np.ndarray:
        """The signed faces of cell c."""
        return self.cell_faces[self.cell_offsets[c] : self.cell_offsets[c + 1]]

    # -- derived topology --------------------------------------------------------------------
    @cached_property
    def face_cells(self) -> np.ndarray:
        """``(F, 2)``: column 0 the cell for which face f as stored points out, column 1 the cell for
        which it points in; ``-1`` where there is none (a boundary face has one of the two)."""
        out = np.full((self.n_faces, 2), -1, dtype=np.int64)
        cells = np.repeat(np.arange(self.n_cells, dtype=np.int64), np.diff(self.cell_offsets))
        forward = self.cell_faces >= 0
        out[self.cell_faces[forward], 0] = cells[forward]
        out[-self.cell_faces[~forward] - 1, 1] = cells[~forward]
        return out

    @cached_property
    def boundary_faces(self) -> np.ndarray:
        """Faces that belong to one cell only."""
        return np.flatnonzero((self.face_cells[:, 0] < 0) | (self.face_cells[:, 1] < 0))

    @cached_property
    def cell_vertex_lists(self) -> tuple[np.ndarray, np.ndarray]:
        """CSR (offsets, vertices): the distinct vertices of every cell, in order of first appearance
        along its faces (a numba kernel; ``polyhedral_reference.cell_vertex_lists_reference`` is its twin)."""
        return polyhedral_kernels.cell_vertex_lists(
            self.cell_offsets, self.cell_faces, self.face_offsets, self.face_vertices, self.n_vertices
        )

    # -- geometry -------------------------------------------------------------------------
    @cached_property
    def _face_geometry(self):
        """(|F| n_F, area centroids) of every face (``polyhedral_kernels.face_geometry``)."""
        return polyhedral_kernels.face_geometry(self.vertices, self.face_offsets, self.face_vertices)

    @cached_property
    def face_vector_areas(self) -> np.ndarray:
        """``(F, 3)``: |F| n_F of every face as stored (half the sum of cross products about its vertex mean)."""
        return self._face_geometry[0]

    @cached_property
    def face_centroids(self) -> np.ndarray:
        """``(F, 3)`` area centroids of the faces (fan triangles from the vertex mean, signed along the
        face normal, so that non-convex planar faces are right too)."""
        return self._face_geometry[1]

    @cached_property
    def cell_volumes(self) -> np.ndarray:
        """Signed volumes by the divergence theorem: sum over the cell's outward faces of x_F . (|F| n_F) / 3
        (x_F relative to the cell's first vertex, so that a cell far from the origin keeps its digits)."""
        sign = np.where(self.cell_faces >= 0, 1.0, -1.0)
        faces = np.where(self.cell_faces >= 0, self.cell_faces, -self.cell_faces - 1)
        cells = np.repeat(np.arange(self.n_cells, dtype=np.int64), np.diff(self.cell_offsets))
        ref = (
            self.vertices[self.face_vertices[self.face_offsets[faces[self.cell_offsets[:-1]]]]]
            if self.n_cells
            else np.zeros((0, 3))
        )
        x = self.face_centroids[faces] - ref[cells]
        flux = sign * np.einsum("ij,ij->i", x, self.face_vector_areas[faces]) / 3.0
        return np.bincount(cells, weights=flux, minlength=self.n_cells)

    @cached_property
    def cell_diameters(self) -> np.ndarray:
        """The largest vertex-to-vertex distance of every cell (a numba kernel; ``diameters_numpy`` is its twin)."""
        offsets, ids = self.cell_vertex_lists
        return _diameters(self.vertices, offsets, ids)

    @property
    def h(self) -> float:
        return float(self.cell_diameters.max()) if self.n_cells else 0.0

    # -- the mesh interface (vemkit.mesh.interface): the facets are the faces -------------------
    facets = property(lambda self: (self.face_offsets, self.face_vertices), doc="CSR (offsets, vertices) of the faces")
    facet_cells = property(lambda self: self.face_cells, doc="``face_cells``")
    cell_facet_lists = property(lambda self: (self.cell_offsets, self.cell_faces), doc="CSR (offsets, signed faces)")
    facet_vector_areas = property(lambda self: self.face_vector_areas, doc="``face_vector_areas``")
    facet_centroids = property(lambda self: self.face_centroids, doc="``face_centroids``")
    boundaries = property(lambda self: self.boundary, doc="``boundary``: {side: face ids}")

    @cached_property
    def cell_centroids(self) -> np.ndarray:
        """``(M, 3)`` volume centroids: the pyramids from the cell's first vertex p over its outward faces,
        of volumes w_F = (x_F - p) . |F| n_F / 3 (as ``cell_volumes``) and centroids p + 3/4 (x_F - p)."""
        sign = np.where(self.cell_faces >= 0, 1.0, -1.0)
        faces = np.where(self.cell_faces >= 0, self.cell_faces, -self.cell_faces - 1)
        cells = np.repeat(np.arange(self.n_cells, dtype=np.int64), np.diff(self.cell_offsets))
        first = self.cell_vertex_lists[1][self.cell_vertex_lists[0][:-1]] if self.n_cells else np.zeros(0, np.int64)
        apex = self.vertices[first]
        x = self.face_centroids[faces] - apex[cells]
        weight = sign * np.einsum("ij,ij->i", x, self.face_vector_areas[faces]) / 3.0
        volume = np.bincount(cells, weights=weight, minlength=self.n_cells)
        moment = np.stack(
            [np.bincount(cells, weights=weight * 0.75 * x[:, a], minlength=self.n_cells) for a in range(3)]
        )
        with np.errstate(divide="ignore", invalid="ignore"):
            return apex + moment.T / volume[:, None]

    @cached_property
    def edges(self) -> np.ndarray:
        """``(E, 2)`` the sides of the faces, each once as (smaller, larger) vertex, in increasing order."""
        offsets, ids = self.face_offsets, self.face_vertices
        following = np.arange(1, ids.size + 1, dtype=np.int64)
        following[offsets[1:][offsets[1:] > offsets[:-1]] - 1] = offsets[:-1][offsets[1:] > offsets[:-1]]
        pairs = np.sort(np.stack([ids, ids[following]], axis=1), axis=1) if ids.size else np.zeros((0, 2), np.int64)
        return np.unique(pairs, axis=0)


@numba.njit(cache=True)
def _diameters(vertices, offsets, ids):
    """Per CSR segment of vertex ids: the largest distance between two of its vertices."""
    out = np.zeros(offsets.size - 1)
    for c in range(offsets.size - 1):
        best = 0.0
        for i in range(offsets[c], offsets[c + 1]):
            for j in range(i + 1, offsets[c + 1]):
                d = 0.0
                for a in range(3):
                    t = vertices[ids[i], a] - vertices[ids[j], a]
                    d += t * t
                best = max(best, d)
        out[c] = np.sqrt(best)
    return out


def diameters_numpy(vertices, offsets, ids) -> np.ndarray:
    """The numpy twin of ``_diameters`` (segments grouped by size, in chunks)."""
    sizes = np.diff(offsets)
    out = np.zeros(sizes.size)
    for size in np.unique(sizes):
        cells = np.flatnonzero(sizes == size)
        step = max(1, 2_000_000 // int(size * size))
        for s in range(0, cells.size, step):
            chunk = cells[s : s + step]
            p = vertices[ids[offsets[chunk][:, None] + np.arange(size)]]
            d = ((p[:, :, None, :] - p[:, None, :, :]) ** 2).sum(axis=-1)
            out[chunk] = np.sqrt(d.reshape(chunk.size, -1).max(axis=1))
    return out


def from_polyhedra(vertices, cells, boundary=None, meta=None) -> PolyhedralMesh:
    """Build a mesh from cells given as lists of outward polygonal faces (vertex-index sequences):
    faces shared by two cells (the same vertex set) are stored once. ``boundary``: {side: list of
    faces as vertex sequences}, matched to the stored faces by their vertex sets."""
    key_of = {}
    face_lists, offsets = [], [0]
    cell_faces = []
    for faces in cells:
        for face in faces:
            face = [int(v) for v in face]
            key = tuple(sorted(face))
            if key in key_of:
                stored = key_of[key]
                cell_faces.append(-(stored + 1) if _same_orientation(face, face_lists[stored]) is False else stored)
            else:
                key_of[key] = len(face_lists)
                face_lists.append(face)
                cell_faces.append(key_of[key])
        offsets.append(len(cell_faces))
    face_offsets = np.concatenate([[0], np.cumsum([len(f) for f in face_lists])])
    parts = {
        side: [key_of[tuple(sorted(int(v) for v in face))] for face in faces]
        for side, faces in (boundary or {}).items()
    }
    flat = np.concatenate([np.asarray(f, dtype=np.int64) for f in face_lists]) if face_lists else np.zeros(0, np.int64)
    return PolyhedralMesh(
        np.asarray(vertices, float), face_offsets, flat, np.asarray(offsets), np.asarray(cell_faces), parts, meta or {}
    )


def _same_orientation(face, stored) -> bool:
    """Whether two vertex cycles of one face run the same way."""
    i = stored.index(face[0])
    return stored[(i + 1) % len(stored)] == face[1]
