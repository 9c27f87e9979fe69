"""
Hertz: a half-disk pressed onto a stiff foundation
==================================================

``config/scenes/hertz.yaml``: a half-disk of radius 1 with a curved contact side (``domain.arcs``),
pushed down by a frictionless platen onto a foundation 10⁴ times stiffer than the body. The contact
zone's half-width and peak pressure follow Hertz's formulas for the force the solution transmits.
"""

from pathlib import Path

import vemkit
from vemkit.report.verification import scene_figure
from vemkit.studies.scene_solve import solve_scene
from vemkit.studies.verification import hertz_quantities

ROOT = Path(".") if Path("config/scenes").is_dir() else Path("../..")  # the repository, or docs/examples
SCENES = ROOT / "config" / "scenes"
scene = vemkit.load_scene(SCENES / "hertz.yaml", ["discretization.mesh.h=0.02"])  # as --set
problem, solution, ds = solve_scene(scene, verify=True)  # what `vemkit solve` runs: solve, check, errors
q = hertz_quantities(scene, problem, ds, contact_side="contact", symmetry_x=None)
print(
    f"force P = {q['contact_force']:.4g}; half-width a = {q['half_width']:.4f} (Hertz {q['half_width_hertz']:.4f}); "
    f"peak pressure p0 = {q['peak_pressure']:.4f} (Hertz {q['peak_pressure_hertz']:.4f})"
)

# %%
# Mesh, deformed shape, stress; below, a zoom on the contact zone, the remaining gap and the
# pressure against Hertz's ellipse.
fig = scene_figure("hertz", problem.mesh, ds, hertz=(q["half_width_hertz"], q["peak_pressure_hertz"]))
