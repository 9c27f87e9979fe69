"""Manufactured frictional-contact solutions of a 3D body that need no traction on Γ_C but the contact law.

u = (u1, u2, u3) on the unit cube (E = 1000, ν = 0.3, the 3D isotropic C: λ = Eν/((1+ν)(1−2ν)),
μ = E/(2(1+ν)), docs/reference/files.md), Γ_C the face y = 0 (ν = (0, −1, 0): u_ν = −u2, u_τ = (u1, u3) in the
x-z plane), u held on y = 1, σ(u)n on the four other faces, the body force −div σ(u). With the signed
penetration t(x, z) chosen the gap is g = u_ν − t = −u2(x, 0, z) − t, and u is built so that on y = 0

    σ22 = −p_ν(t) = −k_ν t₊                         (normal compliance, m_ν = 1: (2.6), (5.1))
    (σ12, σ23) = p_τ(t) λ = k_τ t₊^{m_τ} λ          (friction, (2.7)-(2.9), (5.1))

i.e. σν = −p_ν ν − p_τ λ: the tangential traction σ_τ = (−σ12, −σ23) = −p_τ λ opposes the slip
where λ = u_τ/|u_τ| (docs/reference/files.md, vemkit.solvers.solution). Writing u1 = f1 + y a1 + y² B1,
u2 = h + y b + y² B2, u3 = f3 + y a3 + y² B3 (f1, f3, h, a1, a3, b of x and z), the three conditions
fix a1, a3 and b; the y² terms (``INTERIOR``) leave them alone. The kinds (issue 21 item 3;
k_ν = 1000, t ≤ 0.06, g ≥ 0.01):

- ``sliding``: t > 0 on all of Γ_C, u_τ = s (cos θ, sin θ) with s > 0 and θ = 0.8 + 1.6 (x − z)
  turning by 183° across Γ_C (along the diagonal x = z the slip is diagonal: a box [−1, 1]² for λ
  instead of the unit disk would not enforce |λ| ≤ 1 there), λ = (cos θ, sin θ), k_τ = 10, m_τ = 0;
- ``sticking``: t > 0, u_τ = 0, λ = r (cos φ, sin φ) with r = 0.3 + 0.3 sin(πx) sin(πz) ≤ 0.6 and
  φ = 0.3 + x + z (turning by 115°), k_τ = 100, m_τ = 0. The friction traction p_τ λ is made large
  against the rest of the stress (k_τ = 100, not 10): the discrete multiplier at a vertex is a nodal
  traction, whose error on coarse Voronoi and octree meshes reached 0.3-0.65 in |λ| with k_τ = 10
  (and at the edges of Γ_C with r = 0.6 there), enough to turn stick vertices into slip ones;
- ``separation``: t = c (1 − q)³ (c = 0.01) with q = 8 (x − 0.45)² + 11 (z − 0.52)²: in contact
  (sliding as above) inside the ellipse q = 1 and separated outside it, k_τ = 300, m_τ = 1
  (p_τ = k_τ t₊: no friction where separated). S = (1 − q)₊ is a placeholder function here (``_S``): wherever S > 0
  its derivatives are those of 1 − q, and every term that uses them keeps a factor S (t₊ = c S³ is
  differentiated at most twice), so the substitution is exact; the scene text prints it as
  ``max(1 - q, 0)``. u is C² with a pressure vanishing like the cube of the distance to the
  ellipse (H^{7/2−ε}), plenty for k = 1. The ellipse passes through no vertex of the
  cube grids (|q − 1| ≥ 0.01 at theirs for n ≤ 16).

One solution serves two bodies: the box [0, 1]³ (faces left/right x, front/back y, bottom/top z:
Γ_C = front, Dirichlet back) and the unit square extruded to depth 1 (sides bottom/right/top/left
y = 0, x = 1, y = 1, x = 0, ends front/back z = 0, 1: Γ_C = bottom, Dirichlet top), the prisms'
family. ``python tests/manufactured_contact3d.py`` writes ``config/scenes/3d/contact_<kind>.yaml``
and ``contact_<kind>_extruded.yaml``; a test regenerates them and checks them symbolically.
"""

from __future__ import annotations

import sys
from pathlib import Path

import sympy
import yaml
from sympy.printing.str import StrPrinter

