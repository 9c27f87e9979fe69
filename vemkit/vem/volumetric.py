"""The volumetric (lambda) part of the k = 1 stiffness: per cell (the paper's) or averaged at the nodes.

``cell`` is the paper's form (3.9): a_h(u, v) = sum_K [ |K| eps_K(Pi u) : C eps_K(Pi v) + S_K(u, v) ],
whose lambda part lambda |K| div_K(Pi u) div_K(Pi v) is one constraint per cell. On triangles and
tetrahedra (V_h = P1) there are too many of them near nu = 1/2: the discrete space has almost no
divergence-free fields and the solution locks (Cook's membrane in plane strain at nu = 0.4999:
0.80 of the reference on triangles at h = 2, 0.69 on tetrahedra).

``nodal_average`` is the node-based averaged volumetric strain, the average nodal pressure of Bonet
& Burton (1998) with the nodal averaging of Dohrmann et al. (2000), applied to the lambda part only:

    a(u, v) = sum_K [ 2 mu |K| eps_K(Pi u) : eps_K(Pi v) + S_K(u, v) ] + sum_a lambda V_a theta_a(u) theta_a(v),
    theta_a(u) = (1 / V_a) sum_{K containing vertex a} (|K| / n_K) div_K(Pi u),  V_a = sum_{K containing a} |K| / n_K,

div_K(Pi u) the trace of the cell's constant projected strain (``Element.divergence_table``) and n_K
its number of vertices. In matrix form the lambda part is lambda D^T A^T diag(V) A D = lambda G^T
diag(1 / V) G with D (cells x dofs) the divergence rows, A (vertices x cells) the averaging and
G = diag(V) A D, so K stays symmetric. Why this formulation:

- it works on every family (polygons, polyhedra, triangles, tetrahedra) with only the element's own
  projection: no new space, no new degrees of freedom;
- the unknowns stay the displacements: the contact solvers (ssn, uzawa), AMG with the rigid-body
  near-nullspace, the estimator and the files are untouched;
- one volumetric constraint per vertex against d displacement dofs per vertex removes the locking;
- K stays symmetric positive semidefinite, with exactly the rigid motions as kernel: the mu part
  (consistency plus stabilization) alone has only those, and the lambda part is a Gram matrix, so
  there are no spurious modes (a mixed u-p VEM would make the contact Newton a saddle-point
  problem; an edge-point VEM covers simplices only).

The stabilization S_K is kept exactly as the scene scales it. ``dofi`` and ``dofi-2mu`` do not
involve lambda: the element stiffness is assembled with lambda = 0 and the nodal term added.
``trace`` (alpha_K = tr(consistency) / dofs) does: the element stiffness is assembled with lambda,
so alpha_K is today's, and its cell lambda term lambda D^T diag(|K|) D is subtracted before the
nodal term is added. Only the lambda consistency term changes (with ``trace`` the stabilization
still grows with lambda and can lock on polygons: use ``dofi-2mu``, the default, near nu = 1/2).

The stresses of the formulation are sigma_K = 2 mu eps_K(Pi u) + lambda theta_K I with theta_K the
mean of theta_a over the cell's vertices (its pressure; ``cell_stress``): what the solution files
and the estimator report, so the output does not checkerboard.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from vemkit.exceptions import InputError
from vemkit.vem.projection import stress

#: the treatments of the volumetric part (``discretization.volumetric_strain`` resolved)
TREATMENTS = ("cell", "nodal_average")
#: the stabilization scalings alpha_K that do not involve lambda (``vemkit.vem.elements.STABILIZATIONS``)
LAMBDA_FREE_STABILIZATIONS = ("dofi", "dofi-2mu")

_NODAL: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # space -> NodalAverage


def kept_lambda(lam: float, stabilization: str) -> float:
    """The lambda the element stiffness is assembled with under ``nodal_average``: 0 when the
    stabilization's scaling is free of lambda, else lambda (its alpha_K unchanged; module docstring)."""
    return 0.0 if stabilization in LAMBDA_FREE_STABILIZATIONS else float(lam)


