"""Resources are predicted before they are spent (issue 9)."""

import pytest

from vemkit.config import limits
from vemkit.config.limits import check_resources, check_scene_resources, domain_area, estimate_mesh, estimate_resources
from vemkit.config.scene import scene_from_dict
from vemkit.exceptions import ResourceLimitError
from vemkit.mesh.families import build_mesh

CASES = [
    ("square", {}),
    ("triangle", {}),
    ("triangle", {"kind": "structured"}),
    ("voronoi", {}),
    ("voronoi", {"lloyd_iterations": 0, "seed": 3}),
    ("hanging", {"levels": 0}),
    ("hanging", {"levels": 3}),
    ("hanging", {"levels": 3, "rule": "random"}),
    ("hanging", {"levels": 2, "rule": "random", "fraction": 1.0}),
]


@pytest.mark.parametrize("family, options", CASES)
@pytest.mark.parametrize("n", [3, 16, 33])
def test_the_estimate_bounds_the_mesh_it_predicts(family, options, n):
    mesh = build_mesh(family, n, **options)
    cells, vertices = estimate_mesh({"family": family, "n": n, **options})
    assert mesh.n_vertices <= vertices <= 2.2 * mesh.n_vertices + 16 * n
    assert 0.8 * mesh.n_cells <= cells <= 1.25 * mesh.n_cells + 2


def test_size_given_by_h_or_cells_and_on_other_domains():
    assert estimate_mesh({"family": "square", "h": 0.25}) == (16, 25)
    assert estimate_mesh({"family": "voronoi", "cells": 100}) == estimate_mesh({"family": "voronoi", "n": 10})
    assert domain_area({"polygon": [[0, 0], [48, 44], [48, 60], [0, 44]]}) == 1440.0  # (44 + 16) / 2 * 48
    assert estimate_mesh({"family": "square", "n": 1}, area=4.0) == (4, 9)


def test_limits_name_the_estimate_and_the_fix(monkeypatch):
    estimate = estimate_resources(*estimate_mesh({"family": "square", "n": 5000}))
    assert estimate.dofs == 2 * 5001**2
    with pytest.raises(ResourceLimitError, match=r"50,020,002 DOFs .*limit of 4,000,000 DOFs.*--max-dofs") as caught:
        check_resources(estimate)
    assert caught.value.estimate["dofs"] == estimate.dofs
    monkeypatch.setattr(limits, "available_memory", lambda: 2**30)
    with pytest.raises(ResourceLimitError, match=r"more than this machine has available \(1.0 GiB\)"):
        check_resources(estimate, max_dofs=None)
    check_resources(estimate_resources(10, 25), max_dofs=None)  # 400 MiB of base < 0.8 GiB


def test_a_solve_split_across_ranks_is_checked_against_its_share_of_the_machine(monkeypatch):
    """Each rank holds its own Python and libraries and 1/ranks of the rest: 4 of 16 ranks on this
    machine need 4 x (base + rest / 16)."""
    estimate = estimate_resources(*estimate_mesh({"family": "square", "n": 2000}))
    rest = estimate.peak_bytes - limits.BASE_BYTES
    assert estimate.on_ranks(4, 16).peak_bytes == int(4 * (limits.BASE_BYTES + rest / 16))
    assert estimate.on_ranks(1, 1) == estimate
    monkeypatch.setattr(limits, "available_memory", lambda: estimate.peak_bytes // 2)
    with pytest.raises(ResourceLimitError, match="more than this machine has available"):
        check_resources(estimate, max_dofs=None)
    check_resources(estimate, max_dofs=None, ranks=(1, 8))  # an eighth and a Python fit in half


def test_the_machine_memory_is_known_here():
    free = limits.available_memory()
    assert free is None or free > 0


def test_a_scene_is_checked_before_its_mesh_exists():
    scene = scene_from_dict(
        {
            "material": {"E": 1.0, "nu": 0.3},
            "boundary": {"dirichlet": ["left"]},
            "discretization": {"mesh": {"family": "hanging", "n": 64, "levels": 20}},
        }
    )
    with pytest.raises(ResourceLimitError, match=r"the scene \(hanging mesh, n = 64\) needs about"):
        check_scene_resources(scene)
    assert limits.scene_resources(scene).dofs == 2 * ((3 * (4096 + 3 * 64 * (2**20 - 1))) // 2 + 4 * 64 * 2**20 + 1)
