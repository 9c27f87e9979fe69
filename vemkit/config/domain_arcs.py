"""The arcs of a domain's outer boundary (docs/reference/files.md, ``domain.arcs``): an edge may be
the shorter arc (less than a half circle) of the circle through its two corners about a centre; its
angles, the chords that stand for it at a cell size, its bounding box, and the validation of the
scene's ``arcs`` entry (:func:`arcs_from_spec`, one-line ``InputError`` naming ``domain.arcs[i]``).
"""

from __future__ import annotations

import math

import numpy as np

from vemkit.exceptions import InputError

__all__ = ["MIN_CIRCLE_VERTICES", "arc_angles", "arc_box", "arc_chords", "arc_points", "arcs_from_spec", "point_words"]

#: fewest vertices of the polygon that stands for a circle (and of the chords of a full turn of arcs)
MIN_CIRCLE_VERTICES = 8


def arc_angles(a, b, centre) -> tuple:
    """(r, t0, dt) of the shorter arc from corner a to corner b around ``centre``: radius (the
    distance to a), start angle and signed sweep, |dt| < π (dt > 0: counter-clockwise)."""
    (ax, ay), (bx, by), (cx, cy) = a, b, centre
    t0 = math.atan2(ay - cy, ax - cx)
    dt = math.remainder(math.atan2(by - cy, bx - cx) - t0, 2.0 * math.pi)
    return math.hypot(ax - cx, ay - cy), t0, dt


def arc_chords(r: float, dt: float, h: float | None) -> int:
    """Chords that stand for an arc of radius r and sweep dt at cell size h (``None``: half-degree
    steps, the resolution at which a domain is validated)."""
    step = abs(dt) * MIN_CIRCLE_VERTICES / (2.0 * math.pi)
    fine = abs(dt) / (math.pi / 360.0) if h is None else r * abs(dt) / h
    return max(1, math.ceil(step - 1e-12), math.ceil(fine - 1e-12))


def arc_points(a, b, centre, h: float | None) -> np.ndarray:
    """The points strictly between corners a and b on their arc, in order from a (chords of about h)."""
    r, t0, dt = arc_angles(a, b, centre)
    m = arc_chords(r, dt, h)
    t = t0 + dt * np.arange(1, m) / m
    return np.stack([centre[0] + r * np.cos(t), centre[1] + r * np.sin(t)], axis=1)


def arc_box(a, b, centre) -> tuple:
    """(x0, y0, x1, y1) of an arc: its corners and the circle's axis extremes it passes."""
    r, t0, dt = arc_angles(a, b, centre)
    xs, ys = [a[0], b[0]], [a[1], b[1]]
    for k in range(-4, 5):  # the angles k π/2 within the sweep
        s = (k * 0.5 * math.pi - t0) / dt if dt else -1.0
        if 0.0 < s < 1.0:
            xs.append(centre[0] + r * round(math.cos(k * 0.5 * math.pi)))
            ys.append(centre[1] + r * round(math.sin(k * 0.5 * math.pi)))
    return min(xs), min(ys), max(xs), max(ys)


def arcs_from_spec(value, corners: list) -> tuple:
    """The validated ``domain.arcs``: () when absent or all null, else one centre or None per edge."""
    if value is None:
        return ()
    k = len(corners)
    if not isinstance(value, (list, tuple)) or len(value) != k:
        count = len(value) if isinstance(value, (list, tuple)) else "no list of"
        raise InputError(
            f"domain.arcs has {count} entries but the polygon has {k} edges; give one per edge i -> "
            "i+1: null (straight) or the centre [cx, cy] of its arc",
            key="domain.arcs",
        )
    centres = [
        None if entry is None else _arc_centre(entry, corners[i], corners[(i + 1) % k], f"domain.arcs[{i}]")
        for i, entry in enumerate(value)
    ]
    return tuple(centres) if any(c is not None for c in centres) else ()


def _arc_centre(entry, a, b, key: str) -> tuple:
    try:
        cx, cy = (float(v) for v in entry)
    except (TypeError, ValueError):
        cx = cy = float("nan")
    if not (math.isfinite(cx) and math.isfinite(cy)):
        raise InputError(f"{key}: give null or the centre [cx, cy] (two finite numbers) of the edge's arc", key=key)
    ra, rb = math.hypot(a[0] - cx, a[1] - cy), math.hypot(b[0] - cx, b[1] - cy)
    if abs(ra - rb) > 1e-9 * max(ra, rb):
        raise InputError(
            f"{key}: the corners {point_words(a)} and {point_words(b)} are at distances {ra:.12g} and {rb:.12g} from "
            f"the centre {point_words((cx, cy))}; give a centre equally far from both",
            key=key,
        )
    mid = math.hypot(0.5 * (a[0] + b[0]) - cx, 0.5 * (a[1] + b[1]) - cy)
    if mid <= 1e-9 * ra:
        raise InputError(
            f"{key}: the centre {point_words((cx, cy))} is the middle of the edge, so the arc would be a half "
            "circle; split the edge at a corner on the circle (each arc less than a half circle)",
            key=key,
        )
    return (cx, cy)


def point_words(p) -> str:
    """A point (x, y) in a message: ``(x, y)`` with %g."""
    return f"({p[0]:g}, {p[1]:g})"
