"""The discrete contact boundary: Gamma_C contact points with their quadrature weights, normals and gaps.

One contact boundary for every element and both dimensions, built from the space's trace on Gamma_C
through the rule of its facets (``vemkit.contact.rules``: edges in 2D, faces in 3D; the contact
points, nodal weights, normals, tangent frames and the facets of the ``gauss`` rule). Clamped points
and points with every component prescribed are dropped: they belong to the closure of Gamma_D, and
their displacement is given. A point with only some components prescribed (a symmetry roller meeting
Gamma_C) stays, with either rule: its prescribed components are fixed dofs (``vemkit.vem.dofs``:
decoupled rows K_ii u_i = K_ii g_i, so u_i = g_i is what the law reads), no contact force or Jacobian
entry goes into their rows (the constraint's reaction takes it), and the free components carry the
law. (Until issue 21's 3D Gauss rule the ``gauss`` rule dropped such a point and read u = 0 in its
free components: wrong wherever a roller met Gamma_C.)
``ContactBoundary.vertices`` holds node numbers of the space: a mesh vertex v, or n_vertices + e for the
midpoint of edge e (k = 2). One class for d = 2 and 3: dofs, normals and coordinates are (n_c, d);
tangential quantities are (n_c, d - 1): their components along the tangent basis ``tangents``
(``tangent`` = tau in 2D; ``tangent`` = t1 and ``tangent2`` = t2 in 3D), the friction multiplier in
the unit ball of R^(d-1) (``vemkit.contact.ball``: [-1, 1] in 2D, the unit disk in 3D).

``gauss`` quadrature (``contact_gauss_points`` N per facet; for an element with linear traces,
k = 1): the normal-compliance term of (3.16),

    int_{Gamma_C} p_nu(u_nu - g) v_nu ds  =  sum_f sum_q |f| w_q p_nu(t_fq) sum_a phi_a(x_q) v_a . nu_f,

with t = u_h . nu_f - g interpolated from the facet's vertices by the interpolants ``gauss_shape``
(on an edge the two hat functions, linear along it; on a face the linear interpolant of its triangle
fan), nu_f the facet normal (the normal of a straight edge is also the vertex normal of the nodal
rule on straight parts), and the Gauss points x_q, weights w_q of ``vemkit.contact.rules``. A
dropped vertex keeps its prescribed displacement and its own gap. Its consistent linearization is
sum_q |f| w_q p_nu'(t_fq) phi_a phi_b nu_f nu_f^T, coupling the vertices of a facet (no longer
one block per vertex). On a constant penetration along a facet both rules give the same force.

The friction term keeps its nodal multiplier in both cases: sum_c w_c p_tau(u_nu,c - g_c)
lambda_c tau_c. The multiplier lambda lives at the vertices, |lambda_c| <= 1 is a projection vertex
by vertex, the Uzawa update (5.5) lambda_c <- P(lambda_c + rho k_tau u_tau,c) is vertex-wise, and
the semismooth Newton complementarity function is vertex-wise too; a Gauss-point multiplier
would need its own space and an inf-sup compatible pairing with u_tau, which the paper's
discretization does not have.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp

from vemkit.contact import ball
from vemkit.contact.gaps import FoundationLine, _facet_gaps, _gap_values  # noqa: F401 (FoundationLine re-exported)
from vemkit.contact.rules import FACET_RULES
from vemkit.exceptions import InputError, SceneError

QUADRATURES = ("nodal", "gauss")


def rank_one_blocks(cb, values, left, n, right=None):
    """Sparse sum_c values_c left_c right_c^T on the contact dofs (right = left if not given), d x d
    blocks; the rows and columns of prescribed components (``cb.fixed``) are left out."""
    right = left if right is None else right
    d = cb.dofs.shape[1]
    if cb.fixed is not None:
        left, right = np.where(cb.fixed, 0.0, left), np.where(cb.fixed, 0.0, right)
    pairs = [(i, j) for i in range(d) for j in range(d)]
    rows = np.stack([cb.dofs[:, i] for i, _ in pairs], axis=1).ravel()
    cols = np.stack([cb.dofs[:, j] for _, j in pairs], axis=1).ravel()
    vals = (values[:, None] * np.stack([left[:, i] * right[:, j] for i, j in pairs], axis=1)).ravel()
    return sp.csr_matrix((vals, (rows, cols)), shape=(n, n))


@dataclass(frozen=True)
class ContactBoundary:
    vertices: np.ndarray  # (n_c,) mesh vertex indices
    dofs: np.ndarray  # (n_c, 2) free-dof indices of (u1, u2)
    weight: np.ndarray  # (n_c,) nodal quadrature weights
    normal: np.ndarray  # (n_c, 2) unit outward normals nu
    tangent: np.ndarray  # (n_c, 2) unit tangents tau
    gap: np.ndarray  # (n_c,) initial gap g_a >= 0
    coords: np.ndarray  # (n_c, 2) vertex coordinates
    quadrature: str = "nodal"  # of the normal-compliance term: nodal or gauss
    # the Gamma_C facets (edges in 2D, faces in 3D) of the gauss rule, m = the most vertices of a facet:
    # (n_f, m) contact-point index of every facet vertex, -1 at a dropped vertex and at padding
    facet_vertex: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64))
    facet_normal: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))  # (n_f, d) unit outward normals
    facet_gap: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))  # (n_f, m) gap at the facet vertices
    facet_coords: np.ndarray = field(default_factory=lambda: np.zeros((0, 2, 2)))  # (n_f, m, d)
    # (n_f, m) prescribed u . nu_f at dropped (Dirichlet) facet vertices, 0 at contact points and padding
    facet_prescribed: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    gauss_weight: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))  # (n_f, n_q) |f| w_q (0: padding)
    # (n_f, n_q, m) the interpolant of each facet vertex's value at the Gauss points (rows sum to 1)
    gauss_shape: np.ndarray = field(default_factory=lambda: np.zeros((0, 0, 2)))
    # 3D: (n_c, 3) the second tangent t2 = nu x t1 (``tangent`` holds t1); (0, 2) in 2D
    tangent2: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    # (n_c, d) bool: components with Dirichlet data (a roller meeting Gamma_C); None: none. No contact
    # force enters their rows (the constraint takes it), and u there is the prescribed value
    fixed: np.ndarray | None = None

    def __post_init__(self):
        if self.quadrature not in QUADRATURES:
            raise SceneError(
                f"discretization.contact_quadrature = {self.quadrature!r}: use nodal or gauss",
                key="discretization.contact_quadrature",
            )
        if self.quadrature == "gauss":
            free = self.facet_vertex >= 0
            if not np.array_equal(self.facet_gap[free], self.gap[self.facet_vertex[free]]):
                raise InputError(
                    "the contact gap changed but not the gap at the Gamma_C facet vertices of the gauss "
                    "quadrature: use ContactBoundary.with_gap",
                    key="contact.gap",
                )

    @property
    def size(self) -> int:
        return self.vertices.size

    @property
    def dimension(self) -> int:
        return self.normal.shape[1]

    @property
    def ball(self) -> ball.Disk:
        """The unit ball of R^(d-1) the friction multiplier lives in (``vemkit.contact.ball``)."""
        return ball.BALLS[self.dimension - 1]

    @property
    def tangents(self) -> list:
        """The tangent basis per point, d - 1 vectors (n_c, d): [tau] in 2D, [t1, t2] in 3D."""
        return [self.tangent, self.tangent2][: self.dimension - 1]

    def _along(self, u, direction):
        """sum_i u[dofs_i] direction_i per contact point."""
        return sum(u[self.dofs[:, i]] * direction[:, i] for i in range(self.dofs.shape[1]))

    def normal_displacement(self, u):
        """u_nu at the contact vertices from the free-dof vector u."""
        return self._along(u, self.normal)

    def tangential_displacement(self, u):
        """u_tau at the contact vertices, (n_c, d - 1): its components along the tangent basis."""
        return np.stack([self._along(u, t) for t in self.tangents], axis=1)

    def scatter(self, normal_part, tangential_part, n_dofs):
        """Free-dof vector of sum_c (normal_part_c nu_c + tangential_part_c . (t1, t2)_c); nothing
        into the prescribed components. ``tangential_part``: (n_c, d - 1)."""
        out = np.zeros(n_dofs)
        tangential_part = self.tangential(tangential_part)
        for i in range(self.dofs.shape[1]):
            value = normal_part * self.normal[:, i]
            for k, t in enumerate(self.tangents):
                value = value + tangential_part[:, k] * t[:, i]
            if self.fixed is not None:
                value = np.where(self.fixed[:, i], 0.0, value)
            np.add.at(out, self.dofs[:, i], value)
        return out

    # -- tangential quantities: (n_c, d - 1), the multiplier in the unit ball (vemkit.contact.ball) --------
    def zero_multiplier(self) -> np.ndarray:
        return np.zeros((self.size, self.dimension - 1))

    def tangential(self, values) -> np.ndarray:
        """``values`` as tangential quantities (n, d - 1): one row per point (a 2D one given as (n,)
        gets its column); InputError if a row does not have d - 1 components."""
        values = np.asarray(values, dtype=float)
        values = values.reshape(values.shape[0], -1) if values.size else values.reshape(0, self.dimension - 1)
        if values.shape[1] != self.dimension - 1:
            raise InputError(
                f"tangential quantities of a {self.dimension}D contact boundary have {self.dimension - 1} "
                f"component(s) per point, not {values.shape[1]}",
                key="multiplier",
            )
        return values

    def project(self, lam) -> np.ndarray:
        """P: the projection onto the unit ball of R^(d-1), point by point (5.5)."""
        return ball.project(self.tangential(lam))

    def magnitude(self, tangential) -> np.ndarray:
        """|x| of tangential quantities (``vemkit.contact.ball.norm``)."""
        return ball.norm(self.tangential(tangential))

    def direction(self, tangential) -> np.ndarray:
        """x / |x| (0 where x = 0)."""
        return ball.direction(self.tangential(tangential))

    def dot(self, a, b) -> np.ndarray:
        """a_c . b_c of two tangential quantities."""
        return ball.dot(self.tangential(a), self.tangential(b))

    def times(self, scalar, tangential) -> np.ndarray:
        """scalar_c x_c for tangential quantities x."""
        return ball.times(scalar, self.tangential(tangential))

    def with_gap(self, gap) -> "ContactBoundary":
        """This boundary with another gap, gap(x, y) -> array or a FoundationLine (at the vertices and
        the dropped edge ends)."""
        g = _gap_values(gap, self.coords, self.normal)
        facet_gap = _facet_gaps(gap, self.facet_coords, self.facet_vertex, g, self.facet_normal)
        return replace(self, gap=g, facet_gap=facet_gap)

    # -- the normal-compliance term and its linearization (nodal or gauss) ----------------------------
    def contact_force(self, u, law, multiplier):
        """Free-dof vector of the contact forces: the normal-compliance term plus the nodal friction term."""
        penetration = self.normal_displacement(u) - self.gap
        tangential = self.times(self.weight * law.friction_bound(penetration), multiplier)
        if self.quadrature == "nodal":
            return self.scatter(self.weight * law.normal_pressure(penetration), tangential, u.size)
        return self.normal_force(u, law) + self.scatter(np.zeros(self.size), tangential, u.size)

    def normal_force(self, u, law):
        """Free-dof vector of int p_nu(u_nu - g) phi_i nu ds (the normal-compliance term of (3.16))."""
        if self.quadrature == "nodal":
            t = self.normal_displacement(u) - self.gap
            return self.scatter(self.weight * law.normal_pressure(t), self.zero_multiplier(), u.size)
        t = self._gauss_penetration(u)
        vertex_force = np.einsum("fq,fqa->fa", self.gauss_weight * law.normal_pressure(t), self.gauss_shape)
        values = vertex_force[:, :, None] * self.facet_normal[:, None, :]  # (n_f, vertex, component)
        return self._assemble_vector(values, u.size)

    def normal_energy(self, u, law) -> float:
        """int P_nu(u_nu - g) ds, P_nu' = p_nu (the normal-compliance part of the energy)."""
        if self.quadrature == "nodal":
            return self.weight @ law.normal_energy(self.normal_displacement(u) - self.gap)
        return float(np.sum(self.gauss_weight * law.normal_energy(self._gauss_penetration(u))))

    def normal_jacobian(self, u, law, cap=np.inf):
        """d(normal_force)/du; p_nu' capped at ``cap`` (per contact vertex, or a number) for m_nu < 1."""
        if self.quadrature == "nodal":
            t = self.normal_displacement(u) - self.gap
            return rank_one_blocks(self, self.weight * np.minimum(law.normal_stiffness(t), cap), self.normal, u.size)
        slope = np.minimum(law.normal_stiffness(self._gauss_penetration(u)), self._facet_cap(cap)[:, None])
        phi = self.gauss_shape
        ends = np.einsum("fq,fqa,fqb->fab", self.gauss_weight * slope, phi, phi)  # (n_f, m, m)
        nn = self.facet_normal[:, :, None] * self.facet_normal[:, None, :]  # (n_f, d, d)
        values = ends[:, :, None, :, None] * nn[:, None, :, None, :]  # (n_f, a, i, b, j)
        dofs = self._facet_dofs(u.size, held_out=True)  # (n_f, m, d), dropped vertices -> u.size
        rows = np.broadcast_to(dofs[:, :, :, None, None], values.shape).ravel()
        cols = np.broadcast_to(dofs[:, None, None, :, :], values.shape).ravel()
        keep = (rows < u.size) & (cols < u.size)
        return sp.csr_matrix((values.ravel()[keep], (rows[keep], cols[keep])), shape=(u.size, u.size))

    def _facet_dofs(self, n_dofs, held_out=False):
        """(n_f, m, d) free dofs of the facet vertices; dropped ones point at n_dofs (a dummy slot), and
        with ``held_out`` the prescribed components too (no contact force or Jacobian entry there)."""
        dofs = self.dofs if self.fixed is None or not held_out else np.where(self.fixed, n_dofs, self.dofs)
        padded = np.vstack([dofs, np.full((1, self.dofs.shape[1]), n_dofs)])
        return padded[self.facet_vertex]  # -1 (dropped, padding) indexes the dummy row

    def _gauss_penetration(self, u):
        """(n_f, n_q) u_nu - g at the Gauss points, interpolated from the facet vertices."""
        u_padded = np.append(u, 0.0)
        vertex_u = u_padded[self._facet_dofs(u.size)]  # (n_f, m, d); u = 0 at dropped vertices
        vertex_t = np.einsum("fai,fi->fa", vertex_u, self.facet_normal) + self.facet_prescribed - self.facet_gap
        return np.einsum("fqa,fa->fq", self.gauss_shape, vertex_t)

    def _facet_cap(self, cap):
        """(n_f,) the smallest cap of the contact points of each facet."""
        cap = np.broadcast_to(np.asarray(cap, dtype=float), (self.size,))
        return np.min(np.append(cap, np.inf)[self.facet_vertex], axis=1)

    def _assemble_vector(self, values, n_dofs):
        dofs = self._facet_dofs(n_dofs, held_out=True)
        return np.bincount(dofs.ravel(), weights=values.ravel(), minlength=n_dofs + 1)[:n_dofs]


