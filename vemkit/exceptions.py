"""Layer 0: every failure vemkit reports, as typed exceptions with attributes.

Callers classify failures by type and attributes (``reason``, ``iterations``, ``solver``, ``key``),
never by parsing messages. Messages are one line naming the input or the culprit and the fix.
Imports nothing from vemkit.

    VemkitError
    ├── InputError (ValueError)           something the user gave is not usable
    │   ├── SceneError                    a scene file, a ``--set`` override, a CLI option
    │   ├── ExpressionError               an expression in a scene
    │   ├── MeshError                     a mesh (built or read) the solver must not use
    │   ├── ResultError                   a result that must not be written (NaN, wrong shape)
    │   ├── OutputError                   an output path that must not or cannot be written
    │   ├── ResourceLimitError            a request beyond a documented limit or the machine
    │   └── WorkflowConfigError           a value of the Snakemake workflow's configuration
    └── SolveError (RuntimeError)         a solve that did not produce a trustworthy answer
        ├── ConvergenceError              a contact solver did not converge (``reason``)
        ├── LinearSolveError              a linear solve failed
        ├── TimeBudgetExceeded            a solve ran past its wall-time budget
        └── VerificationError             the independent check of a returned solution failed
"""

from __future__ import annotations


def _one_line(message) -> str:
    return " ".join(str(message).split())


class VemkitError(Exception):
    """Base of every vemkit failure; ``str(error)`` is one line."""

    def __init__(self, message: str = ""):
        super().__init__(_one_line(message))


class InputError(VemkitError, ValueError):
    """Bad input; ``key`` names it (a scene key, an option, a path) when known."""

    def __init__(self, message: str = "", *, key: str | None = None):
        super().__init__(message)
        self.key = key


class SceneError(InputError):
    """An invalid scene, scene file, override or option; the message names the key and the fix."""


class ExpressionError(InputError):
    """A scene expression that cannot be compiled or evaluates to NaN/inf."""

    def __init__(self, message: str = "", *, name: str | None = None, text: str | None = None):
        super().__init__(message, key=name)
        self.name = name
        self.text = text


class MeshError(InputError):
    """A mesh that the solver must not use; the message names the offending item and the fix."""


class ResultError(InputError):
    """A result that must not be stored (non-finite values, inconsistent shapes)."""


class OutputError(InputError):
    """An output path that is refused (an input, a directory, a device) or could not be written."""


class ResourceLimitError(InputError):
    """A request beyond a documented limit or the machine; ``estimate`` holds the prediction."""

    def __init__(self, message: str = "", *, key: str | None = None, estimate: dict | None = None):
        super().__init__(message, key=key)
        self.estimate = dict(estimate or {})


class WorkflowConfigError(InputError):
    """A value of the workflow's configuration (config/*.yaml, --configfile, --config) refused before any
    job. ``path``: the config key as segments (``("sweeps", "mine", "grid", "contact.normal.k", 0)``),
    ``key`` its text (``sweeps.mine.grid.contact.normal.k[0]``); the message says what is wrong and the fix,
    the Snakefile prefixes the file that set the key."""

    def __init__(self, message: str = "", *, path=()):
        self.path = tuple(path)
        text = ""
        for part in self.path:
            text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
        super().__init__(message, key=text or "(top level)")


#: why a solve failed (``SolveError.reason``); the robustness study classifies by these, in this order
#: (its status codes, ``vemkit.solvers.verification.FAILURE_CLASSES``)
SOLVE_FAILURE_REASONS = (
    "diverged",
    "stagnated",
    "max_iterations",
    "inaccurate_stop",
    "other",
    "time_budget",
    "check_failed",
    "linear_solver_failed",
)


class SolveError(VemkitError, RuntimeError):
    """A solve that did not produce a trustworthy answer.

    ``solver``: "ssn", "uzawa", "direct", "amg" … ; ``reason``: one of :data:`SOLVE_FAILURE_REASONS`;
    ``iterations``: the iteration at which it stopped (-1: unknown).
    """

    default_reason = "other"

    def __init__(self, message: str = "", *, solver: str = "", reason: str | None = None, iterations: int = -1):
        super().__init__(message)
        self.solver = solver
        self.reason = reason or self.default_reason
        self.iterations = int(iterations)
        if self.reason not in SOLVE_FAILURE_REASONS:
            raise ValueError(f"unknown solve failure reason {self.reason!r}")


class ConvergenceError(SolveError):
    """A contact solver did not converge; ``reason`` says how it failed."""


class LinearSolveError(SolveError):
    """A linear solve failed (breakdown, no convergence, a singular factorization)."""

    default_reason = "linear_solver_failed"


class TimeBudgetExceeded(SolveError):
    """A solve ran past its wall-time budget (checked after every iteration)."""

    default_reason = "time_budget"


class VerificationError(SolveError):
    """The solver returned, but the independent residual check did not meet the requested accuracy."""

    default_reason = "check_failed"
