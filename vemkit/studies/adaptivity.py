"""The adaptive loop of docs/reference/files.md: solve → estimate → mark → refine, until the estimate is small enough.

Each step solves the scene's contact problem on the current mesh, checks the solution
independently (as ``vemkit solve`` does), computes the indicators η_K of ``vemkit.vem.estimator``
(with the contact traction of the solution as the Γ_C datum), stops when the relative estimate
η ≤ ``target``, when the next mesh would have more than ``max_dofs`` unknowns (counted as the
degrees of freedom of its space, an upper bound: no mesh beyond the limit is ever assembled) or would
need more memory than the machine has (the prediction of ``vemkit.config.limits``, checked before it
is solved), or after
``max_steps`` solves, and otherwise refines the Dörfler-marked cells (``vemkit.mesh.refine``;
new vertices on a circular hole or an arc of the scene's domain are placed on the curve).

Warm start: the solve of step k + 1 starts from the solution of step k prolongated to the refined
mesh (``RefinedMesh.prolongation``: linear along split edges, the vertex mean at new cell centres;
the friction multiplier the same way along Γ_C), see the ``initial`` argument of
``vemkit.solvers.dispatch.solve``.

The history records, per step, the DOFs, cells, η, the solver's iterations and times and, when the
scene has an exact solution (``exact:``) or names a reference solution file
(``adaptivity.reference``), the true error (:mod:`vemkit.studies.adaptivity_errors`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from vemkit.config.domain3d import plane_section
from vemkit.config.expressions import vector_field
from vemkit.config.limits import RESOURCE_MODELS, check_resources
from vemkit.contact.problem import DiscreteProblem, scene_problem
from vemkit.exceptions import InputError, MeshError, ResourceLimitError, ResultError
from vemkit.io.solution_file import solution_dataset
from vemkit.mesh.curves import domain_curves
from vemkit.mesh.meshing import HANGING_LIMIT_DIMENSIONS, checked_mesh, of_dimension, scene_mesh
from vemkit.mesh.ugrid import mesh_topology
from vemkit.solvers.dispatch import floating_point_errors_raise, solve
from vemkit.solvers.solution import ContactSolution, contact_state
from vemkit.studies.error_records import RECORD_KEYS
from vemkit.studies.scene_solve import verified
from vemkit.vem.estimator import dorfler_marking, error_indicators
from vemkit.vem.space import VirtualElementSpace


@dataclass(frozen=True)
class AdaptivitySettings:
    """The scene's ``adaptivity`` block (docs/reference/files.md)."""

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

    @classmethod
    def from_scene(cls, scene, max_dofs: int | None = None) -> AdaptivitySettings:
        """The settings of ``scene.adaptivity_options`` (validated by the scene schema); ``max_dofs``
        (e.g. ``vemkit adapt --max-dofs``) caps ``adaptivity.max_dofs``."""
        options = scene.adaptivity_options
        if options["max_hanging"] is not None and scene.dimension not in HANGING_LIMIT_DIMENSIONS:
            raise InputError(
                f"adaptivity.max_hanging = {options['max_hanging']}: the refinement of {scene.dimension}D bodies "
                "does not limit hanging vertices; leave it out (null)",
                key="adaptivity.max_hanging",
            )
        cap = options["max_dofs"] if max_dofs is None else min(options["max_dofs"], int(max_dofs))
        return cls(
            theta=options["marking"]["dorfler"],
            target=options["target"],
            max_dofs=cap,
            max_steps=options["max_steps"],
            max_hanging=options["max_hanging"],
        )


@dataclass
class AdaptiveRun:
    problem: DiscreteProblem  # the last one
    solution: ContactSolution  # its solution
    indicators: dict  # error_indicators of the last solution
    history: list = field(default_factory=list)  # one dict per step (the keys of HISTORY_ATTRS)
    reason: str = ""  # why the loop stopped: target, max_dofs, memory, max_steps, unrefinable
    checks: dict = field(default_factory=dict)  # the independent check of the last solution


def contact_tractions(problem, solution) -> dict:
    """{side: (n_nodes, d) contact traction t_C = −p_ν ν + Σ_k σ_τ,k τ_k at the contact points}
    (2.6)–(2.9), τ_k the d − 1 tangents of the contact boundary."""
    cb = problem.contact
    if cb.size == 0:
        return {}
    state = contact_state(problem, solution.u, solution.multiplier)
    traction = -state.normal_pressure[:, None] * cb.normal
    for k, tangent in enumerate(cb.tangents):
        traction = traction + state.tangential_stress[:, k : k + 1] * tangent
    at_nodes = np.zeros((problem.space.n_nodes, cb.dimension))
    at_nodes[cb.vertices] = traction
    return {side: at_nodes for side in problem.info.get("contact_sides", ())}


