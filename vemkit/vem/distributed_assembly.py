"""The stiffness (3.9) assembled across MPI ranks: each rank computes its own cells only.

The cells are split by METIS (``vemkit.mesh.partition``); a free node belongs to the rank of its
lowest-numbered cell, and the unknowns are renumbered rank after rank, node by node
(:class:`DofLayout`: PETSc's contiguous ownership, d components per node, so the matrix keeps its
d x d blocks). Each rank computes the local matrices of its cells with the element's Numba kernels
(``cell_entries``, specialized per element as ``vemkit.vem.assembly``'s templates are), a share of
them at a time (:data:`SHARE_ENTRIES`), and sums them into the rows they touch (``rank_rows``); the
rows another rank owns are sent to it and added there (``to_owners``, one MPI all-to-all: the
partition's interface), and PETSc's MPIAIJ matrix is made of each rank's own rows. Held components
(``DofMap.fixed_dofs``) get the symmetric elimination of ``vemkit.vem.dofs.apply_fixed_dofs``
entry by entry: their rows and columns dropped but for the diagonal, K_fh g moved to the load.

Only what a cell's own matrix holds is distributed: the nodal-average volumetric term and the
k = 2 change of variables on Gamma_C couple cells beyond one element and are refused here
(:func:`check_distributable`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
import scipy.sparse as sp

from vemkit.exceptions import SceneError
from vemkit.mesh.partition import cell_partition
from vemkit.vem.assembly import condense_interior, largest_cell, material_of, specialized
from vemkit.vem.distributed_matrix import DistributedStiffness
from vemkit.vem.pattern import ROW_CHUNKS, chunk_rows

#: entries of cell matrices computed at a time (16 bytes each with their row and column): a rank's
#: cells in shares of at most this many, summed into its rows share by share
SHARE_ENTRIES = 1 << 24


@dataclass(frozen=True)
class DofLayout:
    """The unknowns split across the ranks of ``comm``: ``order[p]`` is the unknown (in the serial
    numbering of the DofMap) that PETSc numbers p; rank r owns p in [starts[r], starts[r + 1])."""

    comm: object
    order: np.ndarray
    position: np.ndarray  # the inverse of order: PETSc's number of each serial unknown
    starts: np.ndarray
    dimension: int

    @property
    def rank(self) -> int:
        return self.comm.Get_rank()

    @property
    def owned(self) -> slice:
        return slice(int(self.starts[self.rank]), int(self.starts[self.rank + 1]))

    @property
    def n_owned(self) -> int:
        return int(self.starts[self.rank + 1] - self.starts[self.rank])

    @property
    def size(self) -> int:
        return int(self.starts[-1])

    def local(self, x) -> np.ndarray:
        """The owned entries of a whole vector x (serial numbering), in PETSc's order."""
        return np.ascontiguousarray(np.asarray(x, dtype=float)[self.order[self.owned]])

    def gather(self, local) -> np.ndarray:
        """The whole vector (serial numbering) of every rank's owned entries (allgather)."""
        from mpi4py import MPI

        counts = np.diff(self.starts)
        ordered = np.empty(self.size)
        self.comm.Allgatherv(np.ascontiguousarray(local, dtype=float), [ordered, counts, self.starts[:-1], MPI.DOUBLE])
        out = np.empty(self.size)
        out[self.order] = ordered
        return out

    def sum(self, x) -> np.ndarray:
        """The sum over the ranks of an array (allreduce)."""
        from mpi4py import MPI

        out = np.empty_like(np.asarray(x, dtype=float))
        self.comm.Allreduce(np.ascontiguousarray(x, dtype=float), out, op=MPI.SUM)
        return out


