"""Layer 3, the virtual element spaces (k = 1, and k = 2 in ``*_k2``): element, assembly, loads,
projections, norms.

Owns the element kernel (3.8)-(3.9) and its plain-numpy twin (``element``), the material law
(``elasticity``: Lamé parameters of the paper's C, rigid-body modes), the CSR assembly of the
stiffness matrix and the dof map (``assembly``), quadrature rules (``quadrature``), the load
vector (``load``), the projected fields Π u_h, strain, stress and shear energy (``projection``),
generalized barycentric interpolation of vertex values (``interpolation``: Wachspress / mean value
coordinates) and error norms between discrete and exact or reference solutions (``norms``).
For k = 2 (Section 3 with vertex values, edge and cell means): the projection Π₂ (``element_k2``,
twin ``element_k2_reference``), the element stiffness (``stiffness_k2``), the sparsity pattern and
assembly (``pattern_k2``, ``assembly_k2``), static condensation of the cell means
(``condensation_k2``), Dirichlet data (``constraints_k2``), loads (``load_k2``), errors and
boundary traces (``norms_k2``).
Imports from vemkit: ``exceptions``, ``config``, ``mesh``.
"""
