"""Layer 7, studies: many solves for one purpose.

Owns one solve of a scene (``scene_solve``), the convergence study behind Table 1
(``convergence``), parameter sweeps (``sweeps``), the solver-robustness matrix (``robustness``),
the speed-accuracy study (``tradeoff``), the names of swept dimensions (``sweep_dimensions``) and
the paper's published numbers (``paper``).
Imports from vemkit: every layer below (``exceptions`` … ``io``).
"""