def node_owners(offsets, nodes, cell_part, n_nodes) -> np.ndarray:
    """(n_nodes,) the part of each node's lowest-numbered cell."""
    first = np.full(n_nodes, offsets.shape[0], dtype=np.int64)
    cells = np.repeat(np.arange(offsets.shape[0] - 1, dtype=np.int64), np.diff(offsets))
    np.minimum.at(first, nodes, cells)
    return cell_part[np.minimum(first, offsets.shape[0] - 2)]


def dof_layout(comm, dofs, offsets, nodes, cell_part) -> DofLayout:
    """The free nodes renumbered rank after rank (in their serial order within a rank)."""
    d, size = dofs.dimension, comm.Get_size()
    owner = node_owners(offsets, nodes, cell_part, dofs.n_nodes)[dofs.free_nodes]
    node_order = np.argsort(owner, kind="stable")
    order = (d * node_order[:, None] + np.arange(d)).ravel()
    position = np.empty_like(order)
    position[order] = np.arange(order.size)
    starts = d * np.concatenate([[0], np.cumsum(np.bincount(owner, minlength=size))])
    return DofLayout(comm, order, position, starts.astype(np.int64), d)


def column_layout(layout: DofLayout, Z) -> DofLayout:
    """The columns of Z (n x m, whole on every rank) split across the ranks: a column goes with
    the first unknown it touches (Z's columns each touch one vertex: the stick basis)."""
    csc = Z.tocsc()
    csc.sort_indices()
    first_row = csc.indices[csc.indptr[:-1]]
    owner = np.searchsorted(layout.starts, layout.position[first_row], side="right") - 1
    order = np.argsort(owner, kind="stable")
    position = np.empty_like(order)
    position[order] = np.arange(order.size)
    counts = np.bincount(owner, minlength=layout.comm.Get_size())
    return DofLayout(layout.comm, order, position, np.concatenate([[0], np.cumsum(counts)]).astype(np.int64), 1)


def cell_entries(geometry, cells, owned, starts, free_index, position, material, max_nodes, rows, cols, vals):
    """*Template* (parallel). The entries of the local stiffness (3.9) of every cell in ``owned``,
    rows and columns of its free nodes (PETSc's numbers ``position[d r + a]`` of the serial unknowns
    d r + a), from ``starts[t]`` on for the t-th cell; each thread a contiguous share of the cells,
    its work arrays allocated once."""
    offsets, nodes = cells
    lam, mu, stab, condense = material
    for chunk in numba.prange(ROW_CHUNKS):
        lo, hi = chunk_rows(chunk, owned.shape[0])
        work = workspace(max_nodes)  # noqa: F821 (bound by ``specialized``)
        for t in range(lo, hi):
            c = owned[t]
            start, size = offsets[c], offsets[c + 1] - offsets[c]
            K = cell_matrix(c, geometry, offsets, nodes, lam, mu, stab, work)  # noqa: F821
            if condense:
                condense_interior(K, size)
            p = starts[t]
            for i in range(size):
                r = free_index[nodes[start + i]]
                if r < 0:
                    continue
                for a in range(DIM):  # noqa: F821 (bound by ``specialized``)
                    for j in range(size):
                        s = free_index[nodes[start + j]]
                        if s < 0:
                            continue
                        for b in range(DIM):  # noqa: F821
                            rows[p] = position[DIM * r + a]  # noqa: F821
                            cols[p] = position[DIM * s + b]  # noqa: F821
                            vals[p] = K[DIM * i + a, DIM * j + b]  # noqa: F821
                            p += 1


def cell_entry_counts(space, dofs, owned) -> np.ndarray:
    """The entries of each owned cell's matrix: (d x its free nodes)^2."""
    offsets, nodes = space.cell_nodes
    free = (dofs.free_index[nodes] >= 0).astype(np.int64)
    per_cell = np.add.reduceat(free, offsets[:-1]) if nodes.size else np.zeros(offsets.size - 1, np.int64)
    return (space.element.dimension * per_cell[owned]) ** 2


