"""What every mesh offers, d = 2 and d = 3: one vocabulary for the polygonal
:class:`~vemkit.mesh.mesh.Mesh` and the polyhedral :class:`~vemkit.mesh.polyhedral.PolyhedralMesh`.

A mesh is plain arrays (as scikit-fem's): vertices, cells, facets and the named sides of the
boundary as facet ids. A *facet* is a cell's (d - 1)-dimensional piece: an edge in 2D, a face in 3D.
Both classes implement :class:`MeshInterface` with the same names; the members that follow from the
others are written once, in :class:`SharedMeshMembers`, which both inherit. Families, mesh files,
checks and refinement give one of the two; code that reads a mesh through these members never asks
which (``mesh.dimension`` says d where a formula needs it).

The members, property by property (N vertices, M cells, F facets, E edges):

===========================  ======================================================================
``dimension``                d: 2 or 3
``vertices``                 ``(N, d)`` float64 coordinates
``n_vertices``, ``n_cells``  N, M
``n_facets``                 F
``cell_vertex_lists``        CSR ``(offsets (M + 1,), vertex ids)``: every cell's distinct vertices
                             (2D: the polygon, counter-clockwise; 3D: in order of first appearance
                             along its faces)
``cell_facet_lists``         CSR ``(offsets (M + 1,), signed facet ids)``: ``f >= 0`` facet f as
                             stored, ``-(f + 1)`` facet f reversed; taken with their signs the
                             facets of a cell point out of it
``facets``                   CSR ``(offsets (F + 1,), vertex ids)``: every facet once (2D: an edge
                             ``(a, b)``, oriented as in its first cell; 3D: a face's vertex cycle)
``facet_cells``              ``(F, 2)``: column 0 the cell the stored facet points out of, column 1
                             the cell it points into; ``-1`` where there is none
``facet_vector_areas``       ``(F, d)``: |F| n_F of every stored facet (n_F its unit normal)
``facet_normals``            ``(F, d)`` unit normals n_F of the stored facets (zero for a facet of
                             zero size)
``facet_areas``              ``(F,)`` |F|: face areas in 3D, edge lengths in 2D
``facet_centroids``          ``(F, d)`` area centroids (edge midpoints in 2D)
``cell_volumes``             ``(M,)`` signed volumes (2D: signed areas), positive for a cell whose
                             facets point out
``cell_centroids``           ``(M, d)`` volume (2D: area) centroids
``cell_diameters``, ``h``    ``(M,)`` h_K = diam K, and max h_K
``edges``                    ``(E, 2)`` vertex pairs: the facets in 2D, the faces' sides in 3D
``exterior_facets``          the facets of one cell only (the boundary), increasing
``boundaries``               ``{side: facet ids}``: the named sides of the boundary
``boundary_facets(side)``    ``boundaries[side]``; every exterior facet for ``side=None``
``boundary_vertices(side)``  the sorted vertices of a named side
``side_edges(side)``         ``(k, 2)`` vertex pairs: a side's edges (2D), its faces' sides (3D)
``meta``                     how the mesh was made (family, n, seed, ...)
===========================  ======================================================================

Each class keeps its own older names beside these (2D: ``edges``, ``edge_cells``, ``cell_areas``,
``boundary`` as vertex pairs; 3D: ``faces``-named members, ``boundary`` as face ids).
"""

from __future__ import annotations

from functools import cached_property
from typing import ClassVar, Protocol, runtime_checkable

import numpy as np

__all__ = ["INTERFACE_MEMBERS", "MeshInterface", "SharedMeshMembers"]


@runtime_checkable
class MeshInterface(Protocol):
    """A mesh of any dimension (module doc: every member, its shape and its meaning). Every member
    is read-only (the meshes are frozen; most are properties, computed on demand).

    ``isinstance(mesh, MeshInterface)`` checks that every member is there; on Python < 3.12 it
    evaluates them (cached properties are computed): a test's question, not a dispatch."""

    dimension: int
    vertices: np.ndarray
    n_vertices: int
    n_cells: int
    n_facets: int
    cell_vertex_lists: tuple[np.ndarray, np.ndarray]
    cell_facet_lists: tuple[np.ndarray, np.ndarray]
    facets: tuple[np.ndarray, np.ndarray]
    facet_cells: np.ndarray
    facet_vector_areas: np.ndarray
    facet_normals: np.ndarray
    facet_areas: np.ndarray
    facet_centroids: np.ndarray
    cell_volumes: np.ndarray
    cell_centroids: np.ndarray
    cell_diameters: np.ndarray
    h: float
    edges: np.ndarray
    exterior_facets: np.ndarray
    boundaries: dict
    meta: dict

    def boundary_facets(self, side: str | None = None) -> np.ndarray: ...

    def boundary_vertices(self, name: str) -> np.ndarray: ...

    def side_edges(self, name: str) -> np.ndarray: ...


#: every member of :class:`MeshInterface` (its attributes, then its methods), as the tests check them
INTERFACE_MEMBERS = tuple(MeshInterface.__annotations__) + tuple(
    name for name, member in vars(MeshInterface).items() if callable(member) and not name.startswith("_")
)


class SharedMeshMembers:
    """The members of :class:`MeshInterface` that follow from the others, written once for both
    meshes (a mixin: a mesh class provides ``facets``, ``facet_cells``, ``facet_vector_areas`` and
    ``boundaries``), and the construction of both frozen dataclasses: their arrays (``array_fields``)
    made contiguous of their dtypes, the named boundary parts int64 arrays of ``boundary_part_shape``."""

    #: (field, dtype) of every array the mesh holds
    array_fields: ClassVar[tuple] = ()
    #: the shape of a named boundary part: (-1, 2) vertex pairs (2D), (-1,) face ids (3D)
    boundary_part_shape: ClassVar[tuple] = (-1,)

    def __post_init__(self):
        for name, dtype in self.array_fields:
            object.__setattr__(self, name, np.ascontiguousarray(getattr(self, name), dtype=dtype))
        parts = self.boundary.items()
        boundary = {str(k): np.asarray(v, dtype=np.int64).reshape(self.boundary_part_shape) for k, v in parts}
        object.__setattr__(self, "boundary", boundary)

    @property
    def n_facets(self) -> int:
        return self.facets[0].shape[0] - 1  # type: ignore[attr-defined]

    @cached_property
    def facet_areas(self) -> np.ndarray:
        """|F| of every facet: the length of its vector area."""
        return np.sqrt((self.facet_vector_areas**2).sum(axis=1))  # type: ignore[attr-defined]

    @cached_property
    def facet_normals(self) -> np.ndarray:
        """Unit normals of the stored facets (zero where a facet has no size)."""
        areas = self.facet_areas
        safe = np.where(areas > 0, areas, 1.0)
        return np.where(areas[:, None] > 0, self.facet_vector_areas / safe[:, None], 0.0)  # type: ignore[attr-defined]

    @cached_property
    def exterior_facets(self) -> np.ndarray:
        """The facets of one cell only, increasing."""
        return np.flatnonzero((self.facet_cells < 0).any(axis=1))  # type: ignore[attr-defined]

    def boundary_facets(self, side: str | None = None) -> np.ndarray:
        """The facet ids of the named side ``side``; every exterior facet for None. KeyError for a
        name the mesh does not have."""
        return self.exterior_facets if side is None else self.boundaries[side]  # type: ignore[attr-defined]
