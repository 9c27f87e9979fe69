"""The manufactured 3D frictional-contact scenes (config/scenes/3d/contact_*.yaml), checked from their text.

- Each committed file is what ``tests/manufactured_contact3d.py`` generates (it cannot drift).
- Read back with sympy from the committed text alone (``max`` as sympy's Max; the faces from the
  ``domain`` section): the body force is −div σ(u) of the ``exact:`` displacement, the tractions are
  σ(u)n, the Dirichlet face holds u, and on Γ_C u meets the contact law exactly with no other
  traction: σ_νν = −k_ν (u_ν − g)₊ and σ_τ = −p_τ(u_ν − g) λ with |λ| ≤ 1, λ = u_τ/|u_τ| where it
  slides (a direction turning by more than 90° over Γ_C, both components well inside (−1, 1) on
  much of it: a box [−1, 1]² would not hold |λ| ≤ 1 there), u_τ = 0 where |λ| < 1 (sticking), and
  the separation kind in contact exactly inside its ellipse.
- Solved through the scene (ssn, verified) on two levels of every 3D family (hex, tet, octree,
  voronoi on the box; prisms over voronoi, square and triangle meshes on the extruded square): H1
  order ≥ 0.95 in the mean cell size (cells^(-1/3), as ``vemkit.studies.three_d.convergence_dataset``
  measures it: gmsh's tetrahedra and the octree do not scale their cells as n³), and the discrete
  contact state is the exact one wherever the exact penetration exceeds twice the discrete one's
  error. uzawa and ssn agree to 1e-10 at tol 1e-12 with the turning slip.
"""

from pathlib import Path

import numpy as np
import pytest
import sympy
import yaml
from conftest import AGREEMENT_SOLVERS
from manufactured_contact3d import BODIES, ELLIPSE_CENTRE, ELLIPSE_WEIGHTS, KINDS, scene_path, scene_text

from vemkit.config.scene import load_scene
from vemkit.contact.problem import scene_problem
from vemkit.solvers.dispatch import solve
from vemkit.solvers.solution import SEPARATED, SLIP, STICK, contact_state
from vemkit.studies.scene_solve import solve_scene
from vemkit.studies.three_d import observed_rates

ROOT = Path(__file__).resolve().parents[2]
XYZ = sympy.symbols("x y z")
SAMPLES = np.linspace(0.013, 0.987, 13)
#: case -> (body, mesh family, levels n): every 3D family, two levels each (module docstring)
FAMILIES = {
    "hex": ("box", "hex", (4, 8)),
    "tet": ("box", "tet", (3, 6)),
    "octree": ("box", "octree", (4, 8)),
    "voronoi": ("box", "voronoi", (6, 8)),
    "prisms-voronoi": ("extruded", "voronoi", (4, 8)),
    "prisms-triangle": ("extruded", "triangle", (4, 8)),
}


def _committed(kind, body):
    return scene_path(kind, body).read_text(encoding="utf-8")


def _sym(text):
    return sympy.sympify(text, locals={"max": sympy.Max, **{str(s): s for s in XYZ}})


def _numeric(expr):
    """numpy of a sympy expression; d/dx Max(0, 1 - q) brings Heaviside (kept) and DiracDelta terms,
    which multiply a power of Max(0, 1 - q) and so vanish: dropped."""
    f = sympy.lambdify(XYZ, expr.replace(sympy.DiracDelta, lambda *args: 0), "numpy")
    return lambda x, y, z: np.broadcast_to(f(x, y, z), np.shape(x)).astype(float)


def _faces(domain: dict) -> dict:
    """side -> (outward unit normal, a point of its plane) of the box or the extruded polygon."""
    if "box" in domain:
        lo, hi = np.array(domain["box"], dtype=float)
        out = {}
        for i, side in enumerate(domain["sides"]):
            normal = np.zeros(3)
            normal[i // 2] = 1.0 if i % 2 else -1.0
            out[side] = (normal, hi if i % 2 else lo)
        return out
    corners = np.array(domain["polygon"], dtype=float)  # counter-clockwise: side i from corner i to i + 1
    out = {}
    for i, side in enumerate(domain["sides"]):
        d = corners[(i + 1) % len(corners)] - corners[i]
        out[side] = (np.array([d[1], -d[0], 0.0]) / np.hypot(*d), np.append(corners[i], 0.0))
    front, back = domain["extrude"]["ends"]
    out[front] = (np.array([0.0, 0.0, -1.0]), np.zeros(3))
    out[back] = (np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, domain["extrude"]["depth"]]))
    return out


def _face_points(normal, point):
    """Sample points (3, P) on the unit-square face with this normal through ``point``."""
    a, b = np.meshgrid(SAMPLES, SAMPLES)
    axis = int(np.argmax(np.abs(normal)))
    others = [k for k in range(3) if k != axis]
    pts = np.zeros((3, a.size))
    pts[others[0]], pts[others[1]], pts[axis] = a.ravel(), b.ravel(), point[axis]
    return pts