def check_quadrature(space, quadrature: str) -> None:
    """SceneError unless the quadrature is known and suits the element: ``gauss`` needs linear traces
    (no edge nodes, k = 1)."""
    if quadrature not in QUADRATURES:
        raise SceneError(
            f"discretization.contact_quadrature = {quadrature!r}: use nodal or gauss",
            key="discretization.contact_quadrature",
        )
    if quadrature == "gauss" and space.element.layout.get("edge", 0):
        raise SceneError(
            f"discretization.contact_quadrature = {quadrature!r} is not available with "
            f"discretization.order = {space.order} (Simpson's rule at the Gamma_C vertices and edge "
            "midpoints is used); set contact_quadrature: nodal",
            key="discretization.contact_quadrature",
        )


def fixed_components(dofs, point_dofs: np.ndarray) -> np.ndarray | None:
    """(n_c, d) bool: the contact dofs that are fixed dofs (a prescribed component); None if none."""
    fixed = np.isin(point_dofs, dofs.fixed_dofs)
    return fixed if fixed.any() else None


def contact_boundary(space, parts, dofs, gap, quadrature: str = "nodal", gauss_points: int = 3) -> ContactBoundary:
    """The contact points of the named boundary ``parts`` of ``space`` (module docstring), by the rule
    of its Gamma_C facets (``vemkit.contact.rules``); ``dofs`` must already carry the change of
    variables of the midpoints (``trace_nodes.midpoint_change``). gap(x, ...) -> array, or a
    FoundationLine."""
    check_quadrature(space, quadrature)
    rule = FACET_RULES[space.mesh.dimension]
    nodes, weight, normal, coords = rule.points(space, parts, dofs)
    tangents = rule.tangents(normal)
    d = normal.shape[1]
    point_dofs = (d * dofs.free_index[nodes][:, None] + np.arange(d)[None, :]).reshape(-1, d)
    cb = ContactBoundary(
        nodes,
        point_dofs,
        weight,
        normal,
        tangents[0],
        _gap_values(gap, coords, normal),
        coords,
        quadrature,
        fixed=fixed_components(dofs, point_dofs),
        **dict(zip(("tangent2",), tangents[1:])),
    )
    if quadrature == "nodal":
        return cb
    facet_nodes, facet_normal, gauss_weight, gauss_shape = rule.gauss(space, parts, gauss_points)
    return with_facets(cb, space.mesh, facet_nodes, facet_normal, dofs, gap, gauss_weight, gauss_shape)


