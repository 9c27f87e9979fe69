"""Shared by tests/vem/test_volumetric.py and tests/vem3d/test_volumetric3d.py: the patch test and
the kernel count of the nodal volumetric strain (``vemkit.vem.volumetric``), any dimension."""

from __future__ import annotations

import numpy as np
import scipy.sparse.linalg as spla

from vemkit.vem.volumetric import stiffness_matrix

LAM, MU = 4999.0, 1.0  # nu = 0.4999 in plane strain (lambda / mu = 2 nu / (1 - 2 nu))


def boundary_mask(space) -> np.ndarray:
    mask = np.zeros(space.n_nodes, dtype=bool)
    for sides in space.mesh.boundary.values():
        mask |= space.clamped_on(sides)
    return mask


def linear_field(dimension: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    c, G = rng.normal(size=dimension), rng.normal(size=(dimension, dimension))
    return lambda *x: tuple(c[i] + sum(G[i, j] * x[j] for j in range(dimension)) for i in range(dimension))


def patch_test(space, stabilization: str = "dofi-2mu") -> float:
    """max |u_h - u| / max |u| at the interior nodes, u linear and imposed on the boundary nodes."""
    d = space.element.dimension
    exact = space.interpolate(linear_field(d)).ravel()
    K = stiffness_matrix(space, LAM, MU, stabilization, space.numbering(natural=True), "nodal_average")
    on_boundary = np.repeat(boundary_mask(space), d)
    inner, outer = np.flatnonzero(~on_boundary), np.flatnonzero(on_boundary)
    K = K.tocsr()
    u = spla.spsolve(K[inner][:, inner].tocsc(), -K[inner][:, outer] @ exact[outer])
    return float(np.max(np.abs(u - exact[inner])) / np.max(np.abs(exact)))


def kernel_size(K) -> int:
    """The eigenvalues of the symmetric K below 1e-10 of the largest (after checking K = K^T >= 0; the
    3D element's matrices are symmetric to rounding, the nodal term exactly)."""
    dense = K.toarray()
    assert np.abs(dense - dense.T).max() <= 1e-14 * np.abs(dense).max()
    values = np.linalg.eigvalsh(dense)
    assert values[0] > -1e-10 * values[-1]
    return int(np.sum(values < 1e-10 * values[-1]))
