"""What a sweep records of one converged point (``vemkit.studies.sweeps``): the quantities and the
contact-boundary profiles, and what they are called and measured in for a body of each dimension
(``CONTACT_GEOMETRY``, one table keyed by the dimension of the contact boundary).

Tangential quantities of a d-dimensional body have d - 1 components along the vertex's tangent
basis (``vemkit.contact.boundary.ContactBoundary.tangents``); the profiles keep them so, the file
squeezes the one column of a plane body (``vemkit.io.solution_fields.as_written``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from vemkit.io.solution_fields import as_written
from vemkit.solvers.verification import Outcome

PROFILES = {  # name: (ContactState attribute or "multiplier", long name, units)
    "pressure": ("normal_pressure", "p_nu(u_nu - g_a) along Gamma_C", "daN/mm2"),
    "tangential_stress": ("tangential_stress", "sigma_tau = -p_tau lambda along Gamma_C", "daN/mm2"),
    "slip": ("slip", "tangential displacement u_tau along Gamma_C", "mm"),
    "penetration": ("penetration", "u_nu - g_a along Gamma_C", "mm"),
    "multiplier": ("multiplier", "friction multiplier lambda along Gamma_C", "1"),
}


def _tangential_sum(cb, w: np.ndarray, stress: np.ndarray) -> float:
    """A plane body: sum_c w_c sigma_tau,c, signed along the tangents tau (its one component)."""
    return float(np.sum(w * stress[:, 0]))


def _tangential_magnitude(cb, w: np.ndarray, stress: np.ndarray) -> float:
    """A solid body: |sum_c w_c sigma_tau,c| of the resultant vector in space (components in the vertex bases)."""
    tangents = cb.tangents
    in_space = tangents[0] * stress[:, :1]
    for k in range(1, len(tangents)):
        in_space = in_space + tangents[k] * stress[:, k : k + 1]
    return float(np.linalg.norm(np.sum(w[:, None] * in_space, axis=0)))


@dataclass(frozen=True)
class ContactGeometry:
    """What the sweep calls the quantities of Gamma_C of a body of one dimension: a plane body's
    Gamma_C is a curve (lengths, forces per unit depth), a solid's a surface (areas, forces)."""

    measure: str  # "length" or "area": the suffix of the contact, stick and slip measures
    measure_units: str  # of the measures and of the nodal quadrature weights
    force_units: str
    tangential_force_name: str  # the long name of the file's tangential force
    tangential_force: Callable  # (contact boundary, w (n_c,), sigma_tau (n_c, d - 1)) -> the file's scalar

    @property
    def quantities(self) -> dict:
        """{name: (long name, units)} of the quantities of a point, in the file's order."""
        where = {
            "contact": "where u_nu - g_a > 0 (nodal weights)",
            "stick": "in contact and sticking (contact_state)",
            "slip": "in contact and slipping (contact_state)",
        }
        return {
            "max_penetration": ("max over Gamma_C of (u_nu - g_a)_+", "mm"),
            **{f"{k}_{self.measure}": (f"{self.measure} of Gamma_C {v}", self.measure_units) for k, v in where.items()},
            "normal_force": (NORMAL_FORCE, self.force_units),
            "tangential_force": (self.tangential_force_name, self.force_units),
            "residual": ("worst independent check of the discrete conditions (vemkit.studies.robustness)", "1"),
        }


NORMAL_FORCE = (
    "resultant normal contact force: the integral of p_nu(u_nu - g_a) over Gamma_C with the "
    "scene's contact quadrature (nodal: sum_c w_c p_nu)"
)
#: dimension -> Gamma_C's quantities; 3D (docs/reference/files.md): areas instead of lengths, forces instead of
#: forces per unit depth, and the tangential force is the magnitude of the resultant vector sum_c w_c sigma_tau,c
CONTACT_GEOMETRY = {
    2: ContactGeometry(
        "length",
        "mm",
        "daN/mm",
        "resultant tangential contact stress sum_c w_c sigma_tau (all Gamma_C vertices)",
        _tangential_sum,
    ),
    3: ContactGeometry(
        "area",
        "mm2",
        "daN",
        "magnitude of the resultant tangential contact force |sum_c w_c sigma_tau,c|",
        _tangential_magnitude,
    ),
}
QUANTITIES, QUANTITIES_3D = CONTACT_GEOMETRY[2].quantities, CONTACT_GEOMETRY[3].quantities


def coordinate_names(dimension: int) -> str:
    """The coordinates of a contact vertex, in the profiles' sort order: "xy" or "xyz"."""
    return "xyz"[:dimension]


def point_quantities(problem, outcome: Outcome):
    """(quantities, profiles) of a converged solve; profiles ordered along Gamma_C by (x, y)."""
    from vemkit.solvers.solution import SLIP, STICK, contact_state

    cb, sol = problem.contact, outcome.solution
    geometry = CONTACT_GEOMETRY[cb.dimension]
    st = contact_state(problem, sol.u, sol.multiplier)
    w, measure = cb.weight, geometry.measure
    q = {
        "max_penetration": float(np.max(np.maximum(st.penetration, 0.0), initial=0.0)),
        f"contact_{measure}": float(np.sum(w[st.penetration > 0.0])),
        f"stick_{measure}": float(np.sum(w[st.state == STICK])),
        f"slip_{measure}": float(np.sum(w[st.state == SLIP])),
        "normal_force": _normal_force(problem, sol.u, st),
        "tangential_force": geometry.tangential_force(cb, w, st.tangential_stress),
        "residual": float(outcome.checks.get("worst", np.nan)),
    }
    order = np.lexsort(tuple(cb.coords[:, axis] for axis in reversed(range(cb.dimension))))  # by x, then y (, z)
    values = {"multiplier": np.asarray(sol.multiplier, dtype=float)}
    profiles = {
        name: as_written(values.get(attr, getattr(st, attr, None)), cb.dimension)[order]
        for name, (attr, _, _) in PROFILES.items()
    }
    profiles["state"] = np.asarray(st.state, dtype=np.int8)[order]
    profiles["w"] = cb.weight[order]
    for axis, name in enumerate(coordinate_names(cb.dimension)):
        profiles[name] = cb.coords[order, axis]
    return q, profiles


def _normal_force(problem, u, state) -> float:
    """The resultant normal force with the problem's contact quadrature: sum_c F_c . nu_c."""
    cb = problem.contact
    if cb.quadrature == "nodal":
        return float(np.sum(cb.weight * state.normal_pressure))
    return float(np.sum(cb.normal_displacement(cb.normal_force(u, problem.law))))
