"""The material law of a scene's model (docs/reference/mathematics.md and docs/reference/files.md): the Lamé parameters of C, the one home of the formulas.

- ``plane_stress`` (the default, the paper's C): lambda* = E nu / (1 - nu^2), mu = E / (2 (1 + nu));
- ``plane_strain`` (a long prism with u3 = 0): lambda = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu)),
  and the out-of-plane stress sigma33 = lambda (eps11 + eps22) = nu (sigma11 + sigma22);
- ``3d`` (a body in three dimensions): the same lambda and mu as plane strain, now of the full 3 x 3
  strain (C eps = lambda tr(eps) I + 2 mu eps).
"""

from __future__ import annotations

MODELS = ("plane_stress", "plane_strain", "3d")


def lame_parameters(E: float, nu: float, model: str = "plane_stress") -> tuple[float, float]:
    """(lambda, mu) of C for ``model`` (module docstring)."""
    mu = E / (2.0 * (1.0 + nu))
    if model == "plane_stress":
        return E * nu / (1.0 - nu * nu), mu
    if model in ("plane_strain", "3d"):
        return E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu
    raise ValueError(f"model {model!r} is unknown; use one of {', '.join(MODELS)}")
