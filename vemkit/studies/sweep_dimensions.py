"""The netCDF dimension name of a swept scene key (``contact.normal.k`` -> ``k_nu``).

Imports nothing heavy: the workflow imports it while it builds the DAG.
"""

from __future__ import annotations

import re

#: short dimension names of common scene keys (others: the key with "." -> "_")
DIMENSION_NAMES = {
    "contact.normal.k": "k_nu",
    "contact.normal.m": "m_nu",
    "contact.friction.k": "k_tau",
    "contact.friction.m": "m_tau",
    "contact.gap": "g_a",
    "material.E": "E",
    "material.nu": "kappa",
    "discretization.mesh.n": "n",
    "discretization.stabilization": "stabilization",
    "solver.method": "solver",
    "solver.tol": "tol",
}


def dimension_name(key: str) -> str:
    """The netCDF dimension of a scene key: DIMENSION_NAMES, else the key with [.[]] -> "_"."""
    return DIMENSION_NAMES.get(key, re.sub(r"[^A-Za-z0-9_]+", "_", key).strip("_"))
