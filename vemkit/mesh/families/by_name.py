"""The 2D mesh families by name: ``build_mesh(family, n, domain=..., **options)`` and the checks
of a family's name, kind and options (``family_builder``). Below both the 2D package
(``vemkit.mesh.families``) and the 3D families (``vemkit.mesh.families3d.build`` meshes the base
of an extruded body with it), so that neither imports the other's package."""

from __future__ import annotations

import inspect
from collections.abc import Callable

from vemkit.config.domain import cells_per_length, domain_from_spec
from vemkit.exceptions import MeshError
from vemkit.mesh.families.hanging import hanging
from vemkit.mesh.families.square import square, structured_triangle
from vemkit.mesh.families.triangle import delaunay_triangle
from vemkit.mesh.families.voronoi import voronoi
from vemkit.mesh.mesh import Mesh

FAMILIES = ("square", "triangle", "voronoi", "hanging")
TRIANGLE_KINDS = ("delaunay", "structured")

_BUILDERS: dict[str | tuple[str, str], Callable[..., Mesh]] = {
    "square": square,
    ("triangle", "delaunay"): delaunay_triangle,
    ("triangle", "structured"): structured_triangle,
    "voronoi": voronoi,
    "hanging": hanging,
}


def family_builder(family: str, options: dict):
    """The builder of ``family`` for ``options`` (``kind`` removed from them); MeshError (an
    InputError) naming the family or the option that does not apply to it."""
    if family not in FAMILIES:
        raise MeshError(f"mesh family {family!r} is unknown; valid families: {', '.join(FAMILIES)}", key="family")
    key: str | tuple[str, str] = family
    if family == "triangle":
        kind = options.pop("kind", "delaunay")
        if kind not in TRIANGLE_KINDS:
            raise MeshError(
                f"triangle mesh kind {kind!r} is unknown; valid kinds: {', '.join(TRIANGLE_KINDS)}", key="kind"
            )
        key = (family, kind)
    builder = _BUILDERS[key]
    valid = [p for p in inspect.signature(builder).parameters if p not in ("n", "domain")]
    unknown = sorted(set(options) - set(valid))
    if unknown:
        name = family if family != "triangle" else f"triangle (kind={key[1]})"
        listing = ", ".join(valid + (["kind"] if family == "triangle" else [])) or "none"
        raise MeshError(
            f"mesh option {unknown[0]!r} is not valid for family {name}; valid options: {listing}", key=unknown[0]
        )
    return builder


def build_mesh(
    family: str, n: float | None = None, *, domain=None, h: float | None = None, cells: float | None = None, **options
) -> Mesh:
    """The mesh of ``family`` on ``domain``, made with ``options``.

    ``domain``: a :class:`~vemkit.config.domain.Domain`, its docs/reference/files.md mapping or None (the unit
    square). Size: exactly one of ``n`` (cells per unit length, n = 1/h: about n² cells per unit
    area), ``h`` or ``cells`` (about that many cells). On the unit square with a whole n every
    family makes exactly the mesh it always made.
    """
    builder = family_builder(family, options)
    region = domain_from_spec(domain)
    n = cells_per_length(region, n, h, cells, 2.0 if family == "triangle" else 1.0)
    if region.is_unit_square:
        return builder(n, **options)
    if builder is structured_triangle:
        raise MeshError(
            "triangle kind structured is a unit-square family; use kind delaunay on this domain", key="kind"
        )
    return builder(n, domain=region, **options)
