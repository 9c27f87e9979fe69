"""The Section 4 study's manufactured contact scenes (config/order2/*.yaml), checked from their text.

- Each committed file is what ``tests/manufactured_contact.py`` generates (it cannot drift).
- Read back with sympy from the committed text alone (``max`` as sympy's Max): the body force is
  −div σ(u) of the ``exact:`` displacement, the left and top tractions are σ(u)n, the right side
  holds u, and on Γ_C (y = 0) u meets the contact law exactly with no other traction:
  σ22 = −k_ν (u_ν − g)₊ and σ12 = p_τ(u_ν − g) λ with |λ| ≤ 1, λ = 1 where u_τ > 0 (sliding) and
  u_τ = 0 where |λ| < 1 (sticking).
- Solved through the scene: k = 2 converges at H1 order 2 and k = 1 at order 1, and the discrete
  contact state is the exact one away from the separation point. With the body force projected on
  P_1 (``discretization.body_force_projection: p1``) k = 2 reaches L2 order 3 (the paper's P_0 load
  caps it at 2, ``tests/vem/test_k2_convergence.py``).
"""

from pathlib import Path

import numpy as np
import pytest
import sympy
import yaml
from manufactured_contact import KINDS, SEPARATION_POINT, scene_text

from vemkit.config.scene import load_scene
from vemkit.solvers.solution import SEPARATED, SLIP, STICK, contact_state
from vemkit.studies.scene_solve import solve_scene

ROOT = Path(__file__).resolve().parents[2]
X, Y = sympy.symbols("x y")
SAMPLES = np.linspace(0.013, 0.987, 41)


def _committed(kind):
    return (ROOT / "config" / "order2" / f"{kind}.yaml").read_text(encoding="utf-8")


def _sym(text):
    return sympy.sympify(text, locals={"max": sympy.Max, "x": X, "y": Y})


def _numeric(expr):
    """numpy of a sympy expression; d/dx Max(0, x0 - x) brings Heaviside (kept) and DiracDelta terms,
    which multiply a power of Max(0, x0 - x) and so vanish: dropped."""
    return sympy.lambdify((X, Y), expr.replace(sympy.DiracDelta, lambda *args: 0), "numpy")


@pytest.mark.parametrize("kind", list(KINDS))
def test_the_committed_scene_is_the_generated_one(kind):
    assert _committed(kind) == scene_text(kind), "run `python tests/manufactured_contact.py` and commit"


