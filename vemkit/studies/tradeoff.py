"""Speed against accuracy: which (mesh family, solver, tolerance, stabilization, h) to pick.

Every run solves the scene on one mesh with one configuration and measures

- the error ||Pi_1(u_h - u_ref)|| / ||Pi_1 u_ref|| (full H1 norm, also the seminorm and L2) against
  ONE reference solution (the 2^-8 square mesh, docs/reference/mathematics.md), the same yardstick for every
  stabilization (``vemkit.vem.norms.projection_error``);
- the cost: ``cost_time`` = assembly + contact solve (with its linear solver set-up, nothing
  reused between runs; the fastest of ``repeats`` solves, after an untimed warm-up of the compiled
  kernels), and the number of free unknowns (DOFs). Mesh generation is recorded apart
  (``mesh_time``): a mesh is built once and reused.

A family may set ``order: 2`` (k = 2 virtual elements, ``vemkit.vem.elements.k2``). Its error is
that of Pi_2 u_h (3.8, the projection of every k = 2 degree of freedom, cell means recovered)
against the reference's projection (``vemkit.vem.norms.projection_error``, degree-5 rule on
the reference cells: exact for nested meshes), never Pi_1 of its vertex values; its DOFs count the
whole k = 2 space (vertex values, edge and cell means: ``n_dofs``; the condensed system the solver
sees: ``n_unknowns``), and its cost includes the condensation. The reference is the k = 1 2^-8
solution of the main workflow, so errors of k = 2 runs below the reference's own error (about 0.4 %
in H1 on the paper scene, README "Order 2") measure the distance to that reference, not to u.

Runs whose mesh is finer than the reference somewhere (hanging nodes: n 2^levels > n_ref) are
skipped: the error measure needs the reference at least as fine. The solver tolerance means the
Newton residual for ssn and eps_u = eps_lambda = tol (with the CG tolerance) for uzawa.

The records become the study's Dataset and its answers (Pareto fronts, the cheapest configuration
per target error, the Gamma_C gain) in :mod:`vemkit.studies.tradeoff_answers`.
"""

from __future__ import annotations

import json
import time

import numpy as np

from vemkit.exceptions import InputError
from vemkit.solvers.verification import guarded_solve

SCENE_SECTIONS = ("domain", "material", "body_force", "boundary", "contact")  # must match the reference's


def check_reference_scene(scene, reference_scene) -> None:
    """The reference must solve the same physical problem (domain, material, loads, contact).
    ``reference_scene``: its scene as a mapping, or the YAML text of its ``scene`` attribute (read by
    the safe loader, ``vemkit.config.safe_yaml``: a file's attribute is user input)."""
    from vemkit.config.safe_yaml import parse_yaml

    reference = (
        reference_scene
        if isinstance(reference_scene, dict)
        else parse_yaml(reference_scene or "", "the reference's scene attribute") or {}
    )
    if not isinstance(reference, dict):
        raise InputError(
            "the reference's scene attribute is not a scene (a mapping); give a solution file written by vemkit solve",
            key="reference",
        )
    mine = scene.data
    for section in SCENE_SECTIONS:
        if section in reference and reference.get(section) != mine.get(section):
            raise ValueError(
                f"the reference solution solves another problem: scene section {section!r} differs "
                f"({reference.get(section)!r} != {mine.get(section)!r})"
            )


def _finest_ok(spec: dict, n: int, reference_n: int) -> bool:
    """Every cell at least as large as a reference cell (the error quadrature lives on the reference)."""
    options = spec.get("options") or {}
    refinement = 2 ** int(options.get("levels", 0)) if spec["family"] == "hanging" else 1
    return n * refinement <= reference_n