def owned_cell_entries(space, lam, mu, stabilization, dofs, owned, layout) -> tuple:
    """(rows, cols, values) of the cells ``owned`` (PETSc's numbering of ``layout``)."""
    offsets, nodes = cells = space.cell_nodes
    starts = np.concatenate([[0], np.cumsum(cell_entry_counts(space, dofs, owned))]).astype(np.int64)
    integers = np.int32 if layout.size < 2**31 else np.int64
    rows = np.empty(starts[-1], dtype=integers)
    cols = np.empty(starts[-1], dtype=integers)
    vals = np.empty(starts[-1])
    kernel = specialized(cell_entries, space.element, parallel=True)
    kernel(
        space.element.geometry(space.mesh),
        cells,
        np.ascontiguousarray(owned, dtype=np.int64),
        starts,
        dofs.free_index,
        layout.position.astype(integers),
        material_of(lam, mu, stabilization, dofs),
        largest_cell(offsets),
        rows,
        cols,
        vals,
    )
    return rows, cols, vals


def splits(comm, treatment: str, change) -> bool:
    """Whether the stiffness is assembled across the ranks of ``comm``: on several ranks always
    (else a SceneError, :func:`check_distributable`); on one where the formulation allows it (one
    process then keeps the scipy assembly of what the split does not cover)."""
    if comm.Get_size() > 1:
        check_distributable(treatment, change)
        return True
    return treatment == "cell" and change is None


def check_distributable(treatment: str, change) -> None:
    """SceneError for what couples cells beyond one element's matrix (module docstring)."""
    if treatment != "cell":
        raise SceneError(
            f"volumetric_strain = {treatment} is not split across MPI ranks yet; run in one process "
            "(without mpiexec) or set discretization.volumetric_strain=cell",
            key="discretization.volumetric_strain",
        )
    if change is not None:
        raise SceneError(
            "order 2 with a contact side is not split across MPI ranks yet; run in one process "
            "(without mpiexec) or set discretization.order=1",
            key="discretization.order",
        )


def held_elimination(rows, cols, vals, held, values, lift, diagonal) -> None:
    """The symmetric elimination of the held unknowns on one share of the entries (PETSc's
    numbering): -K_fh g added to ``lift``, the held diagonal to ``diagonal`` (this rank's parts), the
    held rows' and columns' other entries set to zero in place (no copy of the entries)."""
    row_held, col_held = held[rows], held[cols]
    touched = np.flatnonzero(row_held | col_held)  # a few entries: work on them alone
    r, c, row_held, col_held = rows[touched], cols[touched], row_held[touched], col_held[touched]
    into_held = col_held & ~row_held
    np.add.at(lift, r[into_held], -vals[touched[into_held]] * values[c[into_held]])
    on_diagonal = row_held & (r == c)
    np.add.at(diagonal, r[on_diagonal], vals[touched[on_diagonal]])
    vals[touched[r != c]] = 0.0


def cell_shares(entries: np.ndarray) -> list:
    """The owned cells in consecutive shares of at most :data:`SHARE_ENTRIES` entries (one cell at least)."""
    ends = np.cumsum(entries)
    cuts = np.searchsorted(ends, np.arange(1, int(ends[-1] // SHARE_ENTRIES) + 1) * SHARE_ENTRIES) if ends.size else []
    bounds = np.unique(np.concatenate([[0], np.asarray(cuts, dtype=np.int64) + 1, [entries.size]]))
    return [slice(int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:]) if b > a]


def rank_rows(space, lam, mu, stabilization, dofs, owned, layout):
    """(the rows this rank's cells touch, summed: scipy CSR n x n in PETSc's numbering; the held
    elimination's lift and diagonal, this rank's parts), the cells computed share by share."""
    n = layout.size
    held, values = np.zeros(n, dtype=bool), np.zeros(n)
    held[layout.position[dofs.fixed_dofs]] = True
    values[layout.position[dofs.fixed_dofs]] = dofs.fixed_values
    lift, diagonal, rows_sum = np.zeros(n), np.zeros(n), sp.csr_matrix((n, n))
    for share in cell_shares(cell_entry_counts(space, dofs, owned)):
        rows, cols, vals = owned_cell_entries(space, lam, mu, stabilization, dofs, owned[share], layout)
        if dofs.fixed_dofs.size:
            held_elimination(rows, cols, vals, held, values, lift, diagonal)
        part = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))  # duplicates summed
        del rows, cols, vals
        rows_sum = rows_sum + part
    return rows_sum, lift, diagonal


