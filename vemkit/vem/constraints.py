"""Dirichlet conditions (2.4) and SPEC §7: which displacement components are prescribed, and how.

A Dirichlet side prescribes u1, u2 or both (``None``: that component is free, a roller or a
symmetry line); values are numbers or functions of (x, y), evaluated at the side's vertices. At a
vertex shared by two Dirichlet sides, the side listed first prescribes a component both prescribe.

- A vertex with both components prescribed to exactly zero is *clamped*: eliminated while
  assembling (:class:`vemkit.vem.assembly.DofMap`), as the paper's u = 0 on Gamma_D.
- Every other prescribed component is a *fixed dof* of a kept vertex: after assembly its column
  times the value moves to the right-hand side, its row and column are zeroed and the diagonal
  entry K_ii kept, with f_i = K_ii g_i (symmetric elimination: the system stays symmetric
  positive definite and u_i = g_i exactly in its solution).

:func:`free_rigid_motion` says which rigid motion (a translation or a rotation about a point)
the prescribed components leave free; the problem refuses such a scene before assembly.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from vemkit.config.boundary_conditions import free_rigid_motion  # before assembly, also from the domain
from vemkit.mesh.mesh import Mesh
from vemkit.vem.assembly import DofMap

__all__ = ["apply_fixed_dofs", "constrained_dofs", "dirichlet_components", "free_rigid_motion"]


def _values(component, x, y) -> np.ndarray:
    if callable(component):
        return np.broadcast_to(np.asarray(component(x, y), dtype=float), x.shape).copy()
    return np.full(x.shape, float(component))


def dirichlet_components(mesh: Mesh, dirichlet) -> tuple[np.ndarray, np.ndarray]:
    """(prescribed (n_vertices, 2) bool, values (n_vertices, 2)) of ``dirichlet``: a sequence of
    side names (u = 0) or a mapping side -> (u1, u2), each None, a number or a function of (x, y)."""
    entries = dirichlet.items() if isinstance(dirichlet, dict) else ((side, (0.0, 0.0)) for side in dirichlet)
    prescribed = np.zeros((mesh.n_vertices, 2), dtype=bool)
    values = np.zeros((mesh.n_vertices, 2))
    for side, components in entries:
        vertices = np.unique(mesh.boundary[side])
        x, y = mesh.vertices[vertices, 0], mesh.vertices[vertices, 1]
        for c, component in enumerate(components):
            if component is None:
                continue
            new = vertices[~prescribed[vertices, c]]  # the first listed side wins
            values[new, c] = _values(component, x, y)[~prescribed[vertices, c]]
            prescribed[new, c] = True
    return prescribed, values


def constrained_dofs(prescribed: np.ndarray, values: np.ndarray) -> DofMap:
    """The dof map: clamped vertices (both components prescribed zero) eliminated, the other
    prescribed components fixed dofs of kept vertices."""
    clamped = np.all(prescribed, axis=1) & np.all(values == 0.0, axis=1)
    dofs = DofMap.from_clamped(prescribed.shape[0], np.flatnonzero(clamped))
    kept = prescribed[dofs.free_vertices]  # (n_free_vertices, 2)
    fixed = np.flatnonzero(kept.ravel())
    return DofMap(dofs.free_vertices, dofs.free_index, fixed,
                  values[dofs.free_vertices].ravel()[fixed].copy())


def apply_fixed_dofs(stiffness: sp.csr_matrix, load: np.ndarray, dofs: DofMap):
    """(K, f) with the fixed dofs held at their values by symmetric elimination (module doc)."""
    if dofs.fixed_dofs.size == 0:
        return stiffness, load
    fixed, g = dofs.fixed_dofs, dofs.fixed_values
    load = load - stiffness[:, fixed] @ g
    K = stiffness.tocsr(copy=True)
    diagonal = K.diagonal()[fixed]
    held = np.zeros(K.shape[0], dtype=bool)
    held[fixed] = True
    rows = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))
    K.data[held[rows] | held[K.indices]] = 0.0
    K.eliminate_zeros()
    K = (K + sp.csr_matrix((diagonal, (fixed, fixed)), shape=K.shape)).tocsr()
    K.sort_indices()
    load[fixed] = diagonal * g
    return K, load
