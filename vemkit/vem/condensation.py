"""Static condensation of the interior nodes: the condensed load and the recovery of the eliminated dofs.

An element's interior node (the k = 2 cell mean, Section 3.1: its interior moment; the last of the
cell's nodes, ``Element.condensed_nodes``) couples only with the nodes of its own cell, so it can be
eliminated cell by cell, exactly: with b the other scalars of a cell and c its interior scalars,

    K_bb u_b + K_bc u_c = f_b,   K_cb u_b + K_cc u_c = f_c
    =>  (K_bb - K_bc K_cc^-1 K_cb) u_b = f_b - K_bc K_cc^-1 f_c,   u_c = K_cc^-1 (f_c - K_cb u_b).

The Schur complement is summed element by element while assembling (``DofMap.condensed``,
``vemkit.vem.assembly.condense_interior``); :func:`condense_load` gives the right-hand side, and
:func:`recover_interior` the eliminated values from the solution. The contact terms act on Gamma_C
nodes only, so they commute with the elimination. For k = 2 the condensed system has a quarter fewer
unknowns and, measured on the paper scene at 131 584 dofs, needs half the AMG-CG iterations of the
full one (the cell means are poorly represented by aggregation of the rigid modes).
"""

from __future__ import annotations

import weakref

import numba
import numpy as np

from vemkit.vem.assembly import largest_cell, specialized
from vemkit.vem.elements import stabilization_code

CELL_CHUNKS = 8  # threads' shares of the cells in the recovery

#: per space, the last recovery: ((lam, mu, stabilization), node values, interior loads, result).
#: A solution is recovered twice when it is written (its projection and its node values, 0.1 s at
#: 2e5 DOFs); the second time gives a copy of the first result when every input is the same, bit for bit.
_LAST_RECOVERY: "weakref.WeakKeyDictionary[object, tuple]" = weakref.WeakKeyDictionary()


@numba.njit(cache=True)
def interior_solve(K, size, r0, r1):
    """K_cc^-1 (r0, r1) for the interior node (the last of ``size``) of an element matrix."""
    c = 2 * (size - 1)
    a, b, d, e = K[c, c], K[c, c + 1], K[c + 1, c], K[c + 1, c + 1]
    det = a * e - b * d
    return (e * r0 - b * r1) / det, (a * r1 - d * r0) / det


