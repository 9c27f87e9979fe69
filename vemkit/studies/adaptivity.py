"""The adaptive loop of SPEC §9: solve → estimate → mark → refine, until the estimate is small enough.

Each step solves the scene's contact problem on the current mesh, computes the indicators η_K of
``vemkit.vem.estimator`` (with the contact traction of the solution as the Γ_C datum), stops when
the relative estimate η ≤ ``target`` or the next mesh would exceed ``max_dofs`` or ``max_steps`` is
reached, and otherwise refines the Dörfler-marked cells (``vemkit.mesh.refine``). The history
records, per step, the DOFs, cells, η, wall time and, when the caller gives one, the true error.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from vemkit.contact.problem import scene_problem
from vemkit.exceptions import InputError
from vemkit.io.solution_file import solution_dataset
from vemkit.mesh.families import scene_mesh
from vemkit.mesh.refine import refine_cells
from vemkit.mesh.triangulate import triangulate_cells
from vemkit.solvers.dispatch import solve
from vemkit.solvers.solution import contact_state
from vemkit.studies.convergence import RECORD_KEYS
from vemkit.vem.estimator import dorfler_marking, error_indicators
from vemkit.vem.load import cell_averages



@dataclass(frozen=True)
class AdaptivitySettings:
    """The scene's ``adaptivity`` block (SPEC §9)."""

    theta: float = 0.5  # Dörfler bulk parameter
    target: float = 0.01  # relative estimate to reach
    max_dofs: int = 200_000
    max_steps: int = 30
    max_hanging: int | None = None

    def __post_init__(self):
        if not 0.0 < self.theta <= 1.0:
            raise InputError(f"adaptivity.marking.dorfler = {self.theta}: must be in (0, 1]", key="adaptivity.marking")
        if not self.target > 0.0:
            raise InputError(f"adaptivity.target = {self.target}: must be > 0", key="adaptivity.target")
        if self.max_steps < 1 or self.max_dofs < 1:
            raise InputError("adaptivity.max_steps and adaptivity.max_dofs must be >= 1", key="adaptivity")


@dataclass
class AdaptiveRun:
    problem: object  # the last DiscreteProblem
    solution: object  # its ContactSolution
    indicators: dict  # error_indicators of the last solution
    history: list = field(default_factory=list)  # one dict per step (the keys of HISTORY_ATTRS)
    reason: str = ""  # why the loop stopped: target, max_dofs, max_steps


def contact_tractions(problem, solution) -> dict:
    """{side: (N, 2) contact traction t_C = −p_ν ν + σ_τ τ at the Γ_C vertices} (2.6)–(2.9)."""
    cb = problem.contact
    if cb.size == 0:
        return {}
    state = contact_state(problem, solution.u, solution.multiplier)
    at_vertices = np.zeros((problem.mesh.n_vertices, 2))
    at_vertices[cb.vertices] = -state.normal_pressure[:, None] * cb.normal + state.tangential_stress[:, None] * cb.tangent
    return {side: at_vertices for side in problem.info.get("contact_sides", ())}


def _pair(expressions):
    fx, fy = expressions
    return lambda x, y: (np.broadcast_to(fx(x, y), np.shape(x)), np.broadcast_to(fy(x, y), np.shape(y)))


def scene_indicators(scene, problem, solution) -> dict:
    """error_indicators for a solved scene: its body force, tractions and the contact traction."""
    mesh = problem.mesh
    body = None
    if any(not (e.is_constant and float(e(0.0, 0.0)) == 0.0) for e in scene.body_force):
        triangles, parent = triangulate_cells(mesh)
        body = cell_averages(mesh, _pair(scene.body_force), triangles, parent)
    neumann = {side: _pair(scene.traction(side)) for side in scene.neumann_sides}
    contact = contact_tractions(problem, solution)
    return error_indicators(mesh, problem.dofs.expand(solution.u), problem.lam, problem.mu, problem.stabilization,
                            body_force=body, neumann=neumann, contact=contact)


