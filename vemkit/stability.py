"""Trustworthy or clearly failed: guarded solves with an independent check, and the stability matrix.

Every solve of the sweeps, the speed-accuracy study and the stability matrix goes through
:func:`guarded_solve`, which returns an :class:`Outcome` instead of raising. An outcome is
``converged`` only if the solver returned AND the independent check (:func:`verify_solution`)
passed; otherwise it names one class of :data:`FAILURE_CLASSES`:

    diverged             non-finite values, or the iteration grew (ConvergenceError)
    stagnated            the iteration stopped making progress (ConvergenceError)
    max_iterations       the iteration limit was reached first (ConvergenceError)
    inaccurate_stop      the stopping rule fired but the solver's own residual test refused (Uzawa)
    other                any other ConvergenceError
    time_budget          the solve ran past its time budget (checked after every iteration)
    check_failed         the solver returned, but the independent check failed
    linear_solver_failed a linear solve failed (LinearSolveError, also when wrapped)
    invalid_input        the scene, an override or the contact law was rejected (SceneError, ValueError)
    unexpected_exception anything else (a bug): the message keeps the exception type

The independent check uses only u and the friction multiplier lambda: ``contact_residual``
(equilibrium, |lambda| <= 1, lambda u_tau = |u_tau|) and, vertex by vertex, the contact conditions
read off the equilibrium reaction R = f - K u (at a contact vertex R_c = w_c [p_nu nu_c + p_tau
lambda_c tau_c], so R_c . tau_c = -w_c sigma_tau,c):

    normal_law      (2.6)  |R_c . nu_c - w_c p_nu(u_nu - g)| / F
    friction_bound  (2.7)  (|R_c . tau_c| - w_c p_tau(u_nu - g))_+ / F
    slip_direction  (2.8)  where |u_tau| > tol max|u| and p_tau > 0: |R_c . tau_c - w_c p_tau sign(u_tau)| / F
    stick           (2.9)  where |R_c . tau_c| < w_c p_tau - tol F: |u_tau| / max|u|

F = ||f|| (||f|| + ||contact forces|| without load), the scale of ``contact_residual``.

The stability matrix: :data:`CASES` (>= 50 cases, declared as data: scene overrides on the paper
scene), run with every solver by :func:`run_matrix`, gathered by :func:`stability_dataset`
(dims ``case`` x ``solver``) and tabulated by :func:`stability_markdown`.
"""

from __future__ import annotations

import json
import re
import time
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from vemkit.contact.solution import ConvergenceError, contact_force_vector, contact_residual, residual_scale
from vemkit.linear_solvers import LinearSolveError

FAILURE_CLASSES = ("diverged", "stagnated", "max_iterations", "inaccurate_stop", "other", "time_budget",
                   "check_failed", "linear_solver_failed", "invalid_input", "unexpected_exception")
_NOT_CONVERGED = FAILURE_CLASSES[:7]
#: status code i <-> STATUS_MEANINGS[i] (netCDF flag_values / flag_meanings)
STATUS_MEANINGS = ("converged",) + tuple(
    ("not_converged_" if c in _NOT_CONVERGED else "error_") + c for c in FAILURE_CLASSES)
CHECK_KEYS = ("equilibrium", "multiplier_bound", "complementarity", "normal_law", "friction_bound",
              "slip_direction", "stick")
DEFAULT_CHECK_TOL = 1e-6


def status_code(status: str) -> int:
    """0 for converged, 1 + the index of the failure class otherwise."""
    return 0 if status == "converged" else 1 + FAILURE_CLASSES.index(status)


class TimeBudgetExceeded(RuntimeError):
    """Raised from the solver's progress callback when a solve runs past its time budget."""


