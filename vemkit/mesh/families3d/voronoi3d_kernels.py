"""Numba kernels of the Voronoi family (``voronoi3d``): the Lloyd step's nearest-seed sums on a
bucket grid (the cKDTree query it replaces is its twin in the tests)."""

from __future__ import annotations

import numba
import numpy as np


def seed_buckets(points: np.ndarray, lower, upper):
    """(shape (3,), bucket size h (3,), bucket_ptr, bucket_seeds): the seeds sorted into a grid of
    about one seed per bucket (CSR over the buckets, x fastest)."""
    size = np.asarray(upper, float) - np.asarray(lower, float)
    step = (float(np.prod(size)) / max(points.shape[0], 1)) ** (1.0 / 3.0)
    shape = np.maximum(1, np.floor(size / step)).astype(np.int64)
    h = size / shape
    ijk = np.clip(((points - lower) / h).astype(np.int64), 0, shape - 1)
    bucket = (ijk[:, 2] * shape[1] + ijk[:, 1]) * shape[0] + ijk[:, 0]
    order = np.argsort(bucket, kind="stable").astype(np.int64)
    ptr = np.concatenate([[0], np.cumsum(np.bincount(bucket, minlength=int(np.prod(shape))))]).astype(np.int64)
    return shape, h, ptr, order


@numba.njit(cache=True, parallel=True)
def nearest_seeds(points, samples, lower, shape, h, ptr, seeds):
    """The nearest seed of every sample: the rings of buckets around the sample's bucket, ring r + 1
    only while a seed outside the rings searched could still be nearer than the best one found."""
    owner = np.empty(samples.shape[0], dtype=np.int64)
    for s in numba.prange(samples.shape[0]):
        b = np.empty(3, dtype=np.int64)
        for a in range(3):
            b[a] = min(max(int((samples[s, a] - lower[a]) / h[a]), 0), shape[a] - 1)
        best, arg, r = np.inf, -1, 0
        while True:
            for k in range(max(b[2] - r, 0), min(b[2] + r, shape[2] - 1) + 1):
                for j in range(max(b[1] - r, 0), min(b[1] + r, shape[1] - 1) + 1):
                    for i in range(max(b[0] - r, 0), min(b[0] + r, shape[0] - 1) + 1):
                        if max(abs(i - b[0]), abs(j - b[1]), abs(k - b[2])) != r:
                            continue  # an inner ring: searched already
                        cell = (k * shape[1] + j) * shape[0] + i
                        for t in range(ptr[cell], ptr[cell + 1]):
                            q = seeds[t]
                            d = (
                                (points[q, 0] - samples[s, 0]) ** 2
                                + (points[q, 1] - samples[s, 1]) ** 2
                                + (points[q, 2] - samples[s, 2]) ** 2
                            )
                            if d < best or (d == best and q < arg):
                                best, arg = d, q
            reach = np.inf  # the distance from the sample to the outside of the rings searched
            covered = True
            for a in range(3):
                lo_index, hi_index = b[a] - r, b[a] + r + 1
                if lo_index > 0:
                    reach = min(reach, samples[s, a] - (lower[a] + lo_index * h[a]))
                    covered = False
                if hi_index < shape[a]:
                    reach = min(reach, lower[a] + hi_index * h[a] - samples[s, a])
                    covered = False
            if covered or (arg >= 0 and best <= reach * reach):
                break
            r += 1
        owner[s] = arg
    return owner


@numba.njit(cache=True)
def owner_sums(owner, samples, count):
    """(sums (count, 3), numbers (count,)) of the samples per owner, in the samples' order."""
    sums = np.zeros((count, 3))
    numbers = np.zeros(count, dtype=np.int64)
    for s in range(owner.shape[0]):
        o = owner[s]
        numbers[o] += 1
        for a in range(3):
            sums[o, a] += samples[s, a]
    return sums, numbers
