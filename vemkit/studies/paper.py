"""The paper's published numbers (docs/reference/mathematics.md), which the studies and the reports compare with."""

from __future__ import annotations

PAPER_TABLE1 = {
    "n": (4, 8, 16, 32, 64),
    "h": (2.0**-2, 2.0**-3, 2.0**-4, 2.0**-5, 2.0**-6),
    "error": (1.9114e-1, 1.0309e-1, 5.4352e-2, 2.8007e-2, 1.3828e-2),
    "order": (None, 0.89067, 0.92354, 0.95656, 1.0182),
    # the measure the paper's Table 1 prints (vemkit.vem.norms.paper_error, variable error_paper):
    # |Pi_1^ref(I_ref u_h - u_ref)|_H1 / |Pi_1^ref u_ref|_H1, I_ref the bilinear interpolant at the
    # vertices of the h = 2^-8 reference, H1 seminorm
    "norm": "paper",
    "source": "Table 1 of the paper (docs/reference/mathematics.md): relative H1-seminorm error of the bilinear interpolant at the "
    "reference vertices, projected on the reference mesh, square meshes, reference h = 2^-8",
    # h = 2^-5 is printed 2.80070e-2, one digit more than the others, and its sixth digit is not
    # what the paper computed: the paper's order 0.95656 with its 5.4352e-2 at h = 2^-4 (both
    # rounded) puts the error in [2.80064e-2, 2.80071e-2], and the paper's measure with Gauss
    # quadrature on Gamma_C gives 5.43516e-2 and 2.80065e-2 (order 0.95656; docs/reference/mathematics.md). The
    # comparison uses 2.8007e-2, five digits like the other levels.
}


def paper_value(h: float, key: str):
    """The paper's ``error`` or ``order`` at mesh size h, or None."""
    for hp, value in zip(PAPER_TABLE1["h"], PAPER_TABLE1[key]):
        if abs(hp - h) <= 1e-12 * hp:
            return value
    return None
