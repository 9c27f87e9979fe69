"""
Cook's membrane: a tapered panel under shear
============================================

``config/scenes/cook.yaml``: a tapered panel clamped on its left edge and sheared on its right one,
the classic bending test of plane elements (Cook 1974). The published vertical displacement at the
middle of the loaded edge is 23.96; coarse Voronoi cells here (h = 2), so expect about 1 % below it.
"""

from pathlib import Path

import vemkit
from vemkit.report.verification import scene_figure
from vemkit.studies.scene_solve import solve_scene
from vemkit.studies.verification import cook_quantities

ROOT = Path(".") if Path("config/scenes").is_dir() else Path("../..")  # the repository, or docs/examples
SCENES = ROOT / "config" / "scenes"
scene = vemkit.load_scene(SCENES / "cook.yaml").with_overrides(
    ['discretization.mesh={"family": "voronoi", "h": 2.0, "seed": 1}']
)
problem, solution, ds = solve_scene(scene, verify=True)  # what `vemkit solve` runs: solve, check, errors
v = cook_quantities(scene, problem, ds, point=(48.0, 52.0), corner=(48.0, 60.0))["v_mid"]
print(f"v(48, 52) = {v:.3f} on {problem.mesh.n_cells} Voronoi cells (published: 23.96)")

# %%
# The mesh with its named sides, the deformed shape and the von Mises stress.
fig = scene_figure("cook", problem.mesh, ds)
