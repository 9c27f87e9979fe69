"""A posteriori error indicators η_K of the VEM solution of the contact problem, for any element (docs/reference/files.md).

Computable from u_h and the data only, in d = 2 or 3 dimensions. With σ_K = C ε(Π u_h) on cell K
(constant for k = 1, so div σ_K = 0; linear for k = 2, div σ_K constant), f_K the cell average of
the body force, and n_F the outward unit normal of facet F (an edge in 2D, a face in 3D; h_F its
diameter, |e| for an edge):

    η_K² = (1 / 2μ) [ h_K² |f_K + div σ_K|² |K|                         volume residual
                    + ½ Σ_{F ⊂ ∂K interior} h_F ‖[σ n_F]‖²_F           jumps of the projected traction
                    + Σ_{F ⊂ ∂K ∩ Γ_F} h_F ‖f2 − σ_K n_F‖²_F           mismatch on Neumann sides (f2 = −p n_F
                                                                      on a side under a normal pressure p)
                    + Σ_{F ⊂ ∂K ∩ Γ_C} h_F ‖t_C − σ_K n_F‖²_F ]        mismatch with the contact traction
           + α_K S_K((I − Π) u_h, (I − Π) u_h)                            the VEM stabilization term (3.9)

where [σ n_F] = (σ_K − σ_K') n_F (constant on an interior facet for k = 1: the closed form; linear
for k = 2: 3-point Gauss, exact), and t_C = −p_ν(u_ν − g) ν + Σ σ_τ,k τ_k is the contact traction
of (2.6)–(2.9) at the contact points (Γ_C vertices; and edge midpoints for k = 2), interpolated
along the facet as the space's trace (σ_τ = −p_τ λ with the friction multiplier λ). The facet terms
and their rules (3-point Gauss on edges, the edge-midpoint rule on a face's fan of triangles) are
``vemkit.vem.estimator_facets``. The
residual terms are those of the residual estimator for the VEM of Beirão da Veiga & Manzini
(IMA J. Numer. Anal. 35, 2015) and Cangiani, Georgoulis, Pryer & Sutton (Numer. Math. 137, 2017),
with the boundary residual of the contact problem taking the contact traction as its Neumann datum
(as for normal compliance in finite elements, e.g. Wohlmuth, Acta Numerica 2011, §6). The factor
1/(2μ) turns the residuals (stress² × length²) into energy, the units of the stabilization term,
so that η² estimates the energy norm a(u − u_h, u − u_h) of the error. The relative estimate is

    η = (Σ_K η_K²)^½ / a_h(u_h, u_h)^½.

The energies per cell come from the element: for the 2D k = 1 element the kernel ``local_energies``
(which pins the consistency part |K| ε:Cε); otherwise a_h^K(u, u) from the element's local stiffness
and the consistency part |K| σ_K:ε_K for a constant strain (k = 1 on polyhedra), ∫_K σ(Π u):ε(Π u)
by a degree-2 rule on the cell's triangles for k = 2 (exact: linear σ).

Imports from vemkit: ``mesh`` and this layer; the caller (``vemkit.studies.adaptivity``) turns the
scene's data and the contact solution into the plain arrays and callables taken here.
"""

from __future__ import annotations

import numba
import numpy as np

from vemkit.mesh.mesh import Mesh
from vemkit.vem.assembly import largest_cell, specialized
from vemkit.vem.elements import stabilization_code
from vemkit.vem.elements.k1_kernel import cell_coordinates, element_stiffness
from vemkit.vem.estimator_facets import BOUNDARY_RESIDUALS, ProjectedStress, jump_terms, stress_at
from vemkit.vem.projection import VOIGT_PAIRS, strain_of, stress
from vemkit.vem.quadrature import reference_quadrature
from vemkit.vem.space import VirtualElementSpace
from vemkit.vem.volumetric import NodalAverage, cell_stress, kept_lambda

ENERGY_CHUNKS = 64  # cell chunks of the parallel energy loops (one workspace each)


@numba.njit(cache=True, parallel=True)
def local_energies(vertices, offsets, cell_vertices, u, lam, mu, stab):
    """Per cell: a_h^K(u, u) (3.9) and its consistency part a_K(Π u, Π u); the difference is the
    stabilization energy α_K S_K((I − Π)u, (I − Π)u). Cells in parallel (each cell's sums as
    before: the same numbers whatever the number of threads)."""
    n_cells = offsets.shape[0] - 1
    total = np.zeros(n_cells)
    consistency = np.zeros(n_cells)
    for c in numba.prange(n_cells):
        s = offsets[c]
        n = offsets[c + 1] - s
        m = 2 * n
        px, py = cell_coordinates(vertices, offsets, cell_vertices, c)
        K = np.empty((m, m))
        B = np.empty((3, m))
        P = np.empty((6, m))
        R = np.empty((m, m))
        area = element_stiffness(px, py, lam, mu, stab, K, B, P, R)
        ue = np.empty(m)
        for i in range(n):
            ue[2 * i] = u[cell_vertices[s + i], 0]
            ue[2 * i + 1] = u[cell_vertices[s + i], 1]
        energy = 0.0
        for i in range(m):
            for j in range(m):
                energy += ue[i] * K[i, j] * ue[j]
        e0 = 0.0
        e1 = 0.0
        e2 = 0.0
        for j in range(m):
            e0 += B[0, j] * ue[j]
            e1 += B[1, j] * ue[j]
            e2 += B[2, j] * ue[j]  # 2 eps12
        total[c] = energy
        consistency[c] = area * ((lam + 2 * mu) * (e0 * e0 + e1 * e1) + 2 * lam * e0 * e1 + mu * e2 * e2)
    return total, consistency


