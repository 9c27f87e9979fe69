"""Layer 7, studies: many solves for one purpose.

Owns one solve of a scene (``scene_solve``), the convergence study behind Table 1
(``convergence``), parameter sweeps (``sweeps``, what a point records ``sweep_quantities``), the
solver-robustness matrix (``robustness``),
the speed-accuracy study (``tradeoff``, its answers ``tradeoff_answers``), the names of swept dimensions (``sweep_dimensions``), the
paper's published numbers (``paper``), and the adaptive loop of docs/reference/files.md (``adaptivity``), its true
errors (``adaptivity_errors``) and its comparison with uniform refinement (``adaptivity_compare``), and the
checks of the Snakemake workflow's configuration before any job (``workflow_config``).
Imports from vemkit: every layer below (``exceptions`` … ``io``).
"""
