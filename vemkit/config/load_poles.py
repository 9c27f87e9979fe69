"""A load that cannot be integrated along the edges that carry it: a pole between two vertices.

The loads of Section 3.3 integrate a traction or pressure p along each loaded edge with a few Gauss
points. p is checked finite at the mesh's vertices first (``check_expressions_on_mesh``), but a pole
strictly between two vertices, ``1/(x - 0.5)`` on an edge from x = 0 to x = 1, falls between the
Gauss points: every sample is finite, the "integral" is a number, and the load is nonsense (the
exact one does not exist). Sampling densely does not settle it either: a pole is almost never hit
exactly, and a bounded but large, smooth load looks alike at any fixed resolution.

The test here measures the singularity itself, per edge (vectorized over the edges):

1. locate the largest |p| on the edge by zooming: ``SAMPLES`` equally spaced points of the current
   bracket (the ends included), the bracket shrunk to the two spacings around the largest sample,
   ``LEVELS`` times (the bracket ends 16^-LEVELS ~ 1e-12 of the edge wide). A pole is where |p| is
   largest, and it stays inside the bracket; a non-finite sample (the pole hit) is refused at once
   by the expression itself, naming its key and the point;
2. at the point t* found, measure how fast |p| grows towards it: with |p| ~ C d^-alpha at the
   distance d (a fraction of the edge), alpha = log(|p(t* ± NEAR)| / |p(t* ± FAR)|) / log(FAR / NEAR),
   on each side of t* that lies on the edge. A smooth load (its maximum at t*), a jump or a log
   singularity give alpha ~ 0 (log: 0.06); 1/sqrt|d| gives 0.5, 1/d gives 1, 1/|d|^1.5 gives 1.5.
   d^-alpha is integrable iff alpha < 1: the edge is refused when alpha >= ``NON_INTEGRABLE`` (0.9:
   the rounding of t* and of the measure, measured well below 0.05, stays clear of 1; an integrable
   singularity with 0.9 <= alpha < 1 is refused too, and no Gauss rule resolves it anyway).

Cost: SAMPLES * LEVELS + 4 evaluations per loaded edge, in chunks of ``CHUNK`` edges.
"""

from __future__ import annotations

import numpy as np

from vemkit.config.expression_tree import shorten
from vemkit.exceptions import ExpressionError, SceneError

__all__ = ["NON_INTEGRABLE", "check_integrable_on_edges"]

SAMPLES = 33  # points of the bracket per level, its ends included: it shrinks 16x per level
LEVELS = 10  # 16^-10 ~ 1e-12 of the edge: the pole located far closer than NEAR
NEAR, FAR = 1e-9, 1e-6  # the distances (fractions of the edge) at which the growth is measured
NON_INTEGRABLE = 0.9  # alpha at or above this: not integrable (module docstring)
CHUNK = 4096  # edges per pass (bounded memory)


def _values(expression, pa: np.ndarray, pb: np.ndarray, t: np.ndarray) -> np.ndarray:
    """|p| at x = (1 - t) x_a + t x_b for t (E, k); ExpressionError (naming the key) if not finite."""
    x = pa[:, None, :] * (1.0 - t)[..., None] + pb[:, None, :] * t[..., None]
    return np.abs(expression(*(x[..., i] for i in range(x.shape[-1]))))


def _growth(expression, pa, pb) -> tuple[np.ndarray, np.ndarray]:
    """(alpha (E,), t* (E,)): the growth exponent of |p| at its largest point t* of each edge."""
    n = pa.shape[0]
    rows = np.arange(n)
    lo, hi = np.zeros(n), np.ones(n)
    s = np.linspace(0.0, 1.0, SAMPLES)
    for _ in range(LEVELS):
        t = lo[:, None] + (hi - lo)[:, None] * s[None, :]
        centre = t[rows, np.argmax(_values(expression, pa, pb, t), axis=1)]
        step = (hi - lo) / (SAMPLES - 1)
        lo, hi = np.maximum(centre - step, 0.0), np.minimum(centre + step, 1.0)
    alpha = np.zeros(n)
    for sign in (-1.0, 1.0):
        near, far = centre + sign * NEAR, centre + sign * FAR
        on = (far >= 0.0) & (far <= 1.0)
        if not on.any():
            continue
        both = _values(expression, pa[on], pb[on], np.stack([near[on], far[on]], axis=1))
        floor = np.finfo(float).tiny
        slope = np.log((both[:, 0] + floor) / (both[:, 1] + floor)) / np.log(FAR / NEAR)
        alpha[on] = np.maximum(alpha[on], slope)
    return alpha, centre


def check_integrable_on_edges(expression, pa: np.ndarray, pb: np.ndarray, side: str) -> None:
    """Refuse ``expression`` (a compiled scene expression, its ``name`` the scene key) if it is not
    finite or not integrable on one of the edges from ``pa`` to ``pb`` ((E, 2) each) of ``side``:
    a one-line SceneError naming the key, the side, the point and the fix (module docstring)."""
    if getattr(expression, "is_constant", False) or pa.shape[0] == 0:
        return
    for start in range(0, pa.shape[0], CHUNK):
        a, b = pa[start : start + CHUNK], pb[start : start + CHUNK]
        try:
            alpha, t = _growth(expression, a, b)
        except ExpressionError as error:
            raise SceneError(f"{error} (between two vertices of side {side!r})", key=expression.name) from None
        worst = int(np.argmax(alpha))
        if alpha[worst] >= NON_INTEGRABLE:
            point = ", ".join(f"{c:.6g}" for c in a[worst] * (1.0 - t[worst]) + b[worst] * t[worst])
            raise SceneError(
                f"{expression.name} = {shorten(expression.text)!r}: not integrable on side {side!r}: "
                f"it grows like 1/d^{alpha[worst]:.2g} at the distance d from ({point}), a pole between "
                "two vertices; give a load that is finite on the side (move the pole off it)",
                key=expression.name,
            )