def scene_indicators(scene, problem, solution) -> dict:
    """error_indicators for a solved scene: its body force, tractions and the contact traction."""
    body = None
    if any(not (e.is_constant and float(e(0.0, 0.0)) == 0.0) for e in scene.body_force):
        body = problem.space.body_force_averages(vector_field(scene.body_force))
    pressure = {side: scene.pressure(side) for side in scene.neumann_sides if scene.pressure(side) is not None}
    neumann = {side: vector_field(scene.traction(side)) for side in scene.neumann_sides if side not in pressure}
    contact = contact_tractions(problem, solution)
    return error_indicators(
        problem.space,
        problem.node_values(solution.u),
        problem.lam,
        problem.mu,
        problem.stabilization,
        body_force=body,
        neumann=neumann,
        pressure=pressure,
        contact=contact,
        volumetric_strain=problem.volumetric_strain,
    )


def curved_sides(domain_spec) -> list:
    """The boundary pieces of the domain (``vemkit.mesh.curves.domain_curves``: circular holes, outer
    arcs and edges, polygonal holes' edges; of an extruded body, its base's, in the xy plane; a box has
    none); refinement puts a new boundary vertex on its edge's own piece."""
    section = plane_section(domain_spec)
    return [] if section is None else domain_curves(section)


def prolongated_start(refined, problem, solution, new_problem):
    """(u0, λ0) on ``new_problem``: ``solution`` on ``problem`` carried to the refined mesh (a RefinedMesh).

    An element with vertex values only (k = 1) uses the refinement's prolongation (linear along split
    edges, the vertex mean at new cell centres; the friction multiplier the same way along Γ_C);
    otherwise the new degrees of freedom interpolate Π u_h of the coarse solution, and each new contact
    point takes the multiplier of the nearest old one."""
    dofs = new_problem.dofs
    if _vertex_values_only(new_problem):
        u0 = dofs.restrict(refined.prolongation @ problem.dofs.expand(solution.u))
    else:
        u0 = dofs.unknowns(new_problem.space.interpolate(_coarse_field(problem, solution)))
    u0[dofs.fixed_dofs] = dofs.fixed_values  # prescribed displacements at their exact values
    return u0, _prolongated_multiplier(refined, problem, solution, new_problem)


def _vertex_values_only(problem) -> bool:
    """The space's nodes are the mesh vertices: the refinement's prolongation carries them."""
    return tuple(problem.space.element.layout) == ("vertex",)


def _coarse_field(problem, solution):
    """Π u_h of a coarse solution as a field(x, y) -> (u1, u2) anywhere on its mesh."""
    from vemkit.mesh.locate import locate_points, nearest_cells

    projection = problem.projected(solution.u)

    def field(x, y):
        points = np.stack([np.ravel(x), np.ravel(y)], axis=1)
        cells = locate_points(problem.mesh, points)
        cells[cells < 0] = nearest_cells(problem.mesh, points[cells < 0], within_diameter=False)
        values = projection.evaluate(cells, points)
        return values[:, 0].reshape(np.shape(x)), values[:, 1].reshape(np.shape(x))

    return field


def _prolongated_multiplier(refined, problem, solution, new_problem):
    old, new = problem.contact, new_problem.contact
    if _vertex_values_only(new_problem):
        P = refined.prolongation
        lam = old.tangential(solution.multiplier)  # (n_c, d - 1)
        multiplier, on_contact = np.zeros((problem.mesh.n_vertices, lam.shape[1])), np.zeros(problem.mesh.n_vertices)
        multiplier[old.vertices], on_contact[old.vertices] = lam, 1.0
        # a new Γ_C vertex next to a clamped end takes its contact neighbour's value, not half of it
        weight = (P @ on_contact)[new.vertices]
        spread = np.stack([P @ multiplier[:, k] for k in range(lam.shape[1])], axis=1)[new.vertices]
        return spread / np.where(weight > 0, weight, 1.0)[:, None]
    if old.size == 0 or new.size == 0:
        return new.zero_multiplier()
    from scipy.spatial import cKDTree

    return np.asarray(solution.multiplier, dtype=float)[cKDTree(old.coords).query(new.coords)[1]]


def _checked(problem, solution, solver_options) -> dict:
    """The independent check of ``vemkit solve``; VerificationError naming the adapted mesh if it fails."""
    return verified(
        problem, solution, solver_options, where=f" on the {problem.mesh.n_cells}-cell adapted mesh", source=""
    )