def _read_back(kind, body):
    data = yaml.safe_load(_committed(kind, body))
    E, nu = data["material"]["E"], data["material"]["nu"]
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))  # the 3D isotropic C (docs/reference/files.md)
    u = sympy.Matrix([_sym(c) for c in data["exact"]["displacement"]])
    grad = u.jacobian(XYZ)
    eps = (grad + grad.T) / 2
    return data, u, lam * eps.trace() * sympy.eye(3) + 2 * mu * eps


@pytest.mark.parametrize("body", list(BODIES))
@pytest.mark.parametrize("kind", list(KINDS))
def test_the_committed_scene_is_the_generated_one(kind, body):
    assert _committed(kind, body) == scene_text(kind, body), "run `python tests/manufactured_contact3d.py` and commit"


@pytest.mark.parametrize("body", list(BODIES))
@pytest.mark.parametrize("kind", list(KINDS))
def test_the_exact_solution_solves_the_scene(kind, body):
    data, u, sigma = _read_back(kind, body)
    grid = [g.ravel() for g in np.meshgrid(SAMPLES, SAMPLES, SAMPLES)]
    scale = max(float(np.abs(_numeric(sigma[i, j])(*grid)).max()) for i in range(3) for j in range(3))
    for i, f in enumerate(data["body_force"]):
        residual = _sym(f) + sum(sympy.diff(sigma[i, j], XYZ[j]) for j in range(3))
        assert np.abs(_numeric(residual)(*grid)).max() < 1e-9 * scale
    faces = _faces(data["domain"])
    boundary = data["boundary"]
    assert set(faces) == set(boundary["neumann"]) | set(boundary["dirichlet"]) | set(boundary["contact"])
    for side, load in boundary["neumann"].items():
        normal, point = faces[side]
        pts = _face_points(normal, point)
        for i in range(3):
            expected = sum(sigma[i, j] * float(normal[j]) for j in range(3))
            np.testing.assert_allclose(
                _numeric(_sym(load["traction"][i]))(*pts), _numeric(expected)(*pts), atol=1e-10 * scale
            )
    for side, held in boundary["dirichlet"].items():
        pts = _face_points(*faces[side])
        for i in range(3):
            np.testing.assert_allclose(_numeric(_sym(held[i]))(*pts), _numeric(u[i])(*pts), atol=1e-14)


def _gamma_c(kind, body):
    """On Γ_C's samples: (points, t = u_ν − g, |σ_τ| bound p_τ, σ_νν, λ = −σ_τ / p_τ, u_τ, law) from the
    text; tangential vectors in global coordinates (3, P)."""
    data, u, sigma = _read_back(kind, body)
    [side] = data["boundary"]["contact"]
    normal, point = _faces(data["domain"])[side]
    pts = _face_points(normal, point)
    u_h = np.stack([_numeric(c)(*pts) for c in u])
    traction = np.stack([sum(_numeric(sigma[i, j])(*pts) * normal[j] for j in range(3)) for i in range(3)])
    law = data["contact"]
    t = normal @ u_h - _numeric(_sym(law["gap"]))(*pts)
    pressure = -(normal @ traction)
    bound = law["friction"]["k"] * np.maximum(t, 0) ** law["friction"]["m"]
    tangential = traction - np.outer(normal, normal @ traction)
    slip = u_h - np.outer(normal, normal @ u_h)
    multiplier = np.divide(-tangential, bound, out=np.zeros_like(tangential), where=bound > 0)
    return pts, t, bound, pressure, tangential, multiplier, slip, law


