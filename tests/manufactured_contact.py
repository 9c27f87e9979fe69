"""Manufactured frictional-contact solutions that need no traction on Γ_C besides the contact law.

u = (u1, u2) on the unit square (E = 1000, ν = 0.3, the paper's plane-stress C), clamped to u on
the right, σ(u)n on the left and top, the body force −div σ(u), and on Γ_C (the bottom, ν = (0, −1),
τ = (1, 0)) a frictional contact whose conditions u meets exactly. With the signed penetration t(x)
chosen, the gap is g = u_ν − t = −u2(x, 0) − t(x), and u is built so that on y = 0

    σ22 = −p_ν(t) = −k_ν t₊                 (normal compliance, m_ν = 1: (2.6), (5.1))
    σ12 = p_τ(t) λ = k_τ t₊^{m_τ} λ         (friction, (2.8)-(2.9), (5.1))

Writing u1 = f(x) + y a(x) + y² B1, u2 = h(x) + y b(x) + y² B2, the two conditions fix a and b; the
y² terms (a bump at (0.7, 0.6)) leave them alone. The three kinds (issue 14, item 3):

- ``sliding``: t > 0 and u_τ = u1(x, 0) > 0 on all of Γ_C, λ = 1, m_τ = 0;
- ``sticking``: t > 0, u_τ = 0 and λ = cos(x)/2 (|λ| < 1), m_τ = 0;
- ``separation``: t = c (x₀ − x)³, in contact (sliding, λ = 1) for x < x₀ = 0.6 and separated beyond,
  Coulomb-like m_τ = 1 (p_τ = k_τ t₊: no friction where separated). The contact pressure vanishes
  like (x₀ − x)³ at the separation point, so u is in H^{7/2−ε}: enough for k = 2 to converge at its
  full order. (A pressure with a kink, as a true normal-compliance solution has, needs either a
  traction on Γ_C besides the contact law or a singular u; this construction would put the kink on
  the whole line x = x₀ through the body.) x₀ = 0.6 is no vertex of the dyadic meshes.

``python tests/manufactured_contact.py`` writes the scenes to ``config/order2/<kind>.yaml`` (the
Section 4 study's manufactured cases, ``snakemake -j2 order2``); a test regenerates them and checks
them symbolically, so the committed files cannot drift from this construction.
"""

from __future__ import annotations

import sys
from pathlib import Path

import sympy
import yaml
from sympy.printing.str import StrPrinter

X, Y = sympy.symbols("x y")
E, NU = 1000.0, 0.3
K_NORMAL = 1000.0
LAM, MU = E * NU / (1 - NU**2), E / (2 * (1 + NU))  # the paper's plane-stress C (docs/reference/mathematics.md)
BUMP = sympy.exp(-20 * ((X - 0.7) ** 2 + (Y - 0.6) ** 2))
SEPARATION_POINT = sympy.Rational(3, 5)
#: (x0 − x)₊, a placeholder function: its derivative is −1 wherever it is positive, and every term
#: that uses it keeps at least one factor of it, so ``_positive_part`` below is exact
_S = sympy.Function("S")(X)
#: kind -> (u1 on Γ_C = u_τ, signed penetration t, penetration's positive part t₊, k_τ, m_τ, λ)
KINDS = {
    "sliding": (0.02 * (1 + X), 0.02 * (1 + X), 0.02 * (1 + X), 10.0, 0.0, sympy.Integer(1)),
    "sticking": (sympy.Integer(0), 0.02 * (1 + X), 0.02 * (1 + X), 10.0, 0.0, sympy.cos(X) / 2),
    "separation": (0.02 * (1 + X), 0.1 * (SEPARATION_POINT - X) ** 3, 0.1 * _S**3, 300.0, 1.0, sympy.Integer(1)),
}
CONFIG = Path(__file__).resolve().parents[1] / "config" / "order2"


class SceneExpressionPrinter(StrPrinter):
    """sympy's text in the scene's expression syntax: ``max`` for (x₀ − x)₊, ``abs``, ``**``."""

    def _print_Function(self, expr):
        if expr.func == _S.func:
            return f"max({self._print(SEPARATION_POINT - X)}, 0)"
        return super()._print_Function(expr)

    def _print_Rational(self, expr):
        return f"({expr.p}/{expr.q})"