def failure_class(exc: BaseException, phase: str = "solve") -> str:
    """The class of an exception from setting up (``phase="setup"``) or running a solve."""
    from vemkit.scene import SceneError

    declared = getattr(exc, "kind", None) or getattr(exc, "reason", None)
    if isinstance(declared, str) and declared in FAILURE_CLASSES:
        return declared
    if isinstance(exc, TimeBudgetExceeded):
        return "time_budget"
    if isinstance(exc, LinearSolveError) or isinstance(exc.__context__, LinearSolveError):
        return "linear_solver_failed"
    if isinstance(exc, ConvergenceError):
        message = str(exc)
        if re.search(r"diverged|non-finite|grew", message):
            return "diverged"
        if "stagnated" in message:
            return "stagnated"
        if re.search(r"max_iterations = \d+ reached|did not converge after \d+ iterations \(residual", message):
            return "max_iterations"
        if re.search(r"stopped after \d+ iterations .*residual", message):
            return "inaccurate_stop"
        return "other"
    if isinstance(exc, SceneError) or (isinstance(exc, ValueError) and (
            phase == "setup" or str(exc).startswith(("solver.", "contact", "material.", "discretization.")))):
        return "invalid_input"
    return "unexpected_exception"


def iterations_from_message(message: str) -> int:
    """The iteration count named in a ConvergenceError ("... after 200 iterations ..."), or -1."""
    found = re.search(r"after (\d+) iterations", message)
    return int(found.group(1)) if found else -1


def verify_solution(problem, u, multiplier, tol: float = DEFAULT_CHECK_TOL) -> dict:
    """The independent check of the module docstring: {measure: value, "worst": max, "passed": bool}."""
    u = np.asarray(u, dtype=float)
    lam = np.asarray(multiplier, dtype=float)
    out = {k: float(v) for k, v in contact_residual(problem, u, lam).items() if k != "worst"}
    cb, law = problem.contact, problem.law
    finite = np.all(np.isfinite(u)) and np.all(np.isfinite(lam))
    if not finite:
        out.update({k: float("inf") for k in CHECK_KEYS})
    elif cb.size == 0:
        out.update({k: 0.0 for k in CHECK_KEYS[3:]})
    else:
        f = problem.load
        reaction = f - problem.stiffness @ u
        r = reaction[cb.dofs]  # (n_c, 2)
        r_nu = np.sum(r * cb.normal, axis=1)
        r_tau = np.sum(r * cb.tangent, axis=1)
        scale = residual_scale(float(np.linalg.norm(f)), float(np.linalg.norm(contact_force_vector(problem, u, lam))))
        t = cb.normal_displacement(u) - cb.gap
        slip = cb.tangential_displacement(u)
        bound = cb.weight * law.friction_bound(t)
        umax = float(np.max(np.abs(u))) or 1.0
        slipping = (np.abs(slip) > tol * umax) & (bound > 0.0)
        inside = np.abs(r_tau) < bound - tol * scale
        out["normal_law"] = float(np.max(np.abs(r_nu - cb.weight * law.normal_pressure(t)))) / scale
        out["friction_bound"] = float(np.max(np.maximum(np.abs(r_tau) - bound, 0.0))) / scale
        out["slip_direction"] = float(np.max(np.abs(r_tau - bound * np.sign(slip))[slipping], initial=0.0)) / scale
        out["stick"] = float(np.max(np.abs(slip[inside]), initial=0.0)) / umax
    out["worst"] = max(out[k] for k in CHECK_KEYS)
    out["passed"] = bool(out["worst"] <= tol)
    return out


@dataclass
class Outcome:
    """What became of one solve; ``solution`` is None unless the solver returned."""

    method: str
    status: str  # "converged" or a failure class
    message: str = ""
    solution: object = None
    checks: dict = field(default_factory=dict)
    wall_time: float = 0.0  # seconds around the solver call (with its linear solver set-up)
    iterations: int = -1

    @property
    def converged(self) -> bool:
        return self.status == "converged"

    @property
    def code(self) -> int:
        return status_code(self.status)


def failed(method: str, exc: BaseException, phase: str, wall_time: float = 0.0) -> Outcome:
    status = failure_class(exc, phase)
    message = " ".join(str(exc).split()) or type(exc).__name__
    if status == "unexpected_exception":
        message = f"{type(exc).__name__}: {message}"
    return Outcome(method, status, message, wall_time=wall_time, iterations=iterations_from_message(message))


@lru_cache(maxsize=None)
def prebuilt_linear_supported() -> bool:
    """Whether the contact solvers take a prebuilt ``linear`` solver: both hand ``linear`` to
    ``vemkit.linear_solvers.linear_solver``, which returns a solver built earlier as it is (once it
    knows how; before, it rejected anything but a method name)."""
    import scipy.sparse as sp

    from vemkit.linear_solvers import linear_solver

    A = sp.identity(2, format="csr")
    built = linear_solver(A, "direct")
    try:
        return linear_solver(A, built) is built
    except (ValueError, TypeError):
        return False


