"""The Voronoi family's Lloyd kernels (``voronoi3d_kernels``) against their twin, a cKDTree query:
the same nearest seed for every sample, the same centroids."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from vemkit.mesh.families3d.voronoi3d import sample_grid, sampled_centroids
from vemkit.mesh.families3d.voronoi3d_kernels import nearest_seeds, seed_buckets


def sampled_centroids_reference(points, samples):
    """The original Lloyd step: cKDTree nearest seeds, bincount means."""
    _, owner = cKDTree(points).query(samples)
    count = np.bincount(owner, minlength=points.shape[0])
    out = points.copy()
    has = count > 0
    for a in range(3):
        out[has, a] = np.bincount(owner, weights=samples[:, a], minlength=points.shape[0])[has] / count[has]
    return out


@pytest.mark.parametrize("count, clustered", [(1, False), (7, False), (500, False), (400, True)])
def test_nearest_seeds_and_centroids_equal_the_kdtree(count, clustered):
    rng = np.random.default_rng(count)
    lower, upper = np.array([0.0, -1.0, 0.5]), np.array([2.0, 1.0, 1.0])
    points = lower + rng.random((count, 3)) ** (4 if clustered else 1) * (upper - lower)
    samples = sample_grid(count, lower, upper, 3)
    samples = np.concatenate([samples, lower - 0.3 + rng.random((200, 3)) * (upper - lower + 0.6)])  # some outside
    shape, h, ptr, seeds = seed_buckets(points, lower, upper)
    owner = nearest_seeds(points, samples, lower, shape, h, ptr, seeds)
    _, expected = cKDTree(points).query(samples)
    assert np.array_equal(owner, expected)
    assert np.array_equal(
        sampled_centroids(points, samples, lower, upper), sampled_centroids_reference(points, samples)
    )
