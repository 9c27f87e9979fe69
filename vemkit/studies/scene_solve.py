"""One solve, from a validated scene to a result Dataset: scene -> mesh -> problem -> solver -> Dataset."""

from __future__ import annotations

from vemkit.contact.problem import scene_problem
from vemkit.io.solution_file import solution_dataset
from vemkit.mesh.mesh import Mesh
from vemkit.solvers.dispatch import solve


def solve_scene(scene, progress=None, mesh: Mesh | None = None):
    """Solve a scene; returns (problem, solution, dataset)."""
    problem = scene_problem(scene, mesh)
    solution = solve(problem, scene.solver_options, progress=progress)
    attrs = {"assembly_time": float(problem.info.get("assembly_time", 0.0)), "mesh_family": str(problem.mesh.meta.get("family", ""))}
    ds = solution_dataset(problem, solution, scene_yaml=scene.to_yaml(), extra_attrs=attrs)
    return problem, solution, ds