X, Y, Z = sympy.symbols("x y z")
E, NU = 1000.0, 0.3
K_NORMAL = 1000.0
LAM, MU = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))  # the 3D isotropic C (docs/reference/files.md)
#: the y² terms of u (module docstring): a smooth interior field that Γ_C's conditions do not see
INTERIOR = (0.05 * sympy.cos(X - Y + 2 * Z), -0.03 * sympy.sin(2 * X + Y - Z), 0.04 * sympy.cos(X + Y + Z))
#: the separation curve q = 1 on Γ_C (y = 0): the ellipse w_x (x − x_c)² + w_z (z − z_c)² = 1 of
#: centre (x_c, z_c) = ELLIPSE_CENTRE and weights (w_x, w_z) = ELLIPSE_WEIGHTS (semi-axes 0.354, 0.302)
ELLIPSE_CENTRE, ELLIPSE_WEIGHTS = (0.45, 0.52), (8, 11)
Q = ELLIPSE_WEIGHTS[0] * (X - ELLIPSE_CENTRE[0]) ** 2 + ELLIPSE_WEIGHTS[1] * (Z - ELLIPSE_CENTRE[1]) ** 2
#: (1 − q)₊, a placeholder function (module docstring)
_S = sympy.Function("S")(X, Z)
SLIP_ANGLE = 0.8 + 1.6 * (X - Z)
SLIP_SIZE = 0.02 * (1 + 0.5 * X + 0.3 * Z)
SLIDING = (SLIP_SIZE * sympy.cos(SLIP_ANGLE), SLIP_SIZE * sympy.sin(SLIP_ANGLE))
SLIDING_MULTIPLIER = (sympy.cos(SLIP_ANGLE), sympy.sin(SLIP_ANGLE))
STICK_RADIUS, STICK_ANGLE = 0.3 + 0.3 * sympy.sin(sympy.pi * X) * sympy.sin(sympy.pi * Z), 0.3 + 1.0 * (X + Z)
STICKING_MULTIPLIER = (STICK_RADIUS * sympy.cos(STICK_ANGLE), STICK_RADIUS * sympy.sin(STICK_ANGLE))
PENETRATION = 0.02 * (1 + X + Z)
SEPARATION_SCALE = 0.01
ZERO = (sympy.Integer(0), sympy.Integer(0))
#: kind -> (u_τ on Γ_C, signed penetration t, its positive part t₊, k_τ, m_τ, λ)
KINDS = {
    "sliding": (SLIDING, PENETRATION, PENETRATION, 10.0, 0.0, SLIDING_MULTIPLIER),
    "sticking": (ZERO, PENETRATION, PENETRATION, 100.0, 0.0, STICKING_MULTIPLIER),
    "separation": (SLIDING, SEPARATION_SCALE * (1 - Q) ** 3, SEPARATION_SCALE * _S**3, 300.0, 1.0, SLIDING_MULTIPLIER),
}
#: body -> (domain, Γ_C, the Dirichlet face, the traction faces with their outward normals)
BODIES = {
    "box": (
        {"box": [[0, 0, 0], [1, 1, 1]], "sides": ["left", "right", "front", "back", "bottom", "top"]},
        "front",
        "back",
        {"left": (-1, 0, 0), "right": (1, 0, 0), "bottom": (0, 0, -1), "top": (0, 0, 1)},
    ),
    "extruded": (
        {
            "polygon": [[0, 0], [1, 0], [1, 1], [0, 1]],
            "sides": ["bottom", "right", "top", "left"],
            "extrude": {"depth": 1.0, "ends": ["front", "back"]},
        },
        "bottom",
        "top",
        {"left": (-1, 0, 0), "right": (1, 0, 0), "front": (0, 0, -1), "back": (0, 0, 1)},
    ),
}
#: body -> the mesh of the committed scene (the tests and config/three_d.yaml set family and n)
MESHES = {"box": {"family": "hex", "n": 4}, "extruded": {"family": "voronoi", "n": 4}}
CONFIG = Path(__file__).resolve().parents[1] / "config" / "scenes" / "3d"


class SceneExpressionPrinter(StrPrinter):
    """sympy's text in the scene's expression syntax: ``max`` for (1 − q)₊, ``**``, rationals as (p/q)."""

    def _print_Function(self, expr):
        if expr.func == _S.func:
            return f"max({self._print(1 - Q)}, 0)"
        return super()._print_Function(expr)

    def _print_Rational(self, expr):
        return f"({expr.p}/{expr.q})"

    def _as_ordered_terms(self, expr, order=None):
        """The terms in sympy's order, ties broken by their text: sympy's own order leaves terms such
        as ``c1*y*sin(x - y + 2*z)`` and ``c2*y*sin(x + y + z)`` in hash order (PYTHONHASHSEED)."""
        return sorted(
            super()._as_ordered_terms(expr, order), key=lambda term: (sympy.default_sort_key(term), str(term))
        )


