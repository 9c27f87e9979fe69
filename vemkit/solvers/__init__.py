"""Layer 5, solving the discrete problem: linear solvers, the contact solvers, their verification.

Owns the linear solvers (``linear``: AMG-preconditioned CG and SuperLU), the paper's Uzawa
(``uzawa``) and the semismooth Newton method (``ssn``), the solution and its residual measures
(``solution``), the independent check and the guarded solve that never raises
(``verification``), and :func:`solve` (``dispatch``), which runs the method a scene names. The
BLAS thread setting (one thread, unless the user set it) is applied here, when a solve starts.
Imports from vemkit: ``exceptions``, ``config``, ``mesh``, ``vem``, ``contact``.
"""
