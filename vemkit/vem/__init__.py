"""Layer 3, the virtual element space: one space, many elements.

- ``elements/``: the elements as plug-ins behind one interface (``elements/base.py`` says what an
  element declares: its degrees of freedom per mesh entity and its local kernels): ``k1`` (vertex
  values) and ``k2`` (vertex values, edge and cell means), ``k1_3d`` (vertex values on polyhedra),
  each with its Numba kernels and a plain-numpy twin (``*_reference``).
- ``space``: :class:`~vemkit.vem.space.VirtualElementSpace` (mesh, element): layout, numbering,
  constraints, interpolation, traces, loads, the projection of discrete fields.
- ``dofs``: the one numbering (:class:`~vemkit.vem.dofs.DofMap`) and the symmetric elimination of
  fixed dofs; ``pattern``, ``assembly``: the one sparsity pattern and the one CSR assembly,
  specialized per element; ``condensation``: static condensation of interior nodes.
- ``quadrature`` (rules, data sampled on edges and cells), ``elasticity`` (the material law of the
  paper's C, rigid-body modes), ``projection`` (stress, shear energy density), ``norms`` (error
  measures), ``interpolation`` (generalized barycentric coordinates, the paper's measure),
  ``estimator`` (a posteriori indicators, docs/reference/files.md), ``volumetric`` (the lambda part
  of the k = 1 stiffness per cell or averaged at the nodes, ``discretization.volumetric_strain``).
- ``parallel`` (the MPI job: rank, communicator, PETSc), ``distributed_assembly`` (the stiffness
  assembled across MPI ranks, each from its own cells) and ``distributed_matrix`` (the stiffness
  split by rows, as the contact solvers see it).
Imports from vemkit: ``exceptions``, ``config``, ``mesh``.
"""
