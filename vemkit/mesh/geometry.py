"""Items binned on a uniform g x g grid by their bounding boxes, for point location and
segment-intersection searches (``vemkit.vem.norms``, ``vemkit.mesh.checks``)."""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def bin_boxes(boxes, g):
    """CSR (ptr, items) of the items whose bin box (i0, i1, j0, j1) covers each bin j * g + i."""
    ptr = np.zeros(g * g + 1, dtype=np.int64)
    for t in range(boxes.shape[0]):
        for j in range(boxes[t, 2], boxes[t, 3] + 1):
            for i in range(boxes[t, 0], boxes[t, 1] + 1):
                ptr[j * g + i + 1] += 1
    for b in range(g * g):
        ptr[b + 1] += ptr[b]
    items = np.empty(ptr[g * g], dtype=np.int64)
    fill = ptr[:-1].copy()
    for t in range(boxes.shape[0]):
        for j in range(boxes[t, 2], boxes[t, 3] + 1):
            for i in range(boxes[t, 0], boxes[t, 1] + 1):
                items[fill[j * g + i]] = t
                fill[j * g + i] += 1
    return ptr, items
