"""The a posteriori indicators in 3D (``vemkit.vem.estimator`` with the k = 1 element on polyhedra,
issue 36 item 1): reliable and efficient on a smooth manufactured solution (η converges like the exact
energy error, the effectivity stays in a band), zero for a linear field (the patch test), and on a
contact scene the contact term lives on Γ_C and peaks at the edges of the contact zone."""

import numpy as np
import pytest
import scipy.sparse.linalg as spla
import sympy
from test_k1_3d_convergence import LAM, MU, STAB, X, manufactured, solve

from vemkit.config.scene import scene_from_dict
from vemkit.mesh.families3d.build import build_mesh3d
from vemkit.studies.adaptivity import contact_tractions
from vemkit.studies.scene_solve import solve_scene
from vemkit.vem.assembly import dirichlet_lift
from vemkit.vem.elements.k1_3d_fields import cell_quadrature
from vemkit.vem.estimator import error_indicators
from vemkit.vem.space import VirtualElementSpace

CUBE = {"box": [[0, 0, 0], [1, 1, 1]]}
SQUARE_PRISM = {
    "polygon": [[0, 0], [1, 0], [1, 1], [0, 1]],
    "sides": ["bottom", "right", "top", "left"],
    "extrude": {"depth": 1.0, "ends": ["front", "back"]},
}
#: family -> (domain, mesh family, its sizes n)
BODIES = {
    "hex": (CUBE, "hex", (2, 4, 8)),
    "tet": (CUBE, "tet", (2, 4, 8)),
    "octree": (CUBE, "octree", (2, 4, 8)),
    "voronoi": (CUBE, "voronoi", (2, 4, 8)),
    "extruded": (SQUARE_PRISM, "voronoi", (2, 4, 8)),
}


def energy_error(space, u) -> float:
    """a(u − Π u_h, u − Π u_h)^½ by the cells' tetrahedral-fan quadrature."""
    _, grad, _ = manufactured()
    x, w, cells = cell_quadrature(space.mesh, 3)
    g = np.moveaxis(grad(*x.T), -1, 0) - space.project(u, LAM, MU).gradient_at(cells, x)
    eps = 0.5 * (g + np.transpose(g, (0, 2, 1)))
    density = LAM * np.trace(eps, axis1=1, axis2=2) ** 2 + 2 * MU * np.sum(eps**2, axis=(1, 2))
    return float(np.sqrt(w @ density))


def cell_body_force(mesh) -> np.ndarray:
    """(M, 3) the cell averages f_K of the manufactured body force."""
    _, _, force = manufactured()
    x, w, cells = cell_quadrature(mesh, 3)
    f = force(*x.T).T
    volume = np.bincount(cells, w, mesh.n_cells)
    return np.stack([np.bincount(cells, w * f[:, i], mesh.n_cells) for i in range(3)], axis=1) / volume[:, None]


def effectivities(body):
    """(h, η, ‖e‖_a) on the body's three meshes."""
    domain, family, sizes = BODIES[body]
    rows = []
    for n in sizes:
        mesh = build_mesh3d(family, domain, n=n)
        space, u = solve(mesh)
        found = error_indicators(space, u, LAM, MU, STAB, body_force=cell_body_force(mesh))
        rows.append((mesh.h, float(np.sqrt(np.sum(found["indicator"] ** 2))), energy_error(space, u)))
    return np.array(rows)


@pytest.mark.parametrize("body", ["hex", "tet"])
def test_the_estimate_converges_like_the_energy_error(body):
    """η and the exact energy error both go like h (rate ~ 1), their ratio stays in a narrow band."""
    h, eta, error = effectivities(body).T
    print(body, "h", h, "eta", eta, "error", error, "effectivity", eta / error)
    rate = lambda e: np.log(e[0] / e[-1]) / np.log(h[0] / h[-1])  # noqa: E731
    assert 0.85 <= rate(error) <= 1.15 and 0.85 <= rate(eta) <= 1.15
    assert abs(rate(eta) - rate(error)) < 0.1
    assert np.all((eta / error > 1.0) & (eta / error < 10.0))
    assert (eta / error).max() / (eta / error).min() < 1.2


@pytest.mark.parametrize("body", ["octree", "voronoi", "extruded"])
def test_the_effectivity_is_bounded_on_the_other_families(body):
    h, eta, error = effectivities(body).T
    print(body, "h", h, "eta", eta, "error", error, "effectivity", eta / error)
    assert np.all((eta / error > 1.0) & (eta / error < 10.0))
    assert (eta / error).max() / (eta / error).min() < 1.3
    assert eta[-1] < 0.6 * eta[0]  # h falls by 4 (prisms: the base's sizes)