def to_owners(layout, rows_sum) -> sp.csr_matrix:
    """This rank's rows (n_owned x n, global columns) with the other ranks' contributions to them
    added: each rank sends the rows it touched but does not own to their owner (MPI all-to-all)."""
    from mpi4py import MPI

    comm, rank, starts = layout.comm, layout.rank, layout.starts
    indptr = rows_sum.indptr
    ranges = indptr[starts]  # the entries of rank q's rows: ranges[q]:ranges[q + 1] (rows contiguous)
    counts = np.diff(ranges).astype(np.int64)
    counts[rank] = 0
    others = [q for q in range(comm.Get_size()) if q != rank]
    sent = np.concatenate(
        [np.arange(ranges[q], ranges[q + 1], dtype=np.int64) for q in others] or [np.zeros(0, np.int64)]
    )
    row_of = np.concatenate(  # the row of every sent entry
        [np.repeat(np.arange(starts[q], starts[q + 1]), np.diff(indptr[starts[q] : starts[q + 1] + 1])) for q in others]
        or [np.zeros(0, np.int64)]
    )
    received = comm.alltoall(counts.tolist())
    displs, rdispls = np.concatenate([[0], np.cumsum(counts)[:-1]]), np.concatenate([[0], np.cumsum(received)[:-1]])
    out = [np.empty(int(sum(received)), dtype=dtype) for dtype in (np.int64, np.int64, np.float64)]
    for data, buffer, kind in zip(
        (row_of, rows_sum.indices[sent].astype(np.int64), rows_sum.data[sent]),
        out,
        (MPI.INT64_T, MPI.INT64_T, MPI.DOUBLE),
    ):
        comm.Alltoallv([np.ascontiguousarray(data), (counts, displs), kind], [buffer, (received, rdispls), kind])
    lo, hi = int(starts[rank]), int(starts[rank + 1])
    own = rows_sum[lo:hi]
    incoming = sp.csr_matrix((out[2], (out[0] - lo, out[1])), shape=(hi - lo, layout.size))
    total = (own + incoming).tocsr()
    total.sort_indices()
    return total


def distributed_stiffness(space, lam, mu, stabilization, dofs, load, comm, treatment="cell"):
    """(K, f): the stiffness on the free unknowns split across the ranks of ``comm`` (a
    :class:`DistributedStiffness`, every rank its own cells' entries) and the load with the held
    components eliminated (``vemkit.vem.dofs.apply_fixed_dofs``), whole on every rank."""
    check_distributable(treatment, dofs.change)
    offsets, nodes = space.cell_nodes
    part = comm.bcast(cell_partition(space.mesh, offsets, nodes, comm.Get_size()) if comm.Get_rank() == 0 else None)
    layout = dof_layout(comm, dofs, offsets, nodes, part)
    owned = np.flatnonzero(part == comm.Get_rank())
    rows_sum, lift, diagonal = rank_rows(space, lam, mu, stabilization, dofs, owned, layout)
    K = DistributedStiffness.from_rows(layout, to_owners(layout, rows_sum))
    f = load + layout.sum(lift)[layout.position]
    if dofs.fixed_dofs.size:
        f[dofs.fixed_dofs] = layout.sum(diagonal)[layout.position[dofs.fixed_dofs]] * dofs.fixed_values
    return K, f