def _positive_part(expr):
    """Derivatives of S = (x₀ − x)₊: S' = −1 and S'' = 0 wherever S > 0; where S = 0 every term of
    ``expr`` has a factor S (t₊ = 0.1 S³ is differentiated at most twice), so the result is exact."""
    return expr.subs(sympy.Derivative(_S, (X, 2)), 0).subs(sympy.Derivative(_S, X), -1)


def stress(u1, u2):
    """(σ11, σ22, σ12) of the paper's plane-stress C."""
    e11, e22 = sympy.diff(u1, X), sympy.diff(u2, Y)
    e12 = (sympy.diff(u1, Y) + sympy.diff(u2, X)) / 2
    return LAM * (e11 + e22) + 2 * MU * e11, LAM * (e11 + e22) + 2 * MU * e22, 2 * MU * e12


def exact_fields(kind: str) -> dict:
    """The sympy fields of one kind: u1, u2, the stresses, the body force, the gap and the law."""
    f, t, t_plus, k_friction, m_friction, multiplier = KINDS[kind]
    h = -0.1 + 0.03 * sympy.sin(2 * X)  # u2 on Γ_C: pressed down onto the foundation
    shear = k_friction * (t_plus if m_friction == 1.0 else 1) * multiplier  # σ12 = p_τ λ at y = 0
    a = shear / MU - sympy.diff(h, X)  # σ12 = μ (∂u1/∂y + ∂u2/∂x)
    b = (-K_NORMAL * t_plus - LAM * sympy.diff(f, X)) / (LAM + 2 * MU)  # σ22 = −k_ν t₊
    u1 = f + Y * a + Y**2 * 0.05 * BUMP
    u2 = h + Y * b - Y**2 * 0.03 * BUMP
    s11, s22, s12 = (_positive_part(s) for s in stress(u1, u2))
    force = [
        _positive_part(-(sympy.diff(s11, X) + sympy.diff(s12, Y))),
        _positive_part(-(sympy.diff(s12, X) + sympy.diff(s22, Y))),
    ]
    return {
        "u1": u1,
        "u2": u2,
        "s11": s11,
        "s22": s22,
        "s12": s12,
        "force": force,
        "gap": -h - t,
        "t": t,
        "t_plus": t_plus,
        "k_friction": k_friction,
        "m_friction": m_friction,
        "multiplier": multiplier,
    }


def contact_scene(kind: str) -> dict:
    """The scene (a dict for scene_from_dict) whose exact solution is the manufactured u of ``kind``."""
    fields = exact_fields(kind)
    text = SceneExpressionPrinter().doprint
    u1, u2, s11, s22, s12 = (fields[k] for k in ("u1", "u2", "s11", "s22", "s12"))
    return {
        "name": f"manufactured-{kind}",
        "domain": "unit_square",
        "material": {"E": E, "nu": NU},
        "body_force": [text(c) for c in fields["force"]],
        "boundary": {
            "dirichlet": {"right": [text(u1), text(u2)]},
            "neumann": {"left": {"traction": [text(-s11), text(-s12)]}, "top": {"traction": [text(s12), text(s22)]}},
            "contact": ["bottom"],
        },
        "contact": {
            "gap": text(fields["gap"]),
            "normal": {"k": K_NORMAL, "m": 1.0},
            "friction": {"k": fields["k_friction"], "m": fields["m_friction"]},
        },
        "exact": {"displacement": [text(u1), text(u2)]},
        "discretization": {"mesh": {"family": "square", "n": 8}, "stabilization": "dofi-2mu"},
        "solver": {"method": "ssn", "tol": 1e-10},
    }


def scene_text(kind: str) -> str:
    """The YAML file of one kind, with a header saying where it comes from."""
    header = (
        f"# A manufactured frictional-contact solution, kind '{kind}': generated by\n"
        "# tests/manufactured_contact.py (its docstring has the construction); do not edit by hand,\n"
        "# run `python tests/manufactured_contact.py` (a test regenerates and compares this file).\n"
    )
    return header + yaml.safe_dump(contact_scene(kind), sort_keys=False, width=10_000)


def main(argv) -> int:
    CONFIG.mkdir(parents=True, exist_ok=True)
    for kind in KINDS:
        path = CONFIG / f"{kind}.yaml"
        path.write_text(scene_text(kind), encoding="utf-8")
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
