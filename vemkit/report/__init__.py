"""Layer 8, what people read: tables (Markdown, CSV, LaTeX) and figures (matplotlib).

Owns Table 1 and the convergence tables (``tables``), the paper's figures and the contact figure
(``figures``), the figures of the sweeps, the robustness matrix and the speed-accuracy study
(``study_figures``), and those of the adaptive runs (``adaptivity_figures``). matplotlib is imported here only (the ``report`` extra).
Imports from vemkit: every layer below.
"""
