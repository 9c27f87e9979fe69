"""Which rigid motion a Dirichlet set leaves free (docs/reference/files.md), in linear time and memory.

A rigid motion is u(x) = a + ω × x: in 2D u = (a1 − θ y, a2 + θ x) (three modes), in 3D six. A
prescribed component i at a point x holds the functional r = e_i·a + (ω × x)_i. The motion is held
iff these functionals span all the modes, i.e. iff their Gram matrix Σ r rᵀ (3 x 3, or 6 x 6) is
regular. The translation a_i meets only the rows of component i, so its block is n_i, the number
of points where u_i is prescribed, and eliminating it leaves the Schur complement on ω

    S = Σ_i Σ_{x ∈ X_i} ρ_i(x − x̄_i) ρ_i(x − x̄_i)ᵀ,     ρ_i(x) = ∂(ω × x)_i / ∂ω,

x̄_i the mean of the points X_i of component i: 2D, S = Σ_{X_1} (y − ȳ_1)² + Σ_{X_2} (x − x̄_2)²
(a scalar); 3D, a 3 x 3 matrix. Hence: a translation is free iff some component is prescribed
nowhere; otherwise a rotation is free iff S is singular, and then about the point (x̄_2, ȳ_1) in 2D
(every u1 point on the line y = ȳ_1, every u2 point on x = x̄_2). Each sum is one pass over the
points; the points are first shifted by one of their own and scaled by the set's extent, so that an
exactly degenerate set (all u1 points on one line) gives S = 0 exactly and the test is scale-free.
S counts as singular when a diagonal entry is below ``RANK_TOL``² · max_i n_i (the singular value
ratio 1e-9 of the full constraint matrix, as before this module; the matrix itself, N x 3, and its
SVD, quadratic in N, are never formed), or in 3D when the smallest eigenvalue of S scaled to a unit
diagonal (D^-1/2 S D^-1/2, D = diag S: singular together with S) is below ``EIGEN_ROUNDING`` times its
largest (the rounding of the eigenvalue solver). The scaling makes the test relative per axis: the
rotation about the thin axis of a 1 x 1 x 1e-7 plate clamped on a narrow side has an eigenvalue of S
near 1e-15 of the others, which an unscaled test takes for rounding; the 2D S is one sum, exactly 0
for a degenerate set.
"""

from __future__ import annotations

import numpy as np

__all__ = ["RANK_TOL", "free_rigid_motion"]

RANK_TOL = 1e-9  # smallest / largest singular value of the constraints below which a mode is free
EIGEN_ROUNDING = 1e3 * np.finfo(float).eps  # 3D: eigh's rounding of the smallest eigenvalue of S, relative
_AXES = "xyz"


def _plane_rows(c: np.ndarray, component: int) -> np.ndarray:
    """ρ_i at the centred points ``c`` (N, 2): (N, 1), (ω × c)_i = ρ_i ω of the one rotation θ."""
    return (-c[:, 1:2]) if component == 0 else c[:, 0:1]


def _solid_rows(c: np.ndarray, component: int) -> np.ndarray:
    """ρ_i at the centred points ``c`` (N, 3): (N, 3), (ω × c)_i = ρ_i · ω."""
    x, y, z = c.T
    zero = np.zeros_like(x)
    rows = ((zero, z, -y), (-z, zero, x), (y, -x, zero))[component]
    return np.stack(rows, axis=1)


#: ρ_i by the dimension (the rounding of S in each is the one of before this table: a (N, 1) column
#: in the plane, a (N, 3) table in space)
_ROTATION_ROWS = {2: _plane_rows, 3: _solid_rows}


def _schur(points: np.ndarray, prescribed: np.ndarray):
    """(S, means, counts, shift, scale): the Schur complement on ω (module docstring), per-component
    means of the points (in the original coordinates) and the counts n_i."""
    shift = points[0]
    extent = float(np.ptp(points, axis=0).max())
    scale = extent if extent > 0 else 1.0
    d = points.shape[1]
    modes = d * (d - 1) // 2  # the rotations of R^d
    S = np.zeros((modes, modes))
    means, counts = np.zeros((d, d)), np.zeros(d, dtype=np.int64)
    for i in range(d):
        held = (points[prescribed[:, i]] - shift) / scale  # exact zeros for points equal to the shift
        counts[i] = held.shape[0]
        centre = held.mean(axis=0)
        rho = _ROTATION_ROWS[d](held - centre, i)
        S += rho.T @ rho
        means[i] = shift + scale * centre
    return S, means, counts


def _about_point(omega: np.ndarray, means: np.ndarray) -> str:
    """2D: about (x̄_2, ȳ_1): every u1 point on y = ȳ_1, every u2 point on x = x̄_2."""
    return f"a rotation about ({means[1][0]:.6g}, {means[0][1]:.6g})"


def _about_axis(omega: np.ndarray, means: np.ndarray) -> str:
    """3D: about the axis along ω through the point where u_i = 0 at the mean of X_i."""
    omega = omega / np.linalg.norm(omega)
    a = np.array([-np.cross(omega, means[i])[i] for i in range(3)])
    through = np.cross(omega, a)
    return (
        f"a rotation about the axis along ({omega[0]:.3g}, {omega[1]:.3g}, {omega[2]:.3g}) through "
        f"({through[0]:.6g}, {through[1]:.6g}, {through[2]:.6g})"
    )


#: the words of a free rotation by the dimension: about a point in the plane, about an axis in space
_ROTATION_WORDS = {2: _about_point, 3: _about_axis}


def _rotation_words(points, omega: np.ndarray, means: np.ndarray) -> str:
    return _ROTATION_WORDS[points.shape[1]](omega, means)


def free_rigid_motion(coordinates: np.ndarray, prescribed: np.ndarray) -> str | None:
    """Which rigid motion keeps every prescribed component at zero change, in words; None when the
    prescribed components (``prescribed[k, i]``: u_i at ``coordinates[k]``, 2 or 3 columns) hold all
    of them. Linear in the number of points (module docstring)."""
    points = np.asarray(coordinates, dtype=float)
    prescribed = np.asarray(prescribed, dtype=bool)
    if points.shape[0] == 0 or not prescribed.any():
        return "every rigid motion (nothing is prescribed)"
    for component in range(points.shape[1]):
        if not prescribed[:, component].any():
            return f"a translation in {_AXES[component]}"
    S, means, counts = _schur(points, prescribed)
    diagonal = np.diag(S).copy()
    if diagonal.min() <= RANK_TOL**2 * counts.max():  # no spread at all about one axis
        return _rotation_words(points, np.eye(S.shape[0])[:, int(np.argmin(diagonal))], means)
    scale = 1.0 / np.sqrt(diagonal)
    values, vectors = np.linalg.eigh(S * np.outer(scale, scale))
    if values[0] > EIGEN_ROUNDING * values[-1]:
        return None
    return _rotation_words(points, scale * vectors[:, 0], means)
