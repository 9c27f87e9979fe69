"""
The paper's scene: a square pushed onto a foundation
====================================================

``config/scenes/paper.yaml`` is the experiment of the paper (Section 5): the unit square, clamped
on the right, pushed by a traction on the left and pressed onto a deformable foundation across the
bottom gap (normal compliance k_ν = 10, friction bound k_τ = 450). Here on 16 x 16 squares.
"""

from pathlib import Path

import matplotlib.pyplot as plt

import vemkit
from vemkit.report.figures import contact_figure, deformed_figure

ROOT = Path(".") if Path("config/scenes").is_dir() else Path("../..")  # the repository, or docs/examples
SCENES = ROOT / "config" / "scenes"
scene = vemkit.load_scene(SCENES / "paper.yaml").with_overrides(["discretization.mesh.n=16"])
problem = vemkit.scene_problem(scene)
solution = vemkit.solve(problem, scene.solver_options)
ds = vemkit.solution_dataset(problem, solution)
print(
    f"{problem.mesh.n_cells} cells, {problem.n_dofs} unknowns, {ds.attrs['solver']}: "
    f"{ds.attrs['iterations']} iterations"
)

# %%
# The deformed mesh (true scale), grey the shear energy density, and Γ_C in red where it penetrates
# the foundation; then the contact boundary: pressure, tangential stress and the stick/slip zones.
fig = deformed_figure(problem.mesh, ds, magnification=1.0)
profile = contact_figure(ds, title="the contact boundary Γ_C")
plt.show()
