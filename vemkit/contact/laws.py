"""Contact laws of the deformable foundation: the normal compliance p_nu and the friction bound p_tau.

:class:`FoundationLaw` is what the solvers ask of a law (p_nu(t), p_nu'(t), P_nu(t) with P_nu' = p_nu,
p_tau(t), p_tau'(t), the friction coefficient of the reduced law and of the Uzawa update, and bounds
of p_nu' for the solvers' safeguards); they never read a law's parameters. Two laws implement it:

- :class:`ContactLaw`, the power laws (5.1) p(t) = k (t)_+^m for both (``contact.normal: {law: power,
  k, m}``, the default). Convention for m = 0: p(t) = k for every t, the paper's reduced law
  m_tau = 0 ("the friction bound is k_tau, independent of u", Section 5). For m > 0, p vanishes for
  t <= 0 ((2.10)(d)).
- :class:`TabulatedContactLaw`, a measured foundation: p_nu piecewise linear through the points of
  ``contact.normal: {law: table, penetration: [0, ...], pressure: [0, ...]}``, extended beyond the last
  point with the last slope (and 0 for t <= 0); p_nu' piecewise constant (the right slope at a
  point: the generalized derivative the semismooth Newton method works with). The friction bound
  stays the power law of ``contact.friction``.

:func:`contact_law` makes the law a scene's ``contact`` block names (:data:`NORMAL_LAWS`).
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


class FoundationLaw:
    """The interface of a contact law: what the contact boundary and the solvers ask of it.

    Subclasses define the normal compliance (``normal_pressure``, ``normal_stiffness``,
    ``normal_energy``, ``normal_stiffness_unbounded``, ``lagged_stiffness``, the message texts
    ``normal_text``, ``normal_stiffness_text``, ``normal_stiffness_key``) and carry the power-law
    friction bound p_tau(t) = k_friction (t)_+^m_friction, whose members are defined here.
    """

    k_friction: float
    m_friction: float

    # -- the normal compliance p_nu ------------------------------------------------------------------
    def normal_pressure(self, penetration):  # pragma: no cover - the interface
        """p_nu(u_nu - g_a)."""
        raise NotImplementedError

    def normal_stiffness(self, penetration):  # pragma: no cover - the interface
        """d p_nu / d u_nu (a generalized derivative where p_nu has a kink)."""
        raise NotImplementedError

    def normal_energy(self, penetration):  # pragma: no cover - the interface
        """P_nu(t) with P_nu' = p_nu and P_nu(0) = 0."""
        raise NotImplementedError

    @property
    def normal_stiffness_unbounded(self) -> bool:
        """Whether p_nu' grows without bound as t -> 0+ (the Newton step caps it)."""
        return False

    def lagged_stiffness(self, penetration) -> float:  # pragma: no cover - the interface
        """The p_nu' that sets the contraction of Uzawa's lagged normal compliance at these
        penetrations (an estimate; a Lipschitz bound of p_nu where the law has one)."""
        raise NotImplementedError

    # -- the friction bound p_tau (a power law for every normal compliance) -------------------------
    def friction_bound(self, penetration):
        """p_tau(u_nu - g_a)."""
        return power_law(penetration, self.k_friction, self.m_friction)

    def friction_bound_derivative(self, penetration):
        return power_law_derivative(penetration, self.k_friction, self.m_friction)

    @property
    def friction_coefficient(self) -> float:
        """k_tau: the bound of the reduced law, the scale of the Uzawa update (5.5) and of the step rho."""
        return self.k_friction

    @property
    def frictionless(self) -> bool:
        return self.k_friction == 0.0

    @property
    def reduced(self) -> bool:
        """The friction bound does not depend on u (m_tau = 0 or k_tau = 0)."""
        return self.m_friction == 0.0 or self.k_friction == 0.0

    @property
    def friction_text(self) -> str:
        """The friction bound as its scene keys say it (error messages)."""
        return f"contact.friction.m = {self.m_friction:g} (k = {self.k_friction:g})"

    def without_friction(self) -> FoundationLaw:  # pragma: no cover - the interface
        """The same normal compliance with p_tau = 0."""
        raise NotImplementedError


def _check_friction(law) -> None:
    for name in ("k_friction", "m_friction"):
        value = getattr(law, name)
        if not (np.isfinite(value) and value >= 0.0):
            raise InputError(f"contact law {name} = {value}: must be a finite number >= 0", key=name)


