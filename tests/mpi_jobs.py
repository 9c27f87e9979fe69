"""MPI jobs of the tests: ``mpiexec -n N`` of the project's own Python, with a timeout.

The MPI tests need mpi4py and petsc4py (the ``mpi`` extra, which ``make install`` installs) and
an ``mpiexec`` (Debian's MPICH, ``tools/install_mpi_libs.sh``); :func:`require_mpi` fails, not
skips, when ``VEMKIT_REQUIRE_MPI`` is set (``make test`` sets it: CI must run them)."""

import os
import shutil
import subprocess
import sys

import pytest

#: each rank's own exit status, printed by a wrapper shell around it: "rank R exited S"
RANK_STATUS = 'vemkit "$@"; status=$?; echo "rank ${PMI_RANK:-?} exited $status" >&2; exit $status'


def require_mpi() -> str:
    """The mpiexec to run; skip (or fail with VEMKIT_REQUIRE_MPI) without MPI, mpi4py or petsc4py."""
    missing = [name for name in ("mpi4py", "petsc4py", "pymetis") if not _importable(name)]
    mpiexec = shutil.which("mpiexec")
    if mpiexec is None:
        missing.append("mpiexec")
    if missing:
        if os.environ.get("VEMKIT_REQUIRE_MPI"):
            pytest.fail(f"the MPI tests need {', '.join(missing)}: run make install")
        pytest.skip(f"needs {', '.join(missing)}")
    return mpiexec


def _importable(name: str) -> bool:
    try:
        __import__(name)
    except ImportError:
        return False
    return True


def job(ranks: int, *command, cwd=None, timeout: float = 300.0, env=None):
    """The finished ``mpiexec -n ranks COMMAND`` (subprocess.CompletedProcess, text output); a job
    still running after ``timeout`` seconds fails the test (a hang)."""
    mpiexec = require_mpi()
    environment = dict(os.environ, **(env or {}))
    environment["PATH"] = os.path.dirname(sys.executable) + os.pathsep + environment.get("PATH", "")
    try:
        return subprocess.run(
            [mpiexec, "-n", str(ranks), *map(str, command)],
            cwd=cwd,
            capture_output=True,
            text=True,
            timeout=timeout,
            env=environment,
        )
    except subprocess.TimeoutExpired:
        pytest.fail(f"mpiexec -n {ranks} {' '.join(map(str, command))} still ran after {timeout:.0f} s (a hang)")


def vemkit_job(ranks: int, *args, cwd=None, timeout: float = 300.0):
    """``mpiexec -n ranks vemkit ARGS``, each rank's exit status on stderr (:data:`RANK_STATUS`)."""
    return job(ranks, "sh", "-c", RANK_STATUS, "vemkit", *args, cwd=cwd, timeout=timeout)
