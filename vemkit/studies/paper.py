"""The paper's published numbers (SPEC §5), which the studies and the reports compare with."""

from __future__ import annotations

PAPER_TABLE1 = {
    "n": (4, 8, 16, 32, 64),
    "h": (2.0**-2, 2.0**-3, 2.0**-4, 2.0**-5, 2.0**-6),
    "error": (1.9114e-1, 1.0309e-1, 5.4352e-2, 2.8007e-2, 1.3828e-2),
    "order": (None, 0.89067, 0.92354, 0.95656, 1.0182),
    "norm": "h1",
    "source": "Table 1 of the paper (SPEC 5): relative H1 error on square meshes, reference h = 2^-8",
}


def paper_value(h: float, key: str):
    """The paper's ``error`` or ``order`` at mesh size h, or None."""
    for hp, value in zip(PAPER_TABLE1["h"], PAPER_TABLE1[key]):
        if abs(hp - h) <= 1e-12 * hp:
            return value
    return None
