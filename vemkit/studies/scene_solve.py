"""One solve, from a validated scene to a result Dataset (or file description): scene -> mesh -> problem -> solver -> Dataset.

Before any mesh is built, :func:`vemkit.config.limits.check_scene_resources` predicts cells, DOFs
and peak memory from the scene alone and refuses a request beyond the limits. With ``verify=True`` a solve counts only if the independent
residual check (:func:`vemkit.solvers.verification.verify_solution`) meets the scene's accuracy
:func:`check_tolerance`; otherwise it raises VerificationError.
"""

from __future__ import annotations

from vemkit.config.expressions import vector_field
from vemkit.contact.problem import scene_problem
from vemkit.exceptions import MeshError, ResultError, VerificationError
from vemkit.io.solution_file import solution_description
from vemkit.mesh.mesh import Mesh
from vemkit.solvers.dispatch import floating_point_errors_raise, solve
from vemkit.solvers.verification import CHECK_KEYS, verify_solution

#: the independent check must meet min(max(CHECK_FACTOR * tol, CHECK_FLOOR), CHECK_CAP). Measured
#: (paper scene, n = 2 ... 64, square/voronoi/triangle/hanging): ssn's check is <= 1e-13 at tol <=
#: 1e-6 and ~1e-4 at tol = 1e-2; Uzawa's (stop=either) at most 6.2 tol (1.4e-8 at n = 64 triangles,
#: tol = 1e-10). The floor is the
#: studies' verification.DEFAULT_CHECK_TOL (rounding at large n and stiff contact), the cap keeps
#: a loose tol from accepting a residual above 1e-3.
CHECK_FACTOR = 1e3
CHECK_FLOOR = 1e-6
CHECK_CAP = 1e-3


def check_tolerance(solver_options: dict) -> float:
    """The accuracy the independent check must meet: min(max(CHECK_FACTOR * tol, CHECK_FLOOR),
    CHECK_CAP), tol the loosest of solver.tol, eps_u and eps_lambda (README "Input rules and limits")."""
    loosest = max(float(solver_options[k]) for k in ("tol", "eps_u", "eps_lambda") if solver_options.get(k) is not None)
    return min(max(CHECK_FACTOR * loosest, CHECK_FLOOR), CHECK_CAP)


def check_advice(method: str) -> str:
    """What to try when ``method``'s answer fails the independent check: never the method in use."""
    if method == "ssn":
        return "try a smaller solver.tol, or solver.method=uzawa"
    return "try solver.method=ssn or a smaller solver.tol"


def verified(problem, solution, solver_options, where: str = "", source: str = " (from solver.tol)") -> dict:
    """The independent check at :func:`check_tolerance`: {check_worst, check_tolerance}, or a
    VerificationError whose message says ``where`` the solve was (e.g. " on the 96-cell adapted mesh")."""
    tol = check_tolerance(solver_options)
    checks = verify_solution(problem, solution.u, solution.multiplier, tol)
    if not checks["passed"]:
        worst = max(CHECK_KEYS, key=lambda k: checks[k])
        raise VerificationError(
            f"{solution.method} stopped after {solution.iterations} iterations{where} but the independent "
            f"check fails: {worst} = {checks[worst]:.1e} > {tol:.1e}{source}; {check_advice(solution.method)}",
            solver=solution.method,
            iterations=solution.iterations,
        )
    return {"check_worst": float(checks["worst"]), "check_tolerance": tol}


def mesh_family(mesh) -> str:
    """The family that made ``mesh``; prisms over a 2D mesh (SPEC §10): ``extrude:`` and the base's family."""
    family = str(mesh.meta.get("family", ""))
    if family == "extrude":
        family += ":" + str(mesh.meta.get("base", {}).get("family", ""))
    return family


def solve_scene(scene, progress=None, mesh: Mesh | None = None, *, verify: bool = False, dataset: bool = True):
    """Solve a scene; returns (problem, solution, dataset).

    ``verify``: raise VerificationError unless the independent check meets
    :func:`check_tolerance`; the dataset then records ``check_worst`` and ``check_tolerance``.
    ``dataset=False``: the solution file's :class:`~vemkit.mesh.file_description.FileDescription`
    instead of its xarray Dataset (the command line: xarray and pandas are never imported).
    """
    problem = scene_problem(scene, mesh)
    if problem.mesh.n_cells == 0 or problem.n_dofs == 0:
        raise MeshError(
            f"the mesh has {problem.mesh.n_cells} cells and {problem.n_dofs} free DOFs; "
            "nothing to solve: check discretization.mesh",
            key="discretization.mesh",
        )
    solution = solve(problem, scene.solver_options, progress=progress)
    attrs = {"assembly_time": float(problem.info.get("assembly_time", 0.0)), "mesh_family": mesh_family(problem.mesh)}
    if verify:
        attrs.update(verified(problem, solution, scene.solver_options))
    if scene.exact_displacement is not None:  # SPEC §7: relative errors of Pi u_h against the exact field
        from vemkit.vem.norms import relative_exact_errors  # here: a solve without exact: never imports it

        attrs.update(
            relative_exact_errors(problem.mesh, problem.projected(solution.u), vector_field(scene.exact_displacement))
        )
    try:
        with floating_point_errors_raise():
            contents = solution_description(problem, solution, scene_yaml=scene.to_yaml(), extra_attrs=attrs)
    except (FloatingPointError, OverflowError, ZeroDivisionError, RuntimeWarning) as error:
        raise ResultError(
            f"the stresses of the solution overflow double precision ({error}); "
            "rescale the units of the scene (E, k, tractions)"
        ) from None
    return problem, solution, contents.to_dataset() if dataset else contents