def _solve_step(scene, mesh, previous, warm_start: bool, verify: bool, max_dofs: int):
    """(problem, solution, record, checks) of one step; ``previous`` = (refined, problem, solution) or None."""
    start = time.perf_counter()
    problem = scene_problem(scene, mesh)
    if problem.n_dofs > max_dofs:  # only the scene's own mesh can be too fine: refined meshes are checked
        raise InputError(
            f"the scene's mesh has {problem.n_dofs} unknowns, more than adaptivity.max_dofs = {max_dofs}"
            " (or --max-dofs); use a coarser discretization.mesh or raise adaptivity.max_dofs",
            key="adaptivity.max_dofs",
        )
    problem.info["contact_sides"] = tuple(scene.contact_sides)
    initial = prolongated_start(*previous, problem) if warm_start and previous is not None else None
    solution = solve(problem, scene.solver_options, initial=initial)
    checks = _checked(problem, solution, scene.solver_options) if verify else {}
    record = {
        "n_dofs": problem.n_dofs,
        "n_cells": mesh.n_cells,
        "iterations": int(solution.iterations),
        "linear_iterations": int(solution.linear_iterations),
        "solve_time": time.perf_counter() - start,
        "warm_start": int(bool(solution.info.get("warm_start", initial is not None))),
    }
    return problem, solution, record, checks


def adapt(
    scene,
    settings: AdaptivitySettings,
    *,
    true_error=None,
    progress=None,
    observe=None,
    warm_start: bool = True,
    verify: bool = True,
) -> AdaptiveRun:
    """Run the loop from the scene's own mesh (module docstring). ``settings.theta = 1`` marks every
    cell: uniform refinement of the scene's mesh, the yardstick of the adaptive runs.

    ``true_error(problem, u) -> {"error_h1_semi": ..., "error_h1": ...}`` (relative errors of Π u_h; e.g.
    :func:`vemkit.studies.adaptivity_errors.scene_true_error`) is optional; ``progress(step, record)``
    is called after every step, ``observe(step, run)`` too with the AdaptiveRun so far (its problem,
    solution and indicators are the step's); ``warm_start=False`` starts every solve cold (to measure the gain);
    ``verify``: every solution must pass the independent check (VerificationError otherwise).
    """
    mesh = scene_mesh(scene)
    circles = curved_sides(scene.domain)
    try:
        of_dimension("check_refinable", mesh.dimension)(mesh, circles)
    except MeshError as error:
        raise MeshError(f"vemkit adapt: {error}; choose a family that refines", key="discretization.mesh") from None
    run, previous = None, None
    for step in range(settings.max_steps):
        start = time.perf_counter()
        problem, solution, record, checks = _solve_step(scene, mesh, previous, warm_start, verify, settings.max_dofs)
        found = scene_indicators(scene, problem, solution)
        record["estimate"] = found["estimate"]
        if true_error is not None:
            measured = time.perf_counter()
            errors = true_error(problem, solution.u)
            record["error_time"] = time.perf_counter() - measured
            start += record["error_time"]  # measuring is no cost of the loop
            record.update(true_error=errors["error_h1_semi"], true_error_h1=errors["error_h1"])
            record["effectivity"] = found["estimate"] / record["true_error"] if record["true_error"] > 0 else np.nan
        run = AdaptiveRun(problem, solution, found, (run.history if run else []) + [record], checks=checks)
        reason = _stop_reason(found["estimate"], step, settings)
        if reason is None:
            marked = (
                np.arange(mesh.n_cells)
                if settings.theta >= 1.0
                else dorfler_marking(found["indicator"], settings.theta)
            )
            refined = of_dimension("refine", mesh.dimension)(
                mesh, marked, max_hanging=settings.max_hanging, circles=circles
            )
            record["marked"], record["skipped"] = int(marked.size), int(refined.skipped.size)
            reason = _limit_reason(refined.mesh, settings.max_dofs, problem.space.element)  # before it is solved
            if reason is None and refined.refined.size == 0:
                reason = "unrefinable"
            mesh = (
                refined.mesh
                if reason is not None
                else checked_mesh(  # as every mesh a command solves
                    refined.mesh,
                    f"the refined mesh of step {step + 2}",
                    "please report it; meanwhile try another mesh size",
                )
            )
            previous = (refined, problem, solution)
        record["wall_time"] = time.perf_counter() - start
        if progress is not None:
            progress(step, record)
        if observe is not None:
            observe(step, run)
        if reason is not None:
            run.reason = reason
            return run
    run.reason = "max_steps"
    return run


def _limit_reason(mesh, max_dofs: int, element):
    """ "max_dofs" or "memory" when solving ``mesh`` with ``element`` would pass ``max_dofs`` or the memory
    this machine has (the prediction of ``vemkit.config.limits`` from the space's nodes), else None."""
    nodes = VirtualElementSpace(mesh, element).n_nodes
    estimate = RESOURCE_MODELS[mesh.dimension](mesh.n_cells, nodes, mesh.n_facets)
    if estimate.dofs > max_dofs:
        return "max_dofs"
    try:
        check_resources(estimate, None)
    except ResourceLimitError:
        return "memory"
    return None


