"""The cells of a mesh split into parts of nearly equal size with short interfaces (METIS).

:func:`cell_partition` partitions the dual graph of the cells (two cells adjacent when they share
a side: :data:`SHARED_SIDE_VERTICES` vertices, an edge in 2D, a face in 3D) with METIS through
pymetis, as a distributed solve splits the assembly (``vemkit.vem.distributed``). METIS is
deterministic: the same mesh gives the same parts in every process.
"""

from __future__ import annotations

import numpy as np

from vemkit.exceptions import SceneError

#: vertices two cells of dimension d share across a side: an edge's 2, a face's at least 3
SHARED_SIDE_VERTICES = {2: 2, 3: 3}


def cell_vertex_lists(offsets: np.ndarray, nodes: np.ndarray, n_vertices: int) -> list:
    """Each cell's vertices (its nodes below ``n_vertices``; the higher ones are k = 2's edge and
    cell nodes), one array per cell, as METIS reads a mesh."""
    cells = np.split(nodes, offsets[1:-1])
    return [c[c < n_vertices] for c in cells]


def cell_partition(mesh, offsets: np.ndarray, nodes: np.ndarray, parts: int) -> np.ndarray:
    """(M,) the part 0 ... parts - 1 of every cell of ``mesh`` (cells given as the CSR
    (offsets, nodes) of their nodes); one part: every cell in part 0."""
    n_cells = offsets.shape[0] - 1
    if parts <= 1 or n_cells == 0:
        return np.zeros(n_cells, dtype=np.int64)
    if n_cells < parts:
        raise SceneError(
            f"the mesh has {n_cells} cells for {parts} MPI ranks; use fewer ranks or a finer discretization.mesh",
            key="discretization.mesh",
        )
    try:
        import pymetis
    except ImportError:
        raise SceneError(
            "a solve on several MPI ranks partitions the mesh with pymetis, which is not installed; "
            "run make install (it installs the mpi extra) or pip install -e '.[mpi]'",
            key="solver.linear",
        ) from None
    connectivity = cell_vertex_lists(offsets, nodes, mesh.n_vertices)
    result = pymetis.part_mesh(
        parts, connectivity, gtype=pymetis.GType.DUAL, ncommon=SHARED_SIDE_VERTICES[mesh.dimension]
    )
    part = np.asarray(result.element_part, dtype=np.int64)
    if np.unique(part).size < parts:  # METIS left a part empty (a tiny or strangely shaped mesh)
        part = np.minimum(np.arange(n_cells) * parts // n_cells, parts - 1)
    return part