def guarded_solve(problem, solver_options: dict, *, linear=None, time_budget: float | None = None,
                  check_tol: float | None = DEFAULT_CHECK_TOL) -> Outcome:
    """Run the configured solver on ``problem``; never raises (see :class:`Outcome`).

    ``linear``: a prebuilt solver of ``problem.stiffness`` (``vemkit.linear_solvers.linear_solver``),
    used when the contact solver accepts one (:func:`prebuilt_linear_supported`).
    ``check_tol``: None records the independent check without judging it.
    """
    from vemkit.run import solve_problem

    options = dict(solver_options)
    method = str(options.get("method", "ssn"))
    if linear is not None and prebuilt_linear_supported():
        options["linear"] = linear
    start = time.perf_counter()

    def progress(_iteration, _record):
        if time_budget is not None and time.perf_counter() - start > time_budget:
            raise TimeBudgetExceeded(f"{method} ran past its time budget of {time_budget:g} s "
                                     f"after {_iteration} iterations")

    try:
        solution = solve_problem(problem, options, progress=progress)
    except Exception as exc:  # noqa: BLE001 - every failure is classified, none escapes
        return failed(method, exc, "solve", time.perf_counter() - start)
    wall = time.perf_counter() - start
    checks = verify_solution(problem, solution.u, solution.multiplier, check_tol or DEFAULT_CHECK_TOL)
    outcome = Outcome(method, "converged", "", solution, checks, wall, int(solution.iterations))
    if check_tol is not None and not checks["passed"]:
        worst = max(CHECK_KEYS, key=lambda k: checks[k])
        outcome.status = "check_failed"
        outcome.message = (f"{method} reported convergence after {solution.iterations} iterations but the "
                           f"independent check fails: {worst} = {checks[worst]:.1e} > {check_tol:.0e}")
    return outcome


# -- the stability matrix ---------------------------------------------------------------------------
def _case(name, group, **settings):
    return {"name": name, "group": group, "set": settings}