def cell_energies(geometry, offsets, nodes, u, lam, mu, stab, total):
    """*Template* (parallel). total[c] = a_h^K(u, u) (3.9) from the element's local stiffness (its
    ``geometry``, d = DIM components per node); chunks of cells in parallel, one workspace each."""
    n_cells = offsets.shape[0] - 1
    size = largest_cell(offsets)
    for chunk in numba.prange(ENERGY_CHUNKS):
        work = workspace(size)  # noqa: F821 (bound by ``specialized``)
        for c in range(chunk * n_cells // ENERGY_CHUNKS, (chunk + 1) * n_cells // ENERGY_CHUNKS):
            K = cell_matrix(c, geometry, offsets, nodes, lam, mu, stab, work)  # noqa: F821
            start = offsets[c]
            m = DIM * (offsets[c + 1] - start)  # noqa: F821
            energy = 0.0
            for i in range(m):
                ui = u[nodes[start + i // DIM], i % DIM]  # noqa: F821
                for j in range(m):
                    energy += ui * K[i, j] * u[nodes[start + j // DIM], j % DIM]  # noqa: F821
            total[c] = energy


#: element name -> its closed-form energy kernel (exact products; the 2D k = 1 element)
ENERGY_KERNELS = {"k1": local_energies}


def space_energies(space: VirtualElementSpace, u_nodes, lam: float, mu: float, stabilization: str, projection):
    """(a_h^K(u, u), a_K(Π u, Π u)) per cell, for any element (module docstring)."""
    mesh, element = space.mesh, space.element
    u = np.ascontiguousarray(u_nodes, dtype=float).reshape(-1, element.dimension)
    if element.name in ENERGY_KERNELS:
        return ENERGY_KERNELS[element.name](
            mesh.vertices, mesh.cell_offsets, mesh.cell_vertices, u, lam, mu, stabilization_code(stabilization)
        )
    offsets, nodes = space.cell_nodes
    total = np.zeros(mesh.n_cells)
    specialized(cell_energies, element, parallel=True)(
        element.geometry(mesh), offsets, nodes, u, float(lam), float(mu), stabilization_code(stabilization), total
    )
    return total, consistency_energies(space, projection, lam, mu)


#: the number of Voigt components -> their (i, j)
PAIRS_OF_WIDTH = {len(pairs): pairs for pairs in VOIGT_PAIRS.values()}


def energy_density(sig: np.ndarray, strain: np.ndarray) -> np.ndarray:
    """σ : ε from Voigt rows (the shear components count twice), summed in Voigt order."""
    pairs = PAIRS_OF_WIDTH[strain.shape[1]]
    density = sig[:, 0] * strain[:, 0]
    for k in range(1, len(pairs)):
        i, j = pairs[k]
        density = density + (sig[:, k] * strain[:, k] if i == j else 2.0 * sig[:, k] * strain[:, k])
    return density


def consistency_energies(space: VirtualElementSpace, projection, lam: float, mu: float) -> np.ndarray:
    """(M,) a_K(Π u, Π u) = ∫_K σ(Π u) : ε(Π u): |K| σ_K : ε_K for a constant strain, else a degree-2
    rule on the cell's triangles (exact: linear σ, k = 2)."""
    mesh = space.mesh
    if space.element.stress_degree == 0:
        strain = projection.cell_mean_strain()
        return mesh.cell_volumes * energy_density(stress(strain, lam, mu), strain)
    points, weights, cells = reference_quadrature(mesh, degree=2)
    strain = strain_of(projection.gradient_at(cells, points))
    return np.bincount(cells, weights * energy_density(stress(strain, lam, mu), strain), mesh.n_cells)


def stress_divergence(projection, mesh: Mesh, lam: float, mu: float) -> np.ndarray:
    """(M, 2) div σ(Π u) per cell for a linear σ (k = 2): central differences of σ about the cell
    centre, exact for a linear field."""
    cells = np.arange(mesh.n_cells)
    centre = np.add.reduceat(mesh.vertices[mesh.cell_vertices], mesh.cell_offsets[:-1]) / mesh.cell_sizes[:, None]
    step = np.sqrt(np.abs(mesh.cell_areas))[:, None]
    d = {}
    for axis in (0, 1):
        shift = np.zeros_like(centre)
        shift[:, axis] = step[:, 0]
        d[axis] = (
            stress_at(projection, cells, centre + shift, lam, mu)
            - stress_at(projection, cells, centre - shift, lam, mu)
        ) / (2.0 * step)
    return np.stack([d[0][:, 0] + d[1][:, 2], d[0][:, 2] + d[1][:, 1]], axis=1)


def error_indicators(
    space,
    u_nodes,
    lam: float,
    mu: float,
    stabilization: str,
    *,
    body_force=None,
    neumann=None,
    pressure=None,
    contact=None,
    volumetric_strain: str = "cell",
) -> dict:
    """η_K² by term and in total, and the relative estimate η (module docstring).

    space: a :class:`~vemkit.vem.space.VirtualElementSpace` (or a mesh of either dimension: k = 1); u_nodes its
    degrees of freedom (n_nodes, d). body_force: (M, d) cell averages f_K or None; neumann: {side:
    traction(x, y[, z]) -> its d components}; pressure: {side: p(x, y[, z])}, the
    Neumann datum −p ν of a normal pressure; contact: {side: (n_nodes, d) contact traction t_C at
    every node (only Γ_C contact points are read)}. Returns {"indicator" (M,) η_K, "volume", "jump", "neumann",
    "contact", "stabilization" (M,) the squared terms, "estimate" η, "energy" a_h(u_h, u_h)}.
    volumetric_strain: the stiffness's treatment of λ (``vemkit.vem.volumetric``): with
    ``nodal_average`` σ_K = 2μ ε_K + λ θ_K I and a_h^K holds the cell's share of the nodal term.
    """
    space = space if isinstance(space, VirtualElementSpace) else VirtualElementSpace(space, 1)
    mesh = space.mesh
    u = np.ascontiguousarray(u_nodes, dtype=float).reshape(space.n_nodes, space.element.dimension)
    projection = space.project(u, lam, mu)
    sig = ProjectedStress(space, projection, lam, mu)
    if volumetric_strain == "cell":
        total, consistency = space_energies(space, u, lam, mu, stabilization, projection)
    else:  # the formulation's stress and energies (vemkit.vem.volumetric)
        sig.constant = cell_stress(space, u, projection.cell_mean_strain(), lam, mu, volumetric_strain)
        kept = kept_lambda(lam, stabilization)
        total, consistency = space_energies(space, u, kept, mu, stabilization, projection)
        change = NodalAverage.of(space).cell_energy_change(u, lam, kept)
        total, consistency = total + change, consistency + change
    terms = {
        "volume": _volume_terms(mesh, sig, body_force),
        "jump": jump_terms(mesh, sig),
        "neumann": np.zeros(mesh.n_cells),
        "contact": np.zeros(mesh.n_cells),
    }
    facets = BOUNDARY_RESIDUALS[mesh.dimension]
    for side, traction in (neumann or {}).items():
        terms["neumann"] += facets.neumann(space, sig, side, traction)
    for side, p in (pressure or {}).items():
        terms["neumann"] += facets.pressure(space, sig, side, p)
    for side, at_nodes in (contact or {}).items():
        terms["contact"] += facets.contact(space, sig, side, at_nodes)
    residual = sum(terms.values()) / (2.0 * mu)
    terms["stabilization"] = np.maximum(total - consistency, 0.0)
    squared = residual + terms["stabilization"]
    energy = float(total.sum())
    return {
        "indicator": np.sqrt(squared),
        **terms,
        "estimate": float(np.sqrt(squared.sum() / energy)) if energy > 0 else 0.0,
        "energy": energy,
    }


def _volume_terms(mesh, sig: ProjectedStress, body_force) -> np.ndarray:
    """h_K² |f_K + div σ_K|² |K| (div σ_K = 0 for a constant stress)."""
    residual = None if body_force is None else np.asarray(body_force, dtype=float)
    if sig.constant is None:
        divergence = stress_divergence(sig.projection, mesh, sig.lam, sig.mu)
        residual = divergence if residual is None else residual + divergence
    if residual is None:
        return np.zeros(mesh.n_cells)
    return mesh.cell_diameters**2 * np.sum(residual**2, axis=1) * mesh.cell_volumes


def dorfler_marking(indicator: np.ndarray, theta: float) -> np.ndarray:
    """The fewest cells (largest η_K first) with Σ_marked η_K² ≥ θ Σ η_K² (Dörfler 1996)."""
    squared = np.asarray(indicator, float) ** 2
    order = np.argsort(-squared, kind="stable")
    cumulative = np.cumsum(squared[order])
    count = int(np.searchsorted(cumulative, theta * cumulative[-1] * (1 - 1e-12))) + 1 if cumulative.size else 0
    return np.sort(order[:count])
