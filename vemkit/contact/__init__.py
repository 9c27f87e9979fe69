"""Layer 4, the discrete contact problem (3.16): contact boundary, contact laws, assembled problem.

Owns the contact boundary (Γ_C vertices with normals, tangents, weights and gaps: ``boundary``),
the normal compliance and friction bound laws (5.1) (``laws``) and the assembled
:class:`~vemkit.contact.problem.DiscreteProblem` built from plain ingredients or from a scene
(``problem``). Imports from vemkit: ``exceptions``, ``config``, ``mesh``, ``vem``.
"""