def _stop_reason(estimate: float, step: int, settings: AdaptivitySettings):
    if estimate <= settings.target:
        return "target"
    if step + 1 >= settings.max_steps:
        return "max_steps"
    return None


#: why the loop stopped, in words (the CLI's note when the target was not reached)
STOP_REASONS = {
    "target": "the relative estimate reached adaptivity.target",
    "max_dofs": "the next mesh would exceed adaptivity.max_dofs (or --max-dofs)",
    "max_steps": "adaptivity.max_steps solves were done",
    "unrefinable": "no marked cell could be split (no centre in its kernel)",
    "memory": "the next mesh would need more memory than this machine has available",
}
_STEP_VARIABLES = (  # (name, long name, units) of what only the adaptive loop records
    ("estimate", "relative a posteriori estimate eta (vemkit.vem.estimator)", "1"),
    ("true_error", "relative H1-seminorm error of Pi u_h against the exact or reference solution", "1"),
    ("true_error_h1", "relative full H1-norm error of Pi u_h against the exact or reference solution", "1"),
    ("effectivity", "estimate / true_error", "1"),
    ("marked", "cells marked for refinement (0: the last step)", "1"),
    ("skipped", "marked cells that could not be split (no centre in their kernel)", "1"),
    ("linear_iterations", "inner linear iterations (CG) or direct solves of the contact solve", "1"),
    ("warm_start", "1: the solve started from the previous step's solution prolongated to this mesh", "1"),
    ("wall_time", "wall time of the step: assembly, solve, check, estimate, refinement (not error_time)", "s"),
    ("error_time", "wall time of measuring true_error (not part of wall_time)", "s"),
    ("solve_time", "assembly, contact solve and independent check", "s"),
)
#: name: (long name, units) of the per-step history; n_dofs, n_cells, iterations as in the convergence records
HISTORY_ATTRS = {
    **{name: RECORD_KEYS[name] for name in ("n_dofs", "n_cells", "iterations")},
    **{name: (long_name, units) for name, long_name, units in _STEP_VARIABLES},
}
_INTEGER_HISTORY = ("n_dofs", "n_cells", "marked", "skipped", "iterations", "linear_iterations", "warm_start")


def error_indicator_variable(mesh, indicator) -> tuple:
    """(dimension, values, attributes) of the file variable ``error_indicator``: η_K on the mesh's
    cells (``mesh2d_nFaces`` or ``mesh3d_nVolumes``)."""
    topology = mesh_topology(mesh)
    attrs = {
        "long_name": "a posteriori error indicator eta_K (vemkit.vem.estimator)",
        "mesh": topology.name,
        "location": topology.cell_location,
        "units": "sqrt(energy)",
    }
    return topology.cell_dimension, indicator, attrs


def adaptive_dataset(scene, run: AdaptiveRun, extra_attrs=None) -> xr.Dataset:
    """The final solution file (docs/reference/files.md) plus ``error_indicator`` per face and the per-step history
    on the ``adapt_step`` dimension (docs/reference/files.md). Entries a step does not have are not stored."""
    attrs = {"mesh_family": str(run.problem.mesh.meta.get("family", "")), **run.checks, **(extra_attrs or {})}
    try:
        with floating_point_errors_raise():
            ds = solution_dataset(run.problem, run.solution, scene_yaml=scene.to_yaml(), extra_attrs=attrs)
    except (FloatingPointError, OverflowError, ZeroDivisionError, RuntimeWarning) as error:
        raise ResultError(
            f"the stresses of the solution overflow double precision ({error}); "
            "rescale the units of the scene (E, k, tractions)"
        ) from None
    ds["error_indicator"] = error_indicator_variable(run.problem.mesh, run.indicators["indicator"])
    steps = len(run.history)
    for name, (long_name, units) in HISTORY_ATTRS.items():
        values = [record.get(name, 0 if name in ("marked", "skipped") else None) for record in run.history]
        if any(v is None for v in values):
            continue
        dtype = np.int64 if name in _INTEGER_HISTORY else float
        ds[f"adapt_{name}"] = ("adapt_step", np.asarray(values, dtype=dtype), {"long_name": long_name, "units": units})
    ds = ds.assign_coords(adapt_step=("adapt_step", np.arange(steps), {"long_name": "adaptive step"}))
    ds.attrs.update(
        {
            "adapt_stop_reason": run.reason,
            "adapt_steps": steps,
            "adapt_estimate": float(run.history[-1]["estimate"]),
            "adapt_wall_time": float(sum(r["wall_time"] for r in run.history)),
        }
    )
    return ds