_K_NU, _K_TAU, _M_NU, _M_TAU = "contact.normal.k", "contact.friction.k", "contact.normal.m", "contact.friction.m"
_GAP, _E, _NU, _MESH = "contact.gap", "material.E", "material.nu", "discretization.mesh"
#: the cases: overrides of the base scene (the paper's, E = 2000, kappa = 0.4, g_a = 0.1, k_nu = 10,
#: m_nu = 1, k_tau = 450, m_tau = 0) at the matrix's mesh (``discretization.mesh.n`` of run_matrix)
CASES = [
    _case("paper", "baseline"),
    *(_case(f"k_nu={k:g}", "normal stiffness", **{_K_NU: k})
      for k in (1e-3, 1e-1, 1.0, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8)),
    *(_case(f"k_tau={k:g}", "friction bound", **{_K_TAU: k}) for k in (0.0, 1.0, 10.0, 1e3, 1e4, 1e5, 1e6)),
    *(_case(f"m_nu={m:g},k_nu={k:g}", "normal exponent", **{_M_NU: m, _K_NU: k})
      for m in (2.0, 3.0) for k in (10.0, 1e4, 1e8)),
    *(_case(f"m_tau=1,k_tau={k:g}", "friction exponent", **{_M_TAU: 1.0, _K_TAU: k}) for k in (450.0, 1e4, 1e6)),
    _case("m_tau=1,m_nu=3,k_nu=1e4", "friction exponent", **{_M_TAU: 1.0, _M_NU: 3.0, _K_NU: 1e4}),
    *(_case(f"kappa={nu:g}", "Poisson ratio", **{_NU: nu}) for nu in (0.0, 0.3, 0.45, 0.49, 0.499, 0.4999)),
    _case("kappa=0.4999,k_nu=1e6", "Poisson ratio", **{_NU: 0.4999, _K_NU: 1e6}),
    _case("kappa=0.4999,voronoi", "Poisson ratio", **{_NU: 0.4999, _MESH: {"family": "voronoi", "seed": 1}}),
    *(_case(f"E={E:g}", "Young modulus", **{_E: E}) for E in (2e-3, 2e9)),
    _case("E=2e-3,k_nu=1e-3", "Young modulus", **{_E: 2e-3, _K_NU: 1e-3}),
    _case("E=2e9,k_nu=1e8", "Young modulus", **{_E: 2e9, _K_NU: 1e8}),
    _case("E=2e9,k_tau=1e6", "Young modulus", **{_E: 2e9, _K_TAU: 1e6}),
    _case("E=2e-3,g_a=10", "Young modulus", **{_E: 2e-3, _GAP: 10.0}),
    *(_case(f"g_a={g:g}", "gap", **{_GAP: g}) for g in (0.0, 10.0)),
    _case("g_a=0,k_nu=1e8", "gap", **{_GAP: 0.0, _K_NU: 1e8}),
    _case("g_a=10,k_tau=0", "gap", **{_GAP: 10.0, _K_TAU: 0.0}),
    *(_case(f"voronoi,anisotropy={a:g}", "mesh", **{_MESH: {"family": "voronoi", "seed": 1, "anisotropy": a}})
      for a in (4.0, 10.0)),
    _case("voronoi,tiny edges", "mesh",
          **{_MESH: {"family": "voronoi", "seed": 2, "lloyd_iterations": 0, "merge_tol": 0.0}}),
    _case("voronoi,tiny edges,anisotropy=10", "mesh",
          **{_MESH: {"family": "voronoi", "seed": 3, "lloyd_iterations": 0, "merge_tol": 0.0, "anisotropy": 10.0}}),
    *(_case(f"hanging,levels={L}", "mesh", **{_MESH: {"family": "hanging", "levels": L, "rule": "contact"}})
      for L in (3, 5)),
    _case("hanging,random,levels=4", "mesh",
          **{_MESH: {"family": "hanging", "levels": 4, "rule": "random", "seed": 1, "fraction": 0.3}}),
    _case("triangle,delaunay", "mesh", **{_MESH: {"family": "triangle", "kind": "delaunay", "seed": 1}}),
    _case("k_nu=1e8,m_nu=3,k_tau=1e6", "combined", **{_K_NU: 1e8, _M_NU: 3.0, _K_TAU: 1e6}),
    _case("hanging,levels=4,k_nu=1e8", "combined",
          **{_K_NU: 1e8, _MESH: {"family": "hanging", "levels": 4, "rule": "contact"}}),
    _case("tiny edges,kappa=0.4999,k_nu=1e6", "combined",
          **{_NU: 0.4999, _K_NU: 1e6, _MESH: {"family": "voronoi", "seed": 2, "lloyd_iterations": 0, "merge_tol": 0.0}}),
    _case("m_nu=3,k_nu=1e-3,g_a=0", "combined", **{_M_NU: 3.0, _K_NU: 1e-3, _GAP: 0.0}),
    _case("E=2e9,kappa=0.4999,k_nu=1e-3", "combined", **{_E: 2e9, _NU: 0.4999, _K_NU: 1e-3}),
]


def case_overrides(case: dict, n: int) -> list[str]:
    """Scene overrides of a case on an n x n mesh (a mesh entry replaces the whole mesh section)."""
    settings = dict(case["set"])
    mesh = {"family": "square", **settings.pop(_MESH, {}), "n": int(n)}
    return [f"{_MESH}={json.dumps(mesh)}"] + [f"{k}={json.dumps(v)}" for k, v in settings.items()]


def run_case(scene, case: dict, solvers: dict, n: int, *, time_budget=None, check_tol=DEFAULT_CHECK_TOL) -> dict:
    """Every solver on one case: {"case", "n_dofs", "outcomes": {method: Outcome}}.

    ``solvers``: {method: extra solver options}. The problem (and one linear solver, when the solver
    takes it) is built once for all solvers.
    """
    from vemkit.linear_solvers import linear_solver
    from vemkit.run import scene_problem

    result = {"case": case, "n_dofs": -1, "parameters": {}, "outcomes": {}}
    try:
        case_scene = scene.with_overrides(case_overrides(case, n))
        result["parameters"] = case_parameters(case_scene)
        problem = scene_problem(case_scene)
        linear = None
        if prebuilt_linear_supported():
            options = case_scene.solver_options
            linear = linear_solver(problem.stiffness, options.get("linear", "auto"),
                                   near_nullspace=problem.near_nullspace, tol=options["tol"])
    except Exception as exc:  # noqa: BLE001 - an invalid case is a classified failure of every solver
        result["outcomes"] = {m: failed(m, exc, "setup") for m in solvers}
        return result
    result["n_dofs"] = int(problem.n_dofs)
    for method, extra in solvers.items():
        options = {**case_scene.solver_options, **(extra or {}), "method": method}
        result["outcomes"][method] = guarded_solve(problem, options, linear=linear, time_budget=time_budget,
                                                   check_tol=check_tol)
    return result