def condense(vertices, offsets, nodes, interior_load, lam, mu, stab, parts):
    """*Template* (parallel). parts[2 offsets[c] + 2 i + a] = (K_bc K_cc^-1 f_c)[2 i + a] for the
    non-interior nodes i of every cell with a non-zero interior load f_c (M, 2); the others stay 0."""
    n_cells = offsets.shape[0] - 1
    max_nodes = largest_cell(offsets)
    for chunk in numba.prange(CELL_CHUNKS):
        work = workspace(max_nodes)  # noqa: F821 (bound by ``specialized``)
        for c in range(chunk * n_cells // CELL_CHUNKS, (chunk + 1) * n_cells // CELL_CHUNKS):
            if interior_load[c, 0] == 0.0 and interior_load[c, 1] == 0.0:
                continue
            K = cell_matrix(c, vertices, offsets, nodes, lam, mu, stab, work)  # noqa: F821
            start = offsets[c]
            size = offsets[c + 1] - start
            z0, z1 = interior_solve(K, size, interior_load[c, 0], interior_load[c, 1])
            ci = 2 * (size - 1)
            for i in range(size - 1):
                for a in range(2):
                    parts[2 * (start + i) + a] = K[2 * i + a, ci] * z0 + K[2 * i + a, ci + 1] * z1


def recover(vertices, offsets, nodes, u, interior_load, lam, mu, stab):
    """*Template* (parallel). u[interior node] = K_cc^-1 (f_c - K_cb u_b) for every cell (u: (n_nodes, 2))."""
    n_cells = offsets.shape[0] - 1
    max_nodes = largest_cell(offsets)
    for chunk in numba.prange(CELL_CHUNKS):
        work = workspace(max_nodes)  # noqa: F821
        for c in range(chunk * n_cells // CELL_CHUNKS, (chunk + 1) * n_cells // CELL_CHUNKS):
            K = cell_matrix(c, vertices, offsets, nodes, lam, mu, stab, work)  # noqa: F821
            start = offsets[c]
            size = offsets[c + 1] - start
            ci = 2 * (size - 1)
            r0, r1 = interior_load[c, 0], interior_load[c, 1]
            for j in range(size - 1):
                g = nodes[start + j]
                r0 -= K[ci, 2 * j] * u[g, 0] + K[ci, 2 * j + 1] * u[g, 1]
                r1 -= K[ci + 1, 2 * j] * u[g, 0] + K[ci + 1, 2 * j + 1] * u[g, 1]
            u[nodes[start + size - 1], 0], u[nodes[start + size - 1], 1] = interior_solve(K, size, r0, r1)


def interior_load(space, load_nodes) -> np.ndarray:
    """(M, 2) the part of a full load (n_nodes, 2) on the interior (cell) nodes: what recovery needs."""
    first = space.element.first_node(space.mesh, "cell")
    return np.ascontiguousarray(np.asarray(load_nodes, dtype=float).reshape(-1, 2)[first:])


def condense_load(space, lam: float, mu: float, stabilization: str, dofs, load_nodes) -> np.ndarray:
    """The condensed load f_b - K_bc K_cc^-1 f_c on the free dofs of a condensed ``dofs``, from the
    full load ``load_nodes`` (n_nodes, 2)."""
    if not dofs.condensed:
        raise ValueError("condense_load needs a condensed DofMap (VirtualElementSpace.numbering(condensed=True))")
    offsets, nodes = space.cell_nodes
    out, loads = dofs.restrict(load_nodes), interior_load(space, load_nodes)
    parts = np.zeros(2 * offsets[-1])
    specialized(condense, space.element, parallel=True)(
        space.mesh.vertices,
        offsets,
        nodes,
        loads,
        float(lam),
        float(mu),
        stabilization_code(stabilization),
        parts,
    )
    sizes = np.diff(offsets)
    kept = np.repeat((loads[:, 0] != 0.0) | (loads[:, 1] != 0.0), sizes)  # the cells with an interior load,
    kept[offsets[1:] - 1] = False  # their nodes but the interior one,
    kept &= dofs.free_index[nodes] >= 0  # the free ones
    rows = (2 * dofs.free_index[nodes[kept]][:, None] + np.arange(2)).ravel()
    np.subtract.at(out, rows, parts.reshape(-1, 2)[kept].ravel())  # in the cells' order: a serial loop's sums
    return out


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two float arrays are equal bit for bit (a NaN equals itself, -0.0 differs from 0.0)."""
    return a.shape == b.shape and np.array_equal(a.view(np.int64), b.view(np.int64))


def recover_interior(space, lam: float, mu: float, stabilization: str, node_values, interior_loads) -> np.ndarray:
    """(n_nodes, 2) ``node_values`` with its interior nodes recomputed from the other nodes of their cell
    and the load on the interior nodes ``interior_loads`` (M, 2): u_c = K_cc^-1 (f_c - K_cb u_b).
    The same inputs as the space's last recovery give a copy of its result (``_LAST_RECOVERY``)."""
    offsets, nodes = space.cell_nodes
    u = np.array(node_values, dtype=float).reshape(-1, 2)
    loads = np.ascontiguousarray(interior_loads, dtype=float).reshape(-1, 2)
    material = (float(lam), float(mu), stabilization)
    last = _LAST_RECOVERY.get(space)
    if last is not None and last[0] == material and _same_bits(last[1], u) and _same_bits(last[2], loads):
        return last[3].copy()
    given = u.copy()
    specialized(recover, space.element, parallel=True)(
        space.mesh.vertices,
        offsets,
        nodes,
        u,
        loads,
        material[0],
        material[1],
        stabilization_code(stabilization),
    )
    _LAST_RECOVERY[space] = (material, given, loads.copy(), u.copy())
    return u
