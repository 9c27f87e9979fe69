"""Layer 3, the virtual element space (k = 1): element, assembly, loads, projections, norms.

Owns the element kernel (3.8)-(3.9) and its plain-numpy twin (``element``), the material law
(``elasticity``: Lamé parameters of the paper's C, rigid-body modes), the CSR assembly of the
stiffness matrix and the dof map (``assembly``), quadrature rules (``quadrature``), the load
vector (``load``), the projected fields Π u_h, strain, stress and shear energy (``projection``),
generalized barycentric interpolation of vertex values (``interpolation``: Wachspress / mean value
coordinates) and error norms between discrete and exact or reference solutions (``norms``).
Imports from vemkit: ``exceptions``, ``config``, ``mesh``.
"""