def adapt(scene, settings: AdaptivitySettings, *, true_error=None, progress=None) -> AdaptiveRun:
    """Run the loop from the scene's own mesh; ``true_error(problem, solution) -> float`` is optional."""
    mesh = scene_mesh(scene)
    run = None
    for step in range(settings.max_steps):
        start = time.perf_counter()
        problem = scene_problem(scene, mesh)
        problem.info["contact_sides"] = tuple(scene.contact_sides)
        solution = solve(problem, scene.solver_options)
        solved = time.perf_counter()
        found = scene_indicators(scene, problem, solution)
        record = {"n_dofs": problem.n_dofs, "n_cells": mesh.n_cells, "estimate": found["estimate"],
                  "solve_time": solved - start, "iterations": int(solution.iterations)}
        if true_error is not None:
            record["true_error"] = float(true_error(problem, solution))
            record["effectivity"] = found["estimate"] / record["true_error"] if record["true_error"] > 0 else np.nan
        run = AdaptiveRun(problem, solution, found, (run.history if run else []) + [record])
        reason = _stop_reason(found["estimate"], problem.n_dofs, step, settings)
        if reason is None:
            marked = dorfler_marking(found["indicator"], settings.theta)
            refined = refine_cells(mesh, marked, max_hanging=settings.max_hanging)
            record["marked"] = int(marked.size)
            if 2 * refined.mesh.n_vertices > settings.max_dofs:
                reason = "max_dofs"
            mesh = refined.mesh
        record["wall_time"] = time.perf_counter() - start
        if progress is not None:
            progress(step, record)
        if reason is not None:
            run.reason = reason
            return run
    run.reason = "max_steps"
    return run


def _stop_reason(estimate: float, n_dofs: int, step: int, settings: AdaptivitySettings):
    if estimate <= settings.target:
        return "target"
    if step + 1 >= settings.max_steps:
        return "max_steps"
    return None


_STEP_VARIABLES = (  # (name, long name, units) of what only the adaptive loop records
    ("estimate", "relative a posteriori estimate eta (vemkit.vem.estimator)", "1"),
    ("true_error", "relative H1-seminorm error against the exact or reference solution", "1"),
    ("effectivity", "estimate / true_error", "1"),
    ("marked", "cells marked for refinement (0: the last step)", "1"),
    ("wall_time", "wall time of the step: assembly, solve, estimate, refinement", "s"),
    ("solve_time", "assembly and contact solve", "s"),
)
#: name: (long name, units) of the per-step history; n_dofs, n_cells, iterations as in the convergence records
HISTORY_ATTRS = {**{name: RECORD_KEYS[name] for name in ("n_dofs", "n_cells", "iterations")},
                 **{name: (long_name, units) for name, long_name, units in _STEP_VARIABLES}}


def adaptive_dataset(scene, run: AdaptiveRun, extra_attrs=None) -> xr.Dataset:
    """The final solution file (SPEC §6) plus ``error_indicator`` per face and the per-step history
    on the ``adapt_step`` dimension (SPEC §9). Entries a step does not have are not stored."""
    ds = solution_dataset(run.problem, run.solution, scene_yaml=scene.to_yaml(), extra_attrs=extra_attrs)
    ds["error_indicator"] = ("mesh2d_nFaces", run.indicators["indicator"],
                             {"long_name": "a posteriori error indicator eta_K (vemkit.vem.estimator)",
                              "mesh": "mesh2d", "location": "face", "units": "sqrt(daN mm)"})
    steps = len(run.history)
    for name, (long_name, units) in HISTORY_ATTRS.items():
        values = [record.get(name, 0 if name == "marked" else None) for record in run.history]
        if any(v is None for v in values):
            continue
        dtype = np.int64 if name in ("n_dofs", "n_cells", "marked", "iterations") else float
        ds[f"adapt_{name}"] = ("adapt_step", np.asarray(values, dtype=dtype), {"long_name": long_name, "units": units})
    ds = ds.assign_coords(adapt_step=("adapt_step", np.arange(steps), {"long_name": "adaptive step"}))
    ds.attrs.update({"adapt_stop_reason": run.reason, "adapt_steps": steps,
                     "adapt_estimate": float(run.history[-1]["estimate"])})
    return ds
