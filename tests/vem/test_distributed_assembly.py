"""The stiffness assembled across MPI ranks, each rank from its own cells (issue 37 item 2,
vemkit/vem/distributed_assembly.py), is the serial stiffness: 2D k = 1 with contact (Voronoi), k = 2
with its interior nodes condensed, 3D prisms with held components, a 3D Voronoi body with
prescribed displacements; every unknown owned by exactly one rank, the blocks d x d
(tests/vem/distributed_check.py under mpiexec -n 2)."""

import sys
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parents[1])]
from mpi_jobs import job  # noqa: E402

CHECK = Path(__file__).with_name("distributed_check.py")


def test_the_ranks_assemble_the_serial_stiffness():
    run = job(2, sys.executable, CHECK, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.split("\n").count("ok box-voronoi-prescribed") == 1
    assert sum(line.startswith("ok ") for line in run.stdout.splitlines()) == 5  # and once in shares