def _positive_part(expr):
    """Derivatives of S = (1 − q)₊ are those of 1 − q wherever S > 0; where S = 0 every term of
    ``expr`` keeps a factor S (module docstring), so the substitution is exact."""
    rules = {}
    for order in (2, 1):
        for dx in range(order + 1):
            dz = order - dx
            derivative = sympy.Derivative(_S, *([(X, dx)] if dx else []), *([(Z, dz)] if dz else []))
            rules[derivative] = sympy.diff(1 - Q, *([(X, dx)] if dx else []), *([(Z, dz)] if dz else []))
    for derivative, value in rules.items():  # second derivatives first: they contain the first ones
        expr = expr.subs(derivative, value)
    return expr


def stress(u):
    """σ(u) = λ tr ε I + 2 μ ε of the 3D isotropic C, a sympy 3 x 3 Matrix."""
    grad = sympy.Matrix(u).jacobian([X, Y, Z])
    eps = (grad + grad.T) / 2
    return LAM * eps.trace() * sympy.eye(3) + 2 * MU * eps


def exact_fields(kind: str) -> dict:
    """The sympy fields of one kind: u, σ, the body force, the gap and the contact law's data."""
    (f1, f3), t, t_plus, k_friction, m_friction, multiplier = KINDS[kind]
    h = -0.1 + 0.03 * sympy.sin(2 * X) * sympy.cos(Z)  # u2 on Γ_C: pressed down onto the foundation
    bound = k_friction * (t_plus if m_friction == 1.0 else 1)  # p_τ(t)
    a1 = bound * multiplier[0] / MU - sympy.diff(h, X)  # σ12 = μ (∂u1/∂y + ∂u2/∂x) = p_τ λ_x at y = 0
    a3 = bound * multiplier[1] / MU - sympy.diff(h, Z)  # σ23 = μ (∂u3/∂y + ∂u2/∂z) = p_τ λ_z
    b = (-K_NORMAL * t_plus - LAM * (sympy.diff(f1, X) + sympy.diff(f3, Z))) / (LAM + 2 * MU)  # σ22 = −k_ν t₊
    u = [f1 + Y * a1 + Y**2 * INTERIOR[0], h + Y * b + Y**2 * INTERIOR[1], f3 + Y * a3 + Y**2 * INTERIOR[2]]
    sigma = stress(u).applyfunc(_positive_part)
    force = [_positive_part(-sum(sympy.diff(sigma[i, j], v) for j, v in enumerate((X, Y, Z)))) for i in range(3)]
    return {
        "u": u,
        "sigma": sigma,
        "force": force,
        "gap": -h - t,
        "t": t,
        "k_friction": k_friction,
        "m_friction": m_friction,
        "multiplier": multiplier,
    }


def contact_scene(kind: str, body: str = "box") -> dict:
    """The scene (a dict for scene_from_dict) on ``body`` whose exact solution is the u of ``kind``."""
    fields = exact_fields(kind)
    text = SceneExpressionPrinter().doprint
    u, sigma = fields["u"], fields["sigma"]
    domain, contact, held, loaded = BODIES[body]
    traction = {
        side: {"traction": [text(sum(sigma[i, j] * n[j] for j in range(3) if n[j])) for i in range(3)]}
        for side, n in loaded.items()
    }
    suffix = "" if body == "box" else f"-{body}"
    return {
        "name": f"manufactured-contact3d-{kind}{suffix}",
        "model": "3d",
        "domain": domain,
        "material": {"E": E, "nu": NU},
        "body_force": [text(c) for c in fields["force"]],
        "boundary": {"dirichlet": {held: [text(c) for c in u]}, "neumann": traction, "contact": [contact]},
        "contact": {
            "gap": text(fields["gap"]),
            "normal": {"k": K_NORMAL, "m": 1.0},
            "friction": {"k": fields["k_friction"], "m": fields["m_friction"]},
        },
        "exact": {"displacement": [text(c) for c in u]},
        "discretization": {"mesh": dict(MESHES[body]), "stabilization": "dofi-2mu"},
        "solver": {"method": "ssn", "tol": 1e-10},
    }


def scene_path(kind: str, body: str = "box") -> Path:
    return CONFIG / (f"contact_{kind}.yaml" if body == "box" else f"contact_{kind}_{body}.yaml")


def scene_text(kind: str, body: str = "box") -> str:
    """The YAML file of one kind on one body, with a header saying where it comes from."""
    header = (
        f"# A manufactured 3D frictional-contact solution, kind '{kind}', on the {body} body: generated by\n"
        "# tests/manufactured_contact3d.py (its docstring has the construction); do not edit by hand,\n"
        "# run `python tests/manufactured_contact3d.py` (a test regenerates and compares this file).\n"
    )
    return header + yaml.safe_dump(contact_scene(kind, body), sort_keys=False, width=100_000)


def main(argv) -> int:
    CONFIG.mkdir(parents=True, exist_ok=True)
    for kind in KINDS:
        for body in BODIES:
            path = scene_path(kind, body)
            path.write_text(scene_text(kind, body), encoding="utf-8")
            print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