@dataclass(frozen=True)
class NodalAverage:
    """The operators of the nodal averaging on one space (module docstring), on the natural dofs
    (dof = d node + component)."""

    divergence: sp.csr_matrix  # D (cells x d n_nodes): div_K(Pi u)
    measures: np.ndarray  # (M,) |K|
    averaging: sp.csr_matrix  # W (vertices x cells): |K| / n_K where vertex a is in K (A = diag(1 / V) W)
    volumes: np.ndarray  # (vertices,) V_a
    cell_vertex_count: np.ndarray  # (M,) n_K

    @classmethod
    def of(cls, space) -> NodalAverage:
        """The operators of ``space`` (a k = 1 space), built once per space."""
        if space not in _NODAL:
            _NODAL[space] = cls.build(space)
        return _NODAL[space]

    @classmethod
    def build(cls, space) -> NodalAverage:
        weights, measures = space.element.divergence_table(space.mesh)
        offsets, nodes = space.cell_nodes
        d, cells = space.element.dimension, offsets.shape[0] - 1
        count = np.diff(offsets)
        columns = (d * np.asarray(nodes, dtype=np.int64)[:, None] + np.arange(d)).ravel()
        rows = np.repeat(np.arange(cells), d * count)
        divergence = sp.csr_matrix((weights, (rows, columns)), shape=(cells, d * space.n_nodes))
        n_vertices = space.mesh.n_vertices
        share = np.repeat(measures / count, count)
        averaging = sp.csr_matrix((share, (nodes, np.repeat(np.arange(cells), count))), shape=(n_vertices, cells))
        volumes = np.bincount(nodes, share, n_vertices)
        return cls(divergence, measures, averaging, volumes, count)

    # -- fields ----------------------------------------------------------------------------
    def cell_divergence(self, node_values) -> np.ndarray:
        """(M,) div_K(Pi u) of the degrees of freedom (n_nodes, d)."""
        return self.divergence @ np.asarray(node_values, dtype=float).ravel()

    def vertex_divergence(self, node_values) -> np.ndarray:
        """(vertices,) theta_a, the averaged volumetric strain at every vertex (0 at a vertex of no cell)."""
        summed = self.averaging @ self.cell_divergence(node_values)
        return np.divide(summed, self.volumes, out=np.zeros_like(summed), where=self.volumes > 0)

    def cell_pressure_strain(self, node_values) -> np.ndarray:
        """(M,) theta_K, the mean of theta_a over the vertices of each cell."""
        theta = self.vertex_divergence(node_values)
        incidence = self.averaging.copy()
        incidence.data[:] = 1.0
        return (incidence.T @ theta) / self.cell_vertex_count

    def cell_energy_change(self, node_values, lam: float, kept: float) -> np.ndarray:
        """(M,) what the nodal averaging adds to a_h^K(u, u) beside the element's energy assembled with
        lambda = ``kept``: lambda (|K| / n_K) sum_{a in K} theta_a^2 (the nodal term split over the
        cells, summing to lambda sum_a V_a theta_a^2) minus kept |K| div_K(Pi u)^2."""
        theta = self.vertex_divergence(node_values)
        nodal = lam * (self.averaging.T @ theta**2)
        return nodal - kept * self.measures * self.cell_divergence(node_values) ** 2

    # -- matrices on the free dofs -----------------------------------------------------------
    def on_free(self, matrix: sp.csr_matrix, dofs) -> sp.csr_matrix:
        """The columns of ``matrix`` (natural dofs) of the free dofs of ``dofs``, in their order."""
        d = dofs.dimension
        natural = (d * np.asarray(dofs.free_nodes, dtype=np.int64)[:, None] + np.arange(d)).ravel()
        return matrix.tocsc()[:, natural].tocsr()

    def stiffness(self, lam: float, dofs) -> sp.csr_matrix:
        """lambda G^T diag(1 / V) G on the free dofs: the nodal volumetric term (symmetric)."""
        scale = np.divide(float(lam), self.volumes, out=np.zeros_like(self.volumes), where=self.volumes > 0)
        G = self.on_free(self.averaging @ self.divergence, dofs)
        return symmetric(G.T @ (sp.diags(scale) @ G))

    def cell_term(self, lam: float, dofs) -> sp.csr_matrix:
        """lambda D^T diag(|K|) D on the free dofs: the cell lambda term of the element stiffness."""
        D = self.on_free(self.divergence, dofs)
        return symmetric(D.T @ (sp.diags(float(lam) * self.measures) @ D))


def symmetric(A) -> sp.csr_matrix:
    """(A + A^T) / 2 as CSR: exactly symmetric (a product G^T S G need not be, in the last bit)."""
    return (0.5 * (A + A.T)).tocsr()


def check_treatment(space, treatment: str) -> None:
    """An InputError naming ``discretization.volumetric_strain`` unless ``treatment`` fits the space."""
    key = "discretization.volumetric_strain"
    if treatment not in TREATMENTS:
        raise InputError(f"{key} = {treatment!r} is unknown; use one of {', '.join(TREATMENTS)}", key=key)
    if treatment == "nodal_average" and space.element.stress_degree != 0:
        raise InputError(
            f"{key} = nodal_average needs a constant strain per cell (k = 1); the {space.element.name} element "
            f"does not lock: use cell",
            key=key,
        )


def stiffness_matrix(space, lam: float, mu: float, stabilization: str, dofs, treatment: str = "cell") -> sp.csr_matrix:
    """The global stiffness on the free dofs of ``dofs`` with the volumetric ``treatment`` (module
    docstring); ``cell`` is ``space.stiffness_matrix`` itself, bit for bit."""
    check_treatment(space, treatment)
    if treatment == "cell":
        return space.stiffness_matrix(lam, mu, stabilization, dofs)
    nodal = NodalAverage.of(space)
    kept = kept_lambda(lam, stabilization)
    K = space.stiffness_matrix(kept, mu, stabilization, dofs)
    if kept:
        K = K - nodal.cell_term(kept, dofs)
    K = (K + nodal.stiffness(lam, dofs)).tocsr()
    K.sort_indices()
    return K


def cell_stress(space, node_values, strain: np.ndarray, lam: float, mu: float, treatment: str = "cell") -> np.ndarray:
    """(M, 3) (3D: (M, 6)) the cell stresses of the formulation from the cell strains of Pi u:
    C eps_K for ``cell``; 2 mu eps_K + lambda theta_K I for ``nodal_average`` (module docstring)."""
    if treatment == "cell":
        return stress(strain, lam, mu)
    sigma = stress(strain, 0.0, mu)
    sigma[:, : space.element.dimension] += lam * NodalAverage.of(space).cell_pressure_strain(node_values)[:, None]
    return sigma
