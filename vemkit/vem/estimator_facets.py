"""The facet terms of the a posteriori indicators (``vemkit.vem.estimator``), any dimension: the
projected stress per cell, the traction σ n, the jumps of the traction across interior facets and the
boundary misfits on Neumann and contact sides (docs/reference/files.md).

A facet F is an edge in 2D and a face in 3D (``vemkit.mesh.interface``); h_F is its diameter (the
edge's length in 2D). The jump term ½ h_F ‖[σ n_F]‖²_F goes to each of the two cells of an interior
facet; a boundary side adds h_F ‖datum − σ_K n_F‖²_F to the cell of each of its facets. The boundary
integrals need a rule along the facets, one per dimension (``BOUNDARY_RESIDUALS``): 3-point Gauss on
edges, the datum interpolated as the space's trace (``EdgeResiduals``); the edge-midpoint rule (exact
for quadratics) on the fan of triangles (face centroid, v_i, v_i+1) of a face, the contact datum
linear on each triangle from the vertex values and their mean at the centroid (``FaceResiduals``).
"""

from __future__ import annotations

import numpy as np

from vemkit.vem.projection import VOIGT_PAIRS, strain_of, stress

GAUSS3 = (np.array([0.5 - np.sqrt(0.15), 0.5, 0.5 + np.sqrt(0.15)]), np.array([5.0, 8.0, 5.0]) / 18.0)

#: dimension d -> [i][j] the Voigt column of σ_ij
VOIGT_COLUMNS = {
    d: [[next(k for k, p in enumerate(pairs) if p in ((i, j), (j, i))) for j in range(d)] for i in range(d)]
    for d, pairs in VOIGT_PAIRS.items()
}


def stress_at(projection, cells, points, lam, mu) -> np.ndarray:
    """(P, V) Voigt components of C ε(Π u) at points, each in the given cell."""
    return stress(strain_of(projection.gradient_at(cells, points)), lam, mu)


class ProjectedStress:
    """σ(Π u_h) per cell: ``constant`` (M, V) Voigt rows when the element's stress is constant per
    cell (k = 1), else evaluated at points from the projection."""

    def __init__(self, space, projection, lam, mu):
        self.projection, self.lam, self.mu = projection, lam, mu
        constant = space.element.stress_degree == 0
        self.constant = stress(projection.cell_mean_strain(), lam, mu) if constant else None

    def at(self, cells, points):
        if self.constant is not None:
            return self.constant[cells]
        return stress_at(self.projection, cells, points, self.lam, self.mu)


