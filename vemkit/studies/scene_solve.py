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
#: solver.tol of a problem built without a scene (the scene schema's default)
DEFAULT_SOLVER_TOL = 1e-10


def check_tolerance(solver_options: dict) -> float:
    """The accuracy the independent check must meet: min(max(CHECK_FACTOR * tol, CHECK_FLOOR),
    CHECK_CAP), tol the loosest of solver.tol, eps_u and eps_lambda (README "Input rules and limits")."""
    loosest = max(float(solver_options[k]) for k in ("tol", "eps_u", "eps_lambda") if solver_options.get(k) is not None)
    return min(max(CHECK_FACTOR * loosest, CHECK_FLOOR), CHECK_CAP)


def checked(problem, solution, solver_options) -> dict:
    """The independent check at :func:`check_tolerance`, recorded and not enforced:
    {check_worst, check_tolerance} (the Python API's Dataset; :func:`verified` enforces it)."""
    return _check_record(*_independent_check(problem, solution, solver_options))


def _independent_check(problem, solution, solver_options) -> tuple[dict, float]:
    tol = check_tolerance(solver_options)
    return verify_solution(problem, solution.u, solution.multiplier, tol), tol


def _check_record(checks: dict, tol: float) -> dict:
    return {"check_worst": float(checks["worst"]), "check_tolerance": tol}


def check_advice(method: str) -> str:
    """What to try when ``method``'s answer fails the independent check: never the method in use."""
    if method == "ssn":
        return "try a smaller solver.tol, or solver.method=uzawa"
    return "try solver.method=ssn or a smaller solver.tol"


def verified(problem, solution, solver_options, where: str = "", source: str = " (from solver.tol)") -> dict:
    """The independent check at :func:`check_tolerance`: {check_worst, check_tolerance}, or a
    VerificationError whose message says ``where`` the solve was (e.g. " on the 96-cell adapted mesh")."""
    checks, tol = _independent_check(problem, solution, solver_options)
    if not checks["passed"]:
        worst = max(CHECK_KEYS, key=lambda k: checks[k])
        raise VerificationError(
            f"{solution.method} stopped after {solution.iterations} iterations{where} but the independent "
            f"check fails: {worst} = {checks[worst]:.1e} > {tol:.1e}{source}; {check_advice(solution.method)}",
            solver=solution.method,
            iterations=solution.iterations,
        )
    return _check_record(checks, tol)


def mesh_family(mesh) -> str:
    """The family that made ``mesh``; prisms over a 2D mesh (docs/reference/files.md): ``extrude:`` and the base's family."""
    family = str(mesh.meta.get("family", ""))
    if family == "extrude":
        family += ":" + str(mesh.meta.get("base", {}).get("family", ""))
    return family


def solve_scene(
    scene, progress=None, mesh: Mesh | None = None, *, verify: bool = False, dataset: bool = True, comm=None
):
    """Solve a scene; returns (problem, solution, dataset).

    ``verify``: raise VerificationError unless the independent check meets
    :func:`check_tolerance`; the dataset then records ``check_worst`` and ``check_tolerance``.
    ``dataset=False``: the solution file's :class:`~vemkit.mesh.file_description.FileDescription`
    instead of its xarray Dataset (the command line: xarray and pandas are never imported).
    ``comm``: the MPI communicator of a job on several ranks (``vemkit.vem.parallel.world``): the
    problem is split across them; every rank returns the whole solution.
    """
    problem = scene_problem(scene, mesh, comm=comm)
    if problem.mesh.n_cells == 0 or problem.n_dofs == 0:
        raise MeshError(
            f"the mesh has {problem.mesh.n_cells} cells and {problem.n_dofs} free DOFs; "
            "nothing to solve: check discretization.mesh",
            key="discretization.mesh",
        )
    solution = solve(problem, scene.solver_options, progress=progress)
    contents = solution_contents(problem, solution, scene, verify=verify, check=verify)
    return problem, solution, contents.to_dataset() if dataset else contents


def solution_contents(problem, solution, scene=None, *, verify: bool = False, check: bool = True):
    """The solution file's :class:`~vemkit.mesh.file_description.FileDescription`, exactly as
    ``vemkit solve`` writes it: one function for the command and the Python API
    (:func:`solution_dataset`). ``scene``: the scene of the problem (default: the one
    :func:`vemkit.scene_problem` recorded in ``problem.info``); its YAML text, the mesh family, the
    assembly time, the independent check (``verify``: enforced; else recorded unless ``check`` is
    False) and, with ``exact:``, the relative errors become global attributes."""
    if scene is None:
        scene = problem.info.get("scene")
    attrs = {"assembly_time": float(problem.info.get("assembly_time", 0.0)), "mesh_family": mesh_family(problem.mesh)}
    solver_options = scene.solver_options if scene is not None else {"tol": DEFAULT_SOLVER_TOL}
    if verify or check:
        attrs.update((verified if verify else checked)(problem, solution, solver_options))
    # with exact: the relative errors of Pi u_h against the exact field (docs/reference/files.md)
    if scene is not None and scene.exact_displacement is not None:
        from vemkit.vem.norms import relative_exact_errors  # here: a solve without exact: never imports it

        attrs.update(
            relative_exact_errors(problem.mesh, problem.projected(solution.u), vector_field(scene.exact_displacement))
        )
    try:
        with floating_point_errors_raise():
            return solution_description(
                problem, solution, scene_yaml=scene.to_yaml() if scene is not None else "", extra_attrs=attrs
            )
    except (FloatingPointError, OverflowError, ZeroDivisionError, RuntimeWarning) as error:
        raise ResultError(
            f"the stresses of the solution overflow double precision ({error}); "
            "rescale the units of the scene (E, k, tractions)"
        ) from None


def solution_dataset(problem, solution, scene=None):
    """Everything a user needs from one solve as an xarray Dataset: the same variables and global
    attributes as the file ``vemkit solve`` writes for the scene (:func:`solution_contents`; the
    scene is the one :func:`vemkit.scene_problem` built ``problem`` from, unless given). The
    independent check is recorded (``check_worst`` against ``check_tolerance``), not enforced."""
    return solution_contents(problem, solution, scene).to_dataset()
