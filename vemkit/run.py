"""One solve, from a validated scene to a result Dataset: scene -> mesh -> system -> solver -> Dataset."""

from __future__ import annotations

import time

import numpy as np

from vemkit.contact.laws import ContactLaw
from vemkit.families import build_mesh
from vemkit.mesh import Mesh
from vemkit.scene import Scene
from vemkit.system import DiscreteProblem, discrete_problem

def scene_mesh(scene: Scene) -> Mesh:
    opts = scene.mesh_options
    family, n = opts.pop("family"), opts.pop("n")
    return build_mesh(family, n, **opts)  # options were checked by the scene schema and build_mesh


def _pair(expressions):
    fx, fy = expressions

    def field(x, y):
        return np.broadcast_to(fx(x, y), np.shape(x)), np.broadcast_to(fy(x, y), np.shape(x))

    return field


def scene_problem(scene: Scene, mesh: Mesh | None = None) -> DiscreteProblem:
    """Assemble the discrete problem (3.16) of a scene, on its own mesh unless one is given."""
    mesh = scene_mesh(scene) if mesh is None else mesh
    body = None
    if any(not (e.is_constant and float(e(0.0, 0.0)) == 0.0) for e in scene.body_force):
        body = _pair(scene.body_force)
    normal, friction = scene.normal_compliance, scene.friction_bound
    law = ContactLaw(normal.k, normal.m, friction.k, friction.m) if normal is not None else None
    gap = scene.gap_expression
    t0 = time.perf_counter()
    problem = discrete_problem(
        mesh,
        scene.E,
        scene.nu,
        dirichlet=scene.dirichlet_sides,
        neumann={side: _pair(scene.traction(side)) for side in scene.neumann_sides},
        contact=scene.contact_sides,
        gap=(lambda x, y: np.broadcast_to(gap(x, y), np.shape(x))) if gap is not None else (lambda x, y: np.zeros_like(x)),
        law=law,
        body_force=body,
        stabilization=scene.stabilization,
    )
    problem.info["assembly_time"] = time.perf_counter() - t0
    return problem


def solve_problem(problem: DiscreteProblem, solver_options: dict, progress=None):
    """Run the configured contact solver; raises ConvergenceError on failure."""
    from vemkit.contact.ssn import solve_ssn
    from vemkit.contact.uzawa import solve_uzawa

    opts = dict(solver_options)
    method = opts.pop("method")
    common = dict(linear=opts.pop("linear", "auto"), tol=opts.pop("tol"), progress=progress)
    if method == "uzawa":
        uzawa_keys = ("rho", "eps_u", "eps_lambda", "stop", "max_iterations")
        kwargs = {k: opts[k] for k in uzawa_keys if opts.get(k) is not None}
        return solve_uzawa(problem, **common, **kwargs)
    if method == "ssn":
        kwargs = {"max_iterations": opts["max_iterations"]} if opts.get("max_iterations") else {}
        return solve_ssn(problem, **common, **kwargs)
    raise ValueError(f"solver.method = {method!r} is unknown; use ssn or uzawa")


def solve_scene(scene: Scene, progress=None, mesh: Mesh | None = None):
    """Solve a scene; returns (problem, solution, dataset)."""
    from vemkit.results import solution_dataset

    problem = scene_problem(scene, mesh)
    solution = solve_problem(problem, scene.solver_options, progress=progress)
    attrs = {"assembly_time": float(problem.info.get("assembly_time", 0.0)), "mesh_family": str(problem.mesh.meta.get("family", ""))}
    ds = solution_dataset(problem, solution, scene_yaml=scene.to_yaml(), extra_attrs=attrs)
    return problem, solution, ds
