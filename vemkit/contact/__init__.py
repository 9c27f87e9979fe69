"""Layer 4, the discrete contact problem (3.16): contact boundary, contact laws, assembled problem.

Owns the contact boundary, one for 2D and 3D (Γ_C vertices with normals, tangents, weights and gaps:
``boundary``; the per-facet rules of edges and faces: ``rules``; the unit ball of the friction
multiplier, tangential quantities (n_c, d - 1): ``ball``),
the normal compliance and friction bound laws (5.1) (``laws``) and the assembled
:class:`~vemkit.contact.problem.DiscreteProblem` built from plain ingredients or from a scene
(``problem``). Imports from vemkit: ``exceptions``, ``config``, ``mesh``, ``vem``.
"""
