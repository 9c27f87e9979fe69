"""``discretization.volumetric_strain`` (vemkit/config/volumetric.py): what ``auto`` resolves to, and
``nodal_average`` refused at order 2 in one line naming the key."""

import pytest

from vemkit.config.scene import scene_from_dict
from vemkit.exceptions import SceneError


def _scene(model="plane_strain", nu=0.4999, order=1, treatment=None):
    discretization = {"mesh": {"family": "square", "n": 2}, "order": order}
    if treatment is not None:
        discretization["volumetric_strain"] = treatment
    return scene_from_dict(
        {
            "name": "volumetric",
            "model": model,
            "domain": "unit_square",
            "material": {"E": 1.0, "nu": nu},
            "boundary": {"dirichlet": ["left"]},
            "discretization": discretization,
        }
    )


@pytest.mark.parametrize(
    "settings, resolved",
    [
        (dict(), "nodal_average"),  # k = 1, plane strain, nu > 0.45
        (dict(nu=0.45), "cell"),  # every result at nu <= 0.45 as it was
        (dict(nu=0.4501), "nodal_average"),
        (dict(model="plane_stress"), "cell"),  # lambda* <= 2 mu: plane stress does not lock
        (dict(order=2), "cell"),  # k = 2 does not lock
        (dict(treatment="cell"), "cell"),
        (dict(nu=0.3, treatment="nodal_average"), "nodal_average"),
        (dict(model="plane_stress", treatment="nodal_average"), "nodal_average"),
    ],
)
def test_auto_resolves_to_nodal_average_for_k1_on_a_locking_model_above_0_45(settings, resolved):
    scene = _scene(**settings)
    assert scene.volumetric_strain == resolved
    assert scene.data["discretization"]["volumetric_strain"] == settings.get("treatment", "auto")


def test_a_3d_body_above_0_45_averages_at_the_nodes():
    scene = scene_from_dict(
        {
            "name": "box",
            "domain": {"box": [[0, 0, 0], [1, 1, 1]]},
            "material": {"E": 1.0, "nu": 0.49},
            "boundary": {"dirichlet": ["left"]},
            "discretization": {"mesh": {"family": "hex", "n": 2}},
        }
    )
    assert scene.model == "3d" and scene.volumetric_strain == "nodal_average"


def test_nodal_average_at_order_2_is_refused_naming_the_key_and_the_fix():
    with pytest.raises(SceneError, match="does not lock.*volumetric_strain=cell") as caught:
        _scene(order=2, treatment="nodal_average")
    assert caught.value.key == "discretization.volumetric_strain"


def test_the_resource_prediction_counts_the_wider_stencil():
    """nodal_average's stiffness holds up to 3 (2D) times the entries: the predicted memory beyond
    the fixed base grows as much, before any mesh is built."""
    from vemkit.config.limits import BASE_BYTES, check_scene_resources

    cell = check_scene_resources(_scene(treatment="cell"), None)
    nodal = check_scene_resources(_scene(treatment="nodal_average"), None)
    assert (cell.cells, cell.dofs) == (nodal.cells, nodal.dofs)
    assert nodal.peak_bytes - BASE_BYTES == pytest.approx(3.0 * (cell.peak_bytes - BASE_BYTES), rel=1e-9)
