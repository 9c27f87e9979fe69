"""Curved outer sides (``domain.arcs``, an extension of docs/reference/files.md): the geometry of the arcs (exact area,
vertices on the circle, chords of about h, bounds), validation with one-line errors naming the
entry, and the arcs through the scene loader and the real CLI."""

import math
import subprocess
import sys

import numpy as np
import pytest

from vemkit.config.domain import Domain, domain_from_spec
from vemkit.config.scene import scene_from_dict
from vemkit.exceptions import InputError, SceneError

# a half-disk of radius 2 below y = 0, flat side up: the half circle is two quarter arcs
R = 2.0
HALF_DISK = {"polygon": [[-R, 0], [0, -R], [R, 0]], "sides": ["rim", "rim", "top"], "arcs": [[0, 0], [0, 0], None]}
# the quarter of a plate with a hole: the arc of radius 1 bulges into the body (centre outside)
QUARTER_PLATE = {
    "polygon": [[1, 0], [4, 0], [4, 4], [0, 4], [0, 1]],
    "sides": ["sym_x", "right", "top", "sym_y", "hole"],
    "arcs": [None, None, None, None, [0, 0]],
}


def test_exact_area_and_bounds_account_for_arcs():
    half = domain_from_spec(HALF_DISK)
    assert half.exact_area == pytest.approx(math.pi * R**2 / 2, rel=1e-15)
    assert half.bounds == pytest.approx((-R, -R, R, 0.0), abs=1e-15)
    plate = domain_from_spec(QUARTER_PLATE)
    assert plate.exact_area == pytest.approx(16.0 - math.pi / 4, rel=1e-15)
    assert plate.bounds == pytest.approx((0.0, 0.0, 4.0, 4.0))


def test_discretized_area_converges_to_the_half_disk_at_second_order():
    half = domain_from_spec(HALF_DISK)
    errors = [half.exact_area - half.area(h) for h in (0.4, 0.2, 0.1, 0.05)]
    assert all(e > 0 for e in errors)  # inscribed chords: the polygon is inside the disk
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert orders == pytest.approx(2.0, abs=0.15)
    assert errors[-1] < 1e-3 * half.exact_area


@pytest.mark.parametrize("h", [0.7, 0.13, 0.02])
def test_arc_vertices_lie_on_the_circle_with_chords_of_about_h(h):
    polygonal = domain_from_spec(HALF_DISK).discretize(h)
    segments = polygonal.points[polygonal.segments]
    rim = segments[polygonal.segment_sides == "rim"]
    assert np.hypot(rim[..., 0], rim[..., 1]) == pytest.approx(R, abs=1e-14 * R)
    lengths = np.linalg.norm(rim[:, 1] - rim[:, 0], axis=1)
    assert lengths.max() <= h * (1 + 1e-12)
    assert lengths.max() >= 0.5 * min(h, R * math.pi / 8)  # at least 4 chords per quarter circle
    assert np.ptp(lengths) < 1e-12 * R  # equal chords on each arc
    top = segments[polygonal.segment_sides == "top"]
    assert top.shape[0] == 1 and np.allclose(top[0], [[R, 0], [-R, 0]])


def test_arcs_bulging_in_keep_the_body_outside_the_circle():
    polygonal = domain_from_spec(QUARTER_PLATE).discretize(0.1)
    hole = polygonal.points[polygonal.segments[polygonal.segment_sides == "hole"]]
    assert np.hypot(hole[..., 0], hole[..., 1]) == pytest.approx(1.0, abs=1e-15)
    assert polygonal.shape.area > 16.0 - math.pi / 4  # chords cut into the quarter hole
    assert polygonal.shape.area == pytest.approx(16.0 - math.pi / 4, rel=1e-3)


def test_to_spec_round_trips_and_all_null_arcs_are_a_polygon():
    half = domain_from_spec(HALF_DISK)
    assert domain_from_spec(half.to_spec()) == half
    straight = domain_from_spec({**HALF_DISK, "arcs": [None, None, None]})
    assert straight == Domain(
        tuple(map(tuple, map(lambda p: map(float, p), HALF_DISK["polygon"]))), ("rim", "rim", "top")
    )
    assert "arcs" not in straight.to_spec()


@pytest.mark.parametrize(
    "arcs, key, words",
    [
        ([[0, 0], [0, 0]], "domain.arcs", "has 2 entries but the polygon has 3 edges"),
        ("curved", "domain.arcs", "no list of entries"),
        ([[0, 0], [0.1, 0], None], "domain.arcs[1]", "give a centre equally far from both"),
        ([[0, 0], [0, "a"], None], "domain.arcs[1]", "two finite numbers"),
        ([[0, 0], [0, 0], [0, 0]], "domain.arcs[2]", "half circle"),
        ([[0, 0], [1.01, -1.01], None], "domain.arcs", "crosses itself"),
    ],
)
def test_bad_arcs_are_refused_with_one_line_naming_the_entry(arcs, key, words):
    with pytest.raises(InputError) as info:
        domain_from_spec({**HALF_DISK, "arcs": arcs})
    assert info.value.key == key and words in str(info.value) and "\n" not in str(info.value)


def test_a_hole_must_clear_the_curved_side_not_just_the_corners():
    spec = {**HALF_DISK, "holes": [{"circle": [0.0, -1.8, 0.15], "side": "bore"}]}
    # inside the triangle of the corners? no: below the chord line; inside the disk: yes
    assert domain_from_spec(spec).holes
    with pytest.raises(InputError, match=r"domain.holes\[0\] overlaps the outer boundary"):
        domain_from_spec({**HALF_DISK, "holes": [{"circle": [0.0, -1.9, 0.15], "side": "bore"}]})


SCENE = {
    "name": "half-disk",
    "domain": HALF_DISK,
    "material": {"E": 1.0, "nu": 0.3},
    "boundary": {"dirichlet": ["top"]},
    "discretization": {"mesh": {"family": "triangle", "n": 4}},
}


def test_the_scene_loader_takes_arcs_and_names_a_bad_one():
    scene = scene_from_dict(SCENE)
    assert domain_from_spec(scene.domain) == domain_from_spec(HALF_DISK)
    bad = {**SCENE, "domain": {**HALF_DISK, "arcs": [[0, 0], [0, 0.5], None]}}
    with pytest.raises((SceneError, InputError), match=r"domain.arcs\[1\]"):
        scene_from_dict(bad)


def test_vemkit_mesh_refuses_a_bad_arc_in_one_line(tmp_path):
    import yaml

    bad = {**SCENE, "domain": {**HALF_DISK, "arcs": [[0, 0], [0, 0.5], None]}}
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(bad))
    run = subprocess.run(
        [sys.executable, "-m", "vemkit.cli", "mesh", "--scene", str(path), "-o", "m.nc", "-q"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert run.returncode != 0 and not (tmp_path / "m.nc").exists()
    assert len(run.stderr.strip().splitlines()) == 1 and "domain.arcs[1]" in run.stderr
