"""The virtual elements, one module per element, one interface for all (``base.Element``).

- ``k1``: the lowest order, vertex values (kernel ``k1_kernel``, fields ``k1_fields``, twin ``k1_reference``);
- ``k2``: second order, vertex values, edge and cell means (kernels ``k2_kernel``, ``k2_stiffness``,
  fields ``k2_fields``, twin ``k2_reference``);
- ``k1_3d``: the lowest order on polyhedra (d = 3), vertex values (kernel ``k1_3d_kernel``, fields
  ``k1_3d_fields``, twin ``k1_3d_reference``).

``element_for(order, dimension)`` is the element a scene's ``discretization.order`` names (in 3D).
"""

from __future__ import annotations

from importlib import import_module

from vemkit.vem.elements.base import STABILIZATIONS, Element, stabilization_code

#: (order, dimension) -> the module of the element
MODULES = {(1, 2): "vemkit.vem.elements.k1", (2, 2): "vemkit.vem.elements.k2", (1, 3): "vemkit.vem.elements.k1_3d"}
ORDERS = tuple(sorted({order for order, _ in MODULES}))

__all__ = ["ORDERS", "STABILIZATIONS", "Element", "element_for", "stabilization_code"]


def element_for(order: int = 1, dimension: int = 2) -> Element:
    """The element of order k (``discretization.order``) in ``dimension`` space dimensions."""
    try:
        module = MODULES[(int(order), int(dimension))]
    except KeyError:
        raise ValueError(f"no virtual element of order {order} in {dimension} dimensions; orders: {ORDERS}") from None
    return import_module(module).ELEMENT