@pytest.mark.parametrize("body", list(BODIES))
@pytest.mark.parametrize("kind", list(KINDS))
def test_the_exact_solution_meets_the_contact_law_on_gamma_c(kind, body):
    pts, t, bound, pressure, tangential, multiplier, slip, law = _gamma_c(kind, body)
    scale = np.abs(pressure).max()
    np.testing.assert_allclose(
        pressure, law["normal"]["k"] * np.maximum(t, 0) ** law["normal"]["m"], atol=1e-10 * scale
    )
    active = bound > 0
    assert np.all(np.abs(tangential[:, ~active]) < 1e-10 * scale)  # no friction where separated (m_tau = 1)
    size = np.linalg.norm(multiplier, axis=0)[active]
    assert np.all(size <= 1 + 1e-12)
    speed = np.linalg.norm(slip, axis=0)[active]
    sliding = speed > 1e-12
    np.testing.assert_allclose(
        multiplier[:, active][:, sliding], slip[:, active][:, sliding] / speed[sliding], atol=1e-12
    )
    if kind == "sticking":
        assert np.all(t > 0) and not np.any(sliding) and np.all(size <= 0.6 + 1e-12)
        direction = np.arctan2(multiplier[2], multiplier[0])  # λ's angle in the x-z plane turns
        assert np.ptp(direction) > np.pi / 2
        return
    assert np.all(sliding)
    if kind == "sliding":
        assert np.all(t > 0)
        direction = np.arctan2(slip[2], slip[0])
        assert np.ptp(direction) > np.pi / 2, "the slip direction turns by more than 90 degrees over Gamma_C"
        # on the unit circle with both components well inside (-1, 1): the box [-1, 1]^2 would take
        # lambda + u_tau / |u_tau| (|.| = 2) to a corner (|.| = sqrt 2), only the disk gives lambda back
        inner = np.max(np.abs(multiplier[[0, 2]]), axis=0) < 0.9
        assert np.mean(inner) > 0.4, np.mean(inner)
        step = multiplier[[0, 2]][:, inner] * 2.0
        assert np.all(np.linalg.norm(np.clip(step, -1, 1), axis=0) > 1.3)
    else:  # in contact exactly inside the ellipse, separated outside it; it lies inside Gamma_C
        q = (
            ELLIPSE_WEIGHTS[0] * (pts[0] - ELLIPSE_CENTRE[0]) ** 2
            + ELLIPSE_WEIGHTS[1] * (pts[2] - ELLIPSE_CENTRE[1]) ** 2
        )
        assert np.all((t > 0) == (q < 1)) and 0.2 < np.mean(q < 1) < 0.6
        angle = np.linspace(0, 2 * np.pi, 50)
        x = ELLIPSE_CENTRE[0] + np.cos(angle) / np.sqrt(ELLIPSE_WEIGHTS[0])
        z = ELLIPSE_CENTRE[1] + np.sin(angle) / np.sqrt(ELLIPSE_WEIGHTS[1])
        assert 0 < x.min() and x.max() < 1 and 0 < z.min() and z.max() < 1
        curve = np.stack([x, np.full_like(x, pts[1, 0]), z])
        data, u, _ = _read_back(kind, body)
        normal_u = -_numeric(u[1])(*curve)  # nu = (0, -1, 0) on y = 0
        assert np.abs(normal_u - _numeric(_sym(data["contact"]["gap"]))(*curve)).max() < 1e-14


def _exact_penetration(kind, body, problem):
    """u_ν − g of the committed scene's exact u at the contact vertices."""
    cb = problem.contact
    data = yaml.safe_load(_committed(kind, body))
    u = np.stack([_numeric(_sym(c))(*cb.coords.T) for c in data["exact"]["displacement"]], axis=1)
    return np.sum(u * cb.normal, axis=1) - cb.gap


def _solve(kind, body, family, n, overrides=()):
    scene = load_scene(
        str(scene_path(kind, body)), [f"discretization.mesh.family={family}", f"discretization.mesh.n={n}", *overrides]
    )
    return scene, *solve_scene(scene, verify=True)


@pytest.mark.parametrize("case", list(FAMILIES))
@pytest.mark.parametrize("kind", list(KINDS))
def test_every_3d_family_converges_at_h1_order_1_and_finds_the_exact_contact_state(kind, case):
    body, family, levels = FAMILIES[case]
    h1, l2, cells = [], [], []
    for n in levels:
        scene, problem, solution, ds = _solve(kind, body, family, n, ["solver.linear=amg"])
        h1.append(ds.attrs["error_h1"])
        l2.append(ds.attrs["error_l2"])
        cells.append(problem.mesh.n_cells)
    order_h1 = observed_rates(h1, np.cbrt(cells))[-1]
    order_l2 = observed_rates(l2, np.cbrt(cells))[-1]
    assert order_h1 >= 0.95, (order_h1, order_l2, h1, l2, cells)
    found = contact_state(problem, solution.u, solution.multiplier)
    exact = _exact_penetration(kind, body, problem)
    away = np.abs(exact) > 2 * np.abs(found.penetration - exact).max()
    expected = {"sliding": SLIP, "sticking": STICK}.get(kind)
    if expected is None:
        expected = np.where(exact > 0, SLIP, SEPARATED)
    expected = np.broadcast_to(expected, found.state.shape)[away]
    assert np.mean(away) > 0.3 and set(expected) == {"sliding": {SLIP}, "sticking": {STICK}}.get(
        kind, {SLIP, SEPARATED}
    )
    np.testing.assert_array_equal(found.state[away], expected)


def test_uzawa_and_ssn_agree_with_the_turning_slip():
    scene = load_scene(
        str(scene_path("sliding", "box")), ["discretization.mesh.family=voronoi", "discretization.mesh.n=3"]
    )
    problem = scene_problem(scene)
    a, b = solve(problem, AGREEMENT_SOLVERS["uzawa"]), solve(problem, AGREEMENT_SOLVERS["ssn"])
    assert a.converged and b.converged
    assert np.max(np.abs(a.u - b.u)) / np.max(np.abs(b.u)) < 1e-10
    assert np.max(np.abs(a.multiplier - b.multiplier)) < 1e-10
    state = contact_state(problem, b.u, b.multiplier)
    assert np.all(state.state == SLIP)
    lam = b.multiplier
    assert np.allclose(np.linalg.norm(lam, axis=1), 1.0, rtol=0, atol=1e-12)
    assert np.ptp(np.arctan2(lam[:, 1], lam[:, 0])) > np.pi / 2 and np.mean(np.max(np.abs(lam), axis=1) < 0.9) > 0.3