def traction(sig: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """σ n for Voigt rows and unit normals (E, d), both (E, ...): (σ n)_i = Σ_j σ_ij n_j in order of j."""
    columns = VOIGT_COLUMNS[normal.shape[-1]]
    rows = []
    for row in columns:
        value = sig[..., row[0]] * normal[..., 0]
        for j in range(1, len(row)):
            value = value + sig[..., row[j]] * normal[..., j]
        rows.append(value)
    return np.stack(rows, axis=-1)


def facet_diameters(mesh) -> np.ndarray:
    """(F,) h_F = diam F, the largest vertex-to-vertex distance of every facet (|e| in 2D)."""
    offsets, ids = mesh.facets
    sizes = np.diff(offsets)
    out = np.zeros(sizes.size)
    for size in np.unique(sizes):
        facets = np.flatnonzero(sizes == size)
        points = mesh.vertices[ids[offsets[facets][:, None] + np.arange(size)]]
        distance = np.sqrt(((points[:, :, None, :] - points[:, None, :, :]) ** 2).sum(axis=-1))
        out[facets] = distance.reshape(facets.size, -1).max(axis=1)
    return out


def jump_terms(mesh, sig: ProjectedStress) -> np.ndarray:
    """½ h_F ‖[σ n_F]‖²_F added to each of the two cells of every interior facet (the jump is
    constant on the facet for a constant stress: no quadrature; else 3-point Gauss along the edge,
    k = 2 being planar)."""
    cells = mesh.facet_cells
    inner = cells[:, 1] >= 0
    c = cells[inner]
    normal = mesh.facet_normals[inner]
    h_size = facet_diameters(mesh)[inner] * mesh.facet_areas[inner]  # h_F |F| (|e|² in 2D)
    if sig.constant is not None:
        jump = traction(sig.constant[c[:, 0]] - sig.constant[c[:, 1]], normal)
        term = 0.5 * h_size * np.sum(jump**2, axis=1)
    else:
        e = mesh.edges[inner]  # k = 2: the facets are edges
        t, w = GAUSS3
        a, b = mesh.vertices[e[:, 0]], mesh.vertices[e[:, 1]]
        term = np.zeros(e.shape[0])
        for tq, wq in zip(t, w):
            p = a + tq * (b - a)
            jump = traction(sig.at(c[:, 0], p) - sig.at(c[:, 1], p), normal)
            term += wq * 0.5 * h_size * np.sum(jump**2, axis=1)
    out = np.zeros(mesh.n_cells)
    np.add.at(out, c[:, 0], term)
    np.add.at(out, c[:, 1], term)
    return out


def sampled(field):
    """datum(points (..., d)) -> (..., d) of a traction field(x, y[, z]) -> its d components."""

    def datum(points, *_):
        values = field(*(points[..., i] for i in range(points.shape[-1])))
        return np.stack(np.broadcast_arrays(*values), axis=-1)

    return datum


def pressed(pressure):
    """datum(points (..., d), _, normal (..., d)) -> the traction −p ν of a normal pressure p(x, y[, z])."""

    def datum(points, _where, normal):
        p = np.broadcast_to(pressure(*(points[..., i] for i in range(points.shape[-1]))), points.shape[:-1])
        return -p[..., None] * normal

    return datum


class EdgeResiduals:
    """d = 2: the misfits on the edges of a side (vertex pairs ``mesh.boundary[side]``), 3-point Gauss."""

    @staticmethod
    def neumann(space, sig, side, field) -> np.ndarray:
        return _edge_terms(space.mesh, sig, space.mesh.boundary[side], sampled(field))

    @staticmethod
    def pressure(space, sig, side, pressure) -> np.ndarray:
        return _edge_terms(space.mesh, sig, space.mesh.boundary[side], pressed(pressure))

    @staticmethod
    def contact(space, sig, side, at_nodes) -> np.ndarray:
        edges = space.mesh.boundary[side]
        return _edge_terms(space.mesh, sig, edges, _trace_along(space, np.asarray(at_nodes), edges))


def _edge_normals(points_a, points_b):
    """Outward unit normals (for a counter-clockwise cell) and lengths of the edges a -> b."""
    d = points_b - points_a
    length = np.linalg.norm(d, axis=1)
    return np.stack([d[:, 1], -d[:, 0]], axis=1) / length[:, None], length


def _boundary_cells(mesh, edges: np.ndarray) -> np.ndarray:
    """The cell of every boundary edge (a, b) (as stored in ``mesh.boundary``)."""
    key = np.minimum(mesh.edges[:, 0], mesh.edges[:, 1]) * mesh.n_vertices + np.maximum(
        mesh.edges[:, 0], mesh.edges[:, 1]
    )
    order = np.argsort(key)
    wanted = np.minimum(edges[:, 0], edges[:, 1]) * mesh.n_vertices + np.maximum(edges[:, 0], edges[:, 1])
    return mesh.edge_cells[order[np.searchsorted(key[order], wanted)], 0]


def _edge_terms(mesh, sig: ProjectedStress, edges: np.ndarray, datum) -> np.ndarray:
    """|e| ∫_e |datum − σ_K n|² per cell, ``datum(points (Q, E, 2), t (Q,), normal (E, 2)) -> (Q, E, 2)``."""
    out = np.zeros(mesh.n_cells)
    if edges.size == 0:
        return out
    cells = _boundary_cells(mesh, edges)
    a, b = mesh.vertices[edges[:, 0]], mesh.vertices[edges[:, 1]]
    normal, length = _edge_normals(a, b)
    t, w = GAUSS3
    points = a[None] + t[:, None, None] * (b - a)[None]
    if sig.constant is not None:
        own = traction(sig.constant[cells], normal)[None]
    else:
        own = np.stack([traction(sig.at(cells, p), normal) for p in points])
    misfit = datum(points, t, normal) - own
    np.add.at(out, cells, length**2 * np.einsum("q,qe->e", w, np.sum(misfit**2, axis=2)))
    return out


def _trace_along(space, at_nodes: np.ndarray, edges: np.ndarray):
    """The datum of values at the trace nodes of ``edges``, interpolated as the space's trace
    (linear between the ends for k = 1)."""
    nodes = space.edge_nodes(edges)
    if space.element.order == 1:  # two trace nodes per edge
        ta, tb = at_nodes[nodes[:, 0]], at_nodes[nodes[:, 1]]

        def datum(_points, t, _normal):
            return ta[None] + t[:, None, None] * (tb - ta)[None]

        return datum
    values = at_nodes[nodes]  # (E, k + 1, 2)

    def datum(_points, t, _normal):
        return np.einsum("qn,enc->qec", space.element.edge_trace(t), values)

    return datum


#: the edge-midpoint rule on a fan triangle (centroid, a, b): barycentric weights of its 3 points
FAN_POINTS = np.array([[0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]])


class FaceResiduals:
    """d = 3: the misfits on the faces of a side (face ids ``mesh.boundaries[side]``), the
    edge-midpoint rule on each face's fan of triangles (module docstring)."""

    @staticmethod
    def neumann(space, sig, side, field) -> np.ndarray:
        datum = sampled(field)
        return _face_terms(space.mesh, sig, space.mesh.boundaries[side], datum)

    @staticmethod
    def pressure(space, sig, side, pressure) -> np.ndarray:
        return _face_terms(space.mesh, sig, space.mesh.boundaries[side], pressed(pressure))

    @staticmethod
    def contact(space, sig, side, at_nodes) -> np.ndarray:
        values = np.asarray(at_nodes, dtype=float)

        def datum(_points, fan, _normal):
            corners = np.stack([fan.centre_mean(values), values[fan.a], values[fan.b]], axis=1)  # (T, 3, d)
            return np.einsum("qk,tkc->qtc", FAN_POINTS, corners)

        return _face_terms(space.mesh, sig, space.mesh.boundaries[side], datum)


class _Fan:
    """The triangles (face centroid, a, b) of the faces ``faces``: ``face`` (T,) position in
    ``faces``, ``a``, ``b`` (T,) vertex ids, ``area`` (T,), ``points`` (3, T, 3) of the rule."""

    def __init__(self, mesh, faces):
        offsets, ids = mesh.facets
        sizes = np.diff(offsets)[faces]
        self.faces, self.sizes = faces, sizes
        self.face = np.repeat(np.arange(faces.size), sizes)
        start = np.repeat(offsets[faces], sizes)
        k = np.arange(self.face.size) - np.repeat(np.cumsum(sizes) - sizes, sizes)
        self.a, self.b = ids[start + k], ids[start + (k + 1) % np.repeat(sizes, sizes)]
        centre = mesh.facet_centroids[faces][self.face]
        pa, pb = mesh.vertices[self.a], mesh.vertices[self.b]
        self.area = 0.5 * np.linalg.norm(np.cross(pa - centre, pb - centre), axis=1)
        self.points = np.einsum("qk,ktc->qtc", FAN_POINTS, np.stack([centre, pa, pb]))

    def centre_mean(self, values):
        """(T, d) the mean of ``values`` over the vertices of each triangle's face."""
        means = np.add.reduceat(values[self.a], np.cumsum(self.sizes) - self.sizes, axis=0) / self.sizes[:, None]
        return means[self.face]


def _face_terms(mesh, sig: ProjectedStress, faces: np.ndarray, datum) -> np.ndarray:
    """h_F ∫_F |datum − σ_K n_F|² per cell, ``datum(points (3, T, 3), fan, normal (T, 3)) -> (3, T, 3)``."""
    out = np.zeros(mesh.n_cells)
    faces = np.asarray(faces, dtype=np.int64)
    if faces.size == 0:
        return out
    owner = mesh.facet_cells[faces]
    outward = owner[:, 0] >= 0
    cells = np.where(outward, owner[:, 0], owner[:, 1])
    normal = np.where(outward[:, None], 1.0, -1.0) * mesh.facet_normals[faces]
    fan = _Fan(mesh, faces)
    tri_cells = cells[fan.face]
    if sig.constant is not None:
        own = traction(sig.constant[tri_cells], normal[fan.face])[None]
    else:
        own = np.stack([traction(sig.at(tri_cells, p), normal[fan.face]) for p in fan.points])
    misfit = datum(fan.points, fan, normal[fan.face]) - own
    integral = np.bincount(fan.face, fan.area * np.sum(misfit**2, axis=2).mean(axis=0), faces.size)
    np.add.at(out, cells, facet_diameters(mesh)[faces] * integral)
    return out


#: dimension -> the boundary misfits along its facets
BOUNDARY_RESIDUALS = {2: EdgeResiduals, 3: FaceResiduals}