def run_family(
    scene,
    label: str,
    spec: dict,
    reference,
    *,
    levels,
    solvers,
    tolerances,
    stabilizations,
    repeats: int = 1,
    time_budget=None,
    reference_n: int = 256,
    max_iterations=None,
    progress=None,
) -> list[dict]:
    """Records of every run of one mesh family (``spec``: {family, options, order}); see the module docstring.

    ``reference``: a ``vemkit.studies.error_records.ReferenceSolution``. All-triangle k = 1 families are
    solved with the first stabilization only (the VEM space is P1 there, the stabilization vanishes;
    not so for k = 2: the space has a cell mean beyond P2). ``max_iterations``: {solver: limit}.
    """
    from vemkit.contact.problem import scene_problem
    from vemkit.mesh.families import build_mesh

    order = family_order(spec)
    records = []
    from vemkit.vem.elements import element_for

    # on triangles an element equal to its polynomial space (k = 1: P1) has no stabilization: one is enough
    exact = spec["family"] == "triangle" and element_for(order).polynomial_on_triangles
    stabs = list(stabilizations)[:1] if exact else list(stabilizations)
    order_override = [f"discretization.order={order}"] if order != 1 else []
    _warm_up(scene.with_overrides(order_override), spec, stabs, solvers)
    measure = _ErrorMeasure(reference)
    for n in levels:
        if not _finest_ok(spec, n, reference_n):
            continue
        t0 = time.perf_counter()
        mesh = build_mesh(spec["family"], n, **(spec.get("options") or {}))
        mesh_time = time.perf_counter() - t0
        for stab in stabs:
            mesh_section = {"family": spec["family"], "n": int(n), **(spec.get("options") or {})}
            run_scene = scene.with_overrides(
                order_override
                + [f"discretization.stabilization={stab}", f"discretization.mesh={json.dumps(mesh_section)}"]
            )
            t0 = time.perf_counter()
            problem = scene_problem(run_scene, mesh)
            assembly_time = time.perf_counter() - t0
            for solver in solvers:
                for tol in tolerances:
                    options = {**run_scene.solver_options, "method": solver, "tol": float(tol)}
                    if (max_iterations or {}).get(solver):
                        options["max_iterations"] = int(max_iterations[solver])
                    if solver == "uzawa":
                        options.update(eps_u=float(tol), eps_lambda=float(tol))
                    best = _best_solve(problem, options, repeats, time_budget)
                    record = {
                        "family": label,
                        "family_name": spec["family"],
                        "solver": solver,
                        "tol": float(tol),
                        "stabilization": stab,
                        "n": int(n),
                        "order": order,
                        "n_dofs": int(getattr(problem, "n_space_dofs", problem.n_dofs)),
                        "n_unknowns": int(problem.n_dofs),
                        "n_cells": int(mesh.n_cells),
                        "h_min": float(_smallest_edge(mesh)),
                        "iterations": best.iterations,
                        "status": best.code,
                        "message": best.message,
                        "wall_time": best.wall_time,
                        "assembly_time": assembly_time,
                        "mesh_time": mesh_time,
                        "cost_time": assembly_time + best.wall_time,
                        "residual": float(best.checks.get("worst", np.nan)) if best.checks else float("nan"),
                    }
                    record.update(
                        measure(problem, best)
                        if best.converged
                        else {key: float("nan") for key in ("error_h1", "error_h1_semi", "error_l2")}
                    )
                    records.append(record)
                    if progress is not None:
                        progress(record)
    return records


def family_order(spec: dict) -> int:
    """The polynomial order k of a family spec (``order``: 1 or 2, default 1)."""
    order = spec.get("order", 1)
    if order not in (1, 2):
        raise InputError(f"tradeoff family order {order!r} is not supported: use order 1 or 2", key="order")
    return int(order)


def _best_solve(problem, options, repeats, time_budget):
    """The fastest of ``repeats`` guarded solves (a failure is not repeated)."""
    best = guarded_solve(problem, options, time_budget=time_budget, check_tol=None)
    for _ in range(int(repeats) - 1 if best.converged else 0):
        again = guarded_solve(problem, options, time_budget=time_budget, check_tol=None)
        best = again if again.converged and again.wall_time < best.wall_time else best
    return best


class _ErrorMeasure:
    """error_h1, error_h1_semi, error_l2 of a converged run against ``reference``: Pi u_h of the run's
    own space against the reference's projection (``vemkit.vem.norms.projection_error``), with a rule
    exact for the two projections' product (degree 2 for two k = 1 projections, the reference's own
    quadrature; degree 5 with a k = 2 one, built on first use)."""

    def __init__(self, reference):
        self.reference = reference
        self._quadrature = {}

    def __call__(self, problem, outcome) -> dict:
        from vemkit.vem.norms import projection_error
        from vemkit.vem.quadrature import reference_quadrature

        ref = self.reference
        degree = 2 * max(problem.order, getattr(ref, "order", 1))
        if degree == 2 * getattr(ref, "order", 1):
            quadrature = ref.quadrature
        else:
            quadrature = self._quadrature.setdefault(degree, reference_quadrature(ref.mesh, degree=degree))
        err = projection_error(problem.mesh, problem.projected(outcome.solution.u), ref.mesh, ref.projected, quadrature)
        return {"error_h1": err["h1"], "error_h1_semi": err["h1_semi"], "error_l2": err["l2"]}


def _warm_up(scene, spec, stabilizations, solvers):
    """One untimed assembly and solve per stabilization and solver on a 2 x 2 mesh: the first call of
    a kernel in a process loads its compiled code, which is no cost of the configuration timed next."""
    from vemkit.contact.problem import scene_problem
    from vemkit.mesh.families import build_mesh

    mesh = build_mesh(spec["family"], 2, **(spec.get("options") or {}))
    for stab in stabilizations:
        problem = scene_problem(scene.with_overrides([f"discretization.stabilization={stab}"]), mesh)
        for solver in solvers:
            guarded_solve(problem, {**scene.solver_options, "method": solver}, time_budget=10.0, check_tol=None)


def _smallest_edge(mesh) -> float:
    e = mesh.vertices[mesh.edges]
    return float(np.min(np.linalg.norm(e[:, 1] - e[:, 0], axis=1)))