@dataclass(frozen=True)
class ContactLaw(FoundationLaw):
    """The power laws (5.1): p_nu(t) = k_normal (t)_+^m_normal, p_tau(t) = k_friction (t)_+^m_friction."""

    k_normal: float
    m_normal: float
    k_friction: float
    m_friction: float

    name = "power"

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

    @property
    def normal_stiffness_unbounded(self) -> bool:
        """p_nu' = k m t^(m-1) is unbounded at 0 for 0 < m < 1."""
        return 0.0 < self.m_normal < 1.0

    def lagged_stiffness(self, penetration) -> float:
        """max p_nu'(|t|) (t not finite: at 1); k for the linear law m = 1 or when that is not finite."""
        t = np.asarray(penetration, dtype=float)
        slope = self.normal_stiffness(np.where(np.isfinite(t), np.abs(t), 1.0))
        k_eff = float(np.max(slope)) if slope.size else 0.0
        if self.m_normal == 1.0 or not np.isfinite(k_eff):
            k_eff = self.k_normal
        return k_eff

    @property
    def normal_text(self) -> str:
        return f"contact.normal.k = {self.k_normal:g} (m = {self.m_normal:g})"

    @property
    def normal_stiffness_text(self) -> str:
        return f"contact.normal.k = {self.k_normal:g}"

    normal_stiffness_key = "contact.normal.k"

    def without_friction(self) -> ContactLaw:
        return ContactLaw(self.k_normal, self.m_normal, 0.0, 0.0)


@dataclass(frozen=True)
class TabulatedContactLaw(FoundationLaw):
    """p_nu piecewise linear through (penetration[i], pressure[i]) (module docstring); p_tau a power law.

    ``penetration`` increases from 0, ``pressure`` starts at 0 and never decreases (checked:
    vemkit.config.contact_laws.check_table). Beyond the last point p_nu goes on with the last slope.
    """

    penetration: tuple
    pressure: tuple
    k_friction: float
    m_friction: float

    name = "table"

    def __post_init__(self):
        from vemkit.config.contact_laws import check_table

        check_table(self.penetration, self.pressure)
        _check_friction(self)
        points = np.asarray(self.penetration, dtype=float)
        values = np.asarray(self.pressure, dtype=float)
        slopes = np.diff(values) / np.diff(points)
        # energy at each point: the trapezoid integral of p_nu up to it
        energy = np.concatenate([[0.0], np.cumsum(np.diff(points) * (values[:-1] + values[1:]) / 2.0)])
        for name, value in (("_points", points), ("_values", values), ("_slopes", slopes), ("_energy", energy)):
            object.__setattr__(self, name, value)

    def _segment(self, t):
        """The segment of each t: i with points[i] <= t < points[i + 1]; the last beyond the table."""
        return np.clip(np.searchsorted(self._points, t, side="right") - 1, 0, self._slopes.size - 1)

    def normal_pressure(self, penetration):
        t = np.asarray(penetration, dtype=float)
        i = self._segment(t)
        return np.where(t > 0.0, self._values[i] + self._slopes[i] * (t - self._points[i]), 0.0)

    def normal_stiffness(self, penetration):
        """The slope of the segment at t (the right one at a point of the table); 0 for t <= 0."""
        t = np.asarray(penetration, dtype=float)
        return np.where(t > 0.0, self._slopes[self._segment(t)], 0.0)

    def normal_energy(self, penetration):
        t = np.asarray(penetration, dtype=float)
        i = self._segment(t)
        d = t - self._points[i]
        return np.where(t > 0.0, self._energy[i] + self._values[i] * d + self._slopes[i] * d**2.0 / 2.0, 0.0)

    @property
    def largest_slope(self) -> float:
        """The Lipschitz constant of p_nu: its largest slope."""
        return float(np.max(self._slopes))

    def lagged_stiffness(self, penetration) -> float:
        return self.largest_slope

    @property
    def normal_text(self) -> str:
        return f"the table contact.normal (largest slope {self.largest_slope:g})"

    @property
    def normal_stiffness_text(self) -> str:
        return f"contact.normal.pressure (largest slope {self.largest_slope:g})"

    normal_stiffness_key = "contact.normal.pressure"

    def without_friction(self) -> TabulatedContactLaw:
        return TabulatedContactLaw(self.penetration, self.pressure, 0.0, 0.0)


def _power(normal, friction) -> ContactLaw:
    return ContactLaw(normal.k, normal.m, friction.k, friction.m)


def _table(normal, friction) -> TabulatedContactLaw:
    return TabulatedContactLaw(tuple(normal.penetration), tuple(normal.pressure), friction.k, friction.m)


#: ``contact.normal.law`` -> the law made from the scene's normal and friction blocks
NORMAL_LAWS = {"power": _power, "table": _table}


def contact_law(normal, friction) -> FoundationLaw:
    """The law of a scene's ``contact`` block: ``normal`` and ``friction`` as ``Scene.normal_compliance``
    and ``Scene.friction_bound`` give them (``normal.law`` names it)."""
    return NORMAL_LAWS[normal.law](normal, friction)
