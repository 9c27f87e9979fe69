"""The scene's adaptivity block (docs/reference/files.md): defaults from the schema, overrides, one-line refusals."""

from pathlib import Path

import jsonschema
import pytest

from vemkit.config.scene import SceneError, load_scene, scene_schema
from vemkit.studies.adaptivity import AdaptivitySettings

PAPER = Path(__file__).resolve().parents[2] / "config" / "scenes" / "paper.yaml"
SPEC_DEFAULTS = {
    "estimator": "residual",
    "marking": {"dorfler": 0.5},
    "target": 0.01,
    "max_dofs": 200000,
    "max_steps": 30,
}


def test_the_defaults_are_those_of_spec_9_and_the_filled_block_validates():
    scene = load_scene(PAPER)
    options = scene.adaptivity_options
    assert {k: options[k] for k in SPEC_DEFAULTS} == SPEC_DEFAULTS
    assert options["max_hanging"] is None and options["reference"] is None
    jsonschema.Draft202012Validator(scene_schema()).validate(scene.data)
    options["marking"]["dorfler"] = 0.9  # a copy: the scene is immutable
    assert scene.adaptivity_options["marking"]["dorfler"] == 0.5


def test_a_partial_block_is_completed_and_becomes_the_settings():
    scene = load_scene(PAPER, ["adaptivity={marking: {dorfler: 0.3}, max_hanging: 2}", "adaptivity.max_dofs=5000"])
    assert scene.adaptivity_options["target"] == 0.01 and scene.adaptivity_options["max_steps"] == 30
    settings = AdaptivitySettings.from_scene(scene)
    assert settings == AdaptivitySettings(theta=0.3, target=0.01, max_dofs=5000, max_steps=30, max_hanging=2)
    assert AdaptivitySettings.from_scene(scene, max_dofs=1000).max_dofs == 1000  # --max-dofs caps it
    assert AdaptivitySettings.from_scene(scene, max_dofs=10**7).max_dofs == 5000
    again = load_scene(PAPER, ["adaptivity={marking: {dorfler: 0.3}, max_hanging: 2}"]).with_overrides([])
    assert again.adaptivity_options["marking"] == {"dorfler": 0.3}


@pytest.mark.parametrize(
    "override, named",
    [
        ("adaptivity.marking.dorfler=0", "adaptivity.marking.dorfler = 0: must be > 0"),
        ("adaptivity.marking.dorfler=1.01", "adaptivity.marking.dorfler = 1.01: must be <= 1"),
        ("adaptivity.target=-0.1", "adaptivity.target = -0.1: must be > 0"),
        ("adaptivity.target=2", "adaptivity.target = 2: must be <= 1"),
        ("adaptivity.max_dofs=0", "adaptivity.max_dofs = 0: must be >= 1"),
        ("adaptivity.max_steps=1.5", "adaptivity.max_steps = 1.5: must be an integer"),
        ("adaptivity.max_hanging=-1", "adaptivity.max_hanging = -1: must be >= 1"),
        ("adaptivity.estimator=recovery", "adaptivity.estimator = 'recovery': must be one of residual"),
        ("adaptivity.marking.theta=0.5", "unknown key 'adaptivity.marking.theta'"),
        ("adaptivity=[1, 2]", "adaptivity = [1, 2]: must be a mapping"),
        ("adaptivity.reference=''", "adaptivity.reference = '': must not be empty"),
    ],
)
def test_bad_values_are_one_line_errors_naming_the_key(override, named):
    with pytest.raises(SceneError) as error:
        load_scene(PAPER, [override])
    message = str(error.value)
    assert named in message and "\n" not in message