#: the manufactured solution's traction sides (outward normals) in ``test_neumann_faces_...``
TRACTION_SIDES = {"right": (1, 0, 0), "top": (0, 0, 1)}


def exact_tractions():
    """{side: σ(u) n} of the manufactured u on ``TRACTION_SIDES``, functions of (x, y, z)."""
    u = sympy.Matrix(manufactured_expressions())
    grad = u.jacobian(X)
    eps = (grad + grad.T) / 2
    sigma = LAM * eps.trace() * sympy.eye(3) + 2 * MU * eps

    def field(normal):
        t = sympy.lambdify(X, list(sigma * sympy.Matrix(normal)), "numpy")
        return lambda a, b, c: tuple(np.broadcast_to(v, np.shape(a)) for v in t(a, b, c))

    return {side: field(normal) for side, normal in TRACTION_SIDES.items()}


def manufactured_expressions():
    """The u of ``test_k1_3d_convergence.manufactured`` as sympy expressions."""
    x, y, z = X
    return [sympy.sin(2 * x + y) * sympy.cos(z), sympy.exp(x - z) * y, sympy.cos(x * y) + z * z]


def solve_with_tractions(mesh, tractions):
    """u_h of the manufactured problem, u held on the sides without a traction."""
    u_exact, _, force = manufactured()
    space = VirtualElementSpace(mesh, 1)
    exact = space.interpolate(lambda x, y, z: tuple(u_exact(x, y, z)))
    held = [side for side in mesh.boundaries if side not in tractions]
    clamped = np.zeros(space.n_nodes, dtype=bool)
    clamped[np.concatenate([mesh.face_vertex_ids(mesh.boundaries[side]) for side in held])] = True
    dofs = space.numbering(clamped)
    load = space.body_force_load(lambda x, y, z: tuple(force(x, y, z)), LAM, MU)
    for side, traction in tractions.items():
        load = load + space.traction_load(mesh.boundaries[side], traction)
    rhs = dofs.restrict(load) + dirichlet_lift(space, LAM, MU, STAB, dofs, exact)
    u = spla.spsolve(space.stiffness_matrix(LAM, MU, STAB, dofs).tocsc(), rhs)
    return space, dofs.node_values(u, clamped_values=np.where(clamped[:, None], exact, 0.0))


@pytest.mark.parametrize("body", ["hex", "voronoi"])
def test_neumann_faces_keep_the_effectivity_in_the_band(body):
    """Tractions σ(u) n on two sides: their misfit h_F ‖g − σ_h n‖² converges (faster than η) and
    the effectivity stays where it is with u held everywhere."""
    tractions = exact_tractions()
    rows = []
    for n in BODIES[body][2]:
        mesh = build_mesh3d(BODIES[body][1], CUBE, n=n)
        space, u = solve_with_tractions(mesh, tractions)
        found = error_indicators(space, u, LAM, MU, STAB, body_force=cell_body_force(mesh), neumann=tractions)
        eta = float(np.sqrt(np.sum(found["indicator"] ** 2)))
        rows.append((eta, energy_error(space, u), float(np.sqrt(found["neumann"].sum() / (2 * MU)))))
    eta, error, neumann = np.array(rows).T
    print(body, "eta", eta, "error", error, "neumann part", neumann, "effectivity", eta / error)
    assert np.all((eta / error > 1.0) & (eta / error < 10.0))
    assert (eta / error).max() / (eta / error).min() < 1.2
    assert np.all(neumann > 0) and neumann[-1] / neumann[0] < eta[-1] / eta[0]


LINEAR_GRADIENT = np.array([[0.01, 0.02, -0.03], [-0.01, 0.005, 0.0], [0.01, 0.0, 0.02]])


@pytest.mark.parametrize("volumetric_strain", ["cell", "nodal_average"])
@pytest.mark.parametrize("body", list(BODIES))
def test_a_linear_field_has_a_zero_estimate(body, volumetric_strain):
    """The patch test: u linear is the discrete solution, σ is the same constant in every cell (no
    jump, no stabilization), and the exact traction σ n on every side leaves no misfit; a wrong
    traction on one side is seen only in the cells touching it."""
    domain, family, sizes = BODIES[body]
    mesh = build_mesh3d(family, domain, n=sizes[0])
    space = VirtualElementSpace(mesh, 1)
    u = mesh.vertices @ LINEAR_GRADIENT.T
    eps = 0.5 * (LINEAR_GRADIENT + LINEAR_GRADIENT.T)
    sig = LAM * np.trace(eps) * np.eye(3) + 2 * MU * eps

    def exact_traction(side):
        normal = mesh.facet_normals[mesh.boundaries[side][0]] * (
            1 if mesh.facet_cells[mesh.boundaries[side][0], 0] >= 0 else -1
        )
        t = sig @ normal
        return lambda x, y, z: tuple(t[i] + 0 * x for i in range(3))

    tractions = {side: exact_traction(side) for side in mesh.boundaries}
    found = error_indicators(mesh, u, LAM, MU, STAB, neumann=tractions, volumetric_strain=volumetric_strain)
    assert found["estimate"] < 1e-6
    assert np.sqrt(np.sum(found["indicator"] ** 2)) < 1e-6 * np.sqrt(found["energy"])
    side = next(iter(mesh.boundaries))
    wrong = dict(tractions, **{side: lambda x, y, z: (0 * x + 1.0, 0 * x, 0 * x)})
    seen = error_indicators(space, u, LAM, MU, STAB, neumann=wrong)
    touching = np.unique(mesh.facet_cells[mesh.boundaries[side]])
    flagged = np.flatnonzero(seen["neumann"] > 1e-12)
    assert flagged.size and set(flagged) <= set(touching[touching >= 0])


