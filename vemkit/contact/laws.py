"""Contact laws (5.1): p(t) = k (t)_+^m for the normal compliance p_nu and the friction bound p_tau.

Convention for m = 0: p(t) = k for every t, the paper's reduced law m_tau = 0 ("the friction
bound is k_tau, independent of u", Section 5). For m > 0, p vanishes for t <= 0 ((2.10)(d)).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vemkit.exceptions import InputError


def power_law(t, k: float, m: float):
    t = np.asarray(t, dtype=float)
    if m == 0.0:
        return np.full_like(t, k)
    return k * np.maximum(t, 0.0) ** m


def power_law_derivative(t, k: float, m: float):
    """dp/dt; at t = 0 the right derivative for m = 1 is taken only where t > 0 (semismooth choice)."""
    t = np.asarray(t, dtype=float)
    if m == 0.0:
        return np.zeros_like(t)
    positive = t > 0.0
    base = np.where(positive, t, 1.0)  # no 0 ** (m - 1) for m < 1
    return np.where(positive, k * m * base ** (m - 1.0), 0.0)


@dataclass(frozen=True)
class ContactLaw:
    k_normal: float
    m_normal: float
    k_friction: float
    m_friction: float

    def __post_init__(self):
        for name in ("k_normal", "m_normal", "k_friction", "m_friction"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0.0):
                raise InputError(f"contact law {name} = {value}: must be a finite number >= 0", key=name)

    def normal_pressure(self, penetration):
        """p_nu(u_nu - g_a)."""
        return power_law(penetration, self.k_normal, self.m_normal)

    def normal_stiffness(self, penetration):
        """d p_nu / d u_nu."""
        return power_law_derivative(penetration, self.k_normal, self.m_normal)

    def normal_energy(self, penetration):
        """P_nu(t) with P_nu' = p_nu: k t_+^(m+1) / (m+1), or k t for m = 0 (constant pressure)."""
        if self.m_normal == 0.0:
            return self.k_normal * penetration
        return self.k_normal * np.maximum(penetration, 0.0) ** (self.m_normal + 1.0) / (self.m_normal + 1.0)

    def friction_bound(self, penetration):
        """p_tau(u_nu - g_a)."""
        return power_law(penetration, self.k_friction, self.m_friction)

    def friction_bound_derivative(self, penetration):
        return power_law_derivative(penetration, self.k_friction, self.m_friction)

    @property
    def frictionless(self) -> bool:
        return self.k_friction == 0.0

    @property
    def reduced(self) -> bool:
        """The friction bound does not depend on u (m_tau = 0 or k_tau = 0)."""
        return self.m_friction == 0.0 or self.k_friction == 0.0
