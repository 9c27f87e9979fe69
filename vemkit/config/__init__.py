"""Layer 1, input: scene files and the expressions inside them.

Owns the scene schema (``schemas/scene.schema.json``: keys, types, bounds, defaults), loading and
validating a scene (:func:`load_scene`, one-line :class:`~vemkit.exceptions.SceneError`), and the
whitelisted expression compiler (never ``eval``). Imports from vemkit: ``vemkit.exceptions`` only.
"""

from vemkit.config.expressions import Expression, compile_expression
from vemkit.config.scene import Scene, load_scene, scene_from_dict, scene_from_yaml

__all__ = ["Expression", "Scene", "compile_expression", "load_scene", "scene_from_dict", "scene_from_yaml"]
