"""One solve across MPI ranks: which rank this process is, the job's communicator, PETSc.

A job launched by ``mpiexec -n N`` (MPICH, Open MPI) or ``srun`` (SLURM) tells every process its
rank and the job's size in the environment (:data:`LAUNCHER_VARIABLES`): :func:`launched` reads
them without starting MPI, so the command knows before any work that it runs as one rank of many
(it then prints and writes from rank 0 only). :func:`world` starts MPI (mpi4py) on first use and
returns the communicator of all the ranks, or None in a process of its own. :func:`require_petsc4py`
is petsc4py's ``PETSc`` module, initialized once without vemkit's own command-line arguments.

mpi4py and petsc4py are the ``mpi`` extra (``make install`` installs it); without them a scene
that asks for them gets a SceneError naming ``solver.linear`` and the fix.
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass
from functools import cache

from vemkit.exceptions import SceneError

#: (rank, size) environment variables of the launchers: MPICH's Hydra and PMI (also srun's PMI-2),
#: Open MPI's mpiexec, PMIx (srun --mpi=pmix), and SLURM's own for the tasks of an srun step (not
#: SLURM_NTASKS, which a batch script running one vemkit per task of a sweep also has)
LAUNCHER_VARIABLES = (
    ("PMI_RANK", "PMI_SIZE"),
    ("OMPI_COMM_WORLD_RANK", "OMPI_COMM_WORLD_SIZE"),
    ("PMIX_RANK", "PMIX_SIZE"),
    ("SLURM_PROCID", "SLURM_STEP_NUM_TASKS"),
)
INSTALL_FIX = "run make install (it installs the mpi extra) or pip install -e '.[mpi]'"


@dataclass(frozen=True)
class Launch:
    """This process's place in the job: rank r of ``size`` (0 of 1 outside a launcher)."""

    rank: int = 0
    size: int = 1

    @property
    def distributed(self) -> bool:
        """Whether the job has more than one rank (the solve is then split across them)."""
        return self.size > 1

    @property
    def speaks(self) -> bool:
        """Whether this rank prints and writes (rank 0 only)."""
        return self.rank == 0


def launched() -> Launch:
    """The rank and size the launcher put in the environment (without starting MPI)."""
    for rank, size in LAUNCHER_VARIABLES:
        if rank in os.environ and size in os.environ:
            try:
                return Launch(int(os.environ[rank]), int(os.environ[size]))
            except ValueError:
                continue
    return Launch()


@cache
def world():
    """The communicator of every rank of a launched job (mpi4py's COMM_WORLD, MPI started on first
    use), or None when this process is alone."""
    if not launched().distributed:
        return None
    try:
        from mpi4py import MPI
    except ImportError:
        raise SceneError(
            f"this job runs on {launched().size} MPI ranks but mpi4py is not installed; {INSTALL_FIX}",
            key="solver.linear",
        ) from None
    if MPI.COMM_WORLD.Get_size() != launched().size:  # mpiexec of another MPI than mpi4py's
        raise SceneError(
            f"the launcher started {launched().size} ranks but MPI sees {MPI.COMM_WORLD.Get_size()}: they cannot "
            "reach each other; start them with the mpiexec of the MPI mpi4py was built with (make install: "
            "Debian's MPICH, /usr/bin/mpiexec), or under SLURM with srun --mpi=pmi2",
            key="mpiexec",
        )
    _share_cores(MPI.COMM_WORLD)
    return MPI.COMM_WORLD


def solve_communicator(split_in_one_process: bool):
    """The communicator a solve splits its problem across: the job's (:func:`world`) on several
    ranks; in one process MPI's COMM_SELF when the linear solver takes a split problem
    (``split_in_one_process``: ``vemkit.solvers.linear.takes_split_problem``), so that one process
    runs the same split as N ranks; None otherwise (scipy's matrix)."""
    comm = world()
    if comm is not None or not split_in_one_process:
        return comm
    require_petsc4py()  # MPI started by PETSc's initialization, on COMM_WORLD = this process
    from mpi4py import MPI

    return MPI.COMM_SELF


def job_ranks() -> tuple[int, int]:
    """(ranks on this machine, ranks in all) of the job: (1, 1) in a process of its own."""
    comm = world()
    if comm is None:
        return 1, 1
    return _ranks_here(), comm.Get_size()


@cache
def _ranks_here() -> int:
    """The ranks of the job on this machine (MPI_COMM_TYPE_SHARED), found once."""
    from mpi4py import MPI

    return MPI.COMM_WORLD.Split_type(MPI.COMM_TYPE_SHARED).Get_size()


def _share_cores(comm) -> None:
    """The Numba threads of the ranks on one machine share its cores (unless NUMBA_NUM_THREADS
    says otherwise): 2 ranks on 2 cores run one thread each, not two."""
    if "NUMBA_NUM_THREADS" in os.environ:
        return
    import numba

    numba.set_num_threads(max(1, min(numba.config.NUMBA_NUM_THREADS, (os.cpu_count() or 1) // _ranks_here())))


def require_petsc4py():
    """petsc4py's ``PETSc`` module, initialized without the command line's arguments (they are
    vemkit's, not PETSc options); SceneError naming solver.linear and the fix when it is missing."""
    try:
        import petsc4py
    except ImportError:
        raise SceneError(
            f"solver.linear = petsc needs petsc4py, which is not installed; {INSTALL_FIX}", key="solver.linear"
        ) from None
    if "petsc4py.PETSc" not in sys.modules:
        world()  # MPI first (mpi4py's COMM_WORLD is PETSc's), then PETSc on it
        petsc4py.init(["vemkit"])  # a program name, no option
    from petsc4py import PETSc

    return PETSc


def _running_world():
    """COMM_WORLD when MPI has been started in a job of several ranks, else None (never starts MPI)."""
    if not launched().distributed or "mpi4py.MPI" not in sys.modules:
        return None
    from mpi4py import MPI

    return MPI.COMM_WORLD if MPI.Is_initialized() and not MPI.Is_finalized() else None


def agreed_status(status: int) -> int:
    """The exit status of the job, the same on every rank: the largest of the ranks' statuses (a
    failure that every rank met alike, e.g. a refused input, gives its status everywhere)."""
    comm = _running_world()
    if comm is None:
        return status
    from mpi4py import MPI

    return int(comm.allreduce(status, op=MPI.MAX))


def end_job(status: int) -> None:
    """End every rank of the job now (MPI_Abort) after a failure this rank may have met alone (an
    internal error, memory): the others would otherwise wait for it forever. Nothing in one process."""
    comm = _running_world()
    if comm is not None:
        sys.stdout.flush()
        sys.stderr.flush()
        comm.Abort(status)