PARAMETERS = {  # variable name: (scene path, long name)
    "k_nu": (("contact", "normal", "k"), "normal compliance coefficient k_nu (5.1)"),
    "m_nu": (("contact", "normal", "m"), "normal compliance exponent m_nu (5.1)"),
    "k_tau": (("contact", "friction", "k"), "friction bound coefficient k_tau (5.1)"),
    "m_tau": (("contact", "friction", "m"), "friction bound exponent m_tau (5.1)"),
    "g_a": (("contact", "gap"), "initial gap g_a"),
    "E": (("material", "E"), "Young modulus E"),
    "kappa": (("material", "nu"), "Poisson ratio kappa"),
}


def case_parameters(scene) -> dict:
    """The physical parameters of a case scene (NaN where not a number, e.g. a gap expression)."""
    data = scene.data
    out = {}
    for name, (path, _) in PARAMETERS.items():
        value = data
        for part in path:
            value = value.get(part, {}) if isinstance(value, dict) else {}
        out[name] = float(value) if isinstance(value, (int, float)) else float("nan")
    out["mesh"] = json.dumps(data["discretization"]["mesh"], sort_keys=True)
    return out


def select_cases(names=None) -> list[dict]:
    """The cases named (all of :data:`CASES` for None); an unknown name is an error."""
    if names is None:
        return list(CASES)
    index = {c["name"]: c for c in CASES}
    unknown = [name for name in names if name not in index]
    if unknown:
        raise ValueError(f"stability case {unknown[0]!r} is unknown; cases: {', '.join(index)}")
    return [index[name] for name in names]


def run_matrix(scene, cases, solvers: dict, n: int, *, time_budget=None, check_tol=DEFAULT_CHECK_TOL,
               progress=None) -> list[dict]:
    """run_case for every case; progress(result) after each."""
    results = []
    for case in cases:
        results.append(run_case(scene, case, solvers, n, time_budget=time_budget, check_tol=check_tol))
        if progress is not None:
            progress(results[-1])
    return results


