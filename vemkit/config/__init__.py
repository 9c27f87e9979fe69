"""Layer 1, input: scene files and the expressions inside them.

Owns the body (``domain``: :class:`Domain`, an outer polygon and holes with named sides, docs/reference/files.md),
the scene schema (``schemas/scene.schema.json``: keys, types, bounds, defaults), loading and
validating a scene (:func:`load_scene`, one-line :class:`~vemkit.exceptions.SceneError`), and the
whitelisted expression compiler (never ``eval``). Imports from vemkit: ``vemkit.exceptions`` only.
"""

from vemkit.config.domain import Domain, domain_from_spec
from vemkit.config.expressions import Expression, compile_expression
from vemkit.config.scene import Scene, load_scene, scene_from_dict, scene_from_yaml

__all__ = [
    "Domain",
    "Expression",
    "domain_from_spec",
    "Scene",
    "compile_expression",
    "load_scene",
    "scene_from_dict",
    "scene_from_yaml",
]