def normals_in_roller_planes(cb: ContactBoundary, gap) -> ContactBoundary:
    """``cb`` with the normal of every vertex that has prescribed components (a symmetry roller, e.g.
    u1 = 0 on the plane x = 0) put into the roller's plane: those components of nu set to zero,
    renormalized, the tangent basis and the gap (``gap``: a callable or FoundationLine) rebuilt.

    The area-weighted normal of a vertex on x = 0 sees the Gamma_C faces on one side only and tilts
    out of the plane, while the whole symmetric body's normal lies in it; with the roller a stick
    vertex is then pinned and a sliding one cannot follow its slip direction (the held component's
    friction force is the constraint's), so ssn's slip-direction test stalls (measured: 4e-4 on the
    Hertz half sphere). Only for rollers on symmetry planes: a vertex held for another reason keeps
    the normal of its faces when this is not called."""
    if cb.fixed is None or not np.any(cb.fixed):
        return cb
    normal = np.where(cb.fixed, 0.0, cb.normal)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    tangents = FACET_RULES[cb.dimension].tangents(normal)
    return replace(cb, normal=normal, tangent=tangents[0], **dict(zip(("tangent2",), tangents[1:]))).with_gap(gap)


def with_facets(cb: ContactBoundary, mesh, facet_nodes, facet_normal, dofs, gap, gauss_weight, gauss_shape):
    """The boundary with the Gamma_C facets (n_f, m) mesh vertices each (a short facet padded with
    its first vertex and zero shape), their unit normals, and the rule's |f| w_q and interpolants."""
    contact_index = np.full(mesh.n_vertices, -1, dtype=np.int64)
    contact_index[cb.vertices] = np.arange(cb.vertices.size)
    facet_vertex = contact_index[facet_nodes]
    coords = mesh.vertices[facet_nodes]
    prescribed = np.einsum("fai,fi->fa", dofs.prescribed_displacement()[facet_nodes], facet_normal)
    return replace(
        cb,
        facet_vertex=facet_vertex,
        facet_normal=facet_normal,
        facet_gap=_facet_gaps(gap, coords, facet_vertex, cb.gap, facet_normal),
        facet_coords=coords,
        facet_prescribed=np.where(facet_vertex >= 0, 0.0, prescribed),
        gauss_weight=gauss_weight,
        gauss_shape=gauss_shape,
    )