def stability_dataset(results, *, scene_yaml: str = "", settings=None):
    """The matrix as a Dataset: dims ``case`` x ``solver``; NaN / -1 where undefined (see sweeps.write_dataset)."""
    import xarray as xr

    import vemkit

    methods = list(dict.fromkeys(m for r in results for m in r["outcomes"]))
    names = [r["case"]["name"] for r in results]
    shape = (len(results), len(methods))
    status = np.zeros(shape, np.int8)
    iterations = np.full(shape, -1, np.int64)
    wall = np.zeros(shape)
    checks = {k: np.full(shape, np.nan) for k in (*CHECK_KEYS, "worst")}
    messages = np.full(shape, "", dtype=object)
    for i, r in enumerate(results):
        for j, m in enumerate(methods):
            o = r["outcomes"][m]
            status[i, j], iterations[i, j], wall[i, j], messages[i, j] = o.code, o.iterations, o.wall_time, o.message
            for k in checks:
                if o.checks and np.isfinite(o.checks.get(k, np.nan)):
                    checks[k][i, j] = o.checks[k]
    dims = ("case", "solver")
    ds = xr.Dataset(coords={"case": ("case", np.array(names, dtype=object), {"long_name": "stability case"}),
                            "solver": ("solver", np.array(methods, dtype=object), {"long_name": "contact solver"})})
    ds["group"] = ("case", np.array([r["case"]["group"] for r in results], dtype=object))
    ds["overrides"] = ("case", np.array([json.dumps(r["case"]["set"], sort_keys=True) for r in results], dtype=object),
                       {"long_name": "the case's settings on top of the base scene (JSON)"})
    for name, (_, long_name) in PARAMETERS.items():
        ds[name] = ("case", np.array([r["parameters"].get(name, np.nan) for r in results], float), {"long_name": long_name})
    ds["mesh"] = ("case", np.array([r["parameters"].get("mesh", "") for r in results], dtype=object),
                  {"long_name": "discretization.mesh of the case (JSON)"})
    ds["n_dofs"] = ("case", np.array([r["n_dofs"] for r in results], np.int64), {"long_name": "free unknowns (-1: not built)"})
    ds["status"] = (dims, status, {"long_name": "outcome of the solve", "flag_values": np.arange(len(STATUS_MEANINGS), dtype=np.int8),
                                   "flag_meanings": " ".join(STATUS_MEANINGS)})
    ds["iterations"] = (dims, iterations, {"long_name": "nonlinear iterations (-1: unknown)"})
    ds["wall_time"] = (dims, wall, {"long_name": "wall time of the solve", "units": "s"})
    for k, values in checks.items():
        ds[f"check_{k}"] = (dims, values, {"long_name": f"independent check: {k} (dimensionless, see vemkit.stability)"})
    ds["message"] = (dims, messages, {"long_name": "failure message (empty when converged)"})
    ds.attrs.update({"title": "vemkit stability matrix", "scene": scene_yaml, "vemkit_version": vemkit.__version__,
                     "settings": json.dumps(settings or {}, sort_keys=True, default=str),
                     "check_tol": float((settings or {}).get("check_tol", DEFAULT_CHECK_TOL))})
    return summarize(ds)


def summarize(ds):
    """Attributes counting the cases and the outcomes per solver (after gathering parts too)."""
    status = ds["status"].values
    counts = {str(m): {STATUS_MEANINGS[c]: int(np.sum(status[:, j] == c)) for c in np.unique(status[:, j])}
              for j, m in enumerate(ds["solver"].values)}
    ds.attrs.update({"cases": int(ds.sizes["case"]), "outcomes_per_solver": json.dumps(counts, sort_keys=True),
                     "converged_per_solver": json.dumps({m: c.get("converged", 0) for m, c in counts.items()})})
    return ds


def _cell(ds, i, j) -> str:
    status = STATUS_MEANINGS[int(ds["status"].values[i, j])]
    its = int(ds["iterations"].values[i, j])
    worst = ds["check_worst"].values[i, j]
    if status == "converged":
        return f"ok, {its} it, {worst:.0e}, {ds['wall_time'].values[i, j]:.2f} s"
    return f"**{status.split('_', 2)[-1] if status.startswith('not_') else status}**" + (f" ({its} it)" if its >= 0 else "")


def stability_markdown(ds) -> str:
    """A Markdown report: summary per solver, one row per case, then every failure message."""
    methods = [str(m) for m in ds["solver"].values]
    lines = ["# Stability matrix", "",
             f"{ds.attrs.get('cases', ds.sizes['case'])} cases; each cell: outcome, iterations, worst "
             "independent check (dimensionless), wall time.", ""]
    for j, m in enumerate(methods):
        codes = ds["status"].values[:, j]
        counts = {STATUS_MEANINGS[c]: int(np.sum(codes == c)) for c in np.unique(codes)}
        lines.append(f"- **{m}**: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items(), key=lambda kv: -kv[1])))
    lines += ["", "| case | group | dofs | " + " | ".join(methods) + " |", "|---|---|---:|" + "---|" * len(methods)]
    for i, name in enumerate(ds["case"].values):
        cells = " | ".join(_cell(ds, i, j) for j in range(len(methods)))
        lines.append(f"| {name} | {ds['group'].values[i]} | {int(ds['n_dofs'].values[i])} | {cells} |")
    failures = [(str(ds["case"].values[i]), methods[j], str(ds["message"].values[i, j]))
                for i in range(ds.sizes["case"]) for j in range(len(methods)) if ds["status"].values[i, j] != 0]
    if failures:
        lines += ["", "## Failures", ""] + [f"- {case} / {m}: {msg}" for case, m, msg in failures]
    return "\n".join(lines) + "\n"
