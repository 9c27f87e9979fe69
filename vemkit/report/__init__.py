"""Layer 8, what people read: tables (Markdown, CSV, LaTeX) and figures (matplotlib).

Owns Table 1 and the convergence tables (``tables``), the figures of one solution, 2D or 3D (the
paper's, the deformed body, the contact figure) and the convergence figure (``figures``), those of
the Hertz and Cattaneo-Mindlin benchmarks (``contact_benchmark_figures``), of the sweeps, the
robustness matrix and the speed-accuracy study (``study_figures``), and of the adaptive runs
(``adaptivity_figures``). matplotlib is imported here only (the ``report`` extra).
Imports from vemkit: every layer below.
"""
