"""The load options of a scene (Section 3.3): how the body force f1 is projected for the k = 2 load.

``p1`` (P_1 f1 against Pi_2 v) gives k = 2 its L2 order 3; ``p0``, the paper's P_{k-2} f1 = P_0 f1,
caps it at 2 (README "Order 2"). At order 1 the key is irrelevant and stays unset.
"""

BODY_FORCE_PROJECTIONS = ("p0", "p1")
DEFAULT_BODY_FORCE_PROJECTION_K2 = "p1"