@pytest.mark.parametrize("kind", list(KINDS))
def test_the_exact_solution_solves_the_scene_and_meets_the_contact_law_on_gamma_c(kind):
    data = yaml.safe_load(_committed(kind))
    E, nu = data["material"]["E"], data["material"]["nu"]
    lam, mu = E * nu / (1 - nu**2), E / (2 * (1 + nu))  # the paper's plane-stress C (docs/reference/mathematics.md)
    u = sympy.Matrix([_sym(c) for c in data["exact"]["displacement"]])
    grad = u.jacobian([X, Y])
    eps = (grad + grad.T) / 2
    sigma = lam * eps.trace() * sympy.eye(2) + 2 * mu * eps
    # interior: f = -div sigma(u); sides: tractions sigma n on left and top, u on the right
    residual = [
        _sym(f) + sympy.diff(sigma[i, 0], X) + sympy.diff(sigma[i, 1], Y) for i, f in enumerate(data["body_force"])
    ]
    px, py = np.meshgrid(SAMPLES, SAMPLES)
    scale = np.abs(_numeric(sympy.diff(sigma[1, 1], Y))(px, py)).max()
    for r in residual:
        assert np.abs(_numeric(r)(px, py)).max() < 1e-9 * scale
    neumann = data["boundary"]["neumann"]
    for side, normal, line in (("left", (-1, 0), (0 * SAMPLES, SAMPLES)), ("top", (0, 1), (SAMPLES, 0 * SAMPLES + 1))):
        for i in range(2):
            given = _numeric(_sym(neumann[side]["traction"][i]))(*line)
            np.testing.assert_allclose(
                given, _numeric(sigma[i, 0] * normal[0] + sigma[i, 1] * normal[1])(*line), atol=1e-10 * scale
            )
    for i in range(2):
        np.testing.assert_allclose(
            _numeric(_sym(data["boundary"]["dirichlet"]["right"][i]))(1 + 0 * SAMPLES, SAMPLES),
            _numeric(u[i])(1 + 0 * SAMPLES, SAMPLES),
            atol=1e-14,
        )
    # Gamma_C: nu = (0, -1), tau = (1, 0); u_nu = -u2, u_tau = u1; sigma_nu = sigma22, sigma_tau = -sigma12
    law = data["contact"]
    x0 = 0 * SAMPLES
    t = -_numeric(u[1])(SAMPLES, x0) - _numeric(_sym(law["gap"]))(SAMPLES, x0)
    pressure = law["normal"]["k"] * np.maximum(t, 0) ** law["normal"]["m"]
    bound = law["friction"]["k"] * (np.maximum(t, 0) ** law["friction"]["m"] if law["friction"]["m"] else 1.0 + 0 * t)
    np.testing.assert_allclose(_numeric(sigma[1, 1])(SAMPLES, x0), -pressure, atol=1e-10 * scale)
    shear = _numeric(sigma[0, 1])(SAMPLES, x0) + 0 * SAMPLES  # = p_tau lambda
    slip = _numeric(u[0])(SAMPLES, x0) + 0 * SAMPLES
    active = bound > 0
    multiplier = shear[active] / bound[active]
    assert np.all(np.abs(multiplier) <= 1 + 1e-12) and np.all(np.abs(shear[~active]) < 1e-10 * scale)
    sliding = np.abs(slip[active]) > 1e-12
    np.testing.assert_allclose(multiplier[sliding], np.sign(slip[active][sliding]), atol=1e-12)
    assert np.all(np.abs(multiplier[~sliding]) < 1)
    if kind == "separation":  # in contact left of x0, separated right of it
        assert np.all((t > 0) == (SAMPLES < float(SEPARATION_POINT)))
    else:
        assert np.all(t > 0) and (np.all(sliding) if kind == "sliding" else not np.any(sliding))


@pytest.mark.parametrize("kind", list(KINDS))
def test_the_scene_converges_at_order_k_and_finds_the_exact_contact_state(kind):
    path = str(ROOT / "config" / "order2" / f"{kind}.yaml")
    h1 = {}
    for order in (1, 2):
        for n in (8, 16):
            scene = load_scene(path, [f"discretization.mesh.n={n}", f"discretization.order={order}"])
            problem, solution, ds = solve_scene(scene, verify=True)
            h1[order, n] = ds.attrs["error_h1"]
    assert np.log2(h1[2, 8] / h1[2, 16]) >= 1.9 and 0.95 <= np.log2(h1[1, 8] / h1[1, 16]) <= 1.25, h1
    found = contact_state(problem, solution.u, solution.multiplier)  # k = 2, n = 16
    x = problem.contact.coords[:, 0]
    inner = x < 1 - 1e-12  # the clamped corner (1, 0) leaves Gamma_C's conditions
    expected = {"sliding": SLIP, "sticking": STICK, "separation": SLIP}[kind]
    left = inner & (x < 0.5) if kind == "separation" else inner
    assert np.all(found.state[left] == expected)
    if kind == "separation":
        assert np.all(found.state[x > 0.65] == SEPARATED)


@pytest.mark.parametrize("kind", ["sliding", "separation"])
def test_the_p1_body_force_load_gives_k2_its_l2_order_3_with_contact(kind):
    path = str(ROOT / "config" / "order2" / f"{kind}.yaml")
    found = {}
    for projection in ("p0", "p1"):
        for n in (8, 16):
            scene = load_scene(
                path,
                [
                    f"discretization.mesh.n={n}",
                    "discretization.order=2",
                    f"discretization.body_force_projection={projection}",
                ],
            )
            ds = solve_scene(scene, verify=True)[2]
            found[projection, n] = (ds.attrs["error_h1"], ds.attrs["error_l2"])
    l2 = {p: np.log2(found[p, 8][1] / found[p, 16][1]) for p in ("p0", "p1")}
    h1 = np.log2(found["p1", 8][0] / found["p1", 16][0])
    assert l2["p1"] >= 2.8 and l2["p0"] <= 2.3 and h1 >= 1.9, (l2, h1, found)
