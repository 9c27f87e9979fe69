"""
Kirsch's plate: a hole under remote tension
===========================================

``config/scenes/kirsch.yaml``: a square plate with a circular hole, the exact Kirsch field prescribed
on its outer boundary and named under ``exact:``, so every solve also measures its own error. The
stress at the top of the hole is three times the remote stress.
"""

from pathlib import Path

import vemkit
from vemkit.report.verification import scene_figure
from vemkit.studies.scene_solve import solve_scene

ROOT = Path(".") if Path("config/scenes").is_dir() else Path("../..")  # the repository, or docs/examples
SCENES = ROOT / "config" / "scenes"
for h in (0.4, 0.2):
    scene = vemkit.load_scene(SCENES / "kirsch.yaml").with_overrides([f"discretization.mesh.h={h}"])
    problem, solution, ds = solve_scene(scene, verify=True)  # what `vemkit solve` runs
    print(
        f"h = {h}: {problem.n_dofs} unknowns, relative H1 error {ds.attrs['error_h1']:.4f}, "
        f"L2 error {ds.attrs['error_l2']:.5f}"
    )

# %%
# Halving h halves the H1 error and quarters the L2 error. The finer solution:
fig = scene_figure("kirsch", problem.mesh, ds)
