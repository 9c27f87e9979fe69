"""
An L-bracket on a pad: a re-entrant corner, a bore and friction
===============================================================

``config/scenes/lbracket.yaml``: an L-shaped bracket with a bore, clamped at its back, loaded on its
shelf and resting on a compliant pad with friction. Its re-entrant corner is where adaptive
refinement pays most (see the adaptivity tutorial).
"""

from pathlib import Path

import vemkit
from vemkit.report.verification import scene_figure
from vemkit.studies.scene_solve import solve_scene

ROOT = Path(".") if Path("config/scenes").is_dir() else Path("../..")  # the repository, or docs/examples
SCENES = ROOT / "config" / "scenes"
scene = vemkit.load_scene(SCENES / "lbracket.yaml").with_overrides(["discretization.mesh.h=2.0"])
problem, solution, ds = solve_scene(scene, verify=True)  # what `vemkit solve` runs: solve, check, errors
states = ds["contact_state"]
counts = {
    name: int((states.values == code).sum())
    for code, name in zip(states.attrs["flag_values"], states.attrs["flag_meanings"].split())
}
print(
    f"{problem.mesh.n_cells} cells, {problem.n_dofs} unknowns; contact vertices: {counts}; "
    f"independent check {ds.attrs['check_worst']:.1e}"
)

# %%
fig = scene_figure("lbracket", problem.mesh, ds)
