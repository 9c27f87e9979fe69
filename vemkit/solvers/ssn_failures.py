"""Why the semismooth Newton method (vemkit.solvers.ssn) failed: one ConvergenceError naming the likely culprit."""

from __future__ import annotations

from vemkit.exceptions import ConvergenceError
from vemkit.solvers.solution import young_modulus

CONTRAST_WARNING = 1e8  # failures with w p_nu' / kd above this are blamed on the conditioning


def fail(problem, k, what, records, contrast=0.0, *, reason):
    """Raise a one-line ConvergenceError (``reason``, see vemkit.exceptions) naming the likely culprit."""
    law, E = problem.law, young_modulus(problem)
    head = f"ssn did not converge after {k} iterations ({what})"
    if contrast > CONTRAST_WARNING:
        culprit = (
            f"{law.normal_stiffness_text} makes the contact {contrast:.0e} times stiffer than the body "
            f"(E = {E:g}), beyond what double precision resolves; lower {law.normal_stiffness_key} or rescale E"
        )
    elif not law.reduced:
        culprit = (
            f"the friction bound of {law.friction_text} couples too strongly to the penetration "
            f"({law.normal_stiffness_text}); try a smaller contact.friction.k"
        )
    elif any(r["active_changes"] > 0 for r in records[-5:]):
        culprit = (
            f"the stick/slip/contact sets keep changing (contact.friction.k = {law.friction_coefficient:g}, "
            f"{law.normal_stiffness_text}, E = {E:g}); try a larger solver.max_iterations or solver.linear=direct"
        )
    else:
        culprit = (
            f"the normal compliance {law.normal_text} converges slowly against E = {E:g}; "
            f"try a larger solver.max_iterations"
        )
    raise ConvergenceError(f"{head}: {culprit}", solver="ssn", reason=reason, iterations=k)
