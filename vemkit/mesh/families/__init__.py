"""Mesh families of the unit square, by name: ``build_mesh("voronoi", 32, seed=1)``.

- ``square``: n x n squares (no options);
- ``triangle``: ``kind="delaunay"`` (default; options ``seed``, ``min_angle``) about 2 n² quality
  Delaunay triangles, or ``kind="structured"`` the n x n grid cut along diagonals;
- ``voronoi``: about n² centroidal Voronoi cells (``seed``, ``lloyd_iterations``, ``anisotropy``,
  ``merge_tol``);
- ``hanging``: n x n squares quadrisected ``levels`` times (``levels``, ``rule``, ``seed``,
  ``fraction``, ``contact_side``).
"""

from __future__ import annotations

import inspect

from vemkit.mesh.families.hanging import hanging
from vemkit.mesh.families.square import square, structured_triangle
from vemkit.mesh.families.triangle import delaunay_triangle
from vemkit.mesh.families.voronoi import voronoi
from vemkit.mesh.mesh import Mesh

FAMILIES = ("square", "triangle", "voronoi", "hanging")
TRIANGLE_KINDS = ("delaunay", "structured")

_BUILDERS = {
    "square": square,
    ("triangle", "delaunay"): delaunay_triangle,
    ("triangle", "structured"): structured_triangle,
    "voronoi": voronoi,
    "hanging": hanging,
}


def build_mesh(family: str, n: int, **options) -> Mesh:
    """The mesh of ``family`` with n cells per side (n = 1/h), made with ``options``."""
    if family not in FAMILIES:
        raise ValueError(f"mesh family {family!r} is unknown; valid families: {', '.join(FAMILIES)}")
    key = family
    if family == "triangle":
        kind = options.pop("kind", "delaunay")
        if kind not in TRIANGLE_KINDS:
            raise ValueError(f"triangle mesh kind {kind!r} is unknown; valid kinds: {', '.join(TRIANGLE_KINDS)}")
        key = (family, kind)
    builder = _BUILDERS[key]
    valid = [p for p in inspect.signature(builder).parameters if p != "n"]
    unknown = sorted(set(options) - set(valid))
    if unknown:
        name = family if family != "triangle" else f"triangle (kind={key[1]})"
        listing = ", ".join(valid + (["kind"] if family == "triangle" else [])) or "none"
        raise ValueError(f"mesh option {unknown[0]!r} is not valid for family {name}; valid options: {listing}")
    return builder(n, **options)


__all__ = ["FAMILIES", "TRIANGLE_KINDS", "build_mesh", "square", "structured_triangle", "delaunay_triangle",
           "voronoi", "hanging"]


def scene_mesh(scene) -> Mesh:
    """The mesh a scene (``vemkit.config.Scene``) asks for."""
    opts = scene.mesh_options
    family, n = opts.pop("family"), opts.pop("n")
    return build_mesh(family, n, **opts)  # options were checked by the scene schema and build_mesh