def contact_scene(n):
    """A box on a foundation whose gap opens along x: pressed in contact for x < ~0.5, apart beyond."""
    return scene_from_dict(
        {
            "name": "contact-zone",
            "model": "3d",
            "domain": {"box": [[0, 0, 0], [1, 1, 0.5]]},
            "material": {"E": 1000.0, "nu": 0.3},
            "boundary": {"dirichlet": {"top": [0.0, 0.0, -0.01]}, "contact": ["bottom"]},
            "contact": {"gap": "0.02*x", "normal": {"k": 200.0, "m": 1.0}, "friction": {"k": 3.0, "m": 0.0}},
            "discretization": {"mesh": {"family": "hex", "n": n}},
            "solver": {"method": "ssn", "tol": 1e-10},
        }
    )


def test_the_contact_term_lives_on_the_contact_zone_and_peaks_at_its_edges():
    scene = contact_scene(8)
    problem, solution, _ = solve_scene(scene, dataset=False)
    problem.info["contact_sides"] = tuple(scene.contact_sides)
    tractions = contact_tractions(problem, solution)
    u = problem.node_values(solution.u)
    found = error_indicators(problem.space, u, problem.lam, problem.mu, problem.stabilization, contact=tractions)
    mesh = problem.mesh
    assert np.all(np.isfinite(found["indicator"])) and found["contact"].sum() > 0
    bottom = np.unique(mesh.facet_cells[mesh.boundaries["bottom"], 0])
    assert set(np.flatnonzero(found["contact"])) <= set(bottom)
    x = mesh.cell_centroids[bottom, 0]
    pressed, apart = bottom[x < 0.5], bottom[x > 0.5]
    assert found["contact"][pressed].mean() > 10 * found["contact"][apart].mean()
    # the largest indicators sit at the contact zone's free edge x = 0 (highest pressure, free side)
    assert np.all(mesh.cell_centroids[np.argsort(-found["indicator"])[:8], 0] < 0.125)
    # and the indicator rises again at the separation line x ~ 0.5, above the zone's inside
    column = lambda xc: found["indicator"][bottom[np.abs(x - xc) < 1e-6]].mean()  # noqa: E731
    assert column(0.4375) > column(0.3125)


@pytest.mark.parametrize("body", ["hex", "voronoi", "extruded"])
def test_a_normal_pressure_is_the_traction_minus_p_nu(body):
    """A side under a normal pressure p has the Neumann datum −p ν: the same terms as the traction
    field −p ν on each plane side of the body, and zero for the pure pressure field u = −p x / (3λ + 2μ)."""
    domain, family, sizes = BODIES[body]
    mesh = build_mesh3d(family, domain, n=sizes[0])
    p = 0.7
    u = -p / (3 * LAM + 2 * MU) * mesh.vertices  # σ = −p I
    pressure = {side: (lambda x, y, z: p + 0 * x) for side in mesh.boundaries}
    assert error_indicators(mesh, u, LAM, MU, STAB, pressure=pressure)["estimate"] < 1e-6
    rng = np.random.default_rng(4)
    v = u + 0.01 * rng.standard_normal(u.shape)

    def traction_of(side):
        first = mesh.boundaries[side][0]
        normal = mesh.facet_normals[first] * (1 if mesh.facet_cells[first, 0] >= 0 else -1)
        return lambda x, y, z: tuple(-p * normal[i] + 0 * x for i in range(3))

    by_pressure = error_indicators(mesh, v, LAM, MU, STAB, pressure=pressure)
    by_traction = error_indicators(
        mesh, v, LAM, MU, STAB, neumann={side: traction_of(side) for side in mesh.boundaries}
    )
    assert np.allclose(by_pressure["neumann"], by_traction["neumann"], rtol=1e-12, atol=0)
    assert by_pressure["neumann"].max() > 0
