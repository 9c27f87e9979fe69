"""The laws of a scene's ``contact`` block as plain data: the power law and the tabulated normal compliance.

``contact.normal`` names its law (``law: power``, the default when absent, with ``k`` and ``m``;
``law: table`` with ``penetration`` and ``pressure``); ``contact.friction`` is always a power law.
:func:`normal_compliance` reads the block (``Scene.normal_compliance``), :func:`check_normal_compliance`
refuses a bad one with one line naming the key (scene loading), :func:`check_table` the table itself
(also ``vemkit.contact.laws.TabulatedContactLaw``).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from vemkit.exceptions import SceneError


class PowerLaw(NamedTuple):
    """``p(t) = k (t)_+^m`` (5.1)."""

    k: float
    m: float
    law = "power"


class TabulatedLaw(NamedTuple):
    """p_nu piecewise linear through (penetration[i], pressure[i]), the last slope beyond the table."""

    penetration: tuple
    pressure: tuple
    law = "table"


#: the keys each ``contact.normal.law`` takes (besides ``law``)
NORMAL_LAW_KEYS = {"power": ("k", "m"), "table": ("penetration", "pressure")}


def normal_compliance(normal: dict) -> PowerLaw | TabulatedLaw:
    """The law of a validated ``contact.normal`` block."""
    if normal.get("law", "power") == "table":
        return TabulatedLaw(tuple(normal["penetration"]), tuple(normal["pressure"]))
    return PowerLaw(normal["k"], normal["m"])


def check_normal_compliance(normal: dict, max_slope: float = math.inf) -> None:
    """The keys of ``contact.normal`` are its law's, and a table is a valid one whose slopes stay at
    most ``max_slope`` (the limit contact.normal.k has against material.E); one-line SceneError."""
    law = normal.get("law", "power")
    wanted = NORMAL_LAW_KEYS[law]
    for key in wanted:
        if key not in normal:
            example = "k: 10, m: 1" if law == "power" else "penetration: [0, 0.01], pressure: [0, 5]"
            raise SceneError(
                f"contact.normal.{key} is missing (law {law} takes {' and '.join(wanted)}); "
                f"add it to the scene, e.g. contact.normal: {{law: {law}, {example}}}",
                key=f"contact.normal.{key}",
            )
    for key in normal:
        if key != "law" and key not in wanted:
            raise SceneError(
                f"contact.normal.{key}: not a key of law {law} (it takes {' and '.join(wanted)}); "
                f"drop it or set contact.normal.law",
                key=f"contact.normal.{key}",
            )
    if law == "table":
        check_table(normal["penetration"], normal["pressure"])
        points, values = normal["penetration"], normal["pressure"]
        slope = max((values[i] - values[i - 1]) / (points[i] - points[i - 1]) for i in range(1, len(points)))
        if slope > max_slope:
            raise SceneError(
                f"contact.normal.pressure rises with slope {slope:g}: must be at most {max_slope:g} "
                "(1e9 material.E, as contact.normal.k; stiffer is rigid contact, beyond double precision); "
                "fix the table",
                key="contact.normal.pressure",
            )


def check_table(penetration, pressure) -> None:
    """Penetrations increase from 0, pressures start at 0 and never decrease, as many of each (>= 2)."""
    points, values = list(penetration), list(pressure)
    if len(points) != len(values):
        raise SceneError(
            f"contact.normal.pressure has {len(values)} entries against {len(points)} penetrations; "
            "give one pressure per penetration",
            key="contact.normal.pressure",
        )
    if len(points) < 2:
        raise SceneError(
            "contact.normal.penetration: give at least two points, e.g. [0, 0.01]", key="contact.normal.penetration"
        )
    if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in points + values):
        raise SceneError("contact.normal: penetration and pressure must be finite numbers", key="contact.normal")
    if points[0] != 0.0 or values[0] != 0.0:
        key = "contact.normal.penetration" if points[0] != 0.0 else "contact.normal.pressure"
        raise SceneError(
            f"{key} must start at 0 (the table starts at penetration 0 with pressure 0); got {points[0]:g} -> "
            f"{values[0]:g}",
            key=key,
        )
    for i in range(1, len(points)):
        if not points[i] > points[i - 1]:
            raise SceneError(
                f"contact.normal.penetration must increase: entry {i} ({points[i]:g}) is not above "
                f"entry {i - 1} ({points[i - 1]:g}); sort the table",
                key="contact.normal.penetration",
            )
        if values[i] < values[i - 1]:
            raise SceneError(
                f"contact.normal.pressure must not decrease: entry {i} ({values[i]:g}) is below "
                f"entry {i - 1} ({values[i - 1]:g}); a foundation's pressure grows with the penetration",
                key="contact.normal.pressure",
            )
